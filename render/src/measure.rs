//! Measuring the GPU path: every precision × filtering switch of strand generation, its
//! error against f32 textures with exact filtering and its time, side by side. The editor's
//! Strands & accuracy panel and `hairloom bench` both show these rows.

use glam::Vec3;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::textures::Precision;

use crate::device::GpuContext;
use crate::renderer::strand_gen::{StrandGenError, StrandGenRenderer, full_detail_plan};

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
) -> Result<Vec<AccuracyRow>, StrandGenError> {
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
        let gpu = generator.upload(context, &hair)?;
        let plan = full_detail_plan(gpu.root_count, vertex_count);
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
            Err(error) => return Err(error),
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

/// What one effect configuration costs, measured on a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct EffectCost {
    pub name: &'static str,
    pub effects: hairloom_core::model::scene::Effects,
    /// Median wall time of the frame, submission to idle (after a warm-up that makes the
    /// effect's maps, tables and pipelines).
    pub frame_ms: f64,
    /// Summed GPU pass time by timestamps, where the adapter has them.
    pub gpu_ms: Option<f64>,
    /// GPU bytes alive while this configuration is drawn (registry of the device).
    pub live_bytes: u64,
    pub strands: usize,
}

/// The frame with no optional effect, each effect alone, the scene's own combination and
/// everything: what `hairloom bench effects` measures.
pub fn effect_configurations(
    scene: &hairloom_core::model::scene::Effects,
) -> Vec<(&'static str, hairloom_core::model::scene::Effects)> {
    let none = scene.none();
    let list = [
        ("nothing (Kajiya-Kay)", "none"),
        ("marschner", "marschner"),
        ("opacity-shadow-maps", "opacity-shadow-maps"),
        ("deep-opacity-maps", "deep-opacity-maps"),
        ("body-shadows", "body-shadows"),
        ("marschner + dual-scattering", "marschner,dual-scattering"),
        ("width-oit", "width-oit"),
    ];
    let mut configurations: Vec<_> = list
        .iter()
        .map(|(name, effects)| {
            (
                *name,
                none.parse_list(effects).expect("the configurations parse"),
            )
        })
        .collect();
    configurations.push(("the scene's own", scene.clone()));
    configurations.push(("everything", scene.all()));
    configurations
}

/// The scene's effects with one effect switched (on when it is off, off when it is on), for
/// each effect: what the editor's Scene panel measures to put a cost beside each switch.
/// Self-shadowing switches between the scene's kind (or deep opacity maps) and none.
pub fn toggled_effects(
    effects: &hairloom_core::model::scene::Effects,
) -> Vec<(&'static str, hairloom_core::model::scene::Effects)> {
    use hairloom_core::model::scene::{
        Coverage, FarHair, Fur, MultipleScattering, SelfShadowing, Shading,
    };
    let mut list = Vec::new();
    let mut e = effects.clone();
    e.shading = match e.shading {
        Shading::KajiyaKay => Shading::Marschner,
        Shading::Marschner => Shading::KajiyaKay,
    };
    list.push(("marschner", e));
    let mut e = effects.clone();
    e.self_shadowing = match e.self_shadowing {
        SelfShadowing::None => SelfShadowing::DeepOpacityMaps,
        _ => SelfShadowing::None,
    };
    list.push(("self-shadowing", e));
    let mut e = effects.clone();
    e.body_shadows = !e.body_shadows;
    list.push(("body-shadows", e));
    let mut e = effects.clone();
    e.multiple_scattering = match e.multiple_scattering {
        MultipleScattering::None => MultipleScattering::DualScattering,
        MultipleScattering::DualScattering => MultipleScattering::None,
    };
    list.push(("dual-scattering", e));
    let mut e = effects.clone();
    e.coverage = match e.coverage {
        Coverage::Msaa => Coverage::WidthOit,
        Coverage::WidthOit => Coverage::Msaa,
    };
    list.push(("width-oit", e));
    let mut e = effects.clone();
    e.far_hair = match e.far_hair {
        FarHair::Strands => FarHair::Aggregated,
        FarHair::Aggregated => FarHair::Strands,
    };
    list.push(("far-hair", e));
    let mut e = effects.clone();
    e.fur = match e.fur {
        Fur::Off => Fur::ShellsFins,
        Fur::ShellsFins => Fur::Off,
    };
    list.push(("fur", e));
    list
}

/// Times `scene` with each of `configurations` in place of its effects, one renderer for all
/// (effect resources come and go between rows, as when an artist switches them): median of
/// `runs` frames after a warm-up.
pub fn effect_costs(
    context: &GpuContext,
    scene: &crate::preview::PreviewScene,
    configurations: &[(&'static str, hairloom_core::model::scene::Effects)],
    width: u32,
    height: u32,
    runs: usize,
) -> Result<Vec<EffectCost>, crate::preview::PreviewError> {
    let renderer = crate::preview::PreviewRenderer::new(context);
    let mut costs = Vec::with_capacity(configurations.len());
    for (name, effects) in configurations {
        let lighting = hairloom_core::model::scene::Scene {
            effects: effects.clone(),
            ..scene.lighting.clone()
        };
        let scene = crate::preview::PreviewScene {
            lighting: &lighting,
            hair: scene.hair,
            ..*scene
        };
        renderer.time_frame(context, &scene, width, height)?;
        let mut timings = Vec::with_capacity(runs.max(1));
        for _ in 0..runs.max(1) {
            timings.push(renderer.time_frame(context, &scene, width, height)?);
        }
        timings.sort_by(|a, b| a.wall_ms.total_cmp(&b.wall_ms));
        let median = timings[timings.len() / 2];
        costs.push(EffectCost {
            name,
            effects: effects.clone(),
            frame_ms: median.wall_ms,
            gpu_ms: median.gpu_ms,
            live_bytes: context.resources.live_bytes(),
            strands: median.strands,
        });
    }
    Ok(costs)
}
