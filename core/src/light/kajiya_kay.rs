//! Kajiya & Kay 1989's fibre shading, the cheap shading effect: a diffuse lobe `sin(T, L)`, a
//! white primary highlight `sin(T, H)^80` and a tinted secondary one `sin(T, H)^20`, in the
//! fibre frame of [`crate::light::hair_bsdf`] (`x` is the tangent). CPU mirror of
//! `shaders/light/kajiya_kay.wgsl` (same name: `kajiya_kay`).
//!
//! Kajiya-Kay is not a scattering model: its lobes' sizes are free. Left at hand-picked
//! constants it showed a material several times brighter and more orange than the Marschner
//! model does (issue "Hair that looks real up close"), so a scene switched between the two
//! changed the hair's colour, not just its shading. Here its weights are chosen per material
//! ([`KajiyaKayWeights::matching`]) so that, averaged over every view and light direction, it
//! scatters what the Marschner fibre ([`HairBsdf`], single scattering, averaged over the
//! offset `h`) scatters: its primary highlight carries the R lobe's energy (white, from
//! Fresnel) and its tinted lobes carry TT, TRT and the longer paths (coloured by absorption).
//! Averaged over the sphere each Marschner lobe integrates to its attenuation `A_p`
//! (`∫ M_p N_p dω = 1`), so the match needs only `A_p` over the view's inclination and `h`.

use std::f64::consts::{FRAC_PI_4, PI};
use std::sync::OnceLock;

use glam::DVec3;

use crate::light::hair_bsdf::{HairBsdf, P_MAX};
use crate::light::material::Fibre;

/// The diffuse lobe's weight against the tinted secondary highlight's (the tint scales both).
pub const DIFFUSE_WEIGHT: f64 = 0.35;
pub const SECONDARY_WEIGHT: f64 = 0.25;
pub const PRIMARY_EXPONENT: i32 = 80;
pub const SECONDARY_EXPONENT: i32 = 20;

/// The per-material weights the shader receives (`scene.kajiya_kay`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KajiyaKayWeights {
    /// Multiplies the hair's colour in the diffuse and secondary lobes.
    pub tint: [f64; 3],
    /// The white primary highlight's weight.
    pub primary: f64,
}

/// The lobes' means over every pair of directions (wo, wi) on the sphere: diffuse `sin(T, L)`,
/// primary `sin(T, H)^80`, secondary `sin(T, H)^20`. They depend on nothing but the exponents,
/// so they are integrated once per process.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeMeans {
    pub diffuse: f64,
    pub primary: f64,
    pub secondary: f64,
}

/// The lobes `(diffuse, primary, secondary)` before weights, for unit `wo`, `wi` in the fibre
/// frame (`x` along the tangent). A view straight into the light (`wo = −wi`, within
/// `|wo + wi|² ≤ 1e-12`) has no half vector: the highlights are then 0.
pub fn lobes(wo: DVec3, wi: DVec3) -> (f64, f64, f64) {
    let diffuse = (1.0 - wi.x * wi.x).max(0.0).sqrt();
    let sum = wi + wo;
    // The shader's threshold: below it the half vector is rounding, not a direction.
    if sum.length_squared().is_nan() || sum.length_squared() <= 1e-12 {
        return (diffuse, 0.0, 0.0);
    }
    let half = sum.normalize();
    let sin_th = (1.0 - half.x * half.x).max(0.0).sqrt();
    (
        diffuse,
        sin_th.powi(PRIMARY_EXPONENT),
        sin_th.powi(SECONDARY_EXPONENT),
    )
}

/// Kajiya-Kay's reflected radiance per unit irradiance, for unit `wo`, `wi` in the fibre frame
/// and the hair's colour `base` (the shader's `hair_color(σ_a)`).
pub fn kajiya_kay(wo: DVec3, wi: DVec3, base: [f64; 3], weights: &KajiyaKayWeights) -> [f64; 3] {
    let (diffuse, primary, secondary) = lobes(wo, wi);
    let tinted = DIFFUSE_WEIGHT * diffuse + SECONDARY_WEIGHT * secondary;
    std::array::from_fn(|c| base[c] * weights.tint[c] * tinted + weights.primary * primary)
}

/// [`LobeMeans`], integrated once: midpoints in `x = sin θ` (uniform over the sphere's area)
/// for both directions and in the azimuth between them (the lobes depend on nothing else).
pub fn lobe_means() -> LobeMeans {
    static MEANS: OnceLock<LobeMeans> = OnceLock::new();
    *MEANS.get_or_init(|| {
        const XO: usize = 48;
        const XI: usize = 192;
        const AZIMUTHS: usize = 96;
        let direction = |x: f64, phi: f64| {
            let r = (1.0 - x * x).max(0.0).sqrt();
            DVec3::new(x, r * phi.cos(), r * phi.sin())
        };
        let midpoint = |k: usize, n: usize| -1.0 + (2.0 * k as f64 + 1.0) / n as f64;
        let mut sums = [0.0; 3];
        for o in 0..XO {
            let wo = direction(midpoint(o, XO), 0.0);
            for i in 0..XI {
                let x_i = midpoint(i, XI);
                for a in 0..AZIMUTHS {
                    let phi = PI * midpoint(a, AZIMUTHS);
                    let (d, p, s) = lobes(wo, direction(x_i, phi));
                    sums[0] += d;
                    sums[1] += p;
                    sums[2] += s;
                }
            }
        }
        let n = (XO * XI * AZIMUTHS) as f64;
        LobeMeans {
            diffuse: sums[0] / n,
            primary: sums[1] / n,
            secondary: sums[2] / n,
        }
    })
}

/// The mean over the sphere (both directions) of the Marschner fibre's single scattering,
/// `f_s`, per lobe: R, then TT + TRT + the residual, per colour channel, at absorption
/// `sigma_a`. `∫ M_p N_p dω_i = 1`, so each is `A_p / 4π` averaged over `sin θ_o` and `h`
/// (midpoints; `A_p` is smooth in both).
pub fn marschner_means(bsdf: &HairBsdf, sigma_a: [f64; 3]) -> (f64, [f64; 3]) {
    const XO: usize = 32;
    const OFFSETS: usize = 32;
    let mut reflected = 0.0;
    let mut transmitted = [0.0; 3];
    for o in 0..XO {
        let x = -1.0 + (2.0 * o as f64 + 1.0) / XO as f64;
        let wo = DVec3::new(x, 0.0, (1.0 - x * x).max(0.0).sqrt());
        for k in 0..OFFSETS {
            let h = -1.0 + (2.0 * k as f64 + 1.0) / OFFSETS as f64;
            let a = bsdf.attenuations(wo, h, sigma_a);
            reflected += a[0][0];
            for lobe in &a[1..=P_MAX] {
                for c in 0..3 {
                    transmitted[c] += lobe[c];
                }
            }
        }
    }
    let scale = 1.0 / ((XO * OFFSETS) as f64 * 4.0 * PI);
    (reflected * scale, transmitted.map(|t| t * scale))
}

impl KajiyaKayWeights {
    /// The weights with which Kajiya-Kay, averaged over the sphere, scatters what the Marschner
    /// fibre of `fibre` scatters (see the module's documentation), at the material's mean
    /// absorption (mid-strand, the mean strand): tinted lobes as TT + TRT + the residual per
    /// channel, the primary highlight as R. Finite for any material (a channel the hair's
    /// colour has none of gets no tint).
    pub fn matching(fibre: &Fibre) -> Self {
        let bsdf = HairBsdf::new(fibre);
        let sigma_a = fibre.sigma_a_mean();
        let base = fibre.color(sigma_a);
        let (reflected, transmitted) = marschner_means(&bsdf, sigma_a);
        let means = lobe_means();
        let tinted = DIFFUSE_WEIGHT * means.diffuse + SECONDARY_WEIGHT * means.secondary;
        let tint = std::array::from_fn(|c| {
            let value = transmitted[c] / (base[c] * tinted);
            if value.is_finite() {
                value.max(0.0)
            } else {
                0.0
            }
        });
        let primary = reflected / means.primary;
        Self {
            tint,
            primary: if primary.is_finite() { primary } else { 0.0 },
        }
    }
}

/// `∫ sin(T, L) dω / 4π` in closed form (`π/4`), which [`lobe_means`] must reproduce.
pub const DIFFUSE_MEAN: f64 = FRAC_PI_4;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::scene::{HairMaterial, Pigment};
    use crate::strands::random::SplitMix64;

    fn random_direction(rng: &mut SplitMix64) -> DVec3 {
        let x = 2.0 * rng.next_f64() - 1.0;
        let phi = 2.0 * PI * rng.next_f64();
        let r = (1.0 - x * x).sqrt();
        DVec3::new(x, r * phi.cos(), r * phi.sin())
    }

    fn materials() -> Vec<HairMaterial> {
        let melanin = |eumelanin: f32, pheomelanin: f32| HairMaterial {
            pigment: Pigment::Melanin {
                eumelanin,
                pheomelanin,
            },
            ..HairMaterial::default()
        };
        vec![
            melanin(0.45, 0.3),
            melanin(0.05, 0.1),
            melanin(1.5, 0.2),
            HairMaterial {
                longitudinal_roughness: 0.1,
                azimuthal_roughness: 0.8,
                ..melanin(0.2, 0.9)
            },
            HairMaterial {
                pigment: Pigment::Color {
                    rgb: [0.9, 0.9, 0.9],
                },
                ..HairMaterial::default()
            },
        ]
    }

    #[test]
    fn lobe_means_reproduce_the_closed_form_diffuse_mean() {
        let means = lobe_means();
        assert!(
            (means.diffuse - DIFFUSE_MEAN).abs() < 2e-3,
            "diffuse mean {} vs π/4",
            means.diffuse
        );
        assert!(means.primary > 0.0 && means.primary < means.secondary);
        assert!(means.secondary < means.diffuse);
    }

    /// The claim itself, measured independently: random directions and offsets through the
    /// full `hair_bsdf` (not the `A_p` shortcut) against random directions through
    /// `kajiya_kay`, per channel.
    #[test]
    fn kajiya_kay_scatters_the_marschner_mean_colour_of_every_material() {
        for material in materials() {
            let fibre = Fibre::new(&material);
            let bsdf = HairBsdf::new(&fibre);
            let weights = KajiyaKayWeights::matching(&fibre);
            let sigma_a = fibre.sigma_a_mean();
            let base = fibre.color(sigma_a);
            let mut rng = SplitMix64::new(7);
            let samples = 1_000_000;
            let mut marschner = [0.0; 3];
            let mut kajiya = [0.0; 3];
            for _ in 0..samples {
                let (wo, wi) = (random_direction(&mut rng), random_direction(&mut rng));
                let h = 2.0 * rng.next_f64() - 1.0;
                let m = bsdf.hair_bsdf(wo, wi, h, sigma_a);
                let k = kajiya_kay(wo, wi, base, &weights);
                for c in 0..3 {
                    marschner[c] += m[c] / samples as f64;
                    kajiya[c] += k[c] / samples as f64;
                }
            }
            for c in 0..3 {
                let error = (kajiya[c] - marschner[c]).abs() / marschner[c];
                // Monte Carlo over narrow lobes (sin⁸⁰, R at β_m 0.1): a few per cent of
                // noise where the highlight carries most of a dark channel.
                assert!(
                    error < 0.05,
                    "{material:?} channel {c}: Kajiya-Kay {} vs Marschner {} ({:.1} %)",
                    kajiya[c],
                    marschner[c],
                    100.0 * error
                );
            }
        }
    }

    #[test]
    fn weights_stay_finite_for_white_and_black_hair() {
        for rgb in [[1.0, 1.0, 1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]] {
            let fibre = Fibre::new(&HairMaterial {
                pigment: Pigment::Color { rgb },
                ..HairMaterial::default()
            });
            let weights = KajiyaKayWeights::matching(&fibre);
            assert!(
                weights.tint.iter().all(|t| t.is_finite() && *t >= 0.0),
                "{rgb:?}: {weights:?}"
            );
            assert!(weights.primary.is_finite() && weights.primary > 0.0);
        }
    }
}
