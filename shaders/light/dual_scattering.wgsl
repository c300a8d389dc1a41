// Dual scattering (Zinke et al. 2008): global forward scattering through the `n` fibres the
// opacity maps count, local back scattering from tables precomputed from the material.
// CPU mirror (same names, and the derivation in our measure): core/src/light/dual_scattering.rs.
// Tables (group 2): ds_profile rows per |θ_i| — row 0: a_f (rgb), β_f²; row 1: A_b (rgb),
// Δ_b; row 2: σ_b², a_b — and ds_lobes: N_G,p (rgb) per lobe layer, |θ_i| rows, |φ| columns.

@group(2) @binding(4) var table_sampler: sampler;
@group(2) @binding(5) var ds_profile: texture_2d<f32>;
@group(2) @binding(6) var ds_lobes: texture_2d_array<f32>;

const D_F: f32 = 0.7;
const D_B: f32 = 0.7;

fn ds_gaussian(x: f32, variance: f32) -> f32 {
    let v = max(variance, 1e-6);
    return exp(-x * x / (2.0 * v)) / sqrt(TAU * v);
}

fn ds_row(row: f32, theta_u: f32) -> vec4<f32> {
    return textureSampleLevel(ds_profile, table_sampler, vec2<f32>(theta_u, (row + 0.5) / 3.0), 0.0);
}

fn dual_scattering(wo: vec3<f32>, wi: vec3<f32>, f_s: vec3<f32>, n_in: f32) -> vec3<f32> {
    var n = max(n_in, 0.0);
    if !(n < 3.0e38) {
        n = 0.0;
    }
    let theta_i = asin(clamp(wi.x, -1.0, 1.0));
    let theta_o = asin(clamp(wo.x, -1.0, 1.0));
    let theta_h = 0.5 * (theta_i + theta_o);
    let cos_theta_d = max(cos(0.5 * (theta_i - theta_o)), 1e-3);
    let phi = abs(wrap_angle(atan2(wi.z, wi.y) - atan2(wo.z, wo.y)));
    let theta_u = min(abs(theta_i), 0.5 * PI) / (0.5 * PI);
    let forward = ds_row(0.0, theta_u);
    let backward = ds_row(1.0, theta_u);
    let spread = ds_row(2.0, theta_u);
    let sigma_f2 = n * forward.w;
    let direct = clamp(1.0 - n, 0.0, 1.0);
    let near_half = select(0.0, 1.0 / PI, phi < 0.5 * PI);
    let lobe_scale = 1.0 / (2.0 * cos_theta_d);
    let back_direct = ds_gaussian(theta_h - backward.w, spread.x) * lobe_scale * near_half;
    let back_scatter = ds_gaussian(theta_h - backward.w, spread.x + sigma_f2) * lobe_scale * near_half;
    let lobe_uv = vec2<f32>(phi / PI, theta_u);
    var f_scatter = vec3<f32>(0.0);
    for (var p = 0; p < 3; p++) {
        let g = ds_gaussian(theta_h - scene.ds_lobe_shift[p], scene.ds_lobe_variance[p] + sigma_f2) * lobe_scale;
        f_scatter += g * textureSampleLevel(ds_lobes, table_sampler, lobe_uv, p, 0.0).rgb;
    }
    let t_f = pow(max(forward.rgb, vec3<f32>(0.0)), vec3<f32>(n));
    let out = direct * (f_s + D_B * backward.rgb * back_direct)
        + max(t_f - vec3<f32>(direct), vec3<f32>(0.0)) * D_F * (f_scatter + D_B * backward.rgb * back_scatter);
    return select(vec3<f32>(0.0), out, (out < vec3<f32>(3.0e38)) & (out >= vec3<f32>(0.0)));
}
