//! `hairloom bench effects`: what each lighting effect costs. At each strand count, the frame
//! with no optional effect, with each effect alone, with the project scene's own combination
//! and with every effect, measured side by side in one run: frame time (median after a
//! warm-up that compiles the pipelines) and the GPU memory the effects hold (from the
//! renderer's resource registry), with the difference to the plain frame.

use std::path::PathBuf;

use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::RuntimeOptions;
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::hair_asset::HairAsset;
use hairloom_render::measure::{effect_configurations, effect_costs};
use hairloom_render::preview::{Camera, default_scene};
use hairloom_render::renderer::strand_gen::StrandGenRenderer;

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
        let asset = HairAsset::from_document(
            &context,
            &generator,
            &document,
            &RuntimeOptions {
                strands_per_bundle: per_bundle,
                ..RuntimeOptions::default()
            },
        )?;
        let (lo, hi) = asset.bounds();
        let pad = (hi - lo) * 0.05;
        let camera = Camera::framing(lo - pad, hi + pad, glam::Vec3::new(0.75, 0.25, 1.0));
        let scene = default_scene(
            asset.body(),
            asset.source(
                &generator,
                Filtering::Exact,
                LodSettings {
                    enabled: false,
                    ..LodSettings::default()
                },
            ),
            17,
            (lo, hi),
            camera,
            &document.scene,
        );
        let costs = effect_costs(
            &context,
            &scene,
            &effect_configurations(&document.scene.effects),
            width,
            height,
            runs,
        )?;
        let (base_ms, base_bytes) = (costs[0].frame_ms, costs[0].live_bytes);
        for cost in &costs {
            println!(
                "{:>8} {:<28} {:>10.1} {:>10.1} {:>7.2}× {:>11.2} {:>11}",
                asset.gpu().root_count,
                cost.name,
                cost.frame_ms,
                cost.frame_ms - base_ms,
                cost.frame_ms / base_ms.max(1e-9),
                cost.live_bytes.saturating_sub(base_bytes) as f64 / 1e6,
                cost.strands,
            );
        }
    }
    println!(
        "frame ms: wall time from submission to idle, median of {runs} after a warm-up (shadow maps, tables and pipelines are made in the warm-up); effect MB: GPU memory held beyond the plain frame's"
    );
    Ok(())
}
