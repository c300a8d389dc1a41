// strand_lod: a bundle's level of detail (seed 000 §3.6, eq. 7-12) on the GPU, for the mesh
// path's task shader (strand_mesh.wgsl): how many strands, how many vertices each, the morph
// factor and the thickness compensation. CPU mirror, and what every other path plans with:
// core/src/runtime/frame_plan.rs `bundle_lod` (f64; the formulas are in
// core/src/strands/lod.rs). Needs `pcg_hash` and `hash_to_unit` (shared/strand_vertex.wgsl).
// Structs: keep in sync with core/src/runtime/gpu_types.rs.

struct BundleLodGpu {
    centre: vec3<f32>,
    radius_m: f32,
    root_size_m: f32,
    strand_length_m: f32,
    density: f32,
    // ⌈density · N⌉, counted on the CPU (f64) so both sides agree exactly.
    grown_strands: u32,
}

struct LodParams {
    eye: vec4<f32>,
    // x: vertical resolution (px); y: tan of the vertical field of view; z, w: α of strand
    // and vertex LOD.
    detail: vec4<f32>,
    // x: λ; y: 1 when LOD is on; z: 1 when bundles outside the view are culled.
    switches: vec4<f32>,
    // x: strands per bundle; y: log2 of the full-detail segments; z: bundles; w: task
    // workgroups per row of the draw.
    counts: vec4<u32>,
}

// NaN by its bits (a driver may fold `x != x` away).
fn lod_is_nan(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) > 0x7f800000u;
}

// Eq. 7 (lod.rs `detail_level`): L = min(1, h R α / (d tan θ)); a non-positive or infinite
// extent draws everything, a NaN level nothing.
fn lod_detail_level(size_m: f32, resolution_px: f32, distance_m: f32, tan_fov: f32, alpha: f32) -> f32 {
    let extent = distance_m * tan_fov;
    if !(extent > 0.0) || (bitcast<u32>(extent) & 0x7fffffffu) >= 0x7f800000u {
        return 1.0;
    }
    let level = size_m * resolution_px * alpha / extent;
    if lod_is_nan(level) {
        return 0.0;
    }
    return clamp(level, 0.0, 1.0);
}

// Eq. 8 (lod.rs `strand_count`): ⌈L (N + δ)⌉, at most N.
fn lod_strand_count(level: f32, strands: u32, delta: f32) -> u32 {
    let l = select(clamp(level, 0.0, 1.0), 0.0, lod_is_nan(level));
    return min(u32(ceil(l * (f32(strands) + delta))), strands);
}

// min(1/L, N), at least 1 (lod.rs `thickness_factor`).
fn lod_thickness(level: f32, strands: u32) -> f32 {
    let cap = f32(max(strands, 1u));
    if !(level > 0.0) {
        return cap;
    }
    return max(min(1.0 / level, cap), 1.0);
}

// Eq. 9, 10, 12 (lod.rs `vertex_lod`): (vertex count, γ).
fn lod_vertices(level: f32, max_e: u32, lambda: f32) -> vec2<f32> {
    let l = select(clamp(level, 0.0, 1.0), 0.0, lod_is_nan(level));
    let window = select(clamp(lambda, 0.0, 1.0), 0.0, lod_is_nan(lambda));
    if !(l > 0.0) {
        // log2(0) is undefined in SPIR-V; the CPU's −∞ gives e = ẽ = 0: two vertices.
        return vec2<f32>(2.0, 0.0);
    }
    let x = log2(l * f32(1u << max_e));
    let e = u32(clamp(ceil(x), 0.0, f32(max_e)));
    let e_tilde = u32(clamp(ceil(x - window), 0.0, f32(max_e)));
    var gamma = 0.0;
    if e > e_tilde && window > 0.0 {
        gamma = clamp(1.0 - (x - f32(e_tilde)) / window, 0.0, 1.0);
    }
    return vec2<f32>(f32((1u << e) + 1u), gamma);
}

// What LOD draws of bundle `index` as a run of its strands (vertex and segment offsets 0:
// the mesh path has no scratch buffer).
fn bundle_lod(index: u32, bundle: BundleLodGpu, lod: LodParams) -> StrandRun {
    let per_bundle = lod.counts.x;
    let max_e = lod.counts.y;
    var run: StrandRun;
    run.first_root = index * per_bundle;
    // Fur's cross-fade: the share of strands kept (frame_plan.rs `bundle_lod`).
    let keep = clamp(lod.switches.w, 0.0, 1.0);
    if lod.switches.y == 0.0 {
        run.strand_count = min(u32(ceil(f32(bundle.grown_strands) * keep)), bundle.grown_strands);
        run.vertex_count = (1u << max_e) + 1u;
        run.gamma = 0.0;
        run.thickness = 1.0;
        return run;
    }
    let distance = max(distance(bundle.centre, lod.eye.xyz) - bundle.radius_m, 0.0);
    let strand_level = lod_detail_level(bundle.root_size_m, lod.detail.x, distance, lod.detail.y, lod.detail.z);
    let delta = hash_to_unit(pcg_hash(index));
    let density = bundle.density;
    run.strand_count = min(lod_strand_count(strand_level * density * keep, per_bundle, delta), bundle.grown_strands);
    let vertex_level = lod_detail_level(bundle.strand_length_m, lod.detail.x, distance, lod.detail.y, lod.detail.w);
    let vertices = lod_vertices(vertex_level, max_e, lod.switches.x);
    run.vertex_count = u32(vertices.x);
    run.gamma = vertices.y;
    run.thickness = lod_thickness(strand_level, per_bundle);
    return run;
}
