//! The runtime textures of seed 000 Table 1, built from a hair mesh.
//!
//! | texture | dim | texel | slices along r |
//! |---|---|---|---|
//! | hair mesh | 3D | object-space position | root, then per segment 2 control-point + 1 layer slice |
//! | uv | 2D | root uv | — |
//! | w | 3D | w | one per layer |
//! | u, v | 3D | styling directions û, v̂ | one per layer |
//!
//! Hair-mesh slices of segment `k` (layer `k` → `k+1`): `3k` = `p_k`, `3k+1` = `q0`,
//! `3k+2` = `q1`, `3k+3` = `p_{k+1}`, where `(p_k, q0, m)` and `(m, q1, p_{k+1})` are the two
//! quadratics of the column's cubic segment (`curve::cubic_to_quadratics`). Their joint
//! `m = (q0 + q1) / 2` is not stored: it is the filtered fetch half-way between slices `3k+1`
//! and `3k+2`, so a quadratic at parameter `q` is still two filtered fetches and one lerp (de
//! Casteljau; see [`curve_fetch_slices`]) and the texture takes 3 slices per segment, not 4.
//!
//! The root slice's fourth channel holds each root's distance to the border of the hair
//! ([`crate::geometry::hairline`], what the hairline styling op thins by); every other
//! slice's is 0.
//!
//! Texels are stored as RGBA (3D textures have no 3-channel formats). The `f16` variant stores
//! positions relative to [`RuntimeTextures::position_offset`] (the bounding-box centre) so that
//! half precision is spent on the hair, not on the distance from the origin.

use glam::{DVec3, Vec3, Vec4};

use crate::geometry::curve::{cubic_to_quadratics, curve_segments};
use crate::geometry::frames::layer_frames;
use crate::model::mesh::HairMesh;
use crate::model::root_maps::RootMaps;
use crate::runtime::atlas::{Atlas, BundleBlock, build_atlas};
use crate::runtime::hair::{RootSamples, sample_rank, strand_root};
use crate::runtime::half::round_to_f16;

/// Slices of the hair-mesh texture per segment (2 control points + 1 layer).
pub const SLICES_PER_SEGMENT: u32 = 3;
/// Most extruded layers one bundle may have. The hair-mesh texture holds
/// `1 + SLICES_PER_SEGMENT · layers` slices, and 2048 is the 3D-texture depth every wgpu
/// adapter supports (the default `max_texture_dimension_3d`): 1 + 3 · 511 = 1534 (bundles of
/// format 1, with 4 slices per segment, reach 2045). Real hair meshes use 3-30 layers; a file
/// asking for more is refused by name (a 20,000-layer bundle used to take 23 s and 2.5 GB to
/// export).
pub const MAX_LAYERS_PER_BUNDLE: u32 = 511;
/// What a game that animates the hair mesh needs besides the textures to rebuild them
/// (`docs/runtime-format.md`, "Animating the hair mesh"): each column's layer count, and the
/// scalp faces that grow no hair, whose corners still weigh in on layer 0's frames.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeshTopology {
    /// Layer count `c` of every column of the hair mesh (its vertices are `p_0 … p_c`).
    pub column_layers: Vec<u32>,
    pub bare_faces: Vec<BareFace>,
}

/// A scalp face with no layers: its columns in face order, each corner's uv and rest
/// position (model units; a corner no hairy face shares has no texel to read it from).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BareFace {
    pub columns: Vec<u32>,
    pub uvs: Vec<[f32; 2]>,
    pub positions: Vec<[f32; 3]>,
}

impl MeshTopology {
    pub fn of(mesh: &HairMesh) -> Self {
        Self {
            column_layers: mesh
                .columns
                .iter()
                .map(|c| c.positions.len().saturating_sub(1) as u32)
                .collect(),
            bare_faces: mesh
                .bundles
                .iter()
                .filter(|b| !b.removed && b.layers == 0)
                .map(|b| BareFace {
                    columns: b.vertices.clone(),
                    uvs: b.uvs.iter().map(|uv| uv.as_vec2().to_array()).collect(),
                    positions: b
                        .vertices
                        .iter()
                        .map(|&c| {
                            let column = mesh.columns.get(c as usize);
                            let root = column.and_then(|c| c.positions.first()).copied();
                            root.unwrap_or_default().as_vec3().to_array()
                        })
                        .collect(),
                })
                .collect(),
        }
    }
}

/// Largest region side in the atlas.
pub const MAX_REGION_SIDE: usize = 64;

/// Where the two filtered hair-mesh fetches of curve parameter `tau` (in layers, clamped to
/// `[0, layers]`) sit: `(z_a, z_b, q)` with the point `lerp(fetch(z_a), fetch(z_b), q)`
/// (slice coordinates, add ½ for texel centres). First half of segment `k` (quadratic
/// `p_k, q0, m`): `z_a = 3k + q` (p_k → q0), `z_b = 3k + 1 + q/2` (q0 → m, i.e. a quarter of
/// q0 → q1 per half unit of `q`). Second half (`m, q1, p_{k+1}`): `z_a = 3k + 1.5 + q/2`
/// (m → q1), `z_b = 3k + 2 + q` (q1 → p_{k+1}). Mirror: `curve_fetch_slices` in
/// `shaders/shared/strand_vertex.wgsl`.
pub(crate) fn curve_fetch_slices(layers: u32, tau: f32) -> (f32, f32, f32) {
    let layers = layers.max(1);
    let tau = tau.clamp(0.0, layers as f32);
    let segment = (tau.floor() as u32).min(layers - 1);
    let local = tau - segment as f32;
    let base = (SLICES_PER_SEGMENT * segment) as f32;
    if local < 0.5 {
        let q = local * 2.0;
        (base + q, base + 1.0 + 0.5 * q, q)
    } else {
        let q = local * 2.0 - 1.0;
        (base + 1.5 + 0.5 * q, base + 2.0 + q, q)
    }
}

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
    /// Positions: `1 + 3·max_layers` slices.
    pub hair_mesh: Texture3d,
    /// Root uv (x, y used), one slice.
    pub uv: Texture3d,
    /// w (x used), `1 + max_layers` slices.
    pub w: Texture3d,
    /// û (xyz), `1 + max_layers` slices.
    pub u: Texture3d,
    /// v̂ (xyz), `1 + max_layers` slices.
    pub v: Texture3d,
    /// Column layer counts and bare faces (empty for bundles before format version 4).
    pub topology: MeshTopology,
    /// Density, length and clump painted in root-uv space (the document's; none: 1
    /// everywhere). Not built from the hair mesh: [`crate::runtime::hair::RuntimeHair`]
    /// takes them from the document.
    pub root_maps: RootMaps,
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
        // The root slice's fourth channel: each root's distance to the border of the hair
        // (the hairline op's input; object units, not offset).
        let hairline = crate::geometry::hairline::column_distances(mesh);
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
                    let mut point = position(column.positions[layer]);
                    if k == 0 {
                        point.w = quantize(Vec4::splat(hairline[c] as f32), precision).w;
                    }
                    hair_mesh.set(x, y, SLICES_PER_SEGMENT * k as u32, point);
                    w.set(
                        x,
                        y,
                        k as u32,
                        quantize(Vec4::new(column.w[layer] as f32, 0.0, 0.0, 0.0), precision),
                    );
                    let frame = frames[layer][c]
                        .unwrap_or_else(|| crate::geometry::frames::fallback_frame(DVec3::Y));
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
                        // q0 and q1; the joint m = (q0 + q1) / 2 is fetched between them.
                        hair_mesh.set(x, y, base + 1, position(first[1]));
                        hair_mesh.set(x, y, base + 2, position(second[1]));
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
            topology: MeshTopology::of(mesh),
            root_maps: RootMaps::default(),
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
    ) -> Vec<crate::runtime::gpu_types::StrandRoot> {
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
            roots.extend(set[..per_bundle].iter().enumerate().map(|(j, sample)| {
                strand_root(block, *sample, styling, sample_rank(j, per_bundle))
            }));
        }
        roots
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
    pub fn bundle_bounds(&self) -> Vec<crate::runtime::frame_plan::BundleBounds> {
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
                crate::runtime::frame_plan::BundleBounds {
                    centre,
                    radius_m,
                    root_size_m,
                    strand_length_m,
                    density: 1.0,
                }
            })
            .collect()
    }

    /// Bytes the five textures take on the GPU: RGBA hair mesh, u and v (4 channels), R w,
    /// at 4 bytes (f32) or 2 bytes (f16) per channel, and the RG uv-texture, always f32
    /// (see `io::ktx2::TexelFormat::for_precision`).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runtime::strand_gen::{Filtering, StrandGen};
    use crate::runtime::test_meshes::curved_mesh;

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
        let exact = StrandGen {
            textures: &full,
            filtering: Filtering::Exact,
        };
        let rounded = StrandGen {
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
