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
pub fn detail_level(
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
pub fn detail_level_for_extent(
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

/// Where one bundle's hair is, from the runtime textures (`RuntimeTextures::bundle_bounds`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BundleBounds {
    pub centre: glam::Vec3,
    /// Radius of a sphere around every control point of the bundle (culling, distance).
    pub radius_m: f32,
    /// Size of the bundle's root face (longest corner-to-corner distance): the `h` of strand
    /// LOD, as §3.6.1 suggests ("the bundle's scalp face size").
    pub root_size_m: f32,
    /// Length of the bundle's first column curve (control polygon), the `h` of vertex LOD.
    pub strand_length_m: f32,
}

/// Level-of-detail switches of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodSettings {
    /// Strand and vertex LOD (eq. 7-12); off draws every strand at full detail.
    pub enabled: bool,
    /// Bundles whose bounding sphere is outside the view are skipped.
    pub cull: bool,
    pub alpha_strands: f64,
    pub alpha_vertices: f64,
    pub lambda: f64,
}

/// Default α of strand LOD: every strand while a bundle's root face spans ≥ 20 pixels;
/// below that, strands drop in proportion (and thicken to compensate).
pub const DEFAULT_ALPHA_STRANDS: f64 = 0.05;
/// Default α of vertex LOD: full detail while a strand spans ≥ 50 pixels (32 segments:
/// ~1.5 pixels each); curly styles may want more (seed 000 Fig. 6).
pub const DEFAULT_ALPHA_VERTICES: f64 = 0.02;
/// Default morph window λ (eq. 10-12).
pub const DEFAULT_LAMBDA: f64 = 0.5;

impl Default for LodSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            cull: true,
            alpha_strands: DEFAULT_ALPHA_STRANDS,
            alpha_vertices: DEFAULT_ALPHA_VERTICES,
            lambda: DEFAULT_LAMBDA,
        }
    }
}

/// The camera as LOD sees it.
#[derive(Clone, Copy, Debug)]
pub struct LodCamera {
    pub eye: glam::Vec3,
    /// Clip space with depth in `[0, 1]` (wgpu).
    pub view_projection: glam::Mat4,
    pub fov_y_rad: f32,
    pub resolution_px: f32,
}

/// The bundle-level work of one frame: which strands to generate at which detail, split into
/// batches of at most `batch_vertices` vertices (the scratch buffer's size).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FramePlan {
    pub batches: Vec<Vec<crate::gpu_types::StrandRun>>,
    pub strands: usize,
    pub vertices: usize,
    pub culled_bundles: usize,
}

impl FramePlan {
    /// Vertices of one batch.
    pub fn batch_vertices(batch: &[crate::gpu_types::StrandRun]) -> usize {
        batch.last().map_or(0, |r| {
            (r.vertex_offset + r.strand_count * r.vertex_count) as usize
        })
    }

    /// Segments of one batch.
    pub fn batch_segments(batch: &[crate::gpu_types::StrandRun]) -> usize {
        batch.last().map_or(0, |r| {
            (r.segment_offset + r.strand_count * r.vertex_count.saturating_sub(1)) as usize
        })
    }
}

/// Whether a sphere is at least partly inside the view frustum of `view_projection`.
pub fn sphere_in_view(view_projection: &glam::Mat4, centre: glam::Vec3, radius: f32) -> bool {
    let m = view_projection.transpose(); // rows of the matrix as columns
    let (r0, r1, r2, r3) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
    let point = centre.extend(1.0);
    [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2]
        .iter()
        .all(|plane| {
            let length = plane.truncate().length();
            length.is_nan() || length <= 0.0 || plane.dot(point) / length >= -radius
        })
}

/// Eq. 7-12 for every bundle of `per_bundle` strands (roots bundle-major, as
/// `RuntimeTextures::strand_roots` makes them), full detail `2^max_vertices_log2 + 1`
/// vertices: culling, strand counts with thickness compensation, vertex levels with morphing.
pub fn plan_frame(
    bundles: &[BundleBounds],
    per_bundle: u32,
    max_vertices_log2: u32,
    camera: &LodCamera,
    settings: &LodSettings,
    batch_vertices: usize,
) -> FramePlan {
    let mut plan = FramePlan::default();
    let mut batch: Vec<crate::gpu_types::StrandRun> = Vec::new();
    let (mut vertex_offset, mut segment_offset) = (0u32, 0u32);
    let full_vertices = (1u32 << max_vertices_log2) + 1;
    for (index, bounds) in bundles.iter().enumerate() {
        if settings.cull && !sphere_in_view(&camera.view_projection, bounds.centre, bounds.radius_m)
        {
            plan.culled_bundles += 1;
            continue;
        }
        let (strands, vertex_count, gamma, thickness) = if settings.enabled {
            // Eq. 7 with the minimum distance of the bundle to the camera.
            let distance = (bounds.centre.distance(camera.eye) - bounds.radius_m).max(0.0) as f64;
            let (resolution, fov) = (camera.resolution_px as f64, camera.fov_y_rad as f64);
            let strand_level = detail_level(
                bounds.root_size_m as f64,
                resolution,
                distance,
                fov,
                settings.alpha_strands,
            );
            let delta = crate::random::hash_to_unit(crate::random::pcg_hash(index as u32));
            let count = strand_count(strand_level, per_bundle, delta);
            let vertex_level = detail_level(
                bounds.strand_length_m as f64,
                resolution,
                distance,
                fov,
                settings.alpha_vertices,
            );
            let lod = vertex_lod(vertex_level, max_vertices_log2, settings.lambda);
            (
                count,
                lod.vertex_count(),
                lod.gamma as f32,
                thickness_factor(strand_level, per_bundle) as f32,
            )
        } else {
            (per_bundle, full_vertices, 0.0, 1.0)
        };
        let mut first_root = index as u32 * per_bundle;
        let mut remaining = strands;
        while remaining > 0 {
            let room = (batch_vertices as u32).saturating_sub(vertex_offset) / vertex_count;
            if room == 0 {
                if batch.is_empty() {
                    // One strand does not fit an empty batch: nothing can be drawn.
                    return plan;
                }
                plan.batches.push(std::mem::take(&mut batch));
                (vertex_offset, segment_offset) = (0, 0);
                continue;
            }
            let taken = remaining.min(room);
            batch.push(crate::gpu_types::StrandRun {
                first_root,
                strand_count: taken,
                vertex_count,
                vertex_offset,
                segment_offset,
                gamma,
                thickness,
                _padding: 0,
            });
            vertex_offset += taken * vertex_count;
            segment_offset += taken * (vertex_count - 1);
            plan.strands += taken as usize;
            plan.vertices += (taken * vertex_count) as usize;
            first_root += taken;
            remaining -= taken;
        }
    }
    if !batch.is_empty() {
        plan.batches.push(batch);
    }
    plan
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bundles() -> Vec<BundleBounds> {
        (0..40)
            .map(|i| BundleBounds {
                centre: glam::Vec3::new((i % 8) as f32 * 0.02, (i / 8) as f32 * 0.02, 0.0),
                radius_m: 0.1,
                root_size_m: 0.03,
                strand_length_m: 0.2,
            })
            .collect()
    }

    fn camera(distance: f32, look_away: bool) -> LodCamera {
        let eye = glam::Vec3::new(0.07, 0.04, distance);
        let target = if look_away {
            eye + glam::Vec3::Z
        } else {
            glam::Vec3::new(0.07, 0.04, 0.0)
        };
        let fov_y_rad = 30f32.to_radians();
        LodCamera {
            eye,
            view_projection: glam::Mat4::perspective_rh(fov_y_rad, 1.0, 0.01, 100.0)
                * glam::Mat4::look_at_rh(eye, target, glam::Vec3::Y),
            fov_y_rad,
            resolution_px: 1000.0,
        }
    }

    /// Every run's roots, in order, and the batch bound.
    fn check_runs(plan: &FramePlan, batch_vertices: usize) -> Vec<u32> {
        let mut roots = Vec::new();
        for batch in &plan.batches {
            assert!(FramePlan::batch_vertices(batch) <= batch_vertices);
            let (mut vertex, mut segment) = (0, 0);
            for run in batch {
                assert_eq!((run.vertex_offset, run.segment_offset), (vertex, segment));
                vertex += run.strand_count * run.vertex_count;
                segment += run.strand_count * (run.vertex_count - 1);
                roots.extend(run.first_root..run.first_root + run.strand_count);
                assert!(run.gamma.is_finite() && (0.0..=1.0).contains(&run.gamma));
                assert!(run.thickness >= 1.0);
            }
        }
        roots
    }

    #[test]
    fn lod_off_draws_every_strand_at_full_detail_in_bounded_batches() {
        let settings = LodSettings {
            enabled: false,
            ..LodSettings::default()
        };
        let plan = plan_frame(&bundles(), 64, 5, &camera(0.5, false), &settings, 1000);
        assert_eq!(plan.strands, 40 * 64);
        assert_eq!(plan.vertices, 40 * 64 * 33);
        // 30 strands of 33 vertices fit a batch of 1000.
        assert_eq!(plan.batches.len(), (40 * 64usize).div_ceil(30));
        let roots = check_runs(&plan, 1000);
        assert_eq!(
            roots,
            (0..40 * 64).collect::<Vec<u32>>(),
            "each root once, in order"
        );
    }

    #[test]
    fn distance_drops_strands_and_vertices_and_culling_drops_bundles() {
        let settings = LodSettings::default();
        let near = plan_frame(&bundles(), 64, 5, &camera(0.3, false), &settings, 1 << 20);
        let far = plan_frame(&bundles(), 64, 5, &camera(20.0, false), &settings, 1 << 20);
        let away = plan_frame(&bundles(), 64, 5, &camera(0.3, true), &settings, 1 << 20);
        assert_eq!(near.strands, 40 * 64, "close up, everything");
        assert!(
            far.strands < near.strands / 4 && far.strands >= 40,
            "{}",
            far.strands
        );
        assert!(far.vertices * 8 < near.vertices);
        assert!(far.batches[0].iter().all(|r| r.thickness > 1.0));
        assert_eq!((away.strands, away.culled_bundles), (0, 40));
        check_runs(&far, 1 << 20);
        // A strand larger than the batch: nothing, not a hang.
        assert_eq!(
            plan_frame(&bundles(), 64, 5, &camera(0.3, false), &settings, 10).strands,
            0
        );
    }

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
