//! The preview frame: the opaque body ([`crate::renderer::preview_body`]) and the hair as
//! camera-facing ribbons with Kajiya-Kay shading ([`crate::renderer::preview_hair`]),
//! depth-tested, 8× or 4× MSAA where the adapter supports it, into a kept [`View`] that is
//! read back as RGBA8 pixels or sampled by the editor.
//!
//! Strand vertices arrive in a storage buffer, strand-major ([`HairSource`]): generated on
//! the GPU from the runtime textures every frame, batch by batch into one bounded scratch
//! buffer (the paper's path and the game's), or stored (vertices generated beforehand: the
//! explicit-storage baseline, and the CPU reference).

use std::sync::Mutex;

use glam::{Mat4, Vec3};
use hairloom_core::runtime::frame_plan::{FramePlan, LodCamera, LodSettings, plan_frame};
use hairloom_core::runtime::strand_gen::Filtering;
use wgpu::util::DeviceExt;

use crate::device::{GpuContext, PassTimer, submit_timed};
use crate::renderer::preview_body::{BodyRenderer, BodyUniforms, GpuBody};
use crate::renderer::preview_hair::{HairRenderer, HairUniforms};
use crate::renderer::strand_gen::{GpuHair, StrandGenError, StrandGenRenderer, batch_vertex_limit};
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
    pub root_color: [f32; 3],
    pub tip_color: [f32; 3],
    pub body_color: [f32; 3],
    pub camera: Camera,
}

/// The frame of a picture: the body, then per batch the hair's generation and its ribbons,
/// into a kept [`View`]. Renderers are made once per device.
pub struct PreviewRenderer {
    body: BodyRenderer,
    hair: HairRenderer,
    /// The last view, kept while the size stays the same.
    view: Mutex<Option<View>>,
    pub sample_count: u32,
}

impl PreviewRenderer {
    /// See [`crate::view::UI_VIEW_FORMAT`].
    pub const UI_VIEW_FORMAT: wgpu::TextureFormat = crate::view::UI_VIEW_FORMAT;

    pub fn new(context: &GpuContext) -> Self {
        let sample_count = crate::view::sample_count(context);
        Self {
            body: BodyRenderer::new(context, sample_count),
            hair: HairRenderer::new(context, sample_count),
            view: Mutex::new(None),
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
    /// every pass (generation and drawing) by timestamp queries where the adapter has them,
    /// and wall time from submission to idle.
    pub fn time_frame(
        &self,
        context: &GpuContext,
        scene: &PreviewScene,
        width: u32,
        height: u32,
    ) -> Result<FrameTiming, PreviewError> {
        let plan = self.plan(scene, width, height);
        let passes = 1 + 2 * plan.batches.len().max(1);
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

    /// The bundle-level work of a frame: which strands at which detail, in batches.
    pub fn plan(&self, scene: &PreviewScene, width: u32, height: u32) -> FramePlan {
        let (width, height) = (width.max(1), height.max(1));
        match &scene.hair {
            HairSource::Generated { hair, lod, .. } => {
                let camera = LodCamera {
                    eye: scene.camera.eye,
                    view_projection: scene.camera.view_projection(width as f32 / height as f32),
                    fov_y_rad: scene.camera.fov_y_rad,
                    resolution_px: height as f32,
                };
                let max_log2 = scene.vertex_count.saturating_sub(1).max(1).ilog2();
                plan_frame(
                    &hair.bundles,
                    hair.per_bundle,
                    max_log2,
                    &camera,
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

    /// Records a frame into the kept view: the body (clearing), then per batch of the plan
    /// its generation (generated hair) and its ribbons; the last pass resolves MSAA.
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
        let mut kept = self.view.lock().unwrap_or_else(|e| e.into_inner());
        let view = View::ensure(&mut kept, context, width, height, self.sample_count);
        let view_projection = scene
            .camera
            .view_projection(view.width as f32 / view.height as f32)
            .to_cols_array_2d();
        let camera_position = scene.camera.eye.extend(1.0).to_array();
        let rgba = |c: [f32; 3]| [c[0], c[1], c[2], 1.0];
        self.body.prepare(
            context,
            &BodyUniforms {
                view_projection,
                camera_position,
                color: rgba(scene.body_color),
            },
        );
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
        let storage = |label: &str, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
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
        let owned;
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
            HairSource::Generated { generator, .. } => {
                owned = generator.scratch(context, plan);
                (&owned, owned.size())
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
        let hair = self.hair.prepare(
            context,
            &HairUniforms {
                view_projection,
                camera_position,
                root_color: rgba(scene.root_color),
                tip_color: rgba(scene.tip_color),
                width: [scene.strand_width_m, 0.0, 0.0, 0.0],
                batch: [0; 4],
            },
            &ranges,
            strands,
            &runs,
        );
        let (target, resolve) = view.attachments();
        // The body's pass, then one render pass per hair batch (after its generation pass).
        let pass_count = 1 + plan.batches.len().max(1);
        let mut pass_index = 0;
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
                                    r: 0.02,
                                    g: 0.022,
                                    b: 0.026,
                                    a: 1.0,
                                })
                            } else {
                                wgpu::LoadOp::Load
                            },
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: view.depth(),
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
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("preview"),
        });
        {
            let mut pass = begin_pass(&mut encoder);
            self.body.draw(&mut pass, scene.body);
        }
        // The one batch loop: generation into the scratch, then the batch's ribbons.
        for (index, (batch, &[first_run, _])) in plan.batches.iter().zip(&ranges).enumerate() {
            if let Some((generator, gpu_hair, filtering)) = generator {
                generator.encode(
                    context,
                    &mut encoder,
                    gpu_hair,
                    &runs,
                    first_run as usize,
                    batch,
                    filtering,
                    strands,
                    timer.and_then(|t| t.compute_pass()),
                );
            }
            let mut pass = begin_pass(&mut encoder);
            let segments = FramePlan::batch_segments(batch) as u32;
            self.hair.draw(&mut pass, &hair, index, segments);
        }
        if plan.batches.is_empty() {
            // Nothing to draw: the resolving pass still runs.
            drop(begin_pass(&mut encoder));
        }
        Ok(EncodedFrame {
            encoder,
            color: view.color().clone(),
            scratch_bytes,
        })
    }
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
}

/// The look every Hairloom picture shares (renders, the editor's viewport, benchmarks):
/// brown strands a little over a thousandth of the hair's size wide, a skin-toned body.
pub fn default_scene<'a>(
    body: &'a GpuBody,
    hair: HairSource<'a>,
    vertex_count: u32,
    (lo, hi): (Vec3, Vec3),
    camera: Camera,
) -> PreviewScene<'a> {
    PreviewScene {
        body,
        hair,
        vertex_count,
        strand_width_m: (hi - lo).length() * 0.0012,
        // Linear colours (the target is sRGB): dark brown roots, lighter tips.
        root_color: [0.018, 0.008, 0.004],
        tip_color: [0.16, 0.075, 0.03],
        body_color: [0.55, 0.38, 0.30],
        camera,
    }
}
