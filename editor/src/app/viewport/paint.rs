//! Painting the viewport through an `egui_wgpu` paint callback (re_renderer's way into
//! egui): the panel decides on the UI thread what must change — a new asset, a restyle, a new
//! frame — and hands it over; the callback's `prepare` uploads and renders the frame into the
//! preview's kept view on the GPU (submitted, never waited for), and its `paint` draws that
//! picture into egui's own render pass. Every wgpu object lives in egui_wgpu's callback
//! resources ([`ViewportGpu`]); the panel holds none.

use super::*;
use eframe::egui_wgpu::{CallbackResources, CallbackTrait, ScreenDescriptor};
use hairloom_core::model::scene::Scene;
use hairloom_core::model::styling::StylingSet;
use hairloom_render::renderer::strand_gen::GenerationPath;
use hairloom_render::renderer::viewport_blit::ViewportBlitRenderer;

/// The viewport's GPU side, kept in egui_wgpu's callback resources.
pub(super) struct ViewportGpu {
    pub(super) context: GpuContext,
    /// Shared with measurements on worker threads.
    pub(super) generator: Arc<StrandGenRenderer>,
    preview: PreviewRenderer,
    blit: ViewportBlitRenderer,
    hair: Option<GpuSideHair>,
    /// The last rendered picture (the preview's kept colour target) and its blit binding.
    picture: Option<(wgpu::Texture, wgpu::BindGroup)>,
}

/// The hair on the GPU, with the asset it came from (its styling is rewritten in place).
struct GpuSideHair {
    gpu: GpuHair,
    hair: RuntimeHair,
    /// The body, uploaded with the hair (not per frame).
    body: GpuBody,
    /// The hair's box (strand width follows its size).
    bounds: (Vec3, Vec3),
}

impl ViewportGpu {
    /// Makes the viewport's renderers for egui's render pass (`target_format`, single
    /// sample: eframe's default and egui_kittest's).
    pub(super) fn new(context: GpuContext, target_format: wgpu::TextureFormat) -> Self {
        Self {
            // Mesh shaders where the device has them, else compute per strand.
            generator: Arc::new(StrandGenRenderer::with_path(
                &context,
                GenerationPath::preferred(&context.device),
            )),
            preview: PreviewRenderer::new(&context),
            blit: ViewportBlitRenderer::new(&context, target_format, 1),
            context,
            hair: None,
            picture: None,
        }
    }

    /// Takes a new asset: rewritten into the GPU textures in place when only the hair mesh
    /// moved, uploaded afresh otherwise.
    fn replace_hair(&mut self, replacement: Replacement, shared: &CallbackShared) {
        let Replacement {
            hair,
            bounds,
            reshape,
        } = replacement;
        if reshape
            && let Some(uploaded) = self.hair.as_mut()
            && self
                .generator
                .update_shape(&self.context, &mut uploaded.gpu, &hair)
        {
            // A head animation moves the body with the hair.
            if uploaded.hair.body != hair.body {
                uploaded.body = GpuBody::upload(&self.context, &hair.body);
            }
            uploaded.hair = *hair;
            uploaded.bounds = bounds;
            return;
        }
        let upload = self.generator.upload(&self.context, &hair);
        let mut report = shared.report.lock().unwrap_or_else(|e| e.into_inner());
        match upload {
            Ok(gpu) => {
                report.upload_error = None;
                self.hair = Some(GpuSideHair {
                    gpu,
                    body: GpuBody::upload(&self.context, &hair.body),
                    hair: *hair,
                    bounds,
                });
            }
            Err(error) => {
                // Above the adapter's limits nothing is uploaded and the viewport says
                // which limit; the document is untouched (undo the edit, or save it).
                report.upload_error = Some(format!("cannot draw this hair: {error}"));
                self.hair = None;
            }
        }
    }

    /// Does what the panel asked for, in order: a new asset or a restyle, then a frame.
    fn apply(&mut self, work: PendingWork, shared: &CallbackShared, ctx: &egui::Context) {
        if let Some(replacement) = work.full {
            self.replace_hair(replacement, shared);
        }
        if let (Some(styling), Some(uploaded)) = (work.restyle, self.hair.as_mut()) {
            uploaded.hair.set_styling(&styling);
            self.generator
                .update_styling(&self.context, &mut uploaded.gpu, &uploaded.hair);
        }
        let Some(frame) = work.frame else {
            return;
        };
        let Some(hair) = self.hair.as_ref() else {
            return;
        };
        let scene = default_scene(
            &hair.body,
            HairSource::Generated {
                generator: &self.generator,
                hair: &hair.gpu,
                filtering: frame.filtering,
                lod: frame.lod,
            },
            17,
            hair.bounds,
            frame.camera,
            &frame.lighting,
        );
        let [width, height] = frame.size;
        let plan = self.preview.plan(&scene, width, height);
        let started = std::time::Instant::now();
        let rendered = self
            .preview
            .render_texture(&self.context, &scene, &plan, width, height);
        // The status bar says what generating and drawing this frame cost, from submission
        // to the GPU finishing it, without waiting here: egui's own submission on the same
        // queue orders the picture before its use.
        let (frame_ms, timed_quality, repaint, quality) = (
            Arc::clone(&shared.frame_ms),
            Arc::clone(&shared.frame_quality),
            ctx.clone(),
            frame.quality,
        );
        self.context.queue.on_submitted_work_done(move || {
            if let (Ok(mut slot), Ok(mut timed)) = (frame_ms.lock(), timed_quality.lock()) {
                *slot = Some(started.elapsed().as_secs_f64() * 1e3);
                *timed = Some(quality);
            }
            repaint.request_repaint(); // the status bar shows the new time
        });
        let mut report = shared.report.lock().unwrap_or_else(|e| e.into_inner());
        report.drawn_strands = plan.strands;
        report.drawn_vertices = plan.vertices;
        match rendered {
            Ok(texture) => {
                report.error = None;
                let group = self.blit.bind(&self.context, &texture);
                self.picture = Some((texture, group));
            }
            Err(error) => report.error = Some(error.to_string()),
        }
        // The panel shows the new counts (and any error) on its next pass.
        ctx.request_repaint();
    }
}

/// What the panel handed over and the callback has not done yet. Only the newest of each
/// kind matters: a new asset supersedes older ones and any restyle before it.
#[derive(Default)]
pub(super) struct PendingWork {
    /// A new asset and its hair's box.
    full: Option<Replacement>,
    /// New styling for the asset on the GPU.
    restyle: Option<StylingSet>,
    frame: Option<FrameRequest>,
}

/// A new asset for the GPU.
struct Replacement {
    hair: Box<RuntimeHair>,
    /// The hair's box.
    bounds: (Vec3, Vec3),
    /// Only the hair mesh's positions changed since the asset on the GPU: its textures can
    /// be rewritten in place.
    reshape: bool,
}

impl PendingWork {
    fn upload(&mut self, hair: RuntimeHair, bounds: (Vec3, Vec3), reshape: bool) {
        // A reshape of an asset that has not reached the GPU yet is still a new asset.
        let reshape = reshape && self.full.as_ref().is_none_or(|pending| pending.reshape);
        self.full = Some(Replacement {
            hair: Box::new(hair),
            bounds,
            reshape,
        });
        self.restyle = None;
    }

    fn restyle(&mut self, styling: &StylingSet) {
        match self.full.as_mut() {
            // Not uploaded yet: upload it restyled.
            Some(pending) => pending.hair.set_styling(styling),
            None => self.restyle = Some(styling.clone()),
        }
    }
}

/// A frame to render: what the view shows and how.
pub(super) struct FrameRequest {
    camera: hairloom_render::preview::Camera,
    lighting: Scene,
    size: [u32; 2],
    quality: FrameQuality,
    filtering: Filtering,
    lod: LodSettings,
}

/// What the callback found out, read by the panel on its next pass.
#[derive(Clone, Debug, Default)]
pub(super) struct FrameReport {
    pub(super) drawn_strands: usize,
    pub(super) drawn_vertices: usize,
    /// Rendering failed.
    pub(super) error: Option<String>,
    /// The hair is above the adapter's limits.
    pub(super) upload_error: Option<String>,
}

/// Shared between the panel and its paint callbacks.
#[derive(Clone, Default)]
pub(super) struct CallbackShared {
    pub(super) pending: Arc<std::sync::Mutex<PendingWork>>,
    pub(super) report: Arc<std::sync::Mutex<FrameReport>>,
    /// Wall time of generating and drawing the last frame on the GPU (submit to idle),
    /// written by the queue's work-done callback, so drawing never waits on the GPU.
    pub(super) frame_ms: Arc<std::sync::Mutex<Option<f64>>>,
    /// The quality of the frame `frame_ms` timed.
    pub(super) frame_quality: Arc<std::sync::Mutex<Option<FrameQuality>>>,
}

/// The viewport's paint callback: `prepare` does the pending work, `paint` shows the picture.
struct ViewportCallback {
    shared: CallbackShared,
    /// Asked to repaint when the frame's numbers (and its time) are in.
    ctx: egui::Context,
    /// Whether to show the picture (not while the panel shows an error instead; the
    /// callback still runs then, to do the work that may clear it).
    show: bool,
}

impl CallbackTrait for ViewportCallback {
    fn prepare(
        &self,
        _device: &wgpu::Device,
        _queue: &wgpu::Queue,
        _screen_descriptor: &ScreenDescriptor,
        _egui_encoder: &mut wgpu::CommandEncoder,
        resources: &mut CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        let work = std::mem::take(
            &mut *self
                .shared
                .pending
                .lock()
                .unwrap_or_else(|e| e.into_inner()),
        );
        if let Some(gpu) = resources.get_mut::<ViewportGpu>() {
            gpu.apply(work, &self.shared, &self.ctx);
        }
        // The frame was submitted on the queue already, ahead of egui's own work.
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        render_pass: &mut wgpu::RenderPass<'static>,
        resources: &CallbackResources,
    ) {
        if let Some(gpu) = resources.get::<ViewportGpu>()
            && let Some((_, picture)) = &gpu.picture
            && self.show
        {
            gpu.blit.draw(render_pass, picture);
        }
    }
}

impl Viewport {
    /// The quality of the next frame: full unless the artist is interacting and the full
    /// picture is over [`FRAME_BUDGET_MS`]. Learns from the last timed frame: a full frame's
    /// time decides whether to degrade, an interactive frame's time adapts the scale.
    fn frame_quality(
        &mut self,
        ui: &egui::Ui,
        state: &EditorState,
        size: [u32; 2],
        settings: ViewSettings,
    ) -> FrameQuality {
        let timed = self
            .shared
            .frame_quality
            .lock()
            .ok()
            .and_then(|mut q| q.take());
        if let (Some(quality), Some(ms)) = (timed, self.frame_ms()) {
            match quality {
                FrameQuality::Full => self.full_frame_ms = Some(ms),
                FrameQuality::Interactive { .. } => {
                    if let Some(effort) = self.effort.as_mut() {
                        effort.learn(ms);
                    }
                }
            }
        }
        let content = (state.shown_revision(), settings, self.orbit, size);
        let changed = self
            .drawn
            .is_none_or(|d| (d.revision, d.settings, d.orbit, d.size) != content);
        let now = std::time::Instant::now();
        if changed {
            self.last_change = Some(now);
        }
        let interacting = state.edit_open()
            || self.transform.is_some()
            || ui.input(|i| i.pointer.any_down() || i.smooth_scroll_delta != egui::Vec2::ZERO)
            || self
                .last_change
                .is_some_and(|t| now.duration_since(t) < SETTLE);
        if let (true, Some(full_ms)) = (
            interacting,
            self.full_frame_ms.filter(|&ms| ms > FRAME_BUDGET_MS),
        ) {
            // Come back for the full picture once input is still.
            ui.ctx().request_repaint_after(SETTLE);
            self.effort
                .get_or_insert_with(|| InteractiveEffort::from_full_frame(full_ms))
                .quality()
        } else {
            FrameQuality::Full
        }
    }

    /// Decides what must change on the GPU — a new asset, a restyle, a new frame — when the
    /// document, settings, view or size changed, hands it to the paint callback, and adds the
    /// callback that shows the picture.
    pub(super) fn draw(&mut self, ui: &mut egui::Ui, state: &mut EditorState, rect: egui::Rect) {
        let problem = self.device_problem.lock().ok().and_then(|p| p.clone());
        if let Some(problem) = problem {
            // Nothing more is drawn on a device in this state; the document is untouched
            // and can still be saved and exported.
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                format!("{problem}\nSave your work and restart Hairloom to draw again."),
                egui::FontId::proportional(14.0),
                ui.visuals().error_fg_color,
            );
            self.error = Some(problem);
            return;
        }
        if self.gpu.is_none() {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "No GPU device: the viewport is off (hairloom render still works)",
                egui::FontId::proportional(14.0),
                ui.visuals().weak_text_color(),
            );
            return;
        }
        // What the callback found out since the last pass.
        let report = self.report();
        // The overlay does not change the picture: leave it out of what triggers GPU work.
        let settings = ViewSettings {
            wireframe: false,
            frame_glyphs: false,
            gizmo: false,
            ..self.settings
        };
        let pixels_per_point = ui.ctx().pixels_per_point();
        let full_size = [
            ((rect.width() * pixels_per_point).round() as u32).clamp(1, 8192),
            ((rect.height() * pixels_per_point).round() as u32).clamp(1, 8192),
        ];
        let quality = self.frame_quality(ui, state, full_size, settings);
        let size = quality.size(full_size);
        let key = (state.shown_revision(), settings);
        if self.uploaded != Some(key) {
            let document = state.shown_document();
            let mut pending = self
                .shared
                .pending
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            // A styling-only change (same hair mesh, body and view settings) rewrites the
            // styling buffers in place: no texture rebuild, no re-upload.
            let restyle = match (&self.hair_shown, self.uploaded) {
                (Some(shown), Some((_, uploaded_settings)))
                    if uploaded_settings == settings
                        && shown.mesh == document.hair_mesh
                        && shown.body == document.body =>
                {
                    pending.restyle(&document.styling);
                    true
                }
                _ => false,
            };
            if restyle {
                self.uploads.styling += 1;
            } else {
                // Same bundles, columns of the same lengths and settings: only positions
                // moved (the body too, with a head animation), and the GPU textures are
                // rewritten in place.
                let reshape = match (&self.hair_shown, self.uploaded) {
                    (Some(shown), Some((_, uploaded_settings))) => {
                        uploaded_settings == settings
                            && shown.mesh.bundles == document.hair_mesh.bundles
                            && shown.mesh.columns.len() == document.hair_mesh.columns.len()
                            && shown
                                .mesh
                                .columns
                                .iter()
                                .zip(&document.hair_mesh.columns)
                                .all(|(a, b)| a.positions.len() == b.positions.len())
                    }
                    _ => false,
                };
                let hair = RuntimeHair::from_document(
                    document,
                    &RuntimeOptions {
                        precision: self.settings.precision,
                        strands_per_bundle: self.settings.strands_per_bundle,
                        ..RuntimeOptions::default()
                    },
                );
                self.hair_shown = hair.textures.hair_bounds().map(|bounds| ShownHair {
                    mesh: document.hair_mesh.clone(),
                    body: document.body.clone(),
                    bounds,
                });
                if let Some(shown) = &self.hair_shown {
                    pending.upload(hair, shown.bounds, reshape);
                }
                if reshape {
                    self.uploads.shape += 1;
                } else {
                    self.uploads.full += 1;
                }
            }
            self.uploaded = Some(key);
            self.drawn = None;
        }
        let drawn = DrawnKey {
            revision: state.shown_revision(),
            settings,
            orbit: self.orbit,
            size: full_size,
            quality,
        };
        if self.drawn != Some(drawn) {
            if let Some(shown) = &self.hair_shown {
                if !self.framed_from_hair {
                    self.camera_bounds = Some(shown.bounds);
                    self.framed_from_hair = true;
                }
                let (lo, hi) = self.camera_bounds.unwrap_or(shown.bounds);
                let document_scene = &state.document().scene;
                let lighting = match quality {
                    FrameQuality::Full => document_scene.clone(),
                    FrameQuality::Interactive { .. } => Scene {
                        effects: document_scene.effects.none(),
                        ..document_scene.clone()
                    },
                };
                self.shared
                    .pending
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .frame = Some(FrameRequest {
                    camera: self.orbit.camera(lo, hi),
                    lighting,
                    size,
                    quality,
                    filtering: self.settings.filtering,
                    lod: quality.lod(self.settings.lod),
                });
                self.shown_quality = quality;
            }
            self.drawn = Some(drawn);
        }
        // No hair first: an older upload or frame error is about hair no longer shown.
        self.error = match (&self.hair_shown, &report.upload_error, &report.error) {
            (None, _, _) => Some("no bundle grows hair".into()),
            (Some(_), Some(error), _) | (Some(_), None, Some(error)) => Some(error.clone()),
            (Some(_), None, None) => None,
        };
        ui.painter().add(egui_wgpu::Callback::new_paint_callback(
            rect,
            ViewportCallback {
                shared: self.shared.clone(),
                ctx: ui.ctx().clone(),
                show: self.error.is_none(),
            },
        ));
        if let Some(error) = &self.error {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                error,
                egui::FontId::proportional(14.0),
                ui.visuals().error_fg_color,
            );
        }
    }

    /// Strands and vertices of the last frame, after culling and LOD.
    pub fn drawn(&self) -> (usize, usize) {
        let report = self.report();
        (report.drawn_strands, report.drawn_vertices)
    }

    /// Why the viewport shows no picture: no usable device, no hair, the hair above the
    /// adapter's limits, or a failed frame (the latest the paint callback reported).
    pub fn error(&self) -> Option<String> {
        let report = self.report();
        self.error.clone().or(report.upload_error).or(report.error)
    }

    /// What the paint callback reported last.
    fn report(&self) -> FrameReport {
        self.shared
            .report
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }
}

/// What the panel last sent to the GPU, on the CPU: a later change that leaves the mesh and
/// body alone is styling only.
pub(super) struct ShownHair {
    mesh: hairloom_core::HairMesh,
    body: hairloom_core::model::document::BodyMesh,
    pub(super) bounds: (Vec3, Vec3),
}
