// preview_body: the opaque body (head scan, teapot) under the hair, for depth testing and
// context: Lambertian, lit by the scene's lights with the hair's shadow (the fibres in front
// from the opacity maps, each passing the material's forward transmittance) and the body's
// own shadow, plus the ambient light. Smooth normals from the vertices
// (core's `BodyMesh::vertex_normals`), turned to the viewer's side of the face, whose own
// normal (from screen-space derivatives) stands in where a vertex has none.
// `vs_shadow` draws the body into a shadow-casting light's depth map (body shadows).
// Structs: keep in sync with render/src/renderer/preview_body.rs (`BodyUniforms`).

struct BodyUniforms {
    view_projection: mat4x4<f32>,
    camera_position: vec4<f32>,
}

@group(0) @binding(0) var<uniform> body: BodyUniforms;

struct VertexOutput {
    @builtin(position) clip: vec4<f32>,
    // At the pixel's centre, for the face's normal (screen-space derivatives).
    @location(0) world: vec3<f32>,
    // Centroid: with MSAA, a pixel a triangle only partly covers is lit at a point inside
    // the triangle, not at the pixel's centre extrapolated past its edge (behind the
    // neighbouring face, where it would shadow itself).
    @location(1) @interpolate(perspective, centroid) lit_world: vec3<f32>,
    @location(2) @interpolate(perspective, centroid) normal: vec3<f32>,
}

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> VertexOutput {
    var out: VertexOutput;
    out.clip = body.view_projection * vec4<f32>(position, 1.0);
    out.world = position;
    out.lit_world = position;
    out.normal = normal;
    return out;
}

@vertex
fn vs_shadow(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return body.view_projection * vec4<f32>(position, 1.0);
}

@fragment
fn fs_main(in: VertexOutput) -> @location(0) vec4<f32> {
    var face = normalize(cross(dpdx(in.world), dpdy(in.world)));
    let v = normalize(body.camera_position.xyz - in.world);
    if dot(face, v) < 0.0 {
        face = -face;
    }
    // Interpolated normals shorten between vertices that disagree; one that has (nearly)
    // vanished, or a vertex with none, leaves the face's own.
    var n = face;
    let smooth_length = length(in.normal);
    if smooth_length > 0.1 {
        n = in.normal / smooth_length;
        if dot(n, face) < 0.0 {
            n = -n;
        }
    }
    let albedo = scene.body_color.rgb;
    var radiance = scene.ambient.rgb * albedo;
    let p = in.lit_world;
    for (var i = 0u; i < scene.counts.x; i++) {
        let l = light_direction(i, p);
        let cosine = dot(n, l);
        if cosine <= 0.0 {
            continue;
        }
        let slot = light_shadow_slot(i);
        let through_hair = pow(scene.forward_transmittance.rgb, vec3<f32>(hairs_in_front(p, slot)));
        radiance += albedo * 0.31830989 * cosine * light_irradiance(i, p)
            * body_surface_visibility(p, n, slot) * through_hair;
    }
    return vec4<f32>(tonemap(radiance), 1.0);
}
