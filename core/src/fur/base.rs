//! Where fur grows on a hair mesh, and the arrays the shell and fin shaders read
//! (`shaders/fur.wgsl`; CPU mirror of its vertex stage: [`shell_point`], [`fin_fade`]).
//!
//! The surface is the hair mesh's root faces (the bundles that grow hair, quads split in
//! two), read from the runtime textures. At each root vertex the seed's offset vector `c_v` (§3: length and combing) is the
//! hair mesh's own column, resampled at [`FUR_COLUMN_POINTS`] even steps of arc length: shell
//! `h ∈ [0, 1]` sits at fraction `h` along it, so shells follow each bundle's w, lean where
//! the artist combed the mesh and move when it moves.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};

use std::collections::HashMap;

use crate::fur::lapped::{DirectionField, LappedError, LappedParams, LappedSurface};
use crate::runtime::atlas::{Atlas, BLOCK_CORNER_OFFSETS};
use crate::runtime::textures::{RuntimeTextures, SLICES_PER_SEGMENT};

/// Points per resampled column.
pub const FUR_COLUMN_POINTS: usize = 4;

/// The fur's surface from a hair mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FurBase {
    /// Per base vertex, its column from root to tip at even arc-length steps.
    pub columns: Vec<[Vec3; FUR_COLUMN_POINTS]>,
    /// Root triangles over base vertices.
    pub triangles: Vec<[u32; 3]>,
}

impl FurBase {
    /// The root faces of the bundles the runtime textures hold, over their columns as the
    /// textures store them (so a project and its runtime bundle grow the same fur, and a
    /// game reads it from what it already has). Each block's corners are its face's corners
    /// in order (a triangle's last corner twice); corners with the same column are welded
    /// into one vertex, so patches and fins run across bundles.
    pub fn from_textures(textures: &RuntimeTextures) -> Self {
        let mesh = &textures.hair_mesh;
        let mut index_of: HashMap<[u32; 3 * FUR_COLUMN_POINTS], u32> = HashMap::new();
        let mut columns = Vec::new();
        let mut triangles = Vec::new();
        for block in &textures.atlas.blocks {
            if block.layers == 0 {
                continue;
            }
            let corners: Option<Vec<u32>> = BLOCK_CORNER_OFFSETS
                .iter()
                .map(|&[dx, dy]| {
                    let (x, y) = (block.origin[0] + dx as u32, block.origin[1] + dy as u32);
                    if x >= mesh.width || y >= mesh.height {
                        return None;
                    }
                    let points: Vec<DVec3> = (0..=block.layers)
                        .map(|k| {
                            let z = (SLICES_PER_SEGMENT * k).min(mesh.depth.saturating_sub(1));
                            (mesh.get(x, y, z).truncate() + textures.position_offset).as_dvec3()
                        })
                        .collect();
                    let column = resample(&points);
                    let key: [u32; 3 * FUR_COLUMN_POINTS] =
                        std::array::from_fn(|i| column[i / 3][i % 3].to_bits());
                    Some(*index_of.entry(key).or_insert_with(|| {
                        columns.push(column);
                        columns.len() as u32 - 1
                    }))
                })
                .collect();
            let Some(v) = corners else { continue };
            if Atlas::is_triangle(block) {
                triangles.push([v[0], v[1], v[2]]);
            } else {
                triangles.push([v[0], v[1], v[2]]);
                triangles.push([v[0], v[2], v[3]]);
            }
        }
        Self { columns, triangles }
    }

    /// Mean root-to-tip arc length of the columns (the fur's length).
    pub fn mean_length_m(&self) -> f32 {
        if self.columns.is_empty() {
            return 0.0;
        }
        let total: f32 = self
            .columns
            .iter()
            .map(|c| c.windows(2).map(|p| p[0].distance(p[1])).sum::<f32>())
            .sum();
        total / self.columns.len() as f32
    }

    /// Area of the root faces.
    pub fn area_m2(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| {
                    self.columns
                        .get(i as usize)
                        .map_or(DVec3::ZERO, |c| c[0].as_dvec3())
                });
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// The centre and radius of a sphere around every column.
    pub fn bounds(&self) -> (Vec3, f32) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in self.columns.iter().flatten() {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        if lo.x > hi.x {
            return (Vec3::ZERO, 0.0);
        }
        let centre = 0.5 * (lo + hi);
        (centre, 0.5 * lo.distance(hi))
    }
}

/// `positions` (root first) at [`FUR_COLUMN_POINTS`] even steps of arc length; a column with
/// one point (no layers) stays at its root.
fn resample(positions: &[DVec3]) -> [Vec3; FUR_COLUMN_POINTS] {
    let root = positions.first().copied().unwrap_or(DVec3::ZERO);
    let lengths: Vec<f64> = positions.windows(2).map(|p| p[0].distance(p[1])).collect();
    let total: f64 = lengths.iter().sum();
    std::array::from_fn(|k| {
        if total.is_nan() || total <= 0.0 {
            return root.as_vec3();
        }
        let target = total * k as f64 / (FUR_COLUMN_POINTS - 1) as f64;
        let mut walked = 0.0;
        for (i, &length) in lengths.iter().enumerate() {
            if walked + length >= target && length > 0.0 {
                let t = ((target - walked) / length).clamp(0.0, 1.0);
                return positions[i].lerp(positions[i + 1], t).as_vec3();
            }
            walked += length;
        }
        positions[positions.len() - 1].as_vec3()
    })
}

/// One base vertex as the shaders read it: its column and its normal.
/// Keep in sync with `shaders/fur.wgsl` (`FurColumn`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FurColumnGpu {
    /// xyz: the column's points root to tip (w unused).
    pub points: [[f32; 4]; FUR_COLUMN_POINTS],
    /// xyz: the surface normal (w unused).
    pub normal: [f32; 4],
}

/// One face corner: which base vertex, where in the fur tile, and the patch's texture axis.
/// Keep in sync with `shaders/fur.wgsl` (`FurCorner`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FurCornerGpu {
    /// The world direction of the texture's u axis over this corner's face.
    pub tangent: [f32; 3],
    pub vertex: u32,
    /// Texture coordinates in tiles (the texture wraps).
    pub uv: [f32; 2],
    pub _pad: [f32; 2],
}

/// One fin: a base edge and the stretch of fin texture it shows.
/// Keep in sync with `shaders/fur.wgsl` (`FurFin`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FurFinGpu {
    pub vertices: [u32; 2],
    pub u_start: f32,
    pub u_length: f32,
}

const _: () = assert!(size_of::<FurColumnGpu>() == 80);
const _: () = assert!(size_of::<FurCornerGpu>() == 32);
const _: () = assert!(size_of::<FurFinGpu>() == 16);

/// A fur base covered by lapped patches, as the shaders read it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FurGeometry {
    pub columns: Vec<FurColumnGpu>,
    /// Three per root triangle.
    pub corners: Vec<FurCornerGpu>,
    pub fins: Vec<FurFinGpu>,
    pub patch_count: u32,
}

impl FurGeometry {
    /// Covers `base` with patches of a `tile_width_m` tile aligned to its columns' lean (fur
    /// standing straight up gets an isotropic cover).
    pub fn build(
        base: &FurBase,
        tile_width_m: f64,
        patch_radius_m: f64,
        seed: u64,
    ) -> Result<Self, LappedError> {
        let positions: Vec<DVec3> = base.columns.iter().map(|c| c[0].as_dvec3()).collect();
        let leans: Vec<DVec3> = base
            .columns
            .iter()
            .map(|c| (c[FUR_COLUMN_POINTS - 1] - c[0]).as_dvec3())
            .collect();
        // Leans along the surface give the direction field; where they have none (fur
        // standing up), an isotropic cover.
        let surface = LappedSurface::build(
            &positions,
            &base.triangles,
            &LappedParams {
                tile_width_m,
                patch_radius_m,
                direction: DirectionField::PerVertex(leans),
                seed,
            },
        )?;
        let columns = base
            .columns
            .iter()
            .zip(&surface.vertex_normals)
            .map(|(c, n)| FurColumnGpu {
                points: c.map(|p| p.extend(0.0).to_array()),
                normal: n.as_vec3().extend(0.0).to_array(),
            })
            .collect();
        let corners = base
            .triangles
            .iter()
            .enumerate()
            .flat_map(|(f, t)| {
                let tangent = surface.face_tangents[f].as_vec3().to_array();
                let uvs = surface.face_uvs[f];
                (0..3).map(move |k| FurCornerGpu {
                    tangent,
                    vertex: t[k],
                    uv: uvs[k],
                    _pad: [0.0; 2],
                })
            })
            .collect();
        let fins = surface
            .fin_edges
            .iter()
            .map(|e| FurFinGpu {
                vertices: e.vertices,
                u_start: e.u_start,
                u_length: e.u_length,
            })
            .collect();
        Ok(Self {
            columns,
            corners,
            fins,
            patch_count: surface.patch_count,
        })
    }

    /// Bytes of the three arrays.
    pub fn bytes(&self) -> u64 {
        (self.columns.len() * size_of::<FurColumnGpu>()
            + self.corners.len() * size_of::<FurCornerGpu>()
            + self.fins.len() * size_of::<FurFinGpu>()) as u64
    }
}

/// The point at height `h ∈ [0, 1]` of a column: piecewise linear through its points
/// (`fur.wgsl` `shell_point`).
pub fn shell_point(points: &[Vec3; FUR_COLUMN_POINTS], h: f32) -> Vec3 {
    let h = if h.is_nan() { 0.0 } else { h };
    let x = h.clamp(0.0, 1.0) * (FUR_COLUMN_POINTS - 1) as f32;
    let i = (x.floor() as usize).min(FUR_COLUMN_POINTS - 2);
    points[i].lerp(points[i + 1], x - i as f32)
}

/// Seed 002 §2.3: a fin's opacity factor `max(0, 2|p| − 1)`, `p` the cosine between the fin's
/// normal and the direction to the eye; fins face the viewer only near the silhouette
/// (`fur.wgsl` `fin_fade`).
pub fn fin_fade(fin_normal: Vec3, to_eye: Vec3) -> f32 {
    let p = fin_normal
        .normalize_or_zero()
        .dot(to_eye.normalize_or_zero());
    (2.0 * p.abs() - 1.0).max(0.0)
}
