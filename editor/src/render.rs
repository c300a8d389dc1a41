//! `hairloom render`: a headless picture through the game's path. Strands are generated on
//! the GPU from the runtime textures (`strand_gen.wgsl`) every frame and drawn by the preview
//! renderer; a project is turned into the same textures, roots and styling an export would
//! write, so rendering a project and rendering its exported runtime bundle give the same
//! image (tested in `editor/tests/cli.rs`).

use std::path::Path;

use anyhow::{Context, bail};
use glam::Vec3;
use hairloom_core::io::runtime_bundle::load_runtime_bundle;
use hairloom_core::model::document::BodyMesh;
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{DEFAULT_STRANDS_PER_BUNDLE, RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::textures::Precision;
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, PreviewScene};
use hairloom_render::strand_gen::StrandGenRenderer;

/// Vertices per strand in previews by default: 2^4 + 1.
pub const PREVIEW_VERTICES_LOG2: u32 = 4;

/// Settings of a headless render.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub size: String,
    /// `None`: the runtime bundle's own count, or [`DEFAULT_STRANDS_PER_BUNDLE`].
    pub strands_per_bundle: Option<u32>,
    pub view: String,
    pub vertices_log2: u32,
    /// Texture precision of a project render (a runtime bundle has its own).
    pub precision: Precision,
    pub filtering: Filtering,
    pub lod: LodSettings,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            size: "960x960".into(),
            strands_per_bundle: None,
            view: "three-quarter".into(),
            vertices_log2: PREVIEW_VERTICES_LOG2,
            precision: Precision::F32,
            filtering: Filtering::Exact,
            lod: LodSettings::default(),
        }
    }
}

pub fn parse_size(size: &str) -> anyhow::Result<(u32, u32)> {
    let (w, h) = size
        .split_once('x')
        .context("--size must look like 960x960")?;
    let (w, h): (u32, u32) = (w.trim().parse()?, h.trim().parse()?);
    if w == 0 || h == 0 || w > 8192 || h > 8192 {
        bail!("--size {w}x{h}: each side must be 1 to 8192 pixels");
    }
    Ok((w, h))
}

pub fn parse_view(view: &str) -> anyhow::Result<Vec3> {
    Ok(match view {
        "front" => Vec3::new(0.0, 0.1, 1.0),
        "side" => Vec3::new(1.0, 0.1, 0.0),
        "back" => Vec3::new(0.0, 0.2, -1.0),
        "three-quarter" => Vec3::new(0.75, 0.25, 1.0),
        custom => {
            let parts: Vec<f32> = custom
                .split(',')
                .map(|p| p.trim().parse())
                .collect::<Result<_, _>>()
                .with_context(|| format!("--view {custom:?}"))?;
            let [x, y, z] = parts[..] else {
                bail!("--view takes front, side, back, three-quarter or x,y,z")
            };
            let direction = Vec3::new(x, y, z);
            if !direction.is_finite() || direction.length() == 0.0 {
                bail!("--view {custom:?} is not a direction");
            }
            direction
        }
    })
}

/// The runtime asset a render draws: a runtime bundle folder (the game's input) as stored,
/// or a project turned into what an export with `settings` would write.
pub fn load_hair(path: &Path, settings: &RenderSettings) -> anyhow::Result<RuntimeHair> {
    if path.is_dir() {
        let mut hair = load_runtime_bundle(path)?;
        if let Some(per_bundle) = settings.strands_per_bundle {
            hair.set_strands_per_bundle(per_bundle)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        }
        Ok(hair)
    } else {
        let project = hairloom_core::io::project::load(path)?;
        Ok(RuntimeHair::from_document(
            &project.document,
            &RuntimeOptions {
                precision: settings.precision,
                strands_per_bundle: settings
                    .strands_per_bundle
                    .unwrap_or(DEFAULT_STRANDS_PER_BUNDLE),
                ..RuntimeOptions::default()
            },
        ))
    }
}

/// The look every Hairloom picture shares (renders, the editor's viewport, benchmarks):
/// brown strands a little over a thousandth of the hair's size wide, a skin-toned body.
pub fn default_scene<'a>(
    body: &'a BodyMesh,
    hair: HairSource<'a>,
    vertex_count: u32,
    (lo, hi): (Vec3, Vec3),
    camera: Camera,
) -> PreviewScene<'a> {
    PreviewScene {
        body_positions: &body.positions,
        body_triangles: &body.triangles,
        hair,
        vertex_count,
        strand_width_m: (hi - lo).length() * 0.0012,
        // Linear colours (the target is sRGB): dark brown roots, lighter tips.
        root_color: [0.018, 0.008, 0.004],
        tip_color: [0.16, 0.075, 0.03],
        body_color: [0.55, 0.38, 0.30],
        camera,
    }
}

/// Draws `hair` seen from `direction`; returns RGBA8 pixels and a one-line description.
pub fn render_pixels(
    context: &GpuContext,
    hair: &RuntimeHair,
    width: u32,
    height: u32,
    direction: Vec3,
    settings: &RenderSettings,
) -> anyhow::Result<(Vec<u8>, String)> {
    let (vertices_log2, filtering) = (settings.vertices_log2, settings.filtering);
    let generator = StrandGenRenderer::new(context);
    let gpu_hair = generator.upload(context, hair);
    let vertex_count = (1u32 << vertices_log2.min(8)) + 1;
    // Frame the hair (the head scan's shoulders would make it tiny), padded by a margin.
    let (lo, hi) = hair
        .textures
        .hair_bounds()
        .context("nothing to render: no bundle grows hair")?;
    let pad = (hi - lo) * 0.05;
    let camera = Camera::framing(lo - pad, hi + pad, direction);
    let renderer = PreviewRenderer::new(context);
    let scene = default_scene(
        &hair.body,
        HairSource::Generated {
            generator: &generator,
            hair: &gpu_hair,
            filtering,
            lod: settings.lod,
        },
        vertex_count,
        (lo, hi),
        camera,
    );
    let plan = renderer.plan(&scene, width, height);
    let pixels = renderer.render(context, &scene, &plan, width, height)?;
    let summary = format!(
        "{width}x{height}, {} of {} strands ({} vertices, LOD {}) generated on the GPU ({:?} filtering, {:?} textures), {}× MSAA, on {}",
        plan.strands,
        gpu_hair.root_count,
        plan.vertices,
        if settings.lod.enabled { "on" } else { "off" },
        filtering,
        hair.textures.precision,
        renderer.sample_count,
        describe(&context.adapter_info)
    );
    Ok((pixels, summary))
}

/// RGBA8 pixels as a PNG file, written atomically.
pub fn write_png(out: &Path, pixels: &[u8], width: u32, height: u32) -> anyhow::Result<()> {
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        pixels,
        width,
        height,
        image::ExtendedColorType::Rgba8,
    )
    .context("encoding PNG")?;
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    hairloom_core::io::project::write_atomic(out, &png, |_| {})
        .with_context(|| format!("writing {}", out.display()))
}

pub fn run(input: &Path, out: &Path, settings: &RenderSettings) -> anyhow::Result<()> {
    let (width, height) = parse_size(&settings.size)?;
    let direction = parse_view(&settings.view)?;
    let hair = load_hair(input, settings)?;
    let context = GpuContext::new_headless()?;
    let (pixels, summary) = render_pixels(&context, &hair, width, height, direction, settings)?;
    write_png(out, &pixels, width, height)?;
    println!("{}: {summary}", out.display());
    Ok(())
}

/// One accuracy switch setting measured on the GPU against f32 textures with exact
/// filtering (the setting the CPU mirror tests pin to 1e-5 × size).
#[derive(Clone, Debug, PartialEq)]
pub struct AccuracyRow {
    pub precision: Precision,
    pub filtering: Filtering,
    pub max_error_m: f64,
    pub mean_error_m: f64,
    /// GPU time of generating every strand at full detail (timestamps), else wall time.
    pub generation_ms: f64,
    pub timed_on_gpu: bool,
    /// Submit-to-idle wall time of the same work (what a CPU adapter really costs).
    pub wall_ms: f64,
    /// Why this device cannot run the setting (then the numbers are NaN).
    pub unavailable: Option<String>,
}

/// Generates the document's strands (full detail, `vertex_count` vertices each) with every
/// precision × filtering setting and measures each against f32 + exact.
pub fn measure_accuracy(
    context: &GpuContext,
    generator: &StrandGenRenderer,
    document: &hairloom_core::Document,
    strands_per_bundle: u32,
    vertex_count: u32,
) -> anyhow::Result<Vec<AccuracyRow>> {
    let settings = [
        (Precision::F32, Filtering::Exact),
        (Precision::F32, Filtering::Hardware8Bit),
        (Precision::F16, Filtering::Exact),
        (Precision::F16, Filtering::Hardware8Bit),
    ];
    let mut reference: Option<Vec<[f32; 4]>> = None;
    let mut rows = Vec::new();
    for (precision, filtering) in settings {
        let hair = RuntimeHair::from_document(
            document,
            &RuntimeOptions {
                precision,
                strands_per_bundle,
                ..RuntimeOptions::default()
            },
        );
        let gpu = generator.upload(context, &hair);
        let plan = hairloom_render::strand_gen::full_detail_plan(gpu.root_count, vertex_count);
        let generated = generator
            .generate_positions(context, &gpu, &plan, filtering)
            .and_then(|p| {
                Ok((
                    p,
                    generator.time_generation(context, &gpu, &plan, filtering)?,
                ))
            });
        let (positions, timing) = match generated {
            Ok(generated) => generated,
            // The reference must run; another setting may be unsupported by the device.
            Err(error) if reference.is_some() => {
                rows.push(AccuracyRow {
                    precision,
                    filtering,
                    max_error_m: f64::NAN,
                    mean_error_m: f64::NAN,
                    generation_ms: f64::NAN,
                    timed_on_gpu: false,
                    wall_ms: f64::NAN,
                    unavailable: Some(error.to_string()),
                });
                continue;
            }
            Err(error) => return Err(error.into()),
        };
        let reference = reference.get_or_insert_with(|| positions.clone());
        let (mut max, mut sum) = (0.0f64, 0.0f64);
        for (a, b) in positions.iter().zip(reference.iter()) {
            let d = Vec3::from_slice(&a[..3]).distance(Vec3::from_slice(&b[..3])) as f64;
            max = max.max(d);
            sum += d;
        }
        rows.push(AccuracyRow {
            precision,
            filtering,
            max_error_m: max,
            mean_error_m: sum / positions.len().max(1) as f64,
            generation_ms: timing.gpu_ms.unwrap_or(timing.wall_ms),
            timed_on_gpu: timing.gpu_ms.is_some(),
            wall_ms: timing.wall_ms,
            unavailable: None,
        });
    }
    Ok(rows)
}
