//! `hairloom bench effects`: what each lighting effect costs. At each strand count, the frame
//! with no optional effect, with each effect alone, with the project scene's own combination
//! and with every effect, measured side by side in one run: frame time (median after a
//! warm-up that compiles the pipelines) and the GPU memory the effects hold (from the
//! renderer's resource registry), with the difference to the plain frame.

use std::path::PathBuf;

use hairloom_core::model::scene::{
    Coverage, Effects, MultipleScattering, Scene, SelfShadowing, Shading,
};
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, default_scene};
use hairloom_render::renderer::preview_body::GpuBody;
use hairloom_render::renderer::strand_gen::StrandGenRenderer;

/// The configurations of one strand count: a name and its effects.
pub fn configurations(scene: &Effects) -> Vec<(&'static str, Effects)> {
    let none = scene.none();
    let with = |f: fn(&mut Effects)| {
        let mut effects = none.clone();
        f(&mut effects);
        effects
    };
    vec![
        ("nothing (Kajiya-Kay)", none.clone()),
        ("marschner", with(|e| e.shading = Shading::Marschner)),
        (
            "opacity-shadow-maps",
            with(|e| e.self_shadowing = SelfShadowing::OpacityShadowMaps),
        ),
        (
            "deep-opacity-maps",
            with(|e| e.self_shadowing = SelfShadowing::DeepOpacityMaps),
        ),
        ("body-shadows", with(|e| e.body_shadows = true)),
        (
            "marschner + dual-scattering",
            with(|e| {
                e.shading = Shading::Marschner;
                e.multiple_scattering = MultipleScattering::DualScattering;
            }),
        ),
        ("width-oit", with(|e| e.coverage = Coverage::WidthOit)),
        ("the scene's own", scene.clone()),
        ("everything", scene.all()),
    ]
}

pub fn run(
    project: Option<PathBuf>,
    strands: &[usize],
    size: &str,
    runs: usize,
) -> anyhow::Result<()> {
    let path = project.unwrap_or_else(hairloom_core::samples::default_sample_path);
    let (width, height) = super::render::parse_size(size)?;
    let document = hairloom_core::io::project::load(&path)?.document;
    let context = GpuContext::new_headless()?;
    let generator = StrandGenRenderer::new(&context);
    let body = GpuBody::upload(&context, &document.body);
    println!(
        "Effects on demand: frame time and GPU memory of each effect, {width}x{height}: {}",
        path.display()
    );
    println!("adapter: {}", describe(&context.adapter_info));
    println!("machine: {}", super::machine());
    println!(
        "scene effects: {}",
        if document.scene.effects.names().is_empty() {
            "none".to_string()
        } else {
            document.scene.effects.names().join(", ")
        }
    );
    println!(
        "{:>8} {:<28} {:>10} {:>10} {:>8} {:>11} {:>11}",
        "strands", "effects", "frame ms", "+ms", "×", "effect MB", "drawn"
    );
    let bundles = document.hair_mesh.bundles.len().max(1);
    for &count in strands {
        let per_bundle = count.div_ceil(bundles).clamp(1, 4096) as u32;
        let hair = RuntimeHair::from_document(
            &document,
            &RuntimeOptions {
                strands_per_bundle: per_bundle,
                ..RuntimeOptions::default()
            },
        );
        let gpu_hair = generator.upload(&context, &hair)?;
        let (lo, hi) = hair
            .textures
            .hair_bounds()
            .ok_or_else(|| anyhow::anyhow!("no bundle grows hair"))?;
        let pad = (hi - lo) * 0.05;
        let camera = Camera::framing(lo - pad, hi + pad, glam::Vec3::new(0.75, 0.25, 1.0));
        // One renderer for the whole table: effect resources come and go between rows, the
        // way the editor switches them.
        let renderer = PreviewRenderer::new(&context);
        let mut baseline: Option<(f64, u64)> = None;
        for (name, effects) in configurations(&document.scene.effects) {
            let lighting = Scene {
                effects,
                ..document.scene.clone()
            };
            let scene = default_scene(
                &body,
                HairSource::Generated {
                    generator: &generator,
                    hair: &gpu_hair,
                    filtering: Filtering::Exact,
                    lod: LodSettings {
                        enabled: false,
                        ..LodSettings::default()
                    },
                },
                17,
                (lo, hi),
                camera,
                &lighting,
            );
            let timing = super::bench::median_timing(
                || renderer.time_frame(&context, &scene, width, height),
                runs,
                |t| t.wall_ms,
            )?;
            let bytes = context.resources.live_bytes();
            let (base_ms, base_bytes) = *baseline.get_or_insert((timing.wall_ms, bytes));
            println!(
                "{:>8} {:<28} {:>10.1} {:>10.1} {:>7.2}× {:>11.2} {:>11}",
                gpu_hair.root_count,
                name,
                timing.wall_ms,
                timing.wall_ms - base_ms,
                timing.wall_ms / base_ms.max(1e-9),
                bytes.saturating_sub(base_bytes) as f64 / 1e6,
                timing.strands,
            );
        }
    }
    println!(
        "frame ms: wall time from submission to idle, median of {runs} after a warm-up (shadow maps, tables and pipelines are made in the warm-up); effect MB: GPU memory held beyond the plain frame's"
    );
    Ok(())
}
