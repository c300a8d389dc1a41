// Opacity-map lookups: how many fibres lie between a point and a shadow-casting light.
// CPU mirror (same names): core/src/light/opacity_maps.rs, which defines the layers (opacity
// shadow maps: even over the hair's depth; deep opacity maps: quadratic behind the first
// hair). Layers are stored four to a texel in `opacity_layers` (array layer
// slot × layers/4 + k/4, channel k % 4); `first_hair_distance` comes from
// opacity_start_osm.wgsl or opacity_start_dom.wgsl. Points outside a light's view see none.

@group(2) @binding(0) var opacity_layers: texture_2d_array<f32>;

// Fibres in front of distance `z` in one texel (cumulative layer values, linear between
// layer ends, the last value beyond them).
fn texel_hairs_in_front(slot: u32, texel: vec2<i32>, z: f32, depth: f32) -> f32 {
    let layers = scene.counts.y;
    let start = first_hair_distance(slot, texel);
    if !(z > start) {
        return 0.0;
    }
    let groups = layers / 4u;
    var previous_end = start;
    var previous_value = 0.0;
    for (var g = 0u; g < groups; g++) {
        let values = textureLoad(opacity_layers, texel, i32(slot * groups + g), 0);
        for (var c = 0u; c < 4u; c++) {
            let k = g * 4u + c;
            let end = layer_end(k, layers, start, depth);
            let value = values[c];
            if z <= end {
                let t = clamp((z - previous_end) / max(end - previous_end, 1e-12), 0.0, 1.0);
                return max(previous_value + (value - previous_value) * t, 0.0);
            }
            previous_end = end;
            previous_value = value;
        }
    }
    return max(previous_value, 0.0);
}

fn hairs_in_front(world: vec3<f32>, slot_in: i32) -> f32 {
    if slot_in < 0 {
        return 0.0;
    }
    let slot = u32(slot_in);
    let view = scene.shadows[slot];
    let clip = view.view_projection * vec4<f32>(world, 1.0);
    if !(clip.w > 0.0) {
        return 0.0;
    }
    let ndc = clip.xyz / clip.w;
    if !(abs(ndc.x) <= 1.0 && abs(ndc.y) <= 1.0 && ndc.z >= 0.0 && ndc.z <= 1.0) {
        return 0.0;
    }
    let size = vec2<f32>(textureDimensions(opacity_layers));
    let position = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * size - 0.5;
    let base = floor(position);
    let f = position - base;
    let z = light_distance(ndc.z, view.params) - view.layers.y;
    let last = vec2<i32>(size) - 1;
    let t00 = clamp(vec2<i32>(base), vec2<i32>(0), last);
    let t11 = clamp(vec2<i32>(base) + 1, vec2<i32>(0), last);
    let n00 = texel_hairs_in_front(slot, t00, z, view.layers.x);
    let n10 = texel_hairs_in_front(slot, vec2<i32>(t11.x, t00.y), z, view.layers.x);
    let n01 = texel_hairs_in_front(slot, vec2<i32>(t00.x, t11.y), z, view.layers.x);
    let n11 = texel_hairs_in_front(slot, t11, z, view.layers.x);
    let n = mix(mix(n00, n10, f.x), mix(n01, n11, f.x), f.y);
    return select(0.0, n, n >= 0.0 && n < 3.0e38);
}
