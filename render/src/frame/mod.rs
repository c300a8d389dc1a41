//! One frame builder for every picture we draw: the editor's viewport, `hairloom render`, the
//! benches, and the game runtime recording into a game's own pass.
//!
//! The shape is re_renderer's: one renderer per feature owns its pipelines and says which
//! [`Phase`]s of a frame it takes part in ([`FrameRenderer`]); [`FrameRenderers`] holds the
//! renderers a scene's effects call for (an effect that is off has no renderer and no
//! resource); [`prepare`] builds the per-frame draw data from the scene and the hair (scene
//! uniforms, the views of the camera and of each shadow-casting light, the runs of the frame
//! plan, the generation scratch, the bind groups), and [`FrameRecorder`] records the passes in
//! [`Phase::ORDER`].
//!
//! # Adding an effect
//! 1. A renderer file under `renderer/` that owns its pipelines and resources, implementing
//!    [`FrameRenderer`] (its phases);
//! 2. one field and one line of [`FrameRenderers::sync`] that makes it while the scene's
//!    [`ActiveEffects`] name it and drops it otherwise;
//! 3. its draws in the phase it named, in [`FrameRecorder`].

mod prepare;
mod record;
mod renderers;

pub use prepare::{FrameCamera, FrameInputs, HairSource, PreparedFrame, frame_views, prepare};
pub use record::FrameRecorder;
pub use renderers::FrameRenderers;

use crate::renderer::scene_lighting::ActiveEffects;
use crate::renderer::strand_gen::StrandGenError;

/// The passes of a frame, in the order they are recorded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Phase {
    /// Strand generation into the frame's scratch (compute), before any pass reads it.
    Generation,
    /// Depth and opacity seen from each shadow-casting light.
    ShadowViews,
    /// The opaque body, clearing the view.
    Opaque,
    /// Fur (seed 002): fins near the silhouette, then shells from the innermost out, blended
    /// over the body; shells write depth where their alpha test passes, so strands behind
    /// them are hidden.
    Fur,
    /// The hair's depth alone, so that the lit pass shades each visible sample once.
    DepthPrePass,
    /// The lit hair where it is nearest.
    Lit,
    /// Width-based coverage: thin strands' weighted blended transparency.
    Coverage,
    /// Everything the view's passes accumulated, over the opaque picture.
    Composite,
}

impl Phase {
    pub const ORDER: [Phase; 8] = [
        Phase::Generation,
        Phase::ShadowViews,
        Phase::Opaque,
        Phase::Fur,
        Phase::DepthPrePass,
        Phase::Lit,
        Phase::Coverage,
        Phase::Composite,
    ];
}

/// A renderer of one feature: it owns its pipelines and resources and says which passes of a
/// frame it takes part in.
pub trait FrameRenderer {
    /// The feature's name, as the resource registry and the benches say it.
    fn name(&self) -> &'static str;
    /// The phases it records into.
    fn phases(&self) -> &'static [Phase];
}

/// Why a frame could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum FrameError {
    #[error(transparent)]
    Generation(StrandGenError),
    #[error("reading the frame back failed: {0}")]
    Readback(String),
    /// An effect's resource would exceed what the adapter allows; nothing was made.
    #[error("{0}")]
    EffectLimit(String),
    /// Far hair asked for where it cannot be drawn.
    #[error("scene.effects.far_hair: {0}")]
    FarHair(String),
}

/// Refuses effect resources the adapter cannot hold, naming the scene's field and the limit.
pub fn check_effect_limits(
    limits: &wgpu::Limits,
    active: &ActiveEffects,
) -> Result<(), FrameError> {
    if active.shadow_slots == 0 {
        return Ok(());
    }
    if active.shadow_resolution > limits.max_texture_dimension_2d {
        return Err(FrameError::EffectLimit(format!(
            "scene.effects.shadow_resolution: {} texels is above this adapter's max_texture_dimension_2d of {}",
            active.shadow_resolution, limits.max_texture_dimension_2d
        )));
    }
    let layers = active.shadow_slots * (active.opacity_layers / 4).max(1);
    if layers > limits.max_texture_array_layers {
        return Err(FrameError::EffectLimit(format!(
            "scene.effects.opacity_layers: {} layers for {} lights need {layers} texture layers, above this adapter's max_texture_array_layers of {}",
            active.opacity_layers, active.shadow_slots, limits.max_texture_array_layers
        )));
    }
    Ok(())
}
