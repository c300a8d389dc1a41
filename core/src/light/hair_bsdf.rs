//! The fibre scattering function (BCSDF) of the Marschner shading effect: R, TT, TRT and a
//! residual lobe in Chiang et al. 2016's energy-conserving form (the model of pbrt-v4's
//! `HairBxDF` and Blender's Principled Hair "Chiang"), in f64. CPU mirror of
//! `shaders/light/hair_bsdf.wgsl` (same function names: `mp`, `ap`, `np`, `hair_bsdf`), and the
//! model the reference path tracer ([`crate::light::reference_render`]) samples.
//!
//! Why this model and not Karis 2016's real-time fit: the GPU and the reference then share one
//! model, so the measured ꟻLIP error of each effect isolates what that effect approximates
//! (shadows, multiple scattering), not a model mismatch; its cost beside Kajiya-Kay is in
//! `hairloom bench effects`. It is energy conserving (tested: a non-absorbing fibre scatters
//! exactly all light), and its parameters are the ones artists know from Blender.
//!
//! Conventions (pbrt's): directions are in the fibre's frame, `x` along the tangent, `y`
//! across the fibre (the axis `h` is measured on, `h ∈ [−1, 1]` the offset of the incident
//! ray from the axis in radii), `z` the third axis (toward the viewer for a ribbon).
//! `θ = asin(x)`, `φ = atan2(z, y)`. The returned value is `f · |cos θ_n|` in pbrt's terms,
//! which we call `f_s`: reflected radiance is `∫ f_s L_i dω`, so a directional light of
//! irradiance `E` gives `f_s E`, and `∫ f_s dω` over the sphere is the scattered fraction.

use glam::DVec3;

use crate::light::material::Fibre;

/// Lobes evaluated explicitly (R, TT, TRT); the rest are one residual lobe.
pub const P_MAX: usize = 3;

/// The per-material constants of the model, computed once (the shader receives the same
/// numbers in its uniforms).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HairBsdf {
    /// Longitudinal variance per lobe (R, TT, TRT, residual).
    pub v: [f64; P_MAX + 1],
    /// Logistic scale of the azimuthal lobes.
    pub s: f64,
    /// `sin(2^k α)`, `cos(2^k α)` for k = 0, 1, 2: the cuticle tilt's rotations.
    pub sin_2k_alpha: [f64; 3],
    pub cos_2k_alpha: [f64; 3],
    pub eta: f64,
}

const SQRT_PI_OVER_8: f64 = 0.626_657_068_657_750_1;

impl HairBsdf {
    pub fn new(fibre: &Fibre) -> Self {
        let (beta_m, beta_n) = (fibre.beta_m, fibre.beta_n);
        let v0 = (0.726 * beta_m + 0.812 * beta_m.powi(2) + 3.7 * beta_m.powi(20)).powi(2);
        let mut sin_2k_alpha = [fibre.alpha_rad.sin(), 0.0, 0.0];
        let mut cos_2k_alpha = [safe_sqrt(1.0 - sin_2k_alpha[0].powi(2)), 0.0, 0.0];
        for i in 1..3 {
            sin_2k_alpha[i] = 2.0 * cos_2k_alpha[i - 1] * sin_2k_alpha[i - 1];
            cos_2k_alpha[i] = cos_2k_alpha[i - 1].powi(2) - sin_2k_alpha[i - 1].powi(2);
        }
        Self {
            v: [v0, 0.25 * v0, 4.0 * v0, 4.0 * v0],
            s: SQRT_PI_OVER_8 * (0.265 * beta_n + 1.194 * beta_n.powi(2) + 5.372 * beta_n.powi(22)),
            sin_2k_alpha,
            cos_2k_alpha,
            eta: fibre.eta,
        }
    }

    /// `(sin θ, cos θ)` of `wo` turned by lobe `p`'s cuticle tilt (R by 2α one way, TT by α
    /// and TRT by 4α the other).
    pub fn tilted(&self, p: usize, sin_theta: f64, cos_theta: f64) -> (f64, f64) {
        let (s, c) = (self.sin_2k_alpha, self.cos_2k_alpha);
        let (sin_p, cos_p) = match p {
            0 => (
                sin_theta * c[1] - cos_theta * s[1],
                cos_theta * c[1] + sin_theta * s[1],
            ),
            1 => (
                sin_theta * c[0] + cos_theta * s[0],
                cos_theta * c[0] - sin_theta * s[0],
            ),
            2 => (
                sin_theta * c[2] + cos_theta * s[2],
                cos_theta * c[2] - sin_theta * s[2],
            ),
            _ => (sin_theta, cos_theta),
        };
        (sin_p, cos_p.abs())
    }

    /// The geometry of one incident offset `h` for outgoing `wo`: `γ_o`, `γ_t` and the
    /// transmittance of one pass through the fibre.
    fn inside(&self, wo: DVec3, h: f64, sigma_a: [f64; 3]) -> Inside {
        let h = if h.is_finite() {
            h.clamp(-1.0, 1.0)
        } else {
            0.0
        };
        let sin_theta_o = wo.x.clamp(-1.0, 1.0);
        let cos_theta_o = safe_sqrt(1.0 - sin_theta_o * sin_theta_o);
        let sin_theta_t = sin_theta_o / self.eta;
        let cos_theta_t = safe_sqrt(1.0 - sin_theta_t * sin_theta_t);
        // The modified index for the azimuthal plane (Bravais); as cos θ_o → 0 it grows
        // without bound and γ_t → 0, which the max() keeps finite.
        let etap =
            safe_sqrt(self.eta * self.eta - sin_theta_o * sin_theta_o) / cos_theta_o.max(1e-12);
        let sin_gamma_t = (h / etap).clamp(-1.0, 1.0);
        let cos_gamma_t = safe_sqrt(1.0 - sin_gamma_t * sin_gamma_t);
        let path = 2.0 * cos_gamma_t / cos_theta_t.max(1e-12);
        Inside {
            sin_theta_o,
            cos_theta_o,
            gamma_o: h.asin(),
            gamma_t: sin_gamma_t.asin(),
            transmittance: sigma_a.map(|s| (-s.max(0.0) * path).exp()),
            h,
        }
    }

    /// Attenuation of each lobe, `A_p` (Chiang eq. 3-5): Fresnel at the first interface,
    /// `(1 − f)² T f^{p−1} T^{p−1}` inside, and the geometric tail of all longer paths.
    pub fn ap(&self, cos_theta_o: f64, h: f64, transmittance: [f64; 3]) -> [[f64; 3]; P_MAX + 1] {
        let cos_gamma_o = safe_sqrt(1.0 - h * h);
        let f = fr_dielectric(cos_theta_o * cos_gamma_o, self.eta);
        let mut a = [[0.0; 3]; P_MAX + 1];
        a[0] = [f; 3];
        a[1] = transmittance.map(|t| (1.0 - f).powi(2) * t);
        for p in 2..P_MAX {
            a[p] = std::array::from_fn(|c| a[p - 1][c] * transmittance[c] * f);
        }
        a[P_MAX] = std::array::from_fn(|c| {
            let tf = transmittance[c] * f;
            // 1 − T f ≥ 1 − f > 0 for η > 1: the tail never divides by zero.
            a[P_MAX - 1][c] * tf / (1.0 - tf).max(1e-12)
        });
        a
    }

    /// The scattering function `f_s(wo, wi)` at offset `h` (see the module's conventions).
    pub fn hair_bsdf(&self, wo: DVec3, wi: DVec3, h: f64, sigma_a: [f64; 3]) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for lobe in self.lobes(wo, wi, h, sigma_a) {
            for c in 0..3 {
                sum[c] += lobe[c];
            }
        }
        sum.map(|v| if v.is_finite() { v } else { 0.0 })
    }

    /// [`Self::hair_bsdf`] lobe by lobe: R, TT, TRT and the residual.
    pub fn lobes(&self, wo: DVec3, wi: DVec3, h: f64, sigma_a: [f64; 3]) -> [[f64; 3]; P_MAX + 1] {
        let inside = self.inside(wo, h, sigma_a);
        let sin_theta_i = wi.x.clamp(-1.0, 1.0);
        let cos_theta_i = safe_sqrt(1.0 - sin_theta_i * sin_theta_i);
        let phi = azimuth(wi) - azimuth(wo);
        let ap = self.ap(inside.cos_theta_o, inside.h, inside.transmittance);
        std::array::from_fn(|p| {
            let (sin_op, cos_op) = self.tilted(p, inside.sin_theta_o, inside.cos_theta_o);
            let m = mp(cos_theta_i, cos_op, sin_theta_i, sin_op, self.v[p]);
            let n = if p < P_MAX {
                np(phi, p, self.s, inside.gamma_o, inside.gamma_t)
            } else {
                1.0 / std::f64::consts::TAU
            };
            ap[p].map(|a| m * a * n)
        })
    }

    /// How often [`Self::sample`] picks each lobe: its attenuation, averaged over colour.
    fn lobe_pdf(&self, ap: &[[f64; 3]; P_MAX + 1]) -> [f64; P_MAX + 1] {
        let weights = ap.map(|a| (a[0] + a[1] + a[2]) / 3.0);
        let total: f64 = weights.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return [1.0 / (P_MAX + 1) as f64; P_MAX + 1];
        }
        weights.map(|w| w / total)
    }

    /// The density (per solid angle) with which [`Self::sample`] returns `wi`.
    pub fn pdf(&self, wo: DVec3, wi: DVec3, h: f64, sigma_a: [f64; 3]) -> f64 {
        let inside = self.inside(wo, h, sigma_a);
        let sin_theta_i = wi.x.clamp(-1.0, 1.0);
        let cos_theta_i = safe_sqrt(1.0 - sin_theta_i * sin_theta_i);
        let phi = azimuth(wi) - azimuth(wo);
        let lobe_pdf = self.lobe_pdf(&self.ap(inside.cos_theta_o, inside.h, inside.transmittance));
        let mut pdf = 0.0;
        for (p, weight) in lobe_pdf.iter().enumerate() {
            let (sin_op, cos_op) = self.tilted(p, inside.sin_theta_o, inside.cos_theta_o);
            let m = mp(cos_theta_i, cos_op, sin_theta_i, sin_op, self.v[p]);
            let n = if p < P_MAX {
                np(phi, p, self.s, inside.gamma_o, inside.gamma_t)
            } else {
                1.0 / std::f64::consts::TAU
            };
            pdf += m * weight * n;
        }
        if pdf.is_finite() { pdf } else { 0.0 }
    }

    /// Importance-samples an incident direction for `wo` from four uniform numbers in
    /// `[0, 1)`: a lobe by its attenuation, θ from its `M_p`, φ from its `N_p`. Returns the
    /// direction, `f_s` and the pdf; `None` when the sample carries nothing.
    pub fn sample(
        &self,
        wo: DVec3,
        h: f64,
        sigma_a: [f64; 3],
        u: [f64; 4],
    ) -> Option<(DVec3, [f64; 3], f64)> {
        let inside = self.inside(wo, h, sigma_a);
        let ap = self.ap(inside.cos_theta_o, inside.h, inside.transmittance);
        let lobe_pdf = self.lobe_pdf(&ap);
        let mut p = P_MAX;
        let mut rest = u[0];
        for (lobe, &weight) in lobe_pdf.iter().enumerate() {
            if rest < weight || lobe == P_MAX {
                p = lobe;
                break;
            }
            rest -= weight;
        }
        let (sin_op, cos_op) = self.tilted(p, inside.sin_theta_o, inside.cos_theta_o);
        // θ from M_p (d'Eon et al. 2013's sampling of the von Mises-Fisher-like lobe).
        let v = self.v[p];
        let u1 = u[1].max(1e-5);
        let cos_theta = 1.0 + v * (u1 + (1.0 - u1) * (-2.0 / v).exp()).ln();
        let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
        let cos_phi_m = (std::f64::consts::TAU * u[2]).cos();
        let sin_theta_i = (-cos_theta * sin_op + sin_theta * cos_phi_m * cos_op).clamp(-1.0, 1.0);
        let cos_theta_i = safe_sqrt(1.0 - sin_theta_i * sin_theta_i);
        let dphi = if p < P_MAX {
            phi(p, inside.gamma_o, inside.gamma_t)
                + sample_trimmed_logistic(u[3], self.s, -std::f64::consts::PI, std::f64::consts::PI)
        } else {
            std::f64::consts::TAU * u[3]
        };
        let phi_i = azimuth(wo) + dphi;
        let wi = DVec3::new(
            sin_theta_i,
            cos_theta_i * phi_i.cos(),
            cos_theta_i * phi_i.sin(),
        );
        let pdf = self.pdf(wo, wi, h, sigma_a);
        let f = self.hair_bsdf(wo, wi, h, sigma_a);
        (pdf > 0.0 && wi.is_finite()).then_some((wi, f, pdf))
    }
}

struct Inside {
    sin_theta_o: f64,
    cos_theta_o: f64,
    gamma_o: f64,
    gamma_t: f64,
    transmittance: [f64; 3],
    h: f64,
}

/// `atan2(z, y)`: the azimuth around the fibre.
pub fn azimuth(w: DVec3) -> f64 {
    w.z.atan2(w.y)
}

pub(crate) fn safe_sqrt(x: f64) -> f64 {
    x.max(0.0).sqrt()
}

/// The modified Bessel function of the first kind, order 0 (ten terms of its series).
pub fn i0(x: f64) -> f64 {
    let (mut value, mut x2i, mut factorial, mut four_i) = (0.0, 1.0, 1.0, 1.0);
    for i in 0..10 {
        if i > 1 {
            factorial *= i as f64;
        }
        value += x2i / (four_i * factorial * factorial);
        x2i *= x * x;
        four_i *= 4.0;
    }
    value
}

/// `ln I₀(x)`, with the asymptotic form above 12 where the series would overflow.
pub(crate) fn log_i0(x: f64) -> f64 {
    if x > 12.0 {
        x + 0.5 * (-(std::f64::consts::TAU).ln() + (1.0 / x).ln() + 1.0 / (8.0 * x))
    } else {
        i0(x).ln()
    }
}

/// The longitudinal lobe `M_p` (d'Eon et al. 2011), normalised so that
/// `∫ M_p cos θ_i dθ_i = 1`; the log form keeps narrow lobes (`v ≤ 0.1`) finite.
pub(crate) fn mp(
    cos_theta_i: f64,
    cos_theta_o: f64,
    sin_theta_i: f64,
    sin_theta_o: f64,
    v: f64,
) -> f64 {
    let a = cos_theta_i * cos_theta_o / v;
    let b = sin_theta_i * sin_theta_o / v;
    let m = if v <= 0.1 {
        (log_i0(a) - b - 1.0 / v + std::f64::consts::LN_2 + (1.0 / (2.0 * v)).ln()).exp()
    } else {
        (-b).exp() * i0(a) / ((1.0 / v).sinh() * 2.0 * v)
    };
    if m.is_finite() { m } else { 0.0 }
}

/// Unpolarised Fresnel reflectance of a dielectric of relative index `eta`.
pub(crate) fn fr_dielectric(cos_theta_i: f64, eta: f64) -> f64 {
    let mut cos_i = cos_theta_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = safe_sqrt(1.0 - sin2_t);
    let parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (parallel * parallel + perpendicular * perpendicular) / 2.0
}

/// The azimuthal direction lobe `p` leaves in: `Φ = 2p γ_t − 2γ_o + pπ`.
pub fn phi(p: usize, gamma_o: f64, gamma_t: f64) -> f64 {
    let p = p as f64;
    2.0 * p * gamma_t - 2.0 * gamma_o + p * std::f64::consts::PI
}

pub(crate) fn logistic(x: f64, s: f64) -> f64 {
    let x = x.abs();
    let e = (-x / s).exp();
    e / (s * (1.0 + e) * (1.0 + e))
}

pub(crate) fn logistic_cdf(x: f64, s: f64) -> f64 {
    1.0 / (1.0 + (-x / s).exp())
}

/// The logistic restricted to `[a, b]` and normalised there.
pub(crate) fn trimmed_logistic(x: f64, s: f64, a: f64, b: f64) -> f64 {
    logistic(x, s) / (logistic_cdf(b, s) - logistic_cdf(a, s))
}

pub(crate) fn sample_trimmed_logistic(u: f64, s: f64, a: f64, b: f64) -> f64 {
    let k = logistic_cdf(b, s) - logistic_cdf(a, s);
    let x = -s * (1.0 / (u * k + logistic_cdf(a, s)) - 1.0).ln();
    if x.is_finite() { x.clamp(a, b) } else { 0.0 }
}

/// Wraps an angle into `[−π, π]`.
pub(crate) fn wrap_angle(mut x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    if !x.is_finite() {
        return 0.0;
    }
    x = x.rem_euclid(TAU);
    if x > PI { x - TAU } else { x }
}

/// The azimuthal lobe `N_p`: a trimmed logistic around `Φ(p)`.
pub(crate) fn np(phi_diff: f64, p: usize, s: f64, gamma_o: f64, gamma_t: f64) -> f64 {
    use std::f64::consts::PI;
    let dphi = wrap_angle(phi_diff - phi(p, gamma_o, gamma_t));
    trimmed_logistic(dphi, s, -PI, PI)
}

/// A direction in the fibre frame from `θ` (from the normal plane toward the tangent) and `φ`.
pub fn direction(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin(),
        theta.cos() * phi.cos(),
        theta.cos() * phi.sin(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::scene::HairMaterial;

    fn bsdf(beta_m: f32, beta_n: f32, alpha_deg: f32) -> HairBsdf {
        HairBsdf::new(&Fibre::new(&HairMaterial {
            longitudinal_roughness: beta_m,
            azimuthal_roughness: beta_n,
            cuticle_tilt_deg: alpha_deg,
            ..HairMaterial::default()
        }))
    }

    /// `∫ f_s dω` over the sphere by a midpoint rule in (θ, φ), `dω = cos θ dθ dφ`.
    fn scattered(b: &HairBsdf, wo: DVec3, h: f64, sigma_a: [f64; 3], steps: usize) -> [f64; 3] {
        use std::f64::consts::{FRAC_PI_2, PI, TAU};
        let mut total = [0.0; 3];
        let (dt, dp) = (PI / steps as f64, TAU / (2 * steps) as f64);
        for i in 0..steps {
            let theta = -FRAC_PI_2 + (i as f64 + 0.5) * dt;
            for j in 0..2 * steps {
                let phi = -PI + (j as f64 + 0.5) * dp;
                let f = b.hair_bsdf(wo, direction(theta, phi), h, sigma_a);
                for c in 0..3 {
                    total[c] += f[c] * theta.cos() * dt * dp;
                }
            }
        }
        total
    }

    #[test]
    fn lobes_conserve_energy_for_every_roughness() {
        // A non-absorbing fibre scatters all light (the white furnace); an absorbing one
        // less. Quadrature over the sphere for roughness where a 400 × 800 grid resolves the
        // lobes; narrower lobes are checked by importance sampling below.
        for beta in [0.15, 0.3, 0.6, 1.0] {
            for (beta_m, beta_n) in [(beta, beta), (beta, 0.3), (0.3, beta)] {
                let b = bsdf(beta_m, beta_n, 2.0);
                for theta_o in [-1.2, 0.0, 0.7, 1.4] {
                    for h in [-0.9, 0.5] {
                        let wo = direction(theta_o, 0.3);
                        let white = scattered(&b, wo, h, [0.0; 3], 300);
                        assert!(
                            (white[0] - 1.0).abs() < 0.02,
                            "β ({beta_m}, {beta_n}) θ_o {theta_o} h {h}: white furnace {white:?}"
                        );
                        let brown = scattered(&b, wo, h, [0.4, 0.8, 1.6], 120);
                        assert!(
                            brown.iter().all(|&e| e <= white[0] + 1e-9 && e > 0.0),
                            "{brown:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn importance_sampling_matches_the_function_and_keeps_energy_at_low_roughness() {
        // E[f_s / pdf] = ∫ f_s dω: 1 for a white fibre at any roughness, including the
        // narrowest lobes quadrature cannot resolve.
        let mut state = 0x853c_49e6_748f_ea9b_u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64) / (1u64 << 53) as f64
        };
        for beta in [0.02f32, 0.05, 0.3, 0.9] {
            let b = bsdf(beta, beta, 3.0);
            for theta_o in [-1.0, 0.0, 0.8] {
                let wo = direction(theta_o, 1.1);
                let n = 20_000;
                let mut sum = 0.0;
                for _ in 0..n {
                    let h = 2.0 * uniform() - 1.0;
                    let u = [uniform(), uniform(), uniform(), uniform()];
                    if let Some((wi, f, pdf)) = b.sample(wo, h, [0.0; 3], u) {
                        assert!((wi.length() - 1.0).abs() < 1e-9);
                        let again = b.pdf(wo, wi, h, [0.0; 3]);
                        assert!(
                            (again - pdf).abs() <= 1e-9 * pdf.max(1.0),
                            "{again} vs {pdf}"
                        );
                        sum += f[0] / pdf;
                    }
                }
                let estimate = sum / n as f64;
                assert!(
                    (estimate - 1.0).abs() < 0.05,
                    "β {beta} θ_o {theta_o}: ∫ f_s = {estimate}"
                );
            }
        }
    }

    #[test]
    fn degenerate_angles_and_roughness_stay_finite() {
        // β → 0 (clamped to the model's minimum), α = 0, light along the tangent, grazing
        // and exactly opposite directions, h at ±1 and out of range, NaN h.
        for (beta_m, beta_n, alpha) in [(0.0, 0.0, 0.0), (1.0, 1.0, 20.0), (0.0, 1.0, -20.0)] {
            let b = bsdf(beta_m, beta_n, alpha);
            let tangent = DVec3::X;
            let directions = [
                tangent,
                -tangent,
                DVec3::Y,
                DVec3::Z,
                -DVec3::Z,
                direction(std::f64::consts::FRAC_PI_2, 0.0),
                direction(-std::f64::consts::FRAC_PI_2, 2.0),
            ];
            for &wo in &directions {
                for &wi in &directions {
                    for h in [-1.0, -0.999, 0.0, 1.0, 1.5, f64::NAN] {
                        for sigma_a in [[0.0; 3], [0.4, 0.8, 1.6], [1e3; 3]] {
                            let f = b.hair_bsdf(wo, wi, h, sigma_a);
                            assert!(f.iter().all(|v| v.is_finite() && *v >= 0.0), "{f:?}");
                            assert!(b.pdf(wo, wi, h, sigma_a).is_finite());
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_primary_highlight_is_shifted_by_twice_the_cuticle_tilt() {
        // The cuticle tilt shifts R: with light from θ_i the reflection peaks at
        // θ_o ≈ −θ_i + 2α, not at the mirror angle.
        let b = bsdf(0.1, 0.3, 4.0);
        let wi = direction(0.5, 0.0);
        let r_only = |theta_o: f64| {
            // Sum over h of the lobe the direction sees; R dominates near the mirror.
            (0..21)
                .map(|k| {
                    b.hair_bsdf(
                        direction(theta_o, 0.0),
                        wi,
                        -1.0 + 0.1 * k as f64,
                        [50.0; 3],
                    )[0]
                })
                .sum::<f64>()
        };
        let best = (0..200)
            .map(|k| -1.0 + 0.01 * k as f64)
            .max_by(|a, b| r_only(*a).total_cmp(&r_only(*b)))
            .expect("angles");
        let expected = -0.5 + 2.0 * 4f64.to_radians();
        assert!(
            (best - expected).abs() < 0.03,
            "peak at {best}, expected {expected}"
        );
    }
}
