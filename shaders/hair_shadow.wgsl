// hair_shadow: the hair seen from a shadow-casting light. Ribbons face the light and are at
// least a texel wide, with their true coverage (shared/ribbon.wgsl). Deep opacity maps first
// draw depth only (`vs_main` without a fragment stage: the first hair per texel), then every
// map draws `fs_opacity`, adding each fragment's coverage to the layer its distance falls in
// and every later one (additive blending, up to 16 layers in four RGBA targets). Layer
// positions: light/opacity_maps.wgsl (CPU mirror: core/src/light/opacity_maps.rs).

struct ShadowVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) coverage: f32,
}

@vertex
fn vs_main(
    @builtin(vertex_index) vertex_index: u32,
    @builtin(instance_index) instance_index: u32,
) -> ShadowVertex {
    return pass_vertex(ribbon_vertex(vertex_index, instance_index));
}

// What the shadow passes take from a ribbon vertex (see preview_hair.wgsl `PassVertex`).
alias PassVertex = ShadowVertex;

fn pass_vertex(ribbon: RibbonVertex) -> ShadowVertex {
    var out: ShadowVertex;
    out.clip = ribbon.clip;
    out.coverage = ribbon.coverage;
    return out;
}

struct OpacityOutput {
    @location(0) layers0: vec4<f32>,
    @location(1) layers1: vec4<f32>,
    @location(2) layers2: vec4<f32>,
    @location(3) layers3: vec4<f32>,
}

@fragment
fn fs_opacity(in: ShadowVertex) -> OpacityOutput {
    let slot = hair.batch.z;
    let view = scene.shadows[slot];
    let layers = scene.counts.y;
    let z = light_distance(in.clip.z, view.params);
    let start = first_hair_distance(slot, vec2<i32>(in.clip.xy));
    var values = array<vec4<f32>, 4>();
    for (var k = 0u; k < layers; k++) {
        if z <= layer_end(k, layers, start, view.layers.x) {
            values[k / 4u][k % 4u] = in.coverage;
        }
    }
    var out: OpacityOutput;
    out.layers0 = values[0];
    out.layers1 = values[1];
    out.layers2 = values[2];
    out.layers3 = values[3];
    return out;
}
