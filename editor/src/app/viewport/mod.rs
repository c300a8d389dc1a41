//! 3D viewport: the document's strands generated on the GPU from its runtime textures every
//! time the document or the view changes (the same path as `hairloom render` and a game),
//! rendered and shown through an `egui_wgpu` paint callback (`paint.rs`).
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
//! Styling directions (View ▸ Styling-direction gizmo, `styling_gizmo.rs`): at the selected
//! bundles' roots, drag the wave arrow, the twist ring or the curl ring; one undo step each.
//!
//! Grooming brushes (`groom_brush.rs`): with Drag ▸ Groom, a left drag combs, grows or cuts,
//! puffs, smooths, clumps or parts the hair under the brush, X-mirrored and front-facing by
//! default; one undo step per stroke.
//!
//! Transform (modal, like Blender): G moves, R rotates, S scales the selection following
//! the pointer, E extrudes the selected bundles with the pointer setting the distance; X / Y / Z lock an axis, the wheel changes the soft-selection radius; a click
//! or Enter confirms (one undo step), Esc or a right-click cancels. Interior vertices follow
//! live.

mod budget;
pub use budget::{FRAME_BUDGET_MS, FrameQuality, InteractiveEffort, SETTLE};
mod camera;
mod effect_costs;
pub use effect_costs::EffectCostResult;
mod groom_brush;
pub use groom_brush::BrushCursor;
mod input;
mod overlay;
mod paint;
mod settings;
mod styling_gizmo;
pub use styling_gizmo::{StylingGizmoHandles, StylingHandle};
mod transform_tools;

use std::sync::Arc;

use eframe::egui_wgpu;
use glam::{DVec3, Vec3};
use hairloom_core::edit::select::{self, Region};
use hairloom_core::edit::{self, VertexTransform};
use hairloom_core::model::change::ChangeKind;
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::textures::Precision;
use hairloom_core::{Topology, VertexRef};
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::hair_asset::AssetBuilder;
use hairloom_render::preview::{Camera, PreviewRenderer};
use hairloom_render::renderer::strand_gen::StrandGenRenderer;

use super::gizmo::{GizmoAdapter, GizmoStep};
use super::state::{DragTool, EditorState, SelectMode};
use hairloom_core::runtime::hair::RuntimeOptions;
use hairloom_render::measure::{AccuracyRow, measure_accuracy};
use hairloom_render::preview::default_scene;

/// Storage buffers per shader stage the generation and preview pipelines bind.
const MIN_STORAGE_BUFFERS_PER_STAGE: u32 = 8;

/// The Strands & accuracy panel's largest strand count per bundle.
pub const MAX_STRANDS_PER_BUNDLE: u32 = 256;

/// How fast View ▸ Turntable turns: once round in 12 s.
const TURNTABLE_RAD_PER_S: f32 = std::f32::consts::TAU / 12.0;

/// What the viewport shows and how it generates strands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSettings {
    /// Overlay the hair mesh: layer faces and columns, interior vertices in a second colour.
    pub wireframe: bool,
    /// Overlay the styling frame (û red, v̂ green, ŵ blue) at every hair-mesh vertex.
    pub frame_glyphs: bool,
    /// Show the move / rotate / scale gizmo at the selection.
    pub gizmo: bool,
    /// Show the styling-direction gizmo (wave, twist, curl) at the selected bundles'
    /// roots instead of the move gizmo.
    pub styling_gizmo: bool,
    /// Look-dev: the camera goes round the hair, the scene's lights turning with it (the
    /// head seems to turn under studio lights), as `hairloom render --turntable` does.
    pub turntable: bool,
    /// While a map brush paints, show that map over the scalp (under the hair).
    pub map_overlay: bool,
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
            styling_gizmo: false,
            turntable: false,
            map_overlay: true,
            strands_per_bundle: 32,
            precision: Precision::F32,
            filtering: Filtering::Exact,
            lod: LodSettings::default(),
        }
    }
}

/// Uploads of the hair since the viewport was made.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UploadCounts {
    /// Textures, samples, placements and styling built and uploaded.
    pub full: u64,
    /// Only the styling buffers rewritten (a styling-only edit).
    pub styling: u64,
    /// The textures rewritten in place (the hair mesh moved: motion, drape, a drag).
    pub shape: u64,
}

/// Key of what was last drawn, to draw again only when something changed.
#[derive(Clone, Copy, PartialEq)]
struct DrawnKey {
    revision: u64,
    settings: ViewSettings,
    orbit: Orbit,
    size: [u32; 2],
    quality: FrameQuality,
}

/// The styling gizmo's frame and shared group for a (document revision, selection), or why
/// it cannot stand there.
type StylingFrameCache = (
    (u64, Vec<u32>),
    Result<
        (
            hairloom_core::edit::styling_direction::StylingAxes,
            Option<usize>,
        ),
        String,
    >,
);

/// What the overlay's body depth was rasterised for.
#[derive(Clone, Copy, PartialEq)]
struct BodyDepthKey {
    revision: u64,
    orbit: Orbit,
    size: [f32; 2],
    bounds: Option<(Vec3, Vec3)>,
}

/// What an accuracy measurement gives: every switch's row, or why it failed.
type AccuracyResult = Result<Vec<AccuracyRow>, String>;

impl Viewport {
    /// Wall time from submitting the last drawn frame to the GPU finishing it (generation
    /// and drawing); `None` until one has finished.
    pub fn frame_ms(&self) -> Option<f64> {
        self.shared.frame_ms.lock().ok().and_then(|slot| *slot)
    }
}

pub struct Viewport {
    /// egui's renderer, whose callback resources hold the viewport's GPU side
    /// ([`paint::ViewportGpu`]); `None` without a usable wgpu device.
    gpu: Option<Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>>,
    /// What the panel hands to its paint callback and what the callback reports back.
    shared: paint::CallbackShared,
    /// Builds the hair's changes off the UI thread (only with a GPU).
    builder: Option<AssetBuilder>,
    /// What the builder was last asked for.
    requested: Option<paint::RequestedAsset>,
    /// The box of the last built hair: `Some(None)` when no bundle grows hair, `None` before
    /// the first is built.
    hair_bounds: Option<Option<(Vec3, Vec3)>>,
    /// The box of the last built hair's body: framed and drawn alone while no bundle grows
    /// hair (a scalp just imported).
    body_bounds: Option<(Vec3, Vec3)>,
    /// What the viewport says over its picture while there is nothing wrong, as of its last
    /// pass (see [`Self::hint`]).
    hint: Option<&'static str>,
    /// The serial of the first build request since the last reframe: older builds (of the
    /// document shown before) never set `hair_bounds`; `None` until that request is made.
    frame_from_serial: Option<u64>,
    /// A lost device or a GPU error the device reported outside any error scope: shown in
    /// the viewport instead of panicking (wgpu's default).
    device_problem: Arc<std::sync::Mutex<Option<String>>>,
    pub orbit: Orbit,
    pub settings: ViewSettings,
    drawn: Option<DrawnKey>,
    /// The last full frame's time.
    full_frame_ms: Option<f64>,
    /// When what the viewport shows last changed (an edit, the camera, the size).
    last_change: Option<std::time::Instant>,
    /// How much interactive frames draw, adapted to the budget; `None` until the first.
    effort: Option<InteractiveEffort>,
    /// The quality of the picture shown now (the status bar says when it is reduced).
    pub shown_quality: FrameQuality,
    pub adapter: String,
    /// What the panel shows instead of the picture, as of its last pass (see
    /// [`Self::error`]).
    error: Option<String>,
    /// A dialog owns the keyboard this frame (set by the app): no single-key commands.
    pub keyboard_blocked: bool,
    /// Where the viewport was last drawn, in points (snapshot tests crop to it).
    pub rect: Option<egui::Rect>,
    transform: Option<ActiveTransform>,
    /// The on-screen gizmo, at the selection when there is one.
    gizmo: GizmoAdapter,
    /// Whether the gizmo was shown last frame (its handles are drawn then).
    gizmo_shown: bool,
    /// Where the gizmo's centre was drawn last (tests drag it).
    pub gizmo_centre: Option<egui::Pos2>,
    /// A drag on a styling-direction gizmo handle (a modal tool while it runs).
    styling_drag: Option<styling_gizmo::StylingDrag>,
    /// The selected bundles' styling frame and shared group (or why there is none), for the
    /// document revision and selection they were found at.
    styling_frame: Option<StylingFrameCache>,
    /// A cancelled styling drag waits for the button to be let go (the press stays the
    /// gizmo's).
    styling_hold: bool,
    /// Where the styling-direction gizmo's handles were drawn last (tests drag them).
    pub styling_handles: Option<StylingGizmoHandles>,
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
    /// The box the camera frames. Fixed once a document is framed (the hair's box at the
    /// first picture, the mesh's before it), so edits never move the view: a rotate
    /// preview or fifteen extrudes leave the camera where the artist put it. Reset when
    /// another document arrives ([`Self::reframe`]).
    camera_bounds: Option<(Vec3, Vec3)>,
    /// Whether `camera_bounds` came from the generated hair (else from the mesh).
    framed_from_hair: bool,
    /// Per column and layer, whether the vertex is interior, for the document revision it
    /// was computed at (the wireframe marks them; recomputed only when the document changes).
    interior: Option<(u64, Vec<Vec<bool>>)>,
    /// The body's depth for the overlay, with what it was rasterised for.
    body_depth: Option<(BodyDepthKey, Arc<select::DepthMap>)>,
    /// How far View ▸ Turntable has turned the camera and the lights since it was switched
    /// on.
    turntable_rad: f32,
    /// The grooming brush's stroke in progress.
    stroke: Option<groom_brush::Stroke>,
    /// The grooming brush under the pointer, as drawn last (tests aim with it).
    pub brush_cursor: Option<BrushCursor>,
    /// The body's distance field the brushes keep hair out of, built (or building, off the
    /// UI thread, from the moment Groom is chosen) for the body it belongs to.
    body_field: Option<groom_brush::BodyField>,
    /// The fingerprint of the document's body at a document revision.
    body_key: Option<(u64, u64)>,
    /// The scalp cut finely for showing a painted map, for the document revision it was cut
    /// at.
    map_display: Option<(
        u64,
        Vec<hairloom_core::edit::paint_maps::MapDisplayTriangle>,
    )>,
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
        let adapter = render_state.map_or_else(
            || unsupported.clone().unwrap_or("no GPU device".into()),
            |state| describe(&state.adapter.get_info()),
        );
        let gpu = render_state.map(|state| {
            let context = GpuContext::from_parts(
                state.adapter.clone(),
                state.device.clone(),
                state.queue.clone(),
            );
            state
                .renderer
                .write()
                .callback_resources
                .insert(paint::ViewportGpu::new(context, state.target_format));
            state.renderer.clone()
        });
        let builder = gpu.is_some().then(AssetBuilder::new);
        Self {
            adapter,
            gpu,
            shared: paint::CallbackShared::default(),
            builder,
            requested: None,
            hair_bounds: None,
            body_bounds: None,
            hint: None,
            frame_from_serial: None,
            device_problem,
            orbit: Orbit::default(),
            settings: ViewSettings::default(),
            drawn: None,
            full_frame_ms: None,
            last_change: None,
            effort: None,
            shown_quality: FrameQuality::Full,
            error: None,
            keyboard_blocked: false,
            rect: None,
            transform: None,
            gizmo: GizmoAdapter::default(),
            gizmo_shown: false,
            gizmo_drag: None,
            styling_drag: None,
            styling_hold: false,
            styling_frame: None,
            styling_handles: None,
            targets_cache: None,
            gizmo_centre: None,
            accuracy: None,
            measuring: None,
            drag_path: Vec::new(),
            camera_bounds: None,
            framed_from_hair: false,
            interior: None,
            map_display: None,
            body_depth: None,
            stroke: None,
            brush_cursor: None,
            turntable_rad: 0.0,
            body_field: None,
            body_key: None,
            frames: None,
        }
    }

    /// Frames the next document afresh (opened, new, recovered, imported).
    pub fn reframe(&mut self) {
        self.camera_bounds = None;
        self.framed_from_hair = false;
        self.orbit = Orbit::default();
        // The hair is built afresh for the new document, and only that build frames.
        self.hair_bounds = None;
        self.requested = None;
        self.frame_from_serial = None;
    }

    /// The box the camera frames, once framed.
    pub fn camera_bounds(&self) -> Option<(Vec3, Vec3)> {
        self.camera_bounds
    }

    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        let (rect, response) =
            ui.allocate_exact_size(ui.available_size(), egui::Sense::click_and_drag());
        self.rect = Some(rect);
        if self.camera_bounds.is_none() {
            self.camera_bounds = state
                .document()
                .hair_mesh
                .bounds()
                .map(|(lo, hi)| (lo.as_vec3(), hi.as_vec3()));
        }
        if let Some(projector) = self.projector(state, rect) {
            if self.transform.is_some() {
                self.drive_transform(ui, state, &response, projector);
            } else if self.styling_drag.is_some() || self.styling_hold {
                // A modal drag: the pointer and Esc are the gizmo's until it is let go.
                self.drive_styling_gizmo(ui, state, &response, projector);
            } else {
                self.navigate(ui, &response);
                let grabbed = if self.settings.styling_gizmo {
                    self.gizmo_shown = false;
                    self.gizmo_centre = None;
                    self.drive_styling_gizmo(ui, state, &response, projector)
                } else {
                    self.styling_handles = None;
                    self.drive_gizmo(ui, state, &response, projector)
                };
                if !grabbed && !self.groom(ui, state, &response, projector) {
                    self.select(ui, state, &response, projector);
                }
                self.keys(ui, state, &response);
            }
        }
        self.turn_table(ui);
        self.draw(ui, state, rect);
        self.paint_overlay(ui, state, rect);
    }

    /// View ▸ Turntable: turns the camera about the vertical at [`TURNTABLE_RAD_PER_S`] and
    /// keeps how far it has turned, by which the lights turn too (see `draw`). Off, the
    /// lights are the scene's again.
    fn turn_table(&mut self, ui: &egui::Ui) {
        if !self.settings.turntable {
            self.turntable_rad = 0.0;
            return;
        }
        // A slow frame turns no further than a tenth of a second's worth.
        let dt = ui.input(|i| i.stable_dt).clamp(0.0, 0.1);
        let step = TURNTABLE_RAD_PER_S * dt;
        self.orbit.yaw_rad = (self.orbit.yaw_rad + step).rem_euclid(std::f32::consts::TAU);
        self.turntable_rad = (self.turntable_rad + step).rem_euclid(std::f32::consts::TAU);
        ui.ctx().request_repaint();
    }

    /// How far the turntable has turned the camera and the lights (radians, 0 when off).
    pub fn turntable_turned_rad(&self) -> f32 {
        self.turntable_rad
    }

    /// The wgpu device the viewport draws with (tests provoke device errors on it).
    pub fn device(&self) -> Option<wgpu::Device> {
        self.gpu_handles().map(|(context, _)| context.device)
    }

    /// The device and the strand generator, for measurements on a worker thread.
    fn gpu_handles(&self) -> Option<(GpuContext, Arc<StrandGenRenderer>)> {
        let renderer = self.gpu.as_ref()?.read();
        let gpu = renderer.callback_resources.get::<paint::ViewportGpu>()?;
        Some((gpu.context.clone(), Arc::clone(&gpu.generator)))
    }
}

pub use camera::Orbit;
use camera::Projector;
pub use transform_tools::TransformKind;
use transform_tools::{ActiveTransform, TargetsKey};
