//! The runtime textures of seed 000 Table 1, built from a hair mesh.
//!
//! | texture | dim | texel | slices along r |
//! |---|---|---|---|
//! | hair mesh | 3D | object-space position | root, then per segment 3 intermediate + 1 layer slice |
//! | uv | 2D | root uv | — |
//! | w | 3D | w | one per layer |
//! | u, v | 3D | styling directions û, v̂ | one per layer |
//!
//! Hair-mesh slices of segment `k` (layer `k` → `k+1`): `4k` = `p_k`, `4k+1` = `q0`,
//! `4k+2` = `m`, `4k+3` = `q1`, `4k+4` = `p_{k+1}`, where `(p_k, q0, m)` and `(m, q1, p_{k+1})`
//! are the two quadratics of the column's cubic segment (`curve::cubic_to_quadratics`).
//! A quadratic at parameter `q` is `lerp(fetch(a + q), fetch(a + 1 + q), q)` with `a` its first
//! slice: two filtered fetches and one lerp.
//!
//! Texels are stored as RGBA (3D textures have no 3-channel formats). The `f16` variant stores
//! positions relative to [`RuntimeTextures::position_offset`] (the bounding-box centre) so that
//! half precision is spent on the hair, not on the distance from the origin.

use glam::{DVec3, Vec2, Vec3, Vec4};

use crate::atlas::{Atlas, BundleBlock, build_atlas};
use crate::curve::{cubic_to_quadratics, curve_segments};
use crate::frames::layer_frames;
use crate::mesh::HairMesh;

/// Slices of the hair-mesh texture per segment (3 intermediate + 1 layer).
pub const SLICES_PER_SEGMENT: u32 = 4;
/// Largest region side in the atlas.
pub const MAX_REGION_SIDE: usize = 64;

/// Texel precision of the 3D position and direction textures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Precision {
    F32,
    F16,
}

/// A 3D texture of RGBA texels, x fastest, then y, then slice.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture3d {
    pub width: u32,
    pub height: u32,
    pub depth: u32,
    pub texels: Vec<Vec4>,
}

impl Texture3d {
    fn new(width: u32, height: u32, depth: u32) -> Self {
        Self {
            width,
            height,
            depth,
            texels: vec![Vec4::ZERO; (width * height * depth) as usize],
        }
    }

    pub fn index(&self, x: u32, y: u32, z: u32) -> usize {
        ((z * self.height + y) * self.width + x) as usize
    }

    pub fn get(&self, x: u32, y: u32, z: u32) -> Vec4 {
        self.texels[self.index(x, y, z)]
    }

    fn set(&mut self, x: u32, y: u32, z: u32, value: Vec4) {
        let i = self.index(x, y, z);
        self.texels[i] = value;
    }
}

/// The five textures plus the layout needed to sample them.
#[derive(Clone, Debug, PartialEq)]
pub struct RuntimeTextures {
    pub atlas: Atlas,
    pub precision: Precision,
    /// Added back to sampled hair-mesh positions (zero for f32).
    pub position_offset: Vec3,
    /// Positions: `1 + 4·max_layers` slices.
    pub hair_mesh: Texture3d,
    /// Root uv (x, y used), one slice.
    pub uv: Texture3d,
    /// w (x used), `1 + max_layers` slices.
    pub w: Texture3d,
    /// û (xyz), `1 + max_layers` slices.
    pub u: Texture3d,
    /// v̂ (xyz), `1 + max_layers` slices.
    pub v: Texture3d,
}

/// Round-to-nearest-even conversion to IEEE half precision and back (what an f16 texture
/// stores), with overflow to ±∞ clamped to the largest finite half.
pub fn round_to_f16(value: f32) -> f32 {
    if !value.is_finite() {
        return if value.is_nan() {
            0.0
        } else {
            value.signum() * 65504.0
        };
    }
    let magnitude = value.abs();
    if magnitude >= 65504.0 {
        return value.signum() * 65504.0;
    }
    // Spacing of halves near `magnitude`: 2^(e − 10), with subnormals at 2^-24.
    let exponent = if magnitude < 6.103_515_6e-5 {
        -14
    } else {
        magnitude.log2().floor() as i32
    };
    let step = 2f32.powi(exponent - 10);
    let quotient = magnitude / step;
    let rounded = quotient.round();
    // Ties to even (dividing by a power of two is exact, so a tie is exactly .5).
    let rounded = if quotient - quotient.floor() == 0.5 && rounded % 2.0 != 0.0 {
        rounded - 1.0
    } else {
        rounded
    };
    value.signum() * rounded * step
}

fn quantize(v: Vec4, precision: Precision) -> Vec4 {
    match precision {
        Precision::F32 => v,
        Precision::F16 => Vec4::new(
            round_to_f16(v.x),
            round_to_f16(v.y),
            round_to_f16(v.z),
            round_to_f16(v.w),
        ),
    }
}

impl RuntimeTextures {
    /// Builds every texture for the bundles that grow hair.
    pub fn build(mesh: &HairMesh, precision: Precision) -> Self {
        let atlas = build_atlas(mesh, MAX_REGION_SIDE);
        let max_layers = atlas.blocks.iter().map(|b| b.layers).max().unwrap_or(0);
        let (width, height) = (atlas.width, atlas.height);
        let (lo, hi) = mesh.bounds().unwrap_or((DVec3::ZERO, DVec3::ZERO));
        let offset = match precision {
            Precision::F32 => DVec3::ZERO,
            Precision::F16 if lo.is_finite() && hi.is_finite() => (lo + hi) * 0.5,
            Precision::F16 => DVec3::ZERO,
        };
        let mut hair_mesh = Texture3d::new(width, height, 1 + SLICES_PER_SEGMENT * max_layers);
        let mut uv = Texture3d::new(width, height, 1);
        let mut w = Texture3d::new(width, height, 1 + max_layers);
        let mut u = Texture3d::new(width, height, 1 + max_layers);
        let mut v = Texture3d::new(width, height, 1 + max_layers);
        let frames: Vec<_> = (0..=max_layers as usize)
            .map(|k| layer_frames(mesh, k))
            .collect();
        let segments: Vec<_> = mesh
            .columns
            .iter()
            .map(|c| curve_segments(&c.positions))
            .collect();
        let position = |p: DVec3| quantize((p - offset).as_vec3().extend(0.0), precision);
        for y in 0..height {
            for x in 0..width {
                let Some(source) = atlas.texels[(y * width + x) as usize] else {
                    continue;
                };
                let c = source.column as usize;
                let column = &mesh.columns[c];
                uv.set(
                    x,
                    y,
                    0,
                    Vec4::new(source.uv.x as f32, source.uv.y as f32, 0.0, 0.0),
                );
                let last = column.positions.len() - 1;
                for k in 0..=max_layers as usize {
                    // Slices past the column's tip repeat the tip (never sampled by a bundle).
                    let layer = k.min(last);
                    hair_mesh.set(
                        x,
                        y,
                        SLICES_PER_SEGMENT * k as u32,
                        position(column.positions[layer]),
                    );
                    w.set(
                        x,
                        y,
                        k as u32,
                        quantize(Vec4::new(column.w[layer] as f32, 0.0, 0.0, 0.0), precision),
                    );
                    let frame =
                        frames[layer][c].unwrap_or_else(|| crate::frames::fallback_frame(DVec3::Y));
                    u.set(
                        x,
                        y,
                        k as u32,
                        quantize(frame.u.as_vec3().extend(0.0), precision),
                    );
                    v.set(
                        x,
                        y,
                        k as u32,
                        quantize(frame.v.as_vec3().extend(0.0), precision),
                    );
                    if k < max_layers as usize {
                        let base = SLICES_PER_SEGMENT * k as u32;
                        let [first, second] = match segments[c].get(k) {
                            Some(segment) => cubic_to_quadratics(segment),
                            None => [[column.positions[last]; 3]; 2],
                        };
                        hair_mesh.set(x, y, base + 1, position(first[1]));
                        hair_mesh.set(x, y, base + 2, position(first[2]));
                        hair_mesh.set(x, y, base + 3, position(second[1]));
                    }
                }
            }
        }
        Self {
            atlas,
            precision,
            position_offset: offset.as_vec3(),
            hair_mesh,
            uv,
            w,
            u,
            v,
        }
    }

    /// Roots of the first `per_bundle` samples of `samples` in every bundle, mapped onto
    /// each bundle's block: the bundle-level work of generation. `styling_of_block` gives a
    /// block's index into the styling array (0 = global, `g + 1` = group `g`).
    pub fn strand_roots(
        &self,
        samples: &RootSamples,
        per_bundle: usize,
        styling_of_block: impl Fn(usize, &BundleBlock) -> u32,
    ) -> Vec<crate::gpu_types::StrandRoot> {
        let per_bundle = per_bundle
            .min(samples.quad.len())
            .min(samples.triangle.len());
        let mut roots = Vec::with_capacity(self.atlas.blocks.len() * per_bundle);
        for (index, block) in self.atlas.blocks.iter().enumerate() {
            let set = if Atlas::is_triangle(block) {
                &samples.triangle
            } else {
                &samples.quad
            };
            let styling = styling_of_block(index, block);
            roots.extend(
                set[..per_bundle]
                    .iter()
                    .map(|sample| strand_root(block, *sample, styling)),
            );
        }
        roots
    }

    /// Each block's index into the styling array for a document's styling: 0 = global,
    /// `g + 1` = group `g` (see [`crate::styling::StylingSet::group_of`]).
    pub fn block_styling(&self, styling: &crate::styling::StylingSet) -> Vec<u32> {
        self.atlas
            .blocks
            .iter()
            .map(|block| styling.group_of(block.bundle).map_or(0, |g| g as u32 + 1))
            .collect()
    }

    /// Roots of a document's bundles, each with its styling index.
    pub fn document_roots(
        &self,
        styling: &crate::styling::StylingSet,
        samples: &RootSamples,
        per_bundle: usize,
    ) -> Vec<crate::gpu_types::StrandRoot> {
        let block_styling = self.block_styling(styling);
        self.strand_roots(samples, per_bundle, |index, _| block_styling[index])
    }

    /// The control points block `block` samples (positions plus the offset), slice by slice.
    fn block_points(&self, block: &BundleBlock) -> impl Iterator<Item = (u32, Vec3)> + '_ {
        let texture = &self.hair_mesh;
        let slices = (SLICES_PER_SEGMENT * block.layers + 1).min(texture.depth);
        let xs = block.origin[0]..(block.origin[0] + 2).min(texture.width);
        let ys = block.origin[1]..(block.origin[1] + 2).min(texture.height);
        (0..slices).flat_map(move |z| {
            let xs = xs.clone();
            ys.clone().flat_map(move |y| {
                xs.clone()
                    .map(move |x| (z, texture.get(x, y, z).truncate() + self.position_offset))
            })
        })
    }

    /// Bounding box of every control point the bundles' blocks sample, from the hair-mesh
    /// texture alone: the same box for a project and for its exported runtime bundle. `None`
    /// without bundles.
    pub fn hair_bounds(&self) -> Option<(Vec3, Vec3)> {
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for block in &self.atlas.blocks {
            for (_, p) in self.block_points(block) {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        (lo.x <= hi.x).then_some((lo, hi))
    }

    /// Per block: a bounding sphere of its control points and the length of its first
    /// column's layer polygon — the inputs of strand and vertex LOD.
    pub fn bundle_bounds(&self) -> Vec<crate::lod::BundleBounds> {
        self.atlas
            .blocks
            .iter()
            .map(|block| {
                let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
                for (_, p) in self.block_points(block) {
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
                let centre = (lo + hi) * 0.5;
                let radius_m = self
                    .block_points(block)
                    .map(|(_, p)| p.distance(centre))
                    .fold(0.0f32, f32::max);
                let roots: Vec<Vec3> = self
                    .block_points(block)
                    .filter(|&(slice, _)| slice == 0)
                    .map(|(_, p)| p)
                    .collect();
                let root_size_m = roots
                    .iter()
                    .flat_map(|a| roots.iter().map(move |b| a.distance(*b)))
                    .fold(0.0f32, f32::max);
                let (x, y) = (block.origin[0], block.origin[1]);
                let strand_length_m = (0..block.layers)
                    .map(|k| {
                        let at = |layer: u32| {
                            self.hair_mesh
                                .get(
                                    x,
                                    y,
                                    (SLICES_PER_SEGMENT * layer).min(self.hair_mesh.depth - 1),
                                )
                                .truncate()
                        };
                        at(k).distance(at(k + 1))
                    })
                    .sum();
                crate::lod::BundleBounds {
                    centre,
                    radius_m,
                    root_size_m,
                    strand_length_m,
                }
            })
            .collect()
    }

    /// Bytes the five textures take on the GPU: RGBA hair mesh, u and v (4 channels), R w,
    /// at 4 bytes (f32) or 2 bytes (f16) per channel, and the RG uv-texture, always f32
    /// (see `export::TexelFormat::for_precision`).
    pub fn gpu_bytes(&self) -> usize {
        let channel = match self.precision {
            Precision::F32 => 4,
            Precision::F16 => 2,
        };
        let texels = |t: &Texture3d| (t.width * t.height * t.depth) as usize;
        channel
            * (4 * texels(&self.hair_mesh)
                + 4 * texels(&self.u)
                + 4 * texels(&self.v)
                + texels(&self.w))
            + 8 * texels(&self.uv)
    }
}

/// The root of the strand at `sample` (a manifest sample) of `block`, with the texel of the
/// bundle's centre strand (block centre, or the triangle's centroid) for twist.
pub fn strand_root(
    block: &BundleBlock,
    sample: [f32; 2],
    styling: u32,
) -> crate::gpu_types::StrandRoot {
    let origin = Vec2::new(block.origin[0] as f32, block.origin[1] as f32) + 0.5;
    let centre = if Atlas::is_triangle(block) {
        Vec2::new(0.5, 1.0 / 3.0)
    } else {
        Vec2::splat(0.5)
    };
    let (s, t) =
        Atlas::sample_block_coords(block, glam::DVec2::new(sample[0] as f64, sample[1] as f64));
    crate::gpu_types::StrandRoot {
        texel: (origin + Vec2::new(s as f32, t as f32)).to_array(),
        centre_texel: (origin + centre).to_array(),
        layers: block.layers,
        styling,
        _padding: [0; 2],
    }
}

/// Progressive root samples as a runtime bundle stores them (f32, seed 000 §3.3): quads in
/// block coordinates `[0,1)²`, triangles barycentric `(s, t)`, `s + t < 1`.
#[derive(Clone, Debug, PartialEq)]
pub struct RootSamples {
    pub quad: Vec<[f32; 2]>,
    pub triangle: Vec<[f32; 2]>,
}

impl RootSamples {
    /// `set` samples per domain from `seed` (what an export writes to its manifest).
    pub fn progressive(set: usize, seed: u64) -> Self {
        use crate::roots::{SampleDomain, progressive_samples};
        let samples = |domain| {
            progressive_samples(set, domain, seed)
                .iter()
                .map(|p| [p.x as f32, p.y as f32])
                .collect()
        };
        Self {
            quad: samples(SampleDomain::Square),
            triangle: samples(SampleDomain::Triangle),
        }
    }
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

/// Trilinear sample at continuous texel coordinates (texel centres at `i + 0.5`), clamped
/// to the edge: the CPU mirror of a filtered `textureSampleLevel`.
pub fn sample_trilinear(texture: &Texture3d, coord: Vec3, filtering: Filtering) -> Vec4 {
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
pub struct TexturePath<'a> {
    pub textures: &'a RuntimeTextures,
    pub filtering: Filtering,
}

impl TexturePath<'_> {
    /// Position of the strand of atlas block `block` at block coordinates `(s, t)` and
    /// curve parameter `tau ∈ [0, layers]` (layer units).
    pub fn position(&self, block: usize, s: f32, t: f32, tau: f32) -> Vec3 {
        let block = &self.textures.atlas.blocks[block];
        let texel = Vec2::new(
            block.origin[0] as f32 + 0.5 + s,
            block.origin[1] as f32 + 0.5 + t,
        );
        self.position_at(texel, block.layers, tau)
    }

    /// Position at root texel coordinates `texel` of a bundle with `layers` layers and curve
    /// parameter `tau` (mirror: `strand_position` in `strand_gen.wgsl`).
    pub fn position_at(&self, texel: Vec2, layers: u32, tau: f32) -> Vec3 {
        let tau = tau.clamp(0.0, layers.max(1) as f32);
        let segment = (tau.floor() as u32).min(layers.max(1) - 1);
        let local = tau - segment as f32;
        // Which quadratic, and its parameter.
        let (first_slice, q) = if local < 0.5 {
            (SLICES_PER_SEGMENT * segment, local * 2.0)
        } else {
            (SLICES_PER_SEGMENT * segment + 2, local * 2.0 - 1.0)
        };
        let fetch = |slice: f32| {
            sample_trilinear(
                &self.textures.hair_mesh,
                texel.extend(slice + 0.5),
                self.filtering,
            )
            .truncate()
        };
        let a = fetch(first_slice as f32 + q);
        let b = fetch(first_slice as f32 + 1.0 + q);
        a + (b - a) * q + self.textures.position_offset
    }

    /// The styled strand rooted at `sample` (bundle-corner coordinates for quads, barycentric
    /// for triangles — the manifest's sample sets) of atlas block `block_index`.
    pub fn styled_strand(
        &self,
        block_index: usize,
        sample: glam::DVec2,
        vertex_count: usize,
        params: &crate::styling::StylingParams,
    ) -> Vec<Vec3> {
        let block = &self.textures.atlas.blocks[block_index];
        let root = strand_root(block, [sample.x as f32, sample.y as f32], 0);
        self.styled_strand_at(&root, vertex_count, params)
    }

    /// The styled strand of `root`, computed from the five textures as `strand_gen.wgsl`
    /// does: positions from the hair-mesh texture, root uv from the uv-texture, w and û, v̂
    /// from linear fetches between layer slices, then twist, length variation and the
    /// styling offset of `crate::styling` (in f64: the GPU's f32 stays within the parity
    /// bound of `render/tests/strand_gen.rs`).
    pub fn styled_strand_at(
        &self,
        root: &crate::gpu_types::StrandRoot,
        vertex_count: usize,
        params: &crate::styling::StylingParams,
    ) -> Vec<Vec3> {
        use crate::styling::{StylingInput, apply_twist, strand_length_fraction, styling_offset};
        let texel = Vec2::from_array(root.texel);
        let centre = Vec2::from_array(root.centre_texel);
        let layer_fetch = |texture: &Texture3d, tau: f32| {
            sample_trilinear(texture, texel.extend(tau + 0.5), self.filtering)
        };
        // The root uv seeds every per-strand random value, and it is fetched once per strand:
        // always filter it exactly (manual bilinear in the shader), even in hardware mode,
        // so 8-bit weights cannot shift a strand's curl phase or clump.
        let root_uv = sample_trilinear(&self.textures.uv, texel.extend(0.5), Filtering::Exact)
            .truncate()
            .truncate()
            .as_dvec2();
        let tau_max = root.layers as f64 * strand_length_fraction(params, root_uv);
        let vertex_count = vertex_count.max(2);
        (0..vertex_count)
            .map(|k| {
                let along = k as f64 / (vertex_count - 1) as f64;
                let tau = (tau_max * along) as f32;
                let p = self.position_at(texel, root.layers, tau);
                if k == 0 {
                    return p;
                }
                let u = layer_fetch(&self.textures.u, tau)
                    .truncate()
                    .as_dvec3()
                    .try_normalize()
                    .unwrap_or(DVec3::X);
                let v = layer_fetch(&self.textures.v, tau)
                    .truncate()
                    .as_dvec3()
                    .try_normalize()
                    .unwrap_or(DVec3::Y);
                let w_axis = u
                    .cross(v)
                    .try_normalize()
                    .unwrap_or_else(|| crate::frames::fallback_frame(u).v);
                let w = layer_fetch(&self.textures.w, tau).x as f64;
                let mut p = p.as_dvec3();
                if params.twist.turns_per_m != 0.0 {
                    let centre = self.position_at(centre, root.layers, tau).as_dvec3();
                    p = apply_twist(params, p, centre, w_axis, w);
                }
                let input = StylingInput {
                    u,
                    v,
                    w_axis,
                    root_uv,
                    w,
                    along,
                };
                (p + styling_offset(params, &input)).as_vec3()
            })
            .collect()
    }

    /// CPU mirror of the `strand_gen` compute stage for one batch: the vertices of every
    /// run, in scratch order (`run.vertex_offset + strand · vertex_count + k`), with
    /// `styling[root.styling]` (an out-of-range index uses `styling[0]`, as the shader does)
    /// and eq. 11 morphing of odd vertices by the run's γ.
    pub fn strand_gen(
        &self,
        roots: &[crate::gpu_types::StrandRoot],
        runs: &[crate::gpu_types::StrandRun],
        styling: &[&crate::styling::StylingParams],
    ) -> Vec<Vec3> {
        let default = crate::styling::StylingParams::default();
        let mut out = Vec::new();
        for run in runs {
            for strand in 0..run.strand_count {
                let root = &roots[(run.first_root + strand) as usize];
                let params = styling
                    .get(root.styling as usize)
                    .or(styling.first())
                    .copied()
                    .unwrap_or(&default);
                let points = self.styled_strand_at(root, run.vertex_count as usize, params);
                let mut points: Vec<DVec3> = points.iter().map(|p| p.as_dvec3()).collect();
                crate::lod::morph_odd_vertices(&mut points, run.gamma as f64);
                out.extend(points.iter().map(|p| p.as_vec3()));
            }
        }
        out
    }
}

/// One run over the first `root_count` roots at `vertex_count` vertices, no morphing:
/// generation without LOD, in one batch.
pub fn full_detail_runs(root_count: usize, vertex_count: u32) -> Vec<crate::gpu_types::StrandRun> {
    if root_count == 0 {
        return Vec::new();
    }
    vec![crate::gpu_types::StrandRun {
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
    use crate::atlas::Atlas;
    use crate::curve::{ReferenceStrand, SegmentForm};
    use crate::mesh::test_meshes::grid;

    fn curved_mesh() -> HairMesh {
        let mut mesh = grid(4, 3, 3, 0.4);
        for column in &mut mesh.columns {
            let r = column.positions[0];
            for (k, p) in column.positions.iter_mut().enumerate() {
                let k = k as f64;
                *p += DVec3::new(0.2 * k * k, 0.1 * (r.x + k).sin(), 0.05 * r.y * k);
            }
        }
        mesh.update_w();
        mesh
    }

    #[test]
    fn half_rounding_matches_ieee() {
        assert_eq!(round_to_f16(1.0), 1.0);
        assert_eq!(round_to_f16(1.0 + 1.0 / 2048.0), 1.0, "tie rounds to even");
        assert_eq!(round_to_f16(1.0 + 3.0 / 2048.0), 1.0 + 2.0 / 1024.0);
        assert_eq!(round_to_f16(0.1), 0.099_975_586);
        assert_eq!(round_to_f16(1e6), 65504.0);
        assert_eq!(round_to_f16(-2.0e-8), -0.0);
        assert_eq!(
            round_to_f16(3.0e-8),
            2f32.powi(-24),
            "rounds up to the smallest subnormal"
        );
        assert_eq!(round_to_f16(f32::NAN), 0.0);
    }

    #[test]
    fn texture_path_matches_the_f64_reference() {
        let mesh = curved_mesh();
        let textures = RuntimeTextures::build(&mesh, Precision::F32);
        let size = 5.0f32;
        for filtering in [Filtering::Exact, Filtering::Hardware8Bit] {
            let path = TexturePath {
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
                            crate::curve::CurveDefinition::ColumnBlend,
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

    #[test]
    fn f16_textures_round_positions_within_half_precision() {
        let mesh = curved_mesh();
        let full = RuntimeTextures::build(&mesh, Precision::F32);
        let half = RuntimeTextures::build(&mesh, Precision::F16);
        // Everything halves except the uv-texture, which stays f32.
        let uv_bytes = 8 * (full.uv.width * full.uv.height) as usize;
        assert_eq!(
            (half.gpu_bytes() - uv_bytes) * 2,
            full.gpu_bytes() - uv_bytes
        );
        let exact = TexturePath {
            textures: &full,
            filtering: Filtering::Exact,
        };
        let rounded = TexturePath {
            textures: &half,
            filtering: Filtering::Exact,
        };
        let extent = 4.0f32; // largest |p − centre| component is below 4 here
        let mut worst = 0.0f32;
        for index in 0..full.atlas.blocks.len() {
            for i in 0..=12 {
                let tau = i as f32 / 4.0;
                worst = worst.max(
                    exact
                        .position(index, 0.4, 0.6, tau)
                        .distance(rounded.position(index, 0.4, 0.6, tau)),
                );
            }
        }
        assert!(worst > 0.0 && worst < extent * 2f32.powi(-10), "{worst}");
    }
}
