//! The drop-in runtime for wgpu games: load a runtime bundle, and each frame record strand
//! generation into the game's command encoder and the lit hair into the game's own render
//! pass, with the game's camera, colour and depth targets and lights. No editor and no
//! window of ours: [`GameHair`] borrows the game's device and queue.
//!
//! ```no_run
//! # fn frame(device: &wgpu::Device, queue: &wgpu::Queue, adapter: &wgpu::Adapter,
//! #          color: &wgpu::TextureView, depth: &wgpu::TextureView, camera: hairloom_render::game::GameCamera)
//! #          -> Result<(), Box<dyn std::error::Error>> {
//! use hairloom_render::game::{GameHair, HairTargets};
//! let bundle = hairloom_core::io::runtime_bundle::load_runtime_bundle("hair_bundle".as_ref())?;
//! let targets = HairTargets {
//!     color: wgpu::TextureFormat::Bgra8UnormSrgb,
//!     depth: wgpu::TextureFormat::Depth32Float,
//!     sample_count: 1,
//! };
//! let mut hair = GameHair::new(adapter, device, queue, &bundle, targets)?;
//! // Every frame:
//! let mut encoder = device.create_command_encoder(&Default::default());
//! hair.prepare(&mut encoder, &camera); // culling, LOD and generation (compute)
//! {
//!     let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
//!         label: Some("game"),
//!         color_attachments: &[Some(wgpu::RenderPassColorAttachment {
//!             view: color, depth_slice: None, resolve_target: None,
//!             ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
//!         })],
//!         depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
//!             view: depth,
//!             depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
//!             stencil_ops: None,
//!         }),
//!         timestamp_writes: None, occlusion_query_set: None, multiview_mask: None,
//!     });
//!     // … the game's own draws …
//!     hair.draw(&mut pass); // depth-tested against what the game drew
//! }
//! queue.submit([encoder.finish()]);
//! # Ok(()) }
//! ```
//!
//! What the game path draws: everything the bundle's scene names (or the game's own lights:
//! [`GameHair::set_lighting`]) — Kajiya-Kay or Marschner shading, dual scattering, and the
//! shadow passes (opacity shadow maps or deep opacity maps, body shadows from the bundle's
//! body), which `prepare` records into the game's encoder before its pass — except
//! width-based transparency, which needs targets of its own in the game's pass. [`game_scene`]
//! says exactly which scene the game path draws; the editor's preview draws the same picture
//! for it (tested pixel for pixel).

use glam::{Mat4, Vec3};
use hairloom_core::light::scene_uniforms::{SceneUniforms, bounding_sphere, shadow_views};
use hairloom_core::model::scene::{Coverage, Scene, SelfShadowing};
use hairloom_core::runtime::frame_plan::{FramePlan, LodCamera, LodSettings, plan_frame};
use hairloom_core::runtime::gpu_types::StrandRun;
use hairloom_core::runtime::hair::RuntimeHair;
use hairloom_core::runtime::strand_gen::Filtering;

use crate::device::GpuContext;
use crate::preview::{default_strand_width_m, effects_bind_group, frame_views};
use crate::renderer::Targets;
use crate::renderer::body_shadow::BodyShadowRenderer;
use crate::renderer::hair_shadow::HairShadowRenderer;
use crate::renderer::preview_body::{BodyRenderer, GpuBody, PreparedBody};
use crate::renderer::preview_hair::{HairRenderer, HairUniforms, PreparedHair, RibbonInput};
use crate::renderer::scene_lighting::{ActiveEffects, SceneLighting, effects_layout};
use crate::renderer::strand_gen::{GpuHair, StrandGenError, StrandGenRenderer};
use crate::resources::Tracked;

/// The game's targets: the formats and sample count of the pass [`GameHair::draw`] records
/// into.
pub type HairTargets = Targets;

/// The game's camera for a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GameCamera {
    /// World to clip space, depth in `[0, 1]` with nearer smaller (wgpu's convention).
    pub view_projection: Mat4,
    pub eye: Vec3,
    /// Vertical field of view; level of detail measures sizes in pixels with it.
    pub fov_y_rad: f32,
    /// Height of the viewport in pixels.
    pub viewport_height_px: u32,
}

/// What one frame drew.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GameFrameStats {
    /// Strands and vertices generated after culling and level of detail.
    pub strands: usize,
    pub vertices: usize,
    /// Bundles outside the view, skipped.
    pub culled_bundles: usize,
    /// Strands planned but not drawn: more vertices than one generation dispatch of the
    /// game's device holds (its `max_storage_buffer_binding_size` / 16 B and
    /// `max_compute_workgroups_per_dimension` × 64; let LOD drop strands, or raise the
    /// binding limit when the device was created).
    pub strands_over_limit: usize,
}

/// The scene the game path draws for `scene`: the same lights, material and effects, but
/// multisampled coverage in place of width-based transparency (whose accumulation targets
/// would have to live in the game's pass).
pub fn game_scene(scene: &Scene) -> Scene {
    let mut scene = scene.clone();
    scene.effects.coverage = Coverage::Msaa;
    scene
}

/// A runtime bundle on the game's GPU, drawn into the game's passes.
pub struct GameHair {
    context: GpuContext,
    generator: StrandGenRenderer,
    gpu: GpuHair,
    lighting: SceneLighting,
    hair: HairRenderer,
    body_renderer: BodyRenderer,
    body: GpuBody,
    draw_body: bool,
    hair_shadow: Option<HairShadowRenderer>,
    body_shadow: Option<BodyShadowRenderer>,
    scene: Scene,
    active: ActiveEffects,
    effects_group: Option<wgpu::BindGroup>,
    bounds: (Vec3, Vec3),
    strand_width_m: f32,
    lod: LodSettings,
    filtering: Filtering,
    vertex_count: u32,
    frame: Option<PreparedFrame>,
}

/// One frame's GPU state between [`GameHair::prepare`] and [`GameHair::draw`].
struct PreparedFrame {
    hair: PreparedHair,
    body: PreparedBody,
    /// The frame's one batch.
    runs: Vec<StrandRun>,
    _runs: wgpu::Buffer,
    _scratch: Tracked<wgpu::Buffer>,
}

/// Why a bundle could not be put on the game's GPU.
#[derive(Debug, thiserror::Error)]
pub enum GameHairError {
    #[error(transparent)]
    Generation(#[from] StrandGenError),
    #[error("the bundle grows no hair")]
    NoHair,
    #[error(transparent)]
    EffectLimit(#[from] crate::preview::PreviewError),
}

impl GameHair {
    /// Uploads `hair` (its five textures, placements, samples and styling: nothing per
    /// strand) to the game's device and makes the pipelines for `targets`. The bundle's
    /// body is drawn too unless [`Self::set_draw_body`] turns it off.
    pub fn new(
        adapter: &wgpu::Adapter,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        hair: &RuntimeHair,
        targets: HairTargets,
    ) -> Result<Self, GameHairError> {
        let context = GpuContext::from_parts(adapter.clone(), device.clone(), queue.clone());
        let generator = StrandGenRenderer::new(&context);
        let gpu = generator.upload(&context, hair)?;
        let bounds = hair.textures.hair_bounds().ok_or(GameHairError::NoHair)?;
        let max_log2 = hair.lod.max_vertices_log2.min(8);
        let mut this = Self {
            lighting: SceneLighting::new(&context),
            hair: HairRenderer::with_targets(&context, targets),
            body_renderer: BodyRenderer::with_targets(&context, targets),
            body: GpuBody::upload(&context, &hair.body),
            draw_body: true,
            hair_shadow: None,
            body_shadow: None,
            scene: game_scene(&hair.scene),
            active: ActiveEffects::none(),
            effects_group: None,
            bounds,
            strand_width_m: default_strand_width_m(bounds.0, bounds.1),
            lod: LodSettings {
                alpha_strands: hair.lod.alpha_strands,
                alpha_vertices: hair.lod.alpha_vertices,
                lambda: hair.lod.lambda,
                ..LodSettings::default()
            },
            filtering: Filtering::Exact,
            vertex_count: (1u32 << max_log2) + 1,
            frame: None,
            generator,
            gpu,
            context,
        };
        let scene = this.scene.clone();
        this.set_lighting(&scene)?;
        Ok(this)
    }

    /// Lights, material and shading from `scene` (the game's lights, or the bundle's own:
    /// [`RuntimeHair::scene`]); the effects it names that need passes of their own are
    /// left out (see [`game_scene`]).
    pub fn set_lighting(&mut self, scene: &Scene) -> Result<(), GameHairError> {
        let scene = game_scene(scene);
        let active = ActiveEffects::new(&scene, !self.body.is_empty());
        crate::preview::check_effect_limits(&self.context.device.limits(), &active)
            .map_err(GameHairError::EffectLimit)?;
        let context = &self.context;
        self.lighting.sync(context, &active, &scene.material);
        let effects_layout = effects_layout(context, &active);
        // Pipelines are made against the layouts, so new layouts mean new renderers.
        let targets = self.hair.targets();
        self.hair = HairRenderer::with_targets(context, targets);
        self.body_renderer = BodyRenderer::with_targets(context, targets);
        let scene_layout = &self.lighting.scene_layout;
        self.hair.ensure(
            context,
            &active,
            scene_layout,
            effects_layout.as_ref(),
            RibbonInput::Buffer,
        );
        self.body_renderer.ensure(
            context,
            active.shader_key(),
            scene_layout,
            effects_layout.as_ref(),
        );
        let slots = active.shadow_slots;
        self.hair_shadow = (active.opacity_maps != SelfShadowing::None && slots > 0).then(|| {
            HairShadowRenderer::new(
                context,
                &self.hair,
                scene_layout,
                active.opacity_maps,
                active.opacity_layers,
                active.shadow_resolution,
                slots,
                RibbonInput::Buffer,
            )
        });
        self.body_shadow = (active.body_shadows && slots > 0).then(|| {
            BodyShadowRenderer::new(
                context,
                &self.body_renderer,
                active.shadow_resolution,
                slots,
            )
        });
        self.effects_group = effects_layout.as_ref().map(|layout| {
            effects_bind_group(
                context,
                layout,
                self.hair_shadow.as_ref(),
                self.body_shadow.as_ref(),
                &self.lighting,
            )
        });
        self.scene = scene;
        self.active = active;
        Ok(())
    }

    /// Whether [`Self::draw`] draws the bundle's body (on by default; a game that draws its
    /// own character turns it off).
    pub fn set_draw_body(&mut self, draw: bool) {
        self.draw_body = draw;
    }

    /// Level of detail and culling (the bundle's settings by default).
    pub fn set_lod(&mut self, lod: LodSettings) {
        self.lod = lod;
    }

    /// Vertices per strand at full detail: `2^log2 + 1` (the bundle's
    /// `lod.max_vertices_log2` by default; at most 8).
    pub fn set_vertices_log2(&mut self, log2: u32) {
        self.vertex_count = (1u32 << log2.clamp(1, 8)) + 1;
    }

    /// Ribbon width at the root, metres (default: a little over a thousandth of the hair's
    /// size, as `hairloom render` draws).
    pub fn set_strand_width_m(&mut self, width_m: f32) {
        self.strand_width_m = width_m;
    }

    /// The box around the hair (to frame a camera).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// The scene being drawn.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Plans the frame for `camera` (culling, strand and vertex LOD), writes its uniforms
    /// and records the strands' generation and the shadow passes into `encoder`, before the
    /// game's render pass. Once per frame: a second call before the encoder is submitted
    /// overwrites the first camera's uniforms. The frame's transient buffers (runs and
    /// scratch) are made here each frame. The depth test is "nearer is smaller"
    /// (`Less`); reversed-Z depth buffers are not supported yet.
    pub fn prepare(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        camera: &GameCamera,
    ) -> GameFrameStats {
        let context = &self.context;
        let height_px = camera.viewport_height_px.max(1);
        let lod_camera = LodCamera {
            eye: camera.eye,
            view_projection: camera.view_projection,
            fov_y_rad: camera.fov_y_rad,
            resolution_px: height_px as f32,
        };
        // One batch, so generation runs once before the pass: as many vertices as one
        // storage binding holds (16 B each) and one row of 64-wide workgroups reaches.
        let limits = context.device.limits();
        let binding_vertices = (limits.max_storage_buffer_binding_size / 16)
            .min(limits.max_compute_workgroups_per_dimension as u64 * 64)
            .max(2) as usize;
        let mut plan = plan_frame(
            &self.gpu.bundles,
            self.gpu.per_bundle,
            self.vertex_count.saturating_sub(1).max(1).ilog2(),
            &lod_camera,
            &self.lod,
            binding_vertices,
        );
        let mut stats = GameFrameStats {
            strands: plan.strands,
            vertices: plan.vertices,
            culled_bundles: plan.culled_bundles,
            strands_over_limit: 0,
        };
        if plan.batches.len() > 1 {
            let first = plan.batches.swap_remove(0);
            let dropped: usize = plan
                .batches
                .iter()
                .flatten()
                .map(|r| r.strand_count as usize)
                .sum();
            plan.batches = vec![first];
            stats.strands_over_limit = dropped;
            stats.strands -= dropped;
            stats.vertices = FramePlan::batch_vertices(&plan.batches[0]);
        }
        let runs = self.generator.upload_runs(context, &plan);
        let scratch = self.generator.scratch(context, &plan);
        let batch_runs = plan.batches.first().cloned().unwrap_or_default();
        if let Some(batch) = plan.batches.first() {
            self.generator.encode(
                context,
                encoder,
                &self.gpu,
                &runs,
                0,
                batch,
                self.filtering,
                &scratch,
                None,
            );
        }
        let (centre, radius) = bounding_sphere(self.bounds.0, self.bounds.1);
        let shadow_views = if self.active.shadow_slots > 0 {
            shadow_views(&self.scene, centre, radius)
        } else {
            Vec::new()
        };
        let mean_forward = self
            .lighting
            .sync(context, &self.active, &self.scene.material);
        let tables = self.lighting.dual_scattering.as_ref().map(|ds| &ds.tables);
        let uniforms = SceneUniforms::new(
            &self.scene,
            &shadow_views,
            tables,
            mean_forward,
            radius,
            self.strand_width_m,
        );
        self.lighting.write(context, &uniforms);
        let pixel_at_unit = 2.0 * (camera.fov_y_rad * 0.5).tan() / height_px as f32;
        let (hair_views, body_views) = frame_views(
            HairUniforms {
                view_projection: camera.view_projection.to_cols_array_2d(),
                eye: camera.eye.extend(1.0).to_array(),
                width: [self.strand_width_m, pixel_at_unit, 0.0, 0.0],
                batch: [0; 4],
            },
            &shadow_views,
        );
        let ranges = [[0, plan.batches.first().map_or(0, Vec::len) as u32]];
        let hair = self
            .hair
            .prepare(context, &hair_views, &ranges, &scratch, &runs);
        let body = self.body_renderer.prepare(context, &body_views);
        // Shadow passes, per shadow-casting light, into the shadow maps (not the game's
        // targets): the body's depth, the first hair's depth, then the opacity layers.
        for slot in 0..shadow_views.len() {
            if let Some(body_shadow) = &self.body_shadow {
                body_shadow.encode(encoder, &body, &self.body, slot);
            }
            if let Some(hair_shadow) = &self.hair_shadow {
                if hair_shadow.kind == SelfShadowing::DeepOpacityMaps {
                    hair_shadow.encode_depth(encoder, &hair, slot, 0, &batch_runs, true);
                }
                hair_shadow.encode_opacity(
                    encoder,
                    &hair,
                    &self.lighting.scene_group,
                    slot,
                    0,
                    &batch_runs,
                    true,
                );
            }
        }
        self.frame = Some(PreparedFrame {
            hair,
            body,
            runs: batch_runs,
            _runs: runs,
            _scratch: scratch,
        });
        stats
    }

    /// Records the body (when on) and the lit hair into the game's pass, depth-tested
    /// against what the game drew before: a depth pre-pass of the ribbons, then the lit
    /// ribbons where they are nearest, so each visible sample is shaded once. Draws nothing
    /// before the first [`Self::prepare`].
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        let Some(frame) = &self.frame else {
            return;
        };
        pass.set_bind_group(1, &self.lighting.scene_group, &[]);
        if let Some(group) = &self.effects_group {
            pass.set_bind_group(2, group, &[]);
        }
        if self.draw_body {
            self.body_renderer.draw(pass, &frame.body, &self.body);
        }
        for pipeline in [self.hair.depth_pipeline(), self.hair.main_pipeline()]
            .into_iter()
            .flatten()
        {
            HairRenderer::draw_with(pass, pipeline, &frame.hair, 0, 0, &frame.runs);
        }
    }
}
