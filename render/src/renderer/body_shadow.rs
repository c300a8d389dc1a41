//! Body shadows: the body drawn from each shadow-casting light into a depth map
//! (`shaders/preview_body.wgsl`, `vs_shadow`), which the lit shaders compare against
//! (`shaders/light/body_shadows.wgsl`) so the head shadows the hair and itself. Made only when
//! the scene asks for body shadows; one array layer per shadow-casting light.

use crate::device::GpuContext;
use crate::renderer::preview_body::{BODY_VERTEX_LAYOUT, BodyRenderer, GpuBody, PreparedBody};
use crate::renderer::shader_composer::{ShaderKey, body_shader};
use crate::renderer::{PipelineSpec, pipeline};
use crate::resources::Tracked;
use hairloom_core::model::scene::{SelfShadowing, Shading};

pub const SHADOW_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

pub struct BodyShadowRenderer {
    pipeline: Tracked<wgpu::RenderPipeline>,
    _depth: Tracked<wgpu::Texture>,
    /// One per shadow-casting light (render targets).
    layers: Vec<wgpu::TextureView>,
    /// The whole array, for the lit shaders.
    pub array_view: wgpu::TextureView,
    pub resolution: u32,
    pub slots: u32,
}

/// A depth-only pipeline into a shadow map, biased so that surfaces do not shadow themselves.
pub(crate) fn shadow_depth_state(slope: f32) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: SHADOW_DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias: wgpu::DepthBiasState {
            constant: 2,
            slope_scale: slope,
            clamp: 0.0,
        },
    }
}

/// A 2D array of `layers` depth maps, `resolution` a side, and a view of each layer.
pub(crate) fn depth_array(
    context: &GpuContext,
    label: &str,
    resolution: u32,
    layers: u32,
) -> (
    Tracked<wgpu::Texture>,
    Vec<wgpu::TextureView>,
    wgpu::TextureView,
) {
    let texture = context.resources.texture(
        &context.device,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: resolution,
                height: resolution,
                depth_or_array_layers: layers,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: SHADOW_DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
    );
    let layer_views = (0..layers)
        .map(|layer| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                label: Some(label),
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: layer,
                array_layer_count: Some(1),
                ..Default::default()
            })
        })
        .collect();
    let array_view = texture.create_view(&wgpu::TextureViewDescriptor {
        label: Some(label),
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    (texture, layer_views, array_view)
}

impl BodyShadowRenderer {
    pub fn new(context: &GpuContext, body: &BodyRenderer, resolution: u32, slots: u32) -> Self {
        // Every body variant holds `vs_shadow`; the plainest one is compiled for it.
        let source = body_shader(&ShaderKey {
            shading: Shading::KajiyaKay,
            opacity_maps: SelfShadowing::None,
            body_shadows: false,
            dual_scattering: false,
        });
        let made = pipeline(
            context,
            &PipelineSpec {
                label: "body_shadow",
                source: &source,
                groups: &[body.layout()],
                buffers: &BODY_VERTEX_LAYOUT,
                vertex_entry: "vs_shadow",
                topology: wgpu::PrimitiveTopology::TriangleList,
                fragment_entry: None,
                targets: &[],
                depth: Some(shadow_depth_state(2.0)),
                sample_count: 1,
            },
        );
        let (depth, layers, array_view) =
            depth_array(context, "body_shadow_depth", resolution, slots);
        Self {
            pipeline: made,
            _depth: depth,
            layers,
            array_view,
            resolution,
            slots,
        }
    }

    /// Draws the body into slot `slot`'s map (view `slot + 1` of `prepared`).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        prepared: &PreparedBody,
        body: &GpuBody,
        slot: usize,
    ) {
        let Some(target) = self.layers.get(slot) else {
            return;
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("body_shadow"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: target,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        BodyRenderer::bind(&mut pass, prepared, slot + 1);
        body.draw(&mut pass, false);
    }
}
