//! The runtime bundle a game loads: `manifest.json` plus five KTX2 textures and the body
//! (see `docs/runtime-format.md`), written from and read back into a
//! [`RuntimeHair`]. Every function here builds bytes in memory; writing them to disk is the
//! caller's job (atomically, as a whole folder).

use serde::{Deserialize, Serialize};

use crate::io::ktx2::{TexelFormat, ktx2_bytes, read_texture, texel_bytes};
use crate::io::strand_files::glb_body;
use crate::model::document::Document;
use crate::model::styling::StylingSet;
use crate::runtime::atlas::Atlas;
pub use crate::runtime::hair::LodEntry;
use crate::runtime::hair::{RootSamples, RuntimeHair, RuntimeOptions};
use crate::runtime::textures::{Precision, RuntimeTextures, SLICES_PER_SEGMENT, Texture3d};

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
    #[error("writing manifest.json failed: {0}")]
    Manifest(String),
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

/// The files of a runtime bundle of `document` exported with `options`: `(file name,
/// bytes)`, manifest last.
pub fn runtime_bundle(
    document: &Document,
    options: &RuntimeOptions,
) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    bundle_files(&RuntimeHair::from_document(document, options))
}

/// The files of a runtime bundle holding `hair`: `(file name, bytes)`, manifest last.
pub fn bundle_files(hair: &RuntimeHair) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    let textures = &hair.textures;
    if textures.atlas.blocks.is_empty() {
        return Err(ExportError::NothingToExport);
    }
    let precision = textures.precision;
    let mut files = Vec::new();
    let mut entry = |name: &str,
                     texture: &Texture3d,
                     channels: usize,
                     is_2d: bool,
                     contents: &str|
     -> Result<TextureEntry, ExportError> {
        let format = TexelFormat::for_precision(precision, channels);
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
    let manifest = Manifest {
        format: "hairloom-runtime".into(),
        format_version: RUNTIME_FORMAT_VERSION,
        generator: format!("hairloom {}", env!("CARGO_PKG_VERSION")),
        source: hair.source.clone(),
        precision,
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
            .enumerate()
            .map(|(i, b)| BundleEntry {
                bundle: b.bundle,
                origin: b.origin,
                corner_of_block: b.corner_of_block,
                layers: b.layers,
                triangle: Atlas::is_triangle(b),
                styling_group: hair.block_styling[i] as i32 - 1,
            })
            .collect(),
        strands_per_bundle: hair.strands_per_bundle,
        lod: hair.lod.clone(),
        styling: hair.styling.clone(),
        body: (!hair.body.triangles.is_empty()).then(|| BODY_FILE.to_string()),
        quad_samples: hair.samples.quad.clone(),
        triangle_samples: hair.samples.triangle.clone(),
    };
    if manifest.body.is_some() {
        files.push((BODY_FILE.into(), glb_body(&hair.body)));
    }
    let json =
        serde_json::to_vec_pretty(&manifest).map_err(|e| ExportError::Manifest(e.to_string()))?;
    files.push(("manifest.json".into(), json));
    Ok(files)
}
/// Why a runtime bundle could not be loaded; names the file and what is wrong.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct BundleError {
    pub file: String,
    pub message: String,
}

/// Loads and checks a runtime bundle folder written by [`runtime_bundle`]: the manifest's
/// version and formats, every KTX2 header against the manifest, sizes, block placements and
/// layer counts, and finite texel values.
pub fn load_runtime_bundle(dir: &std::path::Path) -> Result<RuntimeHair, BundleError> {
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
        read_texture(&bytes, format, entry.size).map_err(|message| error(&entry.file, message))
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
        // Saturating: an origin near u32::MAX must not wrap past the check.
        if entry.origin[0].saturating_add(1) >= width || entry.origin[1].saturating_add(1) >= height
        {
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
        blocks.push(crate::runtime::atlas::BundleBlock {
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
    let atlas = crate::runtime::atlas::Atlas {
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
        None => crate::model::document::BodyMesh::default(),
        Some(file) => {
            let options = crate::io::import::ImportOptions {
                weld_tolerance_relative: 0.0,
                pair_quads: false,
                ..Default::default()
            };
            crate::io::import::import_file(&dir.join(file), &options)
                .map_err(|e| error(file, e.to_string()))?
                .to_body()
        }
    };
    Ok(RuntimeHair {
        textures,
        samples: RootSamples {
            quad: manifest.quad_samples,
            triangle: manifest.triangle_samples,
        },
        strands_per_bundle: manifest.strands_per_bundle,
        block_styling: manifest
            .bundles
            .iter()
            .map(|b| (b.styling_group + 1) as u32)
            .collect(),
        styling: manifest.styling,
        lod: manifest.lod,
        body,
        source: manifest.source,
        sample_seed: None,
    })
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    #[test]
    fn runtime_bundle_has_five_textures_and_a_manifest() {
        let document = Document::new("grid", grid(3, 2, 2, 0.5));
        let files = runtime_bundle(&document, &RuntimeOptions::default()).expect("export");
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
            runtime_bundle(&empty, &RuntimeOptions::default()),
            Err(ExportError::NothingToExport)
        ));
    }

    #[test]
    fn runtime_bundles_load_back_and_corruption_is_named() {
        use crate::runtime::strand_gen::{Filtering, StrandGen};
        let mut mesh = grid(3, 2, 2, 0.5);
        crate::geometry::interior::place_interior(&mut mesh, None);
        let document = Document::new("grid", mesh);
        let dir = std::env::temp_dir().join(format!("hairloom-bundle-test-{}", std::process::id()));
        for precision in [Precision::F32, Precision::F16] {
            let options = RuntimeOptions {
                precision,
                ..RuntimeOptions::default()
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
                StrandGen {
                    textures: &loaded.textures,
                    filtering: Filtering::Exact,
                },
                StrandGen {
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
        let error = load_runtime_bundle(&dir).expect_err("newer version");
        assert!(error.to_string().contains("format_version 99"), "{error}");
        std::fs::write(&manifest_path, &original).expect("restore");
        let texture = std::fs::read(dir.join("w.ktx2")).expect("w");
        std::fs::write(dir.join("w.ktx2"), &texture[..texture.len() / 2]).expect("truncate");
        let error = load_runtime_bundle(&dir).expect_err("truncated");
        assert!(error.to_string().contains("w.ktx2"), "{error}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
