// Body shadows: the body's depth seen from each shadow-casting light, compared with hardware
// filtering (2×2 PCF). Points outside a light's view are lit.
@group(2) @binding(2) var body_depth: texture_depth_2d_array;
@group(2) @binding(3) var body_depth_sampler: sampler_comparison;

fn body_visibility(world: vec3<f32>, slot: i32) -> f32 {
    if slot < 0 {
        return 1.0;
    }
    let view = scene.shadows[u32(slot)];
    let clip = view.view_projection * vec4<f32>(world, 1.0);
    if !(clip.w > 0.0) {
        return 1.0;
    }
    let ndc = clip.xyz / clip.w;
    if !(abs(ndc.x) <= 1.0 && abs(ndc.y) <= 1.0 && ndc.z >= 0.0 && ndc.z <= 1.0) {
        return 1.0;
    }
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    return textureSampleCompareLevel(body_depth, body_depth_sampler, uv, slot, ndc.z);
}
