//! The fibre material resolved for shading: absorption from melanin or colour, and the
//! per-strand, root-to-tip variation every renderer applies the same way.
//!
//! Conversions follow Chiang et al. 2016 ("A Practical and Controllable Hair and Fur Model
//! for Production Path Tracing") as pbrt-v4 and Blender's Principled Hair use them:
//! - melanin: `σ_a = c_eu (0.419, 0.697, 1.37) + c_pheo (0.187, 0.4, 1.05)` (d'Eon et al. 2011);
//! - colour: `σ_a = (ln c / P(β_n))²` with `P(β) = 5.969 − 0.215β + 2.532β² − 10.73β³ +
//!   5.574β⁴ + 0.245β⁵` (Chiang eq. 9, fitted so that a thick mass of hair shows colour `c`),
//!   and its exact inverse `c = exp(−√σ_a · P(β_n))`.

use crate::model::root_maps::{PaintedColour, RootMaps};
use crate::model::scene::{HairMaterial, Ombre, Pigment};

/// Eumelanin absorption per unit concentration (per unit fibre radius).
pub const EUMELANIN_SIGMA_A: [f64; 3] = [0.419, 0.697, 1.37];
/// Pheomelanin absorption per unit concentration.
pub const PHEOMELANIN_SIGMA_A: [f64; 3] = [0.187, 0.4, 1.05];

/// Colours are clamped into `[MIN_COLOR, MAX_COLOR]` before the logarithm: 0 would be infinite
/// absorption and 1 no absorption at all (the fit is undefined at both).
pub const MIN_COLOR: f64 = 1e-4;
pub const MAX_COLOR: f64 = 0.9999;

/// Chiang et al. 2016 eq. 9's polynomial in the azimuthal roughness.
pub(crate) fn color_polynomial(beta_n: f64) -> f64 {
    let b = beta_n;
    5.969 - 0.215 * b + 2.532 * b * b - 10.73 * b.powi(3) + 5.574 * b.powi(4) + 0.245 * b.powi(5)
}

pub(crate) fn sigma_a_from_melanin(eumelanin: f64, pheomelanin: f64) -> [f64; 3] {
    std::array::from_fn(|c| {
        eumelanin.max(0.0) * EUMELANIN_SIGMA_A[c] + pheomelanin.max(0.0) * PHEOMELANIN_SIGMA_A[c]
    })
}

/// The absorption that shows `rgb` on a thick mass of hair with azimuthal roughness `beta_n`.
pub(crate) fn sigma_a_from_color(rgb: [f64; 3], beta_n: f64) -> [f64; 3] {
    let p = color_polynomial(beta_n);
    rgb.map(|c| {
        let c = if c.is_finite() { c } else { MIN_COLOR };
        (c.clamp(MIN_COLOR, MAX_COLOR).ln() / p).powi(2)
    })
}

/// The darkest colour a blend is taken back to absorption from: above 0, so the logarithm
/// stays finite (hair darker than this shows black either way).
pub const MIN_BLEND_COLOR: f64 = 1e-30;

/// The colour `share` of the way from `own` (what a fibre shows) toward `target`, and the
/// absorption that shows it. Kept in the colour fit's range, except that hair darker than
/// [`MIN_COLOR`] keeps its own floor: a share near 0 then leaves it as it was, with no jump in
/// absorption where a blend starts. Mirror of `blend_toward` in `shaders/shared/scene.wgsl`.
pub(crate) fn blend_toward(
    own: [f64; 3],
    target: [f64; 3],
    share: f64,
    beta_n: f64,
) -> ([f64; 3], [f64; 3]) {
    let p = color_polynomial(beta_n);
    let rgb: [f64; 3] = std::array::from_fn(|c| {
        // (Written out rather than `clamp`: a NaN colour takes the lowest floor, never a
        // NaN one that `clamp` below would panic on.)
        let floor = if own[c] >= MIN_COLOR {
            MIN_COLOR
        } else if own[c] > MIN_BLEND_COLOR {
            own[c]
        } else {
            MIN_BLEND_COLOR
        };
        let blended = own[c] + (target[c] - own[c]) * share;
        if blended.is_nan() {
            floor
        } else {
            blended.clamp(floor, MAX_COLOR)
        }
    });
    (rgb, rgb.map(|c| (c.ln() / p).powi(2)))
}

/// The inverse of [`sigma_a_from_color`]: the colour a thick mass of hair with this
/// absorption shows. Used for ambient light and for Kajiya-Kay's base colour.
pub(crate) fn color_from_sigma_a(sigma_a: [f64; 3], beta_n: f64) -> [f64; 3] {
    let p = color_polynomial(beta_n);
    sigma_a.map(|s| (-s.max(0.0).sqrt() * p).exp())
}

/// A material ready for shading, in the numbers both renderers use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fibre {
    /// Absorption at the root, per unit fibre radius.
    pub sigma_a_root: [f64; 3],
    pub tip_absorption_factor: f64,
    pub strand_absorption_variation: f64,
    /// Roughness clamped into the model's stable range (see [`MIN_ROUGHNESS`]).
    pub beta_m: f64,
    pub beta_n: f64,
    pub alpha_rad: f64,
    pub eta: f64,
    /// The colour along the strand, when the material has an ombré.
    pub ombre: Option<FibreOmbre>,
}

/// [`Ombre`] in the numbers shading uses: its tip colour clamped into `[0, 1]`, and its span
/// ordered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FibreOmbre {
    pub tip_rgb: [f64; 3],
    pub start: f64,
    pub end: f64,
}

impl FibreOmbre {
    pub fn new(ombre: &Ombre) -> Self {
        let unit = |v: f32| {
            if v.is_finite() {
                (v as f64).clamp(0.0, 1.0)
            } else {
                0.0
            }
        };
        let start = unit(ombre.start);
        Self {
            // Into [0, 1] only: the blend keeps it in the colour fit's range (hair darker
            // than the fit's floor may turn toward a tip as dark as itself).
            tip_rgb: ombre.tip_rgb.map(unit),
            start,
            end: unit(ombre.end).max(start),
        }
    }

    /// How far the colour has turned toward the tip's at fraction `along` of the strand: 0
    /// up to `start`, 1 from `end`, a smoothstep between (a step at `start` when the span is
    /// empty). Mirror of `ombre_share` in `shaders/shared/scene.wgsl`.
    pub fn share(&self, along: f64) -> f64 {
        let span = self.end - self.start;
        if span <= 1e-6 {
            return if along >= self.start { 1.0 } else { 0.0 };
        }
        let x = ((along - self.start) / span).clamp(0.0, 1.0);
        x * x * (3.0 - 2.0 * x)
    }
}

/// Roughness below this is raised to it: the longitudinal lobe's variance goes as β², and
/// below about 0.02 it would need more than f32's range in the shader (a perfectly smooth
/// fibre is a delta, which no rasteriser or path tracer can sample from a light).
pub const MIN_ROUGHNESS: f64 = 0.02;
/// Index of refraction below this is raised to it (η = 1 makes Fresnel 0 and γ_t
/// undefined at grazing angles).
pub const MIN_IOR: f64 = 1.001;

impl Fibre {
    pub fn new(material: &HairMaterial) -> Self {
        let beta_n = (material.azimuthal_roughness as f64).clamp(MIN_ROUGHNESS, 1.0);
        let sigma_a_root = match &material.pigment {
            Pigment::Melanin {
                eumelanin,
                pheomelanin,
            } => sigma_a_from_melanin(*eumelanin as f64, *pheomelanin as f64),
            Pigment::Color { rgb } => sigma_a_from_color(rgb.map(f64::from), beta_n),
            Pigment::Absorption { sigma_a } => sigma_a.map(|s| (s as f64).max(0.0)),
        };
        Self {
            sigma_a_root,
            tip_absorption_factor: (material.tip_absorption_factor as f64).max(0.0),
            strand_absorption_variation: (material.strand_absorption_variation as f64)
                .clamp(0.0, 1.0),
            beta_m: (material.longitudinal_roughness as f64).clamp(MIN_ROUGHNESS, 1.0),
            beta_n,
            alpha_rad: (material.cuticle_tilt_deg as f64).to_radians(),
            eta: (material.ior as f64).max(MIN_IOR),
            ombre: material.ombre.as_ref().map(FibreOmbre::new),
        }
    }

    /// Absorption at fraction `along` of a strand (0 root, 1 tip) for a strand whose random
    /// value is `xi` in `[0, 1)`: `σ_a,along · lerp(1, tip, along) · (1 + variation (2ξ − 1))`,
    /// where `σ_a,along` is the root's absorption, or under an ombré the absorption that shows
    /// the root's colour blended toward the tip colour by [`FibreOmbre::share`].
    pub fn sigma_a(&self, along: f64, xi: f64) -> [f64; 3] {
        let along = if along.is_nan() {
            0.0
        } else {
            along.clamp(0.0, 1.0)
        };
        let scale = (1.0 + (self.tip_absorption_factor - 1.0) * along)
            * (1.0 + self.strand_absorption_variation * (2.0 * xi - 1.0));
        self.sigma_a_along(along).map(|s| s * scale.max(0.0))
    }

    /// The absorption before the tip factor and variation at fraction `along`: the root's,
    /// turned toward the ombré's tip colour where the material has one.
    fn sigma_a_along(&self, along: f64) -> [f64; 3] {
        let Some(ombre) = &self.ombre else {
            return self.sigma_a_root;
        };
        let share = ombre.share(along);
        if share <= 0.0 {
            return self.sigma_a_root;
        }
        let own = self.color(self.sigma_a_root);
        blend_toward(own, ombre.tip_rgb, share, self.beta_n).1
    }

    /// The absorption of an average strand at mid-length, in the material's own colour (no
    /// ombré, as no colour map): what precomputed tables (dual scattering, forward
    /// transmittance, far hair's aggregated BCSDF, Kajiya-Kay's weights) are made from.
    pub fn sigma_a_mean(&self) -> [f64; 3] {
        Fibre {
            ombre: None,
            ..*self
        }
        .sigma_a(0.5, 0.5)
    }

    /// The colour a thick mass of this hair shows at `sigma_a`.
    pub fn color(&self, sigma_a: [f64; 3]) -> [f64; 3] {
        color_from_sigma_a(sigma_a, self.beta_n)
    }

    /// This fibre on a strand under the colour map's `paint`: the root colour blended toward
    /// the painted one by its weight (in colour, so half a weight looks half-way), and the
    /// absorption that shows it; the tip factor and per-strand variation then apply as
    /// before. Mirror of `painted_strand_sigma_a` in `shaders/shared/scene.wgsl`.
    pub fn painted(&self, paint: &PaintedColour) -> Fibre {
        let weight = if paint.weight.is_nan() {
            0.0
        } else {
            paint.weight.clamp(0.0, 1.0)
        };
        if weight == 0.0 {
            return *self;
        }
        let own = self.color(self.sigma_a_root);
        Fibre {
            sigma_a_root: blend_toward(own, paint.rgb_linear, weight, self.beta_n).1,
            ..*self
        }
    }
}

/// The random value of a strand's absorption variation, from its root index (bundle ×
/// roots per bundle + sample: stable when LOD drops strands). The shaders' `strand_shading_random`.
pub(crate) fn strand_shading_random(root: u32) -> f64 {
    use crate::strands::random::{hash_to_unit, pcg_hash};
    hash_to_unit(pcg_hash(SHADING_SALT ^ root))
}

/// The colour (linear RGB: what a thick mass of such hair shows) at every point of `strands`,
/// in order: the material's absorption, under the colour map at the strand's root uv, at the
/// point's fraction along its strand (root to tip) with the strand's own variation, hashed
/// from its root index in `roots` (one per strand, as
/// [`crate::strands::reference::root_indices`] numbers them). What strand exports write as
/// vertex colour so that other tools start from the hair's look.
pub fn strand_point_colors(
    material: &HairMaterial,
    colour_map: &RootMaps,
    strands: &[crate::strands::reference::Strand],
    roots: &[u32],
) -> Vec<[f32; 3]> {
    let material_fibre = Fibre::new(material);
    let mut colors = Vec::with_capacity(strands.iter().map(|s| s.points.len()).sum());
    for (strand, &root) in strands.iter().zip(roots) {
        let fibre = material_fibre.painted(&colour_map.sample_colour(strand.root_uv));
        let xi = strand_shading_random(root);
        let last = strand.points.len().saturating_sub(1).max(1) as f64;
        colors.extend((0..strand.points.len()).map(|k| {
            let rgb = fibre.color(fibre.sigma_a(k as f64 / last, xi));
            rgb.map(|c| c as f32)
        }));
    }
    colors
}

/// Keeps the shading random values apart from the styling ones drawn from the same roots.
pub const SHADING_SALT: u32 = 0x5A3D_1E77;

#[cfg(test)]
mod tests {
    use super::*;

    /// A material with only the ombré shaping the colour along the strand.
    fn ombre_material(tip_rgb: [f32; 3], start: f32, end: f32) -> HairMaterial {
        HairMaterial {
            tip_absorption_factor: 1.0,
            strand_absorption_variation: 0.0,
            ombre: Some(Ombre {
                tip_rgb,
                start,
                end,
            }),
            ..HairMaterial::default()
        }
    }

    #[test]
    fn an_ombre_turns_the_colour_from_the_root_to_the_tip() {
        let tip = [0.6, 0.4, 0.2];
        let fibre = Fibre::new(&ombre_material(tip, 0.3, 0.8));
        let own = fibre.color(fibre.sigma_a_root);
        let colour_at = |along: f64| fibre.color(fibre.sigma_a(along, 0.5));
        for along in [0.0, 0.1, 0.3] {
            assert_eq!(colour_at(along), own, "the root's colour up to the start");
        }
        for along in [0.8, 0.9, 1.0] {
            let rgb = colour_at(along);
            for c in 0..3 {
                assert!(
                    (rgb[c] - tip[c] as f64).abs() < 1e-6,
                    "the tip colour from the end: {along} {rgb:?}"
                );
            }
        }
        // Half-way through the span the colour is half-way (the blend is in colour).
        let mid = colour_at(0.55);
        for c in 0..3 {
            let half = 0.5 * (own[c] + tip[c] as f64);
            assert!((mid[c] - half).abs() < 1e-6, "{mid:?} against {half}");
        }
        // It turns monotonically in between, channel by channel.
        let mut last = own;
        for k in 0..=100 {
            let rgb = colour_at(k as f64 / 100.0);
            for c in 0..3 {
                let toward = (tip[c] as f64 - own[c]).signum();
                assert!(
                    (rgb[c] - last[c]) * toward >= -1e-12,
                    "step {k} channel {c}"
                );
            }
            last = rgb;
        }
    }

    #[test]
    fn an_ombre_to_the_hairs_own_colour_changes_nothing() {
        let plain = Fibre::new(&HairMaterial::default());
        let own = plain.color(plain.sigma_a_root).map(|c| c as f32);
        let material = HairMaterial {
            ombre: Some(Ombre {
                tip_rgb: own,
                start: 0.0,
                end: 1.0,
            }),
            ..HairMaterial::default()
        };
        let fibre = Fibre::new(&material);
        for k in 0..=20 {
            let along = k as f64 / 20.0;
            for xi in [0.0, 0.37, 0.99] {
                let (a, b) = (plain.sigma_a(along, xi), fibre.sigma_a(along, xi));
                for c in 0..3 {
                    assert!((a[c] - b[c]).abs() <= 1e-5 * a[c].max(1e-3), "{a:?} {b:?}");
                }
            }
        }
    }

    #[test]
    fn precomputed_tables_take_the_materials_own_colour_under_an_ombre() {
        let plain = Fibre::new(&HairMaterial::default());
        let fibre = Fibre::new(&HairMaterial {
            ombre: Some(Ombre {
                start: 0.0,
                ..Ombre::default()
            }),
            ..HairMaterial::default()
        });
        assert_eq!(fibre.sigma_a_mean(), plain.sigma_a_mean());
        assert_ne!(fibre.sigma_a(0.5, 0.5), plain.sigma_a(0.5, 0.5));
    }

    #[test]
    fn a_dip_dye_line_is_a_step_and_degenerate_input_stays_finite() {
        // start = end: a hard line, the root's colour before it and the tip's from it.
        let fibre = Fibre::new(&ombre_material([0.9, 0.1, 0.5], 0.5, 0.5));
        let own = fibre.color(fibre.sigma_a_root);
        assert_eq!(fibre.color(fibre.sigma_a(0.4999, 0.5)), own);
        let dyed = fibre.color(fibre.sigma_a(0.5, 0.5));
        assert!((dyed[0] - 0.9).abs() < 1e-6 && (dyed[1] - 0.1).abs() < 1e-6);
        // Black and white ends are clamped into the colour fit's range; NaN positions along
        // the strand and out-of-order spans (which validation refuses) give finite absorption.
        for (tip, start, end) in [
            ([0.0, 0.0, 0.0], 0.0, 1.0),
            ([1.0, 1.0, 1.0], 0.2, 0.4),
            ([0.5, 0.5, 0.5], 0.8, 0.2),
            ([f32::NAN, 0.5, 0.5], f32::NAN, f32::INFINITY),
        ] {
            let fibre = Fibre::new(&ombre_material(tip, start, end));
            for along in [f64::NAN, -1.0, 0.0, 0.5, 1.0, 2.0] {
                let sigma_a = fibre.sigma_a(along, 0.5);
                assert!(
                    sigma_a.iter().all(|s| s.is_finite() && *s >= 0.0),
                    "{tip:?} {start} {end} at {along}: {sigma_a:?}"
                );
            }
        }
    }

    #[test]
    fn very_dark_hair_turns_without_a_jump_where_a_blend_starts() {
        // Black hair (eumelanin 8) shows colours far below the colour fit's 1e-4 floor.
        // (Blending in colour, the absorption of hair this dark moves fast once the blend is
        // under way — it is continuous, not a jump to the fit's floor, which is what this checks.)
        for eumelanin in [2.5, 8.0] {
            let material = HairMaterial {
                pigment: Pigment::Melanin {
                    eumelanin,
                    pheomelanin: 0.0,
                },
                ..ombre_material([0.6, 0.4, 0.2], 0.5, 0.9)
            };
            let fibre = Fibre::new(&material);
            let before = fibre.sigma_a(0.5, 0.5);
            let just_after = fibre.sigma_a(0.5 + 1e-6, 0.5);
            for c in 0..3 {
                assert!(
                    (just_after[c] - before[c]).abs() <= 1e-3 * before[c],
                    "eumelanin {eumelanin}: {before:?} -> {just_after:?}"
                );
            }
            // A colour-map stroke at a sliver of weight leaves it as it was, too.
            let faint = fibre.painted(&PaintedColour {
                rgb_linear: [0.9, 0.9, 0.9],
                weight: 1e-12,
            });
            for c in 0..3 {
                let (a, b) = (fibre.sigma_a_root[c], faint.sigma_a_root[c]);
                assert!(
                    (a - b).abs() <= 1e-3 * a,
                    "eumelanin {eumelanin}: {a} -> {b}"
                );
            }
            // And an ombré toward its own colour changes nothing.
            let plain = Fibre::new(&HairMaterial {
                ombre: None,
                ..material.clone()
            });
            let own = plain.color(plain.sigma_a_root).map(|c| c as f32);
            let same = Fibre::new(&HairMaterial {
                ombre: Some(Ombre {
                    tip_rgb: own,
                    start: 0.0,
                    end: 1.0,
                }),
                ..material.clone()
            });
            for k in 0..=10 {
                let (a, b) = (
                    plain.sigma_a(k as f64 / 10.0, 0.5),
                    same.sigma_a(k as f64 / 10.0, 0.5),
                );
                for c in 0..3 {
                    assert!(
                        (a[c] - b[c]).abs() <= 1e-3 * a[c],
                        "eumelanin {eumelanin}: {a:?} {b:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_painted_strand_turns_from_its_painted_colour_to_the_ombres() {
        let tip = [0.7, 0.5, 0.3];
        let fibre = Fibre::new(&ombre_material(tip, 0.5, 1.0));
        let paint = PaintedColour {
            rgb_linear: [0.05, 0.2, 0.4],
            weight: 1.0,
        };
        let painted = fibre.painted(&paint);
        let root = painted.color(painted.sigma_a(0.0, 0.5));
        let end = painted.color(painted.sigma_a(1.0, 0.5));
        for c in 0..3 {
            assert!((root[c] - paint.rgb_linear[c]).abs() < 1e-6, "{root:?}");
            assert!((end[c] - tip[c] as f64).abs() < 1e-6, "{end:?}");
        }
    }

    #[test]
    fn colour_and_absorption_round_trip() {
        for beta_n in [0.02, 0.1, 0.3, 0.6, 1.0] {
            for rgb in [
                [0.5, 0.3, 0.1],
                [0.9, 0.8, 0.6],
                [0.02, 0.015, 0.01],
                [0.2, 0.2, 0.2],
            ] {
                let sigma_a = sigma_a_from_color(rgb, beta_n);
                let back = color_from_sigma_a(sigma_a, beta_n);
                for c in 0..3 {
                    assert!(
                        (back[c] - rgb[c]).abs() < 1e-12,
                        "β_n {beta_n} {rgb:?} -> {sigma_a:?} -> {back:?}"
                    );
                }
                // Darker colours absorb more.
                assert!(
                    sigma_a[0] < sigma_a[2] || rgb[0] <= rgb[2],
                    "{rgb:?} {sigma_a:?}"
                );
            }
        }
        // The extremes are clamped, never infinite or NaN.
        for rgb in [[0.0; 3], [1.0; 3], [f64::NAN, -1.0, 2.0]] {
            let sigma_a = sigma_a_from_color(rgb, 0.3);
            assert!(
                sigma_a.iter().all(|s| s.is_finite() && *s >= 0.0),
                "{sigma_a:?}"
            );
        }
    }

    #[test]
    fn melanin_darkens_and_tips_follow_the_factor() {
        let blond = sigma_a_from_melanin(0.3, 0.0);
        let black = sigma_a_from_melanin(8.0, 0.0);
        assert!((0..3).all(|c| blond[c] < black[c]));
        let fibre = Fibre::new(&HairMaterial {
            tip_absorption_factor: 0.5,
            strand_absorption_variation: 0.0,
            ..HairMaterial::default()
        });
        let root = fibre.sigma_a(0.0, 0.3);
        let tip = fibre.sigma_a(1.0, 0.3);
        for c in 0..3 {
            assert!((tip[c] - 0.5 * root[c]).abs() < 1e-12);
        }
        // Brown hair is reddish: it absorbs blue most.
        let color = fibre.color(root);
        assert!(color[0] > color[1] && color[1] > color[2], "{color:?}");
    }

    #[test]
    fn painting_a_colour_blends_the_root_colour_and_keeps_the_variation() {
        let material = HairMaterial::default();
        let fibre = Fibre::new(&material);
        assert_eq!(fibre.painted(&PaintedColour::NONE), fibre);
        let nan = PaintedColour {
            rgb_linear: [0.5; 3],
            weight: f64::NAN,
        };
        assert_eq!(fibre.painted(&nan), fibre);
        let own = fibre.color(fibre.sigma_a_root);
        let red = [0.6, 0.1, 0.05];
        for weight in [0.0, 0.25, 1.0] {
            let painted = fibre.painted(&PaintedColour {
                rgb_linear: red,
                weight,
            });
            let root = painted.color(painted.sigma_a_root);
            for c in 0..3 {
                let expected = own[c] + (red[c] - own[c]) * weight;
                assert!((root[c] - expected).abs() < 1e-9, "{weight}: {root:?}");
            }
            // The tip factor and per-strand variation apply to the painted absorption.
            let ratio = painted.sigma_a(1.0, 0.9)[0] / painted.sigma_a(0.0, 0.5)[0];
            let plain_ratio = fibre.sigma_a(1.0, 0.9)[0] / fibre.sigma_a(0.0, 0.5)[0];
            assert!((ratio - plain_ratio).abs() < 1e-9);
            assert!(painted.sigma_a(0.7, 0.3).iter().all(|s| s.is_finite()));
        }
        // Black and white paint stay finite (clamped into the fit's range).
        for rgb in [[0.0; 3], [1.0; 3], [f64::NAN, f64::INFINITY, -1.0]] {
            let painted = fibre.painted(&PaintedColour {
                rgb_linear: rgb,
                weight: 1.0,
            });
            assert!(
                painted
                    .sigma_a_root
                    .iter()
                    .all(|s| s.is_finite() && *s >= 0.0),
                "{rgb:?}"
            );
        }
    }

    #[test]
    fn exported_colours_follow_the_colour_map_at_each_root() {
        use crate::strands::reference::Strand;
        let material = HairMaterial {
            strand_absorption_variation: 0.0,
            ..HairMaterial::default()
        };
        let strand = |u: f64| Strand {
            bundle: 0,
            root: 7,
            coord: crate::geometry::curve::FaceCoord { s: 0.5, t: 0.5 },
            root_uv: glam::DVec2::new(u, 0.5),
            length_fraction: 1.0,
            points: vec![glam::DVec3::ZERO, glam::DVec3::Y],
        };
        let strands = [strand(0.1), strand(0.9)];
        // Colour on the left half only, at full weight.
        let mut maps = RootMaps::blank(4, 1).expect("maps");
        for x in 0..2 {
            maps.colour_texels_mut()[x] = [200, 100, 50, 255];
        }
        let plain = strand_point_colors(&material, &RootMaps::default(), &strands, &[7, 7]);
        let colours = strand_point_colors(&material, &maps, &strands, &[7, 7]);
        let painted = maps.sample_colour(glam::DVec2::new(0.1, 0.5)).rgb_linear;
        for c in 0..3 {
            assert!(
                (colours[0][c] as f64 - painted[c]).abs() < 1e-5,
                "{colours:?}"
            );
        }
        assert_eq!(colours[2..], plain[2..], "unpainted on the right");
        assert_ne!(colours[..2], plain[..2]);
        // Under an ombré the tips take its colour and the roots keep theirs.
        let tip = [0.6, 0.45, 0.3];
        let dyed = HairMaterial {
            tip_absorption_factor: 1.0,
            ombre: Some(Ombre {
                tip_rgb: tip,
                start: 0.5,
                end: 1.0,
            }),
            ..material.clone()
        };
        let plain_untipped = strand_point_colors(
            &HairMaterial {
                tip_absorption_factor: 1.0,
                ..material.clone()
            },
            &RootMaps::default(),
            &strands,
            &[7, 7],
        );
        let ombre = strand_point_colors(&dyed, &RootMaps::default(), &strands, &[7, 7]);
        assert_eq!(ombre[0], plain_untipped[0], "the root keeps its colour");
        for c in 0..3 {
            assert!((ombre[1][c] - tip[c]).abs() < 1e-5, "{ombre:?}");
        }
    }
}
