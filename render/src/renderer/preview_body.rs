//! The opaque body (`shaders/preview_body.wgsl`): the scalp and head the hair is depth-tested
//! against, lit by the scene with the hair's shadow and its own. Its mesh is uploaded once
//! per document ([`GpuBody`]); a frame writes the camera (and each shadow-casting light's
//! view, for [`crate::renderer::body_shadow`]) into one uniform buffer.

use bytemuck::{Pod, Zeroable};

use crate::device::GpuContext;
use crate::renderer::shader_composer::{ShaderKey, body_shader};
use crate::renderer::{
    PipelineSpec, Targets, pipeline, uniform_entry, view_color_target, view_depth,
};
use crate::resources::Tracked;

/// Keep in sync with `shaders/preview_body.wgsl` (`BodyUniforms`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct BodyUniforms {
    pub view_projection: [[f32; 4]; 4],
    pub camera_position: [f32; 4],
}

/// The body mesh on the GPU: positions, smooth shading normals
/// ([`hairloom_core::BodyMesh::vertex_normals`]) and indices, made once per document.
pub struct GpuBody {
    buffers: Option<BodyBuffers>,
    index_count: u32,
}

struct BodyBuffers {
    positions: Tracked<wgpu::Buffer>,
    normals: Tracked<wgpu::Buffer>,
    indices: Tracked<wgpu::Buffer>,
}

impl GpuBody {
    pub fn upload(context: &GpuContext, body: &hairloom_core::BodyMesh) -> Self {
        if body.triangles.is_empty() || body.positions.is_empty() {
            return Self::empty();
        }
        let buffer = |label: &str, contents: &[u8], usage| {
            context.resources.buffer_init(
                &context.device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage,
                },
            )
        };
        Self {
            buffers: Some(BodyBuffers {
                positions: buffer(
                    "body_vertices",
                    bytemuck::cast_slice(&body.positions),
                    wgpu::BufferUsages::VERTEX,
                ),
                normals: buffer(
                    "body_normals",
                    bytemuck::cast_slice(&body.vertex_normals()),
                    wgpu::BufferUsages::VERTEX,
                ),
                indices: buffer(
                    "body_indices",
                    bytemuck::cast_slice(&body.triangles),
                    wgpu::BufferUsages::INDEX,
                ),
            }),
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

    pub fn is_empty(&self) -> bool {
        self.buffers.is_none()
    }

    /// Binds the mesh and draws it (pipeline and groups set by the caller): positions in
    /// slot 0, and the normals in slot 1 where `with_normals` (the lit pass; shadow maps
    /// need positions only).
    pub(crate) fn draw(&self, pass: &mut wgpu::RenderPass<'_>, with_normals: bool) {
        if let Some(buffers) = &self.buffers {
            pass.set_vertex_buffer(0, buffers.positions.slice(..));
            if with_normals {
                pass.set_vertex_buffer(1, buffers.normals.slice(..));
            }
            pass.set_index_buffer(buffers.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..self.index_count, 0, 0..1);
        }
    }
}

/// One tightly packed `vec3<f32>` per vertex, for `attributes`' one location.
const fn vec3_buffer(
    attributes: &'static [wgpu::VertexAttribute; 1],
) -> Option<wgpu::VertexBufferLayout<'static>> {
    Some(wgpu::VertexBufferLayout {
        array_stride: 12,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes,
    })
}

/// The body's positions, for the shadow maps (`vs_shadow`).
pub(crate) const BODY_VERTEX_LAYOUT: [Option<wgpu::VertexBufferLayout<'static>>; 1] =
    [vec3_buffer(&wgpu::vertex_attr_array![0 => Float32x3])];

/// The body's positions and smooth normals, for the lit pass (`vs_main`).
const BODY_LIT_VERTEX_LAYOUT: [Option<wgpu::VertexBufferLayout<'static>>; 2] = [
    vec3_buffer(&wgpu::vertex_attr_array![0 => Float32x3]),
    vec3_buffer(&wgpu::vertex_attr_array![1 => Float32x3]),
];

/// The body's bindings (group 0) and its lit pipeline for the current effects.
pub struct BodyRenderer {
    layout: wgpu::BindGroupLayout,
    uniform_stride: u64,
    targets: Targets,
    pipeline: Option<(ShaderKey, Tracked<wgpu::RenderPipeline>)>,
}

/// One frame's body bindings: the camera's uniforms and each shadow view's.
pub struct PreparedBody {
    group: wgpu::BindGroup,
    stride: u64,
}

impl BodyRenderer {
    /// Drawing into the view's targets at `sample_count` samples.
    pub fn new(context: &GpuContext, sample_count: u32) -> Self {
        Self::with_targets(context, Targets::view(sample_count))
    }

    /// Drawing into targets of other formats (a game's).
    pub fn with_targets(context: &GpuContext, targets: Targets) -> Self {
        let device = &context.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview_body"),
            entries: &[uniform_entry(0, size_of::<BodyUniforms>(), true)],
        });
        let alignment = device.limits().min_uniform_buffer_offset_alignment as u64;
        Self {
            layout,
            uniform_stride: (size_of::<BodyUniforms>() as u64).div_ceil(alignment) * alignment,
            targets,
            pipeline: None,
        }
    }

    /// Group 0 of every pipeline that draws the body.
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// Makes the lit pipeline for `key` unless it exists (the previous one is freed).
    pub fn ensure(
        &mut self,
        context: &GpuContext,
        key: ShaderKey,
        scene_layout: &wgpu::BindGroupLayout,
        effects_layout: Option<&wgpu::BindGroupLayout>,
    ) {
        // The body's shader does not depend on the shading model or dual scattering.
        let key = ShaderKey {
            shading: hairloom_core::model::scene::Shading::KajiyaKay,
            dual_scattering: false,
            ..key
        };
        if self.pipeline.as_ref().is_some_and(|(k, _)| *k == key) {
            return;
        }
        self.pipeline = None;
        let source = body_shader(&key);
        let mut groups = vec![&self.layout, scene_layout];
        groups.extend(effects_layout);
        let made = pipeline(
            context,
            &PipelineSpec {
                label: "preview_body",
                source: &source,
                groups: &groups,
                buffers: &BODY_LIT_VERTEX_LAYOUT,
                vertex_entry: "vs_main",
                topology: wgpu::PrimitiveTopology::TriangleList,
                fragment_entry: Some("fs_main"),
                targets: &view_color_target(&self.targets),
                depth: Some(view_depth(&self.targets, true)),
                sample_count: self.targets.sample_count,
            },
        );
        self.pipeline = Some((key, made));
    }

    /// This frame's uniforms: `views[0]` the camera, then one per shadow-casting light.
    pub fn prepare(&self, context: &GpuContext, views: &[BodyUniforms]) -> PreparedBody {
        let stride = self.uniform_stride as usize;
        let mut bytes = vec![0u8; stride * views.len().max(1)];
        for (i, view) in views.iter().enumerate() {
            bytes[i * stride..][..size_of::<BodyUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(view));
        }
        let uniforms = context.resources.buffer_init(
            &context.device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("preview_body_uniforms"),
                contents: &bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        let group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview_body"),
                layout: &self.layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &uniforms,
                        offset: 0,
                        size: wgpu::BufferSize::new(size_of::<BodyUniforms>() as u64),
                    }),
                }],
            });
        PreparedBody {
            group,
            stride: self.uniform_stride,
        }
    }

    /// Sets view `view`'s uniforms as group 0.
    pub(crate) fn bind(pass: &mut wgpu::RenderPass<'_>, prepared: &PreparedBody, view: usize) {
        pass.set_bind_group(
            0,
            &prepared.group,
            &[(view as u64 * prepared.stride) as u32],
        );
    }

    /// Draws `body` lit, seen by the camera (`views[0]`); groups 1 and 2 are set by the caller.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, prepared: &PreparedBody, body: &GpuBody) {
        if let (Some((_, pipeline)), false) = (&self.pipeline, body.is_empty()) {
            pass.set_pipeline(pipeline);
            Self::bind(pass, prepared, 0);
            body.draw(pass, true);
        }
    }
}
