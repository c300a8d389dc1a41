//! Scalp import from glTF 2.0 (`.gltf` with external or embedded buffers, `.glb`).
//!
//! Reads POSITION, NORMAL, TEXCOORD_0, COLOR_0, materials and indices of every triangle
//! primitive of one mesh (or, for a body, of every mesh: [`import_body`]),
//! applies the world transform of the first node that instances it, welds vertices that lie
//! within a tolerance of each other (keeping per-corner uv, so uv seams survive), and pairs
//! triangles back into quads because hair meshes are quad-dominant while glTF stores
//! triangles only.
//!
//! Accessor data is read by our own bounds-checked reader: a truncated buffer, an index out
//! of range, a NaN or an unsupported layout is an [`ImportError`] naming the file, the mesh,
//! the primitive and the accessor — never a panic. External buffers are read only from the
//! glTF's own folder, and every size is capped ([`ImportLimits`]; `docs/resource-policy.md`).

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DQuat, DVec2, DVec3};
use gltf::json;
use gltf::json::validation::Checked;

use crate::io::input_files::{InputFileError, InputFolder, read_regular_file};

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
    /// Caps on file sizes and mesh size.
    pub limits: ImportLimits,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self {
            mesh_name: None,
            weld_tolerance_relative: 1e-6,
            pair_quads: true,
            max_quad_fold_deg: 60.0,
            scale: 1.0,
            limits: ImportLimits::default(),
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
    #[error("{file}: {source}")]
    Input {
        file: String,
        source: InputFileError,
    },
    #[error("{file}: buffer {buffer}: {message}")]
    Buffer {
        file: String,
        buffer: usize,
        message: String,
    },
    #[error("{file}: mesh \"{mesh}\" has {value} {what}, above the import cap of {cap}{raise}")]
    Limit {
        file: String,
        mesh: String,
        what: &'static str,
        value: usize,
        cap: usize,
        raise: &'static str,
    },
    #[error("{file}: not a valid glTF file: {message}")]
    Gltf { file: String, message: String },
    #[error("{file}: {message}")]
    NoMesh { file: String, message: String },
    #[error(
        "{file}: the file has several meshes; choose the one hair grows on by name ({})",
        quoted_names(names)
    )]
    SeveralMeshes { file: String, names: Vec<String> },
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
    /// Vertices read from the file, before welding.
    pub source_vertices: usize,
    /// The glTF primitive each face came from (faces never span two primitives: a quad is
    /// paired only from triangles of one primitive, so a material's border stays a border).
    pub face_primitives: Vec<u32>,
    /// Each primitive's material name (`material N` when the material has none), `None`
    /// where the primitive names no material.
    pub primitive_materials: Vec<Option<String>>,
    /// Each face's mean vertex colour (COLOR_0, linear RGBA) over its corners, when any
    /// primitive has one; primitives without COLOR_0 count as white, as glTF specifies.
    pub face_colours: Option<Vec<[f64; 4]>>,
    /// Triangles dropped because welding collapsed them.
    pub degenerate_triangles: usize,
    /// The body's motion from the file's first animation that moves the mesh's node
    /// (translation and rotation; see [`body_animation`]), as head-animation keys in model
    /// space; empty when nothing animates it.
    pub body_animation: Vec<crate::model::motion::HeadKey>,
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

/// Caps on what one import may read and build (see `docs/resource-policy.md`). Each has a
/// named error; the CLI can raise `max_vertices` with `--max-vertices`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImportLimits {
    /// The `.gltf` / `.glb` file and each external buffer file.
    pub max_file_bytes: u64,
    /// Vertices over all primitives of the mesh, before welding.
    pub max_vertices: usize,
    /// Triangles over all primitives of the mesh.
    pub max_triangles: usize,
    /// Primitives in the mesh.
    pub max_primitives: usize,
}

impl Default for ImportLimits {
    fn default() -> Self {
        Self {
            max_file_bytes: 512 << 20,
            max_vertices: 4_000_000,
            max_triangles: 8_000_000,
            max_primitives: 4096,
        }
    }
}

/// Imports a mesh from a `.gltf` or `.glb` file. External buffers are read only from the
/// file's own folder (see [`crate::io::input_files`]).
pub fn import_file(path: &Path, options: &ImportOptions) -> Result<ImportedMesh, ImportError> {
    let (file, bytes, folder) = read_gltf_file(path, &options.limits)?;
    import_slice(&bytes, Some(&folder), &file, options)
}

/// The file's name for messages, its bytes (capped) and the folder its buffers may be read
/// from.
fn read_gltf_file(
    path: &Path,
    limits: &ImportLimits,
) -> Result<(String, Vec<u8>, InputFolder), ImportError> {
    let file = path.display().to_string();
    let input = |source| ImportError::Input {
        file: file.clone(),
        source,
    };
    let bytes = read_regular_file(path, limits.max_file_bytes, "a glTF file").map_err(input)?;
    let folder = InputFolder::of_file(path).map_err(input)?;
    Ok((file, bytes, folder))
}

/// The glTF JSON (read with `gltf-json`'s deserializer only) and the GLB's binary chunk.
fn parse_gltf<'a>(
    bytes: &'a [u8],
    file: &str,
) -> Result<(json::Root, Option<&'a [u8]>), ImportError> {
    let gltf_error = |message: String| ImportError::Gltf {
        file: file.to_string(),
        message,
    };
    let (json_bytes, blob) = split_glb(bytes).map_err(gltf_error)?;
    let root = json::Root::from_slice(json_bytes).map_err(|e| gltf_error(e.to_string()))?;
    Ok((root, blob))
}

/// Imports from bytes; `folder` is where external buffer URIs may lead (none: only the GLB
/// blob and data URIs), `file` names the source in messages.
///
/// The JSON is read with `gltf-json`'s deserializer only: the `gltf` crate's validation and
/// its document wrappers index arrays unchecked (an accessor index out of range panics), so
/// every index here is resolved by our own checked lookups instead.
pub fn import_slice(
    bytes: &[u8],
    folder: Option<&InputFolder>,
    file: &str,
    options: &ImportOptions,
) -> Result<ImportedMesh, ImportError> {
    let (root, blob) = parse_gltf(bytes, file)?;
    let mesh_index = choose_mesh(&root, options.mesh_name.as_deref(), file)?;
    import_mesh(&root, blob, folder, file, options, mesh_index)
}

/// Every mesh of a file as one body (a character whose scalp, face, eyes and clothes are
/// separate meshes): each read as [`import_slice`] reads one, under the same caps counted
/// over all of them. Meshes that are not triangles (lines, points: eyelashes drawn as
/// lines, say) are left out and named in the second result.
pub fn import_body(
    path: &Path,
    options: &ImportOptions,
) -> Result<(BodyMesh, Vec<String>), ImportError> {
    let (file, bytes, folder) = read_gltf_file(path, &options.limits)?;
    import_body_slice(&bytes, Some(&folder), &file, options)
}

/// [`import_body`] from bytes (see [`import_slice`] for `folder` and `file`).
pub fn import_body_slice(
    bytes: &[u8],
    folder: Option<&InputFolder>,
    file: &str,
    options: &ImportOptions,
) -> Result<(BodyMesh, Vec<String>), ImportError> {
    let (root, blob) = parse_gltf(bytes, file)?;
    if root.meshes.len() > options.limits.max_primitives {
        return Err(ImportError::Limit {
            file: file.to_string(),
            mesh: "(every mesh)".into(),
            what: "meshes",
            value: root.meshes.len(),
            cap: options.limits.max_primitives,
            raise: "",
        });
    }
    let mut body = BodyMesh::default();
    let mut skipped = Vec::new();
    let mut left = options.clone();
    for index in 0..root.meshes.len() {
        match import_mesh(&root, blob, folder, file, &left, index) {
            Ok(mesh) => {
                let part = mesh.to_body();
                let base = body.positions.len() as u32;
                body.positions.extend(part.positions);
                body.triangles
                    .extend(part.triangles.iter().map(|t| t.map(|v| v + base)));
                // What the next meshes may still read.
                left.limits.max_vertices = left
                    .limits
                    .max_vertices
                    .saturating_sub(mesh.source_vertices);
                left.limits.max_triangles = left
                    .limits
                    .max_triangles
                    .saturating_sub(mesh.source_triangles);
            }
            Err(ImportError::Primitive { mesh, message, .. })
                if message.contains("a scalp must be made of triangles") =>
            {
                skipped.push(mesh);
            }
            Err(ImportError::Empty { mesh, .. }) => skipped.push(mesh),
            Err(error) => return Err(error),
        }
    }
    Ok((body, skipped))
}

/// Reads mesh `mesh_index` of a parsed file (see [`import_slice`]).
fn import_mesh(
    root: &json::Root,
    blob: Option<&[u8]>,
    folder: Option<&InputFolder>,
    file: &str,
    options: &ImportOptions,
    mesh_index: usize,
) -> Result<ImportedMesh, ImportError> {
    let limits = options.limits;
    let mesh = &root.meshes[mesh_index];
    let mesh_name = mesh
        .name
        .clone()
        .unwrap_or_else(|| format!("mesh {mesh_index}"));
    let limit =
        |what: &'static str, value: usize, cap: usize, raise: &'static str| ImportError::Limit {
            file: file.to_string(),
            mesh: mesh_name.clone(),
            what,
            value,
            cap,
            raise,
        };
    if mesh.primitives.len() > limits.max_primitives {
        return Err(limit(
            "primitives",
            mesh.primitives.len(),
            limits.max_primitives,
            "",
        ));
    }
    let placement = mesh_node(root, mesh_index);
    let transform = placement.map_or(DMat4::IDENTITY, |(node, parent)| {
        parent * local_transform(&root.nodes[node])
    }) * DMat4::from_scale(DVec3::splat(options.scale));
    let normal_transform = transform.inverse().transpose();
    let buffers = Buffers::load(root, blob, folder, file, limits.max_file_bytes)?;
    let mut reader = AccessorReader {
        root,
        buffers: &buffers,
        file,
        mesh: &mesh_name,
        primitive: 0,
        cache: HashMap::new(),
    };

    let mut positions: Vec<DVec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut corner_uvs: Vec<[DVec2; 3]> = Vec::new();
    let mut triangle_primitives: Vec<u32> = Vec::new();
    // Each triangle's corner colours (white without COLOR_0, as glTF specifies).
    let mut triangle_colours: Vec<[[f64; 4]; 3]> = Vec::new();
    let mut has_colour = false;
    let mut primitive_materials = Vec::with_capacity(mesh.primitives.len());
    let mut has_uv = false;
    for (p_index, primitive) in mesh.primitives.iter().enumerate() {
        reader.primitive = p_index;
        let primitive_error = |message: String| ImportError::Primitive {
            file: file.to_string(),
            mesh: mesh_name.clone(),
            primitive: p_index,
            message,
        };
        match primitive.mode {
            Checked::Valid(json::mesh::Mode::Triangles) => {}
            Checked::Valid(mode) => {
                return Err(primitive_error(format!(
                    "mode {mode:?} is not supported; a scalp must be made of triangles"
                )));
            }
            Checked::Invalid => return Err(primitive_error("unknown primitive mode".into())),
        }
        let attribute = |semantic: json::mesh::Semantic| {
            primitive
                .attributes
                .get(&Checked::Valid(semantic))
                .map(|index| index.value())
        };
        let Some(position_accessor) = attribute(json::mesh::Semantic::Positions) else {
            return Err(primitive_error("missing POSITION attribute".into()));
        };
        let vertex_count = reader.count(position_accessor, "POSITION")?;
        if positions.len().saturating_add(vertex_count) > limits.max_vertices {
            return Err(limit(
                "vertices",
                positions.len().saturating_add(vertex_count),
                limits.max_vertices,
                " (raise it with --max-vertices)",
            ));
        }
        let local_positions = reader.read(position_accessor, "POSITION", 3)?;
        let normals = match attribute(json::mesh::Semantic::Normals) {
            Some(accessor) => {
                let normals = reader.read(accessor, "NORMAL", 3)?;
                if normals.len() / 3 != vertex_count {
                    return Err(reader.error(
                        accessor,
                        "NORMAL",
                        format!("{} normals for {vertex_count} positions", normals.len() / 3),
                    ));
                }
                Some(normals)
            }
            None => None,
        };
        let uvs = match attribute(json::mesh::Semantic::TexCoords(0)) {
            Some(accessor) => {
                let uvs = reader.read(accessor, "TEXCOORD_0", 2)?;
                if uvs.len() / 2 != vertex_count {
                    return Err(reader.error(
                        accessor,
                        "TEXCOORD_0",
                        format!("{} uv values for {vertex_count} positions", uvs.len() / 2),
                    ));
                }
                has_uv = true;
                Some(uvs)
            }
            None => None,
        };
        let colours = match attribute(json::mesh::Semantic::Colors(0)) {
            Some(accessor) => {
                let components = match reader.accessor(accessor, "COLOR_0")?.type_ {
                    Checked::Valid(json::accessor::Type::Vec3) => 3,
                    _ => 4,
                };
                let colours = reader.read(accessor, "COLOR_0", components)?;
                if colours.len() / components != vertex_count {
                    return Err(reader.error(
                        accessor,
                        "COLOR_0",
                        format!(
                            "{} colours for {vertex_count} positions",
                            colours.len() / components
                        ),
                    ));
                }
                has_colour = true;
                Some((colours, components))
            }
            None => None,
        };
        primitive_materials.push(primitive.material.map(|m| {
            let m = m.value();
            root.materials
                .get(m)
                .and_then(|material| material.name.clone())
                .unwrap_or_else(|| format!("material {m}"))
        }));
        let indices: Vec<u32> = match primitive.indices.map(|i| i.value()) {
            Some(accessor) => {
                let count = reader.count(accessor, "indices")?;
                let triangle_total = triangles.len().saturating_add(count / 3);
                if triangle_total > limits.max_triangles {
                    return Err(limit("triangles", triangle_total, limits.max_triangles, ""));
                }
                let values = reader.read(accessor, "indices", 1)?;
                let mut indices = Vec::with_capacity(values.len());
                for (i, &index) in values.iter().enumerate() {
                    if index < 0.0 || index >= vertex_count as f64 {
                        return Err(reader.error(
                            accessor,
                            "indices",
                            format!("index {index} at position {i} is out of range ({vertex_count} vertices)"),
                        ));
                    }
                    indices.push(index as u32);
                }
                if indices.len() % 3 != 0 {
                    return Err(reader.error(
                        accessor,
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
                let triangle_total = triangles.len().saturating_add(vertex_count / 3);
                if triangle_total > limits.max_triangles {
                    return Err(limit("triangles", triangle_total, limits.max_triangles, ""));
                }
                (0..vertex_count as u32).collect()
            }
        };
        // Flip triangles whose winding disagrees with the file's normals, so every face is
        // counter-clockwise seen from outside, as the hair mesh requires.
        let base = positions.len() as u32;
        let vec3 = |values: &[f64], i: usize| DVec3::from_slice(&values[3 * i..3 * i + 3]);
        let world: Vec<DVec3> = (0..vertex_count)
            .map(|i| transform.transform_point3(vec3(&local_positions, i)))
            .collect();
        if let Some(i) = world.iter().position(|p| !p.is_finite()) {
            return Err(primitive_error(format!(
                "vertex {i} is not finite after the node transform and scale"
            )));
        }
        for triangle in indices.chunks_exact(3) {
            let mut t = [triangle[0], triangle[1], triangle[2]];
            if let Some(normals) = &normals {
                let face_normal = (world[t[1] as usize] - world[t[0] as usize])
                    .cross(world[t[2] as usize] - world[t[0] as usize]);
                let vertex_normal: DVec3 = t
                    .iter()
                    .map(|&i| normal_transform.transform_vector3(vec3(normals, i as usize)))
                    .sum();
                if face_normal.dot(vertex_normal) < 0.0 {
                    t.swap(1, 2);
                }
            }
            let uv = t.map(|i| match &uvs {
                Some(uvs) => DVec2::new(uvs[2 * i as usize], uvs[2 * i as usize + 1]),
                None => DVec2::ZERO,
            });
            let colour = t.map(|i| match &colours {
                Some((colours, components)) => {
                    let mut rgba = [0.0, 0.0, 0.0, 1.0];
                    for (c, value) in rgba.iter_mut().enumerate().take(*components) {
                        *value = colours[components * i as usize + c];
                    }
                    rgba
                }
                None => [1.0; 4],
            });
            triangles.push(t.map(|i| i + base));
            corner_uvs.push(uv);
            triangle_primitives.push(p_index as u32);
            triangle_colours.push(colour);
        }
        positions.extend(world);
    }
    let source_triangles = triangles.len();
    let source_vertices = positions.len();
    let (positions, welded) = weld(&positions, &triangles, options.weld_tolerance_relative);
    let degenerate = source_triangles - welded.len();
    let corner_uvs: Vec<[DVec2; 3]> = welded.iter().map(|&(t, _)| corner_uvs[t]).collect();
    let triangle_primitives: Vec<u32> = welded
        .iter()
        .map(|&(t, _)| triangle_primitives[t])
        .collect();
    let triangle_colours: Vec<[[f64; 4]; 3]> =
        welded.iter().map(|&(t, _)| triangle_colours[t]).collect();
    let triangles: Vec<[u32; 3]> = welded.into_iter().map(|(_, t)| t).collect();
    if triangles.is_empty() {
        return Err(ImportError::Empty {
            file: file.to_string(),
            mesh: mesh_name,
        });
    }
    let (faces, uvs, face_triangles) = if options.pair_quads {
        pair_quads(
            &positions,
            &triangles,
            &corner_uvs,
            &triangle_primitives,
            options.max_quad_fold_deg,
        )
    } else {
        (
            triangles.iter().map(|t| t.to_vec()).collect(),
            corner_uvs.iter().map(|u| u.to_vec()).collect(),
            (0..triangles.len()).map(|t| vec![t]).collect(),
        )
    };
    let face_primitives = face_triangles
        .iter()
        .map(|ts| triangle_primitives[ts[0]])
        .collect();
    // A face's colour is the mean over its distinct corners (a quad's diagonal corners
    // count once, whichever diagonal the exporter split it along).
    let face_colours = has_colour.then(|| {
        face_triangles
            .iter()
            .map(|ts| {
                let mut corners: Vec<(u32, [f64; 4])> = Vec::with_capacity(4);
                for &t in ts {
                    for (&vertex, colour) in triangles[t].iter().zip(triangle_colours[t]) {
                        if !corners.iter().any(|(v, _)| *v == vertex) {
                            corners.push((vertex, colour));
                        }
                    }
                }
                let mut mean = [0.0; 4];
                for (_, colour) in &corners {
                    for (m, c) in mean.iter_mut().zip(colour) {
                        *m += c / corners.len() as f64;
                    }
                }
                mean
            })
            .collect()
    });
    let body_animation = match placement {
        Some((node, parent)) => body_animation(root, node, parent, &mut reader)?,
        None => Vec::new(),
    };
    Ok(ImportedMesh {
        mesh_name,
        positions,
        faces,
        uvs,
        has_uv,
        source_triangles,
        source_vertices,
        face_primitives,
        primitive_materials,
        face_colours,
        degenerate_triangles: degenerate,
        body_animation,
    })
}

/// The first animation (in file order) with a translation or rotation channel on `node`,
/// sampled at every key time of those channels into rigid head-animation keys:
/// `p ↦ P · L(t) · L(0)⁻¹ · P⁻¹ · p`, where `P` is the node's parent transform and `L` its
/// local one (the mesh's rest pose is `L` as the file stores it), so the keys move the
/// imported body exactly as the file's animation moves the mesh. Scale channels, morph
/// weights and the animation of ancestor nodes are not read (a head animation is rigid).
/// LINEAR keys interpolate (quaternions by slerp), STEP keys hold, CUBICSPLINE keys keep
/// their values (the tangents are dropped: the head animation interpolates linearly between
/// keys). Euler angles are unwrapped from key to key, so a full turn stays a full turn.
fn body_animation(
    root: &json::Root,
    node: usize,
    parent: DMat4,
    reader: &mut AccessorReader,
) -> Result<Vec<crate::model::motion::HeadKey>, ImportError> {
    use crate::model::motion::{HeadKey, MAX_HEAD_KEYS, MAX_KEY_TIME_S};
    use json::animation::{Interpolation, Property};
    struct Track {
        times: Vec<f64>,
        values: Vec<f64>,
        width: usize,
        step: bool,
    }
    let fail = |animation: usize, message: String| ImportError::Gltf {
        file: reader.file.to_string(),
        message: format!("animation {animation}: {message}"),
    };
    for (a, animation) in root.animations.iter().enumerate() {
        let (mut translation, mut rotation) = (None, None);
        for (c, channel) in animation.channels.iter().enumerate() {
            if channel.target.node.value() != node {
                continue;
            }
            let (slot, width, name) = match channel.target.path {
                Checked::Valid(Property::Translation) => (&mut translation, 3, "translation"),
                Checked::Valid(Property::Rotation) => (&mut rotation, 4, "rotation"),
                _ => continue,
            };
            let s = channel.sampler.value();
            let Some(sampler) = animation.samplers.get(s) else {
                return Err(fail(
                    a,
                    format!(
                        "channel {c} uses sampler {s}; the animation has {}",
                        animation.samplers.len()
                    ),
                ));
            };
            let what = format!("animation {a} {name} times");
            let times = reader.read(sampler.input.value(), &what, 1)?.to_vec();
            if times.len() > MAX_HEAD_KEYS {
                return Err(fail(
                    a,
                    format!(
                        "{} {name} keys, more than the {MAX_HEAD_KEYS} a head animation may hold",
                        times.len()
                    ),
                ));
            }
            if let Some(w) = times.windows(2).find(|w| w[1] < w[0]) {
                return Err(fail(
                    a,
                    format!(
                        "{name} key time {} comes after {}: keys go in time order",
                        w[0], w[1]
                    ),
                ));
            }
            if times.iter().any(|t| !(0.0..=MAX_KEY_TIME_S).contains(t)) {
                return Err(fail(
                    a,
                    format!("{name} key times must lie in [0, {MAX_KEY_TIME_S}] s"),
                ));
            }
            let what = format!("animation {a} {name} values");
            let raw = reader.read(sampler.output.value(), &what, width)?;
            let (values, step) = match sampler.interpolation {
                Checked::Valid(Interpolation::CubicSpline) => {
                    // (in-tangent, value, out-tangent) per key: keep the values.
                    if raw.len() != times.len() * 3 * width {
                        return Err(fail(
                            a,
                            format!(
                                "{} cubic-spline {name} values for {} keys (3 per key)",
                                raw.len() / width,
                                times.len()
                            ),
                        ));
                    }
                    let values = raw
                        .chunks(3 * width)
                        .flat_map(|k| k[width..2 * width].to_vec())
                        .collect();
                    (values, false)
                }
                Checked::Valid(interpolation) => {
                    if raw.len() != times.len() * width {
                        return Err(fail(
                            a,
                            format!(
                                "{} {name} values for {} keys",
                                raw.len() / width,
                                times.len()
                            ),
                        ));
                    }
                    (raw.to_vec(), interpolation == Interpolation::Step)
                }
                Checked::Invalid => {
                    return Err(fail(a, format!("unknown {name} interpolation")));
                }
            };
            if !times.is_empty() {
                *slot = Some(Track {
                    times,
                    values,
                    width,
                    step,
                });
            }
        }
        if translation.is_none() && rotation.is_none() {
            continue;
        }
        // A track's value at `t`: held before the first key and after the last.
        let sample = |track: &Track, t: f64| -> Vec<f64> {
            let w = track.width;
            let at = |k: usize| track.values[k * w..(k + 1) * w].to_vec();
            let next = track.times.partition_point(|&k| k <= t);
            if next == 0 {
                return at(0);
            }
            if next >= track.times.len() || track.step {
                return at(next - 1);
            }
            let (t0, t1) = (track.times[next - 1], track.times[next]);
            let f = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
            if w == 4 {
                let q = |v: Vec<f64>| DQuat::from_array([v[0], v[1], v[2], v[3]]).normalize();
                let (a, b) = (q(at(next - 1)), q(at(next)));
                return a.slerp(b, f).to_array().to_vec();
            }
            at(next - 1)
                .iter()
                .zip(at(next))
                .map(|(a, b)| a + (b - a) * f)
                .collect()
        };
        let mut times: Vec<f64> = translation
            .iter()
            .chain(rotation.iter())
            .flat_map(|t| t.times.iter().copied())
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        if times.len() > MAX_HEAD_KEYS {
            return Err(fail(
                a,
                format!(
                    "{} distinct key times, more than the {MAX_HEAD_KEYS} a head animation may hold",
                    times.len()
                ),
            ));
        }
        let rest = &root.nodes[node];
        let rest_local = local_transform(rest);
        let (rest_scale, rest_rotation, rest_translation) =
            rest_local.to_scale_rotation_translation();
        let to_rest = parent * rest_local;
        if !to_rest.is_finite() || to_rest.determinant().abs() < 1e-12 {
            return Err(fail(
                a,
                "the animated node's rest transform is degenerate".into(),
            ));
        }
        let from_rest = to_rest.inverse();
        let mut keys: Vec<HeadKey> = Vec::with_capacity(times.len());
        for t in times {
            let moved_translation = translation.as_ref().map_or(rest_translation, |track| {
                DVec3::from_slice(&sample(track, t))
            });
            let moved_rotation = rotation.as_ref().map_or(rest_rotation, |track| {
                let v = sample(track, t);
                DQuat::from_array([v[0], v[1], v[2], v[3]]).normalize()
            });
            let local = DMat4::from_scale_rotation_translation(
                rest_scale,
                moved_rotation,
                moved_translation,
            );
            let motion = parent * local * from_rest;
            let (_, turn, shift) = motion.to_scale_rotation_translation();
            if !(turn.is_finite() && shift.is_finite()) {
                return Err(fail(a, format!("the pose at {t} s is not a rigid motion")));
            }
            let (yaw, pitch, roll) = turn.normalize().to_euler(glam::EulerRot::YXZ);
            let mut key = HeadKey {
                time_s: t,
                translation_m: shift.to_array(),
                yaw_deg: yaw.to_degrees(),
                pitch_deg: pitch.to_degrees(),
                roll_deg: roll.to_degrees(),
            };
            // Unwrapped: the angle nearest the previous key's, so interpolating between
            // keys never turns the long way round.
            if let Some(previous) = keys.last() {
                let near = |angle: f64, previous: f64| {
                    angle + 360.0 * ((previous - angle) / 360.0).round()
                };
                key.yaw_deg = near(key.yaw_deg, previous.yaw_deg);
                key.pitch_deg = near(key.pitch_deg, previous.pitch_deg);
                key.roll_deg = near(key.roll_deg, previous.roll_deg);
            }
            keys.push(key);
        }
        return Ok(keys);
    }
    Ok(Vec::new())
}

/// The JSON chunk and the optional BIN chunk of a GLB, or the whole input as JSON. The
/// header is checked here first: `gltf::Glb::from_slice` subtracts the header size from
/// the declared length unchecked.
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok((bytes, None));
    }
    if bytes.len() < 20 {
        return Err(format!(
            "a {}-byte GLB is shorter than its header",
            bytes.len()
        ));
    }
    let word =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    if word(4) != 2 {
        return Err(format!("GLB version {} is not 2", word(4)));
    }
    if word(8) as usize != bytes.len() {
        return Err(format!(
            "the GLB header declares {} bytes but the file has {}",
            word(8),
            bytes.len()
        ));
    }
    let glb = gltf::Glb::from_slice(bytes).map_err(|e| format!("GLB container: {e}"))?;
    match (glb.json, glb.bin) {
        (std::borrow::Cow::Borrowed(json), Some(std::borrow::Cow::Borrowed(bin))) => {
            Ok((json, Some(bin)))
        }
        (std::borrow::Cow::Borrowed(json), None) => Ok((json, None)),
        _ => Err("GLB container copied its chunks".into()),
    }
}

fn choose_mesh(root: &json::Root, name: Option<&str>, file: &str) -> Result<usize, ImportError> {
    let no_mesh = |message: String| ImportError::NoMesh {
        file: file.to_string(),
        message,
    };
    match name {
        Some(name) => root
            .meshes
            .iter()
            .position(|m| m.name.as_deref() == Some(name))
            .or_else(|| {
                // An unnamed mesh by its index, as messages list it.
                let index: usize = name.strip_prefix('#')?.parse().ok()?;
                (index < root.meshes.len() && root.meshes[index].name.is_none()).then_some(index)
            })
            .ok_or_else(|| {
                no_mesh(format!(
                    "no mesh named \"{name}\" (meshes: {})",
                    quoted_names(&mesh_name_list(root))
                ))
            }),
        None => match root.meshes.len() {
            0 => Err(no_mesh("the file contains no mesh".into())),
            1 => Ok(0),
            _ => Err(ImportError::SeveralMeshes {
                file: file.to_string(),
                names: mesh_name_list(root),
            }),
        },
    }
}

/// Every mesh's name (`#N` for an unnamed one, which `ImportOptions::mesh_name` also takes),
/// in file order.
fn mesh_name_list(root: &json::Root) -> Vec<String> {
    root.meshes
        .iter()
        .enumerate()
        .map(|(i, m)| m.name.clone().unwrap_or_else(|| format!("#{i}")))
        .collect()
}

/// The first 20 names, quoted, for a message.
fn quoted_names(names: &[String]) -> String {
    let mut out: Vec<String> = names.iter().take(20).map(|n| format!("\"{n}\"")).collect();
    if names.len() > 20 {
        out.push(format!("… {} more", names.len() - 20));
    }
    out.join(", ")
}

/// The first node (in scene order, depth first) that instances `mesh`, with its parent's
/// world transform; `None` when no node does. Indices are looked up checked, and the walk is
/// bounded in depth and in nodes visited (a hostile file may make the node graph cyclic or
/// shared).
fn mesh_node(root: &json::Root, mesh: usize) -> Option<(usize, DMat4)> {
    struct Walk<'a> {
        root: &'a json::Root,
        mesh: usize,
        visited: usize,
    }
    impl Walk<'_> {
        fn visit(&mut self, index: usize, parent: DMat4, depth: usize) -> Option<(usize, DMat4)> {
            self.visited += 1;
            if depth > 64 || self.visited > 100_000 {
                return None;
            }
            let node = self.root.nodes.get(index)?;
            if node.mesh.is_some_and(|m| m.value() == self.mesh) {
                return Some((index, parent));
            }
            let world = parent * local_transform(node);
            node.children
                .iter()
                .flatten()
                .find_map(|child| self.visit(child.value(), world, depth + 1))
        }
    }
    let mut walk = Walk {
        root,
        mesh,
        visited: 0,
    };
    let scenes = root
        .scene
        .map(|s| s.value())
        .into_iter()
        .chain(0..root.scenes.len());
    scenes
        .filter_map(|s| root.scenes.get(s))
        .find_map(|scene| {
            scene
                .nodes
                .iter()
                .find_map(|node| walk.visit(node.value(), DMat4::IDENTITY, 0))
        })
        .filter(|(node, parent)| (*parent * local_transform(&root.nodes[*node])).is_finite())
}

fn local_transform(node: &json::scene::Node) -> DMat4 {
    if let Some(matrix) = node.matrix {
        return DMat4::from_cols_array(&matrix.map(f64::from));
    }
    let t = node.translation.unwrap_or([0.0; 3]).map(f64::from);
    let r = node
        .rotation
        .map(|q| q.0)
        .unwrap_or([0.0, 0.0, 0.0, 1.0])
        .map(f64::from);
    let s = node.scale.unwrap_or([1.0; 3]).map(f64::from);
    let rotation = DQuat::from_array(r).normalize();
    DMat4::from_scale_rotation_translation(DVec3::from(s), rotation, DVec3::from(t))
}

/// The bytes of every buffer: the GLB blob, a base64 data URI, or a regular file inside the
/// glTF's folder (never anything else: see [`crate::io::input_files`]).
struct Buffers<'a> {
    data: Vec<std::borrow::Cow<'a, [u8]>>,
}

impl<'a> Buffers<'a> {
    fn load(
        root: &json::Root,
        blob: Option<&'a [u8]>,
        folder: Option<&InputFolder>,
        file: &str,
        cap_bytes: u64,
    ) -> Result<Self, ImportError> {
        let mut data = Vec::with_capacity(root.buffers.len());
        let mut total_bytes = 0u64;
        for (index, buffer) in root.buffers.iter().enumerate() {
            let fail = |message: String| ImportError::Buffer {
                file: file.to_string(),
                buffer: index,
                message,
            };
            let declared = buffer.byte_length.0;
            total_bytes = total_bytes.saturating_add(declared);
            if total_bytes > cap_bytes {
                return Err(fail(format!(
                    "the buffers declare more than the cap of {cap_bytes} bytes"
                )));
            }
            let bytes: std::borrow::Cow<[u8]> = match buffer.uri.as_deref() {
                None => match (index, blob) {
                    (0, Some(blob)) => std::borrow::Cow::Borrowed(blob),
                    _ => {
                        return Err(fail(
                            "it has no uri and is not the GLB's binary chunk".into(),
                        ));
                    }
                },
                Some(uri) if uri.starts_with("data:") => {
                    std::borrow::Cow::Owned(decode_data_uri(uri).map_err(fail)?)
                }
                Some(uri) => {
                    let Some(folder) = folder else {
                        return Err(fail(format!(
                            "it names the external file \"{uri}\", but this input has no folder to read it from"
                        )));
                    };
                    let name = percent_decode(uri).map_err(fail)?;
                    let bytes = folder
                        .read(&name, cap_bytes, "a glTF buffer")
                        .map_err(|source| fail(source.to_string()))?;
                    std::borrow::Cow::Owned(bytes)
                }
            };
            if (bytes.len() as u64) < declared {
                return Err(fail(format!(
                    "it holds {} bytes but the file declares byteLength {declared}",
                    bytes.len()
                )));
            }
            data.push(match bytes {
                std::borrow::Cow::Borrowed(b) => {
                    std::borrow::Cow::Borrowed(&b[..declared as usize])
                }
                std::borrow::Cow::Owned(mut b) => {
                    b.truncate(declared as usize);
                    std::borrow::Cow::Owned(b)
                }
            });
        }
        Ok(Self { data })
    }

    fn get(&self, index: usize) -> Option<&[u8]> {
        self.data.get(index).map(|b| b.as_ref())
    }
}

/// The bytes of a base64 `data:` URI (the only data URI form glTF exporters write).
fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    use base64::Engine as _;
    let Some((header, payload)) = uri.split_once(',') else {
        return Err("data URI without a comma".into());
    };
    if !header.ends_with(";base64") {
        return Err("only base64 data URIs are supported".into());
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload)
        .map_err(|e| format!("data URI: {e}"))
}

/// glTF URIs are RFC 3986 references: `%20` in a file name is a space.
fn percent_decode(uri: &str) -> Result<String, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("\"{uri}\": a malformed %-escape"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("\"{uri}\": not UTF-8 after %-decoding"))
}

/// Reads accessors with every index, offset and size checked; each accessor is read once
/// and shared (a file may point thousands of primitives at one accessor).
struct AccessorReader<'a> {
    root: &'a json::Root,
    buffers: &'a Buffers<'a>,
    file: &'a str,
    mesh: &'a str,
    primitive: usize,
    cache: HashMap<usize, std::rc::Rc<Vec<f64>>>,
}

impl AccessorReader<'_> {
    fn error(&self, accessor: usize, semantic: &str, message: String) -> ImportError {
        ImportError::Accessor {
            file: self.file.to_string(),
            mesh: self.mesh.to_string(),
            primitive: self.primitive,
            accessor,
            semantic: semantic.to_string(),
            message,
        }
    }

    fn accessor(
        &self,
        index: usize,
        semantic: &str,
    ) -> Result<&json::accessor::Accessor, ImportError> {
        self.root.accessors.get(index).ok_or_else(|| {
            self.error(
                index,
                semantic,
                format!(
                    "accessor {index} does not exist (the file has {})",
                    self.root.accessors.len()
                ),
            )
        })
    }

    /// Element count of an accessor, before reading it.
    fn count(&self, index: usize, semantic: &str) -> Result<usize, ImportError> {
        let accessor = self.accessor(index, semantic)?;
        usize::try_from(accessor.count.0)
            .map_err(|_| self.error(index, semantic, "count does not fit in memory".into()))
    }

    /// Reads an accessor of `components` components per element into a flat list of f64,
    /// with normalised integers mapped to [0, 1] / [−1, 1]. Every value must be finite.
    fn read(
        &mut self,
        index: usize,
        semantic: &str,
        components: usize,
    ) -> Result<std::rc::Rc<Vec<f64>>, ImportError> {
        use json::accessor::{ComponentType, Type};
        let accessor = self.accessor(index, semantic)?;
        let fail = |message: String| self.error(index, semantic, message);
        let dims = match accessor.type_ {
            Checked::Valid(Type::Scalar) => 1,
            Checked::Valid(Type::Vec2) => 2,
            Checked::Valid(Type::Vec3) => 3,
            Checked::Valid(Type::Vec4) => 4,
            Checked::Valid(other) => {
                return Err(fail(format!("unsupported element type {other:?}")));
            }
            Checked::Invalid => return Err(fail("unknown element type".into())),
        };
        if dims != components {
            return Err(fail(format!(
                "expected {components} components per element, found {dims}"
            )));
        }
        if let Some(cached) = self.cache.get(&index) {
            return Ok(cached.clone());
        }
        if accessor.sparse.is_some() {
            return Err(fail("sparse accessors are not supported".into()));
        }
        let data_type = match accessor.component_type {
            Checked::Valid(json::accessor::GenericComponentType(t)) => t,
            Checked::Invalid => return Err(fail("unknown component type".into())),
        };
        let Some(view_index) = accessor.buffer_view.map(|v| v.value()) else {
            return Err(fail("accessor has no buffer view".into()));
        };
        let Some(view) = self.root.buffer_views.get(view_index) else {
            return Err(fail(format!("buffer view {view_index} does not exist")));
        };
        let component_size = match data_type {
            ComponentType::I8 | ComponentType::U8 => 1,
            ComponentType::I16 | ComponentType::U16 => 2,
            ComponentType::U32 | ComponentType::F32 => 4,
        };
        let element_size = component_size * dims;
        let stride = view.byte_stride.map(|s| s.0).unwrap_or(element_size);
        if stride < element_size {
            return Err(fail(format!(
                "byte stride {stride} is smaller than the element ({element_size} bytes)"
            )));
        }
        let buffer_index = view.buffer.value();
        let Some(buffer) = self.buffers.get(buffer_index) else {
            return Err(fail(format!("buffer {buffer_index} does not exist")));
        };
        let view_offset = view.byte_offset.map_or(0, |o| o.0);
        let view_length = view.byte_length.0;
        let view_range = usize::try_from(view_offset)
            .ok()
            .zip(usize::try_from(view_length).ok())
            .and_then(|(start, length)| Some(start..start.checked_add(length)?))
            .filter(|range| range.end <= buffer.len());
        let Some(view_range) = view_range else {
            return Err(fail(format!(
                "buffer view {view_index} ({view_length} bytes at offset {view_offset}) runs past the end of buffer {buffer_index} ({} bytes)",
                buffer.len()
            )));
        };
        let view_bytes = &buffer[view_range];
        let count = self.count(index, semantic)?;
        let offset = usize::try_from(accessor.byte_offset.map_or(0, |o| o.0)).unwrap_or(usize::MAX);
        let needed = if count == 0 {
            Some(0)
        } else {
            stride
                .checked_mul(count - 1)
                .and_then(|v| v.checked_add(offset))
                .and_then(|v| v.checked_add(element_size))
        };
        if needed.is_none_or(|needed| needed > view_bytes.len()) {
            return Err(fail(format!(
                "{count} elements need more bytes than buffer view {view_index} has ({}; truncated file?)",
                view_bytes.len()
            )));
        }
        let normalized = accessor.normalized;
        let mut out = Vec::with_capacity(count * dims);
        for i in 0..count {
            let start = offset + i * stride;
            for c in 0..dims {
                let at = start + c * component_size;
                let b = &view_bytes[at..at + component_size];
                let value = match data_type {
                    ComponentType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    ComponentType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    ComponentType::U16 => {
                        let v = u16::from_le_bytes([b[0], b[1]]) as f64;
                        if normalized { v / 65535.0 } else { v }
                    }
                    ComponentType::I16 => {
                        let v = i16::from_le_bytes([b[0], b[1]]) as f64;
                        if normalized {
                            (v / 32767.0).max(-1.0)
                        } else {
                            v
                        }
                    }
                    ComponentType::U8 => {
                        let v = b[0] as f64;
                        if normalized { v / 255.0 } else { v }
                    }
                    ComponentType::I8 => {
                        let v = b[0] as i8 as f64;
                        if normalized { (v / 127.0).max(-1.0) } else { v }
                    }
                };
                if !value.is_finite() {
                    return Err(fail(format!(
                        "element {i} component {c} is not finite ({value})"
                    )));
                }
                out.push(value);
            }
        }
        let out = std::rc::Rc::new(out);
        self.cache.insert(index, out.clone());
        Ok(out)
    }
}

/// Merges vertices closer than `relative_tolerance × bounding-box diagonal` and drops
/// triangles that collapse. Returns the welded positions and each surviving triangle as
/// (its index in `triangles`, its welded corners), so per-triangle data follows it.
fn weld(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    relative_tolerance: f64,
) -> (Vec<DVec3>, Vec<(usize, [u32; 3])>) {
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
                    let cell = (
                        x.saturating_add(dx),
                        y.saturating_add(dy),
                        z.saturating_add(dz),
                    );
                    if let Some(list) = grid.get(&cell) {
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
    for (index, t) in triangles.iter().enumerate() {
        let m = t.map(|i| remap[i as usize]);
        if m[0] == m[1] || m[1] == m[2] || m[0] == m[2] {
            continue;
        }
        out_triangles.push((index, m));
    }
    // Drop vertices no triangle uses (for example, only used by collapsed triangles).
    let mut used = vec![u32::MAX; welded.len()];
    let mut compact = Vec::new();
    for (_, t) in &mut out_triangles {
        for i in t.iter_mut() {
            if used[*i as usize] == u32::MAX {
                used[*i as usize] = compact.len() as u32;
                compact.push(welded[*i as usize]);
            }
            *i = used[*i as usize];
        }
    }
    (compact, out_triangles)
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
/// (the quad's diagonal is its longest edge in well-shaped quads). Only triangles of one
/// `group` (the glTF primitive) pair. Returns faces, their corner uvs and the triangles
/// each face was made of.
#[expect(
    clippy::type_complexity,
    reason = "a private helper returning parallel face, uv and source lists"
)]
fn pair_quads(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    uvs: &[[DVec2; 3]],
    group: &[u32],
    max_fold_deg: f64,
) -> (Vec<Vec<u32>>, Vec<Vec<DVec2>>, Vec<Vec<usize>>) {
    let min_fold_cos = max_fold_deg.to_radians().cos();
    let count = triangles.len();
    let mut partner: Vec<Option<(usize, [u32; 4], [DVec2; 4])>> = vec![None; count];
    let mut paired = vec![false; count];
    let mut t = 0;
    while t + 1 < count {
        if group[t] != group[t + 1] {
            t += 1;
            continue;
        }
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
            if other == t || paired[other] || group[other] != group[t] {
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
    let mut face_triangles = Vec::with_capacity(count);
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
                face_triangles.push(vec![t, *other]);
            }
            None if !paired[t] => {
                emitted[t] = true;
                faces.push(triangles[t].to_vec());
                face_uvs.push(uvs[t].to_vec());
                face_triangles.push(vec![t]);
            }
            None => {}
        }
    }
    (faces, face_uvs, face_triangles)
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
        let (faces, face_uvs, sources) = pair_quads(&positions, &tris, &uvs, &[0, 0], 30.0);
        assert_eq!(faces, vec![vec![0, 1, 2, 3]]);
        assert_eq!(face_uvs[0][1], DVec2::X);
        assert_eq!(sources, vec![vec![0, 1]]);
        // Triangles of two primitives (two materials) never become one quad.
        let (faces, _, sources) = pair_quads(&positions, &tris, &uvs, &[0, 1], 30.0);
        assert_eq!(faces.len(), 2);
        assert_eq!(sources, vec![vec![0], vec![1]]);
        // Fold the quad by 90°: stays two triangles.
        let folded = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, -1.0),
        ];
        let (faces, _, _) = pair_quads(&folded, &tris, &uvs, &[0, 0], 30.0);
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
        let (p, t) = weld(&positions, &tris, 1e-6);
        assert_eq!(p.len(), 4);
        // The third triangle collapses; the survivors keep their source index.
        assert_eq!(t, vec![(0, [0, 1, 2]), (1, [1, 3, 2])]);
    }
}
