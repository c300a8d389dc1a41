//! Recording a prepared frame: generation, the shadow views, then the view's passes in
//! [`Phase::ORDER`] — into our own [`View`], or into a game's render pass.

use hairloom_core::model::scene::SelfShadowing;
use hairloom_core::runtime::strand_gen::Filtering;

#[cfg(doc)]
use super::Phase;
use super::{FrameRenderers, HairSource, PreparedFrame};
use crate::device::{GpuContext, PassTimer};
use crate::renderer::preview_body::GpuBody;
use crate::renderer::preview_hair::{HairRenderer, RibbonInput};
use crate::renderer::strand_gen::{GpuHair, StrandGenRenderer};
use crate::view::View;

/// Compute generation of the frame's batches into its scratch.
#[derive(Clone, Copy)]
struct Generation<'a> {
    generator: &'a StrandGenRenderer,
    hair: &'a GpuHair,
    filtering: Filtering,
}

/// Records one prepared frame's passes.
pub struct FrameRecorder<'a> {
    context: &'a GpuContext,
    renderers: &'a FrameRenderers,
    frame: &'a PreparedFrame,
    body: &'a GpuBody,
    generation: Option<Generation<'a>>,
    timer: Option<&'a PassTimer>,
    generated: bool,
}

impl<'a> FrameRecorder<'a> {
    /// A recorder of `frame`, drawn by `renderers` (synced for it); compute generation runs
    /// when `hair` is generated into a scratch buffer.
    pub fn new(
        context: &'a GpuContext,
        renderers: &'a FrameRenderers,
        frame: &'a PreparedFrame,
        body: &'a GpuBody,
        hair: &HairSource<'a>,
    ) -> Self {
        let generation = match *hair {
            HairSource::Generated {
                generator,
                hair,
                filtering,
                ..
            } if frame.input == RibbonInput::Buffer => Some(Generation {
                generator,
                hair,
                filtering,
            }),
            _ => None,
        };
        Self {
            context,
            renderers,
            frame,
            body,
            generation,
            timer: None,
            generated: false,
        }
    }

    /// Times every pass with `timer`.
    pub fn timed(mut self, timer: Option<&'a PassTimer>) -> Self {
        self.timer = timer;
        self
    }

    /// Generates batch `index` into the scratch, unless the frame has no compute generation
    /// or is one batch already generated (every pass then reads the same vertices).
    pub fn generate(&mut self, encoder: &mut wgpu::CommandEncoder, index: usize) {
        let Some(generation) = self.generation else {
            return;
        };
        let frame = self.frame;
        if index >= frame.batches.len() || (frame.batches.len() == 1 && self.generated) {
            return;
        }
        self.generated = true;
        generation.generator.encode(
            self.context,
            encoder,
            generation.hair,
            &frame.runs,
            frame.ranges[index][0] as usize,
            &frame.batches[index],
            generation.filtering,
            &frame.strands,
            self.timer.and_then(|t| t.compute_pass()),
        );
    }

    /// [`Phase::ShadowViews`]: per shadow-casting light, the body's depth, the first hair's
    /// depth (deep opacity maps) and the opacity layers, into the shadow maps.
    pub fn shadow_views(&mut self, encoder: &mut wgpu::CommandEncoder) {
        let (renderers, frame) = (self.renderers, self.frame);
        let batch_count = frame.batches.len();
        for slot in 0..frame.shadow_slots {
            if let Some(body_shadow) = &renderers.body_shadow {
                body_shadow.encode(encoder, &frame.body, self.body, slot);
            }
            let Some(hair_shadow) = &renderers.hair_shadow else {
                continue;
            };
            if hair_shadow.kind == SelfShadowing::DeepOpacityMaps {
                for index in 0..batch_count.max(1) {
                    self.generate(encoder, index);
                    hair_shadow.encode_depth(
                        encoder,
                        &frame.hair,
                        slot,
                        index,
                        frame.batch_runs(index),
                        index == 0,
                    );
                }
            }
            for index in 0..batch_count.max(1) {
                self.generate(encoder, index);
                hair_shadow.encode_opacity(
                    encoder,
                    &frame.hair,
                    &renderers.lighting.scene_group,
                    slot,
                    index,
                    frame.batch_runs(index),
                    index == 0,
                );
            }
        }
    }

    /// Everything after the shadow views into our own `view`: the body (clearing to
    /// `background`), every batch's depth then its lit ribbons (a later batch may hide an
    /// earlier one; each visible sample is shaded once), the thin strands' coverage and its
    /// composite. The last pass resolves MSAA.
    pub fn view(&mut self, encoder: &mut wgpu::CommandEncoder, view: &View, background: [f32; 3]) {
        let (renderers, frame) = (self.renderers, self.frame);
        let batch_count = frame.batches.len();
        let oit = renderers.oit.as_ref();
        let pass_count = 1 + 2 * batch_count.max(1) + usize::from(oit.is_some());
        let mut pass_index = 0;
        let timer = self.timer;
        let mut begin = |encoder: &mut wgpu::CommandEncoder| {
            let pass = begin_view_pass(
                encoder,
                view,
                background,
                pass_index == 0,
                pass_index + 1 == pass_count,
                timer,
            );
            pass_index += 1;
            pass
        };
        {
            let mut pass = begin(encoder);
            self.bind_lighting(&mut pass);
            renderers.body.draw(&mut pass, &frame.body, self.body);
        }
        for pipeline in [
            renderers.hair.depth_pipeline(),
            renderers.hair.main_pipeline(),
        ] {
            for index in 0..batch_count {
                self.generate(encoder, index);
                let mut pass = begin(encoder);
                self.bind_lighting(&mut pass);
                if let Some(pipeline) = pipeline {
                    self.draw_batch(&mut pass, pipeline, index);
                }
            }
            if batch_count == 0 {
                // Nothing to draw: the pass still runs (it resolves when it is the last).
                drop(begin(encoder));
            }
        }
        let (Some(oit), Some(pipeline)) = (oit, renderers.hair.oit_pipeline()) else {
            return;
        };
        for index in 0..batch_count.max(1) {
            self.generate(encoder, index);
            let Some(attachments) = oit.attachments(index == 0) else {
                break;
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("width_coverage"),
                color_attachments: &attachments,
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: view.depth(),
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: self.timer.and_then(|t| t.render_pass()),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.bind_lighting(&mut pass);
            if index < batch_count {
                self.draw_batch(&mut pass, pipeline, index);
            }
        }
        let mut pass = begin(encoder);
        oit.draw(&mut pass);
    }

    /// The view's phases into a pass someone else began (a game's), depth-tested against
    /// what it drew before: the body when `draw_body`, then the first batch's depth pre-pass
    /// and lit ribbons. Generation and the shadow views must have been recorded before the
    /// pass began.
    pub fn draw_into(&self, pass: &mut wgpu::RenderPass<'_>, draw_body: bool) {
        let (renderers, frame) = (self.renderers, self.frame);
        self.bind_lighting(pass);
        if draw_body {
            renderers.body.draw(pass, &frame.body, self.body);
        }
        for pipeline in [
            renderers.hair.depth_pipeline(),
            renderers.hair.main_pipeline(),
        ]
        .into_iter()
        .flatten()
        {
            HairRenderer::draw_with(pass, pipeline, &frame.hair, 0, 0, frame.batch_runs(0));
        }
    }

    /// The hair ribbons of batch `index` with `pipeline` (depth, lit or coverage).
    fn draw_batch(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        pipeline: &wgpu::RenderPipeline,
        index: usize,
    ) {
        let frame = self.frame;
        HairRenderer::draw_with(
            pass,
            pipeline,
            &frame.hair,
            0,
            index,
            frame.batch_runs(index),
        );
    }

    fn bind_lighting(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_bind_group(1, &self.renderers.lighting.scene_group, &[]);
        if let Some(group) = &self.frame.effects_group {
            pass.set_bind_group(2, group, &[]);
        }
    }
}

/// One of the view's colour passes: the first clears colour and depth, the last resolves MSAA
/// and discards depth.
fn begin_view_pass(
    encoder: &mut wgpu::CommandEncoder,
    view: &View,
    background: [f32; 3],
    first: bool,
    last: bool,
    timer: Option<&PassTimer>,
) -> wgpu::RenderPass<'static> {
    let (target, resolve) = view.attachments();
    encoder
        .begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("frame_view"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: if last { resolve } else { None },
                ops: wgpu::Operations {
                    load: if first {
                        wgpu::LoadOp::Clear(wgpu::Color {
                            r: background[0] as f64,
                            g: background[1] as f64,
                            b: background[2] as f64,
                            a: 1.0,
                        })
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: view.depth(),
                depth_ops: Some(wgpu::Operations {
                    load: if first {
                        wgpu::LoadOp::Clear(1.0)
                    } else {
                        wgpu::LoadOp::Load
                    },
                    store: if last {
                        wgpu::StoreOp::Discard
                    } else {
                        wgpu::StoreOp::Store
                    },
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timer.and_then(|t| t.render_pass()),
            occlusion_query_set: None,
            multiview_mask: None,
        })
        // Each pass ends (drops) before the next is begun; wgpu checks this at run time.
        .forget_lifetime()
}
