//! The bundle-level work of a frame (seed 000 §3.6): per bundle, culling against the view
//! and eq. 7-12 (strand count with thickness compensation, vertex level with morphing),
//! turned into batches of strand runs that fit the scratch buffer. `render` runs this on the
//! CPU once per frame and hands the runs to `strand_gen.wgsl`; the formulas themselves are
//! in [`crate::strands::lod`].

use crate::runtime::gpu_types::StrandRun;
use crate::strands::lod::{
    density_count, detail_level, strand_count, thickness_factor, vertex_lod,
};

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
    /// The fraction of its strands the bundle grows (`Bundle::density`; 1 for a full bundle).
    pub density: f32,
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
    /// The share of each bundle's strands drawn, in `[0, 1]` (1: all that LOD draws): fur's
    /// cross-fade lowers it as shells take over, dropping strands in their progressive order
    /// (so nothing pops) with no thickening.
    pub strand_keep: f64,
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
            strand_keep: 1.0,
        }
    }
}

impl LodSettings {
    /// These settings with LOD on and both α scaled by `detail ∈ (0, 1]`: a bias toward
    /// fewer strands (thickened to keep coverage, eq. 8) and fewer vertices, for frames that
    /// must cost less than the full picture (the editor's interactive frames). A
    /// non-finite or non-positive detail is taken as 1.
    pub fn with_detail(self, detail: f64) -> Self {
        let detail = if detail.is_finite() && detail > 0.0 {
            detail.min(1.0)
        } else {
            1.0
        };
        Self {
            enabled: true,
            alpha_strands: self.alpha_strands * detail,
            alpha_vertices: self.alpha_vertices * detail,
            ..self
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
    pub batches: Vec<Vec<StrandRun>>,
    pub strands: usize,
    pub vertices: usize,
    pub culled_bundles: usize,
    /// Bundles in view that far hair draws as thick hairs instead of strands.
    pub far_bundles: usize,
    /// The far-hair level of every bundle the plan was made with (empty: strands everywhere);
    /// the frame draws the thick hairs of exactly these.
    pub far_levels: Vec<u32>,
    /// Vertices of the frame's thick hairs: the most vertex LOD (eq. 7) gives any far bundle
    /// in view (at least 2; 0 without far bundles).
    pub far_vertex_count: u32,
}

impl FramePlan {
    /// Vertices of one batch.
    pub fn batch_vertices(batch: &[StrandRun]) -> usize {
        batch.last().map_or(0, |r| {
            (r.vertex_offset + r.strand_count * r.vertex_count) as usize
        })
    }

    /// Segments of one batch.
    pub fn batch_segments(batch: &[StrandRun]) -> usize {
        batch.last().map_or(0, |r| {
            (r.segment_offset + r.strand_count * r.vertex_count.saturating_sub(1)) as usize
        })
    }
}

/// Whether a sphere is at least partly inside the view frustum of `view_projection`.
pub(crate) fn sphere_in_view(
    view_projection: &glam::Mat4,
    centre: glam::Vec3,
    radius: f32,
) -> bool {
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

/// What LOD draws of one bundle: strands (with density), vertices per strand, the morph
/// factor and the thickness compensation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BundleLod {
    pub strands: u32,
    pub vertex_count: u32,
    pub gamma: f32,
    pub thickness: f32,
}

/// Eq. 7-12 for bundle `index` of `per_bundle` strands at full detail
/// `2^max_vertices_log2 + 1` vertices (culling aside): what [`plan_frame`] draws of it, and
/// what the mesh path's task shader computes on the GPU (`shaders/shared/strand_lod.wgsl`
/// `bundle_lod`, tested against this).
pub fn bundle_lod(
    index: u32,
    bounds: &BundleBounds,
    per_bundle: u32,
    max_vertices_log2: u32,
    camera: &LodCamera,
    settings: &LodSettings,
) -> BundleLod {
    let keep = if settings.strand_keep.is_nan() {
        1.0
    } else {
        settings.strand_keep.clamp(0.0, 1.0)
    };
    if !settings.enabled {
        let grown = density_count(bounds.density as f64, per_bundle);
        return BundleLod {
            strands: ((grown as f64 * keep).ceil() as u32).min(grown),
            vertex_count: (1u32 << max_vertices_log2) + 1,
            gamma: 0.0,
            thickness: 1.0,
        };
    }
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
    let delta = crate::strands::random::hash_to_unit(crate::strands::random::pcg_hash(index));
    // A thinned bundle (density < 1) drops strands at the same rate from its own count,
    // never drawing more than it grows at full detail.
    // Fur's cross-fade keeps a share of them the same way (`strand_lod.wgsl` alike).
    let density = bounds.density as f64;
    let strands = strand_count(strand_level * density * keep, per_bundle, delta)
        .min(density_count(density, per_bundle));
    let vertex_level = detail_level(
        bounds.strand_length_m as f64,
        resolution,
        distance,
        fov,
        settings.alpha_vertices,
    );
    let lod = vertex_lod(vertex_level, max_vertices_log2, settings.lambda);
    BundleLod {
        strands,
        vertex_count: lod.vertex_count(),
        gamma: lod.gamma as f32,
        thickness: thickness_factor(strand_level, per_bundle) as f32,
    }
}

/// Eq. 7-12 for every bundle of `per_bundle` strands (roots bundle-major, as
/// `RuntimeTextures::strand_roots` makes them), full detail `2^max_vertices_log2 + 1`
/// vertices: culling, strand counts with thickness compensation, vertex levels with morphing.
/// A bundle whose entry in `far_levels` is 1 or more draws far hair's thick hairs instead
/// (`crate::runtime::far_lod`) and has no strands here; an empty slice is strands everywhere.
pub fn plan_frame(
    bundles: &[BundleBounds],
    per_bundle: u32,
    max_vertices_log2: u32,
    camera: &LodCamera,
    settings: &LodSettings,
    batch_vertices: usize,
    far_levels: &[u32],
) -> FramePlan {
    let mut plan = FramePlan {
        far_levels: far_levels.to_vec(),
        ..FramePlan::default()
    };
    let mut batch: Vec<StrandRun> = Vec::new();
    let (mut vertex_offset, mut segment_offset) = (0u32, 0u32);
    for (index, bounds) in bundles.iter().enumerate() {
        if settings.cull && !sphere_in_view(&camera.view_projection, bounds.centre, bounds.radius_m)
        {
            plan.culled_bundles += 1;
            continue;
        }
        if far_levels.get(index).is_some_and(|&level| level > 0) {
            plan.far_bundles += 1;
            let lod = bundle_lod(
                index as u32,
                bounds,
                per_bundle,
                max_vertices_log2,
                camera,
                settings,
            );
            plan.far_vertex_count = plan.far_vertex_count.max(lod.vertex_count.max(2));
            continue;
        }
        let BundleLod {
            strands,
            vertex_count,
            gamma,
            thickness,
        } = bundle_lod(
            index as u32,
            bounds,
            per_bundle,
            max_vertices_log2,
            camera,
            settings,
        );
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
            batch.push(StrandRun {
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
                density: 1.0,
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
    fn less_detail_draws_fewer_strands_and_vertices_thicker() {
        let camera = camera(2.0, false);
        let plan_at =
            |settings: &LodSettings| plan_frame(&bundles(), 64, 5, &camera, settings, 1 << 20, &[]);
        // LOD off by the artist: the detail bias turns it on.
        let off = LodSettings {
            enabled: false,
            ..LodSettings::default()
        };
        let full = plan_at(&off.with_detail(1.0));
        assert!(off.with_detail(0.5).enabled);
        let mut previous = full.clone();
        for detail in [0.5, 0.25, 0.1, 0.02] {
            let plan = plan_at(&off.with_detail(detail));
            check_runs(&plan, 1 << 20);
            assert!(
                plan.strands < previous.strands,
                "detail {detail}: {} strands",
                plan.strands
            );
            assert!(plan.vertices < previous.vertices);
            // Thinned bundles draw thicker strands; every bundle keeps at least one.
            let thickest = plan
                .batches
                .iter()
                .flatten()
                .map(|r| r.thickness)
                .fold(1.0, f32::max);
            assert!(thickest > 1.0, "detail {detail}");
            assert!(plan.strands >= 40);
            previous = plan;
        }
        // Nonsense detail means none of the bias.
        for detail in [f64::NAN, 0.0, -1.0, f64::INFINITY, 7.0] {
            assert_eq!(
                plan_at(&LodSettings::default().with_detail(detail)),
                plan_at(&LodSettings::default())
            );
        }
    }

    #[test]
    fn lod_off_draws_every_strand_at_full_detail_in_bounded_batches() {
        let settings = LodSettings {
            enabled: false,
            ..LodSettings::default()
        };
        let plan = plan_frame(&bundles(), 64, 5, &camera(0.5, false), &settings, 1000, &[]);
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

    /// A thinned bundle grows ⌈density · N⌉ strands with LOD off, never more with LOD on
    /// close up, and still drops strands with distance; density 0 grows none.
    #[test]
    fn thinned_bundles_draw_their_share_of_strands() {
        let mut thinned = bundles();
        thinned[0].density = 0.35;
        thinned[1].density = 0.0;
        let off = LodSettings {
            enabled: false,
            ..LodSettings::default()
        };
        let plan = plan_frame(&thinned, 64, 5, &camera(0.3, false), &off, 1 << 20, &[]);
        // ⌈0.35 · 64⌉ = 23 (0.35 in f32 is a hair above 0.35).
        assert_eq!(plan.strands, 38 * 64 + 23);
        let roots = check_runs(&plan, 1 << 20);
        assert_eq!(
            &roots[..23],
            &(0..23).collect::<Vec<u32>>()[..],
            "first samples"
        );
        assert_eq!(
            roots[23], 128,
            "bundle 1 grows nothing, bundle 2 starts at 2 · 64"
        );
        let on = LodSettings::default();
        let near = plan_frame(&thinned, 64, 5, &camera(0.3, false), &on, 1 << 20, &[]);
        assert_eq!(near.strands, plan.strands, "close up, LOD keeps the share");
        let far = plan_frame(&thinned, 64, 5, &camera(20.0, false), &on, 1 << 20, &[]);
        let full_far = plan_frame(&bundles(), 64, 5, &camera(20.0, false), &on, 1 << 20, &[]);
        let first = |p: &FramePlan| {
            p.batches
                .iter()
                .flatten()
                .filter(|r| r.first_root < 64)
                .map(|r| r.strand_count)
                .sum::<u32>()
        };
        assert!(first(&far) < first(&full_far) && first(&far) >= 1);
    }

    #[test]
    fn distance_drops_strands_and_vertices_and_culling_drops_bundles() {
        let settings = LodSettings::default();
        let near = plan_frame(
            &bundles(),
            64,
            5,
            &camera(0.3, false),
            &settings,
            1 << 20,
            &[],
        );
        let far = plan_frame(
            &bundles(),
            64,
            5,
            &camera(20.0, false),
            &settings,
            1 << 20,
            &[],
        );
        let away = plan_frame(
            &bundles(),
            64,
            5,
            &camera(0.3, true),
            &settings,
            1 << 20,
            &[],
        );
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
            plan_frame(&bundles(), 64, 5, &camera(0.3, false), &settings, 10, &[]).strands,
            0
        );
    }

    #[test]
    fn bundles_far_hair_draws_have_no_strands() {
        let settings = LodSettings::default();
        let camera = camera(0.5, false);
        let all = plan_frame(&bundles(), 64, 5, &camera, &settings, 1 << 20, &[]);
        let mut levels = vec![0u32; 40];
        for level in levels.iter_mut().step_by(3) {
            *level = 2;
        }
        let far = plan_frame(&bundles(), 64, 5, &camera, &settings, 1 << 20, &levels);
        let far_count = levels.iter().filter(|&&l| l > 0).count();
        assert_eq!(far.far_bundles, far_count);
        // Thick hairs take the most vertices vertex LOD gives a far bundle.
        let most = all.batches.iter().flatten().map(|r| r.vertex_count).max();
        assert!(far.far_vertex_count >= 2 && Some(far.far_vertex_count) <= most);
        assert_eq!(all.far_vertex_count, 0);
        let roots = check_runs(&far, 1 << 20);
        assert!(roots.iter().all(|r| levels[(r / 64) as usize] == 0));
        let kept: Vec<u32> = check_runs(&all, 1 << 20)
            .into_iter()
            .filter(|r| levels[(r / 64) as usize] == 0)
            .collect();
        assert_eq!(roots, kept);
        // Levels shorter than the bundles leave the rest as strands.
        let short = plan_frame(&bundles(), 64, 5, &camera, &settings, 1 << 20, &[1]);
        let first_bundle = check_runs(&all, 1 << 20)
            .iter()
            .filter(|&&r| r < 64)
            .count();
        assert_eq!(short.far_bundles, 1);
        assert_eq!(short.strands, all.strands - first_bundle);
    }
}
