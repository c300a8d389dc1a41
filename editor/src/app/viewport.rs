//! 3D viewport: the document's strands generated on the GPU from its runtime textures every
//! time the document or the view changes (the same path as `hairloom render` and a game),
//! drawn offscreen by the render crate and shown as an egui image.
//!
//! Navigation (Blender's): middle-drag orbits, shift+middle-drag pans, the wheel zooms; on a
//! trackpad alt+left-drag orbits and shift+alt+left-drag pans. F frames the selection (the
//! hair without one), 1 / 3 / 7 look from the front / side / top.
//!
//! Selection: a click selects the bundle (or, in vertex mode, the exterior vertex) under the
//! pointer, shift/ctrl+click adds or removes it, a click on nothing clears; a left drag
//! selects with the box, lasso or paint brush (shift adds, ctrl removes). A selects all,
//! alt+A none, ctrl +/- grows / shrinks, Tab switches bundles / vertices.
//!
//! Transform (modal, like Blender): G moves, R rotates, S scales the selection following
//! the pointer, E extrudes the selected bundles with the pointer setting the distance; X / Y / Z lock an axis, the wheel changes the soft-selection radius; a click
//! or Enter confirms (one undo step), Esc or a right-click cancels. Interior vertices follow
//! live.

use std::sync::Arc;

use eframe::egui_wgpu;
use glam::{DVec3, Vec3};
use hairloom_core::edit::select::{self, Region};
use hairloom_core::edit::{self, VertexTransform};
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::textures::Precision;
use hairloom_core::{Topology, VertexRef};
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer};
use hairloom_render::renderer::strand_gen::{GpuHair, StrandGenRenderer};

use super::gizmo::{GizmoAdapter, GizmoStep};
use super::state::{DragTool, EditorState, SelectMode};
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_render::measure::{AccuracyRow, measure_accuracy};
use hairloom_render::preview::default_scene;
use hairloom_render::renderer::preview_body::GpuBody;

/// Storage buffers per shader stage the generation and preview pipelines bind.
const MIN_STORAGE_BUFFERS_PER_STAGE: u32 = 8;

/// Where the camera looks from, around the hair's centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub yaw_rad: f32,
    pub pitch_rad: f32,
    /// Distance relative to the framing distance.
    pub zoom: f32,
    /// Pan offset in units of the hair's size, in the view plane.
    pub pan: [f32; 2],
}

impl Default for Orbit {
    fn default() -> Self {
        Self {
            yaw_rad: 0.64,
            pitch_rad: 0.2,
            zoom: 1.0,
            pan: [0.0, 0.0],
        }
    }
}

impl Orbit {
    fn direction(&self) -> Vec3 {
        Vec3::new(
            self.yaw_rad.sin() * self.pitch_rad.cos(),
            self.pitch_rad.sin(),
            self.yaw_rad.cos() * self.pitch_rad.cos(),
        )
    }

    pub fn camera(&self, lo: Vec3, hi: Vec3) -> Camera {
        let pad = (hi - lo) * 0.05;
        let framed = Camera::framing(lo - pad, hi + pad, self.direction());
        let size = (hi - lo).length();
        let forward = (framed.target - framed.eye).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        let up = right.cross(forward);
        let shift = (right * self.pan[0] + up * self.pan[1]) * size;
        let target = framed.target + shift;
        Camera {
            eye: target + (framed.eye - framed.target) * self.zoom,
            target,
            ..framed
        }
    }
}

/// What the viewport shows and how it generates strands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSettings {
    /// Overlay the hair mesh: layer faces and columns, interior vertices in a second colour.
    pub wireframe: bool,
    /// Overlay the styling frame (û red, v̂ green, ŵ blue) at every hair-mesh vertex.
    pub frame_glyphs: bool,
    /// Show the move / rotate / scale gizmo at the selection.
    pub gizmo: bool,
    pub strands_per_bundle: u32,
    pub precision: Precision,
    pub filtering: Filtering,
    pub lod: LodSettings,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            wireframe: false,
            frame_glyphs: false,
            gizmo: true,
            strands_per_bundle: 32,
            precision: Precision::F32,
            filtering: Filtering::Exact,
            lod: LodSettings::default(),
        }
    }
}

/// Which modal transform runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransformKind {
    Move,
    Rotate,
    Scale,
    /// E: the selected bundles grow a layer whose distance follows the pointer.
    Extrude,
}

impl TransformKind {
    fn label(self) -> &'static str {
        match self {
            Self::Move => "Move",
            Self::Rotate => "Rotate",
            Self::Scale => "Scale",
            Self::Extrude => "Extrude",
        }
    }
}

/// A G / R / S gesture in progress: edits preview from the mesh it started on.
struct ActiveTransform {
    kind: TransformKind,
    /// Locked axis (0 = x, 1 = y, 2 = z).
    axis: Option<usize>,
    start_pointer: egui::Pos2,
    vertices: Vec<VertexRef>,
    pivot: DVec3,
    /// Extrude: the bundles, the direction pointer motion is measured along and the
    /// distance at the start pointer.
    bundles: Vec<u32>,
    direction: DVec3,
    base_distance_m: f64,
    /// The last pointer position applied (recomputed only when it or the settings change).
    applied: Option<(egui::Pos2, Option<usize>, u64)>,
}

/// The camera of the last frame: what screen point a model point lands on, and back.
#[derive(Clone, Copy)]
struct Projector {
    view: glam::Mat4,
    view_projection: glam::Mat4,
    rect: egui::Rect,
}

impl Projector {
    fn project(&self, p: DVec3) -> Option<egui::Pos2> {
        let clip = self.view_projection * p.as_vec3().extend(1.0);
        (clip.w > 1e-6).then(|| {
            let ndc = clip.truncate() / clip.w;
            egui::pos2(
                self.rect.left() + (ndc.x + 1.0) * 0.5 * self.rect.width(),
                self.rect.top() + (1.0 - ndc.y) * 0.5 * self.rect.height(),
            )
        })
    }

    fn project_xy(&self, p: DVec3) -> Option<[f64; 2]> {
        self.project(p).map(|q| [q.x as f64, q.y as f64])
    }

    /// Normalised device x, y of screen position `at`.
    fn ndc_xy(&self, at: egui::Pos2) -> (f32, f32) {
        (
            (at.x - self.rect.left()) / self.rect.width().max(1.0) * 2.0 - 1.0,
            1.0 - (at.y - self.rect.top()) / self.rect.height().max(1.0) * 2.0,
        )
    }

    /// The model point at screen position `at`, at the depth (NDC z) of `depth_of`.
    fn unproject(&self, at: egui::Pos2, depth_of: DVec3) -> DVec3 {
        let clip = self.view_projection * depth_of.as_vec3().extend(1.0);
        let z = clip.z / clip.w.max(1e-6);
        let (x, y) = self.ndc_xy(at);
        self.view_projection
            .inverse()
            .project_point3(Vec3::new(x, y, z))
            .as_dvec3()
    }

    /// The ray under screen position `at`: origin and direction.
    fn ray(&self, at: egui::Pos2) -> (DVec3, DVec3) {
        let inverse = self.view_projection.inverse();
        let (x, y) = self.ndc_xy(at);
        let near = inverse.project_point3(Vec3::new(x, y, 0.0)).as_dvec3();
        let far = inverse.project_point3(Vec3::new(x, y, 1.0)).as_dvec3();
        (near, far - near)
    }
}

struct UploadedHair {
    gpu: GpuHair,
    bounds: (Vec3, Vec3),
    /// The asset on the CPU (its body is drawn; its styling is restyled in place).
    hair: RuntimeHair,
    /// The hair mesh the textures were built from: a change that leaves it (and the body)
    /// alone is styling only.
    mesh: hairloom_core::HairMesh,
    /// The body on the GPU, uploaded with the hair (not per frame).
    body: GpuBody,
}

/// Uploads of the hair since the viewport was made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UploadCounts {
    /// Textures, samples, placements and styling built and uploaded.
    pub full: u64,
    /// Only the styling buffers rewritten (a styling-only edit).
    pub styling: u64,
}

/// GPU resources of the viewport (absent without a wgpu device).
struct GpuView {
    context: GpuContext,
    /// Shared with accuracy measurements on a worker thread.
    generator: Arc<StrandGenRenderer>,
    preview: PreviewRenderer,
    egui_renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    hair: Option<UploadedHair>,
    texture: Option<(wgpu::Texture, egui::TextureId)>,
}

/// Key of what was last drawn, to draw again only when something changed.
#[derive(Clone, Copy, PartialEq)]
struct DrawnKey {
    revision: u64,
    settings: ViewSettings,
    orbit: Orbit,
    size: [u32; 2],
}

/// What an accuracy measurement gives: every switch's row, or why it failed.
type AccuracyResult = Result<Vec<AccuracyRow>, String>;

impl Viewport {
    /// Wall time from submitting the last drawn frame to the GPU finishing it (generation
    /// and drawing); `None` until one has finished.
    pub fn frame_ms(&self) -> Option<f64> {
        self.frame_ms.lock().ok().and_then(|slot| *slot)
    }
}

pub struct Viewport {
    gpu: Option<GpuView>,
    /// A lost device or a GPU error the device reported outside any error scope: shown in
    /// the viewport instead of panicking (wgpu's default).
    device_problem: Arc<std::sync::Mutex<Option<String>>>,
    pub orbit: Orbit,
    pub settings: ViewSettings,
    uploaded: Option<(u64, ViewSettings)>,
    /// How often the hair went to the GPU, whole or restyled (tests count them).
    pub uploads: UploadCounts,
    drawn: Option<DrawnKey>,
    /// Strands and vertices of the last frame, after culling and LOD.
    pub drawn_strands: usize,
    pub drawn_vertices: usize,
    /// Wall time of generating and drawing the last frame on the GPU (submit to idle).
    /// Written by the queue's work-done callback, so drawing never waits on the GPU.
    frame_ms: Arc<std::sync::Mutex<Option<f64>>>,
    pub adapter: String,
    pub error: Option<String>,
    /// Where the viewport was last drawn, in points (snapshot tests crop to it).
    pub rect: Option<egui::Rect>,
    transform: Option<ActiveTransform>,
    /// The on-screen gizmo, at the selection when there is one.
    gizmo: GizmoAdapter,
    /// Whether the gizmo was shown last frame (its handles are drawn then).
    gizmo_shown: bool,
    /// Where the gizmo's centre was drawn last (tests drag it).
    pub gizmo_centre: Option<egui::Pos2>,
    /// The vertices a running gizmo drag moves and its pivot (fixed when it began).
    gizmo_drag: Option<(Vec<VertexRef>, Option<DVec3>)>,
    /// What the selection transforms and its centre, for the selection key it was computed
    /// at (the gizmo asks every frame; topology is rebuilt only when the key changes).
    targets_cache: Option<(TargetsKey, Vec<VertexRef>, Option<DVec3>)>,
    /// The last accuracy measurement: the document revision it was made at, and the rows
    /// (or why it failed).
    pub accuracy: Option<(u64, Result<Vec<AccuracyRow>, String>)>,
    /// A measurement running on a worker thread: the revision it measures and where its
    /// rows arrive.
    measuring: Option<(u64, std::sync::mpsc::Receiver<AccuracyResult>)>,
    /// The pointer path of a region drag in progress.
    drag_path: Vec<egui::Pos2>,
    /// The box the camera frames (the drawn hair's), for picking with the same camera.
    camera_bounds: Option<(Vec3, Vec3)>,
    /// Per column and layer, whether the vertex is interior, for the document revision it
    /// was computed at (the wireframe marks them; recomputed only when the document changes).
    interior: Option<(u64, Vec<Vec<bool>>)>,
    /// Styling frames per layer and column for the document revision they were computed at.
    frames: Option<(
        u64,
        Vec<Vec<Option<hairloom_core::geometry::frames::Frame>>>,
    )>,
}

impl Viewport {
    /// A viewport drawing through eframe's wgpu device, or a placeholder without one.
    pub fn new(render_state: Option<&egui_wgpu::RenderState>) -> Self {
        // Generation needs storage buffers in compute and vertex stages (the WebGPU default
        // of 8); a GL/WebGL2-limited device gets the placeholder and says why.
        let unsupported = render_state.and_then(|state| {
            let limits = state.device.limits();
            (limits.max_storage_buffers_per_shader_stage < MIN_STORAGE_BUFFERS_PER_STAGE).then(
                || {
                    format!(
                        "{}: {} storage buffers per shader stage, the viewport needs {}",
                        describe(&state.adapter.get_info()),
                        limits.max_storage_buffers_per_shader_stage,
                        MIN_STORAGE_BUFFERS_PER_STAGE
                    )
                },
            )
        });
        let render_state = render_state.filter(|_| unsupported.is_none());
        let device_problem = Arc::new(std::sync::Mutex::new(None::<String>));
        if let Some(state) = render_state {
            let lost = device_problem.clone();
            state
                .device
                .set_device_lost_callback(move |reason, message| {
                    if let Ok(mut problem) = lost.lock() {
                        *problem = Some(format!("the GPU device was lost ({reason:?}): {message}"));
                    }
                });
            let failed = device_problem.clone();
            state.device.on_uncaptured_error(Arc::new(move |error| {
                if let Ok(mut problem) = failed.lock() {
                    problem.get_or_insert_with(|| format!("GPU error: {error}"));
                }
            }));
        }
        let gpu = render_state.map(|state| {
            let context = GpuContext::from_parts(
                state.adapter.clone(),
                state.device.clone(),
                state.queue.clone(),
            );
            GpuView {
                generator: Arc::new(StrandGenRenderer::new(&context)),
                preview: PreviewRenderer::new(&context),
                egui_renderer: state.renderer.clone(),
                context,
                hair: None,
                texture: None,
            }
        });
        Self {
            adapter: gpu.as_ref().map_or_else(
                || unsupported.clone().unwrap_or("no GPU device".into()),
                |g| describe(&g.context.adapter_info),
            ),
            gpu,
            device_problem,
            orbit: Orbit::default(),
            settings: ViewSettings::default(),
            uploaded: None,
            uploads: UploadCounts::default(),
            drawn: None,
            drawn_strands: 0,
            drawn_vertices: 0,
            frame_ms: Arc::default(),
            error: None,
            rect: None,
            transform: None,
            gizmo: GizmoAdapter::default(),
            gizmo_shown: false,
            gizmo_drag: None,
            targets_cache: None,
            gizmo_centre: None,
            accuracy: None,
            measuring: None,
            drag_path: Vec::new(),
            camera_bounds: None,
            interior: None,
            frames: None,
        }
    }

    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        let (rect, response) =
            ui.allocate_exact_size(ui.available_size(), egui::Sense::click_and_drag());
        self.rect = Some(rect);
        if let Some(projector) = self.projector(state, rect) {
            if self.transform.is_some() {
                self.drive_transform(ui, state, &response, projector);
            } else {
                self.navigate(ui, &response);
                if !self.drive_gizmo(ui, state, &response, projector) {
                    self.select(ui, state, &response, projector);
                }
                self.keys(ui, state, &response);
            }
        }
        self.draw(ui, state, rect);
        self.paint_overlay(ui, state, rect);
    }

    /// The wgpu device the viewport draws with (tests provoke device errors on it).
    pub fn device(&self) -> Option<&wgpu::Device> {
        self.gpu.as_ref().map(|g| &g.context.device)
    }

    /// Strand count, level of detail and the accuracy switches, each setting with its
    /// measured error and generation time beside it (measured on demand: it generates the
    /// whole document four times).
    pub fn settings_ui(&mut self, ui: &mut egui::Ui, state: &EditorState) {
        ui.heading("Strands");
        let settings = &mut self.settings;
        ui.add(
            egui::Slider::new(&mut settings.strands_per_bundle, 1..=256).text("Strands per bundle"),
        );
        ui.checkbox(&mut settings.lod.enabled, "Level of detail");
        ui.add_enabled_ui(settings.lod.enabled, |ui| {
            ui.add(
                egui::Slider::new(&mut settings.lod.alpha_strands, 0.005..=0.5)
                    .logarithmic(true)
                    .text("Strand LOD alpha"),
            );
            ui.add(
                egui::Slider::new(&mut settings.lod.alpha_vertices, 0.005..=0.5)
                    .logarithmic(true)
                    .text("Vertex LOD alpha"),
            );
            ui.add(egui::Slider::new(&mut settings.lod.lambda, 0.0..=1.0).text("Morph lambda"));
        });
        ui.separator();
        ui.heading("Accuracy");
        let rows = match &self.accuracy {
            Some((revision, Ok(rows))) if *revision == state.revision => Some(rows.clone()),
            _ => None,
        };
        let row_for = |precision, filtering| {
            rows.as_ref().and_then(|rows| {
                rows.iter()
                    .find(|r| r.precision == precision && r.filtering == filtering)
                    .cloned()
            })
        };
        let size_m = state.document().hair_mesh.size().max(1e-9);
        egui::Grid::new("accuracy switches")
            .num_columns(4)
            .striped(true)
            .show(ui, |ui| {
                ui.label("Textures / filtering");
                ui.label("max error");
                ui.label("mean error");
                ui.label("generation");
                ui.end_row();
                for precision in [Precision::F32, Precision::F16] {
                    for filtering in [Filtering::Exact, Filtering::Hardware8Bit] {
                        let name = format!(
                            "{} / {}",
                            match precision {
                                Precision::F32 => "f32",
                                Precision::F16 => "f16",
                            },
                            match filtering {
                                Filtering::Exact => "exact",
                                Filtering::Hardware8Bit => "hardware",
                            }
                        );
                        let chosen = self.settings.precision == precision
                            && self.settings.filtering == filtering;
                        if ui.selectable_label(chosen, name).clicked() {
                            self.settings.precision = precision;
                            self.settings.filtering = filtering;
                        }
                        match row_for(precision, filtering) {
                            Some(AccuracyRow {
                                unavailable: Some(why),
                                ..
                            }) => {
                                ui.label("not on this GPU").on_hover_text(why);
                                ui.label("-");
                                ui.label("-");
                            }
                            Some(row) => {
                                ui.label(format!(
                                    "{:.3} mm ({:.2e} × size)",
                                    row.max_error_m * 1e3,
                                    row.max_error_m / size_m
                                ));
                                ui.label(format!("{:.4} mm", row.mean_error_m * 1e3));
                                ui.label(if row.timed_on_gpu {
                                    format!(
                                        "{:.2} ms GPU, {:.1} ms wall",
                                        row.generation_ms, row.wall_ms
                                    )
                                } else {
                                    format!("{:.1} ms wall", row.wall_ms)
                                });
                            }
                            None => {
                                ui.label("-");
                                ui.label("-");
                                ui.label("-");
                            }
                        }
                        ui.end_row();
                    }
                }
            });
        // A finished measurement lands here (the worker never touches the panel).
        if let Some((revision, receiver)) = &self.measuring {
            match receiver.try_recv() {
                Ok(result) => {
                    self.accuracy = Some((*revision, result));
                    self.measuring = None;
                }
                Err(std::sync::mpsc::TryRecvError::Empty) => {
                    ui.ctx()
                        .request_repaint_after(std::time::Duration::from_millis(50));
                }
                Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                    self.accuracy = Some((*revision, Err("the measurement stopped".into())));
                    self.measuring = None;
                }
            }
        }
        ui.horizontal(|ui| {
            let measure = ui
                .add_enabled(
                    self.gpu.is_some() && self.measuring.is_none(),
                    egui::Button::new("Measure"),
                )
                .on_hover_text(
                    "Generates every strand of the document (full detail, 17 vertices) with \
                     each setting on this GPU, on a worker thread; errors against f32 / exact",
                );
            if measure.clicked()
                && let Some(gpu) = &self.gpu
            {
                let (sender, receiver) = std::sync::mpsc::channel();
                let (context, generator) = (gpu.context.clone(), Arc::clone(&gpu.generator));
                let document = state.document().clone();
                let strands_per_bundle = self.settings.strands_per_bundle;
                let ctx = ui.ctx().clone();
                std::thread::spawn(move || {
                    let result =
                        measure_accuracy(&context, &generator, &document, strands_per_bundle, 17)
                            .map_err(|e| format!("{e:#}"));
                    let _ = sender.send(result);
                    ctx.request_repaint();
                });
                self.measuring = Some((state.revision, receiver));
            }
            if self.measuring.is_some() {
                ui.spinner();
                ui.weak("measuring…");
                return;
            }
            match &self.accuracy {
                Some((_, Err(error))) => {
                    ui.colored_label(ui.visuals().error_fg_color, error);
                }
                Some((revision, Ok(_))) if *revision != state.revision => {
                    ui.weak("the document changed since the last measurement");
                }
                None => {
                    ui.weak("not measured yet");
                }
                _ => {
                    ui.weak(format!("on {}", self.adapter));
                }
            }
        });
    }

    /// The camera the picture and overlay use (the mesh's box before the first picture).
    fn projector(&self, state: &EditorState, rect: egui::Rect) -> Option<Projector> {
        let (lo, hi) = self.camera_bounds.or_else(|| {
            let (lo, hi) = state.document().hair_mesh.bounds()?;
            Some((lo.as_vec3(), hi.as_vec3()))
        })?;
        let camera = self.orbit.camera(lo, hi);
        Some(Projector {
            view: glam::Mat4::look_at_rh(camera.eye, camera.target, camera.up),
            view_projection: camera.view_projection(rect.width() / rect.height().max(1.0)),
            rect,
        })
    }

    /// Generates and draws the strands when the document, settings, view or size changed.
    fn draw(&mut self, ui: &mut egui::Ui, state: &mut EditorState, rect: egui::Rect) {
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
        let Some(gpu) = self.gpu.as_mut() else {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "No GPU device: the viewport is off (hairloom render still works)",
                egui::FontId::proportional(14.0),
                ui.visuals().weak_text_color(),
            );
            return;
        };
        // The overlay does not change the picture: leave it out of what triggers GPU work.
        let settings = ViewSettings {
            wireframe: false,
            frame_glyphs: false,
            gizmo: false,
            ..self.settings
        };
        let key = (state.revision, settings);
        if self.uploaded != Some(key) {
            let document = state.document();
            // A styling-only change (same hair mesh, body and view settings) rewrites the
            // styling buffers in place: no texture rebuild, no re-upload.
            let restyle = match (&mut gpu.hair, self.uploaded) {
                (Some(uploaded), Some((_, uploaded_settings)))
                    if uploaded_settings == settings
                        && uploaded.mesh == document.hair_mesh
                        && uploaded.hair.body == document.body =>
                {
                    uploaded.hair.set_styling(&document.styling);
                    gpu.generator
                        .update_styling(&gpu.context, &mut uploaded.gpu, &uploaded.hair);
                    true
                }
                _ => false,
            };
            if restyle {
                self.uploads.styling += 1;
            } else {
                let hair = RuntimeHair::from_document(
                    document,
                    &RuntimeOptions {
                        precision: self.settings.precision,
                        strands_per_bundle: self.settings.strands_per_bundle,
                        ..RuntimeOptions::default()
                    },
                );
                gpu.hair = hair.textures.hair_bounds().map(|bounds| UploadedHair {
                    gpu: gpu.generator.upload(&gpu.context, &hair),
                    body: GpuBody::upload(&gpu.context, &hair.body),
                    bounds,
                    hair,
                    mesh: document.hair_mesh.clone(),
                });
                self.uploads.full += 1;
            }
            self.uploaded = Some(key);
            self.drawn = None;
        }
        let pixels_per_point = ui.ctx().pixels_per_point();
        let size = [
            ((rect.width() * pixels_per_point).round() as u32).clamp(1, 8192),
            ((rect.height() * pixels_per_point).round() as u32).clamp(1, 8192),
        ];
        let drawn = DrawnKey {
            revision: state.revision,
            settings,
            orbit: self.orbit,
            size,
        };
        if self.drawn != Some(drawn) {
            self.error = None;
            match gpu.hair.as_ref() {
                Some(hair) => {
                    let (lo, hi) = hair.bounds;
                    self.camera_bounds = Some(hair.bounds);
                    let scene = default_scene(
                        &hair.body,
                        HairSource::Generated {
                            generator: &gpu.generator,
                            hair: &hair.gpu,
                            filtering: self.settings.filtering,
                            lod: self.settings.lod,
                        },
                        17,
                        hair.bounds,
                        self.orbit.camera(lo, hi),
                    );
                    let plan = gpu.preview.plan(&scene, size[0], size[1]);
                    self.drawn_strands = plan.strands;
                    self.drawn_vertices = plan.vertices;
                    let started = std::time::Instant::now();
                    let rendered =
                        gpu.preview
                            .render_texture(&gpu.context, &scene, &plan, size[0], size[1]);
                    // The status bar says what generating and drawing this frame cost, from
                    // submission to the GPU finishing it, without waiting here: egui's own
                    // submission on the same queue orders the texture before its use.
                    let (frame_ms, ctx) = (Arc::clone(&self.frame_ms), ui.ctx().clone());
                    gpu.context.queue.on_submitted_work_done(move || {
                        if let Ok(mut slot) = frame_ms.lock() {
                            *slot = Some(started.elapsed().as_secs_f64() * 1e3);
                        }
                        ctx.request_repaint(); // the status bar shows the new time
                    });
                    match rendered {
                        Ok(texture) => {
                            // egui composites gamma-encoded bytes: sample the sRGB image raw.
                            let view = texture.create_view(&wgpu::TextureViewDescriptor {
                                format: Some(PreviewRenderer::UI_VIEW_FORMAT),
                                ..Default::default()
                            });
                            let mut renderer = gpu.egui_renderer.write();
                            let id = match gpu.texture.take() {
                                Some((_, id)) => {
                                    renderer.update_egui_texture_from_wgpu_texture(
                                        &gpu.context.device,
                                        &view,
                                        wgpu::FilterMode::Linear,
                                        id,
                                    );
                                    id
                                }
                                None => renderer.register_native_texture(
                                    &gpu.context.device,
                                    &view,
                                    wgpu::FilterMode::Linear,
                                ),
                            };
                            gpu.texture = Some((texture, id));
                        }
                        Err(error) => self.error = Some(error.to_string()),
                    }
                }
                None => self.error = Some("no bundle grows hair".into()),
            }
            self.drawn = Some(drawn);
        }
        match (&gpu.texture, &self.error) {
            (_, Some(error)) => {
                ui.painter().text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    error,
                    egui::FontId::proportional(14.0),
                    ui.visuals().error_fg_color,
                );
            }
            (Some((_, id)), None) => {
                ui.painter().image(
                    *id,
                    rect,
                    egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                    egui::Color32::WHITE,
                );
            }
            (None, None) => {}
        }
    }

    /// The hair-mesh wireframe (when on) and the selected bundles' outlines, drawn over the
    /// picture with the picture's camera (not depth-tested: an X-ray view).
    fn paint_overlay(&mut self, ui: &egui::Ui, state: &EditorState, rect: egui::Rect) {
        let mesh = &state.document().hair_mesh;
        let Some(projector) = self.projector(state, rect) else {
            return;
        };
        let project = |p: DVec3| projector.project(p);
        let painter = ui.painter_at(rect);
        let outline = |bundle: &hairloom_core::Bundle, stroke: egui::Stroke| {
            for layer in 0..=bundle.layers as usize {
                let corners: Vec<_> = bundle
                    .vertices
                    .iter()
                    .filter_map(|&c| project(*mesh.columns.get(c as usize)?.positions.get(layer)?))
                    .collect();
                if corners.len() == bundle.vertices.len() {
                    painter.add(egui::Shape::closed_line(corners, stroke));
                }
            }
            for &c in &bundle.vertices {
                let Some(column) = mesh.columns.get(c as usize) else {
                    continue;
                };
                let points: Vec<_> = column.positions
                    [..=(bundle.layers as usize).min(column.positions.len() - 1)]
                    .iter()
                    .filter_map(|p| project(*p))
                    .collect();
                painter.add(egui::Shape::line(points, stroke));
            }
        };
        let vertex_mode = state.tool.mode == SelectMode::Vertices;
        if self.settings.wireframe || vertex_mode {
            let stroke = egui::Stroke::new(
                1.0,
                egui::Color32::from_rgba_unmultiplied(120, 170, 230, 110),
            );
            for bundle in mesh.bundles.iter().filter(|b| !b.removed) {
                outline(bundle, stroke);
            }
            if self
                .interior
                .as_ref()
                .is_none_or(|(r, _)| *r != state.revision)
            {
                let topology = hairloom_core::Topology::build(mesh);
                let interior = (0..mesh.columns.len())
                    .map(|c| {
                        (0..mesh.columns[c].positions.len())
                            .map(|layer| mesh.is_interior(&topology, c, layer))
                            .collect()
                    })
                    .collect();
                self.interior = Some((state.revision, interior));
            }
            let interior = self.interior.as_ref().map(|(_, i)| i);
            for (c, column) in mesh.columns.iter().enumerate() {
                for (layer, p) in column.positions.iter().enumerate() {
                    let Some(at) = project(*p) else { continue };
                    let is_interior = interior
                        .and_then(|i| i.get(c)?.get(layer).copied())
                        .unwrap_or(false);
                    let colour = if is_interior {
                        egui::Color32::from_rgb(240, 200, 80) // placed automatically
                    } else {
                        egui::Color32::from_rgb(120, 200, 255) // shaped by the artist
                    };
                    painter.circle_filled(at, 1.8, colour);
                }
            }
        }
        let selected = egui::Stroke::new(1.5, egui::Color32::from_rgb(255, 150, 40));
        for &b in &state.selection {
            if let Some(bundle) = mesh.bundles.get(b as usize) {
                outline(bundle, selected);
            }
        }
        if self.settings.frame_glyphs {
            if self
                .frames
                .as_ref()
                .is_none_or(|(r, _)| *r != state.revision)
            {
                let frames = (0..=mesh.max_layers())
                    .map(|layer| hairloom_core::geometry::frames::layer_frames(mesh, layer))
                    .collect();
                self.frames = Some((state.revision, frames));
            }
            let length = mesh.size() * 0.012;
            if let Some((_, frames)) = &self.frames {
                for (layer, frames) in frames.iter().enumerate() {
                    for (c, frame) in frames.iter().enumerate() {
                        let (Some(frame), Some(p)) = (
                            frame,
                            mesh.position(VertexRef {
                                column: c as u32,
                                layer: layer as u32,
                            }),
                        ) else {
                            continue;
                        };
                        let Some(at) = project(p) else { continue };
                        let alpha = if frame.fallback { 90 } else { 220 };
                        for (axis, (r, g, b)) in [
                            (frame.u, (235, 70, 60)),
                            (frame.v, (90, 200, 90)),
                            (frame.w, (80, 140, 255)),
                        ] {
                            if let Some(tip) = project(p + axis * length) {
                                painter.line_segment(
                                    [at, tip],
                                    egui::Stroke::new(
                                        1.2,
                                        egui::Color32::from_rgba_unmultiplied(r, g, b, alpha),
                                    ),
                                );
                            }
                        }
                    }
                }
            }
        }
        if self.gizmo_shown && self.transform.is_none() {
            self.gizmo.paint(&painter);
        }
        let orange = egui::Color32::from_rgb(255, 150, 40);
        for v in &state.vertex_selection {
            if let Some(at) = mesh.position(*v).and_then(project) {
                painter.circle_filled(at, 3.5, orange);
            }
        }
        // The region being dragged.
        if self.drag_path.len() > 1 {
            let stroke = egui::Stroke::new(1.0, egui::Color32::WHITE);
            let (first, last) = (self.drag_path[0], self.drag_path[self.drag_path.len() - 1]);
            match state.tool.drag {
                DragTool::Box => {
                    painter.rect_stroke(
                        egui::Rect::from_two_pos(first, last),
                        0.0,
                        stroke,
                        egui::StrokeKind::Middle,
                    );
                }
                DragTool::Lasso => {
                    painter.add(egui::Shape::closed_line(self.drag_path.clone(), stroke));
                }
                DragTool::Paint => {
                    painter.circle_stroke(last, state.tool.paint_radius_px, stroke);
                    painter.add(egui::Shape::line(
                        self.drag_path.clone(),
                        egui::Stroke::new(
                            state.tool.paint_radius_px * 2.0,
                            egui::Color32::from_rgba_unmultiplied(255, 255, 255, 24),
                        ),
                    ));
                }
            }
        }
        if let Some(active) = &self.transform {
            if let Some(pivot) = project(active.pivot) {
                painter.circle_stroke(pivot, 5.0, egui::Stroke::new(1.5, orange));
                if let Some(pointer) = active.applied.map(|(p, _, _)| p) {
                    painter.line_segment(
                        [pivot, pointer],
                        egui::Stroke::new(1.0, egui::Color32::from_white_alpha(120)),
                    );
                }
            }
            painter.text(
                rect.left_top() + egui::vec2(10.0, 10.0),
                egui::Align2::LEFT_TOP,
                &state.message,
                egui::FontId::proportional(14.0),
                egui::Color32::WHITE,
            );
        }
    }

    /// Click and region selection (see the module documentation).
    fn select(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        response: &egui::Response,
        projector: Projector,
    ) {
        let modifiers = ui.input(|i| i.modifiers);
        let mesh = &state.document().hair_mesh;
        if response.clicked()
            && let Some(pointer) = response.interact_pointer_pos()
        {
            let add = modifiers.command || modifiers.shift;
            match state.tool.mode {
                SelectMode::Bundles => {
                    let (origin, direction) = projector.ray(pointer);
                    let hit = hairloom_core::edit::pick::pick_bundle(mesh, origin, direction);
                    if !add {
                        state.selection.clear();
                    }
                    if let Some((bundle, _)) = hit {
                        if !state.selection.insert(bundle) {
                            state.selection.remove(&bundle);
                        }
                        state.message = format!("bundle {bundle}");
                    }
                }
                SelectMode::Vertices => {
                    let topology = Topology::build(mesh);
                    let hit = select::nearest_vertex(
                        mesh,
                        &topology,
                        |p| projector.project_xy(p),
                        [pointer.x as f64, pointer.y as f64],
                        PICK_RADIUS_PX,
                    );
                    if !add {
                        state.vertex_selection.clear();
                    }
                    if let Some(v) = hit {
                        if !state.vertex_selection.insert(v) {
                            state.vertex_selection.remove(&v);
                        }
                        state.message = format!("vertex: column {} layer {}", v.column, v.layer);
                    }
                }
            }
            return;
        }
        let selecting = response.dragged_by(egui::PointerButton::Primary) && !modifiers.alt;
        if response.drag_started_by(egui::PointerButton::Primary) {
            self.drag_path.clear();
        }
        if selecting && let Some(pointer) = response.interact_pointer_pos() {
            self.drag_path.push(pointer);
        }
        if response.drag_stopped() && self.drag_path.len() > 1 {
            let points: Vec<[f64; 2]> = std::mem::take(&mut self.drag_path)
                .iter()
                .map(|p| [p.x as f64, p.y as f64])
                .collect();
            let region = match state.tool.drag {
                DragTool::Box => Region::Box {
                    a: points[0],
                    b: points[points.len() - 1],
                },
                DragTool::Lasso => Region::Lasso(points),
                DragTool::Paint => Region::Paint {
                    points,
                    radius_px: state.tool.paint_radius_px as f64,
                },
            };
            let project = |p| projector.project_xy(p);
            let replace = !modifiers.shift && !modifiers.command;
            let remove = modifiers.command;
            let count = match state.tool.mode {
                SelectMode::Bundles => {
                    let hits = select::bundles_in_region(mesh, project, &region);
                    apply_hits(&mut state.selection, &hits, replace, remove)
                }
                SelectMode::Vertices => {
                    let topology = Topology::build(mesh);
                    let hits = select::vertices_in_region(mesh, &topology, project, &region);
                    apply_hits(&mut state.vertex_selection, &hits, replace, remove)
                }
            };
            state.message = format!("{count} in the region");
        }
    }

    /// Single-key commands while the pointer is over the viewport.
    fn keys(&mut self, ui: &egui::Ui, state: &mut EditorState, response: &egui::Response) {
        if !response.hovered() || ui.ctx().egui_wants_keyboard_input() {
            return;
        }
        use egui::{Key, Modifiers};
        let pressed = |key| ui.input_mut(|i| i.consume_key(Modifiers::NONE, key));
        for (key, kind) in [
            (Key::G, TransformKind::Move),
            (Key::R, TransformKind::Rotate),
            (Key::S, TransformKind::Scale),
        ] {
            if pressed(key) {
                self.begin_transform(ui, state, kind);
                return;
            }
        }
        if pressed(Key::A) {
            state.select_all(true);
        }
        if ui.input_mut(|i| i.consume_key(Modifiers::ALT, Key::A)) {
            state.select_all(false);
        }
        if pressed(Key::Tab) {
            state.tool.mode = match state.tool.mode {
                SelectMode::Bundles => SelectMode::Vertices,
                SelectMode::Vertices => SelectMode::Bundles,
            };
        }
        if ui.input_mut(|i| {
            i.consume_key(Modifiers::COMMAND, Key::Plus)
                || i.consume_key(Modifiers::COMMAND, Key::Equals)
        }) {
            state.grow_selection(true);
        }
        if ui.input_mut(|i| i.consume_key(Modifiers::COMMAND, Key::Minus)) {
            state.grow_selection(false);
        }
        if pressed(Key::F) {
            self.frame_selection(state);
        }
    }

    /// Frames the selection (the whole hair without one).
    fn frame_selection(&mut self, state: &EditorState) {
        self.orbit.zoom = 1.0;
        self.orbit.pan = [0.0, 0.0];
        let targets = state.transform_targets();
        let mesh = &state.document().hair_mesh;
        let points: Vec<DVec3> = if targets.is_empty() {
            state
                .selection
                .iter()
                .filter_map(|&b| select::bundle_centre(mesh, b))
                .collect()
        } else {
            targets.iter().filter_map(|v| mesh.position(*v)).collect()
        };
        let (Some((lo, hi)), false) = (self.camera_bounds, points.is_empty()) else {
            return;
        };
        let centre = points.iter().sum::<DVec3>() / points.len() as f64;
        let extent = points
            .iter()
            .map(|p| p.distance(centre))
            .fold(0.0, f64::max);
        let camera = self.orbit.camera(lo, hi);
        let forward = (camera.target - camera.eye).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        let up = right.cross(forward);
        let size = (hi - lo).length().max(1e-6);
        let offset = centre.as_vec3() - camera.target;
        self.orbit.pan = [offset.dot(right) / size, offset.dot(up) / size];
        self.orbit.zoom = ((extent as f32 * 2.5) / size).clamp(0.08, 1.0);
    }

    fn begin_transform(&mut self, ui: &egui::Ui, state: &mut EditorState, kind: TransformKind) {
        state.commit_edit();
        let (vertices, pivot) = self.selection_targets(state);
        let Some(pivot) = pivot else {
            state.message = format!(
                "{}: nothing selected (interior vertices place themselves)",
                kind.label()
            );
            return;
        };
        let start_pointer = ui
            .input(|i| i.pointer.hover_pos())
            .unwrap_or(egui::Pos2::ZERO);
        self.transform = Some(ActiveTransform {
            kind,
            axis: None,
            start_pointer,
            vertices,
            pivot,
            bundles: Vec::new(),
            direction: DVec3::ZERO,
            base_distance_m: 0.0,
            applied: None,
        });
        state.message = format!(
            "{}: move the pointer; click confirms, Esc cancels",
            kind.label()
        );
    }

    /// The gizmo at the selection's centre; `true` when it has the pointer (a click or drag
    /// there moves the selection instead of selecting). A drag is one undo step.
    fn drive_gizmo(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        response: &egui::Response,
        projector: Projector,
    ) -> bool {
        self.gizmo_shown = false;
        self.gizmo_centre = None;
        if !self.settings.gizmo || ui.input(|i| i.modifiers.alt) {
            return false;
        }
        // The targets are fixed while a drag runs (the document changes under it);
        // otherwise they follow the selection, recomputed only when it or the document changes.
        let (vertices, pivot) = match &self.gizmo_drag {
            Some(drag) => drag.clone(),
            None => self.selection_targets(state),
        };
        let Some(pivot) = pivot else {
            return false;
        };
        self.gizmo_shown = true;
        self.gizmo_centre = projector.project(pivot);
        let projection = projector.view_projection * projector.view.inverse();
        let step = self.gizmo.update(
            state.tool.gizmo,
            ui,
            response,
            projector.rect,
            projector.view,
            projection,
            pivot,
        );
        match step {
            GizmoStep::Dragging(transform) => {
                if self.gizmo_drag.is_none() {
                    state.commit_edit();
                    self.gizmo_drag = Some((vertices.clone(), Some(pivot)));
                }
                let kind = match transform {
                    VertexTransform::Translate { .. } => TransformKind::Move,
                    VertexTransform::Rotate { .. } => TransformKind::Rotate,
                    VertexTransform::Scale { .. } => TransformKind::Scale,
                };
                preview_transform(state, kind, None, &vertices, transform);
                true
            }
            GizmoStep::Released => {
                state.commit_edit();
                self.gizmo_drag = None;
                true
            }
            GizmoStep::Idle => self.gizmo.is_hovered(ui.input(|i| i.pointer.hover_pos())),
        }
    }

    /// The selection's transform targets and their centre, cached per selection key.
    fn selection_targets(&mut self, state: &EditorState) -> (Vec<VertexRef>, Option<DVec3>) {
        let key = TargetsKey {
            revision: state.revision,
            mode: state.tool.mode,
            bundles: state.selection.clone(),
            vertices: state.vertex_selection.clone(),
        };
        if self
            .targets_cache
            .as_ref()
            .is_none_or(|(k, _, _)| *k != key)
        {
            let targets = state.transform_targets();
            let pivot = centre_of(&state.document().hair_mesh, &targets);
            self.targets_cache = Some((key, targets, pivot));
        }
        self.targets_cache
            .as_ref()
            .map(|(_, targets, pivot)| (targets.clone(), *pivot))
            .unwrap_or_default()
    }

    /// Whether the pointer is over the viewport (the app routes E here then).
    pub fn is_hovered(&self, ui: &egui::Ui) -> bool {
        let pointer = ui.input(|i| i.pointer.hover_pos());
        self.rect
            .zip(pointer)
            .is_some_and(|(rect, pointer)| rect.contains(pointer))
    }

    /// E over the viewport: extrude the selected bundles by `distance_m` at once, then let
    /// the pointer change the distance until a click confirms (one undo step) or Esc cancels.
    pub fn begin_extrude(&mut self, ui: &egui::Ui, state: &mut EditorState, distance_m: f64) {
        state.commit_edit();
        let bundles: Vec<u32> = state.selection.iter().copied().collect();
        let mesh = &state.document().hair_mesh;
        let mut tips = Vec::new();
        let mut direction = DVec3::ZERO;
        for bundle in bundles.iter().filter_map(|&b| mesh.bundles.get(b as usize)) {
            if let Some(tip) = edit::bundle_layer_centre(mesh, bundle, bundle.layers as usize) {
                tips.push(tip);
                direction += edit::growth_direction(mesh, bundle).unwrap_or(DVec3::ZERO);
            }
        }
        if tips.is_empty() {
            state.message = "Extrude: nothing selected".into();
            return;
        }
        let start_pointer = ui
            .input(|i| i.pointer.hover_pos())
            .unwrap_or(egui::Pos2::ZERO);
        self.transform = Some(ActiveTransform {
            kind: TransformKind::Extrude,
            axis: None,
            start_pointer,
            vertices: Vec::new(),
            pivot: tips.iter().sum::<DVec3>() / tips.len() as f64,
            bundles,
            direction: direction.normalize_or(DVec3::Z),
            base_distance_m: distance_m,
            applied: None,
        });
    }

    /// Follows the pointer during G / R / S / E; confirms or cancels.
    fn drive_transform(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        response: &egui::Response,
        projector: Projector,
    ) {
        let Some(active) = self.transform.as_mut() else {
            return;
        };
        use egui::{Key, Modifiers};
        let cancel = ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Escape))
            || response.secondary_clicked();
        if cancel {
            state.cancel_edit();
            state.message = format!("{} cancelled", active.kind.label());
            self.transform = None;
            return;
        }
        for (key, axis) in [(Key::X, 0), (Key::Y, 1), (Key::Z, 2)] {
            if ui.input_mut(|i| i.consume_key(Modifiers::NONE, key)) {
                active.axis = if active.axis == Some(axis) {
                    None
                } else {
                    Some(axis)
                };
            }
        }
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            let radius = &mut state.tool.soft_radius_m;
            *radius = if *radius <= 0.0 && scroll > 0.0 {
                0.005
            } else {
                (*radius * (scroll as f64 * 0.004).exp()).clamp(0.0, 1.0)
            };
        }
        let pointer = ui
            .input(|i| i.pointer.hover_pos())
            .unwrap_or(active.start_pointer);
        let radius_bits = state.tool.soft_radius_m.to_bits();
        if active.applied != Some((pointer, active.axis, radius_bits)) {
            active.applied = Some((pointer, active.axis, radius_bits));
            if active.kind == TransformKind::Extrude {
                let moved = projector.unproject(pointer, active.pivot)
                    - projector.unproject(active.start_pointer, active.pivot);
                let distance = active.base_distance_m + moved.dot(active.direction);
                let extruded = edit::extrude(
                    &state.edit_start().hair_mesh,
                    &active.bundles,
                    edit::ExtrudeDirection::AlongNormal { distance },
                );
                match extruded {
                    Ok(outcome) => {
                        state.edit(active.kind.label()).hair_mesh = outcome.mesh;
                        state.message = format!("Extrude: {distance:.4} m");
                    }
                    Err(error) => state.message = format!("Extrude: {error}"),
                }
            } else {
                let transform = transform_for(active, pointer, projector);
                preview_transform(state, active.kind, active.axis, &active.vertices, transform);
            }
        }
        let confirm =
            response.clicked() || ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Enter));
        if confirm {
            state.commit_edit();
            self.transform = None;
        }
    }

    fn navigate(&mut self, ui: &egui::Ui, response: &egui::Response) {
        let delta = response.drag_delta();
        let modifiers = ui.input(|i| i.modifiers);
        let navigating = response.dragged_by(egui::PointerButton::Middle)
            || (response.dragged_by(egui::PointerButton::Primary) && modifiers.alt);
        if navigating && delta != egui::Vec2::ZERO {
            if modifiers.shift {
                let scale = 1.0 / response.rect.height().max(1.0);
                self.orbit.pan[0] -= delta.x * scale * self.orbit.zoom;
                self.orbit.pan[1] += delta.y * scale * self.orbit.zoom;
            } else {
                self.orbit.yaw_rad -= delta.x * 0.01;
                self.orbit.pitch_rad = (self.orbit.pitch_rad + delta.y * 0.01).clamp(-1.5, 1.5);
            }
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.orbit.zoom = (self.orbit.zoom * (-scroll * 0.002).exp()).clamp(0.05, 20.0);
            }
            ui.input(|i| {
                let view = |yaw: f32, pitch: f32| Orbit {
                    yaw_rad: yaw,
                    pitch_rad: pitch,
                    ..Orbit::default()
                };
                if i.key_pressed(egui::Key::Num1) {
                    self.orbit = view(0.0, 0.05);
                }
                if i.key_pressed(egui::Key::Num3) {
                    self.orbit = view(std::f32::consts::FRAC_PI_2, 0.05);
                }
                if i.key_pressed(egui::Key::Num7) {
                    self.orbit = view(0.0, 1.5);
                }
            });
        }
    }
}

/// What the selection's transform targets depend on.
#[derive(Clone, PartialEq)]
struct TargetsKey {
    revision: u64,
    mode: SelectMode,
    bundles: std::collections::BTreeSet<u32>,
    vertices: std::collections::BTreeSet<VertexRef>,
}

/// The mean position of `vertices` (`None` when none exists).
fn centre_of(mesh: &hairloom_core::HairMesh, vertices: &[VertexRef]) -> Option<DVec3> {
    let positions: Vec<DVec3> = vertices.iter().filter_map(|v| mesh.position(*v)).collect();
    (!positions.is_empty()).then(|| positions.iter().sum::<DVec3>() / positions.len() as f64)
}

/// Previews `transform` of `vertices` from the document as the running edit began (soft
/// selection and interior placement included) and says what it did in the status bar.
fn preview_transform(
    state: &mut EditorState,
    kind: TransformKind,
    axis: Option<usize>,
    vertices: &[VertexRef],
    transform: VertexTransform,
) {
    let moved = edit::transform_vertices(
        &state.edit_start().hair_mesh,
        vertices,
        transform,
        state.tool.soft_radius_m,
    );
    match moved {
        Ok(outcome) => {
            state.edit(kind.label()).hair_mesh = outcome.mesh;
            state.message = describe_transform(kind, axis, transform)
                + &format!(", soft radius {:.3} m", state.tool.soft_radius_m);
        }
        Err(error) => state.message = format!("{}: {error}", kind.label()),
    }
}

/// Applies region hits to a selection: replace it, add to it, or (`remove`) take them out.
/// Returns how many were hit.
fn apply_hits<T: Ord + Copy>(
    selection: &mut std::collections::BTreeSet<T>,
    hits: &[T],
    replace: bool,
    remove: bool,
) -> usize {
    if replace {
        selection.clear();
    }
    for hit in hits {
        if remove {
            selection.remove(hit);
        } else {
            selection.insert(*hit);
        }
    }
    hits.len()
}

/// Pick distance for vertices, in points.
const PICK_RADIUS_PX: f64 = 10.0;

/// The transform the pointer asks for: screen motion mapped at the pivot's depth.
fn transform_for(
    active: &ActiveTransform,
    pointer: egui::Pos2,
    projector: Projector,
) -> VertexTransform {
    let axis_vector = active.axis.map(|a| {
        let mut v = DVec3::ZERO;
        v[a] = 1.0;
        v
    });
    let pivot_screen = projector
        .project(active.pivot)
        .unwrap_or(active.start_pointer);
    match active.kind {
        TransformKind::Move => {
            let offset = projector.unproject(pointer, active.pivot)
                - projector.unproject(active.start_pointer, active.pivot);
            let offset = axis_vector.map_or(offset, |axis| axis * offset.dot(axis));
            VertexTransform::Translate {
                offset: offset.to_array(),
            }
        }
        TransformKind::Rotate => {
            let angle = |p: egui::Pos2| (p.y - pivot_screen.y).atan2(p.x - pivot_screen.x) as f64;
            let turn = angle(pointer) - angle(active.start_pointer);
            // Into the screen: a clockwise pointer turn (screen y points down) turns the
            // model clockwise as seen.
            let forward = projector.ray(pivot_screen).1.normalize_or(DVec3::NEG_Z);
            let axis =
                axis_vector.map_or(
                    forward,
                    |axis| {
                        if axis.dot(forward) < 0.0 { -axis } else { axis }
                    },
                );
            VertexTransform::Rotate {
                axis: axis.to_array(),
                angle_rad: turn,
                pivot: active.pivot.to_array(),
            }
        }
        TransformKind::Extrude => VertexTransform::Translate { offset: [0.0; 3] },
        TransformKind::Scale => {
            let start = active.start_pointer.distance(pivot_screen).max(1.0);
            let factor = (pointer.distance(pivot_screen) / start) as f64;
            let mut factors = [factor; 3];
            if let Some(axis) = active.axis {
                factors = [1.0; 3];
                factors[axis] = factor;
            }
            VertexTransform::Scale {
                factors,
                pivot: active.pivot.to_array(),
            }
        }
    }
}

/// One line for the status bar.
fn describe_transform(
    kind: TransformKind,
    axis: Option<usize>,
    transform: VertexTransform,
) -> String {
    let axis = axis.map_or(String::new(), |a| format!(" along {}", ["x", "y", "z"][a]));
    match transform {
        VertexTransform::Translate { offset } => format!(
            "{}{axis}: ({:.4}, {:.4}, {:.4}) m",
            kind.label(),
            offset[0],
            offset[1],
            offset[2]
        ),
        VertexTransform::Rotate { angle_rad, .. } => {
            format!("{}{axis}: {:.1}°", kind.label(), angle_rad.to_degrees())
        }
        VertexTransform::Scale { factors, .. } => format!(
            "{}{axis}: ×{:.3}",
            kind.label(),
            factors
                .iter()
                .copied()
                .fold(1.0, |a: f64, f| if (f - 1.0).abs() > (a - 1.0).abs() {
                    f
                } else {
                    a
                })
        ),
    }
}
