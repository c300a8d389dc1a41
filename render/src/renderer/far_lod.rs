//! Far hair's deferred level choice on the GPU (`shaders/far_lod.wgsl`, seed 001 eq. 16):
//! the widest each bundle's thick hairs look this frame at the level it draws and the next
//! coarser one, then the next frame's level. Made only where a scene asks for far hair; CPU
//! mirror `hairloom_core::runtime::far_lod`.

use hairloom_core::runtime::far_lod::{FarLodParams, measured_hairs};
use hairloom_core::runtime::gpu_types::ThickGenParams;
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::thick_hair::FarHair;
use wgpu::util::DeviceExt;

use crate::device::{GpuContext, read_buffer};
use crate::renderer::strand_gen::{
    GpuHair, StrandGenError, StrandGenRenderer, ThickGenRenderer, ThickOutput,
};
use crate::resources::Tracked;

/// The WGSL source: `shaders/shared/thick_hair.wgsl`, then `shaders/far_lod.wgsl`.
pub const FAR_LOD_SOURCE: &str = concat!(
    include_str!("../../../shaders/shared/thick_hair.wgsl"),
    include_str!("../../../shaders/far_lod.wgsl")
);

/// Workgroup size of both entry points.
const WORKGROUP_SIZE: u32 = 64;

/// The two pipelines of the level choice.
pub struct FarLodRenderer {
    widths: Tracked<wgpu::ComputePipeline>,
    levels: Tracked<wgpu::ComputePipeline>,
}

impl FarLodRenderer {
    pub fn new(context: &GpuContext) -> Self {
        let device = &context.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("far_lod"),
            source: wgpu::ShaderSource::Wgsl(FAR_LOD_SOURCE.into()),
        });
        let pipeline = |entry: &str| {
            context.resources.compute_pipeline(
                device,
                &wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: None,
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                },
            )
        };
        Self {
            widths: pipeline("thick_widths"),
            levels: pipeline("next_levels"),
        }
    }

    /// One frame of the choice for bundles drawing `levels` seen from `params.eye`: the
    /// measured thick hairs generated at `params.vertex_count` vertices, their widths, eq. 16;
    /// returns the next frame's levels (read back: the frame after uses them).
    #[expect(
        clippy::too_many_arguments,
        reason = "one frame's resources, passed through unchanged"
    )]
    pub fn step(
        &self,
        context: &GpuContext,
        generator: &StrandGenRenderer,
        thick_gen: &ThickGenRenderer,
        hair: &GpuHair,
        far: &FarHair,
        levels: &[u32],
        params: FarLodParams,
    ) -> Result<Vec<u32>, StrandGenError> {
        let device = &context.device;
        let measured = measured_hairs(far, levels);
        let count = measured.len() as u32;
        let n = params.vertex_count.max(2);
        let params = FarLodParams {
            count,
            vertex_count: n,
            ..params
        };
        let selection = ThickGenRenderer::upload_records(context, &measured);
        let vertices = u64::from(count.max(1) * n);
        let storage = |label: &str, size: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let positions = storage("far_lod_positions", vertices * 16);
        let sections = storage("far_lod_sections", vertices * 32);
        let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let blocks = levels.len().max(1);
        let mut level_data = levels.to_vec();
        level_data.resize(blocks, 0);
        let level_counts: Vec<u32> = (0..blocks)
            .map(|b| far.blocks.get(b).map_or(0, Vec::len) as u32)
            .collect();
        let uniform = init(
            "far_lod_params",
            bytemuck::bytes_of(&params),
            wgpu::BufferUsages::UNIFORM,
        );
        let levels_buffer = init(
            "far_lod_levels",
            bytemuck::cast_slice(&level_data),
            wgpu::BufferUsages::STORAGE,
        );
        let widths = init(
            "far_lod_widths",
            bytemuck::cast_slice(&vec![0u32; 2 * blocks]),
            wgpu::BufferUsages::STORAGE,
        );
        let counts = init(
            "far_lod_level_counts",
            bytemuck::cast_slice(&level_counts),
            wgpu::BufferUsages::STORAGE,
        );
        let next = storage("far_lod_next", 4 * blocks as u64);
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("far_lod_readback"),
            size: 4 * blocks as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        if count > 0 {
            thick_gen.encode(
                generator,
                context,
                &mut encoder,
                hair,
                &selection,
                ThickGenParams {
                    first: 0,
                    count,
                    vertex_count: n,
                    output_offset: 0,
                },
                Filtering::Exact,
                ThickOutput {
                    positions: &positions,
                    sections: &sections,
                },
            );
        }
        let group = |pipeline: &wgpu::ComputePipeline, entries: &[(u32, &wgpu::Buffer)]| {
            let entries: Vec<wgpu::BindGroupEntry> = entries
                .iter()
                .map(|(binding, buffer)| wgpu::BindGroupEntry {
                    binding: *binding,
                    resource: buffer.as_entire_binding(),
                })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("far_lod"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        let widths_group = group(
            &self.widths,
            &[
                (0, &uniform),
                (1, &selection),
                (2, &positions),
                (3, &sections),
                (4, &levels_buffer),
                (5, &widths),
            ],
        );
        let levels_group = group(
            &self.levels,
            &[
                (0, &uniform),
                (4, &levels_buffer),
                (5, &widths),
                (6, &counts),
                (7, &next),
            ],
        );
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("far_lod"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.widths);
            pass.set_bind_group(0, &widths_group, &[]);
            pass.dispatch_workgroups(count.div_ceil(WORKGROUP_SIZE), 1, 1);
            pass.set_pipeline(&self.levels);
            pass.set_bind_group(0, &levels_group, &[]);
            pass.dispatch_workgroups((blocks as u32).div_ceil(WORKGROUP_SIZE), 1, 1);
        }
        encoder.copy_buffer_to_buffer(&next, 0, &readback, 0, 4 * blocks as u64);
        context.queue.submit([encoder.finish()]);
        let data = read_buffer(context, &readback).map_err(StrandGenError::Readback)?;
        let mut next: Vec<u32> = bytemuck::cast_slice(&data).to_vec();
        next.truncate(levels.len());
        Ok(next)
    }
}
