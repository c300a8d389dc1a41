//! The runtime bundle a game loads: `manifest.json` plus five KTX2 textures and the body
//! (see `docs/runtime-format.md`), written from and read back into a
//! [`RuntimeHair`]. Every function here builds bytes in memory; writing them to disk is the
//! caller's job (atomically, as a whole folder).

use serde::{Deserialize, Serialize};

use crate::io::ktx2::{TexelFormat, ktx2_bytes, read_texture, texel_bytes};
use crate::io::strand_files::glb_body;
use crate::model::document::Document;
use crate::model::scene::Scene;
use crate::model::styling::StylingSet;
use crate::runtime::atlas::Atlas;
pub use crate::runtime::hair::LodEntry;
use crate::runtime::hair::{RootSamples, RuntimeHair, RuntimeOptions};
use crate::runtime::textures::{Precision, RuntimeTextures, SLICES_PER_SEGMENT, Texture3d};

/// Version of the runtime bundle format described in `docs/runtime-format.md`. Version 9
/// adds the painted colour map (`manifest.colour_map`: sRGB colour and its weight in root-uv
/// space; a version 8 reader would draw every strand in the material's colour). Version 8
/// adds painted maps (`manifest.root_maps`: density, length and clump in root-uv space; a
/// version 7 reader would grow every strand where the maps thin or shorten them). Version 7
/// adds `wave.lock_phase_spread` (how far apart the locks' wave phases lie; absent means 1,
/// the phases older bundles had; a version 6 reader would draw other waves). Version 6
/// adds the hairline op: the `hairline` styling keys and each root's distance to the border
/// of the hair in the hair-mesh root slice's fourth channel (0 before); a version 5 reader
/// would grow every strand at full length. Version 5 adds styling ops (sub-clumps, strays, ringlet and lock-wave phases, curl tip scales): a
/// version 4 reader would skip their keys and grow other strands, so it must refuse the
/// bundle; their defaults leave older bundles' strands unchanged. Version 4 adds what a game needs to rebuild the textures from a moving hair mesh (each bundle's
/// `columns`, `column_layers`, `bare_faces`); version 3 adds far hair's hierarchy (`manifest.far_hair`); version 2 stores 3 hair-mesh slices per
/// segment (`p_k, q0, q1`); version 1 stored the quadratics' joint `m` too (4 slices). All
/// are read (version 1's `m` slices are dropped on load: `m` is exactly `(q0 + q1) / 2`;
/// bundles before version 3 have no far hair).
pub const RUNTIME_FORMAT_VERSION: u32 = 10;
/// Hair-mesh slices per segment in format version 1 bundles.
const VERSION_1_SLICES_PER_SEGMENT: u32 = 4;

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
    #[error("far hair's hierarchy: {0}")]
    FarHair(#[from] crate::runtime::thick_hair::ThickHairError),
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
    /// The fraction of the bundle's strands that grow (`⌈density · N⌉` of them); absent
    /// means 1.
    #[serde(default = "full_density", skip_serializing_if = "is_full_density")]
    pub density: f32,
    /// The hair-mesh column each block corner's texel holds (format version 4): what a game
    /// that simulates the hair mesh writes there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub columns: Option<[u32; 4]>,
}

fn full_density() -> f32 {
    1.0
}

fn is_full_density(density: &f32) -> bool {
    *density == 1.0
}

/// Far hair's hierarchy in a runtime bundle (format version 3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FarHairEntry {
    /// The far-hair file's name (plain, in the bundle folder).
    pub file: String,
    pub levels: u32,
    pub thick_hairs: u32,
    /// A one-line description of the file; informative.
    pub contents: String,
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
    /// Lights, cameras, the fibre material and the effects the picture asks for (see
    /// `docs/runtime-format.md`); bundles from before scenes existed get the default scene.
    #[serde(default)]
    pub scene: Scene,
    /// The opaque body mesh (GLB, triangles) hair is depth-tested against, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<String>,
    /// Progressive root samples in `[0,1)²` for quads (block coordinates).
    pub quad_samples: Vec<[f32; 2]>,
    /// Progressive root samples, barycentric `(s, t)` with `s + t < 1`, for triangles;
    /// block coordinates are `(s / (1 − t), t)`.
    pub triangle_samples: Vec<[f32; 2]>,
    /// Far hair's thick hairs and levels (seed 001), from format version 3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub far_hair: Option<FarHairEntry>,
    /// Layer count of every hair-mesh column (format version 4).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub column_layers: Vec<u32>,
    /// Scalp faces without hair whose corners weigh in on layer 0's frames (version 4).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bare_faces: Vec<crate::runtime::textures::BareFace>,
    /// Density, length and clump painted in root-uv space (format version 8): a 2D
    /// `R8G8B8A8_UNORM` texture; absent where nothing is painted (1 everywhere).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub root_maps: Option<TextureEntry>,
    /// The colour painted in root-uv space (format version 9): a 2D `R8G8B8A8_SRGB` texture
    /// of `root_maps`' size (rgb the colour, a its weight over the material's); absent where
    /// none is painted. Only with `root_maps`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour_map: Option<TextureEntry>,
}

/// File name of the manifest, the bundle's single commit point (see [`write_bundle_folder`]).
pub const MANIFEST_FILE: &str = "manifest.json";

/// `STEM.HASH.EXT`: the file name of `bytes`, unique to its content (64-bit SipHash-1-3
/// with fixed keys, so the name is stable across builds). Because a name never changes its
/// content, writing a new bundle over an old one never alters a file the old manifest
/// names: a reader sees the old bundle or the new one, never a mix.
pub(crate) fn content_addressed_name(stem: &str, extension: &str, bytes: &[u8]) -> String {
    use std::hash::Hasher as _;
    let mut hasher = siphasher::sip::SipHasher13::new();
    hasher.write(bytes);
    format!("{stem}.{:016x}.{extension}", hasher.finish())
}

/// Whether `name` is a data file a runtime bundle export writes (content-addressed, or
/// the fixed names of bundles written before content addressing).
fn is_bundle_data_file(name: &str) -> bool {
    const STEMS: [&str; 9] = [
        "hair_mesh",
        "uv",
        "w",
        "u",
        "v",
        "body",
        "far_hair",
        "root_maps",
        "colour_map",
    ];
    let Some((stem, rest)) = name.split_once('.') else {
        return false;
    };
    if !STEMS.contains(&stem) {
        return false;
    }
    match rest.split_once('.') {
        None => matches!(rest, "ktx2" | "glb"),
        Some((hash, extension)) => {
            hash.len() == 16
                && hash.bytes().all(|b| b.is_ascii_hexdigit())
                && matches!(extension, "ktx2" | "glb" | "bin")
        }
    }
}

/// Writes a runtime bundle's `files` (from [`bundle_files`], manifest last) into `dir`, so
/// that a reader at any moment — including after a crash — sees the old bundle or the new
/// one, whole: every data file is written atomically under its content-addressed name (one
/// already there is kept only when its bytes are these bytes), then the manifest is renamed
/// into place (the single commit point), then data files of earlier exports into `dir` that
/// the new manifest does not name are removed — each only if its content still matches the
/// hash in its name, so a file the export did not write, or one a user changed since, is
/// never removed.
///
/// Which files earlier exports wrote is kept in [`EXPORT_LEDGER_FILE`], written before any
/// data file: an export killed before its commit, or between its commit and its clean-up,
/// leaves names there that the next export removes. Folders exported before the ledger
/// existed count the names their manifest gives.
///
/// The folder may hold anything else (a user's `body.glb`, their own textures): it is never
/// touched. A `manifest.json` there that is not a Hairloom runtime manifest is refused
/// before anything is written (it is the user's, and the export would replace it).
/// Temporaries that killed exports left behind for any bundle file are removed.
pub fn write_bundle_folder(
    dir: &std::path::Path,
    files: &[(String, Vec<u8>)],
    mut after_file: impl FnMut(&str),
) -> std::io::Result<()> {
    use crate::io::project::{remove_dead_writers_temporaries, write_atomic};
    let Some(((manifest_name, manifest), data)) = files.split_last() else {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "a runtime bundle has at least a manifest",
        ));
    };
    if manifest_name != MANIFEST_FILE {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "the manifest must be the last file",
        ));
    }
    std::fs::create_dir_all(dir)?;
    let previous = files_of_previous_bundle(dir)?;
    remove_dead_writers_temporaries(dir, |target| {
        target == MANIFEST_FILE || target == EXPORT_LEDGER_FILE || is_bundle_data_file(target)
    });
    // Every name an earlier export may have left, and every name this one will write,
    // recorded before the first data file is.
    let mut ours = read_ledger(dir);
    ours.extend(previous);
    ours.extend(data.iter().map(|(name, _)| name.clone()));
    ours.sort();
    ours.dedup();
    write_ledger(dir, &ours)?;
    for (name, bytes) in data {
        let path = dir.join(name);
        // A content-addressed file already there is reused only when it holds exactly these
        // bytes: a file damaged since (same name, same size) is written again.
        let content_addressed = name.matches('.').count() == 2 && is_bundle_data_file(name);
        let already_there = content_addressed && file_holds(&path, bytes);
        if !already_there {
            write_atomic(&path, bytes, |_| {})?;
        }
        after_file(name);
    }
    write_atomic(&dir.join(MANIFEST_FILE), manifest, |_| {})?;
    after_file(MANIFEST_FILE);
    let named: std::collections::HashSet<&str> = data.iter().map(|(n, _)| n.as_str()).collect();
    for name in &ours {
        if named.contains(name.as_str()) {
            continue;
        }
        let path = dir.join(name);
        if still_as_written(&path, name) {
            let _ = std::fs::remove_file(path);
        }
    }
    let mut kept: Vec<String> = named.into_iter().map(str::to_string).collect();
    kept.sort();
    write_ledger(dir, &kept)
}

/// The hidden file in a bundle folder that lists the data files exports into it wrote
/// (one name a line), so a later export removes only those (see [`write_bundle_folder`]).
pub const EXPORT_LEDGER_FILE: &str = ".hairloom-export-files";

/// The names [`EXPORT_LEDGER_FILE`] lists that could be bundle data files (none when it is
/// missing or unreadable: then nothing is removed on its word).
fn read_ledger(dir: &std::path::Path) -> Vec<String> {
    use crate::io::input_files::read_regular_file;
    let Ok(bytes) = read_regular_file(
        &dir.join(EXPORT_LEDGER_FILE),
        limits::MANIFEST_BYTES,
        "a runtime bundle folder's export ledger",
    ) else {
        return Vec::new();
    };
    String::from_utf8_lossy(&bytes)
        .lines()
        .map(str::trim)
        .filter(|name| is_bundle_data_file(name))
        .map(str::to_string)
        .collect()
}

fn write_ledger(dir: &std::path::Path, names: &[String]) -> std::io::Result<()> {
    let mut text = String::new();
    for name in names {
        text.push_str(name);
        text.push('\n');
    }
    crate::io::project::write_atomic(&dir.join(EXPORT_LEDGER_FILE), text.as_bytes(), |_| {})
}

/// Whether `path` is a regular file holding exactly `bytes`.
fn file_holds(path: &std::path::Path, bytes: &[u8]) -> bool {
    use crate::io::input_files::read_regular_file;
    let same_size =
        std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file() && m.len() == bytes.len() as u64);
    same_size
        && read_regular_file(path, bytes.len() as u64, "a runtime bundle file")
            .is_ok_and(|existing| existing == bytes)
}

/// Whether the content-addressed file `name` at `path` is a regular file (not a link) whose
/// content still hashes to the name: what an export wrote and nobody changed since.
fn still_as_written(path: &std::path::Path, name: &str) -> bool {
    use crate::io::input_files::read_regular_file;
    let Some((stem, rest)) = name.split_once('.') else {
        return false;
    };
    let Some((_, extension)) = rest.split_once('.') else {
        // A fixed name from before content addressing: nothing to check it against.
        return false;
    };
    let regular = std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file());
    regular
        && read_regular_file(path, limits::FILE_BYTES, "a runtime bundle file")
            .is_ok_and(|bytes| content_addressed_name(stem, extension, &bytes) == name)
}

/// The data files the manifest already in `dir` names (none when there is no manifest). A
/// `manifest.json` that is not a Hairloom runtime manifest is an error: it is someone's
/// file, and writing the bundle would replace it.
fn files_of_previous_bundle(dir: &std::path::Path) -> std::io::Result<Vec<String>> {
    use crate::io::input_files::read_regular_file;
    let path = dir.join(MANIFEST_FILE);
    if std::fs::symlink_metadata(&path).is_err() {
        return Ok(Vec::new());
    }
    let not_ours = |why: &str| {
        std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            format!(
                "{} is not a Hairloom runtime manifest ({why}); export into an empty folder or one that holds a Hairloom runtime bundle",
                path.display()
            ),
        )
    };
    let bytes = read_regular_file(&path, limits::MANIFEST_BYTES, "a runtime bundle manifest")
        .map_err(|e| not_ours(&e.to_string()))?;
    let value: serde_json::Value =
        serde_json::from_slice(&bytes).map_err(|e| not_ours(&format!("not JSON: {e}")))?;
    if value.get("format").and_then(|f| f.as_str()) != Some("hairloom-runtime") {
        return Err(not_ours("its \"format\" is not \"hairloom-runtime\""));
    }
    let mut names: Vec<String> = ["hair_mesh", "uv", "w", "u", "v"]
        .iter()
        .filter_map(|key| value.get(*key)?.get("file")?.as_str())
        .chain(value.get("body").and_then(|b| b.as_str()))
        .filter(|name| is_bundle_data_file(name))
        .map(str::to_string)
        .collect();
    names.dedup();
    Ok(names)
}

/// The files of a runtime bundle of `document` exported with `options`: `(file name,
/// bytes)`, manifest last.
pub fn runtime_bundle(
    document: &Document,
    options: &RuntimeOptions,
) -> Result<Vec<(String, Vec<u8>)>, ExportError> {
    bundle_files(&RuntimeHair::from_document(document, options))
}

/// The hair-mesh column held by each block corner's texel of `block`; `None` when a texel
/// does not know its column (an atlas loaded from a bundle before format version 4).
fn block_columns(atlas: &Atlas, block: &crate::runtime::atlas::BundleBlock) -> Option<[u32; 4]> {
    let mut columns = [0; 4];
    for (column, (x, y)) in columns.iter_mut().zip(block.corner_texels()) {
        *column = atlas
            .texels
            .get((y * atlas.width + x) as usize)
            .copied()
            .flatten()?
            .column;
    }
    Some(columns)
}

/// The mesh topology of a loaded manifest (format version 4; empty before), checked: from
/// version 4 every bundle has `columns`, each naming a column of `column_layers` tall enough
/// for the bundle, a triangle's block corners 2 and 3 the same one, and no texel two
/// columns; no column is taller than `max_layers`; bare faces have 3 or 4 corners with
/// finite uvs and positions. The atlas's texels learn their column and uv (from `uv`).
fn bundle_topology(
    manifest: &Manifest,
    version: u64,
    atlas: &mut Atlas,
    uv: &Texture3d,
) -> Result<crate::runtime::textures::MeshTopology, String> {
    let layers = &manifest.column_layers;
    if version >= 4 && layers.is_empty() {
        return Err(format!(
            "format_version {version} needs column_layers (the hair mesh's columns)"
        ));
    }
    if let Some(c) = layers.iter().position(|&l| l > manifest.max_layers) {
        return Err(format!(
            "column_layers[{c}] {} is above max_layers {}",
            layers[c], manifest.max_layers
        ));
    }
    let column = |c: u32, at: &str, least: u32| -> Result<(), String> {
        match layers.get(c as usize) {
            None => Err(format!(
                "{at} names column {c}, but column_layers has {} columns",
                layers.len()
            )),
            Some(&l) if l < least => Err(format!(
                "{at} names column {c} of {l} layers for a bundle of {least}"
            )),
            Some(_) => Ok(()),
        }
    };
    for (i, entry) in manifest.bundles.iter().enumerate() {
        let Some(columns) = entry.columns else {
            if version >= 4 {
                return Err(format!(
                    "bundles[{i}] has no columns (format_version {version} needs them)"
                ));
            }
            continue;
        };
        if entry.corner_of_block[2] == entry.corner_of_block[3] && columns[2] != columns[3] {
            return Err(format!(
                "bundles[{i}].columns: a triangle's block corners 2 and 3 hold one column, not {} and {}",
                columns[2], columns[3]
            ));
        }
        // The atlas's block i is bundles[i], its placement checked before.
        let corners = atlas.blocks[i].corner_texels();
        for (b, (&c, (x, y))) in columns.iter().zip(corners).enumerate() {
            column(c, &format!("bundles[{i}].columns[{b}]"), entry.layers)?;
            let root_uv = uv.get(x, y, 0);
            let texel = &mut atlas.texels[(y * atlas.width + x) as usize];
            if let Some(held) = texel.filter(|t| t.column != c) {
                return Err(format!(
                    "texel ({x}, {y}) holds column {} for one bundle and column {c} for bundles[{i}]",
                    held.column
                ));
            }
            *texel = Some(crate::runtime::atlas::TexelSource {
                column: c,
                uv: glam::DVec2::new(root_uv.x as f64, root_uv.y as f64),
            });
        }
    }
    for (f, face) in manifest.bare_faces.iter().enumerate() {
        let n = face.columns.len();
        if !(3..=4).contains(&n) || face.uvs.len() != n || face.positions.len() != n {
            return Err(format!(
                "bare_faces[{f}] has {n} columns, {} uvs and {} positions (3 or 4 of each)",
                face.uvs.len(),
                face.positions.len()
            ));
        }
        if face.positions.iter().flatten().any(|x| !x.is_finite()) {
            return Err(format!("bare_faces[{f}] has a position that is not finite"));
        }
        for &c in &face.columns {
            column(c, &format!("bare_faces[{f}]"), 0)?;
        }
        if face.uvs.iter().flatten().any(|x| !x.is_finite()) {
            return Err(format!("bare_faces[{f}] has a uv that is not finite"));
        }
    }
    Ok(crate::runtime::textures::MeshTopology {
        column_layers: layers.clone(),
        bare_faces: manifest.bare_faces.clone(),
    })
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
        let file = content_addressed_name(name, "ktx2", &bytes);
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
        "object-space positions minus position_offset (xyz); slice 3k is layer k, slices 3k+1 and 3k+2 are q0 and q1 of segment k (its quadratics' joint m is their mean)",
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
    let maps = &textures.root_maps;
    // A 2D RGBA8 map of the maps' size, content-addressed, as a manifest entry.
    let mut map_entry = |stem: &str, format: TexelFormat, bytes: &[u8], contents: &str| {
        let bytes = ktx2_bytes(format, maps.width(), maps.height(), 0, bytes)?;
        let file = content_addressed_name(stem, "ktx2", &bytes);
        files.push((file.clone(), bytes));
        Ok::<_, ExportError>(TextureEntry {
            file,
            vk_format: format.vk_name().to_string(),
            size: [maps.width(), maps.height(), 0],
            contents: contents.into(),
        })
    };
    let root_maps = (!maps.is_empty())
        .then(|| {
            map_entry(
                "root_maps",
                TexelFormat::Rgba8Unorm,
                &maps.rgba8(),
                "painted maps in root-uv space: r density, g length, b clump (shares, byte / 255); a unused",
            )
        })
        .transpose()?;
    let colour_map = maps
        .has_colour()
        .then(|| {
            map_entry(
                "colour_map",
                TexelFormat::Rgba8Srgb,
                &maps.colour_rgba8(),
                "the colour painted in root-uv space: rgb the colour a thick mass of the hair shows (sRGB), a its weight over the material's colour (byte / 255)",
            )
        })
        .transpose()?;
    let body_glb = (!hair.body.triangles.is_empty()).then(|| glb_body(&hair.body));
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
                density: hair.block_density[i],
                columns: block_columns(&textures.atlas, b),
            })
            .collect(),
        strands_per_bundle: hair.strands_per_bundle,
        lod: hair.lod.clone(),
        styling: hair.styling.clone(),
        scene: hair.scene.clone(),
        body: body_glb
            .as_ref()
            .map(|bytes| content_addressed_name("body", "glb", bytes)),
        quad_samples: hair.samples.quad.clone(),
        triangle_samples: hair.samples.triangle.clone(),
        far_hair: None,
        column_layers: textures.topology.column_layers.clone(),
        bare_faces: textures.topology.bare_faces.clone(),
        root_maps,
        colour_map,
    };
    if let (Some(name), Some(bytes)) = (&manifest.body, body_glb) {
        files.push((name.clone(), bytes));
    }
    // Far hair's hierarchy from the strands as a game generates them at full detail.
    let far = crate::runtime::thick_hair::FarHair::build(
        hair,
        (1usize << hair.lod.max_vertices_log2.min(limits::MAX_VERTICES_LOG2)) + 1,
    )?;
    let far_bytes = far.to_bytes();
    let far_file = content_addressed_name("far_hair", "bin", &far_bytes);
    let mut manifest = manifest;
    manifest.far_hair = Some(FarHairEntry {
        file: far_file.clone(),
        levels: far.blocks.iter().map(|b| b.len() as u32).sum(),
        thick_hairs: far.thick_hairs.len() as u32,
        contents: "far hair: each bundle's thick hairs by level (corner strands, member counts) and each level's widest diameter; layout in docs/runtime-format.md".into(),
    });
    files.push((far_file, far_bytes));
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

/// Caps on what a runtime bundle may ask for (see `docs/resource-policy.md`).
pub mod limits {
    /// `manifest.json`.
    pub const MANIFEST_BYTES: u64 = 64 << 20;
    /// Each texture and the body file.
    pub const FILE_BYTES: u64 = 512 << 20;
    /// Width and height of the atlas (the 2D extent of every texture).
    pub const ATLAS_EXTENT: u32 = 16384;
    /// Strands per bundle (the editor offers up to 256; 4096 is a very dense fur).
    pub const STRANDS_PER_BUNDLE: u32 = 4096;
    /// Root sample entries of each kind.
    pub const SAMPLES: usize = 1 << 16;
    /// `lod.max_vertices_log2`: 1025 vertices per strand.
    pub const MAX_VERTICES_LOG2: u32 = 10;
    /// Entries of `column_layers` and of `bare_faces` (format version 4), each.
    pub const COLUMNS: usize = 1 << 22;
}

/// Where a runtime bundle's files come from: a folder on disk ([`load_runtime_bundle`]) or
/// memory (tests and fuzzing). `read` returns the file's bytes or a message naming why not.
pub trait BundleFiles {
    fn read(&self, name: &str, cap_bytes: u64) -> Result<Vec<u8>, String>;
}

/// A bundle folder: reads only regular files inside it, capped (see
/// [`crate::io::input_files`]).
pub struct BundleFolder(pub crate::io::input_files::InputFolder);

impl BundleFiles for BundleFolder {
    fn read(&self, name: &str, cap_bytes: u64) -> Result<Vec<u8>, String> {
        self.0
            .read(name, cap_bytes, "a runtime bundle file")
            .map_err(|e| e.to_string())
    }
}

impl BundleFiles for std::collections::HashMap<String, Vec<u8>> {
    fn read(&self, name: &str, cap_bytes: u64) -> Result<Vec<u8>, String> {
        match self.get(name) {
            Some(bytes) if bytes.len() as u64 <= cap_bytes => Ok(bytes.clone()),
            Some(_) => Err(format!("larger than the cap of {cap_bytes} bytes")),
            None => Err("no such file in the bundle".into()),
        }
    }
}

/// Loads and checks a runtime bundle folder written by [`write_bundle_folder`]: see
/// [`load_runtime_bundle_from`]. Only files inside `dir` are read.
pub fn load_runtime_bundle(dir: &std::path::Path) -> Result<RuntimeHair, BundleError> {
    load_runtime_asset(dir).map(|asset| asset.hair)
}

/// A format version 1 hair-mesh texture (`p_k, q0, m, q1` per segment) in today's layout
/// (`p_k, q0, q1`): slices `4k + 2` (the joints `m = (q0 + q1) / 2`) are dropped.
fn without_joint_slices(four: &Texture3d) -> Texture3d {
    let slice = (four.width * four.height) as usize;
    let keep: Vec<u32> = (0..four.depth)
        .filter(|z| z % VERSION_1_SLICES_PER_SEGMENT != 2)
        .collect();
    Texture3d {
        width: four.width,
        height: four.height,
        depth: keep.len() as u32,
        texels: keep
            .iter()
            .flat_map(|&z| {
                four.texels[z as usize * slice..(z as usize + 1) * slice]
                    .iter()
                    .copied()
            })
            .collect(),
    }
}

/// Loads and checks a runtime bundle: the manifest's version and formats, every KTX2
/// header against the manifest, sizes, block placements and layer counts, the caps of
/// [`limits`], and finite texel values. `shown` names the bundle in messages.
pub fn load_runtime_bundle_from(
    files: &dyn BundleFiles,
    shown: &str,
) -> Result<RuntimeHair, BundleError> {
    load_runtime_asset_from(files, shown).map(|asset| asset.hair)
}

/// A runtime bundle as loaded: the hair, and far hair's hierarchy where the bundle has one
/// (format version 3). Kept apart from [`RuntimeHair`], which changes as a document is
/// edited: the hierarchy belongs to the strands it was built from.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedBundle {
    pub hair: RuntimeHair,
    pub far_hair: Option<crate::runtime::thick_hair::FarHair>,
}

/// Loads a runtime bundle folder with its far hair: see [`load_runtime_asset_from`].
pub fn load_runtime_asset(dir: &std::path::Path) -> Result<LoadedBundle, BundleError> {
    let folder = crate::io::input_files::InputFolder::new(dir).map_err(|e| BundleError {
        file: dir.display().to_string(),
        message: e.to_string(),
    })?;
    load_runtime_asset_from(&BundleFolder(folder), &dir.display().to_string())
}

/// [`load_runtime_bundle_from`], plus the far-hair file where the manifest names one,
/// checked against the bundles it describes ([`crate::runtime::thick_hair::FarHair::from_bytes`]).
pub fn load_runtime_asset_from(
    files: &dyn BundleFiles,
    shown: &str,
) -> Result<LoadedBundle, BundleError> {
    let error = |file: &str, message: String| BundleError {
        file: format!("{shown}/{file}"),
        message,
    };
    let manifest_bytes = files
        .read(MANIFEST_FILE, limits::MANIFEST_BYTES)
        .map_err(|e| error(MANIFEST_FILE, e))?;
    let version: serde_json::Value = serde_json::from_slice(&manifest_bytes)
        .map_err(|e| error(MANIFEST_FILE, format!("not JSON: {e}")))?;
    let found = version
        .get("format_version")
        .and_then(|v| v.as_u64())
        .unwrap_or(0);
    if version.get("format").and_then(|v| v.as_str()) != Some("hairloom-runtime") {
        return Err(error(
            MANIFEST_FILE,
            "not a Hairloom runtime manifest (\"format\" is not \"hairloom-runtime\")".into(),
        ));
    }
    if !(1..=RUNTIME_FORMAT_VERSION as u64).contains(&found) {
        return Err(error(
            MANIFEST_FILE,
            format!(
                "format_version {found} is not supported (this build reads 1 to {RUNTIME_FORMAT_VERSION})"
            ),
        ));
    }
    let manifest: Manifest =
        serde_json::from_slice(&manifest_bytes).map_err(|e| error(MANIFEST_FILE, e.to_string()))?;
    check_manifest_caps(&manifest).map_err(|message| error(MANIFEST_FILE, message))?;
    let slices_per_segment = if found == 1 {
        VERSION_1_SLICES_PER_SEGMENT
    } else {
        SLICES_PER_SEGMENT
    };
    if manifest.slices_per_segment != slices_per_segment {
        return Err(error(
            MANIFEST_FILE,
            format!(
                "slices_per_segment {} does not match format_version {found} (which has {slices_per_segment})",
                manifest.slices_per_segment
            ),
        ));
    }
    // A texture of `format`, its entry checked against the format, its name and its file.
    let load_as = |entry: &TextureEntry, format: TexelFormat| -> Result<Texture3d, BundleError> {
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
        check_file_name(&entry.file).map_err(|message| error(MANIFEST_FILE, message))?;
        let bytes = files
            .read(&entry.file, limits::FILE_BYTES)
            .map_err(|e| error(&entry.file, e))?;
        read_texture(&bytes, format, entry.size).map_err(|message| error(&entry.file, message))
    };
    let load = |entry: &TextureEntry, channels: usize| {
        load_as(
            entry,
            TexelFormat::for_precision(manifest.precision, channels),
        )
    };
    let hair_mesh = load(&manifest.hair_mesh, 4)?;
    let uv = load(&manifest.uv, 2)?;
    // An RGBA8 texture's bytes again (read as byte / 255).
    let bytes_of = |texture: &Texture3d| -> Vec<u8> {
        texture
            .texels
            .iter()
            .flat_map(|t| t.to_array().map(|c| (c * 255.0).round() as u8))
            .collect()
    };
    let root_maps = match &manifest.root_maps {
        None => crate::model::root_maps::RootMaps::default(),
        Some(entry) => {
            let [width, height, depth] = entry.size;
            if depth != 0 {
                return Err(error(
                    MANIFEST_FILE,
                    format!("root_maps is a 2D texture: its size's depth is {depth}, not 0"),
                ));
            }
            // Checked before the file is read: a hostile size names the problem.
            crate::model::root_maps::check_size(width, height)
                .map_err(|e| error(MANIFEST_FILE, format!("root_maps: {e}")))?;
            let texture = load_as(entry, TexelFormat::Rgba8Unorm)?;
            let mut maps =
                crate::model::root_maps::RootMaps::from_rgba8(width, height, &bytes_of(&texture))
                    .map_err(|e| error(&entry.file, e.to_string()))?;
            if let Some(colour) = &manifest.colour_map {
                if colour.size != entry.size {
                    return Err(error(
                        MANIFEST_FILE,
                        format!(
                            "colour_map's size {:?} is not root_maps' {:?}",
                            colour.size, entry.size
                        ),
                    ));
                }
                let texture = load_as(colour, TexelFormat::Rgba8Srgb)?;
                maps.set_colour_rgba8(&bytes_of(&texture))
                    .map_err(|e| error(&colour.file, e.to_string()))?;
            }
            maps
        }
    };
    if manifest.colour_map.is_some() && manifest.root_maps.is_none() {
        return Err(error(
            MANIFEST_FILE,
            "colour_map is present without root_maps (they share one size)".to_string(),
        ));
    }
    let w = load(&manifest.w, 1)?;
    let u = load(&manifest.u, 4)?;
    let v = load(&manifest.v, 4)?;
    let (width, height) = (uv.width, uv.height);
    for texture in [&hair_mesh, &w, &u, &v] {
        if (texture.width, texture.height) != (width, height) {
            return Err(error(
                MANIFEST_FILE,
                format!("3D textures must be {width}x{height} like the uv-texture"),
            ));
        }
    }
    if hair_mesh.depth != 1 + slices_per_segment * manifest.max_layers
        || w.depth != 1 + manifest.max_layers
    {
        return Err(error(
            MANIFEST_FILE,
            format!(
                "texture depths do not match max_layers {}",
                manifest.max_layers
            ),
        ));
    }
    let hair_mesh = if slices_per_segment == VERSION_1_SLICES_PER_SEGMENT {
        without_joint_slices(&hair_mesh)
    } else {
        hair_mesh
    };
    let mut blocks = Vec::with_capacity(manifest.bundles.len());
    for (i, entry) in manifest.bundles.iter().enumerate() {
        // Saturating: an origin near u32::MAX must not wrap past the check.
        if entry.origin[0].saturating_add(1) >= width || entry.origin[1].saturating_add(1) >= height
        {
            return Err(error(
                MANIFEST_FILE,
                format!(
                    "bundles[{i}].origin {:?} does not fit a 2x2 block in {width}x{height}",
                    entry.origin
                ),
            ));
        }
        if entry.layers == 0 || entry.layers > manifest.max_layers {
            return Err(error(
                MANIFEST_FILE,
                format!(
                    "bundles[{i}].layers {} is outside 1..={}",
                    entry.layers, manifest.max_layers
                ),
            ));
        }
        if entry.corner_of_block.iter().any(|&c| c > 3) {
            return Err(error(
                MANIFEST_FILE,
                format!("bundles[{i}].corner_of_block has a corner above 3"),
            ));
        }
        if !(0.0..=1.0).contains(&entry.density) {
            return Err(error(
                MANIFEST_FILE,
                format!(
                    "bundles[{i}].density {} is outside [0, 1] (the fraction of strands that grow)",
                    entry.density
                ),
            ));
        }
        let groups = manifest.styling.groups.len() as i32;
        if !(-1..groups).contains(&entry.styling_group) {
            return Err(error(
                MANIFEST_FILE,
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
    manifest
        .scene
        .validate()
        .map_err(|e| error("manifest.json", format!("scene.{e}")))?;
    for (name, samples) in [
        ("quad_samples", &manifest.quad_samples),
        ("triangle_samples", &manifest.triangle_samples),
    ] {
        if samples.len() < manifest.strands_per_bundle as usize {
            return Err(error(
                MANIFEST_FILE,
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
                MANIFEST_FILE,
                format!("{name}[{i}] {:?} is outside [0, 1]²", samples[i]),
            ));
        }
    }
    let atlas_texels = (width as usize)
        .checked_mul(height as usize)
        .ok_or_else(|| {
            error(
                MANIFEST_FILE,
                format!("atlas {width}x{height} is too large"),
            )
        })?;
    let mut atlas = crate::runtime::atlas::Atlas {
        width,
        height,
        blocks,
        texels: vec![None; atlas_texels],
    };
    let topology = bundle_topology(&manifest, found, &mut atlas, &uv)
        .map_err(|message| error(MANIFEST_FILE, message))?;
    let textures = RuntimeTextures {
        atlas,
        precision: manifest.precision,
        position_offset: glam::Vec3::from_array(manifest.position_offset),
        hair_mesh,
        uv,
        w,
        u,
        v,
        topology,
        root_maps,
    };
    let body = match &manifest.body {
        None => crate::model::document::BodyMesh::default(),
        Some(file) => {
            let options = crate::io::import::ImportOptions {
                weld_tolerance_relative: 0.0,
                pair_quads: false,
                ..Default::default()
            };
            // Imported from memory with no folder: a body may not name external buffers.
            check_file_name(file).map_err(|message| error(MANIFEST_FILE, message))?;
            let bytes = files
                .read(file, limits::FILE_BYTES)
                .map_err(|e| error(file, e))?;
            crate::io::import::import_slice(&bytes, None, file, &options)
                .map_err(|e| error(file, e.to_string()))?
                .to_body()
        }
    };
    let far_entry = manifest.far_hair.clone();
    let hair = RuntimeHair {
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
        block_density: manifest.bundles.iter().map(|b| b.density).collect(),
        block_bundle_density: Vec::new(),
        block_root_area: Vec::new(),
        styling: manifest.styling,
        scene: manifest.scene,
        lod: manifest.lod,
        body,
        source: manifest.source,
        sample_seed: None,
        fur_base: Default::default(),
    };
    let hair = RuntimeHair {
        fur_base: crate::fur::base::FurBase::from_textures(&hair.textures),
        ..hair
    };
    let far_hair = match far_entry {
        None => None,
        Some(entry) => {
            check_file_name(&entry.file).map_err(|message| error(MANIFEST_FILE, message))?;
            let bytes = files
                .read(&entry.file, limits::FILE_BYTES)
                .map_err(|e| error(&entry.file, e))?;
            let grown: Vec<u32> = (0..hair.textures.atlas.blocks.len())
                .map(|block| hair.block_strand_count(block))
                .collect();
            let far = crate::runtime::thick_hair::FarHair::from_bytes(
                &bytes,
                &grown,
                hair.strands_per_bundle,
            )
            .map_err(|message| error(&entry.file, message))?;
            let levels: usize = far.blocks.iter().map(Vec::len).sum();
            if (levels, far.thick_hairs.len())
                != (entry.levels as usize, entry.thick_hairs as usize)
            {
                return Err(error(
                    MANIFEST_FILE,
                    format!(
                        "far_hair lists {} levels and {} thick hairs, its file {levels} and {}",
                        entry.levels,
                        entry.thick_hairs,
                        far.thick_hairs.len()
                    ),
                ));
            }
            Some(far)
        }
    };
    Ok(LoadedBundle { hair, far_hair })
}
/// A bundle is one flat folder: the manifest names its files by plain name only.
fn check_file_name(name: &str) -> Result<(), String> {
    let plain =
        !name.is_empty() && name != "." && name != ".." && !name.contains(['/', '\\', ':', '\0']);
    if plain {
        Ok(())
    } else {
        Err(format!(
            "file name \"{name}\" is refused: a bundle names only plain files in its own folder (no /, \\, .. or :)"
        ))
    }
}

/// The manifest's sizes against [`limits`], before any texture is read.
fn check_manifest_caps(manifest: &Manifest) -> Result<(), String> {
    let max_layers = crate::runtime::textures::MAX_LAYERS_PER_BUNDLE;
    if manifest.max_layers > max_layers {
        return Err(format!(
            "max_layers {} is above the cap of {max_layers} layers per bundle",
            manifest.max_layers
        ));
    }
    for (name, entry) in [
        ("hair_mesh", &manifest.hair_mesh),
        ("uv", &manifest.uv),
        ("w", &manifest.w),
        ("u", &manifest.u),
        ("v", &manifest.v),
    ] {
        if entry.size[0] > limits::ATLAS_EXTENT || entry.size[1] > limits::ATLAS_EXTENT {
            return Err(format!(
                "{name}.size {:?} is above the cap of {} texels across",
                entry.size,
                limits::ATLAS_EXTENT
            ));
        }
    }
    if manifest.strands_per_bundle > limits::STRANDS_PER_BUNDLE {
        return Err(format!(
            "strands_per_bundle {} is above the cap of {} (export with fewer strands per bundle)",
            manifest.strands_per_bundle,
            limits::STRANDS_PER_BUNDLE
        ));
    }
    for (name, samples) in [
        ("quad_samples", &manifest.quad_samples),
        ("triangle_samples", &manifest.triangle_samples),
    ] {
        if samples.len() > limits::SAMPLES {
            return Err(format!(
                "{name} has {} entries, above the cap of {}",
                samples.len(),
                limits::SAMPLES
            ));
        }
    }
    for (name, count) in [
        ("column_layers", manifest.column_layers.len()),
        ("bare_faces", manifest.bare_faces.len()),
    ] {
        if count > limits::COLUMNS {
            return Err(format!(
                "{name} has {count} entries, above the cap of {}",
                limits::COLUMNS
            ));
        }
    }
    let lod = &manifest.lod;
    if lod.max_vertices_log2 > limits::MAX_VERTICES_LOG2 {
        return Err(format!(
            "lod.max_vertices_log2 {} is above the cap of {}",
            lod.max_vertices_log2,
            limits::MAX_VERTICES_LOG2
        ));
    }
    for (name, value) in [
        ("lod.alpha_strands", lod.alpha_strands),
        ("lod.alpha_vertices", lod.alpha_vertices),
        ("lod.lambda", lod.lambda),
    ] {
        if !value.is_finite() || value < 0.0 {
            return Err(format!("{name} {value} must be a finite number ≥ 0"));
        }
    }
    if !manifest.position_offset.iter().all(|c| c.is_finite()) {
        return Err("position_offset is not finite".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use super::*;
    use crate::model::mesh::test_meshes::grid;

    #[test]
    fn runtime_bundle_has_five_textures_and_a_manifest() {
        let document = Document::new("grid", grid(3, 2, 2, 0.5));
        let files = runtime_bundle(&document, &RuntimeOptions::default()).expect("export");
        let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names.len(), 7);
        for (name, stem) in names.iter().zip(["hair_mesh", "uv", "w", "u", "v"]) {
            assert!(
                name.starts_with(&format!("{stem}.")) && name.ends_with(".ktx2"),
                "{name}"
            );
            assert!(is_bundle_data_file(name), "{name}");
        }
        assert!(names[5].starts_with("far_hair.") && names[5].ends_with(".bin"));
        assert!(is_bundle_data_file(names[5]));
        assert_eq!(names[6], MANIFEST_FILE);
        // Names follow content: the same texture gets the same name, another a new one.
        assert_eq!(
            names[0],
            content_addressed_name("hair_mesh", "ktx2", &files[0].1)
        );
        assert_ne!(names[0], content_addressed_name("hair_mesh", "ktx2", b"x"));
        assert!(!is_bundle_data_file("notes.ktx2") && !is_bundle_data_file("w.12.ktx2"));
        let manifest: Manifest = serde_json::from_slice(&files[6].1).expect("manifest");
        assert_eq!(manifest.bundles.len(), 6);
        assert_eq!(manifest.format_version, RUNTIME_FORMAT_VERSION);
        assert_eq!(
            manifest.far_hair.as_ref().map(|f| f.file.as_str()),
            Some(names[5])
        );
        assert_eq!(manifest.hair_mesh.size[2], 1 + 3 * 2);
        assert_eq!(manifest.slices_per_segment, 3);
        assert_eq!(manifest.uv.size[2], 0);
        assert_eq!(manifest.quad_samples.len(), 256);
        let empty = Document::new("empty", grid(2, 2, 0, 0.5));
        assert!(matches!(
            runtime_bundle(&empty, &RuntimeOptions::default()),
            Err(ExportError::NothingToExport)
        ));
    }

    #[test]
    fn far_hair_round_trips_and_older_or_corrupt_far_hair_is_handled_by_name() {
        use crate::runtime::thick_hair::FarHair;
        let mut mesh = grid(3, 2, 2, 0.5);
        crate::geometry::interior::place_interior(&mut mesh, None);
        let document = Document::new("grid", mesh);
        let options = RuntimeOptions {
            strands_per_bundle: 16,
            ..RuntimeOptions::default()
        };
        let files: HashMap<String, Vec<u8>> = runtime_bundle(&document, &options)
            .expect("export")
            .into_iter()
            .collect();
        let loaded = load_runtime_asset_from(&files, "memory").expect("loads");
        let built = FarHair::build(
            &RuntimeHair::from_document(&document, &options),
            (1 << options.lod.max_vertices_log2) + 1,
        )
        .expect("builds");
        let far = loaded.far_hair.clone().expect("far hair");
        assert_eq!(far.thick_hairs, built.thick_hairs);
        assert_eq!(far.blocks.len(), built.blocks.len());
        for (a, b) in far
            .blocks
            .iter()
            .flatten()
            .zip(built.blocks.iter().flatten())
        {
            assert_eq!((a.first, a.count), (b.first, b.count));
            // Stored as f32.
            assert!((a.widest_m - b.widest_m).abs() <= 1e-6 * b.widest_m.max(1e-9));
        }
        let manifest: serde_json::Value =
            serde_json::from_slice(&files[MANIFEST_FILE]).expect("manifest");
        let far_file = manifest["far_hair"]["file"]
            .as_str()
            .expect("named")
            .to_string();
        // A version 2 bundle (no far hair) still loads, without it.
        let mut older = files.clone();
        let mut value = manifest.clone();
        value["format_version"] = 2.into();
        value.as_object_mut().expect("object").remove("far_hair");
        older.insert(
            MANIFEST_FILE.into(),
            serde_json::to_vec(&value).expect("json"),
        );
        older.remove(&far_file);
        let loaded = load_runtime_asset_from(&older, "memory").expect("version 2 loads");
        assert_eq!(loaded.far_hair, None);
        assert_eq!(loaded.hair.textures, textures_of(&files));
        // Damage to the file or disagreement with the manifest is named.
        let damaged = |edit: &dyn Fn(&mut Vec<u8>)| {
            let mut files = files.clone();
            edit(files.get_mut(&far_file).expect("file"));
            load_runtime_asset_from(&files, "memory")
                .expect_err("refused")
                .to_string()
        };
        let word_at = |bytes: &mut Vec<u8>, at: usize, value: u32| {
            bytes[at..at + 4].copy_from_slice(&value.to_le_bytes())
        };
        let hairs_at = |bytes: &Vec<u8>| {
            let levels = u32::from_le_bytes([bytes[12], bytes[13], bytes[14], bytes[15]]);
            24 + 16 * levels as usize
        };
        for (what, edit, expected) in [
            (
                "magic",
                Box::new(|b: &mut Vec<u8>| b[0] = b'X') as Box<dyn Fn(&mut Vec<u8>)>,
                "not a far-hair file",
            ),
            (
                "truncated",
                Box::new(|b: &mut Vec<u8>| {
                    b.pop();
                }),
                "bytes where",
            ),
            (
                "huge counts",
                Box::new(move |b: &mut Vec<u8>| word_at(b, 16, u32::MAX)),
                "bytes where",
            ),
            (
                "corner of another bundle",
                Box::new(move |b: &mut Vec<u8>| {
                    let at = hairs_at(b);
                    word_at(b, at, 16 * 5 + 1)
                }),
                "is not a grown strand of bundle",
            ),
            (
                "no members",
                Box::new(move |b: &mut Vec<u8>| {
                    let at = hairs_at(b) + 16;
                    word_at(b, at, 0)
                }),
                "members",
            ),
            (
                "overlapping levels",
                Box::new(move |b: &mut Vec<u8>| word_at(b, 24 + 16 + 4, 0)),
                "do not follow on",
            ),
            (
                "NaN width",
                Box::new(move |b: &mut Vec<u8>| word_at(b, 24 + 12, f32::NAN.to_bits())),
                "widest diameter",
            ),
        ] {
            let message = damaged(&*edit);
            assert!(
                message.contains(&far_file) && message.contains(expected),
                "{what}: {message}"
            );
        }
        let mut disagreeing = files.clone();
        let mut value = manifest.clone();
        value["far_hair"]["thick_hairs"] = 1.into();
        disagreeing.insert(
            MANIFEST_FILE.into(),
            serde_json::to_vec(&value).expect("json"),
        );
        let message = load_runtime_asset_from(&disagreeing, "memory")
            .expect_err("refused")
            .to_string();
        assert!(message.contains("far_hair lists"), "{message}");
        let mut outside = files.clone();
        let mut value = manifest;
        value["far_hair"]["file"] = "../far_hair.bin".into();
        outside.insert(
            MANIFEST_FILE.into(),
            serde_json::to_vec(&value).expect("json"),
        );
        assert!(load_runtime_asset_from(&outside, "memory").is_err());
    }

    #[test]
    fn painted_maps_travel_as_a_texture_and_hostile_entries_are_named() {
        use crate::model::root_maps::{RootMapChannel, RootMaps};
        let mut mesh = grid(3, 2, 2, 0.5);
        crate::geometry::interior::place_interior(&mut mesh, None);
        let mut document = Document::new("grid", mesh);
        let plain = runtime_bundle(&document, &RuntimeOptions::default()).expect("export");
        let plain_manifest: serde_json::Value = serde_json::from_slice(
            &plain
                .iter()
                .find(|(n, _)| n == MANIFEST_FILE)
                .expect("manifest")
                .1,
        )
        .expect("json");
        assert!(
            plain_manifest.get("root_maps").is_none(),
            "nothing painted, no texture"
        );
        let mut maps = RootMaps::blank(5, 3).expect("maps");
        maps.set_channel_from_image(RootMapChannel::Density, 2, 1, &[0.2, 0.9])
            .expect("density");
        maps.texels_mut()[7] = [1, 2, 3, 255];
        maps.colour_texels_mut()[4] = [200, 100, 50, 128];
        document.root_maps = maps.clone();
        let files: HashMap<String, Vec<u8>> = runtime_bundle(&document, &RuntimeOptions::default())
            .expect("export")
            .into_iter()
            .collect();
        assert_eq!(textures_of(&files).root_maps, maps);
        let manifest: serde_json::Value =
            serde_json::from_slice(&files[MANIFEST_FILE]).expect("json");
        assert_eq!(manifest["root_maps"]["vk_format"], "R8G8B8A8_UNORM");
        assert_eq!(manifest["root_maps"]["size"], serde_json::json!([5, 3, 0]));
        assert_eq!(manifest["colour_map"]["vk_format"], "R8G8B8A8_SRGB");
        // The colour map shares the grey maps' size, and needs them.
        let mut value = manifest.clone();
        value["colour_map"]["size"] = serde_json::json!([4, 3, 0]);
        let mut value_alone = manifest.clone();
        value_alone
            .as_object_mut()
            .expect("object")
            .remove("root_maps");
        for (value, names) in [
            (value, "is not root_maps'"),
            (value_alone, "without root_maps"),
        ] {
            let mut hostile = files.clone();
            hostile.insert(
                MANIFEST_FILE.into(),
                serde_json::to_vec(&value).expect("json"),
            );
            let Err(error) = load_runtime_asset_from(&hostile, "memory") else {
                panic!("{names}: refused");
            };
            assert!(error.to_string().contains(names), "{error}");
        }
        for (key, replacement, names) in [
            ("size", serde_json::json!([5000, 3, 0]), "larger than 4096"),
            ("size", serde_json::json!([5, 3, 1]), "2D texture"),
            ("size", serde_json::json!([6, 3, 0]), "does not match"),
            (
                "vk_format",
                "R32G32B32A32_SFLOAT".into(),
                "expected R8G8B8A8_UNORM",
            ),
            ("file", "../root_maps.ktx2".into(), "root_maps.ktx2"),
        ] {
            let mut value = manifest.clone();
            value["root_maps"][key] = replacement;
            let mut hostile = files.clone();
            hostile.insert(
                MANIFEST_FILE.into(),
                serde_json::to_vec(&value).expect("json"),
            );
            let Err(error) = load_runtime_asset_from(&hostile, "memory") else {
                panic!("{key}: refused");
            };
            let error = error.to_string();
            assert!(error.contains(names), "{key}: {error}");
        }
    }

    fn textures_of(files: &HashMap<String, Vec<u8>>) -> crate::runtime::textures::RuntimeTextures {
        load_runtime_asset_from(files, "memory")
            .expect("loads")
            .hair
            .textures
    }

    #[test]
    fn runtime_bundles_load_back_and_corruption_is_named() {
        use crate::runtime::strand_gen::{Filtering, StrandGen};
        let mut mesh = grid(3, 2, 2, 0.5);
        crate::geometry::interior::place_interior(&mut mesh, None);
        let mut document = Document::new("grid", mesh);
        // A material with an ombré (format version 10), which the scene carries.
        document.scene.material.ombre = Some(crate::model::scene::Ombre::default());
        let temp = tempfile::tempdir().expect("temp dir");
        let dir = temp.path().join("bundle");
        for precision in [Precision::F32, Precision::F16] {
            let options = RuntimeOptions {
                precision,
                ..RuntimeOptions::default()
            };
            let files = runtime_bundle(&document, &options).expect("export");
            write_bundle_folder(&dir, &files, |_| {}).expect("write");
            // Only the new bundle's files (and the export ledger) are left: the f32 textures
            // went with the f16 export.
            let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
                .expect("list")
                .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
                .collect();
            on_disk.sort();
            let mut written: Vec<String> = files
                .iter()
                .map(|(n, _)| n.clone())
                .chain([EXPORT_LEDGER_FILE.to_string()])
                .collect();
            written.sort();
            assert_eq!(on_disk, written);
            let loaded = load_runtime_bundle(&dir).expect("loads");
            assert_eq!(
                loaded.scene, document.scene,
                "the scene travels with the bundle"
            );
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
        // The scene travels with the bundle and is validated like a project's.
        let mut value: serde_json::Value = serde_json::from_slice(&original).expect("json");
        assert!(value["scene"]["material"]["pigment"].is_object());
        value["scene"]["material"]["ior"] = (-2.0).into();
        std::fs::write(&manifest_path, serde_json::to_vec(&value).expect("json")).expect("write");
        let error = load_runtime_bundle(&dir).expect_err("bad scene");
        assert!(error.to_string().contains("scene.material.ior"), "{error}");
        std::fs::write(&manifest_path, &original).expect("restore");
        let manifest: Manifest = serde_json::from_slice(&original).expect("manifest");
        let w_file = dir.join(&manifest.w.file);
        let texture = std::fs::read(&w_file).expect("w");
        std::fs::write(&w_file, &texture[..texture.len() / 2]).expect("truncate");
        let error = load_runtime_bundle(&dir).expect_err("truncated");
        assert!(error.to_string().contains(&manifest.w.file), "{error}");
    }

    /// A format version 1 bundle (4 hair-mesh slices per segment, the joint `m` stored) still
    /// loads, into today's 3-slice texture with the same strands; a manifest whose
    /// slices_per_segment disagrees with its version is refused by name.
    #[test]
    fn format_version_1_bundles_load_without_their_joint_slices() {
        use crate::runtime::strand_gen::{Filtering, StrandGen};
        let mut mesh = grid(3, 2, 3, 0.5);
        crate::geometry::interior::place_interior(&mut mesh, None);
        let document = Document::new("grid", mesh);
        let options = RuntimeOptions::default();
        let today = RuntimeHair::from_document(&document, &options);
        // Version 1's layout: p_k, q0, m, q1 per segment.
        let three = &today.textures.hair_mesh;
        let slice = (three.width * three.height) as usize;
        let layers = (three.depth - 1) / 3;
        let at = |z: u32| &three.texels[z as usize * slice..(z as usize + 1) * slice];
        let mut texels = Vec::new();
        for k in 0..layers {
            texels.extend_from_slice(at(3 * k));
            texels.extend_from_slice(at(3 * k + 1));
            texels.extend(
                at(3 * k + 1)
                    .iter()
                    .zip(at(3 * k + 2))
                    .map(|(a, b)| (*a + *b) * 0.5),
            );
            texels.extend_from_slice(at(3 * k + 2));
        }
        texels.extend_from_slice(at(3 * layers));
        let mut old = today.clone();
        old.textures.hair_mesh = Texture3d {
            depth: 1 + 4 * layers,
            texels,
            ..three.clone()
        };
        let mut files: HashMap<String, Vec<u8>> =
            bundle_files(&old).expect("export").into_iter().collect();
        let mut manifest: serde_json::Value =
            serde_json::from_slice(&files[MANIFEST_FILE]).expect("manifest");
        manifest["format_version"] = 1.into();
        manifest["slices_per_segment"] = 4.into();
        files.insert(
            MANIFEST_FILE.into(),
            serde_json::to_vec(&manifest).expect("json"),
        );
        let loaded = load_runtime_bundle_from(&files, "memory").expect("version 1 loads");
        assert_eq!(loaded.textures.hair_mesh, today.textures.hair_mesh);
        let (a, b) = (
            StrandGen {
                textures: &loaded.textures,
                filtering: Filtering::Exact,
            },
            StrandGen {
                textures: &today.textures,
                filtering: Filtering::Exact,
            },
        );
        for block in 0..today.textures.atlas.blocks.len() {
            for tau in [0.2, 0.7, 1.5, 2.9] {
                assert_eq!(
                    a.position(block, 0.3, 0.6, tau),
                    b.position(block, 0.3, 0.6, tau)
                );
            }
        }
        // Version 2 with 4 slices per segment is a contradiction, named.
        manifest["format_version"] = RUNTIME_FORMAT_VERSION.into();
        files.insert(
            MANIFEST_FILE.into(),
            serde_json::to_vec(&manifest).expect("json"),
        );
        let error = load_runtime_bundle_from(&files, "memory").expect_err("contradiction");
        assert!(
            error.to_string().contains("slices_per_segment 4"),
            "{error}"
        );
    }

    /// A thinned bundle's density travels through the manifest (absent when 1) and back, and
    /// the runtime strands grow only its share.
    #[test]
    fn bundle_density_round_trips_and_thins_the_runtime_strands() {
        let mut mesh = grid(2, 2, 1, 0.5);
        crate::geometry::interior::place_interior(&mut mesh, None);
        mesh.bundles[2].density = 0.25;
        let document = Document::new("grid", mesh);
        let options = RuntimeOptions {
            strands_per_bundle: 16,
            ..RuntimeOptions::default()
        };
        let files = runtime_bundle(&document, &options).expect("export");
        let manifest: serde_json::Value =
            serde_json::from_slice(&files[files.len() - 1].1).expect("json");
        let with_density = manifest["bundles"]
            .as_array()
            .expect("bundles")
            .iter()
            .filter(|b| b.get("density").is_some())
            .count();
        assert_eq!(with_density, 1, "only the thinned one");
        let loaded =
            load_runtime_bundle_from(&files.into_iter().collect::<HashMap<_, _>>(), "memory")
                .expect("loads");
        let built = RuntimeHair::from_document(&document, &options);
        assert_eq!(loaded.block_density, built.block_density);
        let block = built
            .textures
            .atlas
            .blocks
            .iter()
            .position(|b| b.bundle == 2)
            .expect("block of bundle 2");
        assert_eq!(built.block_density[block], 0.25);
        assert_eq!(built.block_strand_count(block), 4);
        let strands = crate::runtime::strand_gen::runtime_strands(
            &built,
            5,
            crate::runtime::strand_gen::Filtering::Exact,
        );
        assert_eq!(strands.len(), 3 * 16 + 4);
        assert_eq!(strands.iter().filter(|s| s.bundle == 2).count(), 4);
        // The CPU reference grows the same share.
        let reference = crate::strands::reference::generate(
            &document,
            &crate::strands::reference::StrandOptions {
                strands_per_bundle: 16,
                ..Default::default()
            },
        );
        assert_eq!(reference.iter().filter(|s| s.bundle == 2).count(), 4);
        assert_eq!(reference.len(), 3 * 16 + 4);
    }

    /// A bundle in memory, with its manifest as JSON to edit.
    fn bundle_in_memory() -> (HashMap<String, Vec<u8>>, serde_json::Value) {
        let mut mesh = grid(2, 2, 1, 0.5);
        crate::geometry::interior::place_interior(&mut mesh, None);
        let files = runtime_bundle(&Document::new("grid", mesh), &RuntimeOptions::default())
            .expect("export");
        let manifest = serde_json::from_slice(&files[files.len() - 1].1).expect("json");
        (files.into_iter().collect(), manifest)
    }

    fn load_with(edit: impl FnOnce(&mut serde_json::Value)) -> Result<RuntimeHair, BundleError> {
        let (mut files, mut manifest) = bundle_in_memory();
        edit(&mut manifest);
        files.insert(
            MANIFEST_FILE.into(),
            serde_json::to_vec(&manifest).expect("json"),
        );
        load_runtime_bundle_from(&files, "memory")
    }

    /// Format version 4 carries the mesh topology a game needs to rebuild the textures: each
    /// bundle's columns (the atlas's texels after loading), column layer counts, and the
    /// faces that grow no hair; it loads back as it was built.
    #[test]
    fn the_mesh_topology_round_trips_with_bare_faces() {
        let mut document = Document::new("grid", grid(3, 2, 2, 0.5));
        document.hair_mesh.bundles[4].layers = 0;
        let built = RuntimeHair::from_document(&document, &RuntimeOptions::default());
        assert_eq!(built.textures.topology.bare_faces.len(), 1);
        assert_eq!(
            built.textures.topology.bare_faces[0].columns,
            document.hair_mesh.bundles[4].vertices
        );
        let files: std::collections::HashMap<String, Vec<u8>> =
            bundle_files(&built).expect("export").into_iter().collect();
        let loaded = load_runtime_bundle_from(&files, "memory").expect("loads");
        assert_eq!(loaded.textures.topology, built.textures.topology);
        // Every texel knows its column again (its uv comes back as the f32 the file holds).
        let columns = |hair: &RuntimeHair| -> Vec<Option<u32>> {
            hair.textures
                .atlas
                .texels
                .iter()
                .map(|t| t.map(|t| t.column))
                .collect()
        };
        assert_eq!(columns(&loaded), columns(&built));
    }

    #[test]
    fn hostile_manifests_are_named_errors() {
        load_with(|_| {}).expect("the unedited bundle loads");
        type ManifestEdit = Box<dyn FnOnce(&mut serde_json::Value)>;
        let cases: Vec<(ManifestEdit, &str)> = vec![
            (
                Box::new(|m| m["bundles"][0]["origin"] = serde_json::json!([u32::MAX, 0])),
                "does not fit a 2x2 block",
            ),
            (
                Box::new(|m| m["strands_per_bundle"] = 100_000.into()),
                "strands_per_bundle 100000 is above the cap",
            ),
            (
                Box::new(|m| m["max_layers"] = 20_000.into()),
                "above the cap of 511 layers",
            ),
            (
                Box::new(|m| m["hair_mesh"]["size"] = serde_json::json!([65536, 65536, 268435456])),
                "above the cap of 16384 texels",
            ),
            (
                Box::new(|m| m["lod"]["max_vertices_log2"] = 40.into()),
                "max_vertices_log2 40",
            ),
            (
                Box::new(|m| m["w"]["file"] = "../../etc/passwd".into()),
                "\"../../etc/passwd\" is refused",
            ),
            (
                Box::new(|m| m["body"] = "/etc/passwd".into()),
                "\"/etc/passwd\" is refused",
            ),
            (
                Box::new(|m| m["body"] = "missing.glb".into()),
                "no such file",
            ),
            (
                Box::new(|m| m["bundles"][0]["density"] = 1.5.into()),
                "bundles[0].density 1.5 is outside [0, 1]",
            ),
            (
                Box::new(|m| m["bundles"][0]["columns"][2] = 1_000_000.into()),
                "bundles[0].columns[2] names column 1000000",
            ),
            (
                Box::new(|m| m["column_layers"][0] = 0.into()),
                "names column 0 of 0 layers",
            ),
            (
                Box::new(|m| m["column_layers"][1] = 600.into()),
                "column_layers[1] 600 is above max_layers",
            ),
            (
                Box::new(|m| {
                    m["bare_faces"] = serde_json::json!([
                        {"columns": [0, 1], "uvs": [[0, 0], [1, 0]], "positions": [[0, 0, 0], [1, 0, 0]]}
                    ])
                }),
                "bare_faces[0] has 2 columns",
            ),
            (
                Box::new(|m| {
                    m["bundles"][0]
                        .as_object_mut()
                        .expect("a bundle")
                        .remove("columns");
                }),
                "bundles[0] has no columns (format_version",
            ),
            (
                Box::new(|m| {
                    let other = m["bundles"][0]["columns"][0].as_u64().expect("a column") + 1;
                    m["bundles"][1]["columns"][0] = other.into();
                    m["bundles"][1]["origin"] = m["bundles"][0]["origin"].clone();
                }),
                "holds column",
            ),
        ];
        for (edit, expected) in cases {
            let error = load_with(edit).expect_err(expected).to_string();
            assert!(error.contains(expected), "{expected}: {error}");
        }
    }

    #[test]
    fn folder_bundles_never_read_outside_their_folder() {
        let temp = tempfile::tempdir().expect("temp dir");
        let dir = temp.path().join("bundle");
        let (files, mut manifest) = bundle_in_memory();
        let mut ordered: Vec<(String, Vec<u8>)> = files
            .into_iter()
            .filter(|(n, _)| n != MANIFEST_FILE)
            .collect();
        std::fs::write(temp.path().join("outside.ktx2"), b"secret").expect("write");
        for name in [
            "../outside.ktx2".to_string(),
            temp.path().join("outside.ktx2").display().to_string(),
            "file:///etc/passwd".into(),
        ] {
            manifest["uv"]["file"] = name.clone().into();
            ordered.push((
                MANIFEST_FILE.into(),
                serde_json::to_vec(&manifest).expect("json"),
            ));
            write_bundle_folder(&dir, &ordered, |_| {}).expect("write");
            ordered.pop();
            let error = load_runtime_bundle(&dir).expect_err(&name).to_string();
            assert!(error.contains("refused"), "{name}: {error}");
        }
        // A plain name that is a link out of the folder.
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(temp.path().join("outside.ktx2"), dir.join("link.ktx2"))
                .expect("link");
            manifest["uv"]["file"] = "link.ktx2".into();
            ordered.push((
                MANIFEST_FILE.into(),
                serde_json::to_vec(&manifest).expect("json"),
            ));
            write_bundle_folder(&dir, &ordered, |_| {}).expect("write");
            let error = load_runtime_bundle(&dir).expect_err("link").to_string();
            assert!(error.contains("outside the folder"), "{error}");
        }
    }
}
