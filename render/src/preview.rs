//! The preview frame, built from the scene's effects: shadow passes for each shadow-casting
//! light when the scene asks for self-shadowing or body shadows
//! ([`crate::renderer::hair_shadow`], [`crate::renderer::body_shadow`]), the lit body
//! ([`crate::renderer::preview_body`]), the hair as viewer-facing ribbons lit by Kajiya-Kay or
//! the Marschner model, with dual scattering when asked ([`crate::renderer::preview_hair`]),
//! and the thin strands' order-independent coverage when asked
//! ([`crate::renderer::oit_composite`]); depth-tested, 8× or 4× MSAA where the adapter
//! supports it, into a kept [`View`] that is read back as RGBA8 pixels or sampled by the
//! editor. An effect the scene does not name has no pass and no resource (the registry,
//! [`crate::resources`], lists what exists).
//!
//! Strand vertices arrive in a storage buffer, strand-major ([`HairSource`]): generated on
//! the GPU from the runtime textures every frame, batch by batch into one bounded scratch
//! buffer (the paper's path and the game's), or stored (vertices generated beforehand: the
//! explicit-storage baseline, and the CPU reference).

use std::sync::Mutex;

use glam::{Mat4, Vec3};
use hairloom_core::model::scene::Scene;
use hairloom_core::runtime::frame_plan::{FramePlan, LodSettings, plan_frame};

use crate::device::{GpuContext, PassTimer, submit_timed};
use crate::frame::{FrameCamera, FrameInputs, FrameRecorder, FrameRenderers, Phase, prepare};
pub use crate::frame::{FrameError as PreviewError, HairSource, check_effect_limits};
use crate::renderer::Targets;
use crate::renderer::fur::strand_keep;
use crate::renderer::preview_body::GpuBody;
use crate::renderer::scene_lighting::ActiveEffects;
use crate::renderer::strand_gen::batch_vertex_limit;
use crate::view::View;

/// A perspective camera looking at `target`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov_y_rad: f32,
}

impl Camera {
    /// Frames the box `(min, max)` seen from `direction` (toward the camera), so that its
    /// bounding sphere fills the view.
    pub fn framing(min: Vec3, max: Vec3, direction: Vec3) -> Self {
        let center = (min + max) * 0.5;
        let radius = ((max - min).length() * 0.5).max(1e-6);
        let fov_y_rad = 30f32.to_radians();
        let distance = radius / (fov_y_rad * 0.5).sin() * 0.8;
        Self {
            eye: center + direction.normalize_or(Vec3::Z) * distance,
            target: center,
            up: Vec3::Y,
            fov_y_rad,
        }
    }

    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        let distance = self.eye.distance(self.target).max(1e-6);
        let projection = Mat4::perspective_rh(
            self.fov_y_rad,
            aspect.max(1e-6),
            distance * 0.01,
            distance * 10.0,
        );
        projection * Mat4::look_at_rh(self.eye, self.target, self.up)
    }
}

/// What to draw.
pub struct PreviewScene<'a> {
    /// The body, uploaded once per document.
    pub body: &'a GpuBody,
    pub hair: HairSource<'a>,
    /// Vertices per strand at full detail (`2^e + 1`).
    pub vertex_count: u32,
    pub strand_width_m: f32,
    /// Lights, material, background and the effects that run (a document's scene, or a
    /// render's override of it).
    pub lighting: &'a Scene,
    /// The hair's box: what shadow-casting lights frame.
    pub hair_bounds: (Vec3, Vec3),
    pub camera: Camera,
}

/// What a preview keeps between frames: the view's targets and the frame's renderers.
struct FrameState {
    view: Option<View>,
    renderers: FrameRenderers,
}

/// The frame of a picture: shadow passes for the scene's shadow-casting lights (when it asks
/// for shadows), the lit body, per batch the hair's generation and its lit ribbons, and the
/// order-independent thin strands (when it asks for width-based coverage), into a kept
/// [`View`]. Renderers are made once per device; effect renderers while their effect is on.
pub struct PreviewRenderer {
    state: Mutex<FrameState>,
    pub sample_count: u32,
}

impl PreviewRenderer {
    /// See [`crate::view::UI_VIEW_FORMAT`].
    pub const UI_VIEW_FORMAT: wgpu::TextureFormat = crate::view::UI_VIEW_FORMAT;

    pub fn new(context: &GpuContext) -> Self {
        Self::with_sample_count(context, crate::view::sample_count(context))
    }

    /// A renderer drawing with `sample_count` MSAA samples (1, 4 or 8) where every target
    /// format supports it (`bench switches` measures what MSAA costs); `None` where not.
    pub fn try_with_sample_count(context: &GpuContext, sample_count: u32) -> Option<Self> {
        // 4 samples are supported wherever 8 are (WebGPU guarantees 4 for these formats).
        let supported =
            [1, 4, 8].contains(&sample_count) && sample_count <= crate::view::sample_count(context);
        supported.then(|| Self::with_sample_count(context, sample_count))
    }

    fn with_sample_count(context: &GpuContext, sample_count: u32) -> Self {
        Self {
            state: Mutex::new(FrameState {
                view: None,
                renderers: FrameRenderers::new(context, Targets::view(sample_count)),
            }),
            sample_count,
        }
    }

    /// The renderers of the last frame, with the phases each takes part in: what a frame of
    /// its scene records (an effect that is off has none).
    pub fn participants(&self) -> Vec<(&'static str, &'static [Phase])> {
        let state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        state.renderers.participants()
    }

    /// Renders `scene` into a `width × height` image following `plan` (from [`Self::plan`]
    /// for the same scene and size); returns RGBA8 (sRGB) rows, top first.
    pub fn render(
        &self,
        context: &GpuContext,
        scene: &PreviewScene,
        plan: &FramePlan,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, PreviewError> {
        let frame = self.record_frame(context, scene, plan, width, height, None)?;
        View::read_back(context, &frame.color, frame.encoder).map_err(PreviewError::Readback)
    }

    /// Renders `scene` following `plan` into the view's `width × height` sRGB texture, which
    /// can be sampled (an editor viewport shows it, see [`Self::UI_VIEW_FORMAT`]); the work
    /// is submitted, not waited for. The texture is kept for the next frame of this size.
    pub fn render_texture(
        &self,
        context: &GpuContext,
        scene: &PreviewScene,
        plan: &FramePlan,
        width: u32,
        height: u32,
    ) -> Result<wgpu::Texture, PreviewError> {
        let frame = self.record_frame(context, scene, plan, width, height, None)?;
        context.queue.submit([frame.encoder.finish()]);
        Ok(frame.color)
    }

    /// Renders one frame of `scene` without reading it back and measures it: GPU time of
    /// every pass (generation, shadows and drawing) by timestamp queries where the adapter
    /// has them, and wall time from submission to idle.
    pub fn time_frame(
        &self,
        context: &GpuContext,
        scene: &PreviewScene,
        width: u32,
        height: u32,
    ) -> Result<FrameTiming, PreviewError> {
        let plan = self.plan(scene, width, height);
        // Generation and up to five passes (two per shadow-casting light) per batch.
        let passes = 8 + 16 * (plan.batches.len() + 1);
        let timer = PassTimer::new(context, passes);
        let frame = self.record_frame(context, scene, &plan, width, height, timer.as_ref())?;
        let (wall_ms, gpu_ms) =
            submit_timed(context, frame.encoder, timer).map_err(PreviewError::Readback)?;
        Ok(FrameTiming {
            gpu_ms,
            // Far hair's level measurement ran before the frame's submission.
            wall_ms: wall_ms + frame.far_lod_ms,
            scratch_bytes: frame.scratch_bytes,
            strands: plan.strands,
            vertices: plan.vertices,
            far_bundles: plan.far_bundles,
            far_segments: frame.far_segments,
        })
    }

    /// The camera as the frame sees it in a `width` × `height` frame of `scene`.
    fn frame_camera(scene: &PreviewScene, width: u32, height: u32) -> FrameCamera {
        let (width, height) = (width.max(1), height.max(1));
        FrameCamera {
            eye: scene.camera.eye,
            view_projection: scene.camera.view_projection(width as f32 / height as f32),
            fov_y_rad: scene.camera.fov_y_rad,
            height_px: height,
        }
    }

    /// The bundle-level work of a frame: which strands at which detail, in batches. (The
    /// mesh path's task shaders plan the same on the GPU; this plan then only counts.)
    /// Bundles far hair draws (the scene's `far_hair`) have no strands in it: their levels
    /// are the last frame's choice (eq. 16), and [`Self::render`] draws their thick hairs.
    pub fn plan(&self, scene: &PreviewScene, width: u32, height: u32) -> FramePlan {
        match &scene.hair {
            HairSource::Generated { hair, lod, .. } => {
                let max_log2 = scene.vertex_count.saturating_sub(1).max(1).ilog2();
                let camera = Self::frame_camera(scene, width, height);
                let far_levels = {
                    let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
                    state
                        .renderers
                        .far_levels(scene.lighting, &scene.hair, &camera)
                };
                let lod = LodSettings {
                    strand_keep: strand_keep(scene.lighting, &scene.hair, &camera),
                    ..*lod
                };
                plan_frame(
                    &hair.bundles,
                    hair.per_bundle,
                    max_log2,
                    &camera.lod(),
                    &lod,
                    batch_vertex_limit(scene.vertex_count),
                    &far_levels,
                )
            }
            HairSource::Vertices(vertices) => stored_plan(
                vertices.len() / scene.vertex_count.max(1) as usize,
                scene.vertex_count,
            ),
            HairSource::Stored { strand_count, .. } => {
                stored_plan(*strand_count, scene.vertex_count)
            }
            // The same bundle-level work as the generated strands it stores.
            // No more vertices than were stored and bound.
            HairSource::Skinned {
                hair, lod, skinned, ..
            } => plan_frame(
                &hair.bundles,
                hair.per_bundle,
                scene
                    .vertex_count
                    .min(skinned.vertex_count)
                    .saturating_sub(1)
                    .max(1)
                    .ilog2(),
                &Self::frame_camera(scene, width, height).lod(),
                lod,
                batch_vertex_limit(scene.vertex_count),
                &[],
            ),
        }
    }

    /// Far hair's level choice (eq. 16) run without drawing until a still camera's levels
    /// stop changing (at most one level per bundle per step, so as many steps as the deepest
    /// hierarchy has levels): what a still picture draws. Returns the steps taken (0 without
    /// far hair).
    pub fn settle_far_levels(
        &self,
        context: &GpuContext,
        scene: &PreviewScene,
        width: u32,
        height: u32,
    ) -> Result<usize, PreviewError> {
        let active = self.active_effects(context, scene)?;
        if !active.far_hair {
            return Ok(0);
        }
        scene.hair.check(context, scene.vertex_count, true)?;
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let renderers = &mut state.renderers;
        renderers.sync(context, &active, scene.lighting, scene.hair.ribbon_input());
        let camera = Self::frame_camera(scene, width, height);
        let HairSource::Generated { far: Some(far), .. } = &scene.hair else {
            return Ok(0);
        };
        let deepest = far.table.blocks.iter().map(Vec::len).max().unwrap_or(0);
        for step in 0..=deepest {
            let levels = renderers.far_levels(scene.lighting, &scene.hair, &camera);
            let plan = FramePlan {
                far_levels: levels.clone(),
                ..FramePlan::default()
            };
            renderers.advance_far_levels(
                context,
                scene.lighting,
                &scene.hair,
                &camera,
                scene.vertex_count,
                &plan,
            )?;
            if renderers.far_levels(scene.lighting, &scene.hair, &camera) == levels {
                return Ok(step);
            }
        }
        Ok(deepest + 1)
    }

    /// What runs for `scene`, checked against the adapter's limits before anything is made.
    pub fn active_effects(
        &self,
        context: &GpuContext,
        scene: &PreviewScene,
    ) -> Result<ActiveEffects, PreviewError> {
        let active = ActiveEffects::new(scene.lighting, !scene.body.is_empty());
        check_effect_limits(&context.device.limits(), &active)?;
        Ok(active)
    }

    /// Records a frame into the kept view (see [`PreviewRenderer`]) with the frame builder;
    /// the last pass resolves MSAA.
    fn record_frame(
        &self,
        context: &GpuContext,
        scene: &PreviewScene,
        plan: &FramePlan,
        width: u32,
        height: u32,
        timer: Option<&PassTimer>,
    ) -> Result<EncodedFrame, PreviewError> {
        let active = self.active_effects(context, scene)?;
        scene
            .hair
            .check(context, scene.vertex_count, active.far_hair)?;
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let state = &mut *state;
        let renderers = &mut state.renderers;
        renderers.sync(context, &active, scene.lighting, scene.hair.ribbon_input());
        View::ensure(&mut state.view, context, width, height, self.sample_count);
        let view = state.view.as_ref().expect("made above");
        if let Some(oit) = &mut renderers.oit {
            oit.ensure_targets(context, view.width, view.height);
        }
        let camera = Self::frame_camera(scene, view.width, view.height);
        let inputs = FrameInputs {
            hair: scene.hair,
            body: scene.body,
            vertex_count: scene.vertex_count,
            strand_width_m: scene.strand_width_m,
            scene: scene.lighting,
            hair_bounds: scene.hair_bounds,
            camera,
        };
        let frame = prepare(context, renderers, &inputs, plan);
        let mut encoder = context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("preview"),
            });
        let mut recorder =
            FrameRecorder::new(context, renderers, &frame, scene.body, &scene.hair).timed(timer);
        recorder.shadow_views(&mut encoder);
        recorder.view(&mut encoder, view, scene.lighting.background);
        let far_segments = frame.far.as_ref().map_or(0, |f| f.segments());
        // Far hair: the next frame's levels, from the widths this frame's drew (its own
        // submission, read back: timed and counted in the frame's cost).
        let far_lod_started = std::time::Instant::now();
        renderers.advance_far_levels(
            context,
            scene.lighting,
            &scene.hair,
            &camera,
            scene.vertex_count,
            plan,
        )?;
        let far_lod_ms = far_lod_started.elapsed().as_secs_f64() * 1e3;
        Ok(EncodedFrame {
            far_segments,
            far_lod_ms,
            encoder,
            color: view.color().clone(),
            scratch_bytes: frame.scratch_bytes,
        })
    }
}

struct EncodedFrame {
    encoder: wgpu::CommandEncoder,
    /// Far hair's thick-hair segments drawn (0 without far hair).
    far_segments: u32,
    /// Wall time of far hair's level choice for the next frame (0 without far hair).
    far_lod_ms: f64,
    /// The view's resolved colour target.
    color: wgpu::Texture,
    scratch_bytes: u64,
}

/// Measured cost of one frame.
#[derive(Clone, Copy, Debug)]
pub struct FrameTiming {
    /// Sum of every pass's GPU time; `None` without `TIMESTAMP_QUERY`.
    pub gpu_ms: Option<f64>,
    pub wall_ms: f64,
    /// Transient scratch of generation (0 for stored vertices).
    pub scratch_bytes: u64,
    /// Strands and vertices drawn after culling and LOD.
    pub strands: usize,
    pub vertices: usize,
    /// Far hair: bundles drawn as thick hairs, and their segments.
    pub far_bundles: usize,
    pub far_segments: u32,
}

/// Stored vertices: one run over every strand, one batch.
fn stored_plan(strand_count: usize, vertex_count: u32) -> FramePlan {
    let runs = hairloom_core::runtime::strand_gen::full_detail_runs(strand_count, vertex_count);
    FramePlan {
        strands: strand_count,
        vertices: strand_count * vertex_count as usize,
        batches: if runs.is_empty() {
            Vec::new()
        } else {
            vec![runs]
        },
        ..FramePlan::default()
    }
}

/// The picture of a document: its scene's lights, material and effects, strands a little
/// over a thousandth of the hair's size wide.
pub fn default_scene<'a>(
    body: &'a GpuBody,
    hair: HairSource<'a>,
    vertex_count: u32,
    (lo, hi): (Vec3, Vec3),
    camera: Camera,
    lighting: &'a Scene,
) -> PreviewScene<'a> {
    PreviewScene {
        body,
        hair,
        vertex_count,
        strand_width_m: default_strand_width_m(lo, hi),
        lighting,
        hair_bounds: (lo, hi),
        camera,
    }
}

/// Ribbon width at the root for hair whose box is `(lo, hi)`: a little over a thousandth of
/// its size (what the CPU reference renderer's fibres use too).
pub fn default_strand_width_m(lo: Vec3, hi: Vec3) -> f32 {
    (hi - lo).length() * 0.0012
}
