//! The opaque body (`shaders/preview_body.wgsl`): the scalp and head the hair is
//! depth-tested against. Its mesh is uploaded once per document ([`GpuBody`]); a frame only
//! writes the camera into the renderer's uniform buffer.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::device::GpuContext;
use crate::renderer::{uniform_entry, view_pipeline};

pub const BODY_SHADER: &str = include_str!("../../../shaders/preview_body.wgsl");

/// Keep in sync with `shaders/preview_body.wgsl` (`BodyUniforms`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct BodyUniforms {
    pub view_projection: [[f32; 4]; 4],
    pub camera_position: [f32; 4],
    pub color: [f32; 4],
}

/// The body mesh on the GPU: vertex and index buffers, made once per document.
pub struct GpuBody {
    buffers: Option<(wgpu::Buffer, wgpu::Buffer)>,
    index_count: u32,
}

impl GpuBody {
    pub fn upload(context: &GpuContext, body: &hairloom_core::BodyMesh) -> Self {
        if body.triangles.is_empty() || body.positions.is_empty() {
            return Self::empty();
        }
        let buffer = |label: &str, contents: &[u8], usage| {
            context
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage,
                })
        };
        Self {
            buffers: Some((
                buffer(
                    "body_vertices",
                    bytemuck::cast_slice(&body.positions),
                    wgpu::BufferUsages::VERTEX,
                ),
                buffer(
                    "body_indices",
                    bytemuck::cast_slice(&body.triangles),
                    wgpu::BufferUsages::INDEX,
                ),
            )),
            index_count: body.triangles.len() as u32 * 3,
        }
    }

    /// No body: the hair alone.
    pub fn empty() -> Self {
        Self {
            buffers: None,
            index_count: 0,
        }
    }
}

/// Pipeline, layout and per-frame uniforms of the body.
pub struct BodyRenderer {
    pipeline: wgpu::RenderPipeline,
    uniforms: wgpu::Buffer,
    group: wgpu::BindGroup,
}

impl BodyRenderer {
    pub fn new(context: &GpuContext, sample_count: u32) -> Self {
        let device = &context.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview_body"),
            entries: &[uniform_entry(0, size_of::<BodyUniforms>(), false)],
        });
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3],
        })];
        let pipeline = view_pipeline(
            context,
            "preview_body",
            BODY_SHADER,
            &layout,
            &buffers,
            sample_count,
        );
        // One uniform buffer for the renderer's life: each frame is encoded and submitted
        // before the next writes it.
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("preview_body_uniforms"),
            size: size_of::<BodyUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("preview_body"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniforms.as_entire_binding(),
            }],
        });
        Self {
            pipeline,
            uniforms,
            group,
        }
    }

    /// Writes this frame's uniforms (before the frame is submitted).
    pub fn prepare(&self, context: &GpuContext, uniforms: &BodyUniforms) {
        context
            .queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(uniforms));
    }

    /// Draws `body` into `pass`.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, body: &GpuBody) {
        if let Some((vertices, indices)) = &body.buffers {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.group, &[]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..body.index_count, 0, 0..1);
        }
    }
}
