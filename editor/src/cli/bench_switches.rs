//! `hairloom bench switches`: what the method's switches cost, measured side by side in one
//! run (seed 000 §5): styling on against every styling op off (the paper: 10-20 % of the
//! render time), each op alone against none (its generation cost), the material's ombré off
//! against on (its shading cost), MSAA 1× / 4× / 8×, and exact against hardware (8-bit) texture filtering
//! with the hardware weights' error beside their time — the measure the game runtime takes
//! on its own adapter to choose its default filtering ([`GameHair::filtering_measure`]).
//!
//! [`GameHair::filtering_measure`]: hairloom_render::game::GameHair::filtering_measure

use std::path::PathBuf;

use hairloom_core::model::styling::{StylingParams, StylingSet};
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, default_scene};
use hairloom_render::renderer::preview_body::GpuBody;
use hairloom_render::renderer::strand_gen::{GpuHair, StrandGenRenderer, full_detail_plan};

pub struct SwitchSettings {
    pub project: Option<PathBuf>,
    pub strands: Vec<usize>,
    pub size: String,
    pub runs: usize,
    /// Vertices per strand at full detail: 2^N + 1.
    pub vertices_log2: u32,
}

pub fn run(settings: &SwitchSettings) -> anyhow::Result<()> {
    let path = settings
        .project
        .clone()
        .unwrap_or_else(hairloom_core::samples::default_sample_path);
    let (width, height) = super::render::parse_size(&settings.size)?;
    let document = hairloom_core::io::project::load(&path)?.document;
    let context = GpuContext::new_headless()?;
    let trust = !context.is_cpu();
    let generator = StrandGenRenderer::new(&context);
    let body = GpuBody::upload(&context, &document.body);
    let vertex_count = (1u32 << settings.vertices_log2.clamp(1, 8)) + 1;
    // The method's own cost, as in `bench gpu`: no optional effect.
    let unlit = hairloom_core::model::scene::Scene {
        effects: document.scene.effects.none(),
        ..document.scene.clone()
    };
    let unstyled = hairloom_core::model::document::Document {
        styling: StylingSet::default(),
        ..document.clone()
    };
    let previews: Vec<(u32, PreviewRenderer)> = [1, 4, 8]
        .into_iter()
        .filter_map(|n| PreviewRenderer::try_with_sample_count(&context, n).map(|p| (n, p)))
        .collect();
    let default_samples = hairloom_render::view::sample_count(&context);
    println!(
        "Switch costs (one run, side by side; {vertex_count} vertices per strand, {width}x{height}, LOD off, no optional effect): {}",
        path.display()
    );
    println!("adapter: {}", describe(&context.adapter_info));
    println!("machine: {}", super::machine());
    println!(
        "times: GPU timestamps (* = wall time from submit to idle), median of {} after a warm-up; MSAA counts this adapter lacks are left out (has: {})",
        settings.runs,
        previews
            .iter()
            .map(|(n, _)| format!("{n}×"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    println!(
        "{:>8}  {:<10} {:<26} {:>12} {:>12} {:>9}  error",
        "strands", "switch", "setting", "generate ms", "frame ms", "× first"
    );
    for &target in &settings.strands {
        let runtime_of = |document: &hairloom_core::model::document::Document| {
            let mut hair = RuntimeHair::from_document(document, &RuntimeOptions::default());
            let bundles = hair.textures.atlas.blocks.len().max(1);
            hair.set_strands_per_bundle(target.div_ceil(bundles).clamp(1, 4096) as u32)
                .map(|_| hair)
        };
        let styled = runtime_of(&document)?;
        let plain = runtime_of(&unstyled)?;
        let styled_gpu = generator.upload(&context, &styled)?;
        let plain_gpu = generator.upload(&context, &plain)?;
        let (lo, hi) = styled
            .textures
            .hair_bounds()
            .ok_or_else(|| anyhow::anyhow!("no bundle grows hair"))?;
        let pad = (hi - lo) * 0.05;
        let camera = Camera::framing(lo - pad, hi + pad, glam::Vec3::new(0.75, 0.25, 1.0));
        let full = full_detail_plan(styled_gpu.root_count, vertex_count);
        let generate = |hair: &GpuHair, filtering| -> anyhow::Result<(f64, &'static str)> {
            let t = super::bench::median_timing(
                || generator.time_generation(&context, hair, &full, filtering),
                settings.runs,
                |t| t.wall_ms,
            )?;
            Ok(super::bench::gpu_or_wall(trust, t.gpu_ms, t.wall_ms))
        };
        let frame_in = |preview: &PreviewRenderer,
                        hair: &GpuHair,
                        filtering,
                        scene: &hairloom_core::model::scene::Scene|
         -> anyhow::Result<(f64, &'static str)> {
            let scene = default_scene(
                &body,
                HairSource::Generated {
                    generator: &generator,
                    hair,
                    filtering,
                    lod: LodSettings {
                        enabled: false,
                        ..LodSettings::default()
                    },
                    far: None,
                    fur: None,
                },
                vertex_count,
                (lo, hi),
                camera,
                scene,
            );
            let t = super::bench::median_timing(
                || preview.time_frame(&context, &scene, width, height),
                settings.runs,
                |t| t.wall_ms,
            )?;
            Ok(super::bench::gpu_or_wall(trust, t.gpu_ms, t.wall_ms))
        };
        let frame = |preview: &PreviewRenderer, hair: &GpuHair, filtering| {
            frame_in(preview, hair, filtering, &unlit)
        };
        let default_preview = previews
            .iter()
            .find(|(n, _)| *n == default_samples)
            .map(|(_, p)| p)
            .ok_or_else(|| anyhow::anyhow!("no preview at the default sample count"))?;
        let row = |switch: &str,
                   setting: &str,
                   generated: Option<(f64, &str)>,
                   framed: Option<(f64, &str)>,
                   ratio: Option<f64>,
                   error: &str| {
            let ms = |t: Option<(f64, &str)>| {
                t.map_or(String::new(), |(ms, mark)| format!("{ms:.2}{mark}"))
            };
            println!(
                "{:>8}  {:<10} {:<26} {:>12} {:>12} {:>9}  {error}",
                styled_gpu.root_count,
                switch,
                setting,
                ms(generated),
                ms(framed),
                ratio.map_or(String::new(), |r| format!("{r:.2}×")),
            );
        };

        // Styling: the sample's ops against none (the same strands, roots and mesh).
        let styled_generate = generate(&styled_gpu, Filtering::Exact)?;
        let plain_generate = generate(&plain_gpu, Filtering::Exact)?;
        let styled_frame = frame(default_preview, &styled_gpu, Filtering::Exact)?;
        let plain_frame = frame(default_preview, &plain_gpu, Filtering::Exact)?;
        row(
            "styling",
            "off (no op)",
            Some(plain_generate),
            Some(plain_frame),
            Some(1.0),
            "",
        );
        row(
            "styling",
            &format!("on (the sample's), {default_samples}× MSAA"),
            Some(styled_generate),
            Some(styled_frame),
            Some(styled_frame.0 / plain_frame.0),
            &format!(
                "generation {:.2}×; the frame saves {:.0} % without styling",
                styled_generate.0 / plain_generate.0,
                100.0 * (1.0 - plain_frame.0 / styled_frame.0)
            ),
        );

        // Each op alone (at the every-op setting) against none: generation, where styling
        // is paid.
        for (name, params) in StylingParams::each_op() {
            let alone = hairloom_core::model::document::Document {
                styling: StylingSet {
                    global: params,
                    groups: Vec::new(),
                },
                ..document.clone()
            };
            let hair = generator.upload(&context, &runtime_of(&alone)?)?;
            let t = generate(&hair, Filtering::Exact)?;
            row(
                "op alone",
                name,
                Some(t),
                None,
                Some(t.0 / plain_generate.0),
                "",
            );
        }

        // Colour along the strand: the material as it is against it with an ombré, which
        // shades every fragment past the ombré's start with one more colour blend and a `log`
        // per channel. Both frames measured here, side by side.
        let ombre_scene = hairloom_core::model::scene::Scene {
            material: hairloom_core::model::scene::HairMaterial {
                ombre: Some(hairloom_core::model::scene::Ombre::default()),
                ..unlit.material.clone()
            },
            ..unlit.clone()
        };
        let without_ombre = frame(default_preview, &styled_gpu, Filtering::Exact)?;
        let with_ombre = frame_in(default_preview, &styled_gpu, Filtering::Exact, &ombre_scene)?;
        row("ombré", "off", None, Some(without_ombre), Some(1.0), "");
        row(
            "ombré",
            "on (lightened ends)",
            None,
            Some(with_ombre),
            Some(with_ombre.0 / without_ombre.0),
            "",
        );

        // MSAA, the styled hair.
        let mut first = None;
        for (samples, preview) in &previews {
            let t = frame(preview, &styled_gpu, Filtering::Exact)?;
            let base = *first.get_or_insert(t.0);
            row(
                "MSAA",
                &format!("{samples}×"),
                None,
                Some(t),
                Some(t.0 / base),
                "",
            );
        }

        // Filtering: time and the 8-bit weights' error; the error is the game runtime's own
        // measure (over the first 8,192 strands).
        let measure = generator.measure_filtering(
            &context,
            &styled_gpu,
            vertex_count,
            0.5 * hairloom_render::preview::default_strand_width_m(lo, hi) as f64,
        )?;
        let exact_frame = styled_frame;
        row(
            "filtering",
            "exact",
            Some(styled_generate),
            Some(exact_frame),
            Some(1.0),
            "",
        );
        match generator.check_filtering(&context, Filtering::Hardware8Bit) {
            Ok(()) => {
                let hardware_generate = generate(&styled_gpu, Filtering::Hardware8Bit)?;
                let hardware_frame = frame(default_preview, &styled_gpu, Filtering::Hardware8Bit)?;
                row(
                    "filtering",
                    "hardware (8-bit weights)",
                    Some(hardware_generate),
                    Some(hardware_frame),
                    Some(hardware_frame.0 / exact_frame.0),
                    &format!(
                        "generation {:.2}×; max {:.3} µm, mean {:.3} µm off exact ({} strands; half a strand's width: {:.0} µm)",
                        hardware_generate.0 / styled_generate.0,
                        measure.hardware_error_max_m * 1e6,
                        measure.hardware_error_mean_m * 1e6,
                        measure.strands,
                        measure.tolerance_m * 1e6,
                    ),
                );
            }
            Err(error) => row(
                "filtering",
                "hardware",
                None,
                None,
                None,
                &error.to_string(),
            ),
        }
        println!(
            "{:>8}  the game runtime on this adapter chooses: {:?} (exact {:.2} ms, hardware {} over its {} measured strands; hardware where ≥ 5 % faster and within half a strand's width)",
            styled_gpu.root_count,
            measure.choice(),
            measure.exact_ms,
            measure
                .hardware_ms
                .map_or("not filterable".into(), |ms| format!("{ms:.2} ms")),
            measure.strands
        );
    }
    println!(
        "Seed 000 (RTX 4090): all styling off saves 10-20 % of the render time; 300K strands 1.8 ms without MSAA, 3.3 ms with 8× (1.83×)."
    );
    Ok(())
}
