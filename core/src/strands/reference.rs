//! The f64 reference strand generator: the CPU definition of every strand the GPU draws.
//!
//! For each bundle that grows hair, strand `j` takes root sample `j` of the bundle's
//! progressive sample set ([`crate::strands::roots`]), so fewer strands (LOD) are a prefix of more. A
//! strand of `2^e + 1` vertices samples its curve at evenly spaced `τ ∈ [0, τ_max]` (layer
//! units), `τ_max = layers · length_fraction`. At each vertex after the root:
//! 1. the unstyled point comes from [`ReferenceStrand`];
//! 2. twist rotates it about the bundle's centre strand (same `τ`) around ŵ;
//! 3. the styling offset ([`styling_offset`](crate::strands::styling::styling_offset)) is added, in the frame blended from the
//!    per-vertex frames of the bundle's corners (bilinear across the face, linear between
//!    layers — what sampling the u- and v-textures computes) and with w blended likewise.

use glam::{DVec2, DVec3};

use crate::geometry::curve::{CurveDefinition, FaceCoord, ReferenceStrand, SegmentForm};
use crate::geometry::frames::{Frame, fallback_frame, layer_frames};
use crate::model::document::Document;
use crate::model::styling::StylingParams;
use crate::strands::roots::{SampleDomain, progressive_samples};
use crate::strands::styling::{
    StrandStyling, StylingInput, hairline_length_scale, strand_length_fraction, styling_offset_of,
    twist,
};

/// What to generate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrandOptions {
    pub strands_per_bundle: u32,
    /// Strands have `2^vertices_log2 + 1` vertices.
    pub vertices_log2: u32,
    pub definition: CurveDefinition,
    pub form: SegmentForm,
    /// Seed of the root sample sets.
    pub sample_seed: u64,
}

impl Default for StrandOptions {
    fn default() -> Self {
        Self {
            strands_per_bundle: 64,
            vertices_log2: 4,
            definition: CurveDefinition::ColumnBlend,
            form: SegmentForm::ExactCubic,
            sample_seed: 1,
        }
    }
}

/// One generated strand.
#[derive(Clone, Debug, PartialEq)]
pub struct Strand {
    pub bundle: u32,
    /// The renderers' number for its root: its bundle's atlas block × strands per bundle +
    /// its sample's place in the bundle, what per-strand values (the shading variation) are
    /// hashed from. Set
    /// by whoever knows the strands per bundle (`StrandPlan`, the runtime mirror); 0 for a
    /// strand made alone ([`StrandContext::strand`]).
    pub root: u32,
    /// Root position on the face: bilinear `(s, t)` for quads, barycentric for triangles.
    pub coord: FaceCoord,
    pub root_uv: DVec2,
    /// The share of its bundle's length the strand spans (length variation, strays, the
    /// hairline); 0 for a strand that does not grow (only the runtime mirror keeps those).
    pub length_fraction: f64,
    pub points: Vec<DVec3>,
}

/// Precomputed per-document data shared by every strand.
pub struct StrandContext<'a> {
    pub document: &'a Document,
    /// `frames[layer][column]`.
    frames: Vec<Vec<Option<Frame>>>,
    /// Each bundle's place among the bundles that grow hair: its block in the runtime
    /// atlas, which blocks sort by bundle (`runtime::atlas::build_atlas`).
    blocks: Vec<u32>,
    /// Each column's root distance to the border of the hair (`geometry::hairline`); empty
    /// when no styling uses the hairline op.
    hairline: Vec<f64>,
}

impl<'a> StrandContext<'a> {
    pub fn new(document: &'a Document) -> Self {
        let mesh = &document.hair_mesh;
        let frames = (0..=mesh.max_layers())
            .map(|k| layer_frames(mesh, k))
            .collect();
        let blocks = mesh
            .bundles
            .iter()
            .scan(0u32, |next, bundle| {
                let block = *next;
                *next += u32::from(!bundle.removed && bundle.layers > 0);
                Some(block)
            })
            .collect();
        let styling = &document.styling;
        let uses_hairline = std::iter::once(&styling.global)
            .chain(styling.groups.iter().map(|g| &g.params))
            .any(|p| p.hairline.width_m > 0.0);
        let hairline = if uses_hairline {
            crate::geometry::hairline::column_distances(mesh)
        } else {
            Vec::new()
        };
        Self {
            document,
            frames,
            blocks,
            hairline,
        }
    }

    /// Frame and w at `τ` of the strand with corner `weights` in `bundle`.
    fn frame_at(&self, bundle: usize, weights: &[f64; 4], tau: f64) -> (DVec3, DVec3, DVec3, f64) {
        let mesh = &self.document.hair_mesh;
        let b = &mesh.bundles[bundle];
        let layers = b.layers as usize;
        let k = (tau.floor().max(0.0) as usize).min(layers.saturating_sub(1));
        let f = (tau - k as f64).clamp(0.0, 1.0);
        let (mut u, mut v, mut w) = (DVec3::ZERO, DVec3::ZERO, 0.0);
        for (i, &c) in b.vertices.iter().enumerate() {
            let c = c as usize;
            let column = &mesh.columns[c];
            let frame =
                |layer: usize| self.frames[layer][c].unwrap_or_else(|| fallback_frame(DVec3::Y));
            let k1 = (k + 1).min(column.positions.len() - 1);
            let (a, z) = (frame(k), frame(k1));
            u += weights[i] * a.u.lerp(z.u, f);
            v += weights[i] * a.v.lerp(z.v, f);
            w += weights[i] * (column.w[k] + (column.w[k1] - column.w[k]) * f);
        }
        let u = u.try_normalize().unwrap_or(DVec3::X);
        let v = v.try_normalize().unwrap_or(DVec3::Y);
        let w_axis = u
            .cross(v)
            .try_normalize()
            .unwrap_or_else(|| fallback_frame(u).v);
        (u, v, w_axis, w)
    }

    /// The styled strand of `bundle` rooted at `coord`, with `vertex_count ≥ 2` vertices, at
    /// rank 0 (it grows wherever the hairline op grows any strand: `edge_density > 0`). `None` for a
    /// bundle that does not exist or grows no hair.
    pub fn strand(
        &self,
        bundle: usize,
        coord: FaceCoord,
        vertex_count: usize,
        options: &StrandOptions,
    ) -> Option<Strand> {
        self.strand_ranked(bundle, coord, 0.0, vertex_count, options)
    }

    /// [`Self::strand`] for the root whose place in its bundle's progressive sample set is
    /// `rank = (j + ½) / N` ([`crate::runtime::hair::sample_rank`]); `None` also where the
    /// hairline op does not grow it.
    pub fn strand_ranked(
        &self,
        bundle: usize,
        coord: FaceCoord,
        rank: f64,
        vertex_count: usize,
        options: &StrandOptions,
    ) -> Option<Strand> {
        let mesh = &self.document.hair_mesh;
        let b = mesh.bundles.get(bundle)?;
        if b.layers == 0 || b.removed {
            return None;
        }
        let params: &StylingParams = self.document.styling.params_for(bundle as u32);
        let reference = ReferenceStrand::new(mesh, bundle, coord)?;
        let weights = coord.weights(b.vertices.len());
        let centre_coord = if b.vertices.len() == 3 {
            FaceCoord {
                s: 1.0 / 3.0,
                t: 1.0 / 3.0,
            }
        } else {
            FaceCoord { s: 0.5, t: 0.5 }
        };
        let centre = (params.twist.turns_per_m != 0.0)
            .then(|| ReferenceStrand::new(mesh, bundle, centre_coord))
            .flatten();
        let hairline_distance = if self.hairline.is_empty() {
            crate::geometry::hairline::NO_BORDER_DISTANCE
        } else {
            b.vertices
                .iter()
                .zip(weights)
                .map(|(&c, weight)| weight * self.hairline.get(c as usize).copied().unwrap_or(0.0))
                .sum()
        };
        let maps = self.document.root_maps.sample(reference.root_uv);
        let length_fraction = strand_length_fraction(params, reference.root_uv)
            * hairline_length_scale(params, hairline_distance, rank)
            * maps.length_scale(rank);
        if length_fraction <= 0.0 {
            return None;
        }
        let tau_max = b.layers as f64 * length_fraction;
        // What styling needs of this strand at every vertex, computed once.
        let strand_styling =
            StrandStyling::new(params, reference.root_uv).with_clump_share(maps.clump);
        let vertex_count = vertex_count.max(2);
        let points = (0..vertex_count)
            .map(|k| {
                let along = k as f64 / (vertex_count - 1) as f64;
                let tau = tau_max * along;
                let mut p = reference.point(tau, options.definition, options.form);
                if k == 0 {
                    return p;
                }
                let (u, v, w_axis, w) = self.frame_at(bundle, &weights, tau);
                if let Some(centre) = &centre {
                    let axis_point = centre.point(tau, options.definition, options.form);
                    p = twist(params, p, axis_point, w_axis, w);
                }
                let input = StylingInput {
                    u,
                    v,
                    w_axis,
                    root_uv: reference.root_uv,
                    w,
                    // A strand the length map cuts is the first part of the one it would be.
                    along: along * maps.length,
                };
                p + styling_offset_of(params, &strand_styling, &input)
            })
            .collect();
        Some(Strand {
            bundle: bundle as u32,
            root: 0,
            coord,
            root_uv: reference.root_uv,
            length_fraction,
            points,
        })
    }
}

/// Size of the root sample sets: strand counts up to this take a prefix of one fixed set, so
/// a bundle drawn with fewer strands (LOD) shows a subset of the strands it shows with more.
pub(crate) fn sample_set_size(strands_per_bundle: u32) -> usize {
    (strands_per_bundle as usize)
        .next_power_of_two()
        .max(MIN_SAMPLE_SET)
}

/// Smallest root sample set.
pub const MIN_SAMPLE_SET: usize = 256;

/// What every bundle's strands are generated from: the root sample sets and counts.
pub struct StrandPlan {
    pub options: StrandOptions,
    quad_samples: Vec<glam::DVec2>,
    triangle_samples: Vec<glam::DVec2>,
    count: usize,
    vertex_count: usize,
}

impl StrandPlan {
    pub fn new(options: &StrandOptions) -> Self {
        let set = sample_set_size(options.strands_per_bundle);
        Self {
            options: *options,
            quad_samples: progressive_samples(set, SampleDomain::Square, options.sample_seed),
            triangle_samples: progressive_samples(set, SampleDomain::Triangle, options.sample_seed),
            count: (options.strands_per_bundle as usize).min(set),
            vertex_count: (1usize << options.vertices_log2.min(16)) + 1,
        }
    }

    /// The strands of bundle `index` (none for a bundle that grows no hair).
    pub fn bundle_strands(&self, context: &StrandContext, index: usize) -> Vec<Strand> {
        let Some(bundle) = context.document.hair_mesh.bundles.get(index) else {
            return Vec::new();
        };
        let samples = if bundle.vertices.len() == 3 {
            &self.triangle_samples
        } else {
            &self.quad_samples
        };
        // A thinned bundle grows the first ⌈share · N⌉ of its samples: its own density, and
        // the styling's per-area target over its root face.
        let mesh = &context.document.hair_mesh;
        let share = crate::strands::lod::grown_share(
            bundle.density,
            context
                .document
                .styling
                .params_for(index as u32)
                .density
                .strands_per_cm2,
            mesh.root_face_area(&bundle.vertices),
            self.count as u32,
        );
        let count = crate::strands::lod::density_count(share, self.count as u32);
        samples[..count as usize]
            .iter()
            .enumerate()
            .filter_map(|(i, sample)| {
                let coord = FaceCoord {
                    s: sample.x,
                    t: sample.y,
                };
                let rank = crate::runtime::hair::sample_rank(i, self.count) as f64;
                let mut strand =
                    context.strand_ranked(index, coord, rank, self.vertex_count, &self.options)?;
                // The renderers number roots by atlas block, which skips bald bundles.
                strand.root = context.blocks[index]
                    .wrapping_mul(self.count as u32)
                    .wrapping_add(i as u32);
                Some(strand)
            })
            .collect()
    }
}

/// The renderers' root number of each of `strands` ([`Strand::root`]).
pub fn root_indices(strands: &[Strand]) -> Vec<u32> {
    strands.iter().map(|strand| strand.root).collect()
}

/// Every strand of the document: `strands_per_bundle` per bundle that grows hair.
pub fn generate(document: &Document, options: &StrandOptions) -> Vec<Strand> {
    generate_parallel(document, options, 1)
}

/// [`generate`] on `threads` threads (bundles split into contiguous chunks); the result is
/// identical to the single-threaded one, in the same order.
pub fn generate_parallel(
    document: &Document,
    options: &StrandOptions,
    threads: usize,
) -> Vec<Strand> {
    let context = StrandContext::new(document);
    let plan = StrandPlan::new(options);
    let bundle_count = document.hair_mesh.bundles.len();
    let chunk = bundle_count.div_ceil(threads.max(1));
    crate::parallel::in_chunks(bundle_count, chunk, threads, |range| {
        range
            .flat_map(|i| plan.bundle_strands(&context, i))
            .collect::<Vec<_>>()
    })
    .into_iter()
    .flatten()
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;
    use crate::model::styling::{LengthVariation, Twist};

    fn styled(params: StylingParams) -> Document {
        // Hair-sized: 1 cm quads, three 1 cm layers.
        let mut document = Document::new("grid", grid(3, 2, 3, 1.0));
        for column in &mut document.hair_mesh.columns {
            for p in &mut column.positions {
                *p *= 0.01;
            }
        }
        document.hair_mesh.update_w();
        document.styling.global = params;
        document
    }

    /// The shared every-op set without twist and the hairline (each has its own test
    /// below): the hairline thins the 3 × 2 grid's strands, all of which lie within its
    /// falloff.
    fn everything_but_twist() -> StylingParams {
        StylingParams {
            twist: Twist::default(),
            hairline: crate::model::styling::Hairline::default(),
            ..StylingParams::every_op()
        }
    }

    #[test]
    fn generate_makes_prefix_stable_strands_with_unstyled_roots() {
        let document = styled(everything_but_twist());
        let options = StrandOptions {
            strands_per_bundle: 16,
            vertices_log2: 3,
            ..StrandOptions::default()
        };
        let strands = generate(&document, &options);
        assert_eq!(strands.len(), 6 * 16);
        assert!(
            strands
                .iter()
                .all(|s| s.points.len() == 9 && s.points.iter().all(|p| p.is_finite()))
        );
        // Roots lie on the scalp (z = 0 in this grid) and are not styled.
        assert!(strands.iter().all(|s| s.points[0].z.abs() < 1e-15));
        // Fewer strands are a prefix of more (LOD drops strands from the end).
        let fewer = generate(
            &document,
            &StrandOptions {
                strands_per_bundle: 8,
                ..options
            },
        );
        assert_eq!(fewer[..8], strands[..8]);
    }

    #[test]
    fn strands_across_a_shared_bundle_edge_have_no_seam() {
        // Bundles 0 and 1 share the edge s = 1 of bundle 0 / s = 0 of bundle 1 (same t).
        // Strays are chosen, pointed and sized per random-value cell: steps along the cells'
        // borders by design (uv lines, unrelated to bundle borders; frizz's selection is a
        // step too, which every_op avoids with fraction 1). Checked with no stray.
        let mut params = everything_but_twist();
        params.stray.fraction = 0.0;
        no_seam_across_the_shared_edge(&styled(params));
    }

    fn no_seam_across_the_shared_edge(document: &Document) {
        let context = StrandContext::new(document);
        let options = StrandOptions::default();
        let gap = |a: &Strand, b: &Strand| {
            a.points
                .iter()
                .zip(&b.points)
                .map(|(p, q)| p.distance(*q))
                .fold(0.0, f64::max)
        };
        for t in [0.2, 0.5, 0.77] {
            let mut previous = f64::INFINITY;
            for epsilon in [1e-3, 1e-4, 1e-5, 1e-6] {
                let a = context
                    .strand(
                        0,
                        FaceCoord {
                            s: 1.0 - epsilon,
                            t,
                        },
                        17,
                        &options,
                    )
                    .expect("strand");
                let b = context
                    .strand(1, FaceCoord { s: epsilon, t }, 17, &options)
                    .expect("strand");
                let across = gap(&a, &b);
                // Two strands as far apart inside one bundle differ by about as much: the
                // border is not special.
                let c = context
                    .strand(
                        0,
                        FaceCoord {
                            s: 0.5 - epsilon,
                            t,
                        },
                        17,
                        &options,
                    )
                    .expect("strand");
                let d = context
                    .strand(
                        0,
                        FaceCoord {
                            s: 0.5 + epsilon,
                            t,
                        },
                        17,
                        &options,
                    )
                    .expect("strand");
                let within = gap(&c, &d);
                assert!(
                    across < 3.0 * within + 1e-12,
                    "t {t}, ε {epsilon}: across {across}, within {within}"
                );
                // O(ε): the gap vanishes linearly with the root distance (the constant is the
                // per-strand variation: curl phase and frizz decorrelate over 1/200 uv).
                assert!(across < 10.0 * epsilon, "t {t}, ε {epsilon}: gap {across}");
                assert!(across <= previous);
                previous = across;
            }
            assert!(previous < 1e-5, "{previous}");
        }
    }

    #[test]
    fn twist_turns_bundles_into_locks_about_their_centre() {
        let params = StylingParams {
            twist: Twist { turns_per_m: 20.0 },
            ..StylingParams::default()
        };
        let document = styled(params);
        let plain = styled(StylingParams::default());
        let (twisted, straight) = (StrandContext::new(&document), StrandContext::new(&plain));
        let options = StrandOptions::default();
        let centre = FaceCoord { s: 0.5, t: 0.5 };
        let off_centre = FaceCoord { s: 0.9, t: 0.5 };
        let a = twisted.strand(2, centre, 17, &options).expect("strand");
        let b = straight.strand(2, centre, 17, &options).expect("strand");
        assert!(
            a.points
                .iter()
                .zip(&b.points)
                .all(|(p, q)| p.distance(*q) < 1e-12),
            "the axis does not move"
        );
        let c = twisted.strand(2, off_centre, 17, &options).expect("strand");
        let d = straight
            .strand(2, off_centre, 17, &options)
            .expect("strand");
        let moved = c
            .points
            .iter()
            .zip(&d.points)
            .map(|(p, q)| p.distance(*q))
            .fold(0.0, f64::max);
        assert!(moved > 1e-3, "{moved}");
        // Distance to the axis is kept.
        for k in 0..17 {
            let r_twisted = c.points[k].distance(a.points[k]);
            let r_straight = d.points[k].distance(b.points[k]);
            assert!((r_twisted - r_straight).abs() < 1e-12);
        }
    }

    #[test]
    fn parallel_generation_equals_serial() {
        let document = styled(everything_but_twist());
        let options = StrandOptions {
            strands_per_bundle: 10,
            ..StrandOptions::default()
        };
        assert_eq!(
            generate_parallel(&document, &options, 4),
            generate(&document, &options)
        );
    }

    #[test]
    fn length_variation_shortens_strands() {
        let document = styled(StylingParams {
            length: LengthVariation { fraction: 0.5 },
            ..StylingParams::default()
        });
        let options = StrandOptions {
            strands_per_bundle: 32,
            ..StrandOptions::default()
        };
        let strands = generate(&document, &options);
        let tips: Vec<f64> = strands
            .iter()
            .map(|s| s.points.last().map(|p| p.z).unwrap_or(0.0))
            .collect();
        let full = 3.0 * 0.01;
        assert!(
            tips.iter()
                .all(|&z| z <= full + 1e-15 && z >= 0.5 * full - 1e-15)
        );
        assert!(tips.iter().any(|&z| z < 0.8 * full));
    }

    #[test]
    fn the_hairline_thins_and_shortens_only_near_the_border() {
        use crate::model::styling::Hairline;
        // 8 × 8 quads of 1 cm: the centre lies 4 cm from the border.
        let mut document = Document::new("grid", grid(8, 8, 3, 1.0));
        for column in &mut document.hair_mesh.columns {
            for p in &mut column.positions {
                *p *= 0.01;
            }
        }
        document.hair_mesh.update_w();
        let options = StrandOptions {
            strands_per_bundle: 32,
            vertices_log2: 3,
            ..StrandOptions::default()
        };
        let plain = generate(&document, &options);
        document.styling.global.hairline = Hairline {
            width_m: 0.015,
            edge_density: 0.2,
            edge_length: 0.5,
        };
        let thinned = generate(&document, &options);
        assert_eq!(plain.len(), 64 * 32);
        // The rim bundles (distance 0 … 1 cm) grow fewer, shorter strands; the 4 × 4 in the
        // middle (every corner ≥ 2 cm in) are untouched, bit for bit.
        let of = |strands: &[Strand], bundle: u32| -> Vec<Strand> {
            strands
                .iter()
                .filter(|s| s.bundle == bundle)
                .cloned()
                .collect()
        };
        let rim = |b: u32| matches!(b % 8, 0 | 7) || matches!(b / 8, 0 | 7);
        let middle = |b: u32| (2..6).contains(&(b % 8)) && (2..6).contains(&(b / 8));
        let (mut rim_plain, mut rim_thinned) = (0, 0);
        for bundle in 0..64 {
            let (a, b) = (of(&plain, bundle), of(&thinned, bundle));
            if middle(bundle) {
                assert_eq!(a, b, "bundle {bundle}");
            }
            if rim(bundle) {
                rim_plain += a.len();
                rim_thinned += b.len();
                assert!(b.iter().all(|s| s.length_fraction < 1.0), "bundle {bundle}");
            }
            assert!(b.iter().all(|s| s.points.iter().all(|p| p.is_finite())));
        }
        let share = rim_thinned as f64 / rim_plain as f64;
        assert!(
            (0.2..0.75).contains(&share),
            "rim keeps {share} of its strands"
        );
        // Tips come closer to the root than the plain strands' where shortened.
        let reach = |s: &Strand| s.points[0].distance(*s.points.last().expect("tip"));
        let mean = |strands: &[Strand]| {
            let rim: Vec<f64> = strands
                .iter()
                .filter(|s| rim(s.bundle))
                .map(reach)
                .collect();
            rim.iter().sum::<f64>() / rim.len() as f64
        };
        assert!(mean(&thinned) < 0.9 * mean(&plain));
    }
}
