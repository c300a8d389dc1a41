//! `hairloom render`: a headless picture through the game's path. Strands are generated on
//! the GPU from the runtime textures (`strand_gen.wgsl`) every frame and drawn by the preview
//! renderer; a project is turned into the same textures, roots and styling an export would
//! write, so rendering a project and rendering its exported runtime bundle give the same
//! image (tested in `editor/tests/cli.rs`).

use std::path::Path;

use anyhow::{Context, bail};
use glam::Vec3;
use hairloom_core::io::runtime_bundle::load_runtime_bundle;
use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::scene::Scene;
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{DEFAULT_STRANDS_PER_BUNDLE, RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::textures::Precision;
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::hair_asset::{AssetChange, HairAsset};
use hairloom_render::preview::{Camera, PreviewRenderer, default_scene};
use hairloom_render::renderer::strand_gen::{GenerationPath, StrandGenRenderer};

/// The longest simulated time a command accepts (`--time`, `--seconds`): bounded work.
pub const MAX_SIMULATED_S: f64 = 600.0;

/// Vertices per strand in previews by default: 2^4 + 1.
pub const PREVIEW_VERTICES_LOG2: u32 = 4;

/// Settings of a headless render.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub size: String,
    /// `None`: the runtime bundle's own count, or [`DEFAULT_STRANDS_PER_BUNDLE`].
    pub strands_per_bundle: Option<u32>,
    pub view: String,
    /// `--effects`: none, all or a list overriding the scene's effects (see
    /// [`hairloom_core::model::scene::Effects::parse_list`]).
    pub effects: Option<String>,
    /// Camera distance as a multiple of the framing distance.
    pub distance: f32,
    /// `None`: what the hair's styling needs ([`RuntimeHair::strand_vertices_log2`]).
    ///
    /// [`RuntimeHair::strand_vertices_log2`]: hairloom_core::runtime::hair::RuntimeHair::strand_vertices_log2
    pub vertices_log2: Option<u32>,
    /// Texture precision of a project render (a runtime bundle has its own).
    pub precision: Precision,
    pub filtering: Filtering,
    /// Where strands are generated (compute per strand by default).
    pub generation: GenerationPath,
    pub lod: LodSettings,
    /// `--time`: simulate the scene's motion to this time first (projects only).
    pub time_s: f64,
    /// `--turntable N`: N pictures around the hair (0: one picture).
    pub turntable: u32,
    /// How far the camera and the lights are turned about the vertical through the hair's
    /// centre (a turntable's frame).
    pub turn_rad: f64,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            size: "960x960".into(),
            strands_per_bundle: None,
            view: "three-quarter".into(),
            effects: None,
            distance: 1.0,
            vertices_log2: None,
            precision: Precision::F32,
            filtering: Filtering::Exact,
            generation: GenerationPath::default(),
            lod: LodSettings::default(),
            time_s: 0.0,
            turntable: 0,
            turn_rad: 0.0,
        }
    }
}

/// The most frames `--turntable` makes (one a degree).
pub const MAX_TURNTABLE_FRAMES: u32 = 360;

/// Frame `index` of a turntable of `out`: `NAME_007.png` beside `NAME.png`.
pub fn turntable_frame_path(out: &Path, index: u32) -> std::path::PathBuf {
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "turntable".into());
    let name = match out.extension() {
        Some(extension) => format!("{stem}_{index:03}.{}", extension.to_string_lossy()),
        None => format!("{stem}_{index:03}"),
    };
    out.with_file_name(name)
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

/// A camera direction: one of the scene's presets by name, or `x,y,z`.
pub fn parse_view(view: &str, scene: &Scene) -> anyhow::Result<Vec3> {
    if let Some(preset) = scene.camera(view) {
        return Ok(Vec3::from(preset.direction));
    }
    let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
    let parts: Option<Vec<f32>> = view.split(',').map(|p| p.trim().parse().ok()).collect();
    let Some([x, y, z]) = parts.as_deref().and_then(|p| <[f32; 3]>::try_from(p).ok()) else {
        bail!(
            "--view {view:?}: takes a camera of the scene ({}) or x,y,z",
            names.join(", ")
        )
    };
    let direction = Vec3::new(x, y, z);
    if !direction.is_finite() || direction.length() == 0.0 {
        bail!("--view {view:?} is not a direction");
    }
    Ok(direction)
}

/// `document` at `time_s` of its scene's motion: simulated from the start when the scene has
/// motion, as modelled when it has none (no simulator is made).
pub fn posed_at(
    document: &hairloom_core::Document,
    time_s: f64,
) -> std::borrow::Cow<'_, hairloom_core::Document> {
    match &document.scene.motion {
        // Time 0 too: the body's first key may not be its modelled pose.
        Some(motion) => {
            let mut sim = hairloom_core::simulate::simulator(document, motion);
            hairloom_editor::progress::seek_with_progress(&mut sim, time_s);
            std::borrow::Cow::Owned(hairloom_core::simulate::posed_document(document, &sim))
        }
        None => std::borrow::Cow::Borrowed(document),
    }
}

/// The runtime asset a render draws: a runtime bundle folder (the game's input) as stored,
/// or a project turned into what an export with `settings` would write.
pub fn load_hair(path: &Path, settings: &RenderSettings) -> anyhow::Result<RuntimeHair> {
    if path.is_dir() {
        if settings.time_s != 0.0 {
            bail!("--time needs a project: a runtime bundle holds no hair mesh to simulate");
        }
        let mut hair = load_runtime_bundle(path)?;
        if let Some(per_bundle) = settings.strands_per_bundle {
            hair.set_strands_per_bundle(per_bundle)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        }
        Ok(hair)
    } else {
        let project = hairloom_core::io::project::load(path)?;
        let document = posed_at(&project.document, settings.time_s);
        Ok(RuntimeHair::from_document(
            &document,
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

/// The GPU renderers of a headless picture and the hair asset they draw, made once and reused
/// for every frame of a sequence (`hairloom simulate`: each posed frame moves the asset's
/// textures in place).
pub struct HeadlessRenderer {
    generator: StrandGenRenderer,
    preview: PreviewRenderer,
    asset: Option<HairAsset>,
}

impl HeadlessRenderer {
    pub fn new(context: &GpuContext, generation: GenerationPath) -> Self {
        Self {
            generator: StrandGenRenderer::with_path(context, generation),
            preview: PreviewRenderer::new(context),
            asset: None,
        }
    }

    /// Takes `hair`, a change of `kind` from what was shown before, to the GPU; returns what
    /// was done (a reshape whose texture layout changed is a rebuild).
    pub fn show(
        &mut self,
        context: &GpuContext,
        hair: RuntimeHair,
        kind: ChangeKind,
    ) -> anyhow::Result<ChangeKind> {
        let change = AssetChange::Hair {
            hair: Box::new(hair),
            kind,
        };
        HairAsset::apply_to(&mut self.asset, context, &self.generator, change)
            .context("nothing to render")
    }

    /// Draws the shown hair seen from `direction` with a camera framing the box `frame`;
    /// returns RGBA8 pixels and a one-line description.
    pub fn draw(
        &mut self,
        context: &GpuContext,
        (width, height): (u32, u32),
        frame: (Vec3, Vec3),
        direction: Vec3,
        settings: &RenderSettings,
    ) -> anyhow::Result<(Vec<u8>, String)> {
        let lighting = {
            let asset = self
                .asset
                .as_mut()
                .context("nothing to render: no hair shown")?;
            let lighting = scene_for(asset.hair(), settings)?;
            if lighting.effects.far_hair == hairloom_core::model::scene::FarHair::Aggregated {
                asset
                    .ensure_far_hair(context)
                    .context("far hair's hierarchy")?;
            }
            if lighting.effects.fur == hairloom_core::model::scene::Fur::ShellsFins {
                asset
                    .ensure_fur(context, &lighting.effects.fur_shells)
                    .context("fur's shells and fins")?;
            }
            lighting
        };
        let asset = self.asset.as_ref().context("nothing to render")?;
        let hair = asset.hair();
        let vertices_log2 = settings
            .vertices_log2
            .unwrap_or_else(|| asset.strand_vertices_log2());
        let vertex_count = (1u32 << vertices_log2.min(8)) + 1;
        let mut camera = Camera::framing(frame.0, frame.1, direction);
        camera.eye = camera.target + (camera.eye - camera.target) * settings.distance;
        let scene = default_scene(
            asset.body(),
            asset.source(&self.generator, settings.filtering, settings.lod),
            vertex_count,
            asset.bounds(),
            camera,
            &lighting,
        );
        let renderer = &self.preview;
        // A still picture draws far hair at the levels a still camera settles on.
        renderer.settle_far_levels(context, &scene, width, height)?;
        let plan = renderer.plan(&scene, width, height);
        let pixels = renderer.render(context, &scene, &plan, width, height)?;
        let names = lighting.effects.names();
        let far = if plan.far_levels.is_empty() {
            String::new()
        } else {
            format!(", {} bundles as far hair", plan.far_bundles)
        };
        let summary = format!(
            "{width}x{height}, {} of {} strands ({} vertices, LOD {}){far} generated on the GPU ({:?} filtering, {:?} textures), effects: {}, {}× MSAA, on {}",
            plan.strands,
            asset.gpu().root_count,
            plan.vertices,
            if settings.lod.enabled { "on" } else { "off" },
            settings.filtering,
            hair.textures.precision,
            if names.is_empty() {
                "none (Kajiya-Kay)".to_string()
            } else {
                names.join(", ")
            },
            renderer.sample_count,
            describe(&context.adapter_info)
        );
        Ok((pixels, summary))
    }
}

/// The box a still picture frames: the hair's bounds, padded by 5% (the head scan's
/// shoulders would make the hair tiny).
pub fn still_frame(hair: &RuntimeHair) -> anyhow::Result<(Vec3, Vec3)> {
    let (lo, hi) = hair
        .textures
        .hair_bounds()
        .context("nothing to render: no bundle grows hair")?;
    let pad = (hi - lo) * 0.05;
    Ok((lo - pad, hi + pad))
}

/// Draws `hair` seen from `direction`; returns RGBA8 pixels and a one-line description.
pub fn render_pixels(
    context: &GpuContext,
    hair: RuntimeHair,
    width: u32,
    height: u32,
    direction: Vec3,
    settings: &RenderSettings,
) -> anyhow::Result<(Vec<u8>, String)> {
    let frame = still_frame(&hair)?;
    let mut renderer = HeadlessRenderer::new(context, settings.generation);
    renderer.show(context, hair, ChangeKind::Rebuild)?;
    renderer.draw(context, (width, height), frame, direction, settings)
}

/// RGBA8 pixels as a PNG file, written atomically.
pub fn write_png(out: &Path, pixels: &[u8], width: u32, height: u32) -> anyhow::Result<()> {
    let png = hairloom_editor::files::encode_png(pixels, width, height, 4)?;
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    hairloom_core::io::project::write_atomic(out, &png, |_| {})
        .with_context(|| format!("writing {}", out.display()))
}

/// The asset's scene with `--effects` applied, its lights turned with a turntable's camera.
pub fn scene_for(hair: &RuntimeHair, settings: &RenderSettings) -> anyhow::Result<Scene> {
    let mut scene = hair.scene.clone();
    if settings.turn_rad != 0.0 {
        let centre = hair
            .textures
            .hair_bounds()
            .map_or(glam::DVec3::ZERO, |(lo, hi)| ((lo + hi) * 0.5).as_dvec3());
        scene = scene.lights_turned(settings.turn_rad, centre);
    }
    if let Some(list) = &settings.effects {
        scene.effects = scene.effects.parse_list(list).map_err(anyhow::Error::msg)?;
    }
    Ok(scene)
}

pub fn run(input: &Path, out: &Path, settings: &RenderSettings) -> anyhow::Result<()> {
    let (width, height) = parse_size(&settings.size)?;
    if !(settings.time_s.is_finite() && (0.0..=MAX_SIMULATED_S).contains(&settings.time_s)) {
        bail!(
            "--time {}: must be between 0 and {MAX_SIMULATED_S} s",
            settings.time_s
        );
    }
    let hair = load_hair(input, settings)?;
    let direction = parse_view(&settings.view, &hair.scene)?;
    scene_for(&hair, settings)?;
    if settings.turntable > MAX_TURNTABLE_FRAMES {
        bail!(
            "--turntable {}: at most {MAX_TURNTABLE_FRAMES} frames",
            settings.turntable
        );
    }
    let context = GpuContext::new_headless()?;
    if settings.turntable == 0 {
        let (pixels, summary) = render_pixels(&context, hair, width, height, direction, settings)?;
        write_png(out, &pixels, width, height)?;
        println!("{}: {summary}", out.display());
        return Ok(());
    }
    // A turntable: the camera and the lights go round the hair together, the asset made once.
    let frame = still_frame(&hair)?;
    let mut renderer = HeadlessRenderer::new(&context, settings.generation);
    renderer.show(&context, hair, ChangeKind::Rebuild)?;
    for index in 0..settings.turntable {
        let turn_rad = std::f64::consts::TAU * index as f64 / settings.turntable as f64;
        let turned = RenderSettings {
            turn_rad,
            ..settings.clone()
        };
        let view = glam::DQuat::from_rotation_y(turn_rad) * direction.as_dvec3();
        let (pixels, summary) =
            renderer.draw(&context, (width, height), frame, view.as_vec3(), &turned)?;
        let path = turntable_frame_path(out, index);
        write_png(&path, &pixels, width, height)?;
        println!(
            "{} ({:.0}°): {summary}",
            path.display(),
            turn_rad.to_degrees()
        );
    }
    Ok(())
}
