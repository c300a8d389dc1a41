//! Level of detail (seed 000 §3.6, eq. 7-12) and strand tangents (§3.5, eq. 5-6), as pure
//! functions. The GPU evaluates the same formulas; these are the reference.
//!
//! Every function returns finite values for any input, including `L = 0`, `λ = 0`,
//! zero distances and coincident vertices.

use glam::DVec3;

/// Eq. 7: detail level `L = min(1, h R α / (d tan θ))` for a perspective camera, with
/// `h` the world-space size that matters (bundle size for strand LOD, strand length for
/// vertex LOD), `R` the vertical resolution in pixels, `d` the distance to the camera and
/// `θ` the camera's field of view. Non-positive or non-finite denominators give `L = 1`
/// (the camera is at the hair, draw everything); negative or NaN numerators give `L = 0`.
pub(crate) fn detail_level(
    size_m: f64,
    resolution_px: f64,
    distance_m: f64,
    fov_rad: f64,
    alpha: f64,
) -> f64 {
    detail_level_for_extent(size_m, resolution_px, distance_m * fov_rad.tan(), alpha)
}

/// Eq. 7 with the view extent given directly: `L = min(1, h R α / extent)`. For an
/// orthographic camera (shadow maps of directional lights) the extent is the view height.
pub(crate) fn detail_level_for_extent(
    size_m: f64,
    resolution_px: f64,
    view_extent_m: f64,
    alpha: f64,
) -> f64 {
    let numerator = size_m * resolution_px * alpha;
    if !(view_extent_m > 0.0 && view_extent_m.is_finite()) {
        return 1.0;
    }
    let level = numerator / view_extent_m;
    if level.is_nan() {
        0.0
    } else {
        level.clamp(0.0, 1.0)
    }
}

/// Eq. 8: strands to draw in a bundle of `strands` strands, `⌈L (N + δ)⌉`, where
/// `delta ∈ [0, 1)` is the bundle's random increment (so bundles drop strands at different
/// `L`). At least one strand for `L > 0`, none for `L = 0`, never more than `N`.
pub fn strand_count(level: f64, strands: u32, delta: f64) -> u32 {
    let level = if level.is_nan() {
        0.0
    } else {
        level.clamp(0.0, 1.0)
    };
    let delta = if delta.is_nan() {
        0.0
    } else {
        delta.clamp(0.0, 1.0 - f64::EPSILON)
    };
    let count = (level * (strands as f64 + delta)).ceil();
    (count as u32).min(strands)
}

/// Strands a bundle of `strands` grows at `density` (the fraction that grow, see
/// `Bundle::density`): `⌈density · N⌉`, none for 0 (or NaN), all for 1.
pub fn density_count(density: f64, strands: u32) -> u32 {
    let density = if density.is_nan() {
        0.0
    } else {
        density.clamp(0.0, 1.0)
    };
    ((density * strands as f64).ceil() as u32).min(strands)
}

/// The share of its `per_bundle` strands a bundle grows: its own `density` (the share the
/// artist set; NaN grows nothing), times, where its styling asks for `strands_per_cm2 > 0`,
/// the share that gives that many strands per cm² of its root face (`root_area_m2`, model
/// units taken as metres), at most all of them ([`crate::model::styling::Density`]).
/// A non-finite or negative area or target leaves the density alone.
pub fn grown_share(density: f64, strands_per_cm2: f64, root_area_m2: f64, per_bundle: u32) -> f64 {
    let density = if density.is_nan() {
        0.0
    } else {
        density.clamp(0.0, 1.0)
    };
    let wanted = strands_per_cm2 * root_area_m2 * 1.0e4;
    if strands_per_cm2.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        || !wanted.is_finite()
        || wanted < 0.0
        || per_bundle == 0
    {
        return density;
    }
    density * (wanted / per_bundle as f64).min(1.0)
}

#[cfg(test)]
mod density_tests {
    use super::{density_count, grown_share};

    #[test]
    fn a_per_area_target_makes_strand_counts_follow_face_area() {
        // Off: the artist's share alone.
        assert_eq!(grown_share(0.5, 0.0, 1.0e-4, 64), 0.5);
        // 40 a cm² over faces of 1 cm² and 0.25 cm², 64 strands a bundle: 40 and 10.
        let big = density_count(grown_share(1.0, 40.0, 1.0e-4, 64), 64);
        let small = density_count(grown_share(1.0, 40.0, 0.25e-4, 64), 64);
        assert_eq!((big, small), (40, 10));
        // Capped at all of them; the artist's share still thins.
        assert_eq!(grown_share(1.0, 400.0, 1.0e-4, 64), 1.0);
        assert_eq!(grown_share(0.5, 400.0, 1.0e-4, 64), 0.5);
        // Degenerate inputs leave the share alone or grow nothing, never NaN.
        for (density, target, area, n) in [
            (1.0, f64::NAN, 1.0e-4, 64),
            (1.0, 40.0, f64::NAN, 64),
            (1.0, 40.0, -1.0, 64),
            (1.0, f64::INFINITY, 1.0e-4, 64),
            (1.0, 40.0, 1.0e-4, 0),
        ] {
            assert_eq!(grown_share(density, target, area, n), 1.0);
        }
        assert_eq!(grown_share(f64::NAN, 40.0, 1.0e-4, 64), 0.0);
        assert_eq!(
            grown_share(1.0, 40.0, 0.0, 64),
            0.0,
            "a face of no area grows none"
        );
    }

    #[test]
    fn density_count_rounds_up_and_stays_in_range() {
        assert_eq!(density_count(1.0, 64), 64);
        assert_eq!(density_count(0.5, 64), 32);
        assert_eq!(density_count(0.34, 64), 22, "21.76 rounds up");
        assert_eq!(
            density_count(0.001, 64),
            1,
            "a thinned bundle keeps a strand"
        );
        assert_eq!(density_count(0.0, 64), 0);
        assert_eq!(density_count(f64::NAN, 64), 0);
        assert_eq!(density_count(7.0, 64), 64);
        assert_eq!(density_count(-1.0, 64), 0);
    }
}

/// Thickness factor that compensates for dropped strands: `min(1/L, N)` (eq. 8 text).
/// Equals `N` as `L → 0` and 1 for `L = 1`.
pub fn thickness_factor(level: f64, strands: u32) -> f64 {
    let cap = strands.max(1) as f64;
    // NaN and non-positive levels: the bundle is (nearly) gone, use the full compensation.
    if level.is_nan() || level <= 0.0 {
        return cap;
    }
    (1.0 / level).min(cap).max(1.0)
}

/// Vertex level of detail for one strand.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexLod {
    /// Eq. 9: the strand has `2^e + 1` vertices.
    pub e: u32,
    /// Eq. 10: the next coarser level (`e_tilde ≤ e`).
    pub e_tilde: u32,
    /// Eq. 12: morph factor toward the coarser level, in `[0, 1]`; 0 when `e == e_tilde`.
    pub gamma: f64,
}

impl VertexLod {
    pub fn vertex_count(&self) -> u32 {
        (1u32 << self.e) + 1
    }
}

/// Eq. 9, 10 and 12 for a full-detail strand of `2^max_e + 1` vertices (`ns = 2^max_e`),
/// detail level `L` and transition window `λ ∈ [0, 1]`. `λ = 0` means no morphing (levels
/// switch abruptly); `L → 0` gives `e = 0` (two vertices).
pub fn vertex_lod(level: f64, max_e: u32, lambda: f64) -> VertexLod {
    let level = if level.is_nan() {
        0.0
    } else {
        level.clamp(0.0, 1.0)
    };
    let lambda = if lambda.is_nan() {
        0.0
    } else {
        lambda.clamp(0.0, 1.0)
    };
    let x = (level * (1u64 << max_e) as f64).log2(); // log2(L n s); −∞ for L = 0
    let clamp_e = |v: f64| {
        if v.is_nan() {
            0
        } else {
            v.max(0.0).min(max_e as f64) as u32
        }
    };
    let e = clamp_e(x.ceil());
    let e_tilde = clamp_e((x - lambda).ceil());
    let gamma = if e > e_tilde && lambda > 0.0 {
        (1.0 - (x - e_tilde as f64) / lambda).clamp(0.0, 1.0)
    } else {
        0.0
    };
    VertexLod { e, e_tilde, gamma }
}

/// Eq. 11: moves odd vertices toward the midpoint of their neighbours by `gamma`.
pub fn morph_odd_vertices(points: &mut [DVec3], gamma: f64) {
    if gamma <= 0.0 || points.len() < 3 {
        return;
    }
    for k in (1..points.len() - 1).step_by(2) {
        let middle = (points[k - 1] + points[k + 1]) * 0.5;
        points[k] = points[k].lerp(middle, gamma);
    }
}

/// Eq. 5-6: unit tangents of a polyline. Inner vertices use `p_{k+1} − p_{k−1}`; the ends
/// mirror the neighbouring tangent about the end segment, so the end tangents keep the same
/// angle to their segment when the vertex count changes. Coincident vertices borrow the
/// nearest defined tangent; a polyline with no extent gets +y everywhere.
pub fn tangents(points: &[DVec3]) -> Vec<DVec3> {
    let n = points.len();
    if n < 2 {
        return vec![DVec3::Y; n];
    }
    let mut raw: Vec<Option<DVec3>> = (0..n)
        .map(|k| {
            if k == 0 || k == n - 1 {
                None
            } else {
                (points[k + 1] - points[k - 1]).try_normalize()
            }
        })
        .collect();
    let segment = |k: usize| (points[k] - points[k - 1]).try_normalize();
    if n == 2 {
        let t = segment(1);
        raw[0] = t;
        raw[1] = t;
    } else {
        // Eq. 5 (tip) and eq. 6 (root): reflect the neighbour's tangent about the segment.
        let reflect = |t: Option<DVec3>, q: Option<DVec3>| match (t, q) {
            (Some(t), Some(q)) => (2.0 * q * t.dot(q) - t).try_normalize(),
            (None, q) => q,
            (t, None) => t,
        };
        raw[n - 1] = reflect(raw[n - 2], segment(n - 1));
        raw[0] = reflect(raw[1], segment(1));
    }
    fill_missing(raw)
}

/// Tangents for a morphing strand: `t' = (1 − γ) t + γ t̃`, where `t̃` uses only the even
/// vertices (odd ones average their neighbours), as in §3.6.2.
pub fn morphed_tangents(points: &[DVec3], gamma: f64) -> Vec<DVec3> {
    let fine = tangents(points);
    if gamma <= 0.0 || points.len() < 3 {
        return fine;
    }
    let even: Vec<DVec3> = points.iter().step_by(2).copied().collect();
    let coarse = tangents(&even);
    (0..points.len())
        .map(|k| {
            let t_tilde = if k % 2 == 0 {
                coarse[k / 2]
            } else {
                let next = coarse.get(k / 2 + 1).copied().unwrap_or(coarse[k / 2]);
                (coarse[k / 2] + next) * 0.5
            };
            fine[k]
                .lerp(t_tilde, gamma)
                .try_normalize()
                .unwrap_or(fine[k])
        })
        .collect()
}

fn fill_missing(raw: Vec<Option<DVec3>>) -> Vec<DVec3> {
    let n = raw.len();
    (0..n)
        .map(|k| {
            if let Some(t) = raw[k] {
                return t;
            }
            (1..n)
                .find_map(|d| {
                    let before = k.checked_sub(d).and_then(|i| raw[i]);
                    before.or_else(|| raw.get(k + d).copied().flatten())
                })
                .unwrap_or(DVec3::Y)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detail_level_is_clamped_and_finite() {
        assert_eq!(detail_level(0.1, 1080.0, 0.0, 0.8, 0.01), 1.0);
        assert_eq!(detail_level(0.1, 1080.0, -3.0, 0.8, 0.01), 1.0);
        assert_eq!(detail_level(0.0, 1080.0, 3.0, 0.8, 0.01), 0.0);
        assert_eq!(detail_level(f64::NAN, 1080.0, 3.0, 0.8, 0.01), 0.0);
        let far = detail_level(0.02, 1080.0, 50.0, 0.8, 0.01);
        assert!(far > 0.0 && far < 1.0);
        // Twice as far, half the level (below the clamp).
        let farther = detail_level(0.02, 1080.0, 100.0, 0.8, 0.01);
        assert!((far / farther - 2.0).abs() < 1e-12);
    }

    #[test]
    fn strand_counts_follow_eq_8() {
        assert_eq!(strand_count(1.0, 64, 0.5), 64);
        assert_eq!(strand_count(0.0, 64, 0.9), 0);
        assert_eq!(strand_count(1e-9, 64, 0.0), 1, "any L > 0 keeps one strand");
        assert_eq!(strand_count(0.5, 64, 0.0), 32);
        assert_eq!(strand_count(0.5, 64, 0.99), 33);
        // Monotone in L.
        let mut last = 0;
        for i in 0..=1000 {
            let c = strand_count(i as f64 / 1000.0, 64, 0.37);
            assert!(c >= last);
            last = c;
        }
        assert_eq!(thickness_factor(1.0, 64), 1.0);
        assert_eq!(thickness_factor(0.25, 64), 4.0);
        assert_eq!(thickness_factor(0.0, 64), 64.0);
        assert_eq!(thickness_factor(1e-12, 64), 64.0);
    }

    #[test]
    fn gamma_stays_in_range_and_is_continuous_in_l() {
        for lambda in [0.0, 0.25, 0.5, 1.0] {
            let mut previous: Option<(f64, Vec<DVec3>)> = None;
            let steps = 20_000;
            for i in 1..=steps {
                let level = i as f64 / steps as f64;
                let lod = vertex_lod(level, 5, lambda);
                assert!((0.0..=1.0).contains(&lod.gamma), "{lod:?}");
                assert!(lod.e >= lod.e_tilde && lod.e <= 5);
                // The drawn shape (a strand at this LOD) changes continuously when λ > 0.
                let shape = lod_shape(lod);
                if let Some((_, last)) = &previous
                    && lambda > 0.0
                {
                    let jump = max_distance(&shape, last);
                    assert!(jump < 0.02, "λ {lambda}, L {level}: jump {jump}");
                }
                previous = Some((level, shape));
            }
        }
    }

    /// A wavy test strand sampled at a LOD, morphed, and resampled densely for comparison.
    fn lod_shape(lod: VertexLod) -> Vec<DVec3> {
        let count = lod.vertex_count() as usize;
        let mut points: Vec<DVec3> = (0..count)
            .map(|k| {
                let t = k as f64 / (count - 1) as f64;
                DVec3::new((t * 20.0).sin() * 0.1, t, 0.0)
            })
            .collect();
        morph_odd_vertices(&mut points, lod.gamma);
        (0..=200)
            .map(|i| {
                let t = i as f64 / 200.0 * (count - 1) as f64;
                let k = (t.floor() as usize).min(count - 2);
                points[k].lerp(points[k + 1], t - k as f64)
            })
            .collect()
    }

    fn max_distance(a: &[DVec3], b: &[DVec3]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(p, q)| p.distance(*q))
            .fold(0.0, f64::max)
    }

    #[test]
    fn fully_morphed_strand_equals_the_lower_level() {
        // At the start of the window (γ = 1) the e-level strand lies on the (e−1)-level one.
        let lod = vertex_lod(0.5 + 1e-9, 5, 0.5);
        // log2(L·32) is just above 4: 33 vertices morphing toward 17.
        assert_eq!((lod.e, lod.e_tilde), (5, 4));
        assert!(lod.gamma > 1.0 - 1e-6);
        let fine = lod_shape(VertexLod { gamma: 1.0, ..lod });
        let coarse = lod_shape(VertexLod {
            e: 4,
            e_tilde: 4,
            gamma: 0.0,
        });
        assert!(max_distance(&fine, &coarse) < 1e-12);
        // Without morphing the two levels differ visibly (the wave is under-sampled).
        let unmorphed = lod_shape(VertexLod { gamma: 0.0, ..lod });
        assert!(max_distance(&unmorphed, &coarse) > 1e-3);
    }

    #[test]
    fn lambda_zero_and_vanishing_l_are_safe() {
        let lod = vertex_lod(0.3, 5, 0.0);
        assert_eq!(lod.gamma, 0.0);
        assert_eq!(lod.e, lod.e_tilde);
        for level in [0.0, 1e-300, f64::MIN_POSITIVE, -1.0, f64::NAN] {
            let lod = vertex_lod(level, 5, 0.5);
            assert_eq!(lod.e, 0);
            assert_eq!(lod.vertex_count(), 2);
            assert!(lod.gamma.is_finite());
        }
        assert_eq!(vertex_lod(1.0, 5, 0.5).e, 5);
    }

    #[test]
    fn end_tangents_keep_their_angle_to_the_end_segment() {
        let points: Vec<DVec3> = (0..9)
            .map(|k| {
                let t = k as f64 / 8.0;
                DVec3::new(t.sin(), t * t, 0.3 * t)
            })
            .collect();
        let t = tangents(&points);
        let n = points.len();
        let q_tip = (points[n - 1] - points[n - 2]).normalize();
        assert!((t[n - 1].dot(q_tip) - t[n - 2].dot(q_tip)).abs() < 1e-12);
        let q_root = (points[1] - points[0]).normalize();
        assert!((t[0].dot(q_root) - t[1].dot(q_root)).abs() < 1e-12);
        for tangent in &t {
            assert!((tangent.length() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn degenerate_polylines_get_finite_unit_tangents() {
        let same = vec![DVec3::ONE; 5];
        assert!(tangents(&same).iter().all(|t| *t == DVec3::Y));
        let mut stall = vec![DVec3::ZERO, DVec3::ZERO, DVec3::X, DVec3::X, DVec3::X * 2.0];
        stall.push(DVec3::X * 2.0);
        for t in tangents(&stall)
            .iter()
            .chain(&morphed_tangents(&stall, 0.5))
        {
            assert!(t.is_finite() && (t.length() - 1.0).abs() < 1e-12, "{t}");
        }
        // Fold-back: the strand turns 180°.
        let fold = vec![DVec3::ZERO, DVec3::X, DVec3::ZERO];
        assert!(tangents(&fold).iter().all(|t| t.is_finite()));
        assert_eq!(tangents(&[]).len(), 0);
        assert_eq!(tangents(&[DVec3::ZERO]), vec![DVec3::Y]);
    }
}
