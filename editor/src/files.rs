//! File work shared by the command line and the editor: importing a glTF scalp as a
//! document, and exporting the runtime bundle and strand files (each written atomically).
//! Long work reports progress through a callback that may also cancel it.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use hairloom_core::Document;
use hairloom_core::io::alembic::{AlembicTarget, groom::Groom, groom_file};
use hairloom_core::io::import::{ImportOptions, ImportedMesh, import_file};
use hairloom_core::io::project::write_atomic;
use hairloom_core::io::runtime_bundle::{runtime_bundle, write_bundle_folder};
use hairloom_core::io::scalp_region::ScalpRegion;
use hairloom_core::io::strand_files::{
    ScalpMesh, StrandExportSize, StrandLook, glb_lines, hair_file, usda_file,
};
use hairloom_core::model::document::BodyMesh;
use hairloom_core::runtime::hair::{LodEntry, RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::{Filtering, runtime_strands};
use hairloom_core::runtime::textures::Precision;
use hairloom_core::strands::reference::{Strand, StrandContext, StrandOptions, StrandPlan};

/// Root width of the strands in the strand files (80 µm, a typical human hair); each
/// tapers to 40 % of it at the tip.
pub const STRAND_WIDTH_M: f32 = 8e-5;

/// Strands have 2^N + 1 vertices in exported strand files and at a runtime bundle's full
/// detail unless asked otherwise.
pub const EXPORT_VERTICES_LOG2: u32 = hairloom_core::runtime::hair::DEFAULT_MAX_VERTICES_LOG2;

/// What an export takes by default: [`EXPORT_VERTICES_LOG2`], or more where the styling's
/// curls and waves need it (8 segments a turn: the curly sample's ringlets 65 vertices), so
/// a game or another tool gets the curls the viewport shows.
pub fn export_vertices_log2(document: &Document) -> u32 {
    EXPORT_VERTICES_LOG2.max(document.strand_vertices_log2())
}

/// The strand file formats, by extension.
pub const STRAND_EXTENSIONS: [&str; 4] = ["hair", "usda", "glb", "abc"];

/// A document made from a glTF/GLB scalp (every face in `region` becomes a bare bundle, the
/// whole mesh the body), and a one-line summary of what was read.
pub fn scalp_document(
    scalp: &Path,
    options: &ImportOptions,
    region: &ScalpRegion,
    generate_uv: bool,
) -> anyhow::Result<(Document, String)> {
    if !(options.scale.is_finite() && options.scale > 0.0) {
        bail!("the scale must be a positive number, got {}", options.scale);
    }
    let imported = import_file(scalp, options)?;
    let body = imported.to_body();
    scalp_document_from(scalp, &imported, body, region, generate_uv)
}

/// [`scalp_document`] from a mesh already read (the editor reads the file once, then asks
/// where hair grows), with `body` the body: the mesh's own, or every mesh of the file.
pub fn scalp_document_from(
    scalp: &Path,
    imported: &ImportedMesh,
    body: BodyMesh,
    region: &ScalpRegion,
    generate_uv: bool,
) -> anyhow::Result<(Document, String)> {
    let keep = region
        .faces(imported)
        .with_context(|| format!("{}: where hair grows", scalp.display()))?;
    let mut hair_mesh = imported.to_hair_mesh(|f| keep[f]);
    if generate_uv || !imported.has_uv {
        hairloom_core::geometry::uv::generate_uv(&mut hair_mesh, None);
    }
    let name = scalp
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scalp".into());
    let mut document = Document::new(name, hair_mesh);
    document.source = format!("imported from {}", scalp.display());
    document.body = body;
    // The file's body animation becomes the scene's head animation: the scene then has
    // motion, and the hair is simulated following the body.
    let animation = if imported.body_animation.is_empty() {
        String::new()
    } else {
        let keys = imported.body_animation.clone();
        let seconds = keys.last().map_or(0.0, |k| k.time_s);
        let count = keys.len();
        document.scene.motion = Some(hairloom_core::model::motion::Motion {
            head_animation: keys,
            ..Default::default()
        });
        format!("; body animation: {count} keys over {seconds:.2} s, in the Scene panel's Motion")
    };
    document
        .validate()
        .with_context(|| format!("{} produced an invalid document", scalp.display()))?;
    let kept = |corners: usize| {
        (imported.faces.iter().zip(&keep))
            .filter(|(face, keep)| **keep && face.len() == corners)
            .count()
    };
    let region_text = if *region == ScalpRegion::All {
        String::new()
    } else {
        format!(
            " with hair on {region} (body only: {})",
            hairloom_core::io::scalp_region::face_count(keep.iter().filter(|k| !**k).count())
        )
    };
    let summary = format!(
        "{}: {} quads, {} triangles{region_text} ({} source triangles, {} collapsed by welding){}",
        scalp.display(),
        kept(4),
        kept(3),
        imported.source_triangles,
        imported.degenerate_triangles,
        if imported.has_uv {
            ""
        } else {
            "; uv generated (the file has no TEXCOORD_0)"
        },
    ) + &animation;
    Ok((document, summary))
}

/// Which curves a strand file holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StrandCurve {
    /// The exact cubic curves through the hair mesh (the f64 reference generator).
    Exact,
    /// The strands as the runtime generates them: the textures' piecewise quadratics at their
    /// precision, exact filtering, f32 — to compare a game's own loader with.
    Runtime,
}

/// `document`'s strands as a runtime bundle exported with these settings draws them at full
/// detail.
fn runtime_curve_strands(
    document: &Document,
    precision: Precision,
    strands_per_bundle: u32,
    vertices_log2: u32,
) -> anyhow::Result<Vec<Strand>> {
    check_export_size(document, strands_per_bundle, vertices_log2)?;
    let hair = RuntimeHair::from_document(
        document,
        &runtime_options(precision, strands_per_bundle, vertices_log2),
    );
    let mut strands = runtime_strands(&hair, (1usize << vertices_log2) + 1, Filtering::Exact);
    // Strands the hairline op does not grow lie at their root: nothing for another tool.
    strands.retain(|strand| strand.length_fraction > 0.0);
    Ok(strands)
}

/// How a runtime bundle is exported: `2^vertices_log2 + 1` vertices per strand at full detail.
fn runtime_options(
    precision: Precision,
    strands_per_bundle: u32,
    vertices_log2: u32,
) -> RuntimeOptions {
    RuntimeOptions {
        precision,
        strands_per_bundle,
        lod: LodEntry {
            max_vertices_log2: vertices_log2,
            ..LodEntry::default()
        },
        ..RuntimeOptions::default()
    }
}

/// Writes the runtime bundle of `document` into `dir` (created when missing), its strands
/// `2^vertices_log2 + 1` vertices at full detail (`lod.max_vertices_log2`); returns a
/// one-line summary.
pub fn write_runtime_bundle(
    document: &Document,
    dir: &Path,
    precision: Precision,
    strands_per_bundle: u32,
    vertices_log2: u32,
) -> anyhow::Result<String> {
    let options = runtime_options(precision, strands_per_bundle, vertices_log2);
    let files = runtime_bundle(document, &options)
        .with_context(|| format!("exporting {}", document.name))?;
    write_bundle_folder(dir, &files, |_| {})
        .with_context(|| format!("writing the runtime bundle {}", dir.display()))?;
    let total: usize = files.iter().map(|(_, b)| b.len()).sum();
    Ok(format!(
        "{}: runtime bundle, {} files, {:.1} KiB",
        dir.display(),
        files.len(),
        total as f64 / 1024.0
    ))
}

/// Refuses a strand file whose extension names no format we write.
pub fn check_strand_file(file: &Path) -> anyhow::Result<()> {
    let extension = file.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !STRAND_EXTENSIONS.contains(&extension) {
        bail!(
            "{}: unknown strand format (use .hair, .usda, .glb or .abc)",
            file.display()
        );
    }
    Ok(())
}

/// Generates every strand; `progress` gets the fraction done after each bundle and may
/// stop the work (`Ok(None)` then). An export above the cap on points
/// ([`StrandExportSize::check`]) is refused before anything is generated.
pub fn generate_strands(
    document: &Document,
    strands_per_bundle: u32,
    vertices_log2: u32,
    progress: &mut dyn FnMut(f32) -> ControlFlow<()>,
) -> anyhow::Result<Option<Vec<Strand>>> {
    check_export_size(document, strands_per_bundle, vertices_log2)?;
    let options = StrandOptions {
        strands_per_bundle,
        vertices_log2,
        ..StrandOptions::default()
    };
    let context = StrandContext::new(document);
    let plan = StrandPlan::new(&options);
    let bundle_count = document.hair_mesh.bundles.len();
    let mut strands = Vec::new();
    for index in 0..bundle_count {
        strands.extend(plan.bundle_strands(&context, index));
        if progress((index + 1) as f32 / bundle_count.max(1) as f32).is_break() {
            return Ok(None);
        }
    }
    Ok(Some(strands))
}

/// Writes `strands`, grown from `document`, in the format `file`'s extension names (an
/// Alembic groom in `alembic`'s axes and units); returns a one-line summary.
pub fn write_strand_file(
    strands: &[Strand],
    document: &Document,
    file: &Path,
    alembic: AlembicTarget,
) -> anyhow::Result<String> {
    check_strand_file(file)?;
    let look = || {
        StrandLook::new(
            strands,
            STRAND_WIDTH_M,
            &document.scene.material,
            &document.root_maps,
        )
    };
    let bytes = match file.extension().and_then(|e| e.to_str()) {
        Some("hair") => hair_file(strands, &look()),
        Some("usda") => {
            usda_file(strands, &ScalpMesh::of(&document.hair_mesh), &look()).into_bytes()
        }
        Some("abc") => groom_file(&Groom::new(document, strands, STRAND_WIDTH_M), alembic)
            .map_err(anyhow::Error::msg)?,
        _ => glb_lines(strands),
    };
    write_atomic(file, &bytes, |_| {}).with_context(|| format!("writing {}", file.display()))?;
    let points: usize = strands.iter().map(|s| s.points.len()).sum();
    Ok(format!(
        "{}: {} strands, {} points, {:.1} KiB",
        file.display(),
        strands.len(),
        points,
        bytes.len() as f64 / 1024.0
    ))
}

/// How `hairloom export` grows and writes strands.
#[derive(Clone, Copy, Debug)]
pub struct ExportOptions {
    pub strands_per_bundle: u32,
    /// `None`: [`export_vertices_log2`] of the project.
    pub vertices_log2: Option<u32>,
    pub precision: Precision,
    pub curve: StrandCurve,
    /// The application `.abc` files are written for (axes and units).
    pub alembic: AlembicTarget,
}

/// `hairloom export`: the runtime bundle and/or strand files of a project, with a progress
/// line on a terminal's standard error.
pub fn run(
    project_path: &Path,
    runtime: Option<&Path>,
    strand_files: &[PathBuf],
    options: &ExportOptions,
) -> anyhow::Result<()> {
    let ExportOptions {
        strands_per_bundle,
        vertices_log2,
        precision,
        curve,
        alembic,
    } = *options;
    if runtime.is_none() && strand_files.is_empty() {
        bail!(
            "nothing to export: give --runtime DIR, --strands FILE.{{hair,usda,glb,abc}} and/or --cards DIR"
        );
    }
    if let Some(n) = vertices_log2 {
        check_vertices_log2(n)?;
    }
    for file in strand_files {
        check_strand_file(file)?;
    }
    let project = hairloom_core::io::project::load(project_path)?;
    let document = &project.document;
    let vertices_log2 = vertices_log2.unwrap_or_else(|| export_vertices_log2(document));
    if let Some(dir) = runtime {
        let summary =
            write_runtime_bundle(document, dir, precision, strands_per_bundle, vertices_log2)
                .with_context(|| format!("exporting {}", project_path.display()))?;
        println!("{summary}");
    }
    if !strand_files.is_empty() {
        let mut bar = crate::progress::TerminalProgress::new("generating strands");
        let strands = match curve {
            StrandCurve::Runtime => {
                runtime_curve_strands(document, precision, strands_per_bundle, vertices_log2)?
            }
            StrandCurve::Exact => {
                generate_strands(document, strands_per_bundle, vertices_log2, &mut |done| {
                    bar.update(done as f64);
                    ControlFlow::Continue(())
                })?
                .unwrap_or_default()
            }
        };
        bar.finish();
        for file in strand_files {
            println!("{}", write_strand_file(&strands, document, file, alembic)?);
        }
    }
    Ok(())
}

/// Refuses a strand export above the cap on points before anything is generated.
fn check_export_size(
    document: &Document,
    strands_per_bundle: u32,
    vertices_log2: u32,
) -> anyhow::Result<()> {
    StrandExportSize::of(&document.hair_mesh, strands_per_bundle, vertices_log2)
        .check()
        .map_err(|e| {
            anyhow::anyhow!(
                "{e}: lower the strands per bundle or the vertices per strand (--strands-per-bundle, --vertices-log2)"
            )
        })
}

/// Refuses strands of more than `2^MAX_VERTICES_LOG2 + 1` vertices (the runtime bundle's
/// cap, which every export shares), naming the flag.
fn check_vertices_log2(vertices_log2: u32) -> anyhow::Result<()> {
    let cap = hairloom_core::io::runtime_bundle::limits::MAX_VERTICES_LOG2;
    if vertices_log2 > cap {
        bail!(
            "--vertices-log2 {vertices_log2} is more than {cap} ({} vertices per strand)",
            (1u32 << cap) + 1
        );
    }
    Ok(())
}

/// A PNG of `pixels` (`channels`: 1, 3 or 4 of 8 bits each).
pub fn encode_png(pixels: &[u8], width: u32, height: u32, channels: u8) -> anyhow::Result<Vec<u8>> {
    let kind = match channels {
        1 => image::ExtendedColorType::L8,
        3 => image::ExtendedColorType::Rgb8,
        _ => image::ExtendedColorType::Rgba8,
    };
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        pixels,
        width,
        height,
        kind,
    )
    .context("encoding PNG")?;
    Ok(png)
}

/// `hairloom export --cards DIR`: hair cards of `document`'s bundles, baked from
/// `strands_per_bundle` strands per bundle with `2^vertices_log2 + 1` vertices: one GLB per
/// level of detail (`cards_lod0.glb` …, the albedo atlas embedded), the atlas's maps as PNG
/// and `cards.json` describing them. Returns a one-line summary.
pub fn write_cards(
    document: &Document,
    dir: &Path,
    strands_per_bundle: u32,
    vertices_log2: u32,
) -> anyhow::Result<String> {
    use hairloom_core::cards::{CardOptions, hair_cards};
    use hairloom_core::io::cards_gltf::{CARD_MAPS, CardMap, card_glb};
    check_vertices_log2(vertices_log2)?;
    let strands = generate_strands(document, strands_per_bundle, vertices_log2, &mut |_| {
        ControlFlow::Continue(())
    })?
    .unwrap_or_default();
    let options = CardOptions::default();
    let cards = hair_cards(document, &strands, &options);
    if cards.cards == 0 {
        bail!("no cards to export: no bundle grows hair");
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let atlas = &cards.atlas;
    let (w, h) = (atlas.width, atlas.height);
    let write = |name: &str, bytes: &[u8]| -> anyhow::Result<()> {
        let path = dir.join(name);
        write_atomic(&path, bytes, |_| {}).with_context(|| format!("writing {}", path.display()))
    };
    let albedo = encode_png(&atlas.albedo, w, h, 4)?;
    write("albedo.png", &albedo)?;
    let maps: [(&str, &[u8], u8); 5] = [
        ("coverage", &atlas.coverage, 1),
        ("depth", &atlas.depth, 1),
        ("flow", &atlas.flow, 3),
        ("root_to_tip", &atlas.root_to_tip, 1),
        ("id", &atlas.id, 1),
    ];
    debug_assert_eq!(maps.map(|m| m.0), CARD_MAPS);
    let mut map_files = Vec::new();
    let mut map_pngs = Vec::new();
    for (name, pixels, channels) in maps {
        let file = format!("{name}.png");
        let png = encode_png(pixels, w, h, channels)?;
        write(&file, &png)?;
        map_files.push((name, file));
        map_pngs.push(png);
    }
    let embedded: Vec<CardMap> = map_files
        .iter()
        .zip(&map_pngs)
        .map(|((name, file), png)| CardMap {
            name,
            file: file.clone(),
            png,
        })
        .collect();
    // Unreal's card texture set, beside the rest in unreal/.
    std::fs::create_dir_all(dir.join("unreal"))
        .with_context(|| format!("creating {}", dir.join("unreal").display()))?;
    let mut unreal = serde_json::Map::new();
    for (stem, channels, pixels) in atlas.unreal_textures() {
        let file = format!("unreal/{stem}.png");
        write(&file, &encode_png(&pixels, w, h, channels)?)?;
        unreal.insert(stem.to_string(), file.into());
    }
    let mut levels = Vec::new();
    for (level, mesh) in cards.levels.iter().enumerate() {
        let file = format!("cards_lod{level}.glb");
        write(
            &file,
            &card_glb(&format!("hair_cards_lod{level}"), mesh, &albedo, &embedded),
        )?;
        levels.push(serde_json::json!({
            "file": file,
            "triangles": mesh.triangles(),
            "vertices": mesh.positions.len(),
        }));
    }
    let manifest = serde_json::json!({
        "generator": format!("hairloom {}", env!("CARGO_PKG_VERSION")),
        "cards": cards.cards,
        "levels": levels,
        "atlas": {
            "width": w, "height": h,
            "albedo": "albedo.png",
            "maps": map_files.iter().map(|(k, v)| (k.to_string(), serde_json::Value::from(v.clone()))).collect::<serde_json::Map<_, _>>(),
            "depth_range_m": cards.depth_range_m,
            "unreal": unreal,
            "tile_px": options.tile_px,
        },
        "baked_from": {"strands": strands.len(), "points": cards.baked_points},
    });
    write(
        "cards.json",
        &serde_json::to_vec_pretty(&manifest).context("writing the card manifest")?,
    )?;
    let triangles: Vec<String> = cards
        .levels
        .iter()
        .map(|m| m.triangles().to_string())
        .collect();
    Ok(format!(
        "{}: {} cards, levels of {} triangles, {w}×{h} atlas baked from {} strands",
        dir.display(),
        cards.cards,
        triangles.join(" / "),
        strands.len()
    ))
}
