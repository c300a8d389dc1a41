// far_lod: far hair's deferred level choice (seed 001 §5.2, eq. 16). `thick_widths`: one
// invocation per measured thick hair (as thick_main generated it this frame: centres in
// `positions`, half-axes in `sections`), the widest it looks in pixels, kept per bundle for
// the level it draws (slot 0, w_cur) and the next coarser one (slot 1, w_cur−) by atomicMax
// of the f32 bits (positive floats order as their bits; NaN bits are above every finite
// width, so NaN counts as too wide). `next_levels`: one invocation per bundle, eq. 16.
// CPU mirror (same names): core/src/runtime/far_lod.rs. `ThickHairGpu` is in
// shared/thick_hair.wgsl; keep FarLodParams in sync with the mirror.

struct FarLodParams {
    eye: vec4<f32>,
    pixel_at_unit: f32,
    width_threshold_px: f32,
    vertex_count: u32,
    count: u32,
}

@group(0) @binding(0) var<uniform> lod: FarLodParams;
@group(0) @binding(1) var<storage, read> thick_hairs: array<ThickHairGpu>;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> sections: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> levels: array<u32>;
@group(0) @binding(5) var<storage, read_write> widths: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read> level_counts: array<u32>;
@group(0) @binding(7) var<storage, read_write> next: array<u32>;

fn thick_width_px(centre: vec3<f32>, tangent: vec3<f32>, major: vec3<f32>, minor: vec3<f32>) -> f32 {
    let to_eye = lod.eye.xyz - centre;
    let distance = length(to_eye);
    let side = cross(tangent, to_eye);
    var width_m = 2.0 * max(length(major), length(minor));
    if dot(side, side) > 1e-20 * max(dot(to_eye, to_eye), 1e-30) {
        let s = normalize(side);
        width_m = 2.0 * sqrt(dot(major, s) * dot(major, s) + dot(minor, s) * dot(minor, s));
    }
    return width_m / max(lod.pixel_at_unit * distance, 1e-30);
}

@compute @workgroup_size(64)
fn thick_widths(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = id.x;
    if t >= lod.count {
        return;
    }
    let hair = thick_hairs[t];
    if hair.block >= arrayLength(&levels) {
        return;
    }
    let current = levels[hair.block];
    var slot = 2u;
    if hair.level == current {
        slot = 0u;
    } else if hair.level == current + 1u {
        slot = 1u;
    }
    if slot == 2u {
        return;
    }
    let n = max(lod.vertex_count, 2u);
    let base = t * n;
    var widest = 0u;
    for (var k = 0u; k < n; k++) {
        let tangent = positions[base + min(k + 1u, n - 1u)].xyz - positions[base + max(k, 1u) - 1u].xyz;
        let px = thick_width_px(
            positions[base + k].xyz,
            tangent,
            sections[2u * (base + k)].xyz,
            sections[2u * (base + k) + 1u].xyz,
        );
        widest = max(widest, bitcast<u32>(px));
    }
    atomicMax(&widths[2u * hair.block + slot], widest);
}

@compute @workgroup_size(64)
fn next_levels(@builtin(global_invocation_id) id: vec3<u32>) {
    let b = id.x;
    if b >= arrayLength(&levels) {
        return;
    }
    let count = level_counts[b];
    let level = min(levels[b], count);
    let w_cur = bitcast<f32>(atomicLoad(&widths[2u * b]));
    let w_coarser = bitcast<f32>(atomicLoad(&widths[2u * b + 1u]));
    var chosen = level;
    if level >= 1u && !(w_cur <= lod.width_threshold_px) {
        chosen = level - 1u;
    } else if level < count && w_coarser <= lod.width_threshold_px {
        chosen = level + 1u;
    }
    next[b] = chosen;
}
