//! Hair ribbons (`shaders/preview_hair.wgsl`): every strand segment a camera-facing quad
//! with eq. 5-6 tangents (CPU mirror: `hairloom_core::runtime::preview_hair`), Kajiya-Kay
//! shading and a root-to-tip colour, read from the strand vertices of one batch.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::device::GpuContext;
use crate::renderer::{uniform_entry, view_pipeline};

pub const HAIR_SHADER: &str = concat!(
    include_str!("../../../shaders/shared/strand_run.wgsl"),
    include_str!("../../../shaders/preview_hair.wgsl")
);

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

/// Pipeline and layout of the ribbons.
pub struct HairRenderer {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    /// Bytes between two batches' uniforms (the adapter's dynamic-offset alignment).
    uniform_stride: u64,
}

/// One frame's ribbon resources: every batch's uniforms in one buffer, one bind group.
pub struct PreparedHair {
    group: wgpu::BindGroup,
    stride: u64,
}

impl HairRenderer {
    pub fn new(context: &GpuContext, sample_count: u32) -> Self {
        let device = &context.device;
        let storage = |binding: u32, size: u64| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(size),
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview_hair"),
            entries: &[
                // Dynamic offset: one uniform buffer holds every batch of a frame.
                uniform_entry(0, size_of::<HairUniforms>(), true),
                storage(1, 16),
                storage(
                    2,
                    size_of::<hairloom_core::runtime::gpu_types::StrandRun>() as u64,
                ),
            ],
        });
        let pipeline = view_pipeline(
            context,
            "preview_hair",
            HAIR_SHADER,
            &layout,
            &[],
            sample_count,
        );
        let alignment = device.limits().min_uniform_buffer_offset_alignment as u64;
        Self {
            pipeline,
            layout,
            uniform_stride: (size_of::<HairUniforms>() as u64).div_ceil(alignment) * alignment,
        }
    }

    /// The uniforms of `batch_count` batches (`base` with each batch's run range, from
    /// `batches`) and one bind group over them, the strand vertices and the runs.
    pub fn prepare(
        &self,
        context: &GpuContext,
        base: &HairUniforms,
        batches: &[[u32; 2]],
        strands: &wgpu::Buffer,
        runs: &wgpu::Buffer,
    ) -> PreparedHair {
        let stride = self.uniform_stride as usize;
        let mut bytes = vec![0u8; stride * batches.len().max(1)];
        for (i, &[first_run, run_count]) in batches.iter().enumerate() {
            let uniforms = HairUniforms {
                batch: [first_run, run_count, 0, 0],
                ..*base
            };
            bytes[i * stride..][..size_of::<HairUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(&uniforms));
        }
        let uniforms = context
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("preview_hair_uniforms"),
                contents: &bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview_hair"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &uniforms,
                            offset: 0,
                            size: wgpu::BufferSize::new(size_of::<HairUniforms>() as u64),
                        }),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: strands.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: runs.as_entire_binding(),
                    },
                ],
            });
        PreparedHair {
            group,
            stride: self.uniform_stride,
        }
    }

    /// Draws batch `batch` (its `segments` segments) into `pass`.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        prepared: &PreparedHair,
        batch: usize,
        segments: u32,
    ) {
        if segments > 0 {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(
                0,
                &prepared.group,
                &[(batch as u64 * prepared.stride) as u32],
            );
            pass.draw(0..segments * 6, 0..1);
        }
    }
}
