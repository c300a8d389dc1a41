//! One renderer per feature (re_renderer's shape): each owns the pipeline and bind-group
//! layout of its shader, made once per device, and records its work into a frame that
//! [`crate::preview`] composes. Each is named after its shader: `shaders/X.wgsl` ↔
//! `renderer/X.rs` ↔ `hairloom_core::runtime::X` (the CPU mirror tests compare against).

pub mod preview_body;
pub mod preview_hair;
pub mod strand_gen;

use crate::device::GpuContext;
use crate::view::{COLOR_FORMAT, DEPTH_FORMAT};

/// A depth-tested, multisampled triangle pipeline into the view's targets, entry points
/// `vs_main` and `fs_main`: what the body and the hair ribbons share.
pub(crate) fn view_pipeline(
    context: &GpuContext,
    label: &str,
    source: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[Option<wgpu::VertexBufferLayout>],
    sample_count: u32,
) -> wgpu::RenderPipeline {
    let device = &context.device;
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
}

/// A uniform-buffer layout entry at `binding`, read by both stages.
pub(crate) fn uniform_entry(
    binding: u32,
    size: usize,
    has_dynamic_offset: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset,
            min_binding_size: wgpu::BufferSize::new(size as u64),
        },
        count: None,
    }
}
