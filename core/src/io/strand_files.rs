//! Strands for other tools: Cem Yuksel's `.hair`, USD `.usda` BasisCurves, binary glTF with
//! LINES, and the body as a triangle GLB. Every function builds bytes in memory; writing
//! them is the caller's job (atomically, see [`crate::io::project::write_atomic`]).

use crate::model::mesh::HairMesh;
use crate::model::scene::HairMaterial;
use crate::strands::reference::{Strand, root_indices};

/// How exported strands look, the same in every format: each point's width (the root
/// width tapering to the tip as the renderers draw it) and colour (linear RGB, from the
/// hair material with each strand's own variation).
#[derive(Clone, Debug, PartialEq)]
pub struct StrandLook {
    pub root_width_m: f32,
    /// One per point of the strands, in order.
    pub widths_m: Vec<f32>,
    /// One per point of the strands, in order.
    pub colors: Vec<[f32; 3]>,
}

impl StrandLook {
    /// The look of `strands`: tapered widths, and the material's colour under the colour map
    /// of `maps` at each strand's root.
    pub fn new(
        strands: &[Strand],
        root_width_m: f32,
        material: &HairMaterial,
        maps: &crate::model::root_maps::RootMaps,
    ) -> Self {
        let roots = root_indices(strands);
        Self {
            root_width_m,
            widths_m: strands
                .iter()
                .flat_map(|s| tapered_widths_m(s.points.len(), root_width_m))
                .collect(),
            colors: crate::light::material::strand_point_colors(material, maps, strands, &roots),
        }
    }
}

/// The widths of a curve of `count` points whose root is `root_width_m` wide, tapering as
/// [`crate::strands::strand_width_m`] says.
pub fn tapered_widths_m(count: usize, root_width_m: f32) -> impl Iterator<Item = f32> {
    let last = count.saturating_sub(1).max(1) as f64;
    (0..count)
        .map(move |k| crate::strands::strand_width_m(root_width_m as f64, k as f64 / last) as f32)
}

/// Points one strand export may hold (every strand × its vertices). Strands are generated
/// in memory before they are written (24 B per point as f64, 16 B of width and colour,
/// plus the file's own bytes: 28 to about 90 per point), so this bounds an export to about
/// 4.4 GB of memory; it also keeps every format inside its own 32-bit counts (`.hair`'s
/// point count, a GLB's length). See `docs/resource-policy.md`.
pub const MAX_EXPORT_POINTS: u64 = 32 << 20;

/// How big a strand export of a document would be, counted before anything is generated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StrandExportSize {
    pub strands_per_bundle: u32,
    /// At most this many strands (bundles that are thinned grow fewer; one that is
    /// degenerate grows none).
    pub strands: u64,
    pub vertices_per_strand: u64,
    pub points: u64,
}

impl StrandExportSize {
    /// `strands_per_bundle` strands of `2^vertices_log2 + 1` vertices from every bundle of
    /// `mesh` (each thinned by its density as generation thins it).
    pub fn of(mesh: &HairMesh, strands_per_bundle: u32, vertices_log2: u32) -> Self {
        let strands: u64 = mesh
            .bundles
            .iter()
            .map(|b| crate::strands::lod::density_count(b.density, strands_per_bundle) as u64)
            .sum();
        let vertices_per_strand = 1u64
            .checked_shl(vertices_log2)
            .unwrap_or(u64::MAX)
            .saturating_add(1);
        Self {
            strands_per_bundle,
            strands,
            vertices_per_strand,
            points: strands.saturating_mul(vertices_per_strand),
        }
    }

    /// Bytes of memory the export needs while it is written, roughly: the f64 points, each
    /// point's width and colour, and the largest file's bytes (text USD with per-point
    /// widths and colours, about 90 per point).
    pub fn memory_bytes(&self) -> u64 {
        self.points.saturating_mul(24 + 16 + 90)
    }

    /// Refuses an export above [`MAX_EXPORT_POINTS`], saying how big it would be (the
    /// caller adds which of its settings to lower).
    pub fn check(&self) -> Result<(), String> {
        use crate::io::runtime_bundle::limits::{MAX_VERTICES_LOG2, STRANDS_PER_BUNDLE};
        if self.strands_per_bundle > STRANDS_PER_BUNDLE {
            return Err(format!(
                "{} strands per bundle is more than the cap of {STRANDS_PER_BUNDLE}",
                self.strands_per_bundle
            ));
        }
        let most_vertices = (1u64 << MAX_VERTICES_LOG2) + 1;
        if self.vertices_per_strand > most_vertices {
            return Err(format!(
                "{} vertices per strand is more than the cap of {most_vertices}",
                self.vertices_per_strand
            ));
        }
        if self.points <= MAX_EXPORT_POINTS {
            return Ok(());
        }
        Err(format!(
            "the strand export would hold {} strands × {} vertices = {} points, about {:.1} GB of memory while it is written; the cap is {} points (docs/resource-policy.md)",
            self.strands,
            self.vertices_per_strand,
            self.points,
            self.memory_bytes() as f64 / 1e9,
            MAX_EXPORT_POINTS
        ))
    }
}

/// Cem Yuksel's `.hair` format (cyHair): a 128-byte header, then the segments array (when
/// strands differ in vertex count), the points, and each point's thickness and colour from
/// `look`. The header's defaults are the root width and the first point's colour.
pub fn hair_file(strands: &[Strand], look: &StrandLook) -> Vec<u8> {
    let point_count: usize = strands.iter().map(|s| s.points.len()).sum();
    let uniform = strands
        .windows(2)
        .all(|w| w[0].points.len() == w[1].points.len());
    let default_segments = strands
        .first()
        .map(|s| s.points.len().saturating_sub(1))
        .unwrap_or(0) as u32;
    // Array bits: 1 segments, 2 points, 4 thickness, 8 transparency, 16 colour. The look's
    // arrays go in only when they cover every point (a caller's mismatch keeps the defaults).
    let per_point = look.widths_m.len() == point_count && look.colors.len() == point_count;
    let arrays: u32 = if uniform { 2 } else { 1 | 2 } | if per_point { 4 | 16 } else { 0 };
    let mut out = Vec::with_capacity(128 + point_count * if per_point { 28 } else { 12 });
    out.extend_from_slice(b"HAIR");
    out.extend_from_slice(&(strands.len() as u32).to_le_bytes());
    out.extend_from_slice(&(point_count as u32).to_le_bytes());
    out.extend_from_slice(&arrays.to_le_bytes());
    out.extend_from_slice(&default_segments.to_le_bytes());
    out.extend_from_slice(&look.root_width_m.to_le_bytes());
    out.extend_from_slice(&0.0f32.to_le_bytes()); // default transparency
    for c in look.colors.first().copied().unwrap_or([0.35, 0.22, 0.12]) {
        out.extend_from_slice(&c.to_le_bytes());
    }
    let mut info = [0u8; 88];
    let text = b"Hairloom strands (metres, y up)";
    info[..text.len()].copy_from_slice(text);
    out.extend_from_slice(&info);
    if !uniform {
        for strand in strands {
            out.extend_from_slice(&(strand.points.len().saturating_sub(1) as u16).to_le_bytes());
        }
    }
    for strand in strands {
        for p in &strand.points {
            for c in p.as_vec3().to_array() {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    if per_point {
        for w in &look.widths_m {
            out.extend_from_slice(&w.to_le_bytes());
        }
        for c in look.colors.iter().flatten() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    out
}

/// The scalp the strands grow from, as a polygon mesh: one face per root face of the hair
/// mesh (removed bundles included: they are still scalp), the columns' root positions, and
/// each face corner's styling uv, the uv space the strands' root uv lives in, so a tool can
/// re-attach the curves to the surface.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalpMesh {
    pub positions: Vec<[f32; 3]>,
    /// Corners per face: 3 or 4.
    pub face_vertex_counts: Vec<u32>,
    /// Into `positions`, counter-clockwise seen from outside.
    pub face_vertex_indices: Vec<u32>,
    /// One per entry of `face_vertex_indices` (face-varying: a uv seam splits a vertex).
    pub face_uvs: Vec<[f32; 2]>,
}

impl ScalpMesh {
    pub fn of(mesh: &HairMesh) -> Self {
        let positions = mesh
            .columns
            .iter()
            .map(|c| c.positions[0].as_vec3().to_array())
            .collect();
        let face_vertex_counts = mesh
            .bundles
            .iter()
            .map(|b| b.vertices.len() as u32)
            .collect();
        let face_vertex_indices = mesh
            .bundles
            .iter()
            .flat_map(|b| b.vertices.iter().copied())
            .collect();
        let face_uvs = mesh
            .bundles
            .iter()
            .flat_map(|b| b.uvs.iter().map(|uv| uv.as_vec2().to_array()))
            .collect();
        Self {
            positions,
            face_vertex_counts,
            face_vertex_indices,
            face_uvs,
        }
    }
}

/// A USD stage with the strands as one `BasisCurves` prim (`/Hair`, linear curves, metres,
/// y up, with its `extent`), each point's width (tapering) and colour (`displayColor`,
/// linear) from `look`, and the root uv as a uniform primvar under two names: `st` (USD's
/// convention) and `surface_uv_coordinate` (the attribute Blender's hair tools use to
/// attach curves to a surface); and the scalp as a `Mesh` (`/Scalp`) whose face-varying
/// `st` is the space of those root uvs.
pub fn usda_file(strands: &[Strand], scalp: &ScalpMesh, look: &StrandLook) -> String {
    let mut out = usda_header("", "Exported by Hairloom");
    let points = format!("    point3f[] points = {}\n", usda_points(strands));
    let extent = format!(
        "    float3[] extent = {}\n",
        usda_extent(strands, look.root_width_m)
    );
    usda_curves(&mut out, strands, &points, &extent, look);
    let scalp_points = format!("    point3f[] points = {}\n", usda_vec3s(&scalp.positions));
    let scalp_extent = format!("    float3[] extent = {}\n", usda_scalp_extent(scalp));
    usda_scalp(&mut out, scalp, &scalp_points, &scalp_extent);
    out
}

/// `[(x, y, z), …]`: every strand's points in order, as USD writes a `point3f[]`.
fn usda_points(strands: &[Strand]) -> String {
    let points: Vec<[f32; 3]> = strands
        .iter()
        .flat_map(|s| s.points.iter())
        .map(|p| p.as_vec3().to_array())
        .collect();
    usda_vec3s(&points)
}

fn usda_vec3s(values: &[[f32; 3]]) -> String {
    let values: Vec<String> = values
        .iter()
        .map(|[x, y, z]| format!("({x}, {y}, {z})"))
        .collect();
    format!("[{}]", values.join(", "))
}

/// `[(min), (max)]` of every point, widened by half the strand width (a Boundable's extent
/// covers what it draws).
fn usda_extent(strands: &[Strand], width_m: f32) -> String {
    let (lo, hi) = strand_bounds(strands, width_m);
    usda_vec3s(&[lo, hi])
}

/// The box around every point of `strands`, widened by half of `width_m`; zero when there
/// are no points.
pub(crate) fn strand_bounds(strands: &[Strand], width_m: f32) -> ([f32; 3], [f32; 3]) {
    let points = strands
        .iter()
        .flat_map(|s| s.points.iter())
        .map(|p| p.as_vec3());
    bounds_of(points, 0.5 * width_m)
}

/// The box around `points`, widened by `pad` on every side; zero when there are none.
fn bounds_of(mut points: impl Iterator<Item = glam::Vec3>, pad: f32) -> ([f32; 3], [f32; 3]) {
    let Some(first) = points.next() else {
        return ([0.0; 3], [0.0; 3]);
    };
    let (lo, hi) = points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let pad = glam::Vec3::splat(pad);
    ((lo - pad).to_array(), (hi + pad).to_array())
}

/// `[(min), (max)]` of the scalp's points (a mesh is Boundable too).
fn usda_scalp_extent(scalp: &ScalpMesh) -> String {
    let (lo, hi) = bounds_of(scalp.positions.iter().map(|&p| glam::Vec3::from(p)), 0.0);
    usda_vec3s(&[lo, hi])
}

fn usda_header(metadata: &str, doc: &str) -> String {
    format!(
        "#usda 1.0\n(\n    defaultPrim = \"Hair\"\n    metersPerUnit = 1\n    upAxis = \"Y\"\n{metadata}    doc = \"{doc}\"\n)\n\n"
    )
}

/// The `/Hair` prim: `points` and `extent` are its attributes (a value or time samples);
/// counts and uv come from `strands`, widths and colours from `look` (per point when it
/// covers every point, else the root width alone).
fn usda_curves(
    out: &mut String,
    strands: &[Strand],
    points: &str,
    extent: &str,
    look: &StrandLook,
) {
    use std::fmt::Write;
    let _ = writeln!(
        out,
        "def BasisCurves \"Hair\"\n{{\n    uniform token type = \"linear\"\n    uniform token wrap = \"nonperiodic\""
    );
    let counts: Vec<String> = strands.iter().map(|s| s.points.len().to_string()).collect();
    let _ = writeln!(out, "    int[] curveVertexCounts = [{}]", counts.join(", "));
    out.push_str(points);
    out.push_str(extent);
    let point_count: usize = strands.iter().map(|s| s.points.len()).sum();
    if look.widths_m.len() == point_count && look.colors.len() == point_count {
        out.push_str("    float[] widths = [");
        for (i, width) in look.widths_m.iter().enumerate() {
            let _ = write!(out, "{}{width}", if i == 0 { "" } else { ", " });
        }
        out.push_str("] (\n        interpolation = \"vertex\"\n    )\n");
        let _ = writeln!(
            out,
            "    color3f[] primvars:displayColor = {} (\n        interpolation = \"vertex\"\n    )",
            usda_vec3s(&look.colors)
        );
    } else {
        let _ = writeln!(
            out,
            "    float[] widths = [{}] (\n        interpolation = \"constant\"\n    )",
            look.root_width_m
        );
    }
    let uvs: Vec<String> = strands
        .iter()
        .map(|s| format!("({}, {})", s.root_uv.x as f32, s.root_uv.y as f32))
        .collect();
    let uvs = uvs.join(", ");
    for (kind, name) in [("texCoord2f", "st"), ("float2", "surface_uv_coordinate")] {
        let _ = writeln!(
            out,
            "    {kind}[] primvars:{name} = [{uvs}] (\n        interpolation = \"uniform\"\n    )"
        );
    }
    let _ = writeln!(out, "}}\n");
}

/// The `/Scalp` prim: `points` and `extent` are its attributes (values or time samples).
fn usda_scalp(out: &mut String, scalp: &ScalpMesh, points: &str, extent: &str) {
    use std::fmt::Write;
    let join = |values: &[u32]| {
        values
            .iter()
            .map(u32::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let _ = writeln!(out, "def Mesh \"Scalp\"\n{{");
    let _ = writeln!(
        out,
        "    int[] faceVertexCounts = [{}]",
        join(&scalp.face_vertex_counts)
    );
    let _ = writeln!(
        out,
        "    int[] faceVertexIndices = [{}]",
        join(&scalp.face_vertex_indices)
    );
    out.push_str(points);
    out.push_str(extent);
    let uvs: Vec<String> = scalp
        .face_uvs
        .iter()
        .map(|[u, v]| format!("({u}, {v})"))
        .collect();
    let _ = writeln!(
        out,
        "    texCoord2f[] primvars:st = [{}] (\n        interpolation = \"faceVarying\"\n    )",
        uvs.join(", ")
    );
    let _ = writeln!(out, "    uniform token subdivisionScheme = \"none\"\n}}");
}

/// The first of an animation's `frames`, once they and their rate are checked: an empty
/// list and a rate that is not a positive number are refused (every animated export).
pub(crate) fn first_frame<T>(frames: &[T], frames_per_second: f64) -> Result<&T, String> {
    let Some(first) = frames.first() else {
        return Err("an animation needs at least one frame".into());
    };
    if !(frames_per_second.is_finite() && frames_per_second > 0.0) {
        return Err(format!(
            "{frames_per_second} frames per second is not a rate"
        ));
    }
    Ok(first)
}

/// One frame of an animated export: the strands and the scalp they grow from.
pub struct UsdFrame {
    pub strands: Vec<Strand>,
    pub scalp: ScalpMesh,
}

/// An animated USD stage: the same prims as [`usda_file`], the points and extent of the
/// curves and the scalp's points sampled at each frame (time codes = frame numbers at
/// `frames_per_second`). Every frame must hold the same curves (counts) and scalp faces as
/// the first; an empty list is refused.
pub fn usda_animation(
    frames: &[UsdFrame],
    look: &StrandLook,
    frames_per_second: f64,
) -> Result<String, String> {
    use std::fmt::Write;
    let first = first_frame(frames, frames_per_second)?;
    for (i, frame) in frames.iter().enumerate() {
        if frame.strands.len() != first.strands.len()
            || frame
                .strands
                .iter()
                .zip(&first.strands)
                .any(|(s, f)| s.points.len() != f.points.len())
        {
            return Err(format!("frame {i} has other curves than frame 0"));
        }
        if frame.scalp.face_vertex_indices != first.scalp.face_vertex_indices
            || frame.scalp.positions.len() != first.scalp.positions.len()
        {
            return Err(format!("frame {i} has another scalp than frame 0"));
        }
    }
    let metadata = format!(
        "    startTimeCode = 0\n    endTimeCode = {}\n    timeCodesPerSecond = {frames_per_second}\n    framesPerSecond = {frames_per_second}\n",
        frames.len() - 1
    );
    let sampled = |name: &str, value: &dyn Fn(&UsdFrame) -> String| {
        let mut text = format!("    {name}.timeSamples = {{\n");
        for (i, frame) in frames.iter().enumerate() {
            let _ = writeln!(text, "        {i}: {},", value(frame));
        }
        text.push_str("    }\n");
        text
    };
    let mut out = usda_header(&metadata, "Simulated by Hairloom");
    let points = sampled("point3f[] points", &|f| usda_points(&f.strands));
    let extent = sampled("float3[] extent", &|f| {
        usda_extent(&f.strands, look.root_width_m)
    });
    usda_curves(&mut out, &first.strands, &points, &extent, look);
    let scalp_points = sampled("point3f[] points", &|f| usda_vec3s(&f.scalp.positions));
    let scalp_extent = sampled("float3[] extent", &|f| usda_scalp_extent(&f.scalp));
    usda_scalp(&mut out, &first.scalp, &scalp_points, &scalp_extent);
    Ok(out)
}

/// Binary glTF with one mesh of LINES (glTF has no curve primitive): every strand segment
/// is a line between two shared vertices.
pub fn glb_lines(strands: &[Strand]) -> Vec<u8> {
    let mut positions = Vec::new();
    let mut indices: Vec<u32> = Vec::new();
    for strand in strands {
        let base = positions.len() as u32;
        for (k, p) in strand.points.iter().enumerate() {
            positions.push(p.as_vec3().to_array());
            if k > 0 {
                indices.push(base + k as u32 - 1);
                indices.push(base + k as u32);
            }
        }
    }
    glb_mesh("Hair", &positions, &indices, GLTF_MODE_LINES)
}

const GLTF_MODE_LINES: u32 = 1;
const GLTF_MODE_TRIANGLES: u32 = 4;

/// The opaque body (scalp/head) as a triangle GLB: what the runtime bundle carries so a
/// preview of the bundle alone can depth-test hair against the same mesh.
pub(crate) fn glb_body(body: &crate::model::document::BodyMesh) -> Vec<u8> {
    let indices: Vec<u32> = body.triangles.iter().flatten().copied().collect();
    glb_mesh("Body", &body.positions, &indices, GLTF_MODE_TRIANGLES)
}

/// One indexed mesh of `mode` (glTF primitive mode) in a GLB.
fn glb_mesh(name: &str, positions: &[[f32; 3]], indices: &[u32], mode: u32) -> Vec<u8> {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let mut bin = Vec::with_capacity(positions.len() * 12 + indices.len() * 4);
    for p in positions {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
            bin.extend_from_slice(&p[c].to_le_bytes());
        }
    }
    if positions.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    let index_offset = bin.len();
    for i in indices {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let json = serde_json::json!({
        "asset": {"version": "2.0", "generator": format!("hairloom {}", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": name}],
        "meshes": [{"name": name, "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": mode}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": positions.len(), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": indices.len(), "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": index_offset, "target": 34962},
            {"buffer": 0, "byteOffset": index_offset, "byteLength": indices.len() * 4, "target": 34963}
        ],
        "buffers": [{"byteLength": bin.len()}]
    });
    glb_container(&json, bin)
}

/// A GLB file: 12-byte header, the JSON chunk (space-padded) and the BIN chunk
/// (zero-padded), both 4-byte aligned as the glTF 2.0 binary format requires.
pub fn glb_container(json: &serde_json::Value, mut bin: Vec<u8>) -> Vec<u8> {
    let mut json_bytes = serde_json::to_vec(json).unwrap_or_default();
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Document;
    use crate::model::mesh::test_meshes::grid;
    use crate::strands::reference::{StrandOptions, generate};

    #[test]
    fn strand_files_have_consistent_counts() {
        let document = Document::new("grid", grid(2, 2, 2, 0.5));
        let strands = generate(
            &document,
            &StrandOptions {
                strands_per_bundle: 5,
                vertices_log2: 3,
                ..StrandOptions::default()
            },
        );
        let look = StrandLook::new(
            &strands,
            1e-4,
            &document.scene.material,
            &document.root_maps,
        );
        let hair = hair_file(&strands, &look);
        let u32_at = |at: usize| u32::from_le_bytes(hair[at..at + 4].try_into().expect("4"));
        let f32_at = |at: usize| f32::from_le_bytes(hair[at..at + 4].try_into().expect("4"));
        assert_eq!(&hair[..4], b"HAIR");
        assert_eq!(u32_at(4), 20);
        // Points, thickness and colour arrays (no segments: every strand has 9 points).
        assert_eq!(u32_at(12), 2 | 4 | 16);
        assert_eq!(hair.len(), 128 + 20 * 9 * (12 + 4 + 12));
        // The first strand's thickness tapers from the root width to 40 % at its tip.
        let thickness = 128 + 20 * 9 * 12;
        assert_eq!(f32_at(thickness), 1e-4);
        assert!((f32_at(thickness + 8 * 4) - 0.4e-4).abs() < 1e-9);
        let colors = thickness + 20 * 9 * 4;
        let root = [0, 1, 2].map(|c| f32_at(colors + 4 * c));
        assert!(root.iter().all(|c| c.is_finite() && *c > 0.0 && *c < 1.0));
        // Brown hair: more red than blue.
        assert!(root[0] > root[2], "{root:?}");
        let usda = usda_file(&strands, &ScalpMesh::of(&document.hair_mesh), &look);
        assert!(usda.starts_with("#usda 1.0") && usda.matches("(").count() > 180);
        assert!(usda.contains("primvars:displayColor") && usda.contains("\"vertex\""));
        let glb = glb_lines(&strands);
        let gltf = gltf::Gltf::from_slice(&glb).expect("valid glb");
        let primitive = gltf
            .meshes()
            .next()
            .and_then(|m| m.primitives().next())
            .expect("primitive");
        assert_eq!(primitive.mode(), gltf::mesh::Mode::Lines);
        assert_eq!(primitive.indices().map(|a| a.count()), Some(20 * 8 * 2));
    }

    /// Issue 37: where every bundle is thinned (a hairline everywhere), the export's colours
    /// used to guess the strands per bundle from the strands (half the real count here) and
    /// hashed each strand's variation from the wrong root. Now each strand carries the
    /// renderers' root number.
    #[test]
    fn thinned_bundles_keep_the_renderers_root_numbers() {
        let mut document = Document::new("grid", grid(3, 2, 2, 0.5));
        for bundle in &mut document.hair_mesh.bundles {
            bundle.density = 0.5;
        }
        // A bald bundle first: the renderers number roots by atlas block, which skips it.
        document.hair_mesh.bundles[0].layers = 0;
        let per_bundle = 6u32;
        let strands = generate(
            &document,
            &StrandOptions {
                strands_per_bundle: per_bundle,
                vertices_log2: 2,
                ..StrandOptions::default()
            },
        );
        let bundles = document.hair_mesh.bundles.len();
        assert_eq!(
            strands.len(),
            (bundles - 1) * 3,
            "each bundle but the bald one grows half its strands"
        );
        // Bundle b's k-th strand is root (b − 1) · 6 + k, as the GPU numbers it.
        let expected: Vec<u32> = strands
            .chunk_by(|a, b| a.bundle == b.bundle)
            .flat_map(|run| {
                (0..run.len() as u32).map(move |k| (run[0].bundle - 1) * per_bundle + k)
            })
            .collect();
        assert_eq!(root_indices(&strands), expected);
        let material = &document.scene.material;
        let look = StrandLook::new(&strands, 1e-4, material, &Default::default());
        assert_eq!(
            look.colors,
            crate::light::material::strand_point_colors(
                material,
                &Default::default(),
                &strands,
                &expected
            )
        );
        // The old guess (3 per bundle, numbered by bundle) gives other colours: the test can
        // tell them apart.
        let guessed: Vec<u32> = expected
            .iter()
            .map(|&root| (root / per_bundle + 1) * 3 + root % per_bundle)
            .collect();
        assert_ne!(
            look.colors,
            crate::light::material::strand_point_colors(
                material,
                &Default::default(),
                &strands,
                &guessed
            )
        );
        // The runtime mirror numbers its strands the same way.
        let runtime = crate::runtime::hair::RuntimeHair::from_document(
            &document,
            &crate::runtime::hair::RuntimeOptions {
                strands_per_bundle: per_bundle,
                ..Default::default()
            },
        );
        let mirrored = crate::runtime::strand_gen::runtime_strands(
            &runtime,
            5,
            crate::runtime::strand_gen::Filtering::Exact,
        );
        let mut mirrored_roots = root_indices(&mirrored);
        mirrored_roots.sort_unstable();
        let mut sorted = expected.clone();
        sorted.sort_unstable();
        assert_eq!(mirrored_roots, sorted);
    }
}
