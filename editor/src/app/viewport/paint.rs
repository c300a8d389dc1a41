//! Painting the viewport through an `egui_wgpu` paint callback (re_renderer's way into
//! egui): the panel decides on the UI thread what must change — a new asset, a restyle, a new
//! frame — and hands it over; the callback's `prepare` uploads and renders the frame into the
//! preview's kept view on the GPU (submitted, never waited for), and its `paint` draws that
//! picture into egui's own render pass. Every wgpu object lives in egui_wgpu's callback
//! resources ([`ViewportGpu`]); the panel holds none.

use super::*;
use eframe::egui_wgpu::{CallbackResources, CallbackTrait, ScreenDescriptor};
use hairloom_core::model::scene::Scene;
use hairloom_render::hair_asset::{AssetBuilder, AssetChange, HairAsset, HairAssetError};
use hairloom_render::renderer::preview_body::GpuBody;
use hairloom_render::renderer::strand_gen::GenerationPath;
use hairloom_render::renderer::viewport_blit::ViewportBlitRenderer;

/// How often a viewport waiting for far hair's hierarchy (built on a worker) draws again to
/// pick it up.
const FAR_HAIR_POLL: std::time::Duration = std::time::Duration::from_millis(100);

/// The viewport's GPU side, kept in egui_wgpu's callback resources.
pub(super) struct ViewportGpu {
    pub(super) context: GpuContext,
    /// Shared with measurements on worker threads.
    pub(super) generator: Arc<StrandGenRenderer>,
    preview: PreviewRenderer,
    blit: ViewportBlitRenderer,
    /// The shown document's hair on the GPU, changed only through [`HairAsset::apply`].
    hair: Option<HairAsset>,
    /// The body and its box when no bundle grows hair yet (a scalp just imported): drawn
    /// alone, so the artist sees the head to extrude from.
    bare_body: Option<(GpuBody, (Vec3, Vec3))>,
    /// The last rendered picture (the preview's kept colour target) and its blit binding.
    picture: Option<(wgpu::Texture, wgpu::BindGroup)>,
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
            bare_body: None,
            picture: None,
        }
    }

    /// Does what the panel asked for, in order: the asset's change, then a frame.
    fn apply(&mut self, work: PendingWork, shared: &CallbackShared, ctx: &egui::Context) {
        if let Some(change) = work.change {
            // Hair with no bundle that grows: its body is drawn alone.
            let bare = match &change {
                AssetChange::Hair { hair, .. } if hair.textures.hair_bounds().is_none() => hair
                    .body
                    .bounds()
                    .map(|bounds| (GpuBody::upload(&self.context, &hair.body), bounds)),
                _ => None,
            };
            if let AssetChange::Hair { .. } = &change {
                self.bare_body = None;
            }
            let applied =
                HairAsset::apply_to(&mut self.hair, &self.context, &self.generator, change);
            if let (Err(HairAssetError::NoHair), Some(bare)) = (&applied, bare) {
                self.bare_body = Some(bare);
                let mut report = shared.report.lock().unwrap_or_else(|e| e.into_inner());
                report.upload_error = None;
                drop(report);
                if let Some(frame) = work.frame {
                    self.draw_bare_body(frame, shared, ctx);
                }
                return;
            }
            let mut report = shared.report.lock().unwrap_or_else(|e| e.into_inner());
            match applied {
                // Nothing changed (a restyle of hair that could not be uploaded): the
                // upload's error stands.
                Ok(ChangeKind::Scene) => {}
                Ok(kind) => {
                    report.upload_error = None;
                    match kind {
                        ChangeKind::Scene => {}
                        ChangeKind::Restyle => report.uploads.styling += 1,
                        ChangeKind::Reshape => report.uploads.shape += 1,
                        ChangeKind::Rebuild => report.uploads.full += 1,
                    }
                }
                // Above the adapter's limits nothing is uploaded and the viewport says which
                // limit; the document is untouched (undo the edit, or save it).
                Err(error) => report.upload_error = Some(format!("cannot draw this hair: {error}")),
            }
        }
        let Some(frame) = work.frame else {
            return;
        };
        let Some(hair) = self.hair.as_mut() else {
            self.draw_bare_body(frame, shared, ctx);
            return;
        };
        // Far hair's hierarchy is built on a worker (seconds on a long groom): strands are
        // drawn until it is ready, and the viewport asks to be drawn again to pick it up.
        if frame.lighting.effects.far_hair == hairloom_core::model::scene::FarHair::Aggregated {
            match hair.prepare_far_hair(&self.context) {
                Ok(true) => {}
                Ok(false) => ctx.request_repaint_after(FAR_HAIR_POLL),
                Err(error) => {
                    let mut report = shared.report.lock().unwrap_or_else(|e| e.into_inner());
                    report.upload_error = Some(format!("cannot draw far hair: {error}"));
                }
            }
        }
        if frame.lighting.effects.fur == hairloom_core::model::scene::Fur::ShellsFins
            && let Err(error) = hair.ensure_fur(&self.context, &frame.lighting.effects.fur_shells)
        {
            let mut report = shared.report.lock().unwrap_or_else(|e| e.into_inner());
            report.upload_error = Some(format!("cannot draw fur: {error}"));
        }
        let hair = &*hair;
        // As many vertices as the styling's curls and waves need (vertex LOD thins far ones).
        let vertex_count = (1u32 << hair.strand_vertices_log2()) + 1;
        let scene = default_scene(
            hair.body(),
            hair.source(&self.generator, frame.filtering, frame.lod),
            vertex_count,
            hair.bounds(),
            frame.camera,
            &frame.lighting,
        );
        Self::render_and_report(
            &self.context,
            &self.preview,
            &self.blit,
            &mut self.picture,
            &scene,
            &frame,
            shared,
            ctx,
        );
    }

    /// The body alone, where no bundle grows hair yet (nothing when there is no body).
    fn draw_bare_body(
        &mut self,
        frame: FrameRequest,
        shared: &CallbackShared,
        ctx: &egui::Context,
    ) {
        let Some((body, bounds)) = &self.bare_body else {
            return;
        };
        let scene = default_scene(
            body,
            hairloom_render::preview::HairSource::Vertices(&[]),
            17,
            *bounds,
            frame.camera,
            &frame.lighting,
        );
        Self::render_and_report(
            &self.context,
            &self.preview,
            &self.blit,
            &mut self.picture,
            &scene,
            &frame,
            shared,
            ctx,
        );
    }

    /// Renders `scene` into the kept picture and reports its counts, time and any error.
    #[expect(
        clippy::too_many_arguments,
        reason = "disjoint fields of the viewport's GPU side, borrowed apart from the scene"
    )]
    fn render_and_report(
        context: &GpuContext,
        preview: &PreviewRenderer,
        blit: &ViewportBlitRenderer,
        picture: &mut Option<(wgpu::Texture, wgpu::BindGroup)>,
        scene: &hairloom_render::preview::PreviewScene,
        frame: &FrameRequest,
        shared: &CallbackShared,
        ctx: &egui::Context,
    ) {
        let [width, height] = frame.size;
        let plan = preview.plan(scene, width, height);
        let started = std::time::Instant::now();
        let rendered = preview.render_texture(context, scene, &plan, width, height);
        // The status bar says what generating and drawing this frame cost, from submission
        // to the GPU finishing it, without waiting here: egui's own submission on the same
        // queue orders the picture before its use.
        let (frame_ms, timed_quality, repaint, quality) = (
            Arc::clone(&shared.frame_ms),
            Arc::clone(&shared.frame_quality),
            ctx.clone(),
            frame.quality,
        );
        context.queue.on_submitted_work_done(move || {
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
                let group = blit.bind(context, &texture);
                *picture = Some((texture, group));
            }
            Err(error) => report.error = Some(error.to_string()),
        }
        // The panel shows the new counts (and any error) on its next pass.
        ctx.request_repaint();
    }
}

/// What the panel handed over and the callback has not done yet: the asset's changes, folded
/// into one, and the newest frame.
#[derive(Default)]
pub(super) struct PendingWork {
    change: Option<AssetChange>,
    frame: Option<FrameRequest>,
}

impl PendingWork {
    fn change(&mut self, change: AssetChange) {
        self.change = Some(match self.change.take() {
            Some(earlier) => earlier.then(change),
            None => change,
        });
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
    /// How often the asset changed on the GPU, by kind.
    pub(super) uploads: UploadCounts,
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
        self.request_asset_change(ui.ctx(), state, settings);
        let drawn = DrawnKey {
            revision: state.shown_revision(),
            settings,
            orbit: self.orbit,
            size: full_size,
            quality,
        };
        // No bundle grows hair yet: the body alone, framed as the hair would be (and the view
        // stays put when the first hair grows).
        let bare_body = match self.hair_bounds {
            Some(None) => self.body_bounds,
            _ => None,
        };
        if self.drawn != Some(drawn) {
            if let Some(bounds) = self.hair_bounds.flatten().or(bare_body) {
                if !self.framed_from_hair {
                    self.camera_bounds = Some(bounds);
                    self.framed_from_hair = true;
                }
                let (lo, hi) = self.camera_bounds.unwrap_or(bounds);
                let document_scene = &state.document().scene;
                // The turntable's lights turn with its camera, about the hair's vertical.
                let turned;
                let document_scene = if self.turntable_rad != 0.0 {
                    let centre = ((lo + hi) * 0.5).as_dvec3();
                    turned = document_scene.lights_turned(self.turntable_rad as f64, centre);
                    &turned
                } else {
                    document_scene
                };
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
        self.hint = bare_body.map(
            |_| "No bundle grows hair yet: select scalp faces, then E extrudes them into bundles",
        );
        self.error = match (self.hair_bounds, &report.upload_error, &report.error) {
            (Some(None), _, Some(error)) if bare_body.is_some() => Some(error.clone()),
            (Some(None), _, None) if bare_body.is_some() => None,
            (Some(None), _, _) => Some("no bundle grows hair".into()),
            // Not built yet: nothing to say.
            (None, _, _) => None,
            (Some(Some(_)), Some(error), _) | (Some(Some(_)), None, Some(error)) => {
                Some(error.clone())
            }
            (Some(Some(_)), None, None) => None,
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
        if let (Some(hint), None) = (self.hint, &self.error) {
            ui.painter().text(
                rect.center_bottom() - egui::vec2(0.0, 24.0),
                egui::Align2::CENTER_BOTTOM,
                hint,
                egui::FontId::proportional(14.0),
                ui.visuals().strong_text_color(),
            );
        }
    }

    /// Strands and vertices of the last frame, after culling and LOD.
    pub fn drawn(&self) -> (usize, usize) {
        let report = self.report();
        (report.drawn_strands, report.drawn_vertices)
    }

    /// What the viewport says over a picture that is not wrong (the body alone while no
    /// bundle grows hair).
    pub fn hint(&self) -> Option<&'static str> {
        self.hint
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

/// What the asset was last asked to show: the document's revision and the shown one (they
/// differ while a motion poses the hair), and the settings the runtime data is built with.
#[derive(Clone, Copy, PartialEq)]
pub(super) struct RequestedAsset {
    revision: u64,
    shown_revision: u64,
    precision: hairloom_core::runtime::textures::Precision,
    strands_per_bundle: u32,
}

impl Viewport {
    /// Asks the builder for what changed since the asset was last asked for — the change
    /// kind comes from the editor's history ([`EditorState::change_since`]); the runtime data
    /// is built on the builder's thread — and hands finished changes to the paint callback.
    fn request_asset_change(
        &mut self,
        ctx: &egui::Context,
        state: &EditorState,
        settings: ViewSettings,
    ) {
        let Some(builder) = &self.builder else {
            return;
        };
        let now = RequestedAsset {
            revision: state.revision,
            shown_revision: state.shown_revision(),
            precision: settings.precision,
            strands_per_bundle: settings.strands_per_bundle,
        };
        let kind = match self.requested {
            None => Some(ChangeKind::Rebuild),
            Some(then) if then == now => None,
            Some(then)
                if (then.precision, then.strands_per_bundle)
                    != (now.precision, now.strands_per_bundle) =>
            {
                Some(ChangeKind::Rebuild)
            }
            Some(then) => {
                // A motion's pose moves the hair mesh and the body, nothing else.
                let posed_then = then.shown_revision != then.revision;
                let posed_now = now.shown_revision != now.revision;
                let pose = (now.shown_revision != then.shown_revision && (posed_then || posed_now))
                    .then_some(ChangeKind::Reshape);
                match (state.change_since(then.revision), pose) {
                    (Some(a), Some(b)) => Some(a.and(b)),
                    (a, b) => a.or(b),
                }
            }
        };
        if let Some(kind) = kind {
            let serial = builder.request(
                Arc::new(state.shown_document().clone()),
                kind,
                RuntimeOptions {
                    precision: settings.precision,
                    strands_per_bundle: settings.strands_per_bundle,
                    ..RuntimeOptions::default()
                },
            );
            // The first request after a reframe is the first whose hair may frame.
            if let (None, Some(serial)) = (self.frame_from_serial, serial) {
                self.frame_from_serial = Some(serial);
            }
        }
        self.requested = Some(now);
        if let Some(failure) = builder.take_failure() {
            self.shared
                .report
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .upload_error = Some(failure);
        }
        if let Some(built) = builder.poll() {
            // Hair built for the document shown before a reframe (open, recover, import)
            // goes to the GPU, but neither frames the camera nor is framed: the newer build
            // follows.
            let current = self
                .frame_from_serial
                .is_some_and(|first| built.serial >= first);
            if let (AssetChange::Hair { hair, .. }, true) = (&built.change, current) {
                self.hair_bounds = Some(hair.textures.hair_bounds());
                self.body_bounds = hair.body.bounds();
            }
            self.shared
                .pending
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .change(built.change);
            self.drawn = None;
        }
        if builder.busy() {
            // Come back for the built change without holding the UI.
            ctx.request_repaint_after(std::time::Duration::from_millis(8));
        }
    }

    /// Whether a change of the hair is being built off the UI thread.
    pub fn is_building(&self) -> bool {
        self.builder.as_ref().is_some_and(AssetBuilder::busy)
    }

    /// Blocks until the changes asked for are built (tests: the next frame then shows them).
    pub fn wait_for_builds(&self) {
        if let Some(builder) = &self.builder {
            builder.wait();
        }
    }

    /// How often the hair's asset changed on the GPU, by kind.
    pub fn uploads(&self) -> UploadCounts {
        self.report().uploads
    }
}
