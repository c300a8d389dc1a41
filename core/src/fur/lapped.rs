//! Lapped-texture parameterisation without overlap (seed 002 §2.1, after Praun et al. 2000):
//! patches grown from random uncovered faces over a triangle mesh, each parameterised locally
//! onto the toroidal fur tile and aligned to a global direction field (or to a random
//! direction per patch: "isotropic", for fur standing up). Patch boundaries run along mesh
//! edges and every face belongs to exactly one patch, so each shell draws each face once.
//!
//! Each patch is an irregular "splotch": it grows breadth-first across manifold edges while a
//! face's texture coordinates stay inside a randomly wobbled radius around the seed, its
//! normal stays within 60° of the seed's, and its map is not folded or stretched beyond 2×.
//! A face's texture axes are the direction field projected into its plane and the normal
//! crossed with it, scaled by the tile width; a new vertex gets the mean of the positions its
//! known edge neighbours predict through them (the per-face optimisation of lapped textures
//! in one unfolding step: inside small patches it leaves the map within a few degrees of the
//! field, tested below).
//!
//! No triangulation is made here (boundaries follow existing edges), so `spade` is not used.

use std::collections::{HashMap, VecDeque};

use glam::{DVec2, DVec3};

use crate::strands::random::{SplitMix64, hash_to_unit, hash_values};

/// Which way the fur's texture runs over the surface.
#[derive(Clone, Debug, PartialEq)]
pub enum DirectionField {
    /// Each patch gets its own random orientation (fur standing straight up needs none).
    Isotropic,
    /// One world direction projected onto the surface (gravity-combed fur: `-Y`).
    Global(DVec3),
    /// A direction per vertex, projected onto each face.
    PerVertex(Vec<DVec3>),
}

#[derive(Clone, Debug, PartialEq)]
pub struct LappedParams {
    /// World width of one texture tile on the surface (the fur volume's `tile_width_m`).
    pub tile_width_m: f64,
    /// A patch grows to about this radius before its wobbled boundary stops it.
    pub patch_radius_m: f64,
    pub direction: DirectionField,
    pub seed: u64,
}

/// Why a mesh cannot be covered.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LappedError {
    #[error("fur surface: the mesh has no triangles")]
    NoTriangles,
    #[error("fur surface: {count} triangles is over the limit of {limit}")]
    TooManyTriangles { count: usize, limit: usize },
    #[error("fur surface: position {vertex} is not finite")]
    NonFinitePosition { vertex: usize },
    #[error("fur surface: triangle {triangle} names vertex {index}, but there are {count}")]
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        count: usize,
    },
    #[error("fur surface: every triangle has zero area, there is no surface to grow fur on")]
    NoArea,
    #[error("fur surface: {name} is {value}, it must be finite and positive")]
    BadParameter { name: &'static str, value: f64 },
    #[error("fur surface: the direction field has {given} vectors for {count} vertices")]
    DirectionCount { given: usize, count: usize },
    #[error("fur surface: direction {vertex} is not finite")]
    NonFiniteDirection { vertex: usize },
}

/// The most triangles a fur surface takes (a game character has tens of thousands).
pub const MAX_FUR_TRIANGLES: usize = 4_000_000;

/// One mesh edge that can carry a fin, with the stretch of fin texture it shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FinEdge {
    pub vertices: [u32; 2],
    /// Where along the (wrapping) fin texture this edge starts, in tiles.
    pub u_start: f32,
    /// How much of the fin texture it spans: its length in tiles (the same scale as the
    /// shells, seed 002 §2.2).
    pub u_length: f32,
}

/// A covered mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct LappedSurface {
    /// The patch each face belongs to.
    pub face_patch: Vec<u32>,
    /// Texture coordinates of each face's three corners, in tiles (the texture wraps).
    pub face_uvs: Vec<[[f32; 2]; 3]>,
    /// The world direction of each face's texture u axis (the direction field in its plane):
    /// the shells' strands lean this way, and shading turns the stored strand tangents by it.
    pub face_tangents: Vec<DVec3>,
    pub patch_count: u32,
    /// Area-weighted vertex normals (the shells' offset direction).
    pub vertex_normals: Vec<DVec3>,
    /// The direction field at each vertex, in its tangent plane (zero where it has none);
    /// combing shears shells along it.
    pub vertex_directions: Vec<DVec3>,
    pub fin_edges: Vec<FinEdge>,
}

struct Face {
    normal: Option<DVec3>,
    area: f64,
}

impl LappedSurface {
    /// Covers `triangles` over `positions` with non-overlapping patches.
    pub fn build(
        positions: &[DVec3],
        triangles: &[[u32; 3]],
        params: &LappedParams,
    ) -> Result<Self, LappedError> {
        validate(positions, triangles, params)?;
        let faces: Vec<Face> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                let cross = (b - a).cross(c - a);
                let area = 0.5 * cross.length();
                Face {
                    normal: (area > 1e-14 * (b - a).length_squared().max(1e-300))
                        .then(|| cross.normalize())
                        .filter(|n| n.is_finite()),
                    area,
                }
            })
            .collect();
        if faces.iter().all(|f| f.normal.is_none()) {
            return Err(LappedError::NoArea);
        }
        let vertex_normals = vertex_normals(positions, triangles, &faces);
        let field_at = |vertex: usize| -> Option<DVec3> {
            match &params.direction {
                DirectionField::Isotropic => None,
                DirectionField::Global(d) => Some(*d),
                DirectionField::PerVertex(v) => Some(v[vertex]),
            }
        };
        // A direction with under 5 % of its length along the surface (fur standing up, or
        // rounding) has none there.
        let vertex_directions = (0..positions.len())
            .map(|v| {
                field_at(v)
                    .and_then(|d| {
                        let n = vertex_normals[v];
                        let along = d - n * d.dot(n);
                        (along.length() > 0.05 * d.length())
                            .then(|| along.try_normalize())
                            .flatten()
                    })
                    .unwrap_or(DVec3::ZERO)
            })
            .collect::<Vec<_>>();

        // Faces across each manifold edge; non-manifold edges stop growth.
        let mut edge_faces: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if a != b {
                    edge_faces
                        .entry((a.min(b), a.max(b)))
                        .or_default()
                        .push(f as u32);
                }
            }
        }
        let neighbours = |f: usize| -> Vec<u32> {
            let t = triangles[f];
            let mut out = Vec::with_capacity(3);
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if let Some(list) = edge_faces.get(&(a.min(b), a.max(b)))
                    && list.len() == 2
                {
                    out.extend(list.iter().copied().filter(|&g| g as usize != f));
                }
            }
            out
        };

        // With no direction anywhere the cover is isotropic: each patch turned at random.
        let isotropic = matches!(params.direction, DirectionField::Isotropic)
            || vertex_directions.iter().all(|d| *d == DVec3::ZERO);
        let tile = params.tile_width_m;
        let mut random = SplitMix64::new(params.seed);
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        for i in (1..order.len()).rev() {
            let j = (random.next_u64() % (i as u64 + 1)) as usize;
            order.swap(i, j);
        }
        let mut face_patch = vec![u32::MAX; triangles.len()];
        let mut face_uvs = vec![[[0.0f32; 2]; 3]; triangles.len()];
        let mut face_tangents = vec![DVec3::X; triangles.len()];
        let mut patch_count = 0u32;
        let cos_limit = 60f64.to_radians().cos();

        for &seed_face in &order {
            if face_patch[seed_face as usize] != u32::MAX {
                continue;
            }
            let patch = patch_count;
            patch_count += 1;
            let seed_tri = triangles[seed_face as usize];
            let seed_normal = faces[seed_face as usize]
                .normal
                .or_else(|| vertex_normals[seed_tri[0] as usize].try_normalize())
                .unwrap_or(DVec3::Z);
            // The patch's own orientation: the field at the seed or, isotropic, a random one.
            let fallback = any_perpendicular(seed_normal);
            let seed_tangent = match params.direction {
                _ if isotropic => {
                    let angle = random.next_f64() * std::f64::consts::TAU;
                    let other = seed_normal.cross(fallback);
                    fallback * angle.cos() + other * angle.sin()
                }
                _ => face_tangent(&seed_tri, seed_normal, &vertex_directions).unwrap_or(fallback),
            };
            let offset = DVec2::new(random.next_f64(), random.next_f64());
            let harmonics = [
                (
                    random.next_f64() * 0.15,
                    random.next_f64() * std::f64::consts::TAU,
                ),
                (
                    random.next_f64() * 0.1,
                    random.next_f64() * std::f64::consts::TAU,
                ),
            ];
            let radius_tiles = params.patch_radius_m / tile;
            let splotch = |uv: DVec2| -> bool {
                let d = uv - offset;
                let angle = d.y.atan2(d.x);
                let wobble = 0.8
                    + harmonics[0].0 * (2.0 * angle + harmonics[0].1).sin()
                    + harmonics[1].0 * (3.0 * angle + harmonics[1].1).sin();
                d.length() <= radius_tiles * wobble
            };
            let frame_of = |f: usize| -> (DVec3, DVec3) {
                let normal = faces[f].normal.unwrap_or(seed_normal);
                let transported = (seed_tangent - normal * seed_tangent.dot(normal))
                    .try_normalize()
                    .unwrap_or_else(|| any_perpendicular(normal));
                let tangent = if isotropic {
                    transported
                } else {
                    face_tangent(&triangles[f], normal, &vertex_directions).unwrap_or(transported)
                };
                (tangent, normal.cross(tangent))
            };

            let mut uv_of: HashMap<u32, DVec2> = HashMap::new();
            let (t0, b0) = frame_of(seed_face as usize);
            let centre = seed_tri
                .iter()
                .map(|&v| positions[v as usize])
                .sum::<DVec3>()
                / 3.0;
            for &v in &seed_tri {
                let d = positions[v as usize] - centre;
                uv_of
                    .entry(v)
                    .or_insert(offset + DVec2::new(d.dot(t0), d.dot(b0)) / tile);
            }
            assign(
                &mut face_patch,
                &mut face_uvs,
                seed_face,
                patch,
                &seed_tri,
                &uv_of,
            );
            face_tangents[seed_face as usize] = t0;

            let mut queue: VecDeque<u32> = neighbours(seed_face as usize).into();
            while let Some(g) = queue.pop_front() {
                let gi = g as usize;
                if face_patch[gi] != u32::MAX {
                    continue;
                }
                let tri = triangles[gi];
                let face = &faces[gi];
                if let Some(n) = face.normal
                    && n.dot(seed_normal) < cos_limit
                {
                    continue;
                }
                let (t, b) = frame_of(gi);
                let known: Vec<u32> = tri
                    .iter()
                    .copied()
                    .filter(|v| uv_of.contains_key(v))
                    .collect();
                if known.is_empty() {
                    continue;
                }
                let mut uvs = [DVec2::ZERO; 3];
                for (k, &v) in tri.iter().enumerate() {
                    uvs[k] = match uv_of.get(&v) {
                        Some(&uv) => uv,
                        None => {
                            known
                                .iter()
                                .map(|&w| {
                                    let d = positions[v as usize] - positions[w as usize];
                                    uv_of[&w] + DVec2::new(d.dot(t), d.dot(b)) / tile
                                })
                                .sum::<DVec2>()
                                / known.len() as f64
                        }
                    };
                }
                if !uvs.iter().all(|&uv| splotch(uv)) {
                    continue;
                }
                // Refuse a folded or badly stretched map (degenerate faces have none to judge).
                if face.normal.is_some() {
                    let uv_area = 0.5 * (uvs[1] - uvs[0]).perp_dot(uvs[2] - uvs[0]);
                    let ratio = uv_area * tile * tile / face.area;
                    if !(0.5..=2.0).contains(&ratio) {
                        continue;
                    }
                }
                for (k, &v) in tri.iter().enumerate() {
                    uv_of.entry(v).or_insert(uvs[k]);
                }
                assign(&mut face_patch, &mut face_uvs, g, patch, &tri, &uv_of);
                face_tangents[gi] = t;
                queue.extend(neighbours(gi));
            }
        }

        let mut fin_edges: Vec<FinEdge> = edge_faces
            .keys()
            .map(|&(a, b)| {
                let length = positions[a as usize].distance(positions[b as usize]);
                FinEdge {
                    vertices: [a, b],
                    u_start: hash_to_unit(hash_values(&[a, b, params.seed as u32])) as f32,
                    u_length: (length / tile) as f32,
                }
            })
            .collect();
        fin_edges.sort_by_key(|e| e.vertices);

        Ok(Self {
            face_patch,
            face_uvs,
            face_tangents,
            patch_count,
            vertex_normals,
            vertex_directions,
            fin_edges,
        })
    }
}

fn assign(
    face_patch: &mut [u32],
    face_uvs: &mut [[[f32; 2]; 3]],
    face: u32,
    patch: u32,
    tri: &[u32; 3],
    uv_of: &HashMap<u32, DVec2>,
) {
    face_patch[face as usize] = patch;
    face_uvs[face as usize] = tri.map(|v| {
        let uv = uv_of[&v];
        [uv.x as f32, uv.y as f32]
    });
}

/// The direction field over a face, in its plane: the mean of its vertices' directions.
fn face_tangent(tri: &[u32; 3], normal: DVec3, vertex_directions: &[DVec3]) -> Option<DVec3> {
    let mean: DVec3 = tri.iter().map(|&v| vertex_directions[v as usize]).sum();
    (mean - normal * mean.dot(normal)).try_normalize()
}

fn any_perpendicular(normal: DVec3) -> DVec3 {
    let axis = if normal.x.abs() < 0.9 {
        DVec3::X
    } else {
        DVec3::Y
    };
    (axis - normal * axis.dot(normal)).normalize()
}

fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]], faces: &[Face]) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; positions.len()];
    for (t, face) in triangles.iter().zip(faces) {
        if let Some(n) = face.normal {
            for &v in t {
                normals[v as usize] += n * face.area;
            }
        }
    }
    normals
        .into_iter()
        .map(|n| n.try_normalize().unwrap_or(DVec3::Z))
        .collect()
}

fn validate(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    params: &LappedParams,
) -> Result<(), LappedError> {
    if triangles.is_empty() {
        return Err(LappedError::NoTriangles);
    }
    if triangles.len() > MAX_FUR_TRIANGLES {
        return Err(LappedError::TooManyTriangles {
            count: triangles.len(),
            limit: MAX_FUR_TRIANGLES,
        });
    }
    for (name, value) in [
        ("tile_width_m", params.tile_width_m),
        ("patch_radius_m", params.patch_radius_m),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(LappedError::BadParameter { name, value });
        }
    }
    if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
        return Err(LappedError::NonFinitePosition { vertex });
    }
    for (triangle, t) in triangles.iter().enumerate() {
        if let Some(&index) = t.iter().find(|&&i| i as usize >= positions.len()) {
            return Err(LappedError::IndexOutOfRange {
                triangle,
                index,
                count: positions.len(),
            });
        }
    }
    match &params.direction {
        DirectionField::Isotropic => {}
        DirectionField::Global(d) => {
            if !d.is_finite() {
                return Err(LappedError::NonFiniteDirection { vertex: 0 });
            }
        }
        DirectionField::PerVertex(v) => {
            if v.len() != positions.len() {
                return Err(LappedError::DirectionCount {
                    given: v.len(),
                    count: positions.len(),
                });
            }
            if let Some(vertex) = v.iter().position(|d| !d.is_finite()) {
                return Err(LappedError::NonFiniteDirection { vertex });
            }
        }
    }
    Ok(())
}
