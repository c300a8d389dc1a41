// far_hair_shadow: thick hairs seen from a shadow-casting light (after far_hair.wgsl, the
// scene and the opacity-map modules): each fragment adds the share of its rays that meet a
// fibre (`thick_opacity`) to the opacity layers, as hair_shadow.wgsl adds a strand's coverage.

@fragment
fn fs_far_opacity(in: FarVertex) -> OpacityOutput {
    return opacity_output(in.clip, thick_opacity(in), far_view.batch.z);
}
