//! Kajiya & Kay 1989's fibre shading, the cheap shading effect: a diffuse lobe `sin(T, L)`, a
//! white primary highlight `sin(T, H)^80` and a tinted secondary one `sin(T, H)^20`, in the
//! fibre frame of [`crate::light::hair_bsdf`] (`x` is the tangent). CPU mirror of
//! `shaders/light/kajiya_kay.wgsl` (same name: `kajiya_kay`).
//!
//! Kajiya-Kay is not a scattering model: its lobes' sizes are free. Left at hand-picked
//! constants it showed a material brighter and more orange than the Marschner model does
//! (issue "Hair that looks real up close"), so switching a scene between the two changed the
//! hair's colour, not just its shading. Here its weights are chosen for each light, each
//! frame ([`KajiyaKayWeights::matching`]): for the view and light directions at the hair,
//! averaged over every orientation of the fibre and over its width (the offsets a thin
//! fibre's pixel averages), Kajiya-Kay scatters what the Marschner fibre ([`HairBsdf`],
//! single scattering) does — its primary highlight the R lobe (white, from Fresnel), its
//! tinted lobes TT, TRT and the longer paths (coloured by absorption). So a head of hair,
//! whose fibres take every orientation, shows one mean colour under either model.
//!
//! Over fibres of every orientation the mean depends only on the angle between the view and
//! the light, so [`KajiyaKayTable`] holds the weights at [`TABLE_ANGLES`] angles, made once per
//! material; a frame interpolates each light's.
//!
//! Why per light and not once per material: how much of a fibre's light comes back toward
//! the viewer depends on the angle between light and view (TT's forward scattering, most of
//! what light hair scatters, is seen only against the light), and Kajiya-Kay is blind to
//! it; one weight per material is right for one angle only.
//!
//! What it does and does not give, measured on the curly sample's three-quarter view at
//! 320² (hair pixels, no shadows): the hue now agrees (sRGB R/G 1.14 against Marschner's
//! 1.11; the hand-picked constants gave 1.27, an orange head beside a golden one), while
//! the displayed mean stays brighter (sRGB 183/161/109 against 140/126/97): the filmic
//! tone curve compresses Marschner's narrow highlights, and Kajiya-Kay has none to
//! compress. In radiance the head's fibres, combed along the scalp and lit from above, are
//! not of every orientation and favour Marschner's highlights: at a low exposure, where the
//! curve is nearly linear, Kajiya-Kay shows 0.5-0.63 of Marschner's mean radiance.

use std::f64::consts::PI;

use glam::DVec3;

use crate::light::hair_bsdf::HairBsdf;
use crate::light::material::Fibre;

/// The diffuse lobe's weight against the tinted secondary highlight's (the tint scales both).
pub const DIFFUSE_WEIGHT: f64 = 0.35;
pub const SECONDARY_WEIGHT: f64 = 0.25;
pub const PRIMARY_EXPONENT: i32 = 80;
pub const SECONDARY_EXPONENT: i32 = 20;

/// Fibre orientations the match averages over (a Fibonacci sphere: TT's forward peak, seen
/// against the light, is narrow).
pub const MATCH_TANGENTS: usize = 4096;

/// Angles between the view and the light at which [`KajiyaKayTable`] holds weights (0 to π).
pub const TABLE_ANGLES: usize = 65;

/// Gauss-Legendre offsets across the fibre and their weights: the shader's 3-point average
/// for thin fibres.
const OFFSETS: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 18.0),
    (0.0, 8.0 / 18.0),
    (0.774_596_669_241_483_4, 5.0 / 18.0),
];

/// One light's weights, as the shader receives them (`scene.lights[i].kajiya_kay`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KajiyaKayWeights {
    /// Multiplies the hair's colour in the diffuse and secondary lobes.
    pub tint: [f64; 3],
    /// The white primary highlight's weight.
    pub primary: f64,
}

/// The lobes `(diffuse, primary, secondary)` before weights, for unit `wo`, `wi` in the fibre
/// frame (`x` along the tangent). Looking straight into the light (`wo = −wi`, within
/// `|wo + wi|² ≤ 1e-12`) there is no half vector: the highlights are then 0.
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

/// Point `k` of `n` on a Fibonacci sphere (unit vectors spread evenly by area).
pub fn fibonacci_direction(k: usize, n: usize) -> DVec3 {
    let golden = PI * (3.0 - 5f64.sqrt());
    let y = 1.0 - (2.0 * k as f64 + 1.0) / n as f64;
    let r = (1.0 - y * y).max(0.0).sqrt();
    let phi = golden * k as f64;
    DVec3::new(r * phi.cos(), y, r * phi.sin())
}

/// World directions `to_viewer` and `to_light` in the fibre frame of `tangent`, as the shaders
/// build it (`fibre_frame` in shaders/shared/scene.wgsl: x the tangent, z toward the viewer
/// across it); `None` when the fibre points at the viewer (no frame; measure zero).
pub fn in_fibre_frame(tangent: DVec3, to_viewer: DVec3, to_light: DVec3) -> Option<(DVec3, DVec3)> {
    let x = tangent.try_normalize()?;
    let z = (to_viewer - x * to_viewer.dot(x)).try_normalize()?;
    let y = z.cross(x);
    let local = |w: DVec3| DVec3::new(w.dot(x), w.dot(y), w.dot(z));
    Some((local(to_viewer), local(to_light)))
}

/// [`KajiyaKayWeights::matching`] at [`TABLE_ANGLES`] angles between the view and the light,
/// evenly from 0 (light behind the viewer) to π (looking into the light), for one material.
#[derive(Clone, Debug, PartialEq)]
pub struct KajiyaKayTable {
    weights: Vec<KajiyaKayWeights>,
}

impl KajiyaKayTable {
    pub fn new(fibre: &Fibre) -> Self {
        let material = Material::of(fibre);
        let weights = (0..TABLE_ANGLES)
            .map(|k| {
                let angle = PI * k as f64 / (TABLE_ANGLES - 1) as f64;
                material.matching(DVec3::Z, DVec3::new(angle.sin(), 0.0, angle.cos()))
            })
            .collect();
        Self { weights }
    }

    /// The weights for unit-or-not directions `to_viewer` and `to_light`, linear between the
    /// table's angles (zero weights where a direction is zero or not finite).
    pub fn at(&self, to_viewer: DVec3, to_light: DVec3) -> KajiyaKayWeights {
        let (Some(wo), Some(wi)) = (to_viewer.try_normalize(), to_light.try_normalize()) else {
            return KajiyaKayWeights::NONE;
        };
        let position = wo.dot(wi).clamp(-1.0, 1.0).acos() / PI * (TABLE_ANGLES - 1) as f64;
        let below = (position.floor() as usize).min(TABLE_ANGLES - 2);
        let t = position - below as f64;
        let (a, b) = (self.weights[below], self.weights[below + 1]);
        KajiyaKayWeights {
            tint: std::array::from_fn(|c| a.tint[c] + (b.tint[c] - a.tint[c]) * t),
            primary: a.primary + (b.primary - a.primary) * t,
        }
    }
}

impl KajiyaKayWeights {
    /// No light through Kajiya-Kay (what a light gets under Marschner shading).
    pub const NONE: Self = Self {
        tint: [0.0; 3],
        primary: 0.0,
    };

    /// The weights with which Kajiya-Kay, for unit directions `to_viewer` and `to_light` and
    /// averaged over [`MATCH_TANGENTS`] fibre orientations and the 3-point average across the
    /// fibre, scatters what the Marschner fibre of `fibre` scatters (see the module's
    /// documentation), at the material's mean absorption (mid-strand, the mean strand):
    /// tinted lobes as TT + TRT + the residual per channel, the primary highlight as R.
    /// Finite for any material and any directions (what cannot be matched gets 0).
    pub fn matching(fibre: &Fibre, to_viewer: DVec3, to_light: DVec3) -> Self {
        Material::of(fibre).matching(to_viewer, to_light)
    }
}

/// What the match needs of a material, made once per table.
struct Material {
    bsdf: HairBsdf,
    /// The mean absorption (mid-strand, the mean strand) and the colour it shows.
    sigma_a: [f64; 3],
    base: [f64; 3],
}

impl Material {
    fn of(fibre: &Fibre) -> Self {
        let sigma_a = fibre.sigma_a_mean();
        Self {
            bsdf: HairBsdf::new(fibre),
            sigma_a,
            base: fibre.color(sigma_a),
        }
    }

    /// [`KajiyaKayWeights::matching`] for this material.
    fn matching(&self, to_viewer: DVec3, to_light: DVec3) -> KajiyaKayWeights {
        let (Some(wo), Some(wi)) = (to_viewer.try_normalize(), to_light.try_normalize()) else {
            return KajiyaKayWeights::NONE;
        };
        let mut reflected = 0.0;
        let mut transmitted = [0.0; 3];
        let mut tinted = 0.0;
        let mut primary = 0.0;
        for k in 0..MATCH_TANGENTS {
            let Some((wo_local, wi_local)) =
                in_fibre_frame(fibonacci_direction(k, MATCH_TANGENTS), wo, wi)
            else {
                continue;
            };
            for (h, weight) in OFFSETS {
                let lobes = self.bsdf.lobes(wo_local, wi_local, h, self.sigma_a);
                reflected += weight * lobes[0][0];
                for lobe in &lobes[1..] {
                    for c in 0..3 {
                        transmitted[c] += weight * lobe[c];
                    }
                }
            }
            let (d, p, s) = lobes(wo_local, wi_local);
            tinted += DIFFUSE_WEIGHT * d + SECONDARY_WEIGHT * s;
            primary += p;
        }
        let finite = |v: f64| if v.is_finite() { v.max(0.0) } else { 0.0 };
        KajiyaKayWeights {
            tint: std::array::from_fn(|c| finite(transmitted[c] / (self.base[c] * tinted))),
            primary: finite(reflected / primary),
        }
    }
}

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

    /// The claim itself, measured independently of the match's Fibonacci orientations and of
    /// the table's interpolation (the lights fall between its angles): random fibre
    /// orientations through the full `hair_bsdf` (averaged across the fibre by the
    /// 3-point rule the shader draws thin fibres with) against the same orientations through
    /// `kajiya_kay`, per channel, for a key light in front, a side light, a rim light behind
    /// and one at a grazing angle.
    #[test]
    fn kajiya_kay_shows_the_marschner_mean_colour_for_every_material_and_light() {
        let to_viewer = DVec3::Z;
        let lights = [
            DVec3::new(0.55, 0.75, 0.9),
            DVec3::new(-1.0, 0.1, 0.0),
            DVec3::new(-0.2, 0.55, -1.0),
            DVec3::new(0.0, -0.2, -1.0),
        ];
        for material in materials() {
            let fibre = Fibre::new(&material);
            let bsdf = HairBsdf::new(&fibre);
            let sigma_a = fibre.sigma_a_mean();
            let base = fibre.color(sigma_a);
            let table = KajiyaKayTable::new(&fibre);
            for to_light in lights {
                let to_light = to_light.normalize();
                let weights = table.at(to_viewer, to_light);
                let mut rng = SplitMix64::new(7);
                let samples = 400_000;
                let mut marschner = [0.0; 3];
                let mut kajiya = [0.0; 3];
                for _ in 0..samples {
                    let tangent = random_direction(&mut rng);
                    let Some((wo, wi)) = in_fibre_frame(tangent, to_viewer, to_light) else {
                        continue;
                    };
                    let k = kajiya_kay(wo, wi, base, &weights);
                    for c in 0..3 {
                        kajiya[c] += k[c] / samples as f64;
                    }
                    for (h, weight) in OFFSETS {
                        let m = bsdf.hair_bsdf(wo, wi, h, sigma_a);
                        for c in 0..3 {
                            marschner[c] += weight * m[c] / samples as f64;
                        }
                    }
                }
                for c in 0..3 {
                    let error = (kajiya[c] - marschner[c]).abs() / marschner[c];
                    // Monte Carlo over narrow lobes against the match's quadrature.
                    assert!(
                        error < 0.06,
                        "{material:?} light {to_light}: channel {c}: Kajiya-Kay {} vs \
                         Marschner {} ({:.1} %)",
                        kajiya[c],
                        marschner[c],
                        100.0 * error
                    );
                }
            }
        }
    }

    #[test]
    fn weights_stay_finite_for_white_and_black_hair_and_degenerate_directions() {
        for rgb in [[1.0, 1.0, 1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]] {
            let fibre = Fibre::new(&HairMaterial {
                pigment: Pigment::Color { rgb },
                ..HairMaterial::default()
            });
            for (to_viewer, to_light) in [
                (DVec3::Z, DVec3::Y),
                (DVec3::Z, DVec3::Z),
                (DVec3::Z, -DVec3::Z),
                (DVec3::ZERO, DVec3::Y),
                (DVec3::Z, DVec3::NAN),
            ] {
                let weights = KajiyaKayWeights::matching(&fibre, to_viewer, to_light);
                assert!(
                    weights.tint.iter().all(|t| t.is_finite() && *t >= 0.0)
                        && weights.primary.is_finite()
                        && weights.primary >= 0.0,
                    "{rgb:?} {to_viewer} {to_light}: {weights:?}"
                );
            }
        }
    }

    #[test]
    fn the_fibonacci_sphere_covers_every_direction_evenly() {
        // Its mean is the centre and every octant holds an eighth of the points.
        let n = MATCH_TANGENTS;
        let mut mean = DVec3::ZERO;
        let mut octants = [0usize; 8];
        for k in 0..n {
            let d = fibonacci_direction(k, n);
            assert!((d.length() - 1.0).abs() < 1e-12);
            mean += d / n as f64;
            octants[(d.x > 0.0) as usize
                | ((d.y > 0.0) as usize) << 1
                | ((d.z > 0.0) as usize) << 2] += 1;
        }
        assert!(mean.length() < 0.01, "{mean}");
        assert!(
            octants.iter().all(|&c| c.abs_diff(n / 8) <= 4),
            "{octants:?}"
        );
    }
}
