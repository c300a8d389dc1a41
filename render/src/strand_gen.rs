//! GPU strand generation (`shaders/strand_gen.wgsl`): strand vertex positions computed from
//! the hair-mesh texture, never stored between frames. This first stage writes positions to
//! a storage buffer for read-back (tests, benchmarks); the preview renderer consumes the same
//! shader's output.
//!
//! CPU mirror: `hairloom_core::runtime::TexturePath::position`.

use hairloom_core::gpu_types::{FILTERING_EXACT, FILTERING_HARDWARE, StrandGenParams, StrandRoot};
use hairloom_core::runtime::{Filtering, Precision, RuntimeTextures};
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
/// vertices, under the 64 MB bound). A multiple of 16 keeps root-buffer offsets 256-aligned.
pub const BATCH_STRANDS: usize = 32_768;

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
        let storage = |read_only: bool, size: u64| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: wgpu::BufferSize::new(size),
        };
        // In @binding order, as the shader declares them.
        let bind_group_layout =
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("strand_gen"),
                entries: &[
                    wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: false,
                            min_binding_size: wgpu::BufferSize::new(
                                size_of::<StrandGenParams>() as u64
                            ),
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 1,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: storage(true, size_of::<StrandRoot>() as u64),
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 2,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Texture {
                            sample_type: wgpu::TextureSampleType::Float { filterable: true },
                            view_dimension: wgpu::TextureViewDimension::D3,
                            multisampled: false,
                        },
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 3,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                        count: None,
                    },
                    wgpu::BindGroupLayoutEntry {
                        binding: 4,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: storage(false, 16),
                        count: None,
                    },
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
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("strand_gen_linear_clamp"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Self {
            pipeline,
            bind_group_layout,
            sampler,
            float32_filterable,
        }
    }

    /// Uploads the hair-mesh texture of `textures` (f32 or f16 as built).
    pub fn upload_hair_mesh(
        &self,
        context: &GpuContext,
        textures: &RuntimeTextures,
    ) -> wgpu::Texture {
        let texture = &textures.hair_mesh;
        let (format, export_format) = match textures.precision {
            Precision::F32 => (
                wgpu::TextureFormat::Rgba32Float,
                hairloom_core::export::TexelFormat::Rgba32Float,
            ),
            Precision::F16 => (
                wgpu::TextureFormat::Rgba16Float,
                hairloom_core::export::TexelFormat::Rgba16Float,
            ),
        };
        let bytes = hairloom_core::export::texel_bytes(&texture.texels, export_format);
        let size = wgpu::Extent3d {
            width: texture.width,
            height: texture.height,
            depth_or_array_layers: texture.depth,
        };
        let gpu_texture = context.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("hair_mesh"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let texel_size = 4 * export_format.bytes_per_channel() as u32;
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
        gpu_texture
    }

    /// Uniform parameters for `strand_count` strands.
    fn params(
        textures: &RuntimeTextures,
        strand_count: usize,
        vertex_count: u32,
        hardware: bool,
    ) -> StrandGenParams {
        StrandGenParams {
            position_offset: textures.position_offset.extend(0.0).to_array(),
            texture_size: [
                textures.hair_mesh.width,
                textures.hair_mesh.height,
                textures.hair_mesh.depth,
                0,
            ],
            strand_count: strand_count as u32,
            vertex_count,
            filtering: if hardware {
                FILTERING_HARDWARE
            } else {
                FILTERING_EXACT
            },
            _padding: 0,
        }
    }

    fn check_filtering(
        &self,
        context: &GpuContext,
        textures: &RuntimeTextures,
        filtering: Filtering,
    ) -> Result<bool, StrandGenError> {
        let hardware = filtering == Filtering::Hardware8Bit;
        if hardware && textures.precision == Precision::F32 && !self.float32_filterable {
            return Err(StrandGenError::NoFloat32Filtering {
                adapter: context.adapter_info.name.clone(),
            });
        }
        Ok(hardware)
    }

    /// Records one dispatch over `batch` (a range of the roots buffer) into `encoder`.
    #[expect(
        clippy::too_many_arguments,
        reason = "one dispatch's resources, passed through unchanged"
    )]
    fn dispatch(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        params: &StrandGenParams,
        roots: wgpu::BufferBinding,
        hair_mesh: &wgpu::TextureView,
        output: &wgpu::Buffer,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let device = &context.device;
        let params_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("strand_gen_params"),
            contents: bytemuck::bytes_of(params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
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
                    resource: wgpu::BindingResource::Buffer(roots),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(hair_mesh),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: output.as_entire_binding(),
                },
            ],
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("strand_gen"),
            timestamp_writes,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        let vertices = params.strand_count as u64 * params.vertex_count as u64;
        pass.dispatch_workgroups((vertices as u32).div_ceil(WORKGROUP_SIZE), 1, 1);
    }

    fn roots_buffer(context: &GpuContext, roots: &[StrandRoot]) -> wgpu::Buffer {
        let placeholder = [StrandRoot::default()];
        context
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("strand_gen_roots"),
                contents: bytemuck::cast_slice(if roots.is_empty() {
                    &placeholder
                } else {
                    roots
                }),
                usage: wgpu::BufferUsages::STORAGE,
            })
    }

    /// Generates every strand in batches of [`BATCH_STRANDS`] into one reused output buffer
    /// and measures the GPU time (nothing is read back: this is the cost of generation).
    pub fn time_generation(
        &self,
        context: &GpuContext,
        textures: &RuntimeTextures,
        hair_mesh: &wgpu::Texture,
        roots: &[StrandRoot],
        vertex_count: u32,
        filtering: Filtering,
    ) -> Result<GenerationTiming, StrandGenError> {
        let hardware = self.check_filtering(context, textures, filtering)?;
        let device = &context.device;
        let batches: Vec<&[StrandRoot]> = roots.chunks(BATCH_STRANDS).collect();
        let roots_buffer = Self::roots_buffer(context, roots);
        let scratch_bytes =
            (BATCH_STRANDS.min(roots.len().max(1)) as u64) * vertex_count as u64 * 16;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("strand_gen_positions"),
            size: scratch_bytes.max(16),
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let query_count = (2 * batches.len()).max(2) as u32;
        let query_set = timestamps.then(|| {
            device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("strand_gen_timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: query_count,
            })
        });
        let view = hair_mesh.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("strand_gen_timing"),
        });
        for (index, batch) in batches.iter().enumerate() {
            let params = Self::params(textures, batch.len(), vertex_count, hardware);
            let roots = wgpu::BufferBinding {
                buffer: &roots_buffer,
                offset: (index * BATCH_STRANDS * size_of::<StrandRoot>()) as u64,
                size: wgpu::BufferSize::new(size_of_val(*batch) as u64),
            };
            let timestamp_writes =
                query_set
                    .as_ref()
                    .map(|query_set| wgpu::ComputePassTimestampWrites {
                        query_set,
                        beginning_of_pass_write_index: Some(2 * index as u32),
                        end_of_pass_write_index: Some(2 * index as u32 + 1),
                    });
            self.dispatch(
                context,
                &mut encoder,
                &params,
                roots,
                &view,
                &output,
                timestamp_writes,
            );
        }
        let readback = query_set.as_ref().map(|query_set| {
            let size = query_count as u64 * 8;
            let resolve = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("strand_gen_timestamps_resolve"),
                size,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("strand_gen_timestamps_readback"),
                size,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            encoder.resolve_query_set(query_set, 0..query_count, &resolve, 0);
            encoder.copy_buffer_to_buffer(&resolve, 0, &readback, 0, size);
            readback
        });
        let start = std::time::Instant::now();
        context.queue.submit([encoder.finish()]);
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| StrandGenError::Readback(e.to_string()))?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let gpu_ms = match readback {
            Some(readback) => {
                let bytes = read_buffer(context, &readback).map_err(StrandGenError::Readback)?;
                let ticks: &[u64] = bytemuck::cast_slice(&bytes);
                let period_ns = context.queue.get_timestamp_period() as f64;
                let total: u64 = (0..batches.len())
                    .map(|i| ticks[2 * i + 1].saturating_sub(ticks[2 * i]))
                    .sum();
                Some(total as f64 * period_ns * 1e-6)
            }
            None => None,
        };
        Ok(GenerationTiming {
            gpu_ms,
            wall_ms,
            scratch_bytes,
            batches: batches.len(),
        })
    }

    /// Generates `roots.len() × vertex_count` positions and reads them back (strand-major).
    pub fn generate_positions(
        &self,
        context: &GpuContext,
        textures: &RuntimeTextures,
        hair_mesh: &wgpu::Texture,
        roots: &[StrandRoot],
        vertex_count: u32,
        filtering: Filtering,
    ) -> Result<Vec<[f32; 4]>, StrandGenError> {
        let hardware = self.check_filtering(context, textures, filtering)?;
        let device = &context.device;
        let params = Self::params(textures, roots.len(), vertex_count, hardware);
        let roots_buffer = Self::roots_buffer(context, roots);
        let output_size = (roots.len() as u64 * vertex_count as u64).max(1) * 16;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("strand_gen_positions"),
            size: output_size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("strand_gen_readback"),
            size: output_size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let view = hair_mesh.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("strand_gen"),
        });
        self.dispatch(
            context,
            &mut encoder,
            &params,
            roots_buffer.as_entire_buffer_binding(),
            &view,
            &output,
            None,
        );
        encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, output_size);
        context.queue.submit([encoder.finish()]);
        let bytes = read_buffer(context, &readback).map_err(StrandGenError::Readback)?;
        let mut positions: Vec<[f32; 4]> = bytemuck::cast_slice(&bytes).to_vec();
        positions.truncate(roots.len() * vertex_count as usize);
        Ok(positions)
    }
}
