//! Width-based coverage's resolve (`shaders/oit_composite.wgsl`): strands narrower than a
//! pixel are drawn a pixel wide with their true coverage into weighted blended transparency
//! targets (McGuire & Bavoil 2013; `preview_hair.wgsl`'s `fs_oit`), and this pass blends them
//! over the opaque picture per sample. Made only when the scene asks for it; its targets
//! follow the view's size.

use crate::device::GpuContext;
use crate::renderer::preview_hair::{OIT_ACCUMULATION_FORMAT, OIT_REVEALAGE_FORMAT};
use crate::renderer::{PipelineSpec, pipeline};
use crate::resources::Tracked;
use crate::view::COLOR_FORMAT;

pub const OIT_COMPOSITE_SHADER: &str = include_str!("../../../shaders/oit_composite.wgsl");

/// The shader for `sample_count` samples (single-sampled targets are plain 2D textures).
pub fn oit_composite_shader(sample_count: u32) -> String {
    if sample_count > 1 {
        OIT_COMPOSITE_SHADER.to_string()
    } else {
        OIT_COMPOSITE_SHADER
            .replace("texture_multisampled_2d<f32>", "texture_2d<f32>")
            .replace(", @builtin(sample_index) sample: u32", "")
            .replace("i32(sample)", "0")
    }
}

struct Targets {
    size: (u32, u32),
    _accumulation: Tracked<wgpu::Texture>,
    _revealage: Tracked<wgpu::Texture>,
    accumulation_view: wgpu::TextureView,
    revealage_view: wgpu::TextureView,
    group: wgpu::BindGroup,
}

pub struct OitRenderer {
    layout: wgpu::BindGroupLayout,
    pipeline: Tracked<wgpu::RenderPipeline>,
    sample_count: u32,
    targets: Option<Targets>,
}

impl OitRenderer {
    pub fn new(context: &GpuContext, sample_count: u32) -> Self {
        let device = &context.device;
        let entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: sample_count > 1,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("oit_composite"),
            entries: &[entry(0), entry(1)],
        });
        let source = oit_composite_shader(sample_count);
        let made = pipeline(
            context,
            &PipelineSpec {
                label: "oit_composite",
                source: &source,
                groups: &[&layout],
                buffers: &[],
                vertex_entry: "vs_main",
                topology: wgpu::PrimitiveTopology::TriangleList,
                fragment_entry: Some("fs_main"),
                targets: &[Some(wgpu::ColorTargetState {
                    format: COLOR_FORMAT,
                    blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
                // It runs in the view's colour pass, which has the depth target: never tested.
                depth: Some(wgpu::DepthStencilState {
                    format: crate::view::DEPTH_FORMAT,
                    depth_write_enabled: Some(false),
                    depth_compare: Some(wgpu::CompareFunction::Always),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                sample_count,
            },
        );
        Self {
            layout,
            pipeline: made,
            sample_count,
            targets: None,
        }
    }

    /// Keeps (or makes) the accumulation and revealage targets for a `width × height` view.
    pub fn ensure_targets(&mut self, context: &GpuContext, width: u32, height: u32) {
        if self
            .targets
            .as_ref()
            .is_some_and(|t| t.size == (width, height))
        {
            return;
        }
        self.targets = None;
        let make = |label: &str, format| {
            context.resources.texture(
                &context.device,
                &wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d {
                        width,
                        height,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: self.sample_count,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                        | wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                },
            )
        };
        let accumulation = make("oit_accumulation", OIT_ACCUMULATION_FORMAT);
        let revealage = make("oit_revealage", OIT_REVEALAGE_FORMAT);
        let accumulation_view = accumulation.create_view(&Default::default());
        let revealage_view = revealage.create_view(&Default::default());
        let group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("oit_composite"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&accumulation_view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&revealage_view),
                    },
                ],
            });
        self.targets = Some(Targets {
            size: (width, height),
            _accumulation: accumulation,
            _revealage: revealage,
            accumulation_view,
            revealage_view,
            group,
        });
    }

    /// The accumulation pass's colour attachments (cleared on `clear`).
    pub fn attachments(
        &self,
        clear: bool,
    ) -> Option<[Option<wgpu::RenderPassColorAttachment<'_>>; 2]> {
        let targets = self.targets.as_ref()?;
        let ops = |value: f64| wgpu::Operations {
            load: if clear {
                wgpu::LoadOp::Clear(wgpu::Color {
                    r: value,
                    g: value,
                    b: value,
                    a: value,
                })
            } else {
                wgpu::LoadOp::Load
            },
            store: wgpu::StoreOp::Store,
        };
        Some([
            Some(wgpu::RenderPassColorAttachment {
                view: &targets.accumulation_view,
                depth_slice: None,
                resolve_target: None,
                ops: ops(0.0),
            }),
            Some(wgpu::RenderPassColorAttachment {
                view: &targets.revealage_view,
                depth_slice: None,
                resolve_target: None,
                ops: ops(1.0),
            }),
        ])
    }

    /// Blends the accumulated strands over the opaque picture in `pass`.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        if let Some(targets) = &self.targets {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &targets.group, &[]);
            pass.draw(0..3, 0..1);
        }
    }
}
