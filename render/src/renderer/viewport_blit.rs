//! Draws a rendered view into an egui paint callback (`shaders/viewport_blit.wgsl`): the
//! editor's viewport renders its frame into the view's targets in the callback's `prepare`
//! and this pipeline puts the picture into egui's own render pass in `paint`.
//!
//! The view's colour target is sRGB (`COLOR_FORMAT`). Into an sRGB target it is sampled
//! through the sRGB view (decoded, then encoded again by the target); into a linear target,
//! which egui fills with gamma-encoded colours, through the raw `UI_VIEW_FORMAT` view. Either
//! way the target receives the picture's bytes unchanged.

use crate::device::GpuContext;
use crate::renderer::{PipelineSpec, pipeline};
use crate::resources::Tracked;
use crate::view::{COLOR_FORMAT, UI_VIEW_FORMAT};

pub const VIEWPORT_BLIT_SHADER: &str = include_str!("../../../shaders/viewport_blit.wgsl");

pub struct ViewportBlitRenderer {
    layout: wgpu::BindGroupLayout,
    pipeline: Tracked<wgpu::RenderPipeline>,
    sampler: wgpu::Sampler,
    /// How the picture is viewed for this target (see the module comment).
    view_format: wgpu::TextureFormat,
}

impl ViewportBlitRenderer {
    /// A blit into render passes of `target_format` with `sample_count` samples (egui's
    /// pass: the window's format, single-sampled unless the app asked for MSAA).
    pub fn new(
        context: &GpuContext,
        target_format: wgpu::TextureFormat,
        sample_count: u32,
    ) -> Self {
        let device = &context.device;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("viewport_blit"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let made = pipeline(
            context,
            &PipelineSpec {
                label: "viewport_blit",
                source: VIEWPORT_BLIT_SHADER,
                groups: &[&layout],
                buffers: &[],
                vertex_entry: "vs_main",
                topology: wgpu::PrimitiveTopology::TriangleList,
                fragment_entry: Some("fs_main"),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
                depth: None,
                sample_count: sample_count.max(1),
            },
        );
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("viewport_blit"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Self {
            layout,
            pipeline: made,
            sampler,
            view_format: if target_format.is_srgb() {
                COLOR_FORMAT
            } else {
                UI_VIEW_FORMAT
            },
        }
    }

    /// The bind group that shows `picture` (a view's colour target, see
    /// [`crate::preview::PreviewRenderer::render_texture`]).
    pub fn bind(&self, context: &GpuContext, picture: &wgpu::Texture) -> wgpu::BindGroup {
        let view = picture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.view_format),
            ..Default::default()
        });
        context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("viewport_blit"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                ],
            })
    }

    /// Draws the bound picture over the pass's viewport.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, picture: &wgpu::BindGroup) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, picture, &[]);
        pass.draw(0..3, 0..1);
    }
}
