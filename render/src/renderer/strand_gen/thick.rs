//! Far hair's thick hairs on the GPU (`thick_main` of `shaders/strand_gen.wgsl`): each thick
//! hair's centre line and cross-section half-axes generated from its four corner strands,
//! every frame, from the same textures as the strands (so a thick hair follows the hair mesh
//! with no refit). Exists only where a scene asks for far hair; CPU mirror
//! `hairloom_core::runtime::strand_gen::StrandGen::thick_main`.

use hairloom_core::runtime::gpu_types::{ThickGenParams, ThickHairGpu};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::thick_hair::FarHair;
use wgpu::util::DeviceExt;

use super::*;
use crate::device::{GpuContext, read_buffer};
use crate::resources::Tracked;

/// Workgroup size of `thick_main`.
const WORKGROUP_SIZE: u32 = 64;

/// The thick-hair pipeline (one per device, made only when far hair is on).
pub struct ThickGenRenderer {
    pipeline: Tracked<wgpu::ComputePipeline>,
    bind_group_layout: wgpu::BindGroupLayout,
}

/// A hair's far-hair table on the GPU.
pub struct GpuFarHair {
    pub table: FarHair,
    thick_hairs: Tracked<wgpu::Buffer>,
}

impl GpuFarHair {
    /// Uploads `table` (what a frame that draws far hair reads; no pipeline needed).
    pub fn upload(context: &GpuContext, table: FarHair) -> Self {
        let thick_hairs = ThickGenRenderer::upload_records(context, &table.thick_hairs);
        Self { table, thick_hairs }
    }

    /// Bytes of the table on the GPU.
    pub fn bytes(&self) -> u64 {
        self.thick_hairs.size()
    }

    /// The thick-hair records (`ThickHairGpu`, at least one).
    pub fn thick_hairs(&self) -> &wgpu::Buffer {
        &self.thick_hairs
    }
}

/// Thick hairs read back: per vertex the centre and `along`, and two half-axes.
pub struct ThickReadback {
    pub positions: Vec<[f32; 4]>,
    pub sections: Vec<[f32; 4]>,
}

/// What one thick-hair dispatch writes: per vertex, the centre and `along` (`positions`) and
/// two half-axes (`sections`: major with the member count in w, then minor).
pub struct ThickOutput<'a> {
    pub positions: &'a wgpu::Buffer,
    pub sections: &'a wgpu::Buffer,
}

impl ThickGenRenderer {
    pub fn new(context: &GpuContext) -> Self {
        let device = &context.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("thick_gen"),
            source: wgpu::ShaderSource::Wgsl(SHADER_SOURCE.into()),
        });
        let buffer =
            |binding: u32, ty: wgpu::BufferBindingType, size: u64| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty,
                    has_dynamic_offset: false,
                    min_binding_size: wgpu::BufferSize::new(size),
                },
                count: None,
            };
        let storage = |read_only| wgpu::BufferBindingType::Storage { read_only };
        let mut entries = source_layout_entries(device, 0, wgpu::ShaderStages::COMPUTE);
        entries.push(buffer(4, storage(false), 16));
        entries.push(buffer(12, storage(true), size_of::<ThickHairGpu>() as u64));
        entries.push(buffer(13, storage(false), 32));
        entries.push(buffer(
            14,
            wgpu::BufferBindingType::Uniform,
            size_of::<ThickGenParams>() as u64,
        ));
        let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("thick_gen"),
            entries: &entries,
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("thick_gen"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });
        let pipeline = context.resources.compute_pipeline(
            device,
            &wgpu::ComputePipelineDescriptor {
                label: Some("thick_gen"),
                layout: Some(&layout),
                module: &module,
                entry_point: Some("thick_main"),
                compilation_options: Default::default(),
                cache: None,
            },
        );
        Self {
            pipeline,
            bind_group_layout,
        }
    }

    /// Thick-hair records as `thick_main` reads them (none uploads one unused record:
    /// bindings cannot be empty).
    pub fn upload_records(context: &GpuContext, records: &[ThickHairGpu]) -> Tracked<wgpu::Buffer> {
        let placeholder = [ThickHairGpu::default()];
        let records = if records.is_empty() {
            &placeholder[..]
        } else {
            records
        };
        context.resources.buffer_init(
            &context.device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("far_hair_thick_hairs"),
                contents: bytemuck::cast_slice(records),
                usage: wgpu::BufferUsages::STORAGE,
            },
        )
    }

    /// Records the generation of `thick_hairs[first..][..count]` (records as
    /// [`Self::upload_records`] makes them) at `vertex_count` vertices each into `output` from
    /// vertex `output_offset` on, as one compute pass.
    #[expect(
        clippy::too_many_arguments,
        reason = "one dispatch's resources, passed through unchanged"
    )]
    pub fn encode(
        &self,
        generator: &StrandGenRenderer,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        hair: &GpuHair,
        thick_hairs: &wgpu::Buffer,
        params: ThickGenParams,
        filtering: Filtering,
        output: ThickOutput,
    ) {
        let strand_params = generator.params_buffer(context, hair, filtering, 0, &[]);
        let thick_params = context
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("thick_gen_params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let mut entries = generator.source_entries(0, hair, &strand_params);
        for (binding, buffer) in [
            (4, output.positions),
            (12, thick_hairs),
            (13, output.sections),
            (14, &thick_params),
        ] {
            entries.push(wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            });
        }
        let bind_group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("thick_gen"),
                layout: &self.bind_group_layout,
                entries: &entries,
            });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("thick_gen"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(params.count.div_ceil(WORKGROUP_SIZE), 1, 1);
    }

    /// Generates `far.table.thick_hairs[first..][..count]` and reads back the centres and
    /// sections (tests and benchmarks).
    #[expect(
        clippy::too_many_arguments,
        reason = "one dispatch's resources, passed through unchanged"
    )]
    pub fn generate(
        &self,
        generator: &StrandGenRenderer,
        context: &GpuContext,
        hair: &GpuHair,
        far: &GpuFarHair,
        first: u32,
        count: u32,
        vertex_count: u32,
        filtering: Filtering,
    ) -> Result<ThickReadback, StrandGenError> {
        let vertices = (count.max(1) * vertex_count.max(2)) as u64;
        let device = &context.device;
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let out = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let read = wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ;
        let positions = buffer("thick_positions", vertices * 16, out);
        let sections = buffer("thick_sections", vertices * 32, out);
        let positions_read = buffer("thick_positions_read", vertices * 16, read);
        let sections_read = buffer("thick_sections_read", vertices * 32, read);
        let mut encoder = device.create_command_encoder(&Default::default());
        self.encode(
            generator,
            context,
            &mut encoder,
            hair,
            far.thick_hairs(),
            ThickGenParams {
                first,
                count,
                vertex_count,
                output_offset: 0,
            },
            filtering,
            ThickOutput {
                positions: &positions,
                sections: &sections,
            },
        );
        encoder.copy_buffer_to_buffer(&positions, 0, &positions_read, 0, vertices * 16);
        encoder.copy_buffer_to_buffer(&sections, 0, &sections_read, 0, vertices * 32);
        context.queue.submit([encoder.finish()]);
        let positions = read_buffer(context, &positions_read).map_err(StrandGenError::Readback)?;
        let sections = read_buffer(context, &sections_read).map_err(StrandGenError::Readback)?;
        let used = (count * vertex_count.max(2)) as usize;
        Ok(ThickReadback {
            positions: bytemuck::cast_slice(&positions)[..used].to_vec(),
            sections: bytemuck::cast_slice(&sections)[..2 * used].to_vec(),
        })
    }
}
