//! Exports: the runtime bundle a game loads (`manifest.json` + five KTX2 textures, see
//! `docs/runtime-format.md`) and strands for other tools (Cem Yuksel's `.hair`, USD
//! `.usda` BasisCurves, binary glTF with LINES).
//!
//! Every function here builds bytes in memory; writing them to disk is the caller's job
//! (the CLI writes each file atomically).

use glam::Vec4;
use serde::{Deserialize, Serialize};

use crate::document::Document;
use crate::runtime::{Precision, RootSamples, RuntimeTextures, SLICES_PER_SEGMENT, Texture3d};
use crate::strands::{Strand, sample_set_size};
use crate::styling::StylingSet;

/// Version of the runtime bundle format described in `docs/runtime-format.md`.
pub const RUNTIME_FORMAT_VERSION: u32 = 1;

/// Why an export failed.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("the document has no bundle that grows hair (every bundle is removed or has 0 layers)")]
    NothingToExport,
    #[error("KTX2 data format descriptor for {format}: {message}")]
    Ktx2 {
        format: &'static str,
        message: String,
    },
    #[error("a texture of {0} bytes is too large for a KTX2 level")]
    TooLarge(usize),
}

/// Texel formats the runtime bundle uses, with their Vulkan names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexelFormat {
    Rgba32Float,
    Rg32Float,
    R32Float,
    Rgba16Float,
    Rg16Float,
    R16Float,
}

impl TexelFormat {
    pub fn vk_name(self) -> &'static str {
        match self {
            Self::Rgba32Float => "R32G32B32A32_SFLOAT",
            Self::Rg32Float => "R32G32_SFLOAT",
            Self::R32Float => "R32_SFLOAT",
            Self::Rgba16Float => "R16G16B16A16_SFLOAT",
            Self::Rg16Float => "R16G16_SFLOAT",
            Self::R16Float => "R16_SFLOAT",
        }
    }

    fn ktx2(self) -> ktx2::Format {
        match self {
            Self::Rgba32Float => ktx2::Format::R32G32B32A32_SFLOAT,
            Self::Rg32Float => ktx2::Format::R32G32_SFLOAT,
            Self::R32Float => ktx2::Format::R32_SFLOAT,
            Self::Rgba16Float => ktx2::Format::R16G16B16A16_SFLOAT,
            Self::Rg16Float => ktx2::Format::R16G16_SFLOAT,
            Self::R16Float => ktx2::Format::R16_SFLOAT,
        }
    }

    pub fn channels(self) -> usize {
        match self {
            Self::Rgba32Float | Self::Rgba16Float => 4,
            Self::Rg32Float | Self::Rg16Float => 2,
            Self::R32Float | Self::R16Float => 1,
        }
    }

    pub fn bytes_per_channel(self) -> usize {
        match self {
            Self::Rgba32Float | Self::Rg32Float | Self::R32Float => 4,
            _ => 2,
        }
    }

    /// Format of a runtime texture with `channels` channels at `precision`. The uv-texture
    /// (the only two-channel one) stays f32 at every precision: the root uv seeds every
    /// per-strand random value, and f16 would quantise it to 1/2048 — whole rows of
    /// neighbouring strands would share their curl phase and clump. It is one 2D slice, so
    /// this costs 4 bytes per atlas texel.
    pub fn for_precision(precision: Precision, channels: usize) -> Self {
        match (precision, channels) {
            (_, 2) => Self::Rg32Float,
            (Precision::F32, 4) => Self::Rgba32Float,
            (Precision::F32, _) => Self::R32Float,
            (Precision::F16, 4) => Self::Rgba16Float,
            (Precision::F16, _) => Self::R16Float,
        }
    }
}

/// IEEE binary16 bits of `value` (rounded to nearest even, overflow clamped to ±65504).
pub fn f16_bits(value: f32) -> u16 {
    let value = crate::runtime::round_to_f16(value);
    let sign = if value.is_sign_negative() {
        0x8000u16
    } else {
        0
    };
    let magnitude = value.abs();
    if magnitude == 0.0 {
        return sign;
    }
    if magnitude < 2f32.powi(-14) {
        // Subnormal: magnitude = m · 2^-24.
        return sign | (magnitude / 2f32.powi(-24)).round() as u16;
    }
    let exponent = magnitude.log2().floor() as i32;
    // `log2` can be off by one right at powers of two; fix it up.
    let exponent = if magnitude < 2f32.powi(exponent) {
        exponent - 1
    } else {
        exponent
    };
    let exponent = if magnitude >= 2f32.powi(exponent + 1) {
        exponent + 1
    } else {
        exponent
    };
    let mantissa = ((magnitude / 2f32.powi(exponent) - 1.0) * 1024.0).round() as u16;
    sign | (((exponent + 15) as u16) << 10) | (mantissa & 0x3FF)
}

/// Texel bytes of `texels` in `format` (the first `format.channels()` components of each).
pub fn texel_bytes(texels: &[Vec4], format: TexelFormat) -> Vec<u8> {
    let channels = format.channels();
    let mut out = Vec::with_capacity(texels.len() * channels * format.bytes_per_channel());
    for texel in texels {
        for c in 0..channels {
            if format.bytes_per_channel() == 4 {
                out.extend_from_slice(&texel[c].to_le_bytes());
            } else {
                out.extend_from_slice(&f16_bits(texel[c]).to_le_bytes());
            }
        }
    }
    out
}

/// A single-level, uncompressed KTX2 file (2D when `depth == 0`, else 3D).
pub fn ktx2_bytes(
    format: TexelFormat,
    width: u32,
    height: u32,
    depth: u32,
    data: &[u8],
) -> Result<Vec<u8>, ExportError> {
    let (basic, type_size) =
        ktx2::dfd::Basic::from_format(format.ktx2()).map_err(|e| ExportError::Ktx2 {
            format: format.vk_name(),
            message: format!("{e:?}"),
        })?;
    let block = ktx2::dfd::Block::Basic(basic).to_vec();
    let dfd_total = 4 + block.len();
    let level_index_offset = ktx2::Header::LENGTH;
    let dfd_offset = level_index_offset + ktx2::LevelIndex::LENGTH;
    let kvd_offset = dfd_offset + dfd_total;
    let mut kvd = Vec::new();
    let writer = format!("KTXwriter\0hairloom {}\0", env!("CARGO_PKG_VERSION"));
    kvd.extend_from_slice(&(writer.len() as u32).to_le_bytes());
    kvd.extend_from_slice(writer.as_bytes());
    while !kvd.len().is_multiple_of(4) {
        kvd.push(0);
    }
    // Level data aligned to lcm(texel size, 4).
    let texel_size = format.channels() * format.bytes_per_channel();
    let alignment = if texel_size.is_multiple_of(4) {
        texel_size
    } else {
        texel_size * 4 / gcd(texel_size, 4)
    };
    let mut level_offset = kvd_offset + kvd.len();
    level_offset = level_offset.div_ceil(alignment) * alignment;
    let to_u32 = |v: usize| u32::try_from(v).map_err(|_| ExportError::TooLarge(v));
    let header = ktx2::Header {
        format: Some(format.ktx2()),
        type_size,
        pixel_width: width,
        pixel_height: height,
        pixel_depth: depth,
        layer_count: 0,
        face_count: 1,
        level_count: 1,
        supercompression_scheme: None,
        index: ktx2::Index {
            dfd_byte_offset: to_u32(dfd_offset)?,
            dfd_byte_length: to_u32(dfd_total)?,
            kvd_byte_offset: to_u32(kvd_offset)?,
            kvd_byte_length: to_u32(kvd.len())?,
            sgd_byte_offset: 0,
            sgd_byte_length: 0,
        },
    };
    let level = ktx2::LevelIndex {
        byte_offset: level_offset as u64,
        byte_length: data.len() as u64,
        uncompressed_byte_length: data.len() as u64,
    };
    let mut out = Vec::with_capacity(level_offset + data.len());
    out.extend_from_slice(&header.as_bytes());
    out.extend_from_slice(&level.as_bytes());
    out.extend_from_slice(&to_u32(dfd_total)?.to_le_bytes());
    out.extend_from_slice(&block);
    out.extend_from_slice(&kvd);
    out.resize(level_offset, 0);
    out.extend_from_slice(data);
    Ok(out)
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// One texture of the runtime bundle, as the manifest describes it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TextureEntry {
    pub file: String,
    pub vk_format: String,
    /// `[width, height, depth]`; depth 0 for the 2D uv-texture.
    pub size: [u32; 3],
    pub contents: String,
}

/// Placement of one bundle on the root slice.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BundleEntry {
    pub bundle: u32,
    pub origin: [u32; 2],
    pub corner_of_block: [u8; 4],
    pub layers: u32,
    pub triangle: bool,
    /// Index into `styling.groups`, or −1 for the global parameters.
    pub styling_group: i32,
}

/// Level-of-detail parameters (seed 000 eq. 7-12).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LodEntry {
    pub alpha_strands: f64,
    pub alpha_vertices: f64,
    pub lambda: f64,
    /// Full-detail strands have `2^max_vertices_log2 + 1` vertices.
    pub max_vertices_log2: u32,
}

/// `manifest.json` of a runtime bundle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub format: String,
    pub format_version: u32,
    pub generator: String,
    pub source: String,
    pub precision: Precision,
    /// Added to every position sampled from the hair-mesh texture.
    pub position_offset: [f32; 3],
    pub slices_per_segment: u32,
    pub max_layers: u32,
    pub hair_mesh: TextureEntry,
    pub uv: TextureEntry,
    pub w: TextureEntry,
    pub u: TextureEntry,
    pub v: TextureEntry,
    pub bundles: Vec<BundleEntry>,
    pub strands_per_bundle: u32,
    pub lod: LodEntry,
    pub styling: StylingSet,
    /// The opaque body mesh (GLB, triangles) hair is depth-tested against, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<String>,
    /// Progressive root samples in `[0,1)²` for quads (block coordinates).
    pub quad_samples: Vec<[f32; 2]>,
    /// Progressive root samples, barycentric `(s, t)` with `s + t < 1`, for triangles;
    /// block coordinates are `(s / (1 − t), t)`.
    pub triangle_samples: Vec<[f32; 2]>,
}

/// File name of the body mesh in a runtime bundle.
pub const BODY_FILE: &str = "body.glb";

/// Settings of a runtime export.
#[derive(Clone, Debug)]
pub struct RuntimeExportOptions {
    pub precision: Precision,
    pub strands_per_bundle: u32,
    pub lod: LodEntry,
    pub sample_seed: u64,
}

impl Default for RuntimeExportOptions {
    fn default() -> Self {
        Self {
            precision: Precision::F32,
            strands_per_bundle: 64,
            lod: LodEntry {
                alpha_strands: crate::lod::DEFAULT_ALPHA_STRANDS,
                alpha_vertices: crate::lod::DEFAULT_ALPHA_VERTICES,
                lambda: crate::lod::DEFAULT_LAMBDA,
                max_vertices_log2: 5,
            },
            sample_seed: 1,
        }
    }
}

/// The files of a runtime bundle: `(file name, bytes)`, manifest last.
pub fn runtime_bundle(
    document: &Document,
    options: &RuntimeExportOptions,
) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    let textures = RuntimeTextures::build(&document.hair_mesh, options.precision);
    if textures.atlas.blocks.is_empty() {
        return Err(ExportError::NothingToExport);
    }
    let mut files = Vec::new();
    let mut entry = |name: &str,
                     texture: &Texture3d,
                     channels: usize,
                     is_2d: bool,
                     contents: &str|
     -> Result<TextureEntry, ExportError> {
        let format = TexelFormat::for_precision(options.precision, channels);
        let depth = if is_2d { 0 } else { texture.depth };
        let bytes = ktx2_bytes(
            format,
            texture.width,
            texture.height,
            depth,
            &texel_bytes(&texture.texels, format),
        )?;
        let file = format!("{name}.ktx2");
        files.push((file.clone(), bytes));
        Ok(TextureEntry {
            file,
            vk_format: format.vk_name().to_string(),
            size: [texture.width, texture.height, depth],
            contents: contents.to_string(),
        })
    };
    let hair_mesh = entry(
        "hair_mesh",
        &textures.hair_mesh,
        4,
        false,
        "object-space positions minus position_offset (xyz); slice 4k is layer k, slices 4k+1..4k+3 are q0, m, q1 of segment k",
    )?;
    let uv = entry("uv", &textures.uv, 2, true, "root uv (xy)")?;
    let w = entry(
        "w",
        &textures.w,
        1,
        false,
        "styling coordinate w per layer slice",
    )?;
    let u = entry(
        "u",
        &textures.u,
        4,
        false,
        "unit styling direction u per layer slice (xyz)",
    )?;
    let v = entry(
        "v",
        &textures.v,
        4,
        false,
        "unit styling direction v per layer slice (xyz)",
    )?;
    let set = sample_set_size(options.strands_per_bundle);
    let samples = RootSamples::progressive(set, options.sample_seed);
    let group_of =
        |bundle: u32| -> i32 { document.styling.group_of(bundle).map_or(-1, |i| i as i32) };
    let manifest = Manifest {
        format: "hairloom-runtime".into(),
        format_version: RUNTIME_FORMAT_VERSION,
        generator: format!("hairloom {}", env!("CARGO_PKG_VERSION")),
        source: document.source.clone(),
        precision: options.precision,
        position_offset: textures.position_offset.to_array(),
        slices_per_segment: SLICES_PER_SEGMENT,
        max_layers: textures.w.depth - 1,
        hair_mesh,
        uv,
        w,
        u,
        v,
        bundles: textures
            .atlas
            .blocks
            .iter()
            .map(|b| BundleEntry {
                bundle: b.bundle,
                origin: b.origin,
                corner_of_block: b.corner_of_block,
                layers: b.layers,
                triangle: document.hair_mesh.bundles[b.bundle as usize].vertices.len() == 3,
                styling_group: group_of(b.bundle),
            })
            .collect(),
        strands_per_bundle: options.strands_per_bundle,
        lod: options.lod.clone(),
        styling: document.styling.clone(),
        body: (!document.body.triangles.is_empty()).then(|| BODY_FILE.to_string()),
        quad_samples: samples.quad,
        triangle_samples: samples.triangle,
    };
    if manifest.body.is_some() {
        files.push((BODY_FILE.into(), glb_body(&document.body)));
    }
    let json = serde_json::to_vec_pretty(&manifest).unwrap_or_default();
    files.push(("manifest.json".into(), json));
    Ok(files)
}

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
    use std::fmt::Write;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "#usda 1.0\n(\n    defaultPrim = \"Hair\"\n    metersPerUnit = 1\n    upAxis = \"Y\"\n    doc = \"Exported by Hairloom\"\n)\n"
    );
    let _ = writeln!(
        out,
        "def BasisCurves \"Hair\"\n{{\n    uniform token type = \"linear\"\n    uniform token wrap = \"nonperiodic\""
    );
    let counts: Vec<String> = strands.iter().map(|s| s.points.len().to_string()).collect();
    let _ = writeln!(out, "    int[] curveVertexCounts = [{}]", counts.join(", "));
    let points: Vec<String> = strands
        .iter()
        .flat_map(|s| s.points.iter())
        .map(|p| format!("({}, {}, {})", p.x as f32, p.y as f32, p.z as f32))
        .collect();
    let _ = writeln!(out, "    point3f[] points = [{}]", points.join(", "));
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
pub fn glb_body(body: &crate::document::BodyMesh) -> Vec<u8> {
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

/// Why a runtime bundle could not be loaded; names the file and what is wrong.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct BundleError {
    pub file: String,
    pub message: String,
}

/// A runtime bundle read back from disk: the manifest and the textures, ready for the
/// texture-path mirror or a GPU upload.
pub struct LoadedBundle {
    pub manifest: Manifest,
    pub textures: RuntimeTextures,
    /// The body mesh the manifest names (empty when it names none).
    pub body: crate::document::BodyMesh,
}

impl LoadedBundle {
    /// The manifest's root samples.
    pub fn root_samples(&self) -> RootSamples {
        RootSamples {
            quad: self.manifest.quad_samples.clone(),
            triangle: self.manifest.triangle_samples.clone(),
        }
    }

    /// Each bundle's index into the styling array (0 = global, `g + 1` = group `g`), in
    /// block order: with [`Self::root_samples`], what a game uploads to generate strands.
    pub fn block_styling(&self) -> Vec<u32> {
        self.manifest
            .bundles
            .iter()
            .map(|b| (b.styling_group + 1) as u32)
            .collect()
    }
}

/// Half-precision bits to f32.
pub fn f16_to_f32(bits: u16) -> f32 {
    let sign = if bits & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = ((bits >> 10) & 0x1F) as i32;
    let mantissa = (bits & 0x3FF) as f32;
    match exponent {
        0 => sign * mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        e => sign * (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}

/// Loads and checks a runtime bundle folder written by [`runtime_bundle`]: the manifest's
/// version and formats, every KTX2 header against the manifest, sizes, block placements and
/// layer counts, and finite texel values.
pub fn load_runtime_bundle(dir: &std::path::Path) -> Result<LoadedBundle, BundleError> {
    let error = |file: &str, message: String| BundleError {
        file: dir.join(file).display().to_string(),
        message,
    };
    let manifest_bytes = std::fs::read(dir.join("manifest.json"))
        .map_err(|e| error("manifest.json", format!("cannot read: {e}")))?;
    let version: serde_json::Value = serde_json::from_slice(&manifest_bytes)
        .map_err(|e| error("manifest.json", format!("not JSON: {e}")))?;
    let found = version
        .get("format_version")
        .and_then(|v| v.as_u64())
        .unwrap_or(0);
    if version.get("format").and_then(|v| v.as_str()) != Some("hairloom-runtime") {
        return Err(error(
            "manifest.json",
            "not a Hairloom runtime manifest (\"format\" is not \"hairloom-runtime\")".into(),
        ));
    }
    if found != RUNTIME_FORMAT_VERSION as u64 {
        return Err(error(
            "manifest.json",
            format!(
                "format_version {found} is not supported (this build reads {RUNTIME_FORMAT_VERSION})"
            ),
        ));
    }
    let manifest: Manifest = serde_json::from_slice(&manifest_bytes)
        .map_err(|e| error("manifest.json", e.to_string()))?;
    let load = |entry: &TextureEntry, channels: usize| -> Result<Texture3d, BundleError> {
        let format = TexelFormat::for_precision(manifest.precision, channels);
        if entry.vk_format != format.vk_name() {
            return Err(error(
                &entry.file,
                format!(
                    "manifest says {}, expected {} for {:?}",
                    entry.vk_format,
                    format.vk_name(),
                    manifest.precision
                ),
            ));
        }
        let bytes = std::fs::read(dir.join(&entry.file))
            .map_err(|e| error(&entry.file, format!("cannot read: {e}")))?;
        let reader = ktx2::Reader::new(&bytes[..])
            .map_err(|e| error(&entry.file, format!("not a valid KTX2 file: {e:?}")))?;
        let header = reader.header();
        if header.format != Some(format.ktx2()) {
            return Err(error(
                &entry.file,
                format!(
                    "KTX2 format {:?} does not match the manifest ({})",
                    header.format, entry.vk_format
                ),
            ));
        }
        let size = [header.pixel_width, header.pixel_height, header.pixel_depth];
        if size != entry.size {
            return Err(error(
                &entry.file,
                format!(
                    "KTX2 size {size:?} does not match the manifest {:?}",
                    entry.size
                ),
            ));
        }
        let Some(level) = reader.levels().next() else {
            return Err(error(&entry.file, "no mip level".into()));
        };
        let depth = size[2].max(1);
        let texel_count = (size[0] as usize) * (size[1] as usize) * depth as usize;
        let texel_bytes = channels * format.bytes_per_channel();
        if level.data.len() != texel_count * texel_bytes {
            return Err(error(
                &entry.file,
                format!(
                    "{} bytes of texels, expected {}",
                    level.data.len(),
                    texel_count * texel_bytes
                ),
            ));
        }
        let mut texels = Vec::with_capacity(texel_count);
        for chunk in level.data.chunks_exact(texel_bytes) {
            let mut texel = Vec4::ZERO;
            for c in 0..channels {
                let value = if format.bytes_per_channel() == 4 {
                    f32::from_le_bytes([
                        chunk[4 * c],
                        chunk[4 * c + 1],
                        chunk[4 * c + 2],
                        chunk[4 * c + 3],
                    ])
                } else {
                    f16_to_f32(u16::from_le_bytes([chunk[2 * c], chunk[2 * c + 1]]))
                };
                if !value.is_finite() {
                    return Err(error(
                        &entry.file,
                        format!("texel {} channel {c} is not finite", texels.len()),
                    ));
                }
                texel[c] = value;
            }
            texels.push(texel);
        }
        Ok(Texture3d {
            width: size[0],
            height: size[1],
            depth,
            texels,
        })
    };
    let hair_mesh = load(&manifest.hair_mesh, 4)?;
    let uv = load(&manifest.uv, 2)?;
    let w = load(&manifest.w, 1)?;
    let u = load(&manifest.u, 4)?;
    let v = load(&manifest.v, 4)?;
    let (width, height) = (uv.width, uv.height);
    for texture in [&hair_mesh, &w, &u, &v] {
        if (texture.width, texture.height) != (width, height) {
            return Err(error(
                "manifest.json",
                format!("3D textures must be {width}x{height} like the uv-texture"),
            ));
        }
    }
    if hair_mesh.depth != 1 + SLICES_PER_SEGMENT * manifest.max_layers
        || w.depth != 1 + manifest.max_layers
    {
        return Err(error(
            "manifest.json",
            format!(
                "texture depths do not match max_layers {}",
                manifest.max_layers
            ),
        ));
    }
    let mut blocks = Vec::with_capacity(manifest.bundles.len());
    for (i, entry) in manifest.bundles.iter().enumerate() {
        if entry.origin[0] + 1 >= width || entry.origin[1] + 1 >= height {
            return Err(error(
                "manifest.json",
                format!(
                    "bundles[{i}].origin {:?} does not fit a 2x2 block in {width}x{height}",
                    entry.origin
                ),
            ));
        }
        if entry.layers == 0 || entry.layers > manifest.max_layers {
            return Err(error(
                "manifest.json",
                format!(
                    "bundles[{i}].layers {} is outside 1..={}",
                    entry.layers, manifest.max_layers
                ),
            ));
        }
        if entry.corner_of_block.iter().any(|&c| c > 3) {
            return Err(error(
                "manifest.json",
                format!("bundles[{i}].corner_of_block has a corner above 3"),
            ));
        }
        let groups = manifest.styling.groups.len() as i32;
        if !(-1..groups).contains(&entry.styling_group) {
            return Err(error(
                "manifest.json",
                format!(
                    "bundles[{i}].styling_group {} is outside -1..{groups}",
                    entry.styling_group
                ),
            ));
        }
        blocks.push(crate::atlas::BundleBlock {
            bundle: entry.bundle,
            origin: entry.origin,
            corner_of_block: entry.corner_of_block,
            layers: entry.layers,
        });
    }
    manifest
        .styling
        .validate()
        .map_err(|e| error("manifest.json", format!("styling.{e}")))?;
    for (name, samples) in [
        ("quad_samples", &manifest.quad_samples),
        ("triangle_samples", &manifest.triangle_samples),
    ] {
        if samples.len() < manifest.strands_per_bundle as usize {
            return Err(error(
                "manifest.json",
                format!(
                    "{name} has {} samples, fewer than strands_per_bundle {}",
                    samples.len(),
                    manifest.strands_per_bundle
                ),
            ));
        }
        if let Some(i) = samples
            .iter()
            .position(|p| !p.iter().all(|c| (0.0..=1.0).contains(c)))
        {
            return Err(error(
                "manifest.json",
                format!("{name}[{i}] {:?} is outside [0, 1]²", samples[i]),
            ));
        }
    }
    let atlas = crate::atlas::Atlas {
        width,
        height,
        blocks,
        texels: vec![None; (width * height) as usize],
    };
    let textures = RuntimeTextures {
        atlas,
        precision: manifest.precision,
        position_offset: glam::Vec3::from_array(manifest.position_offset),
        hair_mesh,
        uv,
        w,
        u,
        v,
    };
    let body = match &manifest.body {
        None => crate::document::BodyMesh::default(),
        Some(file) => {
            let options = crate::import::ImportOptions {
                weld_tolerance_relative: 0.0,
                pair_quads: false,
                ..Default::default()
            };
            crate::import::import_file(&dir.join(file), &options)
                .map_err(|e| error(file, e.to_string()))?
                .to_body()
        }
    };
    Ok(LoadedBundle {
        manifest,
        textures,
        body,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::test_meshes::grid;
    use crate::strands::{StrandOptions, generate};

    #[test]
    fn half_bits_match_ieee() {
        assert_eq!(f16_bits(1.0), 0x3C00);
        assert_eq!(f16_bits(-2.0), 0xC000);
        assert_eq!(f16_bits(0.1), 0x2E66);
        assert_eq!(f16_bits(65504.0), 0x7BFF);
        assert_eq!(f16_bits(1e9), 0x7BFF);
        assert_eq!(f16_bits(2f32.powi(-24)), 0x0001);
        assert_eq!(f16_bits(0.5), 0x3800);
        assert_eq!(f16_bits(0.0), 0);
    }

    #[test]
    fn ktx2_files_read_back_with_the_ktx2_crate() {
        let texels: Vec<Vec4> = (0..2 * 3 * 4)
            .map(|i| Vec4::new(i as f32, -(i as f32), 0.5, 1.0))
            .collect();
        for format in [
            TexelFormat::Rgba32Float,
            TexelFormat::Rgba16Float,
            TexelFormat::R32Float,
            TexelFormat::Rg16Float,
        ] {
            let data = texel_bytes(&texels, format);
            let bytes = ktx2_bytes(format, 2, 3, 4, &data).expect("ktx2");
            let reader = ktx2::Reader::new(&bytes).expect("valid KTX2");
            let header = reader.header();
            assert_eq!(
                (header.pixel_width, header.pixel_height, header.pixel_depth),
                (2, 3, 4)
            );
            assert_eq!(header.format, Some(format.ktx2()));
            let level = reader.levels().next().expect("one level");
            assert_eq!(level.data, &data[..]);
            assert_eq!(reader.dfd_blocks().len(), 1);
        }
    }

    #[test]
    fn runtime_bundle_has_five_textures_and_a_manifest() {
        let document = Document::new("grid", grid(3, 2, 2, 0.5));
        let files = runtime_bundle(&document, &RuntimeExportOptions::default()).expect("export");
        let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "hair_mesh.ktx2",
                "uv.ktx2",
                "w.ktx2",
                "u.ktx2",
                "v.ktx2",
                "manifest.json"
            ]
        );
        let manifest: Manifest = serde_json::from_slice(&files[5].1).expect("manifest");
        assert_eq!(manifest.bundles.len(), 6);
        assert_eq!(manifest.hair_mesh.size[2], 1 + 4 * 2);
        assert_eq!(manifest.uv.size[2], 0);
        assert_eq!(manifest.quad_samples.len(), 256);
        let empty = Document::new("empty", grid(2, 2, 0, 0.5));
        assert!(matches!(
            runtime_bundle(&empty, &RuntimeExportOptions::default()),
            Err(ExportError::NothingToExport)
        ));
    }

    #[test]
    fn runtime_bundles_load_back_and_corruption_is_named() {
        use crate::runtime::{Filtering, TexturePath};
        let mut mesh = grid(3, 2, 2, 0.5);
        crate::interior::place_interior(&mut mesh, None);
        let document = Document::new("grid", mesh);
        let dir = std::env::temp_dir().join(format!("hairloom-bundle-test-{}", std::process::id()));
        for precision in [Precision::F32, Precision::F16] {
            let options = RuntimeExportOptions {
                precision,
                ..RuntimeExportOptions::default()
            };
            std::fs::create_dir_all(&dir).expect("dir");
            for (name, bytes) in runtime_bundle(&document, &options).expect("export") {
                std::fs::write(dir.join(name), bytes).expect("write");
            }
            let loaded = load_runtime_bundle(&dir).expect("loads");
            let built = RuntimeTextures::build(&document.hair_mesh, precision);
            assert_eq!(loaded.textures.hair_mesh, built.hair_mesh);
            assert_eq!(
                (loaded.textures.u.clone(), loaded.textures.w.clone()),
                (built.u.clone(), built.w.clone())
            );
            // The texture path gives the same strands from the loaded bundle.
            let (a, b) = (
                TexturePath {
                    textures: &loaded.textures,
                    filtering: Filtering::Exact,
                },
                TexturePath {
                    textures: &built,
                    filtering: Filtering::Exact,
                },
            );
            for block in 0..built.atlas.blocks.len() {
                assert_eq!(
                    a.position(block, 0.3, 0.6, 1.4),
                    b.position(block, 0.3, 0.6, 1.4)
                );
            }
        }
        // Corruptions, each named.
        let manifest_path = dir.join("manifest.json");
        let original = std::fs::read(&manifest_path).expect("manifest");
        let mut value: serde_json::Value = serde_json::from_slice(&original).expect("json");
        value["format_version"] = 99.into();
        std::fs::write(&manifest_path, serde_json::to_vec(&value).expect("json")).expect("write");
        let error = load_runtime_bundle(&dir).err().expect("newer version");
        assert!(error.to_string().contains("format_version 99"), "{error}");
        std::fs::write(&manifest_path, &original).expect("restore");
        let texture = std::fs::read(dir.join("w.ktx2")).expect("w");
        std::fs::write(dir.join("w.ktx2"), &texture[..texture.len() / 2]).expect("truncate");
        let error = load_runtime_bundle(&dir).err().expect("truncated");
        assert!(error.to_string().contains("w.ktx2"), "{error}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn half_to_float_inverts_rounding() {
        for value in [0.0f32, 1.0, -2.5, 0.1, 65504.0, 2f32.powi(-24), -3.0e-5] {
            assert_eq!(
                f16_to_f32(f16_bits(value)),
                crate::runtime::round_to_f16(value),
                "{value}"
            );
        }
    }

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
