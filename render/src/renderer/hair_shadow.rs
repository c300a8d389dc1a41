//! The hair seen from each shadow-casting light (`shaders/hair_shadow.wgsl`): opacity shadow
//! maps (Kim & Neumann 2001, seed 004) or deep opacity maps (Yuksel & Keyser 2008, seed 001),
//! CPU mirror `hairloom_core::light::opacity_maps`. Made only when the scene asks for
//! self-shadowing: the opacity layers (four per RGBA16F array layer, one group of array layers
//! per light), for deep opacity maps a first-hair depth map, and their pipelines.
//!
//! Per light and batch, deep opacity maps first draw the hair's depth (the first hair each
//! texel sees), then both kinds draw the ribbons again, adding each fragment's coverage to
//! the layers at and behind its distance.

use hairloom_core::model::scene::SelfShadowing;
use hairloom_core::runtime::gpu_types::StrandRun;

use crate::device::GpuContext;
use crate::renderer::body_shadow::{depth_array, shadow_depth_state};
use crate::renderer::preview_hair::{HairRenderer, PreparedHair, RibbonInput};
use crate::renderer::scene_lighting::first_hair_depth_entry;
use crate::renderer::shader_composer::hair_shadow_shader;
use crate::renderer::{PipelineSpec, ribbon_pipeline};
use crate::resources::Tracked;

pub const OPACITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// A shader of another source of hair drawn into the maps: its label, source and entries
/// (`fragment_entry` `None`: depth only).
#[derive(Clone, Copy)]
pub struct ShaderEntries<'a> {
    pub label: &'a str,
    pub source: &'a str,
    pub vertex_entry: &'a str,
    pub fragment_entry: Option<&'a str>,
}

pub struct HairShadowRenderer {
    pub kind: SelfShadowing,
    /// Where the ribbons' vertices come from.
    pub input: RibbonInput,
    pub layers: u32,
    pub resolution: u32,
    pub slots: u32,
    depth_pipeline: Option<Tracked<wgpu::RenderPipeline>>,
    opacity_pipeline: Tracked<wgpu::RenderPipeline>,
    _opacity: Tracked<wgpu::Texture>,
    /// Per light, its `layers / 4` array layers as render targets.
    opacity_targets: Vec<Vec<wgpu::TextureView>>,
    pub opacity_view: wgpu::TextureView,
    /// Deep opacity maps: the first hair's depth, per light and as one array.
    first_hair: Option<(
        Tracked<wgpu::Texture>,
        Vec<wgpu::TextureView>,
        wgpu::TextureView,
    )>,
    /// Deep opacity maps: the opacity pass reads the first hair's depth (group 2).
    opacity_group: Option<wgpu::BindGroup>,
    first_hair_layout: Option<wgpu::BindGroupLayout>,
    /// The opacity targets' states (additive), as every opacity pipeline writes them.
    target_states: Vec<Option<wgpu::ColorTargetState>>,
}

impl HairShadowRenderer {
    #[expect(
        clippy::too_many_arguments,
        reason = "the effect's settings, each a field of the renderer"
    )]
    pub fn new(
        context: &GpuContext,
        hair: &HairRenderer,
        scene_layout: &wgpu::BindGroupLayout,
        kind: SelfShadowing,
        layers: u32,
        resolution: u32,
        slots: u32,
        input: RibbonInput,
    ) -> Self {
        let device = &context.device;
        let source = hair_shadow_shader(kind, input);
        let topology = HairRenderer::topology(input);
        let deep = kind == SelfShadowing::DeepOpacityMaps;
        let depth_pipeline = deep.then(|| {
            ribbon_pipeline(
                context,
                &PipelineSpec {
                    label: "hair_shadow_depth",
                    source: &source,
                    groups: &[hair.draw_layout(input)],
                    buffers: &[],
                    vertex_entry: "vs_main",
                    topology,
                    fragment_entry: None,
                    targets: &[],
                    depth: Some(shadow_depth_state(0.0)),
                    sample_count: 1,
                },
                input,
            )
        });
        let first_hair_layout = deep.then(|| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("hair_shadow_first_hair"),
                entries: &[first_hair_depth_entry()],
            })
        });
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let groups = (layers / 4).clamp(1, 4) as usize;
        let targets: Vec<Option<wgpu::ColorTargetState>> = (0..4)
            .map(|g| {
                (g < groups).then_some(wgpu::ColorTargetState {
                    format: OPACITY_FORMAT,
                    blend: Some(wgpu::BlendState {
                        color: add,
                        alpha: add,
                    }),
                    write_mask: wgpu::ColorWrites::ALL,
                })
            })
            .collect();
        let mut pipeline_groups = vec![hair.draw_layout(input), scene_layout];
        pipeline_groups.extend(first_hair_layout.as_ref());
        let opacity_pipeline = ribbon_pipeline(
            context,
            &PipelineSpec {
                label: "hair_shadow_opacity",
                source: &source,
                groups: &pipeline_groups,
                buffers: &[],
                vertex_entry: "vs_main",
                topology,
                fragment_entry: Some("fs_opacity"),
                targets: &targets,
                depth: None,
                sample_count: 1,
            },
            input,
        );
        let opacity = context.resources.texture(
            device,
            &wgpu::TextureDescriptor {
                label: Some("opacity_layers"),
                size: wgpu::Extent3d {
                    width: resolution,
                    height: resolution,
                    depth_or_array_layers: slots * groups as u32,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: OPACITY_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
        );
        let opacity_targets = (0..slots)
            .map(|slot| {
                (0..groups as u32)
                    .map(|g| {
                        opacity.create_view(&wgpu::TextureViewDescriptor {
                            label: Some("opacity_layers"),
                            dimension: Some(wgpu::TextureViewDimension::D2),
                            base_array_layer: slot * groups as u32 + g,
                            array_layer_count: Some(1),
                            ..Default::default()
                        })
                    })
                    .collect()
            })
            .collect();
        let opacity_view = opacity.create_view(&wgpu::TextureViewDescriptor {
            label: Some("opacity_layers"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let first_hair = deep.then(|| depth_array(context, "first_hair_depth", resolution, slots));
        let opacity_group =
            first_hair_layout
                .as_ref()
                .zip(first_hair.as_ref())
                .map(|(layout, (_, _, array))| {
                    device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("hair_shadow_first_hair"),
                        layout,
                        entries: &[wgpu::BindGroupEntry {
                            binding: crate::renderer::scene_lighting::binding::FIRST_HAIR_DEPTH,
                            resource: wgpu::BindingResource::TextureView(array),
                        }],
                    })
                });
        Self {
            kind,
            input,
            layers,
            resolution,
            slots,
            depth_pipeline,
            opacity_pipeline,
            _opacity: opacity,
            opacity_targets,
            opacity_view,
            first_hair,
            opacity_group,
            first_hair_layout,
            target_states: targets,
        }
    }

    /// A pipeline that draws another source's hair into these maps' first-hair depth (deep
    /// opacity maps; `None` otherwise): `source`'s `vertex_entry` and, where it alpha-tests,
    /// its depth-only `fragment_entry`, bound as `groups` (group 0 of the source's own).
    pub fn depth_pipeline_for(
        &self,
        context: &GpuContext,
        shader: ShaderEntries,
        groups: &[&wgpu::BindGroupLayout],
    ) -> Option<Tracked<wgpu::RenderPipeline>> {
        let ShaderEntries {
            label,
            source,
            vertex_entry,
            fragment_entry,
        } = shader;
        self.first_hair.as_ref()?;
        Some(crate::renderer::pipeline(
            context,
            &PipelineSpec {
                label,
                source,
                groups,
                buffers: &[],
                vertex_entry,
                topology: wgpu::PrimitiveTopology::TriangleList,
                fragment_entry,
                targets: &[],
                depth: Some(shadow_depth_state(0.0)),
                sample_count: 1,
            },
        ))
    }

    /// A pipeline that adds another source's hair to these maps' opacity layers: `source`'s
    /// `vertex_entry` and `fragment_entry` (returning `OpacityOutput`), its own group 0
    /// layout `own`, then the scene (group 1) and, for deep opacity maps, the first hair's
    /// depth (group 2), as [`Self::opacity_pass`] binds them.
    pub fn opacity_pipeline_for(
        &self,
        context: &GpuContext,
        shader: ShaderEntries,
        own: &wgpu::BindGroupLayout,
        scene_layout: &wgpu::BindGroupLayout,
    ) -> Tracked<wgpu::RenderPipeline> {
        let ShaderEntries {
            label,
            source,
            vertex_entry,
            fragment_entry,
        } = shader;
        let mut groups = vec![own, scene_layout];
        groups.extend(self.first_hair_layout.as_ref());
        crate::renderer::pipeline(
            context,
            &PipelineSpec {
                label,
                source,
                groups: &groups,
                buffers: &[],
                vertex_entry,
                topology: wgpu::PrimitiveTopology::TriangleList,
                fragment_entry,
                targets: &self.target_states,
                depth: None,
                sample_count: 1,
            },
        )
    }

    /// Whether these maps serve a scene with these settings.
    pub fn fits(
        &self,
        kind: SelfShadowing,
        layers: u32,
        resolution: u32,
        slots: u32,
        input: RibbonInput,
    ) -> bool {
        if self.input != input {
            return false;
        }
        (self.kind, self.layers, self.resolution, self.slots) == (kind, layers, resolution, slots)
    }

    /// The first hair's depth (deep opacity maps), for the lit shaders.
    pub fn first_hair_view(&self) -> Option<&wgpu::TextureView> {
        self.first_hair.as_ref().map(|(_, _, array)| array)
    }

    /// Deep opacity maps' depth pass of light `slot` for one batch (ribbons of view
    /// `slot + 1` in `prepared`); `clear` on the first batch.
    pub fn encode_depth(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        prepared: &PreparedHair,
        slot: usize,
        batch: usize,
        runs: &[StrandRun],
        clear: bool,
    ) {
        let (Some(pipeline), Some(mut pass)) =
            (&self.depth_pipeline, self.depth_pass(encoder, slot, clear))
        else {
            return;
        };
        HairRenderer::draw_with(&mut pass, pipeline, prepared, slot + 1, batch, runs);
    }

    /// Deep opacity maps' depth pass of light `slot` (`None` for opacity shadow maps),
    /// cleared when `clear`.
    pub fn depth_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        slot: usize,
        clear: bool,
    ) -> Option<wgpu::RenderPass<'static>> {
        let (_, layers, _) = self.first_hair.as_ref()?;
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("hair_shadow_depth"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &layers[slot],
                depth_ops: Some(wgpu::Operations {
                    load: if clear {
                        wgpu::LoadOp::Clear(1.0)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        // Each pass ends (drops) before the next is begun; wgpu checks this at run time.
        Some(pass.forget_lifetime())
    }

    /// The opacity pass of light `slot` for one batch; `clear` on the first batch.
    #[expect(
        clippy::too_many_arguments,
        reason = "one pass's inputs, passed through"
    )]
    pub fn encode_opacity(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        prepared: &PreparedHair,
        scene_group: &wgpu::BindGroup,
        slot: usize,
        batch: usize,
        runs: &[StrandRun],
        clear: bool,
    ) {
        let mut pass = self.opacity_pass(encoder, scene_group, slot, clear);
        HairRenderer::draw_with(
            &mut pass,
            &self.opacity_pipeline,
            prepared,
            slot + 1,
            batch,
            runs,
        );
    }

    /// The opacity pass of light `slot`, cleared when `clear`, with the scene (group 1) and,
    /// for deep opacity maps, the first hair's depth (group 2) bound.
    pub fn opacity_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene_group: &wgpu::BindGroup,
        slot: usize,
        clear: bool,
    ) -> wgpu::RenderPass<'static> {
        let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = (0..4)
            .map(|g| {
                self.opacity_targets[slot]
                    .get(g)
                    .map(|view| wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: if clear {
                                wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT)
                            } else {
                                wgpu::LoadOp::Load
                            },
                            store: wgpu::StoreOp::Store,
                        },
                    })
            })
            .collect();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("hair_shadow_opacity"),
            color_attachments: &attachments,
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(1, scene_group, &[]);
        if let Some(group) = &self.opacity_group {
            pass.set_bind_group(2, group, &[]);
        }
        pass.forget_lifetime()
    }
}
