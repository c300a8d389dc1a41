//! Offscreen preview: the opaque body and the hair as camera-facing ribbons with Kajiya-Kay
//! shading (`shaders/preview_body.wgsl`, `shaders/preview_hair.wgsl`), depth-tested, 4× MSAA
//! where the adapter supports it, read back as RGBA8 pixels.
//!
//! Strand vertices arrive in a storage buffer, strand-major ([`HairSource`]): generated on
//! the GPU from the runtime textures every frame, batch by batch into one bounded scratch
//! buffer (the paper's path and the game's), or stored (vertices generated beforehand: the
//! explicit-storage baseline, and the CPU reference).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use hairloom_core::runtime::strand_gen::Filtering;
use wgpu::util::DeviceExt;

use crate::device::{GpuContext, PassTimer, read_buffer, submit_timed};
use crate::strand_gen::{GpuHair, StrandGenError, StrandGenRenderer, batch_vertex_limit};
use hairloom_core::runtime::frame_plan::{FramePlan, LodCamera, LodSettings, plan_frame};

pub const HAIR_SHADER: &str = concat!(
    include_str!("../../shaders/shared/strand_run.wgsl"),
    include_str!("../../shaders/preview_hair.wgsl")
);
pub const BODY_SHADER: &str = include_str!("../../shaders/preview_body.wgsl");

const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Keep in sync with `shaders/preview_hair.wgsl` (`HairUniforms`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct HairUniforms {
    pub view_projection: [[f32; 4]; 4],
    pub camera_position: [f32; 4],
    pub root_color: [f32; 4],
    pub tip_color: [f32; 4],
    /// Ribbon width in model units (x); y, z, w unused.
    pub width: [f32; 4],
    /// The batch's runs: first run (x) and run count (y); z, w unused.
    pub batch: [u32; 4],
}

/// Keep in sync with `shaders/preview_body.wgsl` (`BodyUniforms`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct BodyUniforms {
    pub view_projection: [[f32; 4]; 4],
    pub camera_position: [f32; 4],
    pub color: [f32; 4],
}

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
    pub body_positions: &'a [[f32; 3]],
    pub body_triangles: &'a [[u32; 3]],
    pub hair: HairSource<'a>,
    /// Vertices per strand at full detail (`2^e + 1`).
    pub vertex_count: u32,
    pub strand_width_m: f32,
    pub root_color: [f32; 3],
    pub tip_color: [f32; 3],
    pub body_color: [f32; 3],
    pub camera: Camera,
}

/// Pipelines of the preview (one per device and sample count).
pub struct PreviewRenderer {
    hair_pipeline: wgpu::RenderPipeline,
    hair_layout: wgpu::BindGroupLayout,
    body_pipeline: wgpu::RenderPipeline,
    body_layout: wgpu::BindGroupLayout,
    pub sample_count: u32,
}

impl PreviewRenderer {
    /// The non-sRGB view format of a [`Self::render_texture`] result: sampling it returns the
    /// sRGB-encoded bytes, which is what egui composites.
    pub const UI_VIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

    pub fn new(context: &GpuContext) -> Self {
        let device = &context.device;
        let flags = |format| context.adapter.get_texture_format_features(format).flags;
        let (color, depth) = (flags(COLOR_FORMAT), flags(DEPTH_FORMAT));
        // 8× where the adapter allows it for both targets, else 4×, else none.
        let sample_count = [8, 4]
            .into_iter()
            .find(|&count| {
                color.sample_count_supported(count) && depth.sample_count_supported(count)
            })
            .unwrap_or(1);
        let uniform_entry = |size: usize| wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(size as u64),
            },
            count: None,
        };
        let hair_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview_hair"),
            entries: &[
                uniform_entry(size_of::<HairUniforms>()),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::VERTEX,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: wgpu::BufferSize::new(16),
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::VERTEX,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: wgpu::BufferSize::new(size_of::<
                            hairloom_core::runtime::gpu_types::StrandRun,
                        >() as u64),
                    },
                    count: None,
                },
            ],
        });
        let body_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview_body"),
            entries: &[uniform_entry(size_of::<BodyUniforms>())],
        });
        let pipeline = |label: &str,
                        source: &str,
                        layout: &wgpu::BindGroupLayout,
                        buffers: &[Option<wgpu::VertexBufferLayout>]| {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(layout)],
                immediate_size: 0,
            });
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: sample_count,
                    ..Default::default()
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(COLOR_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let body_buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3],
        })];
        let hair_pipeline = pipeline("preview_hair", HAIR_SHADER, &hair_layout, &[]);
        let body_pipeline = pipeline("preview_body", BODY_SHADER, &body_layout, &body_buffers);
        Self {
            hair_pipeline,
            hair_layout,
            body_pipeline,
            body_layout,
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
        let (width, height) = (frame.width, frame.height);
        // Rows of a texture-to-buffer copy are padded to 256 bytes.
        let padded_row = (width * 4).div_ceil(256) * 256;
        let readback = context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("preview_readback"),
            size: (padded_row * height) as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = frame.encoder;
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &frame.resolved,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        context.queue.submit([encoder.finish()]);
        let mapped = read_buffer(context, &readback).map_err(PreviewError::Readback)?;
        let mut pixels = Vec::with_capacity((width * height * 4) as usize);
        for row in 0..height {
            let start = (row * padded_row) as usize;
            pixels.extend_from_slice(&mapped[start..start + (width * 4) as usize]);
        }
        Ok(pixels)
    }

    /// Renders `scene` following `plan` into a new `width × height` sRGB texture that can be
    /// sampled (an editor viewport shows it); the work is submitted, not waited for.
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
        Ok(frame.resolved)
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

    /// Records a frame: the body (clearing), then the hair, one generation + draw pair per
    /// batch for generated hair.
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
        let (width, height) = (width.max(1), height.max(1));
        let view_projection = scene
            .camera
            .view_projection(width as f32 / height as f32)
            .to_cols_array_2d();
        let camera_position = scene.camera.eye.extend(1.0).to_array();
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        // The colour target may also be viewed without the sRGB suffix: UIs that composite
        // gamma-encoded bytes (egui) sample it that way (see `PreviewRenderer::UI_VIEW_FORMAT`).
        let ui_view = [Self::UI_VIEW_FORMAT];
        let target =
            |label: &str, format: wgpu::TextureFormat, samples: u32, usage: wgpu::TextureUsages| {
                device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size,
                    mip_level_count: 1,
                    sample_count: samples,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: if format == COLOR_FORMAT && samples == 1 {
                        &ui_view
                    } else {
                        &[]
                    },
                })
            };
        let resolved = target(
            "preview_color",
            COLOR_FORMAT,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let msaa = (self.sample_count > 1).then(|| {
            target(
                "preview_msaa",
                COLOR_FORMAT,
                self.sample_count,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )
        });
        let depth = target(
            "preview_depth",
            DEPTH_FORMAT,
            self.sample_count,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let resolved_view = resolved.create_view(&Default::default());
        let msaa_view = msaa.as_ref().map(|t| t.create_view(&Default::default()));
        let depth_view = depth.create_view(&Default::default());

        let body_uniforms = BodyUniforms {
            view_projection,
            camera_position,
            color: [
                scene.body_color[0],
                scene.body_color[1],
                scene.body_color[2],
                1.0,
            ],
        };
        let hair_uniforms = HairUniforms {
            view_projection,
            camera_position,
            root_color: [
                scene.root_color[0],
                scene.root_color[1],
                scene.root_color[2],
                1.0,
            ],
            tip_color: [
                scene.tip_color[0],
                scene.tip_color[1],
                scene.tip_color[2],
                1.0,
            ],
            width: [scene.strand_width_m, 0.0, 0.0, 0.0],
            batch: [0; 4],
        };
        let buffer = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let body_uniform_buffer = buffer(
            "preview_body_uniforms",
            bytemuck::bytes_of(&body_uniforms),
            wgpu::BufferUsages::UNIFORM,
        );
        let body_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview_body"),
            layout: &self.body_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: body_uniform_buffer.as_entire_binding(),
            }],
        });
        let generator_runs = match &scene.hair {
            HairSource::Generated {
                generator,
                filtering,
                ..
            } => {
                generator
                    .check_filtering(context, *filtering)
                    .map_err(PreviewError::Generation)?;
                Some(generator.upload_runs(context, plan))
            }
            _ => None,
        };
        let stored_runs;
        let runs_buffer = match &generator_runs {
            Some(runs) => runs,
            None => {
                let mut runs: Vec<_> = plan.batches.iter().flatten().copied().collect();
                if runs.is_empty() {
                    runs.push(Default::default());
                }
                stored_runs = buffer(
                    "preview_runs",
                    bytemuck::cast_slice(&runs),
                    wgpu::BufferUsages::STORAGE,
                );
                &stored_runs
            }
        };
        // Where the hair's vertices live: uploaded now, already stored, or a scratch buffer
        // that each batch's generation overwrites.
        let uploaded;
        let scratch;
        let (strands_buffer, scratch_bytes): (&wgpu::Buffer, u64) = match &scene.hair {
            HairSource::Vertices(vertices) => {
                let placeholder = [[0.0f32; 4]];
                let data = if vertices.is_empty() {
                    &placeholder[..]
                } else {
                    vertices
                };
                uploaded = buffer(
                    "preview_strands",
                    bytemuck::cast_slice(data),
                    wgpu::BufferUsages::STORAGE,
                );
                (&uploaded, 0)
            }
            HairSource::Stored { buffer, .. } => (buffer, 0),
            HairSource::Generated { generator, .. } => {
                scratch = generator.scratch(context, plan);
                (&scratch, scratch.size())
            }
        };
        let (view, resolve_view) = match &msaa_view {
            Some(msaa_view) => (msaa_view, Some(&resolved_view)),
            None => (&resolved_view, None),
        };
        // The body's pass, then one render pass per hair batch (after its generation pass);
        // the last pass resolves the multisampled target.
        let pass_count = 1 + plan.batches.len().max(1);
        let mut pass_index = 0;
        let mut begin_pass = |encoder: &mut wgpu::CommandEncoder| {
            let first = pass_index == 0;
            let last = pass_index + 1 == pass_count;
            pass_index += 1;
            encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("preview"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target: if last { resolve_view } else { None },
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
                        view: &depth_view,
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
        let body_vertices;
        let body_indices;
        {
            let mut pass = begin_pass(&mut encoder);
            if !scene.body_triangles.is_empty() {
                body_vertices = buffer(
                    "preview_body_vertices",
                    bytemuck::cast_slice(scene.body_positions),
                    wgpu::BufferUsages::VERTEX,
                );
                body_indices = buffer(
                    "preview_body_indices",
                    bytemuck::cast_slice(scene.body_triangles),
                    wgpu::BufferUsages::INDEX,
                );
                pass.set_pipeline(&self.body_pipeline);
                pass.set_bind_group(0, &body_group, &[]);
                pass.set_vertex_buffer(0, body_vertices.slice(..));
                pass.set_index_buffer(body_indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..scene.body_triangles.len() as u32 * 3, 0, 0..1);
            }
        }
        let mut first_run = 0;
        for batch in &plan.batches {
            if let HairSource::Generated {
                generator,
                hair,
                filtering,
                ..
            } = &scene.hair
            {
                generator.encode(
                    context,
                    &mut encoder,
                    hair,
                    runs_buffer,
                    first_run,
                    batch,
                    *filtering,
                    strands_buffer,
                    timer.and_then(|t| t.compute_pass()),
                );
            }
            let uniforms = HairUniforms {
                batch: [first_run as u32, batch.len() as u32, 0, 0],
                ..hair_uniforms
            };
            let uniform_buffer = buffer(
                "preview_hair_uniforms",
                bytemuck::bytes_of(&uniforms),
                wgpu::BufferUsages::UNIFORM,
            );
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview_hair"),
                layout: &self.hair_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: uniform_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: strands_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: runs_buffer.as_entire_binding(),
                    },
                ],
            });
            let mut pass = begin_pass(&mut encoder);
            let segments = FramePlan::batch_segments(batch) as u32;
            if segments > 0 {
                pass.set_pipeline(&self.hair_pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.draw(0..segments * 6, 0..1);
            }
            first_run += batch.len();
        }
        if plan.batches.is_empty() {
            // Nothing to draw: the resolving pass still runs.
            drop(begin_pass(&mut encoder));
        }
        Ok(EncodedFrame {
            encoder,
            resolved,
            width,
            height,
            scratch_bytes,
        })
    }
}

struct EncodedFrame {
    encoder: wgpu::CommandEncoder,
    resolved: wgpu::Texture,
    width: u32,
    height: u32,
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
    body: &'a hairloom_core::BodyMesh,
    hair: HairSource<'a>,
    vertex_count: u32,
    (lo, hi): (Vec3, Vec3),
    camera: Camera,
) -> PreviewScene<'a> {
    PreviewScene {
        body_positions: &body.positions,
        body_triangles: &body.triangles,
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
