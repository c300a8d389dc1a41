// Far hair: seed 001's aggregated BCSDF for a thick hair that stands for a cluster of fibres,
// over the near fibre's lobes (hair_bsdf.wgsl's `mp`, `tilted` and the scene's variances).
// CPU mirror (same names, the model and its departures from the paper written out):
// core/src/light/aggregated_bcsdf.rs. The composer prepends AGG_THETA_COUNT, AGG_PHI_COUNT
// and AGG_LOBES_OFFSET from their one definition there.
// Tables (group 2, binding 7), one storage buffer of vec4: profile rows of AGG_THETA_COUNT
// texels over |θ| — by |θ_i|: 0: a_F (rgb), β_f²; 1: A₁ + A₃ (rgb), Δ_b; 2: a_b (rgb), σ_b²;
// 3: R_f — by |θ_o|: 4-7: Ā_R, Ā_TT, Ā_TRT, Ā_residual (rgb); then from AGG_LOBES_OFFSET the
// h-averaged lobes A_p N_p (rgb) per lobe, |θ_o| rows, |φ| columns.

@group(2) @binding(7) var<storage, read> agg_tables: array<vec4<f32>>;

const AGG_D_1PLUS: f32 = 0.6;
const AGG_C_M: f32 = 0.2;
const AGG_D_B: f32 = 0.7;

// E[a^k] for a Poisson count k of mean `mean` (what passes a random number of hairs).
fn expected_power(a: f32, mean: f32) -> f32 {
    return exp(-max(mean, 0.0) * (1.0 - clamp(a, 0.0, 1.0)));
}

fn agg_gaussian(x: f32, variance: f32) -> f32 {
    let v = max(variance, 1e-6);
    return exp(-x * x / (2.0 * v)) / sqrt(TAU * v);
}

// Texel pair and weight of |value| over [0, range] sampled at `count` texel centres.
fn agg_coordinate(value: f32, range: f32, count: u32) -> vec3<f32> {
    let x = (min(abs(value), range) / range) * f32(count) - 0.5;
    let lo = clamp(floor(x), 0.0, f32(count - 1u));
    let hi = min(lo + 1.0, f32(count - 1u));
    return vec3<f32>(lo, hi, clamp(x - lo, 0.0, 1.0));
}

fn agg_profile(row: u32, theta: f32) -> vec4<f32> {
    let c = agg_coordinate(theta, 0.5 * PI, AGG_THETA_COUNT);
    let base = row * AGG_THETA_COUNT;
    return mix(agg_tables[base + u32(c.x)], agg_tables[base + u32(c.y)], c.z);
}

fn agg_lobe(p: u32, theta: f32, phi: f32) -> vec3<f32> {
    let t = agg_coordinate(theta, 0.5 * PI, AGG_THETA_COUNT);
    let f = agg_coordinate(phi, PI, AGG_PHI_COUNT);
    let layer = AGG_LOBES_OFFSET + p * AGG_THETA_COUNT * AGG_PHI_COUNT;
    let r0 = layer + u32(t.x) * AGG_PHI_COUNT;
    let r1 = layer + u32(t.y) * AGG_PHI_COUNT;
    let a = mix(agg_tables[r0 + u32(f.x)].rgb, agg_tables[r0 + u32(f.y)].rgb, f.z);
    let b = mix(agg_tables[r1 + u32(f.x)].rgb, agg_tables[r1 + u32(f.y)].rgb, f.z);
    return mix(a, b, t.z);
}

// E[Σ_{i=1}^{k} a^{2i−1}] for a Poisson count k of mean n, in closed form.
fn odd_power_sum(a: f32, n: f32) -> f32 {
    let a2 = a * a;
    if 1.0 - a2 < 1e-6 {
        return a * n;
    }
    return a * (1.0 - expected_power(a2, n)) / (1.0 - a2);
}

// f for the shaded fibre of a cluster: `path` = (hairs before, itself included; hairs behind)
// from `cluster_hairs_on_path`, `coverage` the cluster's ρ.
fn aggregated_bcsdf(wo: vec3<f32>, wi: vec3<f32>, path: vec2<f32>, coverage: f32) -> vec3<f32> {
    var n = 1.0;
    if path.x < 3.0e38 && path.x >= 1.0 {
        n = min(path.x, 1e4);
    }
    var behind = 0.0;
    if path.y < 3.0e38 && path.y >= 0.0 {
        behind = min(path.y, 1e4);
    }
    var rho = 1.0;
    if coverage < 3.0e38 && coverage > -3.0e38 {
        rho = clamp(coverage, 0.0, 1.0);
    }
    let before = n - 1.0;
    let sin_theta_i = clamp(wi.x, -1.0, 1.0);
    let sin_theta_o = clamp(wo.x, -1.0, 1.0);
    let theta_i = asin(sin_theta_i);
    let theta_o = asin(sin_theta_o);
    let cos_theta_i = cos(theta_i);
    let cos_theta_o = cos(theta_o);
    let theta_h = 0.5 * (theta_i + theta_o);
    let cos_theta_d = max(cos(0.5 * (theta_i - theta_o)), 1e-3);
    let phi = abs(wrap_angle(atan2(wi.z, wi.y) - atan2(wo.z, wo.y)));
    let forward = agg_profile(0u, theta_i);
    let back = agg_profile(1u, theta_i);
    let single_back = agg_profile(2u, theta_i);
    let r_f = agg_profile(3u, theta_i).x;
    let widen = 4.0 * before * forward.w;
    let sharpness = expected_power(clamp(r_f, 0.0, 1.0), before);
    var lobes = vec3<f32>(0.0);
    for (var p = 0u; p < 4u; p++) {
        let o = tilted(p, sin_theta_o, cos_theta_o);
        let m = mp(cos_theta_i, o.y, sin_theta_i, o.x, scene.lobe_variance[p] + widen);
        let mean = agg_profile(4u + p, theta_o).rgb;
        var shaped = mean / TAU;
        if p < 3u {
            shaped = agg_lobe(p, theta_o, phi);
        }
        lobes += m * (sharpness * shaped + (1.0 - sharpness) * mean / TAU);
    }
    let near_half = select(0.0, 1.0 / PI, phi < 0.5 * PI);
    // Eq. 12-13 on the light's side; past |φ| = π/2 both fade to 0 at φ = π (n counts it).
    let cos_phi = cos(phi);
    let p_s = (1.0 - rho) * (1.0 - abs(cos_phi));
    let p_m = (1.0 - rho) * AGG_C_M * min(1.0 + cos_phi, 1.0);
    let p_n = max(1.0 - p_s - p_m, 0.0);
    var out = vec3<f32>(0.0);
    for (var c = 0; c < 3; c++) {
        let a_f = clamp(forward[c], 0.0, 1.0);
        let local = AGG_D_B * max(back[c], 0.0) * (1.0 - expected_power(a_f * a_f, behind));
        let gaps = AGG_D_1PLUS * max(single_back[c], 0.0) * odd_power_sum(a_f, behind);
        let total_b = local + gaps;
        var variance_b = single_back.w;
        if total_b > 1e-12 {
            variance_b = (local * single_back.w + gaps * (single_back.w + behind * forward.w)) / total_b;
        }
        let b_hat = total_b * agg_gaussian(theta_h - back.w, variance_b) / (2.0 * cos_theta_d) * near_half;
        let s = p_s * a_f + p_n;
        out[c] = s * (expected_power(a_f, before) * lobes[c] + b_hat);
    }
    return select(vec3<f32>(0.0), out, (out < vec3<f32>(3.0e38)) & (out >= vec3<f32>(0.0)));
}

const AGG_VISIBLE_DEPTHS: u32 = 3u;

// How far the line p + t d runs inside the unit circle ahead and behind, for p inside or on
// it (the stable roots of |p + t d|² = 1).
fn chord_ends(p: vec2<f32>, d: vec2<f32>) -> vec2<f32> {
    let aa = dot(d, d);
    if aa < 1e-18 {
        return vec2<f32>(0.0);
    }
    let bb = dot(p, d);
    let cc = min(dot(p, p) - 1.0, 0.0);
    let root = sqrt(max(bb * bb - aa * cc, 0.0));
    let q = -(bb + select(-root, root, bb >= 0.0));
    var t = vec2<f32>(0.0);
    if q != 0.0 {
        t = vec2<f32>(q / aa, cc / q);
    }
    return vec2<f32>(max(max(t.x, t.y), 0.0), max(-min(t.x, t.y), 0.0));
}

// (hairs before the shaded fibre, itself included; hairs behind it) on the light's line
// through the k-th of AGG_VISIBLE_DEPTHS depths at which the eye's ray at `across` ∈ [−1, 1]
// meets its fibre (quantiles of the exponential first-hit depth within the ellipse's chord).
// `shape`: semi-major, semi-minor (m), major-axis angle in the fibre frame's y-z plane,
// crossings per metre. In the ellipse's unit-circle coordinates, where the entry is exactly on
// the circle and chords stay well-conditioned; counts follow the in-plane chords (fibres run
// along the hair).
fn cluster_hairs_on_path(
    shape: vec4<f32>,
    fibre_radius_m: f32,
    wo: vec3<f32>,
    wi: vec3<f32>,
    across: f32,
    k: u32,
) -> vec2<f32> {
    let c = cos(shape.z);
    let s_angle = sin(shape.z);
    let to_unit = mat2x2<f32>(vec2<f32>(c / shape.x, -s_angle / shape.y), vec2<f32>(s_angle / shape.x, c / shape.y));
    var view = vec2<f32>(0.0, 1.0);
    let view_length = length(wo.yz);
    if view_length > 1e-6 {
        view = wo.yz / view_length;
    }
    let v = to_unit * view;
    let v_length = length(v);
    if !(v_length > 0.0 && v_length < 3.0e38) {
        return vec2<f32>(1.0, 0.0);
    }
    let v_hat = v / v_length;
    let side = vec2<f32>(v_hat.y, -v_hat.x);
    var s = 0.0;
    if across < 3.0e38 && across > -3.0e38 {
        s = clamp(across, -1.0, 1.0);
    }
    let entry = s * side + sqrt(max(1.0 - s * s, 0.0)) * v_hat;
    let inward = -v;
    let chord = max(-2.0 * dot(entry, inward) / (v_length * v_length), 0.0);
    let u = (f32(min(k, AGG_VISIBLE_DEPTHS - 1u)) + 0.5) / f32(AGG_VISIBLE_DEPTHS);
    let rate = shape.w;
    let q = rate * chord;
    var depth = u * chord;
    if q >= 1e-4 {
        depth = -log(1.0 - u * (1.0 - exp(-q))) / rate;
    }
    depth = clamp(depth, 0.0, chord);
    let in_plane = length(wi.yz);
    if !(in_plane > 1e-6) {
        return vec2<f32>(1.0, 0.0);
    }
    let light = wi.yz / in_plane;
    let ends = chord_ends(entry + depth * inward, to_unit * light);
    // The eye's ray is empty up to the shaded fibre: light leaving back along it meets
    // nothing while the two stay within a fibre's width.
    let cos_a = dot(light, view);
    var free = 0.0;
    if cos_a > 0.0 {
        let sin_a = sqrt(max(1.0 - cos_a * cos_a, 0.0));
        free = min(ends.x, min(depth / max(cos_a, 1e-6), 2.0 * fibre_radius_m / max(sin_a, 1e-6)));
    }
    let path = vec2<f32>(1.0 + rate * max(ends.x - free, 0.0), rate * ends.y);
    if !(path.x < 3.0e38 && path.y < 3.0e38) {
        return vec2<f32>(1.0, 0.0);
    }
    return path;
}

// What a thick hair shows at `across` of its ribbon: `aggregated_bcsdf` averaged over the
// depths of the fibre the eye meets.
fn aggregated_cluster(
    shape: vec4<f32>,
    fibre_radius_m: f32,
    coverage: f32,
    wo: vec3<f32>,
    wi: vec3<f32>,
    across: f32,
) -> vec3<f32> {
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < AGG_VISIBLE_DEPTHS; k++) {
        let path = cluster_hairs_on_path(shape, fibre_radius_m, wo, wi, across, k);
        sum += aggregated_bcsdf(wo, wi, path, coverage);
    }
    return sum / f32(AGG_VISIBLE_DEPTHS);
}
