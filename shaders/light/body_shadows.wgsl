// Body shadows: the body's depth seen from each shadow-casting light, compared through a
// 3 × 3 grid of hardware-filtered (2×2 PCF) taps a texel and a half apart: a soft edge
// about five texels wide (a tent filter) instead of the single tap's one-texel stair-steps.
// Points outside a light's view are lit.
@group(2) @binding(2) var body_depth: texture_depth_2d_array;
@group(2) @binding(3) var body_depth_sampler: sampler_comparison;

fn body_visibility(world: vec3<f32>, slot: i32) -> f32 {
    if slot < 0 {
        return 1.0;
    }
    return body_depth_compare(scene.shadows[u32(slot)].view_projection * vec4<f32>(world, 1.0), slot);
}

// The body's own surface, with its unit `normal` on the light's side: looked up two texels off the
// surface along the normal, so the filter's wide footprint does not reach depths of the same
// surface behind the point (acne, and dark lines along the triangles' edges).
fn body_surface_visibility(world: vec3<f32>, normal: vec3<f32>, slot: i32) -> f32 {
    if slot < 0 {
        return 1.0;
    }
    let view = scene.shadows[u32(slot)];
    let clip = view.view_projection * vec4<f32>(world, 1.0);
    // A texel's width at this point: params.w per metre of distance (perspective: clip.w is
    // that distance) or everywhere (orthographic).
    var texel = view.params.w;
    if view.params.z != 0.0 {
        texel *= max(clip.w, 0.0);
    }
    return body_depth_compare(view.view_projection * vec4<f32>(world + normal * (2.0 * texel), 1.0), slot);
}

fn body_depth_compare(clip: vec4<f32>, slot: i32) -> f32 {
    if !(clip.w > 0.0) {
        return 1.0;
    }
    let ndc = clip.xyz / clip.w;
    if !(abs(ndc.x) <= 1.0 && abs(ndc.y) <= 1.0 && ndc.z >= 0.0 && ndc.z <= 1.0) {
        return 1.0;
    }
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let step = 1.5 / vec2<f32>(textureDimensions(body_depth));
    var lit = 0.0;
    for (var j = -1; j <= 1; j++) {
        for (var i = -1; i <= 1; i++) {
            // Corner taps weigh 1, edge taps 2, the centre 4 (a tent over the taps).
            let weight = f32((2 - abs(i)) * (2 - abs(j)));
            lit += weight * textureSampleCompareLevel(
                body_depth, body_depth_sampler, uv + vec2<f32>(f32(i), f32(j)) * step, slot, ndc.z,
            );
        }
    }
    return lit / 16.0;
}
