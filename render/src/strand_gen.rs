//! GPU strand generation (`shaders/strand_gen.wgsl`): every styled strand vertex computed from
//! the five runtime textures, never stored between frames. Strands are generated in batches
//! of [`BATCH_STRANDS`] into one bounded scratch buffer, which the preview draws from right
//! away; tests and benchmarks read it back or time it.
//!
//! CPU mirror: `hairloom_core::runtime::TexturePath::strand_gen`.

use std::ops::Range;

use hairloom_core::export::TexelFormat;
use hairloom_core::gpu_types::{
    FILTERING_EXACT, FILTERING_HARDWARE, StrandGenParams, StrandRoot, StylingGpu,
};
use hairloom_core::runtime::{Filtering, Precision, RuntimeTextures, Texture3d};
use wgpu::util::DeviceExt;

use crate::device::{GpuContext, read_buffer};

/// The WGSL source, validated by naga in `cargo test`.
pub const SHADER_SOURCE: &str = include_str!("../../shaders/strand_gen.wgsl");

/// Why generation failed.
#[derive(Debug, thiserror::Error)]
pub enum StrandGenError {
    #[error(
        "{adapter} cannot filter 32-bit float textures in hardware; use exact filtering or f16 textures"
    )]
    NoFloat32Filtering { adapter: String },
    #[error("reading generated positions back failed: {0}")]
    Readback(String),
}

/// Pipeline and bind-group layout of `strand_gen` (one per device).
pub struct StrandGenRenderer {
    pipeline: wgpu::ComputePipeline,
    bind_group_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    float32_filterable: bool,
}

/// Workgroup size of `main` in `strand_gen.wgsl`.
const WORKGROUP_SIZE: u32 = 64;

/// Strands generated per dispatch. The transient output buffer holds one batch, so scratch
/// memory is `BATCH_STRANDS × vertices × 16` bytes whatever the strand count (34 MB at 65
/// vertices, under the 64 MB bound).
pub const BATCH_STRANDS: usize = 32_768;

/// Bytes of the scratch buffer for `strand_count` strands of `vertex_count` vertices: one
/// batch at most.
pub fn scratch_bytes(strand_count: usize, vertex_count: u32) -> u64 {
    (BATCH_STRANDS.min(strand_count.max(1)) as u64) * vertex_count as u64 * 16
}

/// The strand ranges of the batches covering `strand_count` strands.
pub fn batches(strand_count: usize) -> impl Iterator<Item = Range<usize>> {
    (0..strand_count)
        .step_by(BATCH_STRANDS)
        .map(move |start| start..(start + BATCH_STRANDS).min(strand_count))
}

/// Measured cost of generating a set of strands.
#[derive(Clone, Copy, Debug)]
pub struct GenerationTiming {
    /// Sum of the compute passes' GPU time (timestamp queries); `None` without
    /// `TIMESTAMP_QUERY`.
    pub gpu_ms: Option<f64>,
    /// Wall time from the first submit to the GPU going idle.
    pub wall_ms: f64,
    /// Bytes of the transient output buffer.
    pub scratch_bytes: u64,
    pub batches: usize,
}

/// Everything generation reads, uploaded once (the game's per-asset data): the five
/// textures, the roots and the styling array.
pub struct GpuHair {
    pub precision: Precision,
    pub position_offset: [f32; 3],
    pub texture_size: [u32; 3],
    hair_mesh: wgpu::TextureView,
    uv: wgpu::TextureView,
    w: wgpu::TextureView,
    u: wgpu::TextureView,
    v: wgpu::TextureView,
    roots: wgpu::Buffer,
    pub root_count: usize,
    styling: wgpu::Buffer,
    /// Bytes of the textures, roots and styling on the GPU.
    pub bytes: u64,
}

fn upload_texture(
    context: &GpuContext,
    label: &str,
    texture: &Texture3d,
    precision: Precision,
    channels: usize,
) -> (wgpu::TextureView, u64) {
    let export_format = TexelFormat::for_precision(precision, channels);
    let format = match export_format {
        TexelFormat::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
        TexelFormat::Rg32Float => wgpu::TextureFormat::Rg32Float,
        TexelFormat::R32Float => wgpu::TextureFormat::R32Float,
        TexelFormat::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
        TexelFormat::Rg16Float => wgpu::TextureFormat::Rg16Float,
        TexelFormat::R16Float => wgpu::TextureFormat::R16Float,
    };
    let bytes = hairloom_core::export::texel_bytes(&texture.texels, export_format);
    let size = wgpu::Extent3d {
        width: texture.width,
        height: texture.height,
        depth_or_array_layers: texture.depth,
    };
    let gpu_texture = context.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let texel_size = (channels * export_format.bytes_per_channel()) as u32;
    context.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &gpu_texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        &bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(texture.width * texel_size),
            rows_per_image: Some(texture.height),
        },
        size,
    );
    (
        gpu_texture.create_view(&wgpu::TextureViewDescriptor::default()),
        bytes.len() as u64,
    )
}

impl StrandGenRenderer {
    pub fn new(context: &GpuContext) -> Self {
        let device = &context.device;
        let float32_filterable = device
            .features()
            .contains(wgpu::Features::FLOAT32_FILTERABLE);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("strand_gen"),
            source: wgpu::ShaderSource::Wgsl(SHADER_SOURCE.into()),
        });
        let entry = |binding: u32, ty: wgpu::BindingType| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        };
        let storage = |read_only: bool, size: u64| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: wgpu::BufferSize::new(size),
        };
        // 32-bit float textures are only filterable with FLOAT32_FILTERABLE; without it the
        // layout declares them unfilterable and hardware filtering is refused (check_filtering).
        let texture = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float {
                filterable: float32_filterable,
            },
            view_dimension: wgpu::TextureViewDimension::D3,
            multisampled: false,
        };
        let sampler_type = if float32_filterable {
            wgpu::SamplerBindingType::Filtering
        } else {
            wgpu::SamplerBindingType::NonFiltering
        };
        // In @binding order, as the shader declares them.
        let bind_group_layout =
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("strand_gen"),
                entries: &[
                    entry(
                        0,
                        wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: false,
                            min_binding_size: wgpu::BufferSize::new(
                                size_of::<StrandGenParams>() as u64
                            ),
                        },
                    ),
                    entry(1, storage(true, size_of::<StrandRoot>() as u64)),
                    entry(2, texture),
                    entry(3, wgpu::BindingType::Sampler(sampler_type)),
                    entry(4, storage(false, 16)),
                    entry(5, texture),
                    entry(6, texture),
                    entry(7, texture),
                    entry(8, texture),
                    entry(9, storage(true, size_of::<StylingGpu>() as u64)),
                ],
            });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("strand_gen"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("strand_gen"),
            layout: Some(&layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let filter = if float32_filterable {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        };
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("strand_gen_linear_clamp"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: filter,
            min_filter: filter,
            ..Default::default()
        });
        Self {
            pipeline,
            bind_group_layout,
            sampler,
            float32_filterable,
        }
    }

    /// Uploads the five textures of `textures` (f32 or f16 as built), the strand roots and
    /// the styling array (index 0 = global parameters).
    pub fn upload(
        &self,
        context: &GpuContext,
        textures: &RuntimeTextures,
        roots: &[StrandRoot],
        styling: &[StylingGpu],
    ) -> GpuHair {
        let precision = textures.precision;
        let (hair_mesh, a) =
            upload_texture(context, "hair_mesh", &textures.hair_mesh, precision, 4);
        let (uv, b) = upload_texture(context, "uv", &textures.uv, precision, 2);
        let (w, c) = upload_texture(context, "w", &textures.w, precision, 1);
        let (u, d) = upload_texture(context, "u", &textures.u, precision, 4);
        let (v, e) = upload_texture(context, "v", &textures.v, precision, 4);
        let buffer = |label: &str, contents: &[u8]| {
            context
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                })
        };
        let placeholder_root = [StrandRoot::default()];
        let roots_bytes: &[u8] = bytemuck::cast_slice(if roots.is_empty() {
            &placeholder_root
        } else {
            roots
        });
        let default_styling = [StylingGpu::from(
            &hairloom_core::styling::StylingParams::default(),
        )];
        let styling_bytes: &[u8] = bytemuck::cast_slice(if styling.is_empty() {
            &default_styling
        } else {
            styling
        });
        GpuHair {
            precision,
            position_offset: textures.position_offset.to_array(),
            texture_size: [
                textures.hair_mesh.width,
                textures.hair_mesh.height,
                textures.hair_mesh.depth,
            ],
            hair_mesh,
            uv,
            w,
            u,
            v,
            roots: buffer("strand_gen_roots", roots_bytes),
            root_count: roots.len(),
            styling: buffer("strand_gen_styling", styling_bytes),
            bytes: a + b + c + d + e + roots_bytes.len() as u64 + styling_bytes.len() as u64,
        }
    }

    /// Refuses hardware filtering of f32 textures on adapters that cannot filter them.
    pub fn check_filtering(
        &self,
        context: &GpuContext,
        filtering: Filtering,
    ) -> Result<(), StrandGenError> {
        if filtering == Filtering::Hardware8Bit && !self.float32_filterable {
            return Err(StrandGenError::NoFloat32Filtering {
                adapter: context.adapter_info.name.clone(),
            });
        }
        Ok(())
    }

    /// Records the generation of strands `batch` of `hair` into `output` (which must hold
    /// `batch.len() × vertex_count` vec4s) as one compute pass of `encoder`.
    #[expect(
        clippy::too_many_arguments,
        reason = "one dispatch's resources, passed through unchanged"
    )]
    pub fn encode(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        hair: &GpuHair,
        batch: Range<usize>,
        vertex_count: u32,
        filtering: Filtering,
        output: &wgpu::Buffer,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let device = &context.device;
        let params = StrandGenParams {
            position_offset: [
                hair.position_offset[0],
                hair.position_offset[1],
                hair.position_offset[2],
                0.0,
            ],
            texture_size: [
                hair.texture_size[0],
                hair.texture_size[1],
                hair.texture_size[2],
                0,
            ],
            strand_count: batch.len() as u32,
            vertex_count,
            filtering: match filtering {
                Filtering::Exact => FILTERING_EXACT,
                Filtering::Hardware8Bit => FILTERING_HARDWARE,
            },
            first_strand: batch.start as u32,
        };
        let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("strand_gen_params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        fn view(binding: u32, view: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: wgpu::BindingResource::TextureView(view),
            }
        }
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("strand_gen"),
            layout: &self.bind_group_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: hair.roots.as_entire_binding(),
                },
                view(2, &hair.hair_mesh),
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: output.as_entire_binding(),
                },
                view(5, &hair.uv),
                view(6, &hair.w),
                view(7, &hair.u),
                view(8, &hair.v),
                wgpu::BindGroupEntry {
                    binding: 9,
                    resource: hair.styling.as_entire_binding(),
                },
            ],
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("strand_gen"),
            timestamp_writes,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        let vertices = batch.len() as u64 * vertex_count as u64;
        pass.dispatch_workgroups((vertices as u32).div_ceil(WORKGROUP_SIZE), 1, 1);
    }

    /// A scratch buffer for one batch of `hair`'s strands.
    pub fn scratch(
        &self,
        context: &GpuContext,
        strand_count: usize,
        vertex_count: u32,
    ) -> wgpu::Buffer {
        context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("strand_gen_scratch"),
            size: scratch_bytes(strand_count, vertex_count),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        })
    }

    /// Generates every strand in batches into one reused scratch buffer and measures the GPU
    /// time (nothing is read back: this is the cost of generation).
    pub fn time_generation(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        vertex_count: u32,
        filtering: Filtering,
    ) -> Result<GenerationTiming, StrandGenError> {
        self.check_filtering(context, filtering)?;
        let device = &context.device;
        let batches: Vec<Range<usize>> = batches(hair.root_count).collect();
        let output = self.scratch(context, hair.root_count, vertex_count);
        let timer = crate::device::PassTimer::new(context, batches.len());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("strand_gen_timing"),
        });
        for batch in &batches {
            let timestamp_writes = timer.as_ref().and_then(|t| t.compute_pass());
            self.encode(
                context,
                &mut encoder,
                hair,
                batch.clone(),
                vertex_count,
                filtering,
                &output,
                timestamp_writes,
            );
        }
        let (wall_ms, gpu_ms) = crate::device::submit_timed(context, encoder, timer)
            .map_err(StrandGenError::Readback)?;
        Ok(GenerationTiming {
            gpu_ms,
            wall_ms,
            scratch_bytes: output.size(),
            batches: batches.len(),
        })
    }

    /// Generates every strand of `hair` and reads the vertices back, strand-major:
    /// (position, fraction along the strand).
    pub fn generate_positions(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        vertex_count: u32,
        filtering: Filtering,
    ) -> Result<Vec<[f32; 4]>, StrandGenError> {
        self.check_filtering(context, filtering)?;
        let device = &context.device;
        let output = self.scratch(context, hair.root_count, vertex_count);
        let mut positions = Vec::with_capacity(hair.root_count * vertex_count as usize);
        for batch in batches(hair.root_count) {
            let bytes = batch.len() as u64 * vertex_count as u64 * 16;
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("strand_gen_readback"),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("strand_gen"),
            });
            self.encode(
                context,
                &mut encoder,
                hair,
                batch,
                vertex_count,
                filtering,
                &output,
                None,
            );
            encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
            context.queue.submit([encoder.finish()]);
            let data = read_buffer(context, &readback).map_err(StrandGenError::Readback)?;
            positions.extend_from_slice(bytemuck::cast_slice(&data));
        }
        Ok(positions)
    }
}
