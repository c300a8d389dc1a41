//! Linear hair skinning (LHS): the baseline seed 000 §5 measures its method against, and what
//! engines ship for strand hair. Every strand is stored; a small share of them are *guides*
//! (what a simulation moves); each strand vertex is bound to its strand's nearest guides with
//! weights and an offset in each guide vertex's frame, and every frame the GPU rebuilds the
//! guides' frames and skins every vertex:
//!
//! `p = Σ_g w_g (c_g,s + x_g,s · n̂_g,s + y_g,s · b̂_g,s + z_g,s · t̂_g,s)`
//!
//! where `c_g,s` is guide `g`'s vertex `s` in the current pose and (n̂, b̂, t̂) its frame. The
//! weights sum to one, so a pose equal to the rest pose reproduces every strand exactly (to
//! f32 rounding), as in the paper's comparison, which does not animate the guides; and a guide
//! pose moved rigidly moves every strand rigidly.
//!
//! This is the CPU mirror of `shaders/linear_hair_skinning.wgsl` (same names: `guide_frames`,
//! `skin_main`); `render/src/renderer/linear_hair_skinning.rs` runs it in frames, where it
//! takes the place of generation and writes the same scratch layout the frame plan's runs
//! describe, so both methods draw through the same passes with the same level of detail.
//!
//! Choices, as the paper's comparison made them where it says:
//! - guides are a share of the strands (1 % by default, the paper's), spread evenly over the
//!   strands in root order (roots are bundle-major, so over the scalp);
//! - each strand is bound to its [`GUIDES_PER_STRAND`] nearest guides by root distance
//!   (`kiddo`), weighted by inverse squared distance (a guide binds to itself alone);
//! - a guide's frame is its tangent (central differences) and a normal parallel-transported
//!   from the root, where the pose's *reference* direction (a scalp direction that moves with
//!   the head; at rest the world axis least aligned with the root tangent) fixes the twist.
//!
//! Vertex level of detail subsamples the stored vertices (a run of `n` vertices takes every
//! `(V − 1)/(n − 1)`-th), with eq. 11's morph of odd vertices as generation does it.

use glam::Vec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::runtime::gpu_types::StrandRun;

/// Guides each strand vertex is bound to.
pub const GUIDES_PER_STRAND: usize = 3;

/// The share of strands that are guides in seed 000's comparison (1 %).
pub const DEFAULT_GUIDE_SHARE: f64 = 0.01;

/// Stored strand vertices a skinned hair may hold: the strand export's cap (32 Mi points,
/// 1.3 GB of skinning data at 40 B a vertex).
pub const MAX_SKINNED_VERTICES: usize = 32 << 20;

/// One strand's guides and weights, as the skinning shader reads it.
/// Keep in sync with `shaders/linear_hair_skinning.wgsl` (`SkinBinding`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SkinBinding {
    /// Indices into the guides (not strand indices).
    pub guides: [u32; GUIDES_PER_STRAND],
    pub _padding: u32,
    /// Sum to one; a slot with weight 0 is never read.
    pub weights: [f32; GUIDES_PER_STRAND],
    pub _padding2: f32,
}

/// The skinning pass's uniforms.
/// Keep in sync with `shaders/linear_hair_skinning.wgsl` (`SkinParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SkinParams {
    /// The batch's runs: `runs[first_run .. first_run + run_count]`.
    pub first_run: u32,
    pub run_count: u32,
    /// Strands this dispatch writes (the batch's runs together).
    pub strand_total: u32,
    /// Stored vertices per strand and per guide (`2^e + 1`).
    pub vertex_count: u32,
    pub guide_count: u32,
    pub _padding: [u32; 3],
}

/// Why strands cannot be skinned.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SkinningError {
    #[error("linear hair skinning: no strands to skin")]
    NoStrands,
    #[error("linear hair skinning: {vertex_count} vertices per strand; strands need 2^e + 1 ≥ 2")]
    VertexCount { vertex_count: u32 },
    #[error(
        "linear hair skinning: {points} points are not {strands} strands × {vertex_count} vertices"
    )]
    Length {
        points: usize,
        strands: usize,
        vertex_count: u32,
    },
    #[error(
        "linear hair skinning: {vertices} stored vertices exceed the cap of {MAX_SKINNED_VERTICES}; lower the strand count"
    )]
    TooLarge { vertices: usize },
    #[error("linear hair skinning: strand {strand} vertex {vertex} is not finite")]
    NonFinite { strand: usize, vertex: usize },
    #[error("linear hair skinning: guide share {0} is not in (0, 1]")]
    GuideShare(f64),
    #[error(
        "linear hair skinning: a pose of {points} guide points and {references} references does not fit {guides} guides × {vertex_count} vertices"
    )]
    Pose {
        points: usize,
        references: usize,
        guides: usize,
        vertex_count: u32,
    },
}

/// A guide vertex's frame: unit tangent and unit normal (the binormal is `tangent × normal`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuideFrame {
    pub tangent: Vec3,
    pub normal: Vec3,
}

impl GuideFrame {
    fn binormal(&self) -> Vec3 {
        self.tangent.cross(self.normal)
    }
}

/// The guides in one pose: every guide's vertices (guide-major) and root reference direction.
#[derive(Clone, Debug, PartialEq)]
pub struct GuidePose {
    pub points: Vec<Vec3>,
    pub references: Vec<Vec3>,
}

/// Every strand stored with its guide bindings: what LHS keeps on the GPU.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinnedHair {
    /// Stored vertices per strand (`2^e + 1`).
    pub vertex_count: u32,
    pub strand_count: usize,
    /// The strand each guide is.
    pub guides: Vec<u32>,
    /// The pose the offsets were taken in.
    pub rest: GuidePose,
    /// One per strand.
    pub bindings: Vec<SkinBinding>,
    /// Slot `g`: every strand vertex's (strand-major) offset from its guide `g`'s vertex in
    /// that vertex's rest frame (normal, binormal, tangent components).
    pub offsets: [Vec<[f32; 3]>; GUIDES_PER_STRAND],
}

impl SkinnedHair {
    /// Binds `points` (`strand_count` strands of `vertex_count` vertices, strand-major) to
    /// `guide_share` of them as guides.
    pub fn bind(
        points: &[Vec3],
        vertex_count: u32,
        guide_share: f64,
    ) -> Result<Self, SkinningError> {
        let v = vertex_count as usize;
        if vertex_count < 2 || !(vertex_count - 1).is_power_of_two() {
            return Err(SkinningError::VertexCount { vertex_count });
        }
        check_size(points.len())?;
        if points.is_empty() {
            return Err(SkinningError::NoStrands);
        }
        if !points.len().is_multiple_of(v) {
            return Err(SkinningError::Length {
                points: points.len(),
                strands: points.len() / v,
                vertex_count,
            });
        }
        if !(guide_share > 0.0 && guide_share <= 1.0) {
            return Err(SkinningError::GuideShare(guide_share));
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return Err(SkinningError::NonFinite {
                strand: i / v,
                vertex: i % v,
            });
        }
        let strand_count = points.len() / v;
        let guide_count =
            ((strand_count as f64 * guide_share).round() as usize).clamp(1, strand_count);
        let guides: Vec<u32> = (0..guide_count)
            .map(|j| ((2 * j + 1) * strand_count / (2 * guide_count)) as u32)
            .collect();
        let guide_points: Vec<Vec3> = guides
            .iter()
            .flat_map(|&g| points[g as usize * v..][..v].iter().copied())
            .collect();
        let references = guides
            .iter()
            .map(|&g| rest_reference(points[g as usize * v + 1] - points[g as usize * v]))
            .collect();
        let rest = GuidePose {
            points: guide_points,
            references,
        };
        let frames = guide_frames(&rest, vertex_count);
        let bindings = bind_roots(points, v, &guides);
        let mut offsets: [Vec<[f32; 3]>; GUIDES_PER_STRAND] =
            std::array::from_fn(|_| Vec::with_capacity(points.len()));
        for (strand, binding) in bindings.iter().enumerate() {
            for s in 0..v {
                let p = points[strand * v + s];
                for (slot, out) in offsets.iter_mut().enumerate() {
                    let g = binding.guides[slot] as usize;
                    let frame = frames[g * v + s];
                    let d = p - rest.points[g * v + s];
                    out.push([
                        d.dot(frame.normal),
                        d.dot(frame.binormal()),
                        d.dot(frame.tangent),
                    ]);
                }
            }
        }
        Ok(Self {
            vertex_count,
            strand_count,
            guides,
            rest,
            bindings,
            offsets,
        })
    }

    /// Bytes LHS keeps on the GPU: the strands' offsets and bindings, the guides' pose and
    /// frames (the frame's scratch aside).
    pub fn gpu_bytes(&self) -> u64 {
        let vertices = (self.strand_count * self.vertex_count as usize) as u64;
        let guide_vertices = self.rest.points.len() as u64;
        vertices * 12 * GUIDES_PER_STRAND as u64
            + self.bindings.len() as u64 * size_of::<SkinBinding>() as u64
            + guide_vertices * (16 + 32)
            + self.rest.references.len() as u64 * 16
    }

    /// Checks that `pose` fits these guides.
    pub fn check_pose(&self, pose: &GuidePose) -> Result<(), SkinningError> {
        let v = self.vertex_count as usize;
        if pose.points.len() != self.guides.len() * v || pose.references.len() != self.guides.len()
        {
            return Err(SkinningError::Pose {
                points: pose.points.len(),
                references: pose.references.len(),
                guides: self.guides.len(),
                vertex_count: self.vertex_count,
            });
        }
        Ok(())
    }

    /// CPU mirror of `skin_main` for one batch: the vertices of every run in scratch order
    /// (`run.vertex_offset + strand · run.vertex_count + k`), skinned to `pose` with its
    /// `frames` ([`guide_frames`]). Runs naming strands out of range are skipped, as the
    /// shader leaves them unwritten.
    pub fn skin_main(
        &self,
        pose: &GuidePose,
        frames: &[GuideFrame],
        runs: &[StrandRun],
    ) -> Vec<[f32; 4]> {
        let v = self.vertex_count as usize;
        let mut out = Vec::new();
        for run in runs {
            let n = run.vertex_count.max(2) as usize;
            let step = ((v - 1) / (n - 1)).max(1);
            for local in 0..run.strand_count as usize {
                let strand = run.first_root as usize + local;
                if strand >= self.strand_count {
                    continue;
                }
                let vertex =
                    |k: usize| self.skin_vertex(pose, frames, strand, (k * step).min(v - 1));
                let mut previous = vertex(0);
                out.push(previous.extend(0.0).to_array());
                let mut k = 1;
                while k < n {
                    let current = vertex(k);
                    if k + 1 < n {
                        let next = vertex(k + 1);
                        let p = if run.gamma > 0.0 {
                            current.lerp(0.5 * (previous + next), run.gamma)
                        } else {
                            current
                        };
                        out.push(p.extend(along_of(k, n)).to_array());
                        out.push(next.extend(along_of(k + 1, n)).to_array());
                        previous = next;
                    } else {
                        out.push(current.extend(along_of(k, n)).to_array());
                    }
                    k += 2;
                }
            }
        }
        out
    }

    /// Stored vertex `s` of `strand`, skinned.
    fn skin_vertex(
        &self,
        pose: &GuidePose,
        frames: &[GuideFrame],
        strand: usize,
        s: usize,
    ) -> Vec3 {
        let v = self.vertex_count as usize;
        let binding = &self.bindings[strand];
        let mut p = Vec3::ZERO;
        for slot in 0..GUIDES_PER_STRAND {
            let w = binding.weights[slot];
            if w == 0.0 {
                continue;
            }
            let g = binding.guides[slot] as usize;
            let frame = frames[g * v + s];
            let [x, y, z] = self.offsets[slot][strand * v + s];
            p += w
                * (pose.points[g * v + s]
                    + x * frame.normal
                    + y * frame.binormal()
                    + z * frame.tangent);
        }
        p
    }
}

/// Refuses more than [`MAX_SKINNED_VERTICES`] stored vertices (before a caller makes them).
pub fn check_size(vertices: usize) -> Result<(), SkinningError> {
    if vertices > MAX_SKINNED_VERTICES {
        return Err(SkinningError::TooLarge { vertices });
    }
    Ok(())
}

/// `k / (n − 1)`, as generation writes it.
fn along_of(k: usize, n: usize) -> f32 {
    k as f32 / (n - 1) as f32
}

/// The rest reference of a guide whose root segment is `root_segment`: the world axis least
/// aligned with it.
fn rest_reference(root_segment: Vec3) -> Vec3 {
    let a = root_segment.abs();
    if a.x <= a.y && a.x <= a.z {
        Vec3::X
    } else if a.y <= a.z {
        Vec3::Y
    } else {
        Vec3::Z
    }
}

/// Each strand's [`GUIDES_PER_STRAND`] nearest guides by root, inverse-square weighted.
fn bind_roots(points: &[Vec3], v: usize, guides: &[u32]) -> Vec<SkinBinding> {
    let roots: Vec<[f32; 3]> = guides
        .iter()
        .map(|&g| points[g as usize * v].to_array())
        .collect();
    // kiddo refuses some inputs (e.g. more coincident points than a bucket holds): then a
    // scan over the guides, which are few.
    let tree = ImmutableKdTree::<f32, 3>::new_from_slice(&roots).ok();
    let k = GUIDES_PER_STRAND.min(guides.len());
    let nearest_of = |root: Vec3| -> Vec<(usize, f32)> {
        match &tree {
            Some(tree) => tree
                .query(&root.to_array())
                .nearest_n::<SquaredEuclidean<f32>>(
                    std::num::NonZeroUsize::new(k).unwrap_or(std::num::NonZeroUsize::MIN),
                )
                .execute()
                .into_iter()
                .map(|n| (n.item as usize, n.distance))
                .collect(),
            None => {
                let mut all: Vec<(usize, f32)> = roots
                    .iter()
                    .enumerate()
                    .map(|(i, r)| (i, Vec3::from_array(*r).distance_squared(root)))
                    .collect();
                all.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
                all.truncate(k);
                all
            }
        }
    };
    let strand_count = points.len() / v;
    crate::parallel::in_chunks(
        strand_count,
        4096,
        std::thread::available_parallelism().map_or(1, |n| n.get()),
        |range| {
            range
                .map(|strand| {
                    let nearest = nearest_of(points[strand * v]);
                    let mut binding = SkinBinding::default();
                    // A strand that is a guide (or sits on one) follows it alone.
                    if let Some(own) = nearest.iter().find(|n| n.1 <= f32::MIN_POSITIVE) {
                        binding.guides[0] = own.0 as u32;
                        binding.weights[0] = 1.0;
                        return binding;
                    }
                    let total: f32 = nearest.iter().map(|n| 1.0 / n.1).sum();
                    for (slot, &(guide, distance)) in nearest.iter().enumerate() {
                        binding.guides[slot] = guide as u32;
                        binding.weights[slot] = 1.0 / distance / total;
                    }
                    binding
                })
                .collect::<Vec<_>>()
        },
    )
    .into_iter()
    .flatten()
    .collect()
}

/// CPU mirror of the `guide_frames` pass: every guide vertex's frame in `pose` (guide-major).
/// Tangents by central differences (one-sided at the ends); a zero-length difference keeps
/// the previous tangent (the root's falls back to the reference's Duff basis). The root's
/// normal is the reference made perpendicular to the tangent; each next normal is the
/// previous one made perpendicular to the next tangent (parallel transport), with the
/// previous binormal's turn where the tangent turned onto the normal.
pub fn guide_frames(pose: &GuidePose, vertex_count: u32) -> Vec<GuideFrame> {
    let v = vertex_count.max(2) as usize;
    let mut frames = Vec::with_capacity(pose.points.len());
    for (g, reference) in pose.references.iter().enumerate() {
        let Some(points) = pose.points.get(g * v..(g + 1) * v) else {
            break;
        };
        let mut previous: Option<GuideFrame> = None;
        for s in 0..v {
            let d = points[(s + 1).min(v - 1)] - points[s.saturating_sub(1)];
            let tangent = match (try_normalize(d), previous) {
                (Some(t), _) => t,
                (None, Some(frame)) => frame.tangent,
                (None, None) => duff_basis(*reference).0,
            };
            let carried = match previous {
                Some(frame) => frame.normal,
                None => *reference,
            };
            let normal = try_normalize(carried - tangent * tangent.dot(carried))
                .or_else(|| {
                    previous.and_then(|frame| {
                        let b = frame.binormal();
                        try_normalize(b - tangent * tangent.dot(b))
                    })
                })
                .unwrap_or_else(|| duff_basis(tangent).1);
            let frame = GuideFrame { tangent, normal };
            frames.push(frame);
            previous = Some(frame);
        }
    }
    frames
}

/// `v` made unit where its squared length is above 1e-30, as the shader's `try_normalize`.
fn try_normalize(v: Vec3) -> Option<Vec3> {
    let length_squared = v.length_squared();
    (length_squared > 1e-30).then(|| v / length_squared.sqrt())
}

/// A unit `z` (from `direction`, +z when it has no length) and a unit vector ⟂ it (Duff et
/// al. 2017's branchless basis).
fn duff_basis(direction: Vec3) -> (Vec3, Vec3) {
    let n = try_normalize(direction).unwrap_or(Vec3::Z);
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        n,
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::strand_gen::full_detail_runs;

    /// `strands` wavy strands of `v` vertices rooted on a curved patch.
    fn wavy_strands(strands: usize, v: usize) -> Vec<Vec3> {
        let mut points = Vec::with_capacity(strands * v);
        for i in 0..strands {
            let a = i as f32 * 0.37;
            let root = Vec3::new(a.cos() * 0.1, 0.02 * (i % 13) as f32, a.sin() * 0.1);
            for s in 0..v {
                let t = s as f32 / (v - 1) as f32;
                points.push(
                    root + Vec3::new(
                        0.01 * (9.0 * t + a).sin(),
                        -0.3 * t,
                        0.05 * t * t + 0.008 * (7.0 * t).cos(),
                    ),
                );
            }
        }
        points
    }

    fn skin_all(hair: &SkinnedHair, pose: &GuidePose) -> Vec<[f32; 4]> {
        let frames = guide_frames(pose, hair.vertex_count);
        hair.skin_main(
            pose,
            &frames,
            &full_detail_runs(hair.strand_count, hair.vertex_count),
        )
    }

    #[test]
    fn the_rest_pose_gives_back_every_strand() -> Result<(), SkinningError> {
        let v = 17;
        let points = wavy_strands(500, v);
        for share in [0.002, 0.01, 0.1, 1.0] {
            let hair = SkinnedHair::bind(&points, v as u32, share)?;
            let skinned = skin_all(&hair, &hair.rest);
            assert_eq!(skinned.len(), points.len());
            let worst = skinned
                .iter()
                .zip(&points)
                .map(|(s, p)| Vec3::from_slice(s).distance(*p))
                .fold(0.0f32, f32::max);
            // f32 rounding of a 0.3 m hair: a few micrometres at most.
            assert!(worst < 2e-6, "share {share}: {worst} m");
            assert_eq!(skinned[v - 1][3], 1.0);
        }
        Ok(())
    }

    #[test]
    fn guides_are_the_asked_share_and_weights_sum_to_one() -> Result<(), SkinningError> {
        let points = wavy_strands(1000, 9);
        let hair = SkinnedHair::bind(&points, 9, 0.01)?;
        assert_eq!(hair.guides.len(), 10);
        for binding in &hair.bindings {
            let sum: f32 = binding.weights.iter().sum();
            assert!((sum - 1.0).abs() < 1e-5, "{binding:?}");
            assert!(binding.guides.iter().all(|&g| (g as usize) < 10));
        }
        // A guide strand follows itself alone.
        for (j, &g) in hair.guides.iter().enumerate() {
            let binding = hair.bindings[g as usize];
            assert_eq!((binding.guides[0], binding.weights[0]), (j as u32, 1.0));
        }
        Ok(())
    }

    #[test]
    fn a_rigidly_moved_pose_moves_every_strand_rigidly() -> Result<(), SkinningError> {
        let v = 9;
        let points = wavy_strands(300, v);
        let hair = SkinnedHair::bind(&points, v as u32, 0.05)?;
        let rotation = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.4, -1.1, 0.7);
        let shift = Vec3::new(0.3, -0.2, 1.5);
        let moved = GuidePose {
            points: hair
                .rest
                .points
                .iter()
                .map(|p| rotation * *p + shift)
                .collect(),
            references: hair.rest.references.iter().map(|r| rotation * *r).collect(),
        };
        let skinned = skin_all(&hair, &moved);
        let worst = skinned
            .iter()
            .zip(&points)
            .map(|(s, p)| Vec3::from_slice(s).distance(rotation * *p + shift))
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-5, "{worst} m");
        Ok(())
    }

    #[test]
    fn a_bent_guide_bends_its_strands_and_fewer_vertices_subsample() -> Result<(), SkinningError> {
        let v = 9;
        let points = wavy_strands(40, v);
        let hair = SkinnedHair::bind(&points, v as u32, 0.05)?;
        let mut bent = hair.rest.clone();
        // Swing the lower half of every guide sideways.
        for g in 0..hair.guides.len() {
            for s in v / 2..v {
                bent.points[g * v + s] += Vec3::new(0.05 * (s - v / 2) as f32, 0.0, 0.0);
            }
        }
        let skinned = skin_all(&hair, &bent);
        let tip_moves: Vec<f32> = (0..hair.strand_count)
            .map(|i| Vec3::from_slice(&skinned[i * v + v - 1]).distance(points[i * v + v - 1]))
            .collect();
        let root_moves: Vec<f32> = (0..hair.strand_count)
            .map(|i| Vec3::from_slice(&skinned[i * v]).distance(points[i * v]))
            .collect();
        assert!(tip_moves.iter().all(|&d| d > 0.1), "{tip_moves:?}");
        assert!(root_moves.iter().all(|&d| d < 1e-6), "{root_moves:?}");
        // Three vertices per strand are stored vertices 0, 4 and 8, morphed by γ = 0.
        let frames = guide_frames(&bent, hair.vertex_count);
        let coarse = hair.skin_main(&bent, &frames, &full_detail_runs(hair.strand_count, 3));
        for i in 0..hair.strand_count {
            for (k, s) in [0, 4, 8].into_iter().enumerate() {
                assert_eq!(coarse[i * 3 + k][..3], skinned[i * v + s][..3]);
                assert_eq!(coarse[i * 3 + k][3], k as f32 / 2.0);
            }
        }
        Ok(())
    }

    #[test]
    fn degenerate_guides_keep_finite_frames() {
        let v = 5;
        let cases = [
            // Every vertex on the root.
            vec![Vec3::ONE; v],
            // Collinear with the reference.
            (0..v).map(|s| Vec3::X * s as f32).collect(),
            // A right-angle kink onto the normal, and a repeated vertex.
            vec![
                Vec3::ZERO,
                Vec3::Y,
                Vec3::Y,
                Vec3::Y + Vec3::X,
                Vec3::Y + 2.0 * Vec3::X,
            ],
        ];
        for points in cases {
            for reference in [Vec3::X, Vec3::ZERO, Vec3::NEG_Z] {
                let pose = GuidePose {
                    points: points.clone(),
                    references: vec![reference],
                };
                for frame in guide_frames(&pose, v as u32) {
                    assert!((frame.tangent.length() - 1.0).abs() < 1e-5, "{frame:?}");
                    assert!((frame.normal.length() - 1.0).abs() < 1e-5, "{frame:?}");
                    assert!(frame.tangent.dot(frame.normal).abs() < 1e-5, "{frame:?}");
                }
            }
        }
    }

    #[test]
    fn coincident_strands_and_roots_bind_finitely() -> Result<(), SkinningError> {
        // Every strand the same: every root on every guide.
        let one = wavy_strands(1, 5);
        let points: Vec<Vec3> = (0..50).flat_map(|_| one.iter().copied()).collect();
        let hair = SkinnedHair::bind(&points, 5, 0.1)?;
        let skinned = skin_all(&hair, &hair.rest);
        assert!(skinned.iter().flatten().all(|x| x.is_finite()));
        let worst = skinned
            .iter()
            .zip(&points)
            .map(|(s, p)| Vec3::from_slice(s).distance(*p))
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-6);
        Ok(())
    }

    #[test]
    fn bad_input_is_refused_by_name() {
        let points = wavy_strands(4, 5);
        assert_eq!(
            SkinnedHair::bind(&[], 5, 0.01),
            Err(SkinningError::NoStrands)
        );
        assert_eq!(
            SkinnedHair::bind(&points, 4, 0.01),
            Err(SkinningError::VertexCount { vertex_count: 4 })
        );
        assert!(matches!(
            SkinnedHair::bind(&points[1..], 5, 0.01),
            Err(SkinningError::Length { .. })
        ));
        for share in [0.0, -1.0, 1.5, f64::NAN] {
            assert!(matches!(
                SkinnedHair::bind(&points, 5, share),
                Err(SkinningError::GuideShare(_))
            ));
        }
        let mut nan = points.clone();
        nan[7] = Vec3::new(f32::NAN, 0.0, 0.0);
        assert_eq!(
            SkinnedHair::bind(&nan, 5, 0.01),
            Err(SkinningError::NonFinite {
                strand: 1,
                vertex: 2
            })
        );
        assert_eq!(
            check_size(MAX_SKINNED_VERTICES + 5),
            Err(SkinningError::TooLarge {
                vertices: MAX_SKINNED_VERTICES + 5
            })
        );
        assert_eq!(check_size(MAX_SKINNED_VERTICES), Ok(()));
        let Ok(hair) = SkinnedHair::bind(&points, 5, 0.5) else {
            panic!("binds")
        };
        let short = GuidePose {
            points: hair.rest.points[1..].to_vec(),
            references: hair.rest.references.clone(),
        };
        assert!(matches!(
            hair.check_pose(&short),
            Err(SkinningError::Pose { .. })
        ));
        assert_eq!(hair.check_pose(&hair.rest), Ok(()));
    }
}
