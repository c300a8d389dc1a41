//! Measuring what each effect of the scene costs in this viewport's frame, on a worker
//! thread with the viewport's device: the Scene panel shows the numbers beside the switches.

use super::*;
use hairloom_render::hair_asset::HairAsset;
use hairloom_render::measure::{EffectCost, effect_costs, toggled_effects};

/// What an effect-cost measurement gives: the scene's frame first, then the frame with each
/// effect switched, or why it failed.
pub type EffectCostResult = Result<Vec<EffectCost>, String>;

impl Viewport {
    /// Whether the viewport has a GPU device (measurements need one).
    pub fn has_gpu(&self) -> bool {
        self.gpu.is_some()
    }

    /// Starts timing the frame of `document` as this viewport draws it (its size, camera,
    /// strand count and LOD) with the scene's effects, then with each effect switched; `None`
    /// without a GPU. The result arrives on the receiver; the UI asks for a repaint then.
    pub fn spawn_effect_costs(
        &self,
        document: &hairloom_core::Document,
        ctx: &egui::Context,
    ) -> Option<std::sync::mpsc::Receiver<EffectCostResult>> {
        let (context, generator) = self.gpu_handles()?;
        let document = document.clone();
        let settings = self.settings;
        let orbit = self.orbit;
        let camera_bounds = self.camera_bounds;
        let size = self.drawn.map_or([960, 720], |d| d.size);
        let (sender, receiver) = std::sync::mpsc::channel();
        let ctx = ctx.clone();
        std::thread::spawn(move || {
            let result = (|| -> anyhow::Result<Vec<EffectCost>> {
                // On this worker thread, never the UI's: the document's own asset.
                let mut asset = HairAsset::from_document(
                    &context,
                    &generator,
                    &document,
                    &RuntimeOptions {
                        precision: settings.precision,
                        strands_per_bundle: settings.strands_per_bundle,
                        ..RuntimeOptions::default()
                    },
                )?;
                // The far-hair row measures thick hairs: the hierarchy is built here.
                asset.ensure_far_hair(&context)?;
                // The fur row measures shells and fins: their textures are made here (a hair
                // with no root faces has none, and its fur row draws strands alone).
                asset
                    .ensure_fur(&context, &document.scene.effects.fur_shells)
                    .ok();
                let bounds = asset.bounds();
                let (lo, hi) = camera_bounds.unwrap_or(bounds);
                let scene = default_scene(
                    asset.body(),
                    asset.source(&generator, settings.filtering, settings.lod),
                    17,
                    bounds,
                    orbit.camera(lo, hi),
                    &document.scene,
                );
                let mut configurations = vec![("the scene", document.scene.effects.clone())];
                configurations.extend(toggled_effects(&document.scene.effects));
                Ok(effect_costs(
                    &context,
                    &scene,
                    &configurations,
                    size[0],
                    size[1],
                    1,
                )?)
            })()
            .map_err(|e| format!("{e:#}"));
            let _ = sender.send(result);
            ctx.request_repaint();
        });
        Some(receiver)
    }
}
