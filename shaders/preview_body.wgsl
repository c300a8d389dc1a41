// preview_body: the opaque body (head scan, teapot) under the hair, for depth testing and
// context. Flat normals from screen-space derivatives; two lights.
// Structs: keep in sync with render/src/preview.rs (`BodyUniforms`).

struct BodyUniforms {
    view_projection: mat4x4<f32>,
    camera_position: vec4<f32>,
    color: vec4<f32>,
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

@fragment
fn fs_main(in: VertexOutput) -> @location(0) vec4<f32> {
    var n = normalize(cross(dpdx(in.world), dpdy(in.world)));
    let v = normalize(body.camera_position.xyz - in.world);
    if dot(n, v) < 0.0 {
        n = -n;
    }
    let key = max(dot(n, normalize(vec3<f32>(0.6, 0.8, 0.9))), 0.0);
    let fill = max(dot(n, normalize(vec3<f32>(-0.8, 0.3, 0.5))), 0.0) * 0.35;
    let light = 0.18 + key * 0.75 + fill;
    return vec4<f32>(body.color.rgb * light, 1.0);
}
