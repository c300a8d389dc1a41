//! Scalp import from glTF 2.0 (`.gltf` with external or embedded buffers, `.glb`).
//!
//! Reads POSITION, NORMAL, TEXCOORD_0 and indices of every triangle primitive of one mesh,
//! applies the world transform of the first node that instances it, welds vertices that lie
//! within a tolerance of each other (keeping per-corner uv, so uv seams survive), and pairs
//! triangles back into quads because hair meshes are quad-dominant while glTF stores
//! triangles only.
//!
//! Accessor data is read by our own bounds-checked reader: a truncated buffer, an index out
//! of range, a NaN or an unsupported layout is an [`ImportError`] naming the file, the mesh,
//! the primitive and the accessor — never a panic.

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DVec2, DVec3};

use crate::model::document::BodyMesh;
use crate::model::mesh::HairMesh;

/// Import settings.
#[derive(Clone, Debug)]
pub struct ImportOptions {
    /// Mesh to import by name; required when the file has several meshes.
    pub mesh_name: Option<String>,
    /// Vertices closer than this fraction of the bounding-box diagonal are welded.
    pub weld_tolerance_relative: f64,
    /// Pair triangles into quads where two share an edge and form a planar-enough convex quad.
    pub pair_quads: bool,
    /// Largest angle between the two triangles' normals for them to become one quad.
    pub max_quad_fold_deg: f64,
    /// Uniform scale applied after the node transform (model units per file unit).
    pub scale: f64,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            mesh_name: None,
            weld_tolerance_relative: 1e-6,
            pair_quads: true,
            max_quad_fold_deg: 60.0,
            scale: 1.0,
        }
    }
}

/// What went wrong, with where.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    #[error("{file}: cannot read: {source}")]
    Read {
        file: String,
        source: std::io::Error,
    },
    #[error("{file}: not a valid glTF file: {message}")]
    Gltf { file: String, message: String },
    #[error("{file}: {message}")]
    NoMesh { file: String, message: String },
    #[error("{file}: mesh \"{mesh}\", primitive {primitive}: {message}")]
    Primitive {
        file: String,
        mesh: String,
        primitive: usize,
        message: String,
    },
    #[error(
        "{file}: mesh \"{mesh}\", primitive {primitive}, accessor {accessor} ({semantic}): {message}"
    )]
    Accessor {
        file: String,
        mesh: String,
        primitive: usize,
        accessor: usize,
        semantic: String,
        message: String,
    },
    #[error("{file}: mesh \"{mesh}\" has no triangles after welding")]
    Empty { file: String, mesh: String },
}

/// A welded polygon mesh read from glTF.
#[derive(Clone, Debug)]
pub struct ImportedMesh {
    /// Name of the mesh that was read.
    pub mesh_name: String,
    pub positions: Vec<DVec3>,
    /// Faces of 3 or 4 vertex indices, counter-clockwise.
    pub faces: Vec<Vec<u32>>,
    /// uv per face corner.
    pub uvs: Vec<Vec<DVec2>>,
    /// Whether the file had TEXCOORD_0 (otherwise every uv is zero; see [`crate::geometry::uv`]).
    pub has_uv: bool,
    /// Triangles read from the file, before welding and pairing.
    pub source_triangles: usize,
    /// Triangles dropped because welding collapsed them.
    pub degenerate_triangles: usize,
}

impl ImportedMesh {
    pub fn quad_count(&self) -> usize {
        self.faces.iter().filter(|f| f.len() == 4).count()
    }

    pub fn triangle_count(&self) -> usize {
        self.faces.iter().filter(|f| f.len() == 3).count()
    }

    /// The whole mesh as a display/depth body (quads split back into two triangles).
    pub fn to_body(&self) -> BodyMesh {
        let positions = self
            .positions
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        let mut triangles = Vec::with_capacity(self.faces.len() * 2);
        for face in &self.faces {
            triangles.push([face[0], face[1], face[2]]);
            if face.len() == 4 {
                triangles.push([face[0], face[2], face[3]]);
            }
        }
        BodyMesh {
            positions,
            triangles,
        }
    }

    /// A scalp from the faces for which `keep(face_index)` is true; unused vertices are
    /// dropped and the rest renumbered in order.
    pub fn to_hair_mesh(&self, keep: impl Fn(usize) -> bool) -> HairMesh {
        let mut remap = vec![u32::MAX; self.positions.len()];
        let mut positions = Vec::new();
        let mut faces = Vec::new();
        let mut uvs = Vec::new();
        for (f, face) in self.faces.iter().enumerate() {
            if !keep(f) {
                continue;
            }
            let mapped = face
                .iter()
                .map(|&v| {
                    if remap[v as usize] == u32::MAX {
                        remap[v as usize] = positions.len() as u32;
                        positions.push(self.positions[v as usize]);
                    }
                    remap[v as usize]
                })
                .collect();
            faces.push(mapped);
            uvs.push(self.uvs[f].clone());
        }
        HairMesh::from_scalp(&positions, &faces, &uvs)
    }
}

/// Imports a mesh from a `.gltf` or `.glb` file.
pub fn import_file(path: &Path, options: &ImportOptions) -> Result<ImportedMesh, ImportError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| ImportError::Read {
        file: file.clone(),
        source,
    })?;
    import_slice(&bytes, path.parent(), &file, options)
}

/// Imports from bytes; `base` resolves external buffer URIs, `file` names the source in
/// messages.
pub fn import_slice(
    bytes: &[u8],
    base: Option<&Path>,
    file: &str,
    options: &ImportOptions,
) -> Result<ImportedMesh, ImportError> {
    let gltf_error = |message: String| ImportError::Gltf {
        file: file.to_string(),
        message,
    };
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| gltf_error(e.to_string()))?;
    let buffers = gltf::import_buffers(&gltf.document, base, gltf.blob.clone())
        .map_err(|e| gltf_error(format!("buffer data: {e}")))?;
    let document = &gltf.document;
    let meshes: Vec<gltf::Mesh> = document.meshes().collect();
    let mesh = match &options.mesh_name {
        Some(name) => meshes
            .iter()
            .find(|m| m.name() == Some(name.as_str()))
            .ok_or_else(|| ImportError::NoMesh {
                file: file.to_string(),
                message: format!("no mesh named \"{name}\" (meshes: {})", mesh_names(&meshes)),
            })?,
        None => match meshes.as_slice() {
            [] => {
                return Err(ImportError::NoMesh {
                    file: file.to_string(),
                    message: "the file contains no mesh".into(),
                });
            }
            [only] => only,
            _ => {
                return Err(ImportError::NoMesh {
                    file: file.to_string(),
                    message: format!(
                        "the file has several meshes; choose one by name ({})",
                        mesh_names(&meshes)
                    ),
                });
            }
        },
    };
    let mesh_name = mesh
        .name()
        .map(str::to_string)
        .unwrap_or_else(|| format!("mesh {}", mesh.index()));
    let transform =
        node_transform(document, mesh.index()) * DMat4::from_scale(DVec3::splat(options.scale));
    let normal_transform = transform.inverse().transpose();

    let mut positions: Vec<DVec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut corner_uvs: Vec<[DVec2; 3]> = Vec::new();
    let mut has_uv = false;
    for primitive in mesh.primitives() {
        let p_index = primitive.index();
        let primitive_error = |message: String| ImportError::Primitive {
            file: file.to_string(),
            mesh: mesh_name.clone(),
            primitive: p_index,
            message,
        };
        if primitive.mode() != gltf::mesh::Mode::Triangles {
            return Err(primitive_error(format!(
                "mode {:?} is not supported; a scalp must be made of triangles",
                primitive.mode()
            )));
        }
        let context = AccessorContext {
            file,
            mesh: &mesh_name,
            primitive: p_index,
            buffers: &buffers,
        };
        let Some(position_accessor) = primitive.get(&gltf::Semantic::Positions) else {
            return Err(primitive_error("missing POSITION attribute".into()));
        };
        let local_positions = context.read_vec(&position_accessor, "POSITION", 3)?;
        let vertex_count = local_positions.len();
        let normals = match primitive.get(&gltf::Semantic::Normals) {
            Some(accessor) => {
                let normals = context.read_vec(&accessor, "NORMAL", 3)?;
                if normals.len() != vertex_count {
                    return Err(context.error(
                        &accessor,
                        "NORMAL",
                        format!("{} normals for {vertex_count} positions", normals.len()),
                    ));
                }
                Some(normals)
            }
            None => None,
        };
        let uvs = match primitive.get(&gltf::Semantic::TexCoords(0)) {
            Some(accessor) => {
                let uvs = context.read_vec(&accessor, "TEXCOORD_0", 2)?;
                if uvs.len() != vertex_count {
                    return Err(context.error(
                        &accessor,
                        "TEXCOORD_0",
                        format!("{} uv values for {vertex_count} positions", uvs.len()),
                    ));
                }
                has_uv = true;
                Some(uvs)
            }
            None => None,
        };
        let indices: Vec<u32> = match primitive.indices() {
            Some(accessor) => {
                let values = context.read_vec(&accessor, "indices", 1)?;
                let mut indices = Vec::with_capacity(values.len());
                for (i, v) in values.iter().enumerate() {
                    let index = v[0];
                    if index < 0.0 || index >= vertex_count as f64 {
                        return Err(context.error(
                            &accessor,
                            "indices",
                            format!("index {index} at position {i} is out of range ({vertex_count} vertices)"),
                        ));
                    }
                    indices.push(index as u32);
                }
                if indices.len() % 3 != 0 {
                    return Err(context.error(
                        &accessor,
                        "indices",
                        format!(
                            "{} indices is not a whole number of triangles",
                            indices.len()
                        ),
                    ));
                }
                indices
            }
            None => {
                if vertex_count % 3 != 0 {
                    return Err(primitive_error(format!(
                        "{vertex_count} vertices without indices is not a whole number of triangles"
                    )));
                }
                (0..vertex_count as u32).collect()
            }
        };
        // Flip triangles whose winding disagrees with the file's normals, so every face is
        // counter-clockwise seen from outside, as the hair mesh requires.
        let base = positions.len() as u32;
        let world: Vec<DVec3> = local_positions
            .iter()
            .map(|p| transform.transform_point3(DVec3::new(p[0], p[1], p[2])))
            .collect();
        for triangle in indices.chunks_exact(3) {
            let mut t = [triangle[0], triangle[1], triangle[2]];
            if let Some(normals) = &normals {
                let face_normal = (world[t[1] as usize] - world[t[0] as usize])
                    .cross(world[t[2] as usize] - world[t[0] as usize]);
                let vertex_normal: DVec3 = t
                    .iter()
                    .map(|&i| {
                        let n = &normals[i as usize];
                        normal_transform.transform_vector3(DVec3::new(n[0], n[1], n[2]))
                    })
                    .sum();
                if face_normal.dot(vertex_normal) < 0.0 {
                    t.swap(1, 2);
                }
            }
            let uv = t.map(|i| match &uvs {
                Some(uvs) => DVec2::new(uvs[i as usize][0], uvs[i as usize][1]),
                None => DVec2::ZERO,
            });
            triangles.push(t.map(|i| i + base));
            corner_uvs.push(uv);
        }
        positions.extend(world);
    }
    let source_triangles = triangles.len();
    let (positions, triangles, corner_uvs, degenerate) = weld(
        &positions,
        &triangles,
        &corner_uvs,
        options.weld_tolerance_relative,
    );
    if triangles.is_empty() {
        return Err(ImportError::Empty {
            file: file.to_string(),
            mesh: mesh_name,
        });
    }
    let (faces, uvs) = if options.pair_quads {
        pair_quads(
            &positions,
            &triangles,
            &corner_uvs,
            options.max_quad_fold_deg,
        )
    } else {
        (
            triangles.iter().map(|t| t.to_vec()).collect(),
            corner_uvs.iter().map(|u| u.to_vec()).collect(),
        )
    };
    Ok(ImportedMesh {
        mesh_name,
        positions,
        faces,
        uvs,
        has_uv,
        source_triangles,
        degenerate_triangles: degenerate,
    })
}

fn mesh_names(meshes: &[gltf::Mesh]) -> String {
    meshes
        .iter()
        .map(|m| {
            m.name()
                .map(|n| format!("\"{n}\""))
                .unwrap_or_else(|| format!("#{}", m.index()))
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// World transform of the first node (in scene order, depth first) that instances `mesh`;
/// identity when no node does.
fn node_transform(document: &gltf::Document, mesh: usize) -> DMat4 {
    fn visit(node: gltf::Node, parent: DMat4, mesh: usize, depth: usize) -> Option<DMat4> {
        // Guard against malicious cycles (validation rejects them, but stay bounded).
        if depth > 64 {
            return None;
        }
        let local = node.transform().matrix();
        let local = DMat4::from_cols_array_2d(&local.map(|c| c.map(f64::from)));
        let world = parent * local;
        if node.mesh().is_some_and(|m| m.index() == mesh) {
            return Some(world);
        }
        node.children()
            .find_map(|child| visit(child, world, mesh, depth + 1))
    }
    let scenes: Vec<gltf::Scene> = document
        .default_scene()
        .into_iter()
        .chain(document.scenes())
        .collect();
    scenes
        .into_iter()
        .find_map(|scene| {
            scene
                .nodes()
                .find_map(|node| visit(node, DMat4::IDENTITY, mesh, 0))
        })
        .filter(|m| m.is_finite())
        .unwrap_or(DMat4::IDENTITY)
}

struct AccessorContext<'a> {
    file: &'a str,
    mesh: &'a str,
    primitive: usize,
    buffers: &'a [gltf::buffer::Data],
}

impl AccessorContext<'_> {
    fn error(&self, accessor: &gltf::Accessor, semantic: &str, message: String) -> ImportError {
        ImportError::Accessor {
            file: self.file.to_string(),
            mesh: self.mesh.to_string(),
            primitive: self.primitive,
            accessor: accessor.index(),
            semantic: semantic.to_string(),
            message,
        }
    }

    /// Reads an accessor of `components` components per element into f64 values, with
    /// normalised integers mapped to [0, 1] / [−1, 1]. Every read is bounds-checked and
    /// every value must be finite.
    fn read_vec(
        &self,
        accessor: &gltf::Accessor,
        semantic: &str,
        components: usize,
    ) -> Result<Vec<Vec<f64>>, ImportError> {
        use gltf::accessor::{DataType, Dimensions};
        let fail = |message: String| self.error(accessor, semantic, message);
        let dims = match accessor.dimensions() {
            Dimensions::Scalar => 1,
            Dimensions::Vec2 => 2,
            Dimensions::Vec3 => 3,
            Dimensions::Vec4 => 4,
            other => return Err(fail(format!("unsupported element type {other:?}"))),
        };
        if dims != components {
            return Err(fail(format!(
                "expected {components} components per element, found {dims}"
            )));
        }
        if accessor.sparse().is_some() {
            return Err(fail("sparse accessors are not supported".into()));
        }
        let Some(view) = accessor.view() else {
            return Err(fail("accessor has no buffer view".into()));
        };
        let data_type = accessor.data_type();
        let component_size = data_type.size();
        let element_size = component_size * dims;
        let stride = view.stride().unwrap_or(element_size);
        if stride < element_size {
            return Err(fail(format!(
                "byte stride {stride} is smaller than the element ({element_size} bytes)"
            )));
        }
        let Some(buffer) = self.buffers.get(view.buffer().index()) else {
            return Err(fail(format!("buffer {} is missing", view.buffer().index())));
        };
        let view_end = view.offset().checked_add(view.length());
        if view_end.is_none_or(|end| end > buffer.len()) {
            return Err(fail(format!(
                "buffer view {} ({} bytes at offset {}) runs past the end of buffer {} ({} bytes)",
                view.index(),
                view.length(),
                view.offset(),
                view.buffer().index(),
                buffer.len()
            )));
        }
        let view_bytes = &buffer[view.offset()..view.offset() + view.length()];
        let count = accessor.count();
        let needed = if count == 0 {
            0
        } else {
            accessor
                .offset()
                .checked_add(stride.saturating_mul(count - 1))
                .and_then(|v| v.checked_add(element_size))
                .unwrap_or(usize::MAX)
        };
        if needed > view_bytes.len() {
            return Err(fail(format!(
                "{count} elements need {needed} bytes but buffer view {} has {} (truncated file?)",
                view.index(),
                view_bytes.len()
            )));
        }
        let normalized = accessor.normalized();
        let mut out = Vec::with_capacity(count);
        for i in 0..count {
            let start = accessor.offset() + i * stride;
            let mut element = Vec::with_capacity(dims);
            for c in 0..dims {
                let at = start + c * component_size;
                let b = &view_bytes[at..at + component_size];
                let value = match data_type {
                    DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    DataType::U16 => {
                        let v = u16::from_le_bytes([b[0], b[1]]) as f64;
                        if normalized { v / 65535.0 } else { v }
                    }
                    DataType::I16 => {
                        let v = i16::from_le_bytes([b[0], b[1]]) as f64;
                        if normalized {
                            (v / 32767.0).max(-1.0)
                        } else {
                            v
                        }
                    }
                    DataType::U8 => {
                        let v = b[0] as f64;
                        if normalized { v / 255.0 } else { v }
                    }
                    DataType::I8 => {
                        let v = b[0] as i8 as f64;
                        if normalized { (v / 127.0).max(-1.0) } else { v }
                    }
                };
                if !value.is_finite() {
                    return Err(fail(format!(
                        "element {i} component {c} is not finite ({value})"
                    )));
                }
                element.push(value);
            }
            out.push(element);
        }
        Ok(out)
    }
}

/// Merges vertices closer than `relative_tolerance × bounding-box diagonal`, keeps corner uv
/// and drops triangles that collapse. Returns (positions, triangles, uvs, dropped).
#[expect(
    clippy::type_complexity,
    reason = "a private helper returning four parallel results"
)]
fn weld(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    uvs: &[[DVec2; 3]],
    relative_tolerance: f64,
) -> (Vec<DVec3>, Vec<[u32; 3]>, Vec<[DVec2; 3]>, usize) {
    let (min, max) = positions.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let diagonal = if positions.is_empty() {
        0.0
    } else {
        (max - min).length()
    };
    let tolerance = relative_tolerance.max(0.0) * diagonal;
    let cell = if tolerance > 0.0 { tolerance } else { 1.0 };
    let key = |p: DVec3| {
        let q = ((p - min) / cell).floor();
        (q.x as i64, q.y as i64, q.z as i64)
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
    let mut welded: Vec<DVec3> = Vec::new();
    let mut remap = Vec::with_capacity(positions.len());
    for &p in positions {
        let (x, y, z) = key(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&(x + dx, y + dy, z + dz)) {
                        for &candidate in list {
                            if welded[candidate as usize].distance(p) <= tolerance {
                                found = Some(candidate);
                                break 'search;
                            }
                        }
                    }
                }
            }
        }
        let index = match found {
            Some(index) => index,
            None => {
                let index = welded.len() as u32;
                welded.push(p);
                grid.entry((x, y, z)).or_default().push(index);
                index
            }
        };
        remap.push(index);
    }
    let mut out_triangles = Vec::with_capacity(triangles.len());
    let mut out_uvs = Vec::with_capacity(triangles.len());
    let mut dropped = 0;
    for (t, uv) in triangles.iter().zip(uvs) {
        let m = t.map(|i| remap[i as usize]);
        if m[0] == m[1] || m[1] == m[2] || m[0] == m[2] {
            dropped += 1;
            continue;
        }
        out_triangles.push(m);
        out_uvs.push(*uv);
    }
    // Drop vertices no triangle uses (for example, only used by collapsed triangles).
    let mut used = vec![u32::MAX; welded.len()];
    let mut compact = Vec::new();
    for t in &mut out_triangles {
        for i in t.iter_mut() {
            if used[*i as usize] == u32::MAX {
                used[*i as usize] = compact.len() as u32;
                compact.push(welded[*i as usize]);
            }
            *i = used[*i as usize];
        }
    }
    (compact, out_triangles, out_uvs, dropped)
}

/// Quad made of triangles `a` and `b` if they share an edge (in opposite directions), agree
/// on the uv of the shared corners, fold by at most `max_fold_cos` and form a strictly
/// convex quad. Returns the quad's corners and uvs, counter-clockwise.
fn try_pair(
    positions: &[DVec3],
    a: [u32; 3],
    a_uv: [DVec2; 3],
    b: [u32; 3],
    b_uv: [DVec2; 3],
    min_fold_cos: f64,
) -> Option<([u32; 4], [DVec2; 4])> {
    for i in 0..3 {
        let (p, q, r) = (a[i], a[(i + 1) % 3], a[(i + 2) % 3]);
        let Some(j) = (0..3).find(|&j| b[j] == q && b[(j + 1) % 3] == p) else {
            continue;
        };
        let d = b[(j + 2) % 3];
        if d == r {
            return None;
        }
        // The shared corners must carry the same uv on both sides (no seam on the diagonal).
        let uv_tolerance = 1e-9;
        if a_uv[i].distance(b_uv[(j + 1) % 3]) > uv_tolerance
            || a_uv[(i + 1) % 3].distance(b_uv[j]) > uv_tolerance
        {
            return None;
        }
        let quad = [q, r, p, d];
        let quad_uv = [
            a_uv[(i + 1) % 3],
            a_uv[(i + 2) % 3],
            a_uv[i],
            b_uv[(j + 2) % 3],
        ];
        let at = |k: usize| positions[quad[k] as usize];
        let n_a = (at(1) - at(0)).cross(at(2) - at(0));
        let n_b = (at(2) - at(0)).cross(at(3) - at(0));
        let (Some(na), Some(nb)) = (n_a.try_normalize(), n_b.try_normalize()) else {
            return None;
        };
        if na.dot(nb) < min_fold_cos {
            return None;
        }
        let normal = na + nb;
        for k in 0..4 {
            let turn = (at((k + 1) % 4) - at(k)).cross(at((k + 2) % 4) - at((k + 1) % 4));
            if turn.dot(normal) <= 0.0 {
                return None;
            }
        }
        return Some((quad, quad_uv));
    }
    None
}

/// Pairs triangles into quads: first consecutive triangles (exporters write a quad as two
/// consecutive triangles), then any remaining neighbours across the longest edge of both
/// (the quad's diagonal is its longest edge in well-shaped quads).
#[expect(
    clippy::type_complexity,
    reason = "a private helper returning parallel face and uv lists"
)]
fn pair_quads(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    uvs: &[[DVec2; 3]],
    max_fold_deg: f64,
) -> (Vec<Vec<u32>>, Vec<Vec<DVec2>>) {
    let min_fold_cos = max_fold_deg.to_radians().cos();
    let count = triangles.len();
    let mut partner: Vec<Option<(usize, [u32; 4], [DVec2; 4])>> = vec![None; count];
    let mut paired = vec![false; count];
    let mut t = 0;
    while t + 1 < count {
        if let Some((quad, quad_uv)) = try_pair(
            positions,
            triangles[t],
            uvs[t],
            triangles[t + 1],
            uvs[t + 1],
            min_fold_cos,
        ) {
            partner[t] = Some((t + 1, quad, quad_uv));
            paired[t] = true;
            paired[t + 1] = true;
            t += 2;
        } else {
            t += 1;
        }
    }
    let longest_edge = |tri: [u32; 3]| {
        (0..3)
            .max_by(|&i, &j| {
                let len = |k: usize| {
                    positions[tri[k] as usize].distance(positions[tri[(k + 1) % 3] as usize])
                };
                len(i).total_cmp(&len(j))
            })
            .map(|i| {
                let (x, y) = (tri[i], tri[(i + 1) % 3]);
                (x.min(y), x.max(y))
            })
            .unwrap_or((0, 0))
    };
    let mut by_diagonal: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for t in 0..count {
        if !paired[t] {
            by_diagonal
                .entry(longest_edge(triangles[t]))
                .or_default()
                .push(t);
        }
    }
    for t in 0..count {
        if paired[t] {
            continue;
        }
        let Some(candidates) = by_diagonal.get(&longest_edge(triangles[t])) else {
            continue;
        };
        for &other in candidates {
            if other == t || paired[other] {
                continue;
            }
            if let Some((quad, quad_uv)) = try_pair(
                positions,
                triangles[t],
                uvs[t],
                triangles[other],
                uvs[other],
                min_fold_cos,
            ) {
                partner[t] = Some((other, quad, quad_uv));
                paired[t] = true;
                paired[other] = true;
                break;
            }
        }
    }
    let mut faces = Vec::with_capacity(count);
    let mut face_uvs = Vec::with_capacity(count);
    let mut emitted = vec![false; count];
    for t in 0..count {
        if emitted[t] {
            continue;
        }
        match &partner[t] {
            Some((other, quad, quad_uv)) => {
                emitted[t] = true;
                emitted[*other] = true;
                faces.push(quad.to_vec());
                face_uvs.push(quad_uv.to_vec());
            }
            None if !paired[t] => {
                emitted[t] = true;
                faces.push(triangles[t].to_vec());
                face_uvs.push(uvs[t].to_vec());
            }
            None => {}
        }
    }
    (faces, face_uvs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_two_triangles_into_a_quad_but_not_across_a_fold() {
        let positions = vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let uv = |i: u32| DVec2::new(positions[i as usize].x, positions[i as usize].y);
        let tris = vec![[0, 1, 2], [0, 2, 3]];
        let uvs: Vec<[DVec2; 3]> = tris.iter().map(|t: &[u32; 3]| t.map(uv)).collect();
        let (faces, face_uvs) = pair_quads(&positions, &tris, &uvs, 30.0);
        assert_eq!(faces, vec![vec![0, 1, 2, 3]]);
        assert_eq!(face_uvs[0][1], DVec2::X);
        // Fold the quad by 90°: stays two triangles.
        let folded = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, -1.0),
        ];
        let (faces, _) = pair_quads(&folded, &tris, &uvs, 30.0);
        assert_eq!(faces.len(), 2);
    }

    #[test]
    fn weld_merges_close_vertices_and_drops_collapsed_triangles() {
        let positions = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::X * (1.0 + 1e-9),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::Y * 1e-12,
        ];
        let tris = vec![[0, 1, 2], [3, 4, 2], [0, 5, 1]];
        let uvs = vec![[DVec2::ZERO; 3]; 3];
        let (p, t, _, dropped) = weld(&positions, &tris, &uvs, 1e-6);
        assert_eq!(p.len(), 4);
        assert_eq!(t, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(dropped, 1);
    }
}
