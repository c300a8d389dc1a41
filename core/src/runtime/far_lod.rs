//! Far hair's deferred level choice (seed 001 §5.2, eq. 16), the CPU mirror of
//! `shaders/far_lod.wgsl` (same names: `thick_widths`, `next_levels`). Each frame measures,
//! for every bundle, the widest its thick hairs look in pixels at the level it draws (`w_cur`)
//! and at the next coarser one (`w_cur−`), from the thick hairs as generated this frame
//! (`thick_main`: they follow the hair mesh), and chooses the next frame's level:
//! finer when `w_cur > ε_w`, coarser when `w_cur− ≤ ε_w`, else the same. Widths only grow
//! with the level, so the rule settles and never oscillates under a still camera (tested).
//!
//! Levels count as in [`crate::runtime::thick_hair::FarHair`]: 0 draws the strands, `j ≥ 1`
//! the thick hairs of level `j`; a bundle drawing strands measures level 1 to know when to
//! leave them (strands are never too wide: they are what far hair widens from).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::runtime::frame_plan::BundleBounds;
use crate::runtime::gpu_types::ThickHairGpu;
use crate::runtime::strand_gen::ThickVertex;
use crate::runtime::thick_hair::FarHair;

/// Uniform parameters of the level choice.
/// Keep in sync with `shaders/far_lod.wgsl` (`FarLodParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FarLodParams {
    /// The camera's position (w unused).
    pub eye: [f32; 4],
    /// World size of a pixel at unit distance.
    pub pixel_at_unit: f32,
    /// ε_w: the widest a drawn thick hair may look, in pixels.
    pub width_threshold_px: f32,
    /// Vertices per measured thick hair.
    pub vertex_count: u32,
    /// Measured thick hairs.
    pub count: u32,
}

/// The thick hairs a frame measures for bundles drawing `levels`: each bundle's current level
/// (from 1 up) and the next coarser one where it has one.
pub fn measured_hairs(far: &FarHair, levels: &[u32]) -> Vec<ThickHairGpu> {
    let mut out = Vec::new();
    for (block, block_levels) in far.blocks.iter().enumerate() {
        let current = levels.get(block).copied().unwrap_or(0) as usize;
        for level in [current, current + 1] {
            if level == 0 {
                continue;
            }
            if let Some(entry) = block_levels.get(level - 1) {
                out.extend_from_slice(
                    &far.thick_hairs[entry.first as usize..][..entry.count as usize],
                );
            }
        }
    }
    out
}

/// The thick hairs a frame draws for bundles drawing `levels`: each bundle's current level,
/// where it is 1 or more (level 0 draws the bundle's strands).
pub fn drawn_hairs(far: &FarHair, levels: &[u32]) -> Vec<ThickHairGpu> {
    let mut out = Vec::new();
    for (block, block_levels) in far.blocks.iter().enumerate() {
        let level = levels.get(block).copied().unwrap_or(0) as usize;
        if level == 0 {
            continue;
        }
        if let Some(entry) = block_levels.get(level - 1) {
            out.extend_from_slice(&far.thick_hairs[entry.first as usize..][..entry.count as usize]);
        }
    }
    out
}

/// Where the level choice starts when there is no last frame to measure (a first frame, a
/// still render): per bundle, the coarsest level whose widest fitted diameter fits half of
/// `threshold_px` at the bundle's nearest point to the eye ([`FarHair::level_for`]). Half:
/// the fit's diameter is the members' spread, and the corner strands a frame measures span
/// up to about twice that; eq. 16 then corrects the guess within a few frames.
pub fn first_levels(
    far: &FarHair,
    bundles: &[BundleBounds],
    eye: Vec3,
    pixel_at_unit: f32,
    threshold_px: f32,
) -> Vec<u32> {
    (0..far.blocks.len())
        .map(|block| {
            let Some(bounds) = bundles.get(block) else {
                return 0;
            };
            let distance = (bounds.centre.distance(eye) - bounds.radius_m).max(0.0);
            far.level_for(
                block,
                f64::from(pixel_at_unit * distance),
                0.5 * f64::from(threshold_px),
            ) as u32
        })
        .collect()
}

/// How wide a thick hair's vertex looks in pixels: its ellipse across the view
/// (`2 √((major·s)² + (minor·s)²)`, `s` the ribbon's side) over a pixel at its distance; the
/// larger diameter when it is seen along its tangent.
pub fn thick_width_px(
    centre: Vec3,
    tangent: Vec3,
    major: Vec3,
    minor: Vec3,
    eye: Vec3,
    pixel_at_unit: f32,
) -> f32 {
    let to_eye = eye - centre;
    let distance = to_eye.length();
    let side = tangent.cross(to_eye);
    let width_m = if side.length_squared() > 1e-20 * to_eye.length_squared().max(1e-30) {
        let s = side.normalize();
        2.0 * (major.dot(s).powi(2) + minor.dot(s).powi(2)).sqrt()
    } else {
        2.0 * major.length().max(minor.length())
    };
    width_m / (pixel_at_unit * distance).max(1e-30)
}

/// Per bundle `[w_cur, w_cur−]` in pixels, the widest of `hairs` (generated as `vertices`,
/// `params.vertex_count` each) at the bundle's current level and the next coarser one; 0
/// where none was measured (mirror: `thick_widths`, which keeps them as f32 bits under
/// `atomicMax`).
pub fn thick_widths(
    vertices: &[ThickVertex],
    hairs: &[ThickHairGpu],
    levels: &[u32],
    params: &FarLodParams,
) -> Vec<[f32; 2]> {
    let n = params.vertex_count.max(2) as usize;
    let eye = Vec3::new(params.eye[0], params.eye[1], params.eye[2]);
    let mut widths = vec![[0.0f32; 2]; levels.len()];
    for (t, hair) in hairs.iter().enumerate() {
        let Some(&current) = levels.get(hair.block as usize) else {
            continue;
        };
        let slot = if hair.level == current {
            0
        } else if hair.level == current + 1 {
            1
        } else {
            continue;
        };
        let strand = &vertices[t * n..][..n];
        let mut widest = 0.0f32;
        for k in 0..n {
            let tangent = strand[(k + 1).min(n - 1)].centre - strand[k.saturating_sub(1)].centre;
            let v = &strand[k];
            let px = thick_width_px(
                v.centre,
                tangent,
                v.major,
                v.minor,
                eye,
                params.pixel_at_unit,
            );
            // NaN counts as too wide (the shader's u32 maximum of its bits does the same).
            widest = if px.is_nan() {
                f32::INFINITY
            } else {
                widest.max(px)
            };
        }
        let entry = &mut widths[hair.block as usize][slot];
        *entry = entry.max(widest);
    }
    widths
}

/// Eq. 16 for one bundle at `level` of `level_count` thick levels: finer when what it draws
/// is wider than `threshold_px`, coarser when the next level is no wider than it, else the
/// same (mirror: `next_levels`).
pub fn next_level(level: u32, widths: [f32; 2], level_count: u32, threshold_px: f32) -> u32 {
    let level = level.min(level_count);
    // NaN compares as neither: it counts as too wide.
    let fits = |width: f32| width <= threshold_px;
    if level >= 1 && !fits(widths[0]) {
        return level - 1;
    }
    if level < level_count && fits(widths[1]) {
        return level + 1;
    }
    level
}

/// Eq. 16 for every bundle.
pub fn next_levels(
    levels: &[u32],
    widths: &[[f32; 2]],
    far: &FarHair,
    threshold_px: f32,
) -> Vec<u32> {
    levels
        .iter()
        .enumerate()
        .map(|(block, &level)| {
            let count = far.blocks.get(block).map_or(0, Vec::len) as u32;
            next_level(level, widths[block], count, threshold_px)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::styling::StylingParams;
    use crate::runtime::hair::{RuntimeHair, RuntimeOptions};
    use crate::runtime::strand_gen::{Filtering, StrandGen};

    fn long_sample() -> RuntimeHair {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../assets/samples/head_long_wavy.hairloom");
        let document = crate::io::project::load(&path).expect("sample").document;
        RuntimeHair::from_document(
            &document,
            &RuntimeOptions {
                strands_per_bundle: 16,
                ..RuntimeOptions::default()
            },
        )
    }

    const THRESHOLD_PX: f32 = 2.0;

    /// This frame's `[w_cur, w_cur−]` per bundle on the CPU.
    fn measure(hair: &RuntimeHair, far: &FarHair, levels: &[u32], eye: Vec3) -> Vec<[f32; 2]> {
        let n = 9;
        let hairs = measured_hairs(far, levels);
        let generator = StrandGen {
            textures: &hair.textures,
            filtering: Filtering::Exact,
        };
        let styling: Vec<&StylingParams> = std::iter::once(&hair.styling.global)
            .chain(hair.styling.groups.iter().map(|g| &g.params))
            .collect();
        let vertices = generator.thick_main(&hair.strand_roots(), &hairs, n, &styling);
        let params = FarLodParams {
            eye: eye.extend(1.0).to_array(),
            pixel_at_unit: 2.0 * (15f32.to_radians()).tan() / 1080.0,
            width_threshold_px: THRESHOLD_PX,
            vertex_count: n,
            count: hairs.len() as u32,
        };
        thick_widths(&vertices, &hairs, levels, &params)
    }

    /// One frame of the deferred choice on the CPU: measure, then eq. 16.
    fn frame(hair: &RuntimeHair, far: &FarHair, levels: &[u32], eye: Vec3) -> Vec<u32> {
        next_levels(levels, &measure(hair, far, levels, eye), far, THRESHOLD_PX)
    }

    #[test]
    fn a_still_camera_settles_on_levels_and_never_oscillates() {
        let hair = long_sample();
        let far = FarHair::build(&hair, 9).expect("hierarchy");
        let blocks = far.blocks.len();
        let (lo, hi) = hair.textures.hair_bounds().expect("hair");
        let centre = (lo + hi) * 0.5;
        let mut settled_at = Vec::new();
        for distance_m in [0.8f32, 4.0, 20.0] {
            let eye = centre + Vec3::new(0.3, 0.1, 1.0).normalize() * distance_m;
            let mut levels = vec![0u32; blocks];
            let mut history = vec![levels.clone()];
            for _ in 0..12 {
                levels = frame(&hair, &far, &levels, eye);
                history.push(levels.clone());
            }
            // Settled: the last frames agree, and no bundle ever went back to a level it left
            // the other way (no A → B → A).
            let last = history.last().expect("frames").clone();
            assert_eq!(
                history[history.len() - 2],
                last,
                "{distance_m} m: still moving"
            );
            for block in 0..blocks {
                let path: Vec<u32> = history.iter().map(|l| l[block]).collect();
                let rising = path.windows(2).all(|w| w[1] >= w[0]);
                let falling = path.windows(2).all(|w| w[1] <= w[0]);
                assert!(rising || falling, "{distance_m} m bundle {block}: {path:?}");
            }
            // Every drawn level is at most ε_w wide and the next one is wider (where one is).
            let widths = measure(&hair, &far, &last, eye);
            for block in 0..blocks {
                let count = far.blocks[block].len() as u32;
                assert!(
                    widths[block][0] <= 2.0,
                    "bundle {block}: {:?}",
                    widths[block]
                );
                if last[block] < count {
                    assert!(
                        widths[block][1] > 2.0,
                        "bundle {block}: {:?}",
                        widths[block]
                    );
                }
            }
            settled_at.push(last.iter().map(|&l| l as f64).sum::<f64>() / blocks as f64);
            // A first frame's guess from the stored widest diameters is close (at most a
            // little wider than ε_w), and the choice settles from it too, within ε_w.
            let pixel_at_unit = 2.0 * (15f32.to_radians()).tan() / 1080.0;
            let mut levels = first_levels(
                &far,
                &hair.bundle_bounds(),
                eye,
                pixel_at_unit,
                THRESHOLD_PX,
            );
            let guessed = measure(&hair, &far, &levels, eye);
            assert!(
                guessed.iter().all(|w| w[0] <= 1.5 * THRESHOLD_PX),
                "{guessed:?}"
            );
            for _ in 0..12 {
                levels = frame(&hair, &far, &levels, eye);
            }
            assert_eq!(frame(&hair, &far, &levels, eye), levels, "{distance_m} m");
            let settled = measure(&hair, &far, &levels, eye);
            assert!(settled.iter().all(|w| w[0] <= THRESHOLD_PX), "{settled:?}");
            assert_eq!(
                drawn_hairs(&far, &levels).len(),
                levels
                    .iter()
                    .enumerate()
                    .filter(|&(_, &l)| l > 0)
                    .map(|(b, &l)| far.blocks[b][l as usize - 1].count as usize)
                    .sum::<usize>()
            );
        }
        // Farther away, coarser.
        assert!(
            settled_at.windows(2).all(|w| w[1] > w[0]),
            "mean level by distance: {settled_at:?}"
        );
        eprintln!("mean level at 0.8, 4 and 20 m: {settled_at:?}");
    }

    #[test]
    fn the_rule_moves_one_level_at_a_time_and_nan_counts_as_too_wide() {
        assert_eq!(next_level(2, [3.0, 9.0], 4, 2.0), 1);
        assert_eq!(next_level(2, [1.0, 1.5], 4, 2.0), 3);
        assert_eq!(next_level(2, [1.0, 3.0], 4, 2.0), 2);
        assert_eq!(next_level(0, [0.0, 1.0], 4, 2.0), 1);
        assert_eq!(next_level(0, [0.0, 3.0], 4, 2.0), 0);
        assert_eq!(next_level(4, [1.0, 0.0], 4, 2.0), 4);
        assert_eq!(next_level(9, [1.0, 0.0], 4, 2.0), 4);
        assert_eq!(next_level(3, [f32::NAN, 0.0], 4, 2.0), 2);
        assert_eq!(next_level(0, [0.0, f32::NAN], 4, 2.0), 0);
        let seen_end_on = thick_width_px(
            Vec3::ZERO,
            Vec3::Z,
            Vec3::X * 0.01,
            Vec3::Y * 0.002,
            Vec3::Z * 2.0,
            0.001,
        );
        assert!((seen_end_on - 10.0).abs() < 1e-3, "{seen_end_on}");
    }
}
