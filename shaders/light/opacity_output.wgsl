// The opacity maps' fragment output (hair_shadow.wgsl for strands, far_hair_shadow.wgsl for
// far hair's thick hairs): up to 16 layers in four RGBA targets, blended additively.

struct OpacityOutput {
    @location(0) layers0: vec4<f32>,
    @location(1) layers1: vec4<f32>,
    @location(2) layers2: vec4<f32>,
    @location(3) layers3: vec4<f32>,
}

// A fragment at clip position `clip` (depth in z) covering `coverage` of its sample, seen
// from shadow slot `slot`: its coverage in the layer its distance falls in and every later one.
fn opacity_output(clip: vec4<f32>, coverage: f32, slot: u32) -> OpacityOutput {
    let shadow_view = scene.shadows[slot];
    let layers = scene.counts.y;
    let z = light_distance(clip.z, shadow_view.params);
    let start = first_hair_distance(slot, vec2<i32>(clip.xy));
    var values = array<vec4<f32>, 4>();
    for (var k = 0u; k < layers; k++) {
        if z <= layer_end(k, layers, start, shadow_view.layers.x) {
            values[k / 4u][k % 4u] = coverage;
        }
    }
    var out: OpacityOutput;
    out.layers0 = values[0];
    out.layers1 = values[1];
    out.layers2 = values[2];
    out.layers3 = values[3];
    return out;
}
