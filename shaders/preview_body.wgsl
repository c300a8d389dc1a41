// preview_body: the opaque body (head scan, teapot) under the hair, for depth testing and
// context: Lambertian, lit by the scene's lights with the hair's shadow (the fibres in front
// from the opacity maps, each passing the material's forward transmittance) and the body's
// own shadow, plus the ambient light. Flat normals from screen-space derivatives.
// `vs_shadow` draws the body into a shadow-casting light's depth map (body shadows).
// Structs: keep in sync with render/src/renderer/preview_body.rs (`BodyUniforms`).

struct BodyUniforms {
    view_projection: mat4x4<f32>,
    camera_position: vec4<f32>,
}

@group(0) @binding(0) var<uniform> body: BodyUniforms;

struct VertexOutput {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
}

@vertex
fn vs_main(@location(0) position: vec3<f32>) -> VertexOutput {
    var out: VertexOutput;
    out.clip = body.view_projection * vec4<f32>(position, 1.0);
    out.world = position;
    return out;
}

@vertex
fn vs_shadow(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return body.view_projection * vec4<f32>(position, 1.0);
}

@fragment
fn fs_main(in: VertexOutput) -> @location(0) vec4<f32> {
    var n = normalize(cross(dpdx(in.world), dpdy(in.world)));
    let v = normalize(body.camera_position.xyz - in.world);
    if dot(n, v) < 0.0 {
        n = -n;
    }
    let albedo = scene.body_color.rgb;
    var radiance = scene.ambient.rgb * albedo;
    for (var i = 0u; i < scene.counts.x; i++) {
        let l = light_direction(i, in.world);
        let cosine = dot(n, l);
        if cosine <= 0.0 {
            continue;
        }
        let slot = light_shadow_slot(i);
        let through_hair = pow(scene.forward_transmittance.rgb, vec3<f32>(hairs_in_front(in.world, slot)));
        radiance += albedo * 0.31830989 * cosine * light_irradiance(i, in.world)
            * body_visibility(in.world, slot) * through_hair;
    }
    return vec4<f32>(tonemap(radiance), 1.0);
}
