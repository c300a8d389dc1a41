//! Strands for other tools: Cem Yuksel's `.hair`, USD `.usda` BasisCurves, binary glTF with
//! LINES, and the body as a triangle GLB. Every function builds bytes in memory; writing
//! them is the caller's job (atomically, see [`crate::io::project::write_atomic`]).

use crate::strands::reference::Strand;

/// Cem Yuksel's `.hair` format (cyHair): a 128-byte header then the point array (and a
/// segments array when strands differ in vertex count). Thickness and colour are defaults
/// in the header.
pub fn hair_file(strands: &[Strand], thickness_m: f32, color: [f32; 3]) -> Vec<u8> {
    let point_count: usize = strands.iter().map(|s| s.points.len()).sum();
    let uniform = strands
        .windows(2)
        .all(|w| w[0].points.len() == w[1].points.len());
    let default_segments = strands
        .first()
        .map(|s| s.points.len().saturating_sub(1))
        .unwrap_or(0) as u32;
    // Array bits: 1 segments, 2 points, 4 thickness, 8 transparency, 16 colour.
    let arrays: u32 = if uniform { 2 } else { 1 | 2 };
    let mut out = Vec::with_capacity(128 + point_count * 12);
    out.extend_from_slice(b"HAIR");
    out.extend_from_slice(&(strands.len() as u32).to_le_bytes());
    out.extend_from_slice(&(point_count as u32).to_le_bytes());
    out.extend_from_slice(&arrays.to_le_bytes());
    out.extend_from_slice(&default_segments.to_le_bytes());
    out.extend_from_slice(&thickness_m.to_le_bytes());
    out.extend_from_slice(&0.0f32.to_le_bytes()); // default transparency
    for c in color {
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
    out
}

/// A USD stage with one `BasisCurves` prim (`/Hair`, linear curves, metres, y up), constant
/// width and the root uv as a uniform `primvars:st`.
pub fn usda_file(strands: &[Strand], width_m: f32) -> String {
    let points = format!("    point3f[] points = {}\n", usda_points(strands));
    usda_stage("", "Exported by Hairloom", strands, &points, width_m)
}

/// `[(x, y, z), …]`: every strand's points in order, as USD writes a `point3f[]`.
fn usda_points(strands: &[Strand]) -> String {
    let points: Vec<String> = strands
        .iter()
        .flat_map(|s| s.points.iter())
        .map(|p| format!("({}, {}, {})", p.x as f32, p.y as f32, p.z as f32))
        .collect();
    format!("[{}]", points.join(", "))
}

/// The stage around the `/Hair` prim: `metadata` lines join the stage's, `points` is the
/// prim's points attribute (a value or time samples); counts and uv come from `strands`.
fn usda_stage(metadata: &str, doc: &str, strands: &[Strand], points: &str, width_m: f32) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "#usda 1.0\n(\n    defaultPrim = \"Hair\"\n    metersPerUnit = 1\n    upAxis = \"Y\"\n{metadata}    doc = \"{doc}\"\n)\n"
    );
    let _ = writeln!(
        out,
        "def BasisCurves \"Hair\"\n{{\n    uniform token type = \"linear\"\n    uniform token wrap = \"nonperiodic\""
    );
    let counts: Vec<String> = strands.iter().map(|s| s.points.len().to_string()).collect();
    let _ = writeln!(out, "    int[] curveVertexCounts = [{}]", counts.join(", "));
    out.push_str(points);
    let _ = writeln!(
        out,
        "    float[] widths = [{width_m}] (\n        interpolation = \"constant\"\n    )"
    );
    let uvs: Vec<String> = strands
        .iter()
        .map(|s| format!("({}, {})", s.root_uv.x as f32, s.root_uv.y as f32))
        .collect();
    let _ = writeln!(
        out,
        "    texCoord2f[] primvars:st = [{}] (\n        interpolation = \"uniform\"\n    )",
        uvs.join(", ")
    );
    let _ = writeln!(out, "}}");
    out
}

/// An animated USD stage: the same `BasisCurves` prim as [`usda_file`], its points sampled at
/// each frame (`points.timeSamples`, time codes = frame numbers at `frames_per_second`).
/// Every frame must hold the same curves (counts) as the first; an empty list is refused.
pub fn usda_animation(
    frames: &[Vec<Strand>],
    width_m: f32,
    frames_per_second: f64,
) -> Result<String, String> {
    use std::fmt::Write;
    let Some(first) = frames.first() else {
        return Err("an animation needs at least one frame".into());
    };
    if !(frames_per_second.is_finite() && frames_per_second > 0.0) {
        return Err(format!(
            "{frames_per_second} frames per second is not a rate"
        ));
    }
    for (i, frame) in frames.iter().enumerate() {
        if frame.len() != first.len()
            || frame
                .iter()
                .zip(first)
                .any(|(s, f)| s.points.len() != f.points.len())
        {
            return Err(format!("frame {i} has other curves than frame 0"));
        }
    }
    let metadata = format!(
        "    startTimeCode = 0\n    endTimeCode = {}\n    timeCodesPerSecond = {frames_per_second}\n    framesPerSecond = {frames_per_second}\n",
        frames.len() - 1
    );
    let mut points = String::from("    point3f[] points.timeSamples = {\n");
    for (i, frame) in frames.iter().enumerate() {
        let _ = writeln!(points, "        {i}: {},", usda_points(frame));
    }
    points.push_str("    }\n");
    Ok(usda_stage(
        &metadata,
        "Simulated by Hairloom",
        first,
        &points,
        width_m,
    ))
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
pub fn glb_body(body: &crate::model::document::BodyMesh) -> Vec<u8> {
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
        let hair = hair_file(&strands, 1e-4, [0.3, 0.2, 0.1]);
        assert_eq!(&hair[..4], b"HAIR");
        assert_eq!(u32::from_le_bytes([hair[4], hair[5], hair[6], hair[7]]), 20);
        assert_eq!(hair.len(), 128 + 20 * 9 * 12);
        let usda = usda_file(&strands, 1e-4);
        assert!(usda.starts_with("#usda 1.0") && usda.matches("(").count() > 180);
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
}
