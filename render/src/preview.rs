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
use hairloom_core::light::opacity_maps::ShadowView;
use hairloom_core::light::scene_uniforms::{SceneUniforms, bounding_sphere, shadow_views};
use hairloom_core::model::scene::{Scene, SelfShadowing};
use hairloom_core::runtime::frame_plan::{FramePlan, LodCamera, LodSettings, plan_frame};
use hairloom_core::runtime::strand_gen::Filtering;

use crate::device::{GpuContext, PassTimer, submit_timed};
use crate::renderer::body_shadow::BodyShadowRenderer;
use crate::renderer::hair_shadow::HairShadowRenderer;
use crate::renderer::oit_composite::OitRenderer;
use crate::renderer::preview_body::{BodyRenderer, BodyUniforms, GpuBody};
use crate::renderer::preview_hair::{HairRenderer, HairUniforms, MeshLod, RibbonInput};
use crate::renderer::scene_lighting::{ActiveEffects, SceneLighting, binding, effects_layout};
use crate::renderer::strand_gen::{
    GenerationPath, GpuHair, StrandGenError, StrandGenRenderer, batch_vertex_limit,
    check_mesh_groups,
};
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

/// Where the strand vertices of a frame come from.
#[derive(Clone, Copy)]
pub enum HairSource<'a> {
    /// Strand-major vertices in memory (xyz, w = fraction along the strand), uploaded for
    /// the frame: the CPU reference generator's output.
    Vertices(&'a [[f32; 4]]),
    /// Strand-major vertices already in a GPU storage buffer: the explicit-storage baseline.
    Stored {
        buffer: &'a wgpu::Buffer,
        strand_count: usize,
    },
    /// Generated from the runtime textures in this frame, batch by batch, after the
    /// bundle-level work (culling, strand and vertex LOD) planned the frame.
    Generated {
        generator: &'a StrandGenRenderer,
        hair: &'a GpuHair,
        filtering: Filtering,
        lod: LodSettings,
    },
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

/// Everything a frame keeps between frames: the view's targets and one renderer per feature.
/// The effect renderers exist only while the scene asks for their effect.
struct FrameState {
    view: Option<View>,
    lighting: SceneLighting,
    hair: HairRenderer,
    body: BodyRenderer,
    /// The group-2 layout of the lit shaders, for the effects that make it up.
    effects_layout: Option<((SelfShadowing, bool, bool), Option<wgpu::BindGroupLayout>)>,
    hair_shadow: Option<HairShadowRenderer>,
    body_shadow: Option<BodyShadowRenderer>,
    oit: Option<OitRenderer>,
    lighting_sample_count: u32,
}

impl FrameState {
    /// Makes what `active` needs and frees what it does not; returns the material's mean
    /// forward transmittance per fibre.
    fn sync(
        &mut self,
        context: &GpuContext,
        active: &ActiveEffects,
        scene: &Scene,
        input: RibbonInput,
    ) -> [f32; 3] {
        let mean_forward = self.lighting.sync(context, active, &scene.material);
        let layout_key = (
            active.opacity_maps,
            active.body_shadows,
            active.dual_scattering,
        );
        if self
            .effects_layout
            .as_ref()
            .is_none_or(|(key, _)| *key != layout_key)
        {
            self.effects_layout = Some((layout_key, effects_layout(context, active)));
            // Pipelines made with the old layout go with it.
            self.hair = HairRenderer::new(context, self.hair_sample_count());
            self.body = BodyRenderer::new(context, self.hair_sample_count());
        }
        let effects_layout = self.effects_layout.as_ref().and_then(|(_, l)| l.as_ref());
        self.hair.ensure(
            context,
            active,
            &self.lighting.scene_layout,
            effects_layout,
            input,
        );
        self.body.ensure(
            context,
            active.shader_key(),
            &self.lighting.scene_layout,
            effects_layout,
        );
        let slots = active.shadow_slots;
        if active.opacity_maps != SelfShadowing::None && slots > 0 {
            let fits = self.hair_shadow.as_ref().is_some_and(|h| {
                h.fits(
                    active.opacity_maps,
                    active.opacity_layers,
                    active.shadow_resolution,
                    slots,
                    input,
                )
            });
            if !fits {
                self.hair_shadow = None;
                self.hair_shadow = Some(HairShadowRenderer::new(
                    context,
                    &self.hair,
                    &self.lighting.scene_layout,
                    active.opacity_maps,
                    active.opacity_layers,
                    active.shadow_resolution,
                    slots,
                    input,
                ));
            }
        } else {
            self.hair_shadow = None;
        }
        if active.body_shadows && slots > 0 {
            let fits = self
                .body_shadow
                .as_ref()
                .is_some_and(|b| (b.resolution, b.slots) == (active.shadow_resolution, slots));
            if !fits {
                self.body_shadow = None;
                self.body_shadow = Some(BodyShadowRenderer::new(
                    context,
                    &self.body,
                    active.shadow_resolution,
                    slots,
                ));
            }
        } else {
            self.body_shadow = None;
        }
        if active.width_oit {
            if self.oit.is_none() {
                self.oit = Some(OitRenderer::new(context, self.hair_sample_count()));
            }
        } else {
            self.oit = None;
        }
        mean_forward
    }

    fn hair_sample_count(&self) -> u32 {
        self.lighting_sample_count
    }
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
        let sample_count = crate::view::sample_count(context);
        Self {
            state: Mutex::new(FrameState {
                view: None,
                lighting: SceneLighting::new(context),
                hair: HairRenderer::new(context, sample_count),
                body: BodyRenderer::new(context, sample_count),
                effects_layout: None,
                hair_shadow: None,
                body_shadow: None,
                oit: None,
                lighting_sample_count: sample_count,
            }),
            sample_count,
        }
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
        let frame = self.encode_frame(context, scene, plan, width, height, None)?;
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
        let frame = self.encode_frame(context, scene, plan, width, height, None)?;
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
        let frame = self.encode_frame(context, scene, &plan, width, height, timer.as_ref())?;
        let (wall_ms, gpu_ms) =
            submit_timed(context, frame.encoder, timer).map_err(PreviewError::Readback)?;
        Ok(FrameTiming {
            gpu_ms,
            wall_ms,
            scratch_bytes: frame.scratch_bytes,
            strands: plan.strands,
            vertices: plan.vertices,
        })
    }

    /// The camera as LOD sees it in a `width` × `height` frame of `scene`.
    fn lod_camera(scene: &PreviewScene, width: u32, height: u32) -> LodCamera {
        let (width, height) = (width.max(1), height.max(1));
        LodCamera {
            eye: scene.camera.eye,
            view_projection: scene.camera.view_projection(width as f32 / height as f32),
            fov_y_rad: scene.camera.fov_y_rad,
            resolution_px: height as f32,
        }
    }

    /// The bundle-level work of a frame: which strands at which detail, in batches. (The
    /// mesh path's task shaders plan the same on the GPU; this plan then only counts.)
    pub fn plan(&self, scene: &PreviewScene, width: u32, height: u32) -> FramePlan {
        match &scene.hair {
            HairSource::Generated { hair, lod, .. } => {
                let max_log2 = scene.vertex_count.saturating_sub(1).max(1).ilog2();
                plan_frame(
                    &hair.bundles,
                    hair.per_bundle,
                    max_log2,
                    &Self::lod_camera(scene, width, height),
                    lod,
                    batch_vertex_limit(scene.vertex_count),
                )
            }
            HairSource::Vertices(vertices) => stored_plan(
                vertices.len() / scene.vertex_count.max(1) as usize,
                scene.vertex_count,
            ),
            HairSource::Stored { strand_count, .. } => {
                stored_plan(*strand_count, scene.vertex_count)
            }
        }
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

    /// Records a frame into the kept view (see [`PreviewRenderer`]); the last pass resolves
    /// MSAA.
    fn encode_frame(
        &self,
        context: &GpuContext,
        scene: &PreviewScene,
        plan: &FramePlan,
        width: u32,
        height: u32,
        timer: Option<&PassTimer>,
    ) -> Result<EncodedFrame, PreviewError> {
        let device = &context.device;
        let active = self.active_effects(context, scene)?;
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let state = &mut *state;
        // Ribbons read their vertices from a buffer unless the generator makes them in the
        // vertex shader.
        let input = match &scene.hair {
            HairSource::Generated {
                generator, hair, ..
            } => {
                StrandGenRenderer::check_path(context, generator.path())
                    .map_err(PreviewError::Generation)?;
                if generator.path() == GenerationPath::MeshShader {
                    check_mesh_groups(
                        &device.limits(),
                        hair.bundles.len(),
                        hair.per_bundle,
                        scene.vertex_count,
                    )
                    .map_err(PreviewError::Generation)?;
                }
                generator.path().ribbon_input()
            }
            _ => RibbonInput::Buffer,
        };
        let mean_forward = state.sync(context, &active, scene.lighting, input);
        View::ensure(&mut state.view, context, width, height, self.sample_count);
        let view = state.view.as_ref().expect("made above");
        if let Some(oit) = &mut state.oit {
            oit.ensure_targets(context, view.width, view.height);
        }
        let aspect = view.width as f32 / view.height as f32;
        let view_projection = scene.camera.view_projection(aspect).to_cols_array_2d();
        let camera_position = scene.camera.eye.extend(1.0).to_array();
        // The scene as the shaders see it, with a view per shadow-casting light.
        let (center, radius) = bounding_sphere(scene.hair_bounds.0, scene.hair_bounds.1);
        let shadow_views: Vec<_> = if active.shadow_slots > 0 {
            shadow_views(scene.lighting, center, radius)
        } else {
            Vec::new()
        };
        let tables = state.lighting.dual_scattering.as_ref().map(|ds| &ds.tables);
        let uniforms = SceneUniforms::new(
            scene.lighting,
            &shadow_views,
            tables,
            mean_forward,
            radius,
            scene.strand_width_m,
        );
        state.lighting.write(context, &uniforms);
        let effects_group = state
            .effects_layout
            .as_ref()
            .and_then(|(_, layout)| layout.as_ref())
            .map(|layout| {
                effects_bind_group(
                    context,
                    layout,
                    state.hair_shadow.as_ref(),
                    state.body_shadow.as_ref(),
                    &state.lighting,
                )
            });
        let generator = match &scene.hair {
            HairSource::Generated {
                generator,
                hair,
                filtering,
                ..
            } => {
                generator
                    .check_filtering(context, *filtering)
                    .map_err(PreviewError::Generation)?;
                Some((*generator, *hair, *filtering))
            }
            _ => None,
        };
        // Per-frame buffers (not kept, so not in the registry).
        let storage = |label: &str, contents: &[u8]| {
            wgpu::util::DeviceExt::create_buffer_init(
                device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                },
            )
        };
        let runs = match generator {
            Some((generator, ..)) => generator.upload_runs(context, plan),
            None => {
                let mut runs: Vec<_> = plan.batches.iter().flatten().copied().collect();
                if runs.is_empty() {
                    runs.push(Default::default());
                }
                storage("preview_runs", bytemuck::cast_slice(&runs))
            }
        };
        // Where the hair's vertices live: uploaded now, already stored, or a scratch buffer
        // that each batch's generation overwrites.
        let (owned, scratch);
        let (strands, scratch_bytes): (&wgpu::Buffer, u64) = match &scene.hair {
            HairSource::Vertices(vertices) => {
                let placeholder = [[0.0f32; 4]];
                let data = if vertices.is_empty() {
                    &placeholder[..]
                } else {
                    vertices
                };
                owned = storage("preview_strands", bytemuck::cast_slice(data));
                (&owned, 0)
            }
            HairSource::Stored { buffer, .. } => (buffer, 0),
            // No scratch: the ribbons bind the textures instead.
            HairSource::Generated { .. } if input != RibbonInput::Buffer => {
                owned = storage("preview_no_strands", &[0; 16]);
                (&owned, 0)
            }
            HairSource::Generated { generator, .. } => {
                scratch = generator.scratch(context, plan);
                (&scratch, scratch.size())
            }
        };
        // Each batch's runs: `runs[first_run..][..batch.len()]`.
        let ranges: Vec<[u32; 2]> = plan
            .batches
            .iter()
            .scan(0u32, |first, batch| {
                let range = [*first, batch.len() as u32];
                *first += batch.len() as u32;
                Some(range)
            })
            .collect();
        // The hair's views: the camera, then each shadow-casting light (ribbons at least a
        // texel wide there, and a pixel wide for the camera with width-based coverage).
        let pixel_at_unit = 2.0 * (scene.camera.fov_y_rad * 0.5).tan() / view.height as f32;
        let (hair_views, body_views) = frame_views(
            HairUniforms {
                view_projection,
                eye: camera_position,
                width: [
                    scene.strand_width_m,
                    pixel_at_unit,
                    if active.width_oit { 1.0 } else { 0.0 },
                    0.0,
                ],
                batch: [0; 4],
            },
            &shadow_views,
        );
        let prepared_hair = match generator {
            Some((generator, gpu_hair, filtering)) if input != RibbonInput::Buffer => {
                state.hair.prepare_generated(
                    context,
                    &hair_views,
                    &ranges,
                    generator,
                    gpu_hair,
                    filtering,
                    &runs,
                    (input == RibbonInput::Mesh).then(|| MeshLod {
                        camera: Self::lod_camera(scene, width, height),
                        settings: match &scene.hair {
                            HairSource::Generated { lod, .. } => *lod,
                            _ => LodSettings::default(),
                        },
                        max_vertices_log2: scene.vertex_count.saturating_sub(1).max(1).ilog2(),
                    }),
                )
            }
            _ => state
                .hair
                .prepare(context, &hair_views, &ranges, strands, &runs),
        };
        let prepared_body = state.body.prepare(context, &body_views);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("preview"),
        });
        // Generation: once when the plan is one batch (every pass then reads the same
        // vertices), else again before each pass that draws a batch.
        let single_batch = plan.batches.len() == 1;
        let mut generated = false;
        let mut generate = |encoder: &mut wgpu::CommandEncoder, index: usize| {
            let Some((generator, gpu_hair, filtering)) = generator else {
                return;
            };
            if (single_batch && generated) || input != RibbonInput::Buffer {
                return;
            }
            generated = true;
            generator.encode(
                context,
                encoder,
                gpu_hair,
                &runs,
                ranges[index][0] as usize,
                &plan.batches[index],
                filtering,
                strands,
                timer.and_then(|t| t.compute_pass()),
            );
        };
        let no_runs = Vec::new();
        let batch_runs = |index: usize| plan.batches.get(index).unwrap_or(&no_runs);
        let batch_count = plan.batches.len();
        // 1. Shadow passes, per shadow-casting light.
        for slot in 0..active.shadow_slots as usize {
            if let Some(body_shadow) = &state.body_shadow {
                body_shadow.encode(&mut encoder, &prepared_body, scene.body, slot);
            }
            if let Some(hair_shadow) = &state.hair_shadow {
                if hair_shadow.kind == SelfShadowing::DeepOpacityMaps {
                    for index in 0..batch_count.max(1) {
                        if index < batch_count {
                            generate(&mut encoder, index);
                        }
                        hair_shadow.encode_depth(
                            &mut encoder,
                            &prepared_hair,
                            slot,
                            index,
                            batch_runs(index),
                            index == 0,
                        );
                    }
                }
                for index in 0..batch_count.max(1) {
                    if index < batch_count {
                        generate(&mut encoder, index);
                    }
                    hair_shadow.encode_opacity(
                        &mut encoder,
                        &prepared_hair,
                        &state.lighting.scene_group,
                        slot,
                        index,
                        batch_runs(index),
                        index == 0,
                    );
                }
            }
        }
        // 2. The colour passes: the body (clearing), then each batch's ribbons; the last of
        // them (or the OIT composite after them) resolves MSAA.
        let (target, resolve) = view.attachments();
        let background = scene.lighting.background;
        let oit = state.oit.as_ref();
        let pass_count = 1 + 2 * batch_count.max(1) + usize::from(oit.is_some());
        let mut pass_index = 0;
        let depth_view = view.depth();
        let mut begin_pass = |encoder: &mut wgpu::CommandEncoder| {
            let (first, last) = (pass_index == 0, pass_index + 1 == pass_count);
            pass_index += 1;
            encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("preview"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: target,
                        depth_slice: None,
                        resolve_target: if last { resolve } else { None },
                        ops: wgpu::Operations {
                            load: if first {
                                wgpu::LoadOp::Clear(wgpu::Color {
                                    r: background[0] as f64,
                                    g: background[1] as f64,
                                    b: background[2] as f64,
                                    a: 1.0,
                                })
                            } else {
                                wgpu::LoadOp::Load
                            },
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: depth_view,
                        depth_ops: Some(wgpu::Operations {
                            load: if first {
                                wgpu::LoadOp::Clear(1.0)
                            } else {
                                wgpu::LoadOp::Load
                            },
                            store: if last {
                                wgpu::StoreOp::Discard
                            } else {
                                wgpu::StoreOp::Store
                            },
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: timer.and_then(|t| t.render_pass()),
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                // Each pass ends (drops) before the next is begun; wgpu checks this at run time.
                .forget_lifetime()
        };
        let bind_lighting = |pass: &mut wgpu::RenderPass<'_>| {
            pass.set_bind_group(1, &state.lighting.scene_group, &[]);
            if let Some(group) = &effects_group {
                pass.set_bind_group(2, group, &[]);
            }
        };
        {
            let mut pass = begin_pass(&mut encoder);
            bind_lighting(&mut pass);
            state.body.draw(&mut pass, &prepared_body, scene.body);
        }
        // Every batch's depth first (a later batch may hide an earlier one), then the lit
        // ribbons where they are nearest: each visible sample is shaded once.
        for pipeline in [state.hair.depth_pipeline(), state.hair.main_pipeline()] {
            for index in 0..batch_count {
                generate(&mut encoder, index);
                let mut pass = begin_pass(&mut encoder);
                bind_lighting(&mut pass);
                if let Some(pipeline) = pipeline {
                    HairRenderer::draw_with(
                        &mut pass,
                        pipeline,
                        &prepared_hair,
                        0,
                        index,
                        batch_runs(index),
                    );
                }
            }
            if batch_count == 0 {
                // Nothing to draw: the pass still runs (it resolves when it is the last).
                drop(begin_pass(&mut encoder));
            }
        }
        // 3. Width-based coverage: the thin strands' weighted blended transparency, then its
        // composite over the opaque picture.
        if let (Some(oit), Some(pipeline)) = (oit, state.hair.oit_pipeline()) {
            for index in 0..batch_count.max(1) {
                if index < batch_count {
                    generate(&mut encoder, index);
                }
                let Some(attachments) = oit.attachments(index == 0) else {
                    break;
                };
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("preview_hair_oit"),
                    color_attachments: &attachments,
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: depth_view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: timer.and_then(|t| t.render_pass()),
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                bind_lighting(&mut pass);
                if index < batch_count {
                    HairRenderer::draw_with(
                        &mut pass,
                        pipeline,
                        &prepared_hair,
                        0,
                        index,
                        batch_runs(index),
                    );
                }
            }
            let mut pass = begin_pass(&mut encoder);
            oit.draw(&mut pass);
        }
        Ok(EncodedFrame {
            encoder,
            color: view.color().clone(),
            scratch_bytes,
        })
    }
}

/// The views a frame draws the hair and the body from: `camera`, then each shadow-casting
/// light of `shadow_views` (ribbons at least a shadow texel wide there), in the order the
/// renderers index them (view `slot + 1` is light `slot`).
pub(crate) fn frame_views(
    camera: HairUniforms,
    shadow_views: &[ShadowView],
) -> (Vec<HairUniforms>, Vec<BodyUniforms>) {
    let strand_width_m = camera.width[0];
    let mut hair_views = vec![camera];
    let mut body_views = vec![BodyUniforms {
        view_projection: camera.view_projection,
        camera_position: camera.eye,
    }];
    for (slot, light_view) in shadow_views.iter().enumerate() {
        let view_projection = light_view.view_projection.to_cols_array_2d();
        hair_views.push(HairUniforms {
            view_projection,
            eye: light_view
                .eye
                .extend(if light_view.perspective { 1.0 } else { 0.0 })
                .to_array(),
            width: [strand_width_m, light_view.texel_size, 1.0, 0.0],
            batch: [0, 0, slot as u32, 0],
        });
        body_views.push(BodyUniforms {
            view_projection,
            camera_position: light_view.eye.extend(1.0).to_array(),
        });
    }
    (hair_views, body_views)
}

/// The group-2 bind group of the lit shaders from the effect renderers that exist (the
/// preview's frame and the game runtime's).
pub(crate) fn effects_bind_group(
    context: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    hair_shadow: Option<&HairShadowRenderer>,
    body_shadow: Option<&BodyShadowRenderer>,
    lighting: &SceneLighting,
) -> wgpu::BindGroup {
    let mut entries = Vec::new();
    let view = |binding, view| wgpu::BindGroupEntry {
        binding,
        resource: wgpu::BindingResource::TextureView(view),
    };
    if let Some(hair_shadow) = hair_shadow {
        entries.push(view(binding::OPACITY_LAYERS, &hair_shadow.opacity_view));
        if let Some(first_hair) = hair_shadow.first_hair_view() {
            entries.push(view(binding::FIRST_HAIR_DEPTH, first_hair));
        }
    }
    if let Some(body_shadow) = body_shadow {
        entries.push(view(binding::BODY_DEPTH, &body_shadow.array_view));
        entries.push(wgpu::BindGroupEntry {
            binding: binding::BODY_DEPTH_SAMPLER,
            resource: wgpu::BindingResource::Sampler(&lighting.depth_sampler),
        });
    }
    if let Some(ds) = &lighting.dual_scattering {
        entries.push(wgpu::BindGroupEntry {
            binding: binding::TABLE_SAMPLER,
            resource: wgpu::BindingResource::Sampler(&lighting.table_sampler),
        });
        entries.push(view(binding::DS_PROFILE, &ds.profile_view));
        entries.push(view(binding::DS_LOBES, &ds.lobes_view));
    }
    context
        .device
        .create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("effects"),
            layout,
            entries: &entries,
        })
}

/// Refuses effect resources the adapter cannot hold, naming the scene's field and the limit.
pub fn check_effect_limits(
    limits: &wgpu::Limits,
    active: &ActiveEffects,
) -> Result<(), PreviewError> {
    if active.shadow_slots == 0 {
        return Ok(());
    }
    if active.shadow_resolution > limits.max_texture_dimension_2d {
        return Err(PreviewError::EffectLimit(format!(
            "scene.effects.shadow_resolution: {} texels is above this adapter's max_texture_dimension_2d of {}",
            active.shadow_resolution, limits.max_texture_dimension_2d
        )));
    }
    let layers = active.shadow_slots * (active.opacity_layers / 4).max(1);
    if layers > limits.max_texture_array_layers {
        return Err(PreviewError::EffectLimit(format!(
            "scene.effects.opacity_layers: {} layers for {} lights need {layers} texture layers, above this adapter's max_texture_array_layers of {}",
            active.opacity_layers, active.shadow_slots, limits.max_texture_array_layers
        )));
    }
    Ok(())
}

struct EncodedFrame {
    encoder: wgpu::CommandEncoder,
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
        culled_bundles: 0,
    }
}

/// Why a frame could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PreviewError {
    #[error(transparent)]
    Generation(StrandGenError),
    #[error("reading the frame back failed: {0}")]
    Readback(String),
    /// An effect's resource would exceed what the adapter allows; nothing was made.
    #[error("{0}")]
    EffectLimit(String),
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
