//! Dual scattering (Zinke et al. 2008): multiple scattering between fibres as a global
//! forward-scattering term (light that reached a point through `n` fibres, from the opacity
//! maps) and a local back-scattering term (light returned by the fibres around the point),
//! from tables precomputed once per material. CPU mirror of `shaders/light/dual_scattering.wgsl`
//! (same names: `dual_scattering`, `ds_gaussian`), and the tables the renderer uploads.
//!
//! Our reading of the paper, in the measure of [`crate::light::hair_bsdf`] (`∫ f_s dω` is the
//! scattered fraction) and with every angle of the longitudinal lobes in `θ_h = (θ_i + θ_o)/2`:
//! - averages over the incident offset `h` of Chiang's lobes give the forward and backward
//!   attenuations `a_f(θ)`, `a_b(θ)` (light leaving into the far / near azimuthal half), the
//!   lobes' mean shifts `α_f`, `α_b` and variances `β_f²`, `β_b²`, weighted by energy;
//! - back scattering `A_b = A₁ + A₃`, its shift `Δ_b` and spread `σ_b²` follow the paper's
//!   eq. 12-16;
//! - after `n` fibres: `T_f = a_f(θ_i)^n`, `σ_f² = n β_f²`; the light arriving that way is
//!   spread uniformly over the half circle facing the light, so each lobe `p`'s azimuthal
//!   response is the table `N_G,p(θ, φ) = avg_h A_p · (1/π) ∫_{−π/2}^{π/2} N_p(φ + δ) dδ`;
//! - `F = d · (f_s + d_b f_back) + max(T_f − d, 0) · d_f · (f_s^G + d_b f_back^G)` with `d` the
//!   direct fraction `clamp(1 − n, 0, 1)`, each longitudinal lobe a Gaussian in `θ_h` over
//!   `2 cos θ_d` (so that it integrates to 1 against `cos θ_i dθ_i`), and `f_back` spread
//!   uniformly over the near half circle. `d_f = d_b = 0.7`, the paper's density factors.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use crate::light::hair_bsdf::{
    HairBsdf, P_MAX, azimuth, direction, logistic_cdf, phi as lobe_phi, wrap_angle,
};
use crate::light::material::Fibre;

/// Samples of `|θ_i|` over `[0, π/2]` (texel centres).
pub const THETA_COUNT: usize = 32;
/// Samples of `|φ|` over `[0, π]` (texel centres).
pub const PHI_COUNT: usize = 32;
/// Density factors of forward and backward scattering (Zinke et al. 2008).
pub const D_F: f64 = 0.7;
pub const D_B: f64 = 0.7;

/// Incident offsets averaged over (midpoints of `[−1, 1]`).
pub(crate) const H_SAMPLES: usize = 48;

/// The precomputed tables of one material.
#[derive(Clone, Debug, PartialEq)]
pub struct DualScatteringTables {
    /// Per `|θ_i|` sample: forward attenuation `a_f` (rgb) and variance `β_f²`.
    pub forward: Vec<[f32; 4]>,
    /// Per `|θ_i|` sample: back scattering `A_b` (rgb) and its shift `Δ_b`.
    pub backward: Vec<[f32; 4]>,
    /// Per `|θ_i|` sample: `σ_b²`, `a_b` averaged over colour, and two zeros.
    pub spread: Vec<[f32; 4]>,
    /// Per lobe `p < P_MAX`, row `θ`, column `|φ|`: `N_G,p` (rgb, attenuation included), 0.
    pub lobes: Vec<[f32; 4]>,
    /// Each lobe's shift and variance in `θ_h` (R, TT, TRT).
    pub lobe_shift: [f32; 3],
    pub lobe_variance: [f32; 3],
    /// `a_f` averaged over `θ` (rgb): forward transmittance per fibre for shadows without
    /// dual scattering.
    pub mean_forward: [f32; 3],
}

impl DualScatteringTables {
    /// Integrates the tables for `fibre` at its mean absorption.
    pub fn new(fibre: &Fibre) -> Self {
        let bsdf = HairBsdf::new(fibre);
        let sigma_a = fibre.sigma_a_mean();
        // Lobe centres and widths in θ_h (see `HairBsdf::tilted`: R peaks at θ_h = α, TT at
        // −α/2, TRT at −2α); M_p's variance v_p is in θ_i, a quarter of it in θ_h.
        let alpha = fibre.alpha_rad;
        let lobe_shift = [alpha, -alpha / 2.0, -2.0 * alpha];
        let lobe_variance: [f64; 3] = std::array::from_fn(|p| bsdf.v[p] / 4.0);
        let mut forward = Vec::with_capacity(THETA_COUNT);
        let mut backward = Vec::with_capacity(THETA_COUNT);
        let mut spread = Vec::with_capacity(THETA_COUNT);
        let mut lobes = vec![[0.0f32; 4]; P_MAX * THETA_COUNT * PHI_COUNT];
        let mut mean_forward = [0.0; 3];
        for t in 0..THETA_COUNT {
            let theta = (t as f64 + 0.5) / THETA_COUNT as f64 * FRAC_PI_2;
            let light = direction(theta, 0.0);
            let (mut a_f, mut a_b) = ([0.0; 3], [0.0; 3]);
            // Energy-weighted shift and variance of forward and backward scattering.
            let (mut weight_f, mut weight_b) = (0.0, 0.0);
            let (mut shift_f, mut shift_b, mut var_f, mut var_b) = (0.0, 0.0, 0.0, 0.0);
            let mut lobe_rows = vec![[0.0f64; 3]; P_MAX * PHI_COUNT];
            for k in 0..H_SAMPLES {
                let h = -1.0 + (k as f64 + 0.5) * 2.0 / H_SAMPLES as f64;
                let inside = gamma(&bsdf, light, h);
                let transmittance = sigma_a.map(|s| (-s * inside.path).exp());
                let ap = bsdf.ap(light.x.asin().cos(), h, transmittance);
                for (p, a) in ap.iter().enumerate() {
                    // Fraction of lobe p leaving into the far half (|φ| > π/2).
                    let far = if p < P_MAX {
                        np_integral(
                            FRAC_PI_2,
                            1.5 * PI,
                            p,
                            bsdf.s,
                            inside.gamma_o,
                            inside.gamma_t,
                        )
                    } else {
                        0.5
                    };
                    let mean_a = (a[0] + a[1] + a[2]) / 3.0;
                    for c in 0..3 {
                        a_f[c] += a[c] * far / H_SAMPLES as f64;
                        a_b[c] += a[c] * (1.0 - far) / H_SAMPLES as f64;
                    }
                    if p < P_MAX {
                        let (wf, wb) = (mean_a * far, mean_a * (1.0 - far));
                        weight_f += wf;
                        weight_b += wb;
                        shift_f += wf * lobe_shift[p];
                        shift_b += wb * lobe_shift[p];
                        var_f += wf * lobe_variance[p];
                        var_b += wb * lobe_variance[p];
                    }
                }
                // N_G,p: the lobe convolved with incidence spread over the near half circle.
                for p in 0..P_MAX {
                    for j in 0..PHI_COUNT {
                        let phi = (j as f64 + 0.5) / PHI_COUNT as f64 * PI;
                        let spread_sum = np_integral(
                            phi - FRAC_PI_2,
                            phi + FRAC_PI_2,
                            p,
                            bsdf.s,
                            inside.gamma_o,
                            inside.gamma_t,
                        ) / PI;
                        for c in 0..3 {
                            lobe_rows[p * PHI_COUNT + j][c] +=
                                ap[p][c] * spread_sum / H_SAMPLES as f64;
                        }
                    }
                }
            }
            let mean = |w: f64, sum: f64| if w > 0.0 { sum / w } else { 0.0 };
            let (alpha_f, alpha_b) = (mean(weight_f, shift_f), mean(weight_b, shift_b));
            let (beta_f2, beta_b2) = (mean(weight_f, var_f), mean(weight_b, var_b));
            let big_a_b = a_f
                .iter()
                .zip(&a_b)
                .map(|(&f, &b)| back_scattering(f, b))
                .collect::<Vec<_>>();
            let (af, ab) = (
                (a_f[0] + a_f[1] + a_f[2]) / 3.0,
                (a_b[0] + a_b[1] + a_b[2]) / 3.0,
            );
            let (delta_b, sigma_b2) =
                back_shift_and_spread(af, ab, alpha_f, alpha_b, beta_f2, beta_b2);
            forward.push([a_f[0] as f32, a_f[1] as f32, a_f[2] as f32, beta_f2 as f32]);
            backward.push([
                big_a_b[0] as f32,
                big_a_b[1] as f32,
                big_a_b[2] as f32,
                delta_b as f32,
            ]);
            spread.push([sigma_b2 as f32, ab as f32, 0.0, 0.0]);
            for p in 0..P_MAX {
                for j in 0..PHI_COUNT {
                    let v = lobe_rows[p * PHI_COUNT + j];
                    lobes[(p * THETA_COUNT + t) * PHI_COUNT + j] =
                        [v[0] as f32, v[1] as f32, v[2] as f32, 0.0];
                }
            }
            for c in 0..3 {
                mean_forward[c] += a_f[c] / THETA_COUNT as f64;
            }
        }
        Self {
            forward,
            backward,
            spread,
            lobes,
            lobe_shift: lobe_shift.map(|v| v as f32),
            lobe_variance: lobe_variance.map(|v| v as f32),
            mean_forward: mean_forward.map(|v| v as f32),
        }
    }

    /// A row of a 1-D table at `|θ_i|`, linearly interpolated between texel centres (what the
    /// GPU's filtered sample returns).
    pub fn profile(table: &[[f32; 4]], theta: f64) -> [f64; 4] {
        let x = (theta.abs().min(FRAC_PI_2) / FRAC_PI_2) * table.len() as f64 - 0.5;
        let lo = x.floor().clamp(0.0, (table.len() - 1) as f64) as usize;
        let hi = (lo + 1).min(table.len() - 1);
        let t = (x - lo as f64).clamp(0.0, 1.0);
        std::array::from_fn(|c| table[lo][c] as f64 * (1.0 - t) + table[hi][c] as f64 * t)
    }

    /// `N_G,p` at `(|θ_i|, |φ|)`, bilinearly interpolated between texel centres.
    pub fn lobe(&self, p: usize, theta: f64, phi: f64) -> [f64; 3] {
        bilinear_lobe(&self.lobes, p, theta, phi)
    }

    /// The dual-scattering response `F` (the shader's `dual_scattering`): directions in the
    /// fibre frame, `f_s` the single-scattering value at this fragment (from
    /// [`HairBsdf::hair_bsdf`]), `n` the fibres between the point and the light.
    pub fn dual_scattering(&self, wo: DVec3, wi: DVec3, f_s: [f64; 3], n: f64) -> [f64; 3] {
        let n = if n.is_finite() { n.max(0.0) } else { 0.0 };
        let theta_i = wi.x.clamp(-1.0, 1.0).asin();
        let theta_o = wo.x.clamp(-1.0, 1.0).asin();
        let theta_h = 0.5 * (theta_i + theta_o);
        let cos_theta_d = (0.5 * (theta_i - theta_o)).cos().max(1e-3);
        let phi = wrap_angle(azimuth(wi) - azimuth(wo)).abs();
        let forward = Self::profile(&self.forward, theta_i);
        let backward = Self::profile(&self.backward, theta_i);
        let spread = Self::profile(&self.spread, theta_i);
        let sigma_f2 = n * forward[3];
        let direct = (1.0 - n).clamp(0.0, 1.0);
        let near_half = if phi < FRAC_PI_2 { 1.0 / PI } else { 0.0 };
        let lobe = |x: f64, variance: f64| ds_gaussian(x, variance) / (2.0 * cos_theta_d);
        let back_direct = lobe(theta_h - backward[3], spread[0]) * near_half;
        let back_scatter = lobe(theta_h - backward[3], spread[0] + sigma_f2) * near_half;
        let mut out = [0.0; 3];
        for c in 0..3 {
            let t_f = forward[c].max(0.0).powf(n);
            let mut f_scatter = 0.0;
            for p in 0..P_MAX {
                f_scatter += lobe(
                    theta_h - self.lobe_shift[p] as f64,
                    self.lobe_variance[p] as f64 + sigma_f2,
                ) * self.lobe(p, theta_i, phi)[c];
            }
            out[c] = direct * (f_s[c] + D_B * backward[c] * back_direct)
                + (t_f - direct).max(0.0) * D_F * (f_scatter + D_B * backward[c] * back_scatter);
        }
        out.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 })
    }
}

/// Lobe layer `p` of a `P_MAX × THETA_COUNT × PHI_COUNT` table at `(|θ_i|, |φ|)`, bilinearly
/// interpolated between texel centres (what the GPU's filtered sample returns, and what the
/// aggregated model's manual lookup computes).
pub(crate) fn bilinear_lobe(lobes: &[[f32; 4]], p: usize, theta: f64, phi: f64) -> [f64; 3] {
    let coordinate = |value: f64, range: f64, count: usize| {
        let x = (value.abs().min(range) / range) * count as f64 - 0.5;
        let lo = x.floor().clamp(0.0, (count - 1) as f64) as usize;
        (lo, (lo + 1).min(count - 1), (x - lo as f64).clamp(0.0, 1.0))
    };
    let (t0, t1, tt) = coordinate(theta, FRAC_PI_2, THETA_COUNT);
    let (p0, p1, pt) = coordinate(phi, PI, PHI_COUNT);
    let at = |t: usize, j: usize| lobes[(p * THETA_COUNT + t) * PHI_COUNT + j];
    std::array::from_fn(|c| {
        let a = at(t0, p0)[c] as f64 * (1.0 - pt) + at(t0, p1)[c] as f64 * pt;
        let b = at(t1, p0)[c] as f64 * (1.0 - pt) + at(t1, p1)[c] as f64 * pt;
        a * (1.0 - tt) + b * tt
    })
}

/// `∫_a^b N_p(φ) dφ` for an interval no longer than a turn, exactly: `N_p` is a trimmed
/// logistic on the circle, so the integral is a difference of its cumulative distribution
/// (wrapped once when the interval crosses ±π).
pub(crate) fn np_integral(a: f64, b: f64, p: usize, s: f64, gamma_o: f64, gamma_t: f64) -> f64 {
    let length = (b - a).clamp(0.0, 2.0 * PI);
    let cdf_lo = logistic_cdf(-PI, s);
    let k = logistic_cdf(PI, s) - cdf_lo;
    let cumulative = |x: f64| ((logistic_cdf(x, s) - cdf_lo) / k).clamp(0.0, 1.0);
    let start = wrap_angle(a - lobe_phi(p, gamma_o, gamma_t));
    let end = start + length;
    let integral = if end <= PI {
        cumulative(end) - cumulative(start)
    } else {
        (1.0 - cumulative(start)) + cumulative(end - 2.0 * PI)
    };
    if integral.is_finite() {
        integral.max(0.0)
    } else {
        0.0
    }
}

/// A normalised Gaussian of variance `variance` at `x` (the variance is kept above a floor so
/// that a lobe of zero width stays finite).
pub(crate) fn ds_gaussian(x: f64, variance: f64) -> f64 {
    let variance = variance.max(1e-6);
    (-x * x / (2.0 * variance)).exp() / (2.0 * PI * variance).sqrt()
}

pub(crate) struct Gamma {
    pub(crate) gamma_o: f64,
    pub(crate) gamma_t: f64,
    /// Path length through the fibre in radii (`2 cos γ_t / cos θ_t`).
    pub(crate) path: f64,
}

pub(crate) fn gamma(bsdf: &HairBsdf, w: DVec3, h: f64) -> Gamma {
    let sin_theta = w.x;
    let cos_theta = (1.0 - sin_theta * sin_theta).max(0.0).sqrt();
    let sin_theta_t = sin_theta / bsdf.eta;
    let cos_theta_t = (1.0 - sin_theta_t * sin_theta_t).max(0.0).sqrt();
    let etap = (bsdf.eta * bsdf.eta - sin_theta * sin_theta)
        .max(0.0)
        .sqrt()
        / cos_theta.max(1e-12);
    let sin_gamma_t = (h / etap).clamp(-1.0, 1.0);
    Gamma {
        gamma_o: h.asin(),
        gamma_t: sin_gamma_t.asin(),
        path: 2.0 * (1.0 - sin_gamma_t * sin_gamma_t).max(0.0).sqrt() / cos_theta_t.max(1e-12),
    }
}

/// `A_b = A₁ + A₃` (Zinke et al. 2008 eq. 12-13): light returned after one or three backward
/// scatterings among forward ones.
pub(crate) fn back_scattering(a_f: f64, a_b: f64) -> f64 {
    let one_minus = (1.0 - a_f * a_f).max(1e-6);
    let a1 = a_b * a_f * a_f / one_minus;
    let a3 = a_b.powi(3) * a_f * a_f / one_minus.powi(3);
    let total = a1 + a3;
    if total.is_finite() { total } else { 0.0 }
}

/// The shift `Δ_b` and variance `σ_b²` of back scattering (Zinke et al. 2008 eq. 14-16).
pub(crate) fn back_shift_and_spread(
    a_f: f64,
    a_b: f64,
    alpha_f: f64,
    alpha_b: f64,
    beta_f2: f64,
    beta_b2: f64,
) -> (f64, f64) {
    let one_minus = (1.0 - a_f * a_f).max(1e-6);
    let delta = alpha_b * (1.0 - 2.0 * a_b * a_b / one_minus.powi(2))
        + alpha_f * (2.0 * one_minus.powi(2) + 4.0 * a_f * a_f * a_b * a_b) / one_minus.powi(3);
    let (beta_f, beta_b) = (beta_f2.max(0.0).sqrt(), beta_b2.max(0.0).sqrt());
    let denominator = a_b + a_b.powi(3) * (2.0 * beta_f + 3.0 * beta_b);
    let sigma = if denominator > 1e-12 {
        (1.0 + D_B * a_f * a_f)
            * (a_b * (2.0 * beta_f2 + beta_b2).sqrt()
                + a_b.powi(3) * (2.0 * beta_f2 + 3.0 * beta_b2).sqrt())
            / denominator
    } else {
        beta_b
    };
    let delta = if delta.is_finite() {
        delta.clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let sigma = if sigma.is_finite() {
        sigma.clamp(1e-3, 1.0)
    } else {
        0.1
    };
    (delta, sigma * sigma)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::scene::{HairMaterial, Pigment};

    fn tables(material: HairMaterial) -> DualScatteringTables {
        DualScatteringTables::new(&Fibre::new(&material))
    }

    #[test]
    fn the_exact_lobe_integral_matches_quadrature() {
        use crate::light::hair_bsdf::np;
        for (s, gamma_o, gamma_t) in [(0.05, 0.3, 0.2), (0.4, -1.2, 0.7), (2.0, 1.5, -0.6)] {
            for p in 0..P_MAX {
                for (a, b) in [
                    (-PI, PI),
                    (FRAC_PI_2, 1.5 * PI),
                    (-2.0, 0.5),
                    (2.5, 4.0),
                    (-4.0, -3.0),
                ] {
                    let steps = 20_000;
                    let dx = (b - a) / steps as f64;
                    let quadrature: f64 = (0..steps)
                        .map(|i| np(a + (i as f64 + 0.5) * dx, p, s, gamma_o, gamma_t) * dx)
                        .sum();
                    let exact = np_integral(a, b, p, s, gamma_o, gamma_t);
                    assert!(
                        (exact - quadrature).abs() < 1e-4,
                        "p {p} [{a}, {b}]: {exact} vs {quadrature}"
                    );
                }
            }
        }
    }

    #[test]
    fn attenuations_split_the_scattered_light_and_absorbing_fibres_pass_less() {
        let white = tables(HairMaterial {
            pigment: Pigment::Absorption { sigma_a: [0.0; 3] },
            tip_absorption_factor: 1.0,
            ..HairMaterial::default()
        });
        for t in 0..THETA_COUNT {
            let [f, ..] = white.forward[t];
            let grazing = t >= THETA_COUNT * 2 / 3;
            let [_, b, ..] = white.spread[t];
            // A non-absorbing fibre scatters everything, into one half or the other (the
            // midpoint rule over h and φ costs about a percent).
            assert!(((f + b) - 1.0).abs() < 0.02, "θ {t}: a_f {f} + a_b {b}");
            // Away from grazing light (where Fresnel reflection takes over), TT carries most.
            assert!(
                grazing || f > 2.0 * b,
                "θ {t}: a clear fibre scatters forward: {f} {b}"
            );
        }
        let brown = tables(HairMaterial::default());
        let black = tables(HairMaterial {
            pigment: Pigment::Melanin {
                eumelanin: 8.0,
                pheomelanin: 0.0,
            },
            ..HairMaterial::default()
        });
        for c in 0..3 {
            assert!(black.mean_forward[c] < brown.mean_forward[c]);
            assert!(brown.mean_forward[c] < white.mean_forward[c]);
        }
        // Brown passes red more than blue.
        assert!(brown.mean_forward[0] > brown.mean_forward[2]);
    }

    #[test]
    fn tables_and_response_stay_finite_at_the_limits() {
        for (beta, alpha, sigma) in [(0.0, 0.0, 0.0), (1.0, 20.0, 1e3), (0.02, -20.0, 0.5)] {
            let t = tables(HairMaterial {
                pigment: Pigment::Absorption {
                    sigma_a: [sigma; 3],
                },
                longitudinal_roughness: beta,
                azimuthal_roughness: beta,
                cuticle_tilt_deg: alpha,
                ..HairMaterial::default()
            });
            let all = t
                .forward
                .iter()
                .chain(&t.backward)
                .chain(&t.spread)
                .chain(&t.lobes);
            for row in all {
                assert!(row.iter().all(|v| v.is_finite()), "{row:?}");
            }
            for n in [0.0, 0.3, 1.0, 7.5, 1e6, f64::NAN, -1.0] {
                for (wo, wi) in [
                    (direction(0.2, 1.0), direction(-0.4, 0.0)),
                    (DVec3::X, DVec3::X),
                    (direction(0.0, 0.0), direction(0.0, PI)),
                ] {
                    let out = t.dual_scattering(wo, wi, [0.1; 3], n);
                    assert!(out.iter().all(|v| v.is_finite() && *v >= 0.0), "{out:?}");
                }
            }
        }
    }

    #[test]
    fn light_behind_more_fibres_arrives_dimmer_and_direct_light_is_single_scattering_plus_local() {
        let t = tables(HairMaterial::default());
        let (wo, wi) = (direction(0.1, 0.4), direction(-0.3, 0.0));
        let single = [0.2, 0.1, 0.05];
        let direct = t.dual_scattering(wo, wi, single, 0.0);
        for c in 0..3 {
            assert!(direct[c] >= single[c], "local back scattering only adds");
        }
        let mut previous = direct;
        for n in [1.0, 2.0, 4.0, 8.0, 16.0] {
            let deeper = t.dual_scattering(wo, wi, single, n);
            assert!(deeper[0] < previous[0], "n {n}: {deeper:?} vs {previous:?}");
            previous = deeper;
        }
    }
}
