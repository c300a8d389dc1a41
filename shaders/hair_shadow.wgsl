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

@fragment
fn fs_opacity(in: ShadowVertex) -> OpacityOutput {
    return opacity_output(in.clip, in.coverage, hair.batch.z);
}
