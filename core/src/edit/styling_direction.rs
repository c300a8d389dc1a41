//! The styling-direction gizmo's geometry (seed 004 §3.1: a local frame of styling
//! directions on a wisp, the active one dragged): where a bundle group's uvw frame stands,
//! and how a dragged direction becomes its wave direction, its twist and its curl's
//! handedness. The editor draws and drags; these functions hold the maths so it is tested
//! without a window.
//!
//! The parameters stay the ones generation reads: the wave displaces along
//! `d = cos α û + sin α v̂` (`Wave::direction_rad`), the twist turns strands about the
//! bundle's centre line (ŵ) by `2π · turns_per_m · w`, and the curl's helix is right-handed
//! for positive `turns_per_m`. û and v̂ need not be orthogonal, so directions are solved in
//! their (dual) basis, never by dot products alone.

use glam::DVec3;

use crate::geometry::frames::layer_frames;
use crate::model::mesh::HairMesh;
use crate::model::styling::{HARD_RANGES, StylingSet};

/// A bundle group's styling frame, where the gizmo stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StylingAxes {
    /// The centre of the bundles' roots.
    pub origin: DVec3,
    /// û and v̂ averaged over the roots' corners (unit, not necessarily orthogonal).
    pub u: DVec3,
    pub v: DVec3,
    /// The direction the hair leaves the roots (unit): the average first step of the bundles'
    /// centre lines, the root faces' normal for bare bundles.
    pub w: DVec3,
    /// The mean length of the bundles' centre lines, metres (0 for bare bundles).
    pub length_m: f64,
}

/// The frame of `bundles` (out-of-range indices ignored), or `None` when none of them has a
/// usable frame (no bundle, collapsed roots).
pub fn styling_axes(mesh: &HairMesh, bundles: &[u32]) -> Option<StylingAxes> {
    let frames = layer_frames(mesh, 0);
    let (mut origin, mut u, mut v, mut w) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    let (mut length_m, mut count) = (0.0, 0usize);
    for &b in bundles {
        let Some(bundle) = mesh.bundles.get(b as usize) else {
            continue;
        };
        let Some(path) = (0..=bundle.layers as usize)
            .map(|k| super::bundle_layer_centre(mesh, bundle, k))
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        let corners: Option<Vec<_>> = bundle
            .vertices
            .iter()
            .map(|&c| frames.get(c as usize).copied().flatten())
            .collect();
        let Some(corners) = corners else {
            continue;
        };
        for frame in &corners {
            u += frame.u;
            v += frame.v;
        }
        origin += path[0];
        length_m += path.windows(2).map(|s| s[0].distance(s[1])).sum::<f64>();
        // The first step of the centre line; a bare bundle grows along its root normal.
        w += path
            .get(1)
            .and_then(|p| (*p - path[0]).try_normalize())
            .or_else(|| super::growth_direction(mesh, bundle))
            .unwrap_or(DVec3::ZERO);
        count += 1;
    }
    if count == 0 {
        return None;
    }
    let axes = StylingAxes {
        origin: origin / count as f64,
        u: u.try_normalize()?,
        v: v.try_normalize()?,
        w: w.try_normalize()?,
        length_m: length_m / count as f64,
    };
    // û ∥ v̂ leaves no plane to point a wave in.
    (axes.u.cross(axes.v).length() > 1e-6 && axes.origin.is_finite()).then_some(axes)
}

impl StylingAxes {
    /// The direction a wave of direction `alpha_rad` displaces strands (unit).
    pub fn wave_vector(&self, alpha_rad: f64) -> DVec3 {
        (alpha_rad.cos() * self.u + alpha_rad.sin() * self.v)
            .try_normalize()
            .unwrap_or(self.u)
    }
}

/// The wave direction `α` pointing along `a û + b v̂` (the dragged direction's coordinates in
/// the frame's basis), wrapped to (−π, π]; `None` when the direction is (nearly) zero or not
/// finite, so a drag through the gizmo's centre leaves the direction alone.
pub fn wave_direction_rad(a: f64, b: f64) -> Option<f64> {
    let r = a.hypot(b);
    (r.is_finite() && r > 1e-9).then(|| b.atan2(a))
}

/// The coordinates `(a, b)` with `a·su + b·sv = p` for 2D vectors (the screen images of û
/// and v̂ and the pointer's offset from the gizmo's centre); `None` when û and v̂ look edge-on
/// (their images nearly parallel: the plane cannot be pointed into from this view).
pub fn solve_in_basis(su: [f64; 2], sv: [f64; 2], p: [f64; 2]) -> Option<(f64, f64)> {
    let det = su[0] * sv[1] - su[1] * sv[0];
    let scale = (su[0].hypot(su[1]) * sv[0].hypot(sv[1])).max(f64::MIN_POSITIVE);
    let skew = det.abs() / scale;
    if skew.is_nan() || skew <= 0.05 {
        return None;
    }
    let a = (p[0] * sv[1] - p[1] * sv[0]) / det;
    let b = (su[0] * p[1] - su[1] * p[0]) / det;
    (a.is_finite() && b.is_finite()).then_some((a, b))
}

/// The twist rate that turns the bundle's tips by `tip_angle_rad` about ŵ over `length_m`,
/// held inside the parameter's valid range; `None` for a bare bundle or a non-finite angle.
pub fn twist_turns_per_m(tip_angle_rad: f64, length_m: f64) -> Option<f64> {
    if !(length_m > 1e-9 && tip_angle_rad.is_finite()) {
        return None;
    }
    let (lo, hi) = hard_range("twist.turns_per_m");
    Some((tip_angle_rad / (std::f64::consts::TAU * length_m)).clamp(lo, hi))
}

/// How far a twist of `turns_per_m` turns the tips of a bundle `length_m` long.
pub fn tip_twist_rad(turns_per_m: f64, length_m: f64) -> f64 {
    std::f64::consts::TAU * turns_per_m * length_m
}

impl StylingAxes {
    /// +1 when û × v̂ points along ŵ, −1 when against it (a mirrored uv layout). Generation
    /// twists about û × v̂, so a twist seen about ŵ turns by this sign.
    pub fn uv_sense(&self) -> f64 {
        if self.u.cross(self.v).dot(self.w) < 0.0 {
            -1.0
        } else {
            1.0
        }
    }

    /// How far a twist of `turns_per_m` turns the bundle's tips about ŵ (right-hand rule).
    pub fn tip_twist_about_w_rad(&self, turns_per_m: f64) -> f64 {
        self.uv_sense() * tip_twist_rad(turns_per_m, self.length_m)
    }

    /// The twist rate after a drag swept `swept_rad` about ŵ from a start of
    /// `start_turns_per_m`: unchanged for no sweep (exactly: a click is no edit), held in the
    /// valid range; `None` for a bare bundle.
    pub fn twist_after_sweep(&self, start_turns_per_m: f64, swept_rad: f64) -> Option<f64> {
        if swept_rad == 0.0 || !swept_rad.is_finite() {
            return Some(start_turns_per_m);
        }
        let change = twist_turns_per_m(self.uv_sense() * swept_rad, self.length_m)?;
        let (lo, hi) = hard_range("twist.turns_per_m");
        Some((start_turns_per_m + change).clamp(lo, hi))
    }

    /// Which way a curl of `turns_per_m` winds about ŵ: +1 counter-clockwise seen looking
    /// down ŵ toward the root (the right-hand rule), −1 clockwise, 0 for no curl. The helix
    /// turns from û toward v̂ as w grows, so the sense is the sign of the rate times that of
    /// `(û × v̂) · ŵ`.
    pub fn curl_sense(&self, turns_per_m: f64) -> f64 {
        if turns_per_m == 0.0 || !turns_per_m.is_finite() {
            return 0.0;
        }
        turns_per_m.signum() * self.uv_sense()
    }

    /// `turns_per_m` made to wind the way a drag about ŵ swept (its rate kept). A sweep
    /// smaller than `min_sweep_rad` changes nothing: a click is not a drag.
    pub fn curl_turns_for_sweep(
        &self,
        turns_per_m: f64,
        swept_rad: f64,
        min_sweep_rad: f64,
    ) -> f64 {
        if !swept_rad.is_finite() || swept_rad.abs() < min_sweep_rad {
            return turns_per_m;
        }
        if self.curl_sense(turns_per_m) * swept_rad < 0.0 {
            -turns_per_m
        } else {
            turns_per_m
        }
    }
}

/// The angle swept about `axis` from `from` to `to` (both projected into the plane across
/// `axis`), in (−π, π]; 0 when either is along the axis.
pub fn swept_about(axis: DVec3, from: DVec3, to: DVec3) -> f64 {
    let (Some(f), Some(t)) = (
        from.reject_from(axis).try_normalize(),
        to.reject_from(axis).try_normalize(),
    ) else {
        return 0.0;
    };
    f.cross(t).dot(axis.normalize()).atan2(f.dot(t))
}

/// Whose parameters a gizmo on `bundles` edits: `Ok(Some(g))` styling group `g`,
/// `Ok(None)` the global parameters (none of them is grouped); an error naming the mix when
/// they belong to different groups (one drag must not edit several sets).
pub fn shared_group(styling: &StylingSet, bundles: &[u32]) -> Result<Option<usize>, String> {
    let mut groups = bundles.iter().map(|&b| styling.group_of(b));
    let Some(first) = groups.next() else {
        return Err("no bundle is selected".into());
    };
    match groups.find(|g| *g != first) {
        None => Ok(first),
        Some(other) => {
            let name = |g: Option<usize>| {
                g.map_or("the global parameters".into(), |g| {
                    format!("group {}", styling.groups[g].name)
                })
            };
            Err(format!(
                "the selection mixes {} and {}: select one group's bundles",
                name(first),
                name(other)
            ))
        }
    }
}

fn hard_range(name: &str) -> (f64, f64) {
    HARD_RANGES
        .iter()
        .find(|(n, ..)| *n == name)
        .map_or((f64::MIN, f64::MAX), |&(_, lo, hi)| (lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::document::Document;
    use crate::model::mesh::test_meshes::grid;
    use crate::model::styling::StylingParams;
    use crate::strands::reference::{StrandOptions, generate};
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    fn hair_sized(layers: u32) -> HairMesh {
        let mut mesh = grid(3, 2, layers, 1.0);
        for column in &mut mesh.columns {
            for p in &mut column.positions {
                *p *= 0.01;
            }
        }
        mesh.update_w();
        mesh
    }

    #[test]
    fn the_frame_stands_at_the_roots_and_points_along_the_hair() {
        let mesh = hair_sized(3);
        let axes = styling_axes(&mesh, &[0]).expect("axes");
        // Bundle 0 is the quad [0, 1] × [0, 1] cm; layers go up +z by 1 cm.
        assert!(axes.origin.distance(DVec3::new(0.005, 0.005, 0.0)) < 1e-12);
        assert!(axes.w.distance(DVec3::Z) < 1e-9, "{:?}", axes.w);
        assert!((axes.length_m - 0.03).abs() < 1e-12);
        assert!(axes.u.dot(axes.w).abs() < 1e-6 && axes.v.dot(axes.w).abs() < 1e-6);
        // Several bundles: the centre of their roots, out-of-range indices ignored.
        let both = styling_axes(&mesh, &[0, 1, 99]).expect("axes");
        assert!(both.origin.distance(DVec3::new(0.01, 0.005, 0.0)) < 1e-12);
        // A bare bundle points along its root normal and has no length.
        let bare = styling_axes(&hair_sized(0), &[0]).expect("bare axes");
        assert_eq!(bare.length_m, 0.0);
        assert!(bare.w.cross(DVec3::Z).length() < 1e-9);
        // Nothing usable: no bundle, or roots collapsed to a point.
        assert_eq!(styling_axes(&mesh, &[]), None);
        assert_eq!(styling_axes(&mesh, &[99]), None);
        let mut collapsed = mesh.clone();
        for column in &mut collapsed.columns {
            for p in &mut column.positions {
                *p = DVec3::ZERO;
            }
        }
        assert_eq!(styling_axes(&collapsed, &[0]), None);
    }

    #[test]
    fn a_dragged_direction_becomes_the_wave_direction_it_points_along() {
        // A skewed basis on screen: the solve must use it, not assume orthogonal axes.
        let (su, sv) = ([40.0, 5.0], [12.0, -30.0]);
        for alpha in [0.0, 0.3, FRAC_PI_2, 2.0, PI, -2.5, -FRAC_PI_2] {
            let (c, s) = (f64::cos(alpha), f64::sin(alpha));
            let pointer = [2.0 * (c * su[0] + s * sv[0]), 2.0 * (c * su[1] + s * sv[1])];
            let (a, b) = solve_in_basis(su, sv, pointer).expect("solvable");
            let got = wave_direction_rad(a, b).expect("direction");
            assert!(
                (got - alpha)
                    .rem_euclid(TAU)
                    .min((alpha - got).rem_euclid(TAU))
                    < 1e-9,
                "{alpha} -> {got}"
            );
        }
        // At the centre, NaN, or edge-on: no direction (the old one stays).
        assert_eq!(wave_direction_rad(0.0, 0.0), None);
        assert_eq!(wave_direction_rad(f64::NAN, 1.0), None);
        assert_eq!(solve_in_basis([1.0, 0.0], [2.0, 0.001], [1.0, 1.0]), None);
        assert_eq!(solve_in_basis([0.0, 0.0], [0.0, 0.0], [1.0, 1.0]), None);
        assert_eq!(
            solve_in_basis([1.0, 0.0], [0.0, 1.0], [f64::INFINITY, 0.0]),
            None
        );
    }

    #[test]
    fn generated_strands_wave_along_the_arrow_the_gizmo_draws() {
        let mut document = Document::new("grid", hair_sized(3));
        let axes = styling_axes(&document.hair_mesh, &[0]).expect("axes");
        let options = StrandOptions {
            strands_per_bundle: 8,
            ..StrandOptions::default()
        };
        let plain = generate(&document, &options);
        for alpha in [0.4, 2.2, -1.1] {
            document.styling.global = StylingParams::default();
            document.styling.global.wave.amplitude_m = 0.004;
            document.styling.global.wave.frequency_per_m = 40.0;
            document.styling.global.wave.direction_rad = alpha;
            let waved = generate(&document, &options);
            let arrow = axes.wave_vector(alpha);
            let mut largest = 0.0f64;
            for (p, w) in plain.iter().zip(&waved).filter(|(s, _)| s.bundle == 0) {
                for (a, b) in p.points.iter().zip(&w.points) {
                    let offset = *b - *a;
                    largest = largest.max(offset.length());
                    // Every displacement is along the arrow (either way along it).
                    assert!(
                        offset.cross(arrow).length() <= 1e-9 + 1e-6 * offset.length(),
                        "alpha {alpha}: offset {offset:?} is not along {arrow:?}"
                    );
                }
            }
            assert!(largest > 1e-3, "alpha {alpha}: the wave moved the strands");
        }
    }

    #[test]
    fn twist_and_curl_follow_the_swept_angle() {
        // Turning the tips a quarter turn on a 5 cm bundle is 5 turns per metre.
        let turns = twist_turns_per_m(FRAC_PI_2, 0.05).expect("twist");
        assert!((turns - 5.0).abs() < 1e-12);
        assert!((tip_twist_rad(turns, 0.05) - FRAC_PI_2).abs() < 1e-12);
        // Held in the valid range; nothing for a bare bundle or a NaN drag.
        assert_eq!(twist_turns_per_m(1e9, 0.05), Some(1000.0));
        assert_eq!(twist_turns_per_m(-1e9, 0.05), Some(-1000.0));
        assert_eq!(twist_turns_per_m(1.0, 0.0), None);
        assert_eq!(twist_turns_per_m(f64::NAN, 0.05), None);
        // The right-hand rule about the axis.
        let swept = swept_about(DVec3::Z, DVec3::X, DVec3::Y);
        assert!((swept - FRAC_PI_2).abs() < 1e-12);
        assert!((swept_about(DVec3::Z, DVec3::Y, DVec3::X) + FRAC_PI_2).abs() < 1e-12);
        assert_eq!(swept_about(DVec3::Z, DVec3::Z, DVec3::X), 0.0);
        // A sweep sets the curl's sense and keeps its rate; a click changes nothing.
        let axes = styling_axes(&hair_sized(3), &[0]).expect("axes");
        let sense = axes.curl_sense(20.0);
        assert!(sense == 1.0 || sense == -1.0);
        assert_eq!(axes.curl_sense(-20.0), -sense);
        assert_eq!(axes.curl_sense(0.0), 0.0);
        let turned = axes.curl_turns_for_sweep(20.0, -0.5 * sense, 0.1);
        assert_eq!((turned, axes.curl_sense(turned)), (-20.0, -sense));
        assert_eq!(axes.curl_turns_for_sweep(20.0, 0.5 * sense, 0.1), 20.0);
        assert_eq!(axes.curl_turns_for_sweep(20.0, -0.05 * sense, 0.1), 20.0);
        assert_eq!(axes.curl_turns_for_sweep(20.0, f64::NAN, 0.1), 20.0);
    }

    #[test]
    fn the_twist_drawn_about_w_is_the_way_generated_strands_turn_even_with_mirrored_uvs() {
        for mirrored in [false, true] {
            let mut mesh = hair_sized(3);
            if mirrored {
                // Swap u for its mirror: û × v̂ then points against the hair.
                for bundle in &mut mesh.bundles {
                    for uv in &mut bundle.uvs {
                        uv.x = 1.0 - uv.x;
                    }
                }
            }
            let mut document = Document::new("grid", mesh);
            let axes = styling_axes(&document.hair_mesh, &[0]).expect("axes");
            assert_eq!(axes.uv_sense() < 0.0, mirrored, "{axes:?}");
            let options = StrandOptions {
                strands_per_bundle: 8,
                ..StrandOptions::default()
            };
            let plain = generate(&document, &options);
            // A quarter turn of the tips about ŵ, as the ring would set it.
            let turns = axes.twist_after_sweep(0.0, FRAC_PI_2).expect("twist");
            assert!((axes.tip_twist_about_w_rad(turns) - FRAC_PI_2).abs() < 1e-9);
            document.styling.global.twist.turns_per_m = turns;
            let twisted = generate(&document, &options);
            let centre = axes.origin + axes.w * axes.length_m;
            let (p, t) = plain
                .iter()
                .zip(&twisted)
                .filter(|(s, _)| s.bundle == 0)
                .max_by(|a, b| {
                    let d = |s: &crate::strands::reference::Strand| {
                        s.points.last().map_or(0.0, |p| p.distance(centre))
                    };
                    d(a.0).total_cmp(&d(b.0))
                })
                .expect("strands of bundle 0");
            let (from, to) = (
                *p.points.last().expect("tip") - centre,
                *t.points.last().expect("tip") - centre,
            );
            let turned = swept_about(axes.w, from, to);
            assert!(
                (turned - FRAC_PI_2).abs() < 0.15,
                "mirrored {mirrored}: the tips turned {turned} rad about w, drawn {FRAC_PI_2}"
            );
        }
        // No sweep, no change (bit for bit); a bare bundle cannot twist.
        let axes = styling_axes(&hair_sized(3), &[0]).expect("axes");
        assert_eq!(axes.twist_after_sweep(3.0, 0.0), Some(3.0));
        let bare = styling_axes(&hair_sized(0), &[0]).expect("bare");
        assert_eq!(bare.twist_after_sweep(3.0, 0.5), None);
    }

    #[test]
    fn the_curl_sense_drawn_is_the_way_generated_strands_wind() {
        let mut document = Document::new("grid", hair_sized(3));
        let axes = styling_axes(&document.hair_mesh, &[0]).expect("axes");
        let options = StrandOptions {
            strands_per_bundle: 4,
            vertices_log2: 6,
            ..StrandOptions::default()
        };
        let plain = generate(&document, &options);
        for turns in [30.0, -30.0] {
            document.styling.global = StylingParams::default();
            document.styling.global.curl.radius_m = 0.002;
            document.styling.global.curl.turns_per_m = turns;
            document.styling.global.curl.ramp_in_m = 0.0;
            let curled = generate(&document, &options);
            let (p, c) = plain
                .iter()
                .zip(&curled)
                .find(|(s, _)| s.bundle == 0)
                .expect("a strand of bundle 0");
            // The curl offset's angle about ŵ, summed along the strand.
            let offsets: Vec<DVec3> = p
                .points
                .iter()
                .zip(&c.points)
                .map(|(a, b)| *b - *a)
                .collect();
            let swept: f64 = offsets
                .windows(2)
                .map(|o| swept_about(axes.w, o[0], o[1]))
                .sum();
            assert!(
                swept.signum() == axes.curl_sense(turns) && swept.abs() > 1.0,
                "turns {turns}: swept {swept}, drawn sense {}",
                axes.curl_sense(turns)
            );
        }
    }

    #[test]
    fn one_drag_edits_one_set_of_parameters() {
        let mut styling = StylingSet::default();
        assert_eq!(shared_group(&styling, &[0, 1]), Ok(None));
        let g = styling.new_group("fringe", &[2, 3]);
        assert_eq!(shared_group(&styling, &[2, 3]), Ok(Some(g)));
        let mixed = shared_group(&styling, &[1, 2]).expect_err("mixed");
        assert!(
            mixed.contains("group fringe") && mixed.contains("global"),
            "{mixed}"
        );
        assert!(shared_group(&styling, &[]).is_err());
    }
}
