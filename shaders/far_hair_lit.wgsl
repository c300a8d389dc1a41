// far_hair_lit: the thick hairs' colour pass (after far_hair.wgsl and the scene, shading and
// shadow modules).

// Radiance leaving the thick hair toward the viewer, tone-mapped.
fn shade_thick(in: FarVertex) -> vec3<f32> {
    let wo = far_safe_normalize(far_toward_viewer(in.world));
    let frame = fibre_frame(in.tangent, wo);
    let x = frame[0];
    let y = frame[1];
    let z = frame[2];
    let r = max(0.5 * far_view.width.x, 1e-9);
    let members = in.members_coverage.x;
    let section = far_section(in.major, in.minor, y, z, r);
    // Fibres a ray crosses per metre past the shaded one, and the share of the section the
    // fibres cover (aggregated_bcsdf.rs `ClusterShape::crossings_per_m`, `coverage`).
    let crossings = 2.0 * r * max(members - 1.0, 0.0) / (PI * section.w);
    let coverage = min(members * r * r / section.w, 1.0);
    let shape = vec4<f32>(section.x, section.y, section.z, crossings);
    let sigma_a = strand_sigma_a(in.along, 0.5);
    let wo_local = vec3<f32>(dot(wo, x), dot(wo, y), dot(wo, z));
    var radiance = scene.ambient.rgb * hair_color(sigma_a);
    for (var i = 0u; i < scene.counts.x; i++) {
        let wi = light_direction(i, in.world);
        let slot = light_shadow_slot(i);
        let n = hairs_in_front(in.world, slot);
        let visible = body_visibility(in.world, slot);
        let wi_local = vec3<f32>(dot(wi, x), dot(wi, y), dot(wi, z));
        let f = aggregated_cluster(shape, r, coverage, wo_local, wi_local, -in.across);
        radiance += f * pow(scene.forward_transmittance.rgb, vec3<f32>(n)) * light_irradiance(i, in.world) * visible;
    }
    return tonemap(radiance);
}

// The lit pass, where the pre-pass left a thick hair nearest. No discard (see preview_hair's
// fs_main): the early depth test keeps shading to one fragment per sample.
@fragment
fn fs_far(in: FarVertex) -> @location(0) vec4<f32> {
    return vec4<f32>(shade_thick(in), 1.0);
}
