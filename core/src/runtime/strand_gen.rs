//! CPU mirror of `shaders/strand_gen.wgsl` and the vertex it evaluates,
//! `shaders/shared/strand_vertex.wgsl`: every strand vertex computed from the five
//! runtime textures exactly as the shader computes it, in f32 (the styling ops in f64, within
//! the parity bound of `render/tests/strand_gen.rs`). Functions carry the names of the WGSL
//! functions they mirror: [`fetch`], [`StrandGen::strand_position`], [`strand_root`],
//! [`StrandGen::styled_vertex`], [`StrandGen::main`] (the compute entry point, one batch) and
//! [`StrandGen::thick_main`] (far hair's thick hairs from their corner strands).
//! The GPU stage that runs the shader is `render/src/renderer/strand_gen.rs`.

use glam::{DVec3, Vec2, Vec3, Vec4};

use crate::model::styling::StylingParams;
use crate::runtime::gpu_types::{StrandRoot, StrandRun, ThickHairGpu};
use crate::runtime::hair::strand_root;
use crate::runtime::textures::{RuntimeTextures, Texture3d, curve_fetch_slices};
use crate::strands::styling::{
    StrandStyling, StylingInput, hairline_length_scale, strand_length_fraction, styling_offset_of,
    twist,
};

/// The per-strand values `strand_gen.wgsl` computes once before a strand's vertices.
#[derive(Clone, Copy, Debug)]
pub struct StrandInput<'p> {
    pub root: StrandRoot,
    pub params: &'p StylingParams,
    pub root_uv: glam::DVec2,
    /// Fraction of the bundle's length this strand keeps (length variation, strays, the
    /// hairline); 0 for a strand that does not grow.
    pub length_fraction: f64,
    /// The styling ops' per-strand values (random phases and keys, clump pull).
    pub styling: StrandStyling,
    /// The painted length map's share at the root (1 without maps): a cut strand is the
    /// first `cut` of the strand it would be, so its styling reads `along · cut`.
    pub cut: f64,
}

/// Texture filtering as the texture-path mirror performs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Filtering {
    /// f32 weights (manual filtering in the shader).
    Exact,
    /// Weights quantised to 8 fractional bits, as GPU texture units do.
    Hardware8Bit,
}

/// What a runtime measured of the two filterings on its own adapter, from which it chooses
/// its default ([`FilteringMeasure::choice`]): the paper's "texture-unit interpolation"
/// pays only where the adapter makes it faster, and only while the 8-bit weights move no
/// vertex visibly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilteringMeasure {
    /// Generation time of the measured strands with exact filtering.
    pub exact_ms: f64,
    /// With hardware weights; `None` where the adapter cannot filter the textures.
    pub hardware_ms: Option<f64>,
    /// Largest and mean distance of a hardware-filtered vertex from its exact one.
    pub hardware_error_max_m: f64,
    pub hardware_error_mean_m: f64,
    /// The largest error allowed (half a strand's width).
    pub tolerance_m: f64,
    /// Strands measured.
    pub strands: usize,
}

impl FilteringMeasure {
    /// Hardware weights where they are at least [`Self::MIN_GAIN`] faster and their largest
    /// error is within the tolerance; exact filtering otherwise (and on any non-finite
    /// measure).
    pub fn choice(&self) -> Filtering {
        match self.hardware_ms {
            Some(hardware)
                if hardware.is_finite()
                    && self.exact_ms.is_finite()
                    && hardware <= self.exact_ms * (1.0 - Self::MIN_GAIN)
                    && self.hardware_error_max_m <= self.tolerance_m =>
            {
                Filtering::Hardware8Bit
            }
            _ => Filtering::Exact,
        }
    }

    /// The least time saved (a share of exact filtering's) worth 8-bit weights: below it a
    /// measure on a shared machine is noise.
    pub const MIN_GAIN: f64 = 0.05;
}

/// Trilinear sample at continuous texel coordinates (texel centres at `i + 0.5`), clamped
/// to the edge: the CPU mirror of a filtered `textureSampleLevel`.
pub fn fetch(texture: &Texture3d, coord: Vec3, filtering: Filtering) -> Vec4 {
    let axis = |c: f32, size: u32| {
        let x = (c - 0.5).clamp(0.0, (size - 1) as f32);
        let i0 = (x.floor() as u32).min(size.saturating_sub(2));
        let mut frac = x - i0 as f32;
        if filtering == Filtering::Hardware8Bit {
            frac = (frac * 256.0).round() / 256.0;
        }
        let i1 = (i0 + 1).min(size - 1);
        (i0, i1, frac)
    };
    let (x0, x1, fx) = axis(coord.x, texture.width);
    let (y0, y1, fy) = axis(coord.y, texture.height);
    let (z0, z1, fz) = axis(coord.z, texture.depth);
    let lerp = |a: Vec4, b: Vec4, t: f32| a + (b - a) * t;
    let plane = |z: u32| {
        let bottom = lerp(texture.get(x0, y0, z), texture.get(x1, y0, z), fx);
        let top = lerp(texture.get(x0, y1, z), texture.get(x1, y1, z), fx);
        lerp(bottom, top, fy)
    };
    lerp(plane(z0), plane(z1), fz)
}

/// The texture-path mirror: a strand position computed exactly as the strand-generation
/// shader will, from the textures alone, in f32.
pub struct StrandGen<'a> {
    pub textures: &'a RuntimeTextures,
    pub filtering: Filtering,
}

impl StrandGen<'_> {
    /// Position of the strand of atlas block `block` at block coordinates `(s, t)` and
    /// curve parameter `tau ∈ [0, layers]` (layer units).
    pub fn position(&self, block: usize, s: f32, t: f32, tau: f32) -> Vec3 {
        let block = &self.textures.atlas.blocks[block];
        let texel = Vec2::new(
            block.origin[0] as f32 + 0.5 + s,
            block.origin[1] as f32 + 0.5 + t,
        );
        self.strand_position(texel, block.layers, tau)
    }

    /// Position at root texel coordinates `texel` of a bundle with `layers` layers and curve
    /// parameter `tau` (mirror: `strand_position` in `shared/strand_vertex.wgsl`).
    pub fn strand_position(&self, texel: Vec2, layers: u32, tau: f32) -> Vec3 {
        let (z_a, z_b, q) = curve_fetch_slices(layers, tau);
        let fetch = |slice: f32| {
            fetch(
                &self.textures.hair_mesh,
                texel.extend(slice + 0.5),
                self.filtering,
            )
            .truncate()
        };
        let a = fetch(z_a);
        let b = fetch(z_b);
        a + (b - a) * q + self.textures.position_offset
    }

    /// The styled strand rooted at `sample` (bundle-corner coordinates for quads, barycentric
    /// for triangles — the manifest's sample sets) of atlas block `block_index`.
    pub fn styled_strand_of_sample(
        &self,
        block_index: usize,
        sample: glam::DVec2,
        vertex_count: usize,
        params: &StylingParams,
    ) -> Vec<Vec3> {
        let block = &self.textures.atlas.blocks[block_index];
        // Rank 0: it grows wherever the hairline op grows any strand (`edge_density > 0`).
        let root = strand_root(block, [sample.x as f32, sample.y as f32], 0, 0.0);
        self.styled_strand(&root, vertex_count, params)
    }

    /// What a strand's vertices share, computed once (mirror: `strand_input`, which the
    /// shader's `main` runs once per strand): the root uv, the length fraction and the
    /// styling ops' random values and clump pull. The root uv seeds every per-strand random
    /// value, so it is always filtered exactly (manual bilinear in the shader), even in
    /// hardware mode: 8-bit weights must not shift a strand's curl phase or clump.
    pub fn strand_input<'p>(
        &self,
        root: &StrandRoot,
        params: &'p StylingParams,
    ) -> StrandInput<'p> {
        let texel = Vec2::from_array(root.texel);
        let root_uv = fetch(&self.textures.uv, texel.extend(0.5), Filtering::Exact)
            .truncate()
            .truncate()
            .as_dvec2();
        // The root slice's fourth channel: the root's distance to the border of the hair,
        // always exact (it decides whether the strand grows).
        let hairline_distance = fetch(
            &self.textures.hair_mesh,
            texel.extend(0.5),
            Filtering::Exact,
        )
        .w as f64;
        // The painted maps at the root (exact too: density decides whether it grows).
        let maps = self.textures.root_maps.sample(root_uv);
        StrandInput {
            root: *root,
            params,
            root_uv,
            length_fraction: strand_length_fraction(params, root_uv)
                * hairline_length_scale(params, hairline_distance, root.rank as f64)
                * maps.length_scale(root.rank as f64),
            styling: StrandStyling::new(params, root_uv).with_clump_share(maps.clump),
            cut: maps.length,
        }
    }

    /// Vertex `k` of `n` of a styled strand (mirror: `styled_vertex`): the position from the
    /// hair-mesh texture, w and û, v̂ from linear fetches between layer slices, then twist and
    /// the styling offset of [`crate::strands::styling`] (in f64: the GPU's f32 stays within
    /// the parity bound of `render/tests/strand_gen.rs`).
    pub fn styled_vertex(&self, input: &StrandInput<'_>, k: usize, n: usize) -> Vec3 {
        let (root, params) = (&input.root, input.params);
        let texel = Vec2::from_array(root.texel);
        let along = k as f64 / (n.max(2) - 1) as f64;
        let tau = (root.layers as f64 * input.length_fraction * along) as f32;
        let p = self.strand_position(texel, root.layers, tau);
        // A strand that does not grow (hairline) lies at its root: nothing is drawn.
        if k == 0 || input.length_fraction <= 0.0 {
            return p;
        }
        let layer_fetch =
            |texture: &Texture3d| fetch(texture, texel.extend(tau + 0.5), self.filtering);
        let u = layer_fetch(&self.textures.u)
            .truncate()
            .as_dvec3()
            .try_normalize()
            .unwrap_or(DVec3::X);
        let v = layer_fetch(&self.textures.v)
            .truncate()
            .as_dvec3()
            .try_normalize()
            .unwrap_or(DVec3::Y);
        let w_axis = u
            .cross(v)
            .try_normalize()
            .unwrap_or_else(|| crate::geometry::frames::fallback_frame(u).v);
        let w = layer_fetch(&self.textures.w).x as f64;
        let mut p = p.as_dvec3();
        if params.twist.turns_per_m != 0.0 {
            let centre = Vec2::from_array(root.centre_texel);
            let centre = self.strand_position(centre, root.layers, tau).as_dvec3();
            p = twist(params, p, centre, w_axis, w);
        }
        let styling = StylingInput {
            u,
            v,
            w_axis,
            root_uv: input.root_uv,
            w,
            along: along * input.cut,
        };
        (p + styling_offset_of(params, &input.styling, &styling)).as_vec3()
    }

    /// The styled strand of `root` at `vertex_count` vertices (at least 2).
    pub fn styled_strand(
        &self,
        root: &StrandRoot,
        vertex_count: usize,
        params: &StylingParams,
    ) -> Vec<Vec3> {
        let input = self.strand_input(root, params);
        let n = vertex_count.max(2);
        (0..n).map(|k| self.styled_vertex(&input, k, n)).collect()
    }

    /// CPU mirror of the `strand_gen` compute stage for one batch: the vertices of every
    /// run, in scratch order (`run.vertex_offset + strand · vertex_count + k`), with
    /// `styling[root.styling]` (an out-of-range index uses `styling[0]`, as the shader does)
    /// and eq. 11 morphing of odd vertices by the run's γ.
    pub fn main(
        &self,
        roots: &[StrandRoot],
        runs: &[StrandRun],
        styling: &[&StylingParams],
    ) -> Vec<Vec3> {
        let default = StylingParams::default();
        let mut out = Vec::new();
        for run in runs {
            for strand in 0..run.strand_count {
                let root = &roots[(run.first_root + strand) as usize];
                let params = params_of(root, styling, &default);
                let points = self.styled_strand(root, run.vertex_count as usize, params);
                let mut points: Vec<DVec3> = points.iter().map(|p| p.as_dvec3()).collect();
                crate::strands::lod::morph_odd_vertices(&mut points, run.gamma as f64);
                out.extend(points.iter().map(|p| p.as_vec3()));
            }
        }
        out
    }
}

/// A thick hair's vertex as `thick_main` writes it: the centre of its four corner strands'
/// vertices and the half-axes they span ([`crate::runtime::thick_hair::CrossSection::from_corners`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThickVertex {
    pub centre: Vec3,
    /// `k / (n − 1)`.
    pub along: f32,
    /// Half of `+major − −major` and of `+minor − −minor`.
    pub major: Vec3,
    pub minor: Vec3,
    pub members: u32,
}

impl StrandGen<'_> {
    /// CPU mirror of `thick_main`: every vertex of `thick_hairs` at `vertex_count` vertices
    /// each, thick-hair-major, with `styling` chosen per corner root as [`StrandGen::main`]
    /// chooses it. Corner roots out of `roots` are refused by the caller's table
    /// ([`crate::runtime::thick_hair::FarHair`] only names grown strands).
    pub fn thick_main(
        &self,
        roots: &[StrandRoot],
        thick_hairs: &[ThickHairGpu],
        vertex_count: u32,
        styling: &[&StylingParams],
    ) -> Vec<ThickVertex> {
        let default = StylingParams::default();
        let n = vertex_count.max(2) as usize;
        let mut out = Vec::with_capacity(thick_hairs.len() * n);
        for thick in thick_hairs {
            let inputs = thick.corners.map(|c| {
                let root = &roots[c as usize];
                self.strand_input(root, params_of(root, styling, &default))
            });
            for k in 0..n {
                let [a, b, c, d] = inputs
                    .each_ref()
                    .map(|input| self.styled_vertex(input, k, n));
                out.push(ThickVertex {
                    centre: (a + b + c + d) * 0.25,
                    along: k as f32 / (n - 1) as f32,
                    major: (a - b) * 0.5,
                    minor: (c - d) * 0.5,
                    members: thick.members,
                });
            }
        }
        out
    }
}

/// The styling parameters of `root`: `styling[root.styling]`, or `styling[0]` when out of
/// range (as the shader reads them).
fn params_of<'p>(
    root: &StrandRoot,
    styling: &[&'p StylingParams],
    default: &'p StylingParams,
) -> &'p StylingParams {
    styling
        .get(root.styling as usize)
        .or(styling.first())
        .copied()
        .unwrap_or(default)
}

/// Every strand as the runtime draws it at full detail, `vertex_count` vertices each: the
/// piecewise quadratics of the textures at their precision, filtered by `filtering`, styled
/// (what `hairloom export --curve runtime` writes, so a game can compare its own loader).
/// Strands come in the GPU's order: bundle-major over the atlas blocks, `coord` holding the
/// manifest sample each was drawn from. A strand the hairline op does not grow is kept, every
/// vertex at its root and `length_fraction` 0, as the GPU draws it (far hair's hierarchy
/// numbers strands by their place in the bundle); exports leave such strands out.
pub fn runtime_strands(
    hair: &crate::runtime::hair::RuntimeHair,
    vertex_count: usize,
    filtering: Filtering,
) -> Vec<crate::strands::reference::Strand> {
    let generator = StrandGen {
        textures: &hair.textures,
        filtering,
    };
    let styling: Vec<&StylingParams> = std::iter::once(&hair.styling.global)
        .chain(hair.styling.groups.iter().map(|g| &g.params))
        .collect();
    let per_bundle = (hair.strands_per_bundle as usize).max(1);
    let n = vertex_count.max(2);
    hair.strand_roots()
        .iter()
        .enumerate()
        // A thinned bundle grows only its first ⌈density · N⌉ roots.
        .filter(|(i, _)| i % per_bundle < hair.block_strand_count(i / per_bundle) as usize)
        .map(|(i, root)| {
            let block = &hair.textures.atlas.blocks[i / per_bundle];
            let params = styling
                .get(root.styling as usize)
                .copied()
                .unwrap_or(&hair.styling.global);
            let input = generator.strand_input(root, params);
            let samples = if crate::runtime::atlas::Atlas::is_triangle(block) {
                &hair.samples.triangle
            } else {
                &hair.samples.quad
            };
            let sample = samples.get(i % per_bundle).copied().unwrap_or_default();
            crate::strands::reference::Strand {
                bundle: block.bundle,
                root: i as u32,
                coord: crate::geometry::curve::FaceCoord {
                    s: sample[0] as f64,
                    t: sample[1] as f64,
                },
                root_uv: input.root_uv,
                length_fraction: input.length_fraction,
                points: (0..n)
                    .map(|k| generator.styled_vertex(&input, k, n).as_dvec3())
                    .collect(),
            }
        })
        .collect()
}

/// One run over the first `root_count` roots at `vertex_count` vertices, no morphing:
/// generation without LOD, in one batch.
pub fn full_detail_runs(root_count: usize, vertex_count: u32) -> Vec<StrandRun> {
    if root_count == 0 {
        return Vec::new();
    }
    vec![StrandRun {
        first_root: 0,
        strand_count: root_count as u32,
        vertex_count,
        vertex_offset: 0,
        segment_offset: 0,
        gamma: 0.0,
        thickness: 1.0,
        _padding: 0,
    }]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::curve::{ReferenceStrand, SegmentForm};
    use crate::runtime::atlas::Atlas;
    use crate::runtime::test_meshes::curved_mesh;
    use crate::runtime::textures::Precision;

    #[test]
    fn hardware_filtering_is_chosen_only_where_faster_and_within_tolerance() {
        let measure = FilteringMeasure {
            exact_ms: 1.0,
            hardware_ms: Some(0.8),
            hardware_error_max_m: 1e-4,
            hardware_error_mean_m: 1e-5,
            tolerance_m: 2e-4,
            strands: 100,
        };
        assert_eq!(measure.choice(), Filtering::Hardware8Bit);
        for worse in [
            FilteringMeasure {
                hardware_ms: Some(0.97),
                ..measure
            },
            FilteringMeasure {
                hardware_ms: None,
                ..measure
            },
            FilteringMeasure {
                hardware_error_max_m: 3e-4,
                ..measure
            },
            FilteringMeasure {
                hardware_ms: Some(f64::NAN),
                ..measure
            },
            FilteringMeasure {
                exact_ms: f64::INFINITY,
                hardware_ms: Some(1.0),
                ..measure
            },
        ] {
            assert_eq!(worse.choice(), Filtering::Exact, "{worse:?}");
        }
    }

    #[test]
    fn texture_path_matches_the_f64_reference() {
        let mesh = curved_mesh();
        let textures = RuntimeTextures::build(&mesh, Precision::F32);
        let size = 5.0f32;
        for filtering in [Filtering::Exact, Filtering::Hardware8Bit] {
            let path = StrandGen {
                textures: &textures,
                filtering,
            };
            let mut worst = 0.0f64;
            for (index, block) in textures.atlas.blocks.iter().enumerate() {
                for (s, t) in [(0.0, 0.0), (0.3, 0.7), (0.91, 0.12), (1.0, 1.0), (0.5, 0.5)] {
                    let weights = Atlas::corner_weights(block, s, t);
                    let reference =
                        ReferenceStrand::with_weights(&mesh, block.bundle as usize, weights)
                            .expect("bundle");
                    for i in 0..=30 {
                        let tau = i as f64 / 10.0;
                        let expected = reference.point(
                            tau,
                            crate::geometry::curve::CurveDefinition::ColumnBlend,
                            SegmentForm::TwoQuadratics,
                        );
                        let got = path.position(index, s as f32, t as f32, tau as f32);
                        worst = worst.max(got.as_dvec3().distance(expected));
                    }
                }
            }
            match filtering {
                // f32 rounding only.
                Filtering::Exact => assert!(worst < 1e-6 * size as f64, "exact: {worst}"),
                // 8-bit weights: at most half a step (1/512) of the largest texel difference
                // per axis; this mesh's neighbouring control points are ≤ 1.6 apart.
                Filtering::Hardware8Bit => {
                    assert!(worst > 1e-6, "quantisation must show");
                    assert!(worst < 3.0 * 1.6 / 512.0, "hardware: {worst}");
                }
            }
        }
    }
}
