//! The interactive editor (eframe on wgpu): a 3D viewport with live GPU strands and dockable
//! panels (egui_tiles: tools, outliner, history, styling), menus and a status bar. `state` is
//! the model; panels follow the egui demo pattern `fn ui(&mut self, ui, state)`.

pub mod files;
pub mod gizmo;
pub mod history_panel;
pub mod layout_panel;
pub mod outliner_panel;
pub mod panel_memory;
pub mod playback;
pub mod recovery;
pub mod scene_panel;
pub mod state;
pub mod styling_panel;
#[cfg(test)]
mod test_support;
pub mod tools_panel;
pub mod view_memory;
pub mod viewport;

pub use state::EditorState;

pub mod groom_import;
pub mod scalp_import;

use hairloom_core::io::alembic::AlembicTarget;
use std::path::PathBuf;

use files::{
    DialogAnswer, ExportJob, ExportTarget, FileDialogs, FileRequest, NativeDialogs, PathPrompt,
    RecentFiles,
};
use history_panel::HistoryPanel;
use layout_panel::LayoutPanel;
use outliner_panel::OutlinerPanel;
use recovery::{AUTOSAVE_SECONDS, PendingRecovery, Recovery};
use scene_panel::ScenePanel;
use styling_panel::StylingPanel;
use tools_panel::ToolsPanel;
use viewport::Viewport;

/// The editor's wgpu setup: egui's defaults plus the optional features the generator uses
/// when the adapter has them (timestamps for measured GPU time, f32 texture filtering for
/// the hardware-filtering switch, f16, 8× MSAA where the adapter has it, mesh shaders for the fastest generation path), and
/// without the GL backend, whose WebGL2 limits have
/// no storage buffers. Shared by the binary and the wgpu snapshot tests.
pub fn wgpu_setup() -> eframe::egui_wgpu::WgpuSetup {
    let mut setup = eframe::egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.instance_descriptor.backends = wgpu::Backends::PRIMARY;
    let egui_descriptor = setup.device_descriptor.clone();
    setup.device_descriptor = std::sync::Arc::new(move |adapter| {
        let mut descriptor = egui_descriptor(adapter);
        descriptor.required_features |=
            adapter.features() & hairloom_render::device::OPTIONAL_FEATURES;
        hairloom_render::device::request_mesh_shaders(adapter, &mut descriptor);
        descriptor
    });
    eframe::egui_wgpu::WgpuSetup::CreateNew(setup)
}

/// What runs after the artist answers "save changes?".
#[derive(Clone, Debug, PartialEq)]
pub enum AfterConfirm {
    Quit,
    New,
    Open(PathBuf),
}

/// The dockable panes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Pane {
    Viewport,
    Tools,
    Outliner,
    History,
    Styling,
    Scene,
    Strands,
    Layout,
}

impl Pane {
    /// Every pane; a layout shows each exactly once.
    pub const ALL: [Self; 8] = [
        Self::Viewport,
        Self::Tools,
        Self::Outliner,
        Self::History,
        Self::Styling,
        Self::Scene,
        Self::Strands,
        Self::Layout,
    ];

    pub fn title(self) -> &'static str {
        match self {
            Self::Viewport => "Viewport",
            Self::Tools => "Tools",
            Self::Outliner => "Outliner",
            Self::History => "History",
            Self::Styling => "Styling",
            Self::Scene => "Scene",
            Self::Strands => "Strands & accuracy",
            Self::Layout => "uv / w layout",
        }
    }
}

/// The default layout: tools / outliner / history on the left, the viewport in the middle,
/// styling on the right. Panes can be dragged into tabs and splits.
pub fn default_layout() -> egui_tiles::Tree<Pane> {
    let mut tiles = egui_tiles::Tiles::default();
    let tools = tiles.insert_pane(Pane::Tools);
    let outliner = tiles.insert_pane(Pane::Outliner);
    let history = tiles.insert_pane(Pane::History);
    let left_top = tiles.insert_tab_tile(vec![tools]);
    let left_middle = tiles.insert_tab_tile(vec![outliner]);
    let left_bottom = tiles.insert_tab_tile(vec![history]);
    let left = tiles.insert_vertical_tile(vec![left_top, left_middle, left_bottom]);
    if let Some(egui_tiles::Tile::Container(egui_tiles::Container::Linear(linear))) =
        tiles.get_mut(left)
    {
        linear.shares.set_share(left_top, 2.6);
        linear.shares.set_share(left_middle, 1.2);
        linear.shares.set_share(left_bottom, 0.9);
    }
    // In a tab group of its own, as egui_tiles would put it on the first frame (every pane
    // must have tabs): the default is then exactly what the dock shows, and a layout nobody
    // rearranged is never written to `panels.json`.
    let viewport_pane = tiles.insert_pane(Pane::Viewport);
    let viewport = tiles.insert_tab_tile(vec![viewport_pane]);
    let styling = tiles.insert_pane(Pane::Styling);
    let scene = tiles.insert_pane(Pane::Scene);
    let strands = tiles.insert_pane(Pane::Strands);
    let layout = tiles.insert_pane(Pane::Layout);
    let right = tiles.insert_tab_tile(vec![styling, scene, strands, layout]);
    let root = tiles.insert_horizontal_tile(vec![left, viewport, right]);
    if let Some(egui_tiles::Tile::Container(egui_tiles::Container::Linear(linear))) =
        tiles.get_mut(root)
    {
        linear.shares.set_share(left, 1.0);
        linear.shares.set_share(viewport, 3.0);
        linear.shares.set_share(right, 1.5);
    }
    egui_tiles::Tree::new(egui::Id::unique("hairloom layout"), root, tiles)
}

pub struct HairloomApp {
    pub state: EditorState,
    pub styling: StylingPanel,
    pub scene: ScenePanel,
    pub history: HistoryPanel,
    pub tools: ToolsPanel,
    pub outliner: OutlinerPanel,
    pub layout_panel: LayoutPanel,
    pub viewport: Viewport,
    pub layout: egui_tiles::Tree<Pane>,
    pub recovery: Recovery,
    /// A recovery file from an earlier run, offered until recovered or discarded.
    pub offer: Option<PendingRecovery>,
    pub dialogs: Box<dyn FileDialogs>,
    pub recent: RecentFiles,
    /// How each project was last viewed (per user; not part of any document).
    pub views: view_memory::ViewMemory,
    /// How the panes are arranged (per user; not part of any document).
    pub panels: panel_memory::PanelMemory,
    /// The typed-path prompt, where no native dialog exists.
    pub prompt: Option<PathPrompt>,
    pub export: Option<ExportJob>,
    /// File ▸ Import groom…: the scalp question, then the fit on a worker.
    pub groom_import: Option<groom_import::GroomImport>,
    /// File ▸ Import scalp… on a file with several materials or vertex colours: where hair
    /// grows.
    pub scalp_import: Option<scalp_import::ScalpImport>,
    /// File ▸ Import scalp… on a file of several meshes: which one grows hair.
    pub mesh_choice: Option<scalp_import::MeshChoice>,
    /// The application the next `.abc` export is for (File ▸ Export groom for ▸).
    pub alembic_target: AlembicTarget,
    /// "Save changes?" is being asked before this action.
    pub confirm: Option<AfterConfirm>,
    /// The action to run once the typed-path prompt's Save As succeeds.
    after_save: Option<AfterConfirm>,
    /// The artist chose to quit; the next close request is let through.
    quitting: bool,
    close_sent: bool,
    /// Time (s) and document revision of the last autosave.
    autosaved: (f64, u64),
    title: String,
}

impl HairloomApp {
    pub fn new(cc: &eframe::CreationContext<'_>, state: EditorState) -> Self {
        Self::with_recovery(cc, state, Recovery::default_location())
    }

    /// The app with its autosaves (and recent-files list) in `recovery` (tests use a
    /// temporary folder) and native file dialogs.
    pub fn with_recovery(
        cc: &eframe::CreationContext<'_>,
        state: EditorState,
        recovery: Recovery,
    ) -> Self {
        let (panels, stored_layout, layout_problem) =
            panel_memory::PanelMemory::load(recovery.dir().join("panels.json"));
        let mut app = Self {
            viewport: Viewport::new(cc.wgpu_render_state.as_ref()),
            panels,
            offer: recovery.pending(),
            autosaved: (0.0, state.revision),
            recent: RecentFiles::load(recovery.dir().join("recent.txt")),
            views: view_memory::ViewMemory::load(recovery.dir().join("views.json")),
            recovery,
            state,
            styling: StylingPanel::default(),
            scene: ScenePanel::default(),
            history: HistoryPanel::default(),
            tools: ToolsPanel::default(),
            outliner: OutlinerPanel::default(),
            layout_panel: LayoutPanel::default(),
            layout: stored_layout.unwrap_or_else(default_layout),
            dialogs: Box::new(NativeDialogs),
            prompt: None,
            export: None,
            groom_import: None,
            scalp_import: None,
            mesh_choice: None,
            alembic_target: AlembicTarget::default(),
            confirm: None,
            after_save: None,
            quitting: false,
            close_sent: false,
            title: String::new(),
        };
        app.recall_view();
        if let Some(note) = app.recovery.note() {
            app.state.message = note.to_string();
        }
        if let Some(problem) = layout_problem {
            app.state.message = problem;
        }
        app
    }

    /// Replaces the file dialogs (tests script them).
    pub fn with_dialogs(mut self, dialogs: impl FileDialogs + 'static) -> Self {
        self.dialogs = Box::new(dialogs);
        self
    }

    /// Writes the recovery file when there is unsaved work newer than the last autosave.
    fn autosave(&mut self, now: f64) {
        if now - self.autosaved.0 < AUTOSAVE_SECONDS || self.offer.is_some() {
            return;
        }
        if self.state.is_dirty() && self.state.revision != self.autosaved.1 {
            match self.recovery.write(&self.state) {
                Ok(()) => self.state.message = "autosaved".into(),
                Err(error) => {
                    self.state.message = format!(
                        "autosave to {} failed: {error}",
                        self.recovery.dir().display()
                    )
                }
            }
        }
        self.autosaved = (now, self.state.revision);
    }

    /// The recovery offer, as a modal window.
    fn recovery_offer(&mut self, ui: &mut egui::Ui) {
        let Some(offer) = self.offer.clone() else {
            return;
        };
        let mut choice = None;
        egui::Modal::new(egui::Id::unique("hairloom recovery offer")).show(ui.ctx(), |ui| {
            ui.heading("Recover unsaved work?");
            let age = offer
                .modified
                .and_then(|m| m.elapsed().ok())
                .map_or("some time".into(), |d| format!("{} min", d.as_secs() / 60));
            ui.label(format!(
                "Hairloom did not close normally {age} ago. Its unsaved work{} was autosaved.",
                offer
                    .origin
                    .as_ref()
                    .map_or(String::new(), |p| format!(" on {}", p.display()))
            ));
            ui.horizontal(|ui| {
                if ui.button("Recover").clicked() {
                    choice = Some(true);
                }
                if ui.button("Discard").clicked() {
                    choice = Some(false);
                }
            });
        });
        match choice {
            Some(true) => match self.recovery.load() {
                Ok(state) => {
                    self.remember_view();
                    self.state = state;
                    self.viewport.reframe();
                    self.recall_view();
                    self.offer = None;
                }
                Err(error) => {
                    self.state.message = format!("recovery failed: {error}");
                    self.offer = None;
                }
            },
            Some(false) => {
                self.recovery.discard();
                self.offer = None;
                self.state.message = "discarded the autosaved work".into();
            }
            None => {}
        }
    }

    /// Whether a modal window (recovery offer, "save changes?", path prompt, export
    /// progress) is open: it owns the keyboard, and nothing behind it reacts.
    pub fn dialog_open(&self) -> bool {
        self.offer.is_some()
            || self.confirm.is_some()
            || self.prompt.is_some()
            || self.export.is_some()
            || self.groom_import.is_some()
            || self.scalp_import.is_some()
            || self.mesh_choice.is_some()
    }

    fn shortcuts(&mut self, ui: &mut egui::Ui) {
        use egui::{Key, Modifiers};
        use shortcut::*;
        // Blender's rule: a modal tool (G / R / S / E) owns the keyboard until it is
        // confirmed or cancelled, and so does an open dialog. Their own keys are read by
        // them; everything else waits.
        if self.dialog_open() || self.viewport.modal_tool().is_some() {
            return;
        }
        // Single-key commands only when no text field has the keyboard (a focused button
        // or slider does not: letters mean nothing to it).
        let typing = ui.ctx().text_edit_focused();
        // Tab toggles bundles / vertices. egui moves keyboard focus on Tab at the start of
        // the frame; take that back, so focus never lands on the menu bar.
        let tabs = if typing {
            0
        } else {
            ui.input_mut(|i| i.count_and_consume_key(Modifiers::NONE, Key::Tab))
        };
        if tabs > 0 {
            ui.memory_mut(|m| {
                // Cancel the pending focus move (widgets registered after this point would
                // take it) and drop any focus already held.
                m.move_focus(egui::FocusDirection::None);
                if let Some(id) = m.focused() {
                    m.surrender_focus(id);
                }
            });
            if tabs % 2 == 1 {
                self.state.toggle_select_mode();
            }
        }
        let (redo_shift, redo_y, undo) = (REDO, REDO_Y, UNDO);
        let (save, save_as, open, new, quit) = (SAVE, SAVE_AS, OPEN, NEW, QUIT);
        // The most specific shortcut first: Ctrl+Shift+Z would also match Ctrl+Z. Every
        // press counts, however slow the frame that collected them (egui queues them).
        let count = |ui: &mut egui::Ui, shortcut: &egui::KeyboardShortcut| {
            ui.input_mut(|i| i.count_and_consume_key(shortcut.modifiers, shortcut.logical_key))
        };
        let redos = count(ui, &redo_shift) + count(ui, &redo_y);
        for _ in 0..redos {
            self.state.redo();
        }
        for _ in 0..count(ui, &undo) {
            self.state.undo();
        }
        if ui.input_mut(|i| i.consume_shortcut(&save_as)) {
            self.save_as();
        }
        if ui.input_mut(|i| i.consume_shortcut(&save)) {
            self.save();
        }
        if ui.input_mut(|i| i.consume_shortcut(&open)) {
            self.file_request(FileRequest::OpenProject);
        }
        if ui.input_mut(|i| i.consume_shortcut(&new)) {
            self.request(AfterConfirm::New);
        }
        if ui.input_mut(|i| i.consume_shortcut(&quit)) {
            self.request(AfterConfirm::Quit);
        }
        if !typing
            && self.state.tool.mode == state::SelectMode::Bundles
            && !self.state.selection.is_empty()
            && ui.input_mut(|i| i.consume_shortcut(&DELETE))
        {
            self.delete_bundles(false);
        }
        if !typing && ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::E)) {
            // Over the viewport E is interactive (the pointer sets the distance, a click
            // confirms); elsewhere it extrudes by the Tools panel's distance at once.
            if self.viewport.is_hovered(ui) {
                let distance = self.tools.extrude_distance_m;
                self.viewport.begin_extrude(ui, &mut self.state, distance);
            } else {
                self.tools.extrude(&mut self.state);
            }
        }
    }

    /// Edit ▸ Delete selected bundles / Keep only selected bundles; the copied wisp shape
    /// follows its bundle's new number (or is dropped with it).
    fn delete_bundles(&mut self, keep_selected: bool) {
        if let Some(renumbering) = self.state.delete_bundles(keep_selected) {
            self.tools.copied_shape = self
                .tools
                .copied_shape
                .and_then(|b| renumbering.get(b as usize).copied().flatten());
        }
    }

    /// Saves (Save As when the project has no file yet); a saved project needs no
    /// recovery file.
    pub fn save(&mut self) -> bool {
        if self.state.path.is_none() {
            return self.save_as();
        }
        match self.state.save() {
            Ok(path) => {
                self.saved_to(&path);
                true
            }
            Err(_) => false,
        }
    }

    pub fn save_as(&mut self) -> bool {
        let suggested =
            self.state.path.clone().unwrap_or_else(|| {
                PathBuf::from(format!("{}.hairloom", self.state.document().name))
            });
        match self.ask(FileRequest::SaveProjectAs, Some(suggested)) {
            Some(mut path) => {
                if path.extension().is_none() {
                    path.set_extension("hairloom");
                }
                match self.state.save_as(&path) {
                    Ok(path) => {
                        self.saved_to(&path);
                        true
                    }
                    Err(_) => false,
                }
            }
            None => false,
        }
    }

    fn saved_to(&mut self, path: &std::path::Path) {
        self.recovery.discard();
        self.recent.push(path);
        self.remember_view();
    }

    /// Keeps how the open project is viewed (per user, outside the document and its undo
    /// history); projects without a file have no view to keep.
    fn remember_view(&mut self) {
        if let Some(path) = &self.state.path {
            let view = view_memory::SavedView::of(&self.viewport.orbit, &self.viewport.settings);
            self.views.remember(path, view);
        }
    }

    /// Shows the open project as it was last viewed, if it was.
    fn recall_view(&mut self) {
        if let Some(view) = self.state.path.as_ref().and_then(|p| self.views.recall(p)) {
            view.apply(&mut self.viewport.orbit, &mut self.viewport.settings);
        }
    }

    /// Asks a dialog for a path; `None` when cancelled or when the typed-path prompt was
    /// opened instead (its OK continues the request).
    fn ask(&mut self, request: FileRequest, suggested: Option<PathBuf>) -> Option<PathBuf> {
        // A bare suggested name lands next to the open project, not in the working folder. A
        // suggestion with folders of its own (the project's path, which is relative when it
        // was opened by a relative path) is kept as it is: joining it to its own folder
        // doubled that folder (`work/work/…`).
        let folder = self
            .state
            .path
            .as_deref()
            .and_then(std::path::Path::parent)
            .filter(|p| !p.as_os_str().is_empty());
        let bare_name = |s: &std::path::Path| {
            s.parent()
                .is_none_or(|parent| parent.as_os_str().is_empty())
        };
        let suggested = suggested.map(|s| match folder {
            Some(folder) if s.is_relative() && bare_name(&s) => folder.join(s),
            _ => s,
        });
        match self.dialogs.ask(request, suggested.as_deref()) {
            DialogAnswer::Chosen(path) => Some(path),
            DialogAnswer::Cancelled => None,
            DialogAnswer::Unavailable => {
                self.prompt = Some(PathPrompt {
                    request,
                    text: suggested.map_or(String::new(), |p| p.display().to_string()),
                    focused: false,
                });
                None
            }
        }
    }

    /// Runs a file request for a chosen path.
    fn answered(&mut self, request: FileRequest, path: PathBuf) {
        match request {
            FileRequest::OpenProject => self.request(AfterConfirm::Open(path)),
            FileRequest::SaveProjectAs => match self.state.save_as(&path) {
                Ok(path) => {
                    self.saved_to(&path);
                    // Quit / New / Open waiting on this save ("Save changes?" ▸ Save).
                    if let Some(action) = self.after_save.take() {
                        self.run_action(action);
                    }
                }
                Err(_) => self.after_save = None,
            },
            FileRequest::ImportScalp => self.import_scalp(&path),
            FileRequest::ImportGroom => {
                let has_scalp = !self.state.document().hair_mesh.bundles.is_empty();
                self.groom_import = Some(groom_import::GroomImport::choose(path, has_scalp));
            }
            FileRequest::ExportRuntime => self.start_export(ExportTarget::Runtime {
                dir: path,
                precision: self.viewport.settings.precision,
            }),
            FileRequest::ExportStrands => self.start_export(ExportTarget::Strands {
                file: path,
                vertices_log2: crate::files::export_vertices_log2(self.state.document()),
                alembic: self.alembic_target,
            }),
        }
    }

    /// File ▸ Open, Import, Export: ask for the path, then do it.
    pub fn file_request(&mut self, request: FileRequest) {
        let suggested = match request {
            FileRequest::ExportRuntime => Some(PathBuf::from(format!(
                "{}_runtime",
                self.state.document().name
            ))),
            FileRequest::ExportStrands => {
                Some(PathBuf::from(format!("{}.glb", self.state.document().name)))
            }
            _ => self.state.path.clone(),
        };
        if let Some(path) = self.ask(request, suggested) {
            self.answered(request, path);
        }
    }

    /// New, Open or Quit: asks "save changes?" first when there is unsaved work.
    pub fn request(&mut self, action: AfterConfirm) {
        if self.state.is_dirty() {
            self.confirm = Some(action);
        } else {
            self.run_action(action);
        }
    }

    fn run_action(&mut self, action: AfterConfirm) {
        match action {
            AfterConfirm::Quit => {
                self.quitting = true;
                self.recovery.discard();
            }
            AfterConfirm::New => self.replace_state(EditorState::new_project()),
            AfterConfirm::Open(path) => match EditorState::open(&path) {
                Ok(state) => {
                    self.recent.push(&path);
                    self.replace_state(state);
                }
                // The open document stays as it was.
                Err(error) => self.state.message = format!("open failed: {error}"),
            },
        }
    }

    fn replace_state(&mut self, state: EditorState) {
        self.remember_view();
        self.state = state;
        self.viewport.reframe();
        self.recall_view();
        self.recovery.discard();
        self.autosaved.1 = self.state.revision;
    }

    /// Reads the scalp file; asks which mesh grows hair when it has several, and where on
    /// it when it offers a choice (several materials, vertex colours); else imports every
    /// face.
    fn import_scalp(&mut self, path: &std::path::Path) {
        use hairloom_core::io::import::{ImportError, ImportOptions, import_file};
        match import_file(path, &ImportOptions::default()) {
            Ok(mesh) => self.offer_or_import(path, mesh, None),
            Err(ImportError::SeveralMeshes { names, .. }) => {
                self.mesh_choice = Some(scalp_import::MeshChoice::new(path.to_path_buf(), names));
            }
            Err(error) => self.state.message = format!("import failed: {error}"),
        }
    }

    /// Reads mesh `name` as the scalp and every mesh of the file as the body.
    fn import_scalp_mesh(&mut self, path: &std::path::Path, name: String) {
        use hairloom_core::io::import::{ImportOptions, import_body, import_file};
        let options = ImportOptions {
            mesh_name: Some(name),
            ..ImportOptions::default()
        };
        let read = import_file(path, &options)
            .and_then(|mesh| Ok((mesh, import_body(path, &ImportOptions::default())?)));
        match read {
            Ok((mesh, (body, skipped))) => {
                self.offer_or_import(path, mesh, Some(body));
                if !skipped.is_empty() {
                    self.state.message += &format!(
                        "; left out of the body (not triangles): {}",
                        skipped.join(", ")
                    );
                }
            }
            Err(error) => self.state.message = format!("import failed: {error}"),
        }
    }

    /// Asks where hair grows on `mesh` when it offers a choice, else imports every face;
    /// `body` is the file's every mesh when it has several.
    fn offer_or_import(
        &mut self,
        path: &std::path::Path,
        mesh: hairloom_core::io::import::ImportedMesh,
        body: Option<hairloom_core::model::document::BodyMesh>,
    ) {
        if scalp_import::ScalpImport::offers_choice(&mesh) {
            let mut import = scalp_import::ScalpImport::new(path.to_path_buf(), mesh);
            import.body = body;
            self.scalp_import = Some(import);
        } else {
            self.finish_scalp_import(
                path,
                &mesh,
                body,
                &hairloom_core::io::scalp_region::ScalpRegion::All,
            );
        }
    }

    fn finish_scalp_import(
        &mut self,
        path: &std::path::Path,
        mesh: &hairloom_core::io::import::ImportedMesh,
        body: Option<hairloom_core::model::document::BodyMesh>,
        region: &hairloom_core::io::scalp_region::ScalpRegion,
    ) {
        let body = body.unwrap_or_else(|| mesh.to_body());
        match crate::files::scalp_document_from(path, mesh, body, region, false) {
            Ok((document, summary)) => {
                self.state.import_scalp(document, &summary);
                self.viewport.reframe();
            }
            Err(error) => self.state.message = format!("import failed: {error:#}"),
        }
    }

    /// The "which mesh grows hair?" modal of a scalp import.
    fn mesh_choice_modal(&mut self, ui: &mut egui::Ui) {
        let Some(choice) = &mut self.mesh_choice else {
            return;
        };
        match choice.ui(ui) {
            scalp_import::MeshChoiceAction::Waiting => {}
            scalp_import::MeshChoiceAction::Closed => {
                self.mesh_choice = None;
                self.state.message = "import cancelled".into();
            }
            scalp_import::MeshChoiceAction::Read(name) => {
                if let Some(choice) = self.mesh_choice.take() {
                    self.import_scalp_mesh(&choice.path, name);
                }
            }
        }
    }

    /// The "where does hair grow?" modal of a scalp import.
    fn scalp_import_modal(&mut self, ui: &mut egui::Ui) {
        let Some(import) = &mut self.scalp_import else {
            return;
        };
        match import.ui(ui) {
            scalp_import::ScalpImportAction::Waiting => {}
            scalp_import::ScalpImportAction::Closed => {
                self.scalp_import = None;
                self.state.message = "import cancelled".into();
            }
            scalp_import::ScalpImportAction::Import(region, scale) => {
                if let Some(mut import) = self.scalp_import.take() {
                    if scale != 1.0 {
                        for p in &mut import.mesh.positions {
                            *p *= scale;
                        }
                        if let Some(body) = &mut import.body {
                            for p in &mut body.positions {
                                *p = p.map(|c| (c as f64 * scale) as f32);
                            }
                        }
                    }
                    self.finish_scalp_import(&import.path, &import.mesh, import.body, &region);
                }
            }
        }
    }

    fn start_export(&mut self, target: ExportTarget) {
        if let ExportTarget::Strands { file, .. } = &target
            && !files::is_strand_file(file)
        {
            self.state.message = format!(
                "export failed: {}: unknown strand format (use .hair, .usda, .glb or .abc)",
                file.display()
            );
            return;
        }
        self.state.commit_edit();
        self.export = Some(ExportJob::start(
            self.state.document().clone(),
            target,
            self.viewport.settings.strands_per_bundle,
        ));
    }

    /// Whether the artist asked to quit and nothing is left to ask (the window may close).
    pub fn wants_to_quit(&self) -> bool {
        self.quitting
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui
                    .add(
                        egui::Button::new("New")
                            .shortcut_text(ui.ctx().format_shortcut(&shortcut::NEW)),
                    )
                    .clicked()
                {
                    self.request(AfterConfirm::New);
                    ui.close();
                }
                if ui
                    .add(
                        egui::Button::new("Open…")
                            .shortcut_text(ui.ctx().format_shortcut(&shortcut::OPEN)),
                    )
                    .clicked()
                {
                    ui.close();
                    self.file_request(FileRequest::OpenProject);
                }
                ui.menu_button("Open Recent", |ui| {
                    if self.recent.paths.is_empty() {
                        ui.label("(none yet)");
                    }
                    for path in self.recent.paths.clone() {
                        if ui.button(path.display().to_string()).clicked() {
                            ui.close();
                            self.request(AfterConfirm::Open(path));
                        }
                    }
                });
                ui.separator();
                if ui
                    .add(
                        egui::Button::new("Save")
                            .shortcut_text(ui.ctx().format_shortcut(&shortcut::SAVE)),
                    )
                    .clicked()
                {
                    ui.close();
                    self.save();
                }
                if ui
                    .add(
                        egui::Button::new("Save As…")
                            .shortcut_text(ui.ctx().format_shortcut(&shortcut::SAVE_AS)),
                    )
                    .clicked()
                {
                    ui.close();
                    self.save_as();
                }
                ui.separator();
                if ui.button("Import scalp…").clicked() {
                    ui.close();
                    self.file_request(FileRequest::ImportScalp);
                }
                if ui.button("Import groom…").clicked() {
                    ui.close();
                    self.file_request(FileRequest::ImportGroom);
                }
                let exporting = self.export.is_some();
                if ui
                    .add_enabled(!exporting, egui::Button::new("Export runtime bundle…"))
                    .clicked()
                {
                    ui.close();
                    self.file_request(FileRequest::ExportRuntime);
                }
                if ui
                    .add_enabled(!exporting, egui::Button::new("Export strands…"))
                    .clicked()
                {
                    ui.close();
                    // A plain strand export writes an .abc for the default client.
                    self.alembic_target = AlembicTarget::default();
                    self.file_request(FileRequest::ExportStrands);
                }
                ui.add_enabled_ui(!exporting, |ui| {
                    ui.menu_button("Export groom (.abc) for", |ui| {
                        for target in AlembicTarget::ALL {
                            if ui.button(alembic_target_label(target)).clicked() {
                                ui.close();
                                self.alembic_target = target;
                                self.file_request(FileRequest::ExportStrands);
                            }
                        }
                    });
                });
                ui.separator();
                if ui
                    .add(
                        egui::Button::new("Quit")
                            .shortcut_text(ui.ctx().format_shortcut(&shortcut::QUIT)),
                    )
                    .clicked()
                {
                    ui.close();
                    self.request(AfterConfirm::Quit);
                }
            });
            ui.menu_button("Edit", |ui| {
                if ui
                    .add_enabled(
                        self.state.can_undo(),
                        egui::Button::new("Undo")
                            .shortcut_text(ui.ctx().format_shortcut(&shortcut::UNDO)),
                    )
                    .clicked()
                {
                    self.state.undo();
                    ui.close();
                }
                if ui
                    .add_enabled(
                        self.state.can_redo(),
                        egui::Button::new("Redo")
                            .shortcut_text(ui.ctx().format_shortcut(&shortcut::REDO)),
                    )
                    .clicked()
                {
                    self.state.redo();
                    ui.close();
                }
                ui.separator();
                // Cutting the scalp out of an imported body: select it, keep it.
                let any = !self.state.selection.is_empty()
                    && self.state.tool.mode == state::SelectMode::Bundles;
                if ui
                    .add_enabled(
                        any,
                        egui::Button::new("Delete selected bundles")
                            .shortcut_text(ui.ctx().format_shortcut(&shortcut::DELETE)),
                    )
                    .on_hover_text(
                        "For good: their faces leave the scalp and stay in the body (Remove in Tools keeps them)",
                    )
                    .clicked()
                {
                    self.delete_bundles(false);
                    ui.close();
                }
                if ui
                    .add_enabled(any, egui::Button::new("Keep only selected bundles"))
                    .on_hover_text(
                        "Delete every other bundle: box-select the scalp on an imported body, then keep it",
                    )
                    .clicked()
                {
                    self.delete_bundles(true);
                    ui.close();
                }
            });
            ui.menu_button("View", |ui| {
                let settings = &mut self.viewport.settings;
                ui.checkbox(&mut settings.wireframe, "Hair-mesh wireframe");
                ui.checkbox(&mut settings.gizmo, "Transform gizmo");
                ui.checkbox(
                    &mut settings.styling_gizmo,
                    "Styling-direction gizmo (wave, twist, curl)",
                )
                .on_hover_text(
                    "At the selected bundles' roots, instead of the transform gizmo: drag the \
                     yellow tip to point the wave, the cyan ring to twist, the magenta ring to \
                     mirror the curl",
                );
                ui.checkbox(
                    &mut settings.frame_glyphs,
                    "Styling frames (u red, v green, w blue)",
                );
                ui.checkbox(&mut settings.map_overlay, "Painted map over the scalp")
                    .on_hover_text(
                        "While a map brush paints, show that map over the scalp: blue 0 to \
                         red 1 for density, length and clump; the colour map by its weight",
                    );
                ui.checkbox(&mut settings.turntable, "Turntable (look-dev)")
                    .on_hover_text(
                        "The camera goes round the hair once in 12 s, the lights turning with \
                         it, as if the head turned under studio lights",
                    );
                ui.label(
                    egui::RichText::new("Strands, LOD and accuracy: the Strands & accuracy panel")
                        .weak(),
                );
                ui.separator();
                if ui.button("Reset layout").clicked() {
                    self.layout = default_layout();
                    ui.close();
                }
            });
        });
    }

    /// The modal windows: recovery offer, groom and scalp import, "save changes?", typed
    /// path, export progress.
    fn modals(&mut self, ui: &mut egui::Ui) {
        self.recovery_offer(ui);
        self.groom_import_modal(ui);
        self.mesh_choice_modal(ui);
        self.scalp_import_modal(ui);
        if let Some(action) = self.confirm.clone() {
            let mut choice = None;
            let modal =
                egui::Modal::new(egui::Id::unique("hairloom save changes")).show(ui.ctx(), |ui| {
                    ui.heading("Save changes?");
                    ui.label(format!(
                        "{} has unsaved changes. They are lost if you do not save them.",
                        self.state.display_name()
                    ));
                    ui.horizontal(|ui| {
                        if ui.button("Save").clicked() {
                            choice = Some(Some(true));
                        }
                        if ui.button("Don't Save").clicked() {
                            choice = Some(Some(false));
                        }
                        if ui.button("Cancel").clicked() {
                            choice = Some(None);
                        }
                    });
                });
            // Esc (or a click beside the window) is Cancel.
            if choice.is_none() && modal.should_close() {
                choice = Some(None);
            }
            match choice {
                Some(Some(save)) => {
                    self.confirm = None;
                    if !save || self.save() {
                        self.run_action(action);
                    } else if self.prompt.is_some() {
                        // Save went to the typed-path prompt: its OK saves, then continues.
                        self.after_save = Some(action);
                    }
                }
                Some(None) => self.confirm = None,
                None => {}
            }
        }
        if let Some(prompt) = self.prompt.as_mut() {
            let mut answer = None;
            let modal =
                egui::Modal::new(egui::Id::unique("hairloom path prompt")).show(ui.ctx(), |ui| {
                    ui.heading(prompt.request.title());
                    ui.label("No file dialog is available here: type the path.");
                    let field = ui.add(
                        egui::TextEdit::singleline(&mut prompt.text)
                            .desired_width(420.0)
                            .hint_text("/path/to/file"),
                    );
                    if !prompt.focused {
                        field.request_focus();
                        prompt.focused = true;
                    }
                    let entered =
                        field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                    ui.horizontal(|ui| {
                        if ui.button("OK").clicked() || entered {
                            answer = Some(Some(PathBuf::from(prompt.text.trim())));
                        }
                        if ui.button("Cancel").clicked() {
                            answer = Some(None);
                        }
                    });
                });
            if answer.is_none() && modal.should_close() {
                answer = Some(None);
            }
            if let Some(answer) = answer {
                let request = prompt.request;
                self.prompt = None;
                match answer.filter(|p| !p.as_os_str().is_empty()) {
                    Some(path) => self.answered(request, path),
                    None => self.after_save = None,
                }
            }
        }
        if let Some(job) = &self.export {
            match job.finished() {
                Some(outcome) => {
                    self.state.message = match outcome {
                        Ok(summary) => format!("exported {summary}"),
                        Err(error) => format!("export failed: {error}"),
                    };
                    self.export = None;
                }
                None => {
                    let label = match &job.target {
                        ExportTarget::Runtime { dir, .. } => dir.display().to_string(),
                        ExportTarget::Strands { file, .. } => file.display().to_string(),
                    };
                    if files::progress_modal(ui, "Exporting", &label, job.fraction()) {
                        job.cancel();
                    }
                }
            }
        }
    }

    /// The groom import's modal, and its result once the fit is done.
    fn groom_import_modal(&mut self, ui: &mut egui::Ui) {
        let Some(import) = &mut self.groom_import else {
            return;
        };
        match import.ui(ui, self.state.document()) {
            groom_import::GroomImportAction::Waiting => {}
            groom_import::GroomImportAction::Closed => self.groom_import = None,
            groom_import::GroomImportAction::Done(outcome) => {
                self.groom_import = None;
                match outcome {
                    Ok(fitted) => {
                        self.viewport.settings.strands_per_bundle = fitted
                            .strands_per_bundle
                            .clamp(1, viewport::MAX_STRANDS_PER_BUNDLE);
                        self.state.import_groom(*fitted.document, &fitted.summary);
                        self.viewport.reframe();
                    }
                    Err(error) => self.state.message = format!("groom import failed: {error}"),
                }
            }
        }
    }

    fn status_bar(&self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label(&self.state.message);
            ui.separator();
            let (strands, vertices) = self.viewport.drawn();
            ui.label(format!("{strands} strands, {vertices} vertices drawn"));
            if let Some(ms) = self.viewport.frame_ms() {
                // The viewport's real rate: from its last frame's cost, not the UI's repaints
                // (which idle between frames).
                ui.separator();
                let fps = 1e3 / ms.max(1e-3);
                // Below one frame a second, show enough digits to tell 0.05 from 0.5.
                let digits = if fps < 1.0 { 2 } else { 1 };
                ui.label(format!(
                    "GPU generate + draw {ms:.1} ms ({fps:.digits$} fps)"
                ));
            }
            if let viewport::FrameQuality::Interactive { scale, detail } =
                self.viewport.shown_quality
            {
                ui.separator();
                ui.label(format!(
                    "interactive: {:.0}% size, {:.0}% LOD detail, no effects (budget {} ms)",
                    scale * 100.0,
                    detail * 100.0,
                    viewport::FRAME_BUDGET_MS
                ))
                .on_hover_text("the full picture follows when input is still");
            }
            ui.separator();
            ui.label(&self.viewport.adapter);
        });
    }
}

/// Draws each pane with the app's panels.
struct PaneUi<'a> {
    state: &'a mut EditorState,
    tools: &'a mut ToolsPanel,
    outliner: &'a mut OutlinerPanel,
    history: &'a mut HistoryPanel,
    styling: &'a mut StylingPanel,
    scene: &'a mut ScenePanel,
    layout: &'a mut LayoutPanel,
    viewport: &'a mut Viewport,
}

impl egui_tiles::Behavior<Pane> for PaneUi<'_> {
    fn tab_title_for_pane(&mut self, pane: &Pane) -> egui::WidgetText {
        pane.title().into()
    }

    /// Ctrl+Tab cycles the hovered tab group, except while a modal tool or a dialog owns the
    /// keyboard: switching the viewport's tab away would leave a running drag or G / R / S
    /// with nothing to confirm or cancel it.
    fn cycle_tabs_with_keyboard(&self) -> bool {
        !self.viewport.keyboard_blocked && self.viewport.modal_tool().is_none()
    }

    fn pane_ui(
        &mut self,
        ui: &mut egui::Ui,
        _tile_id: egui_tiles::TileId,
        pane: &mut Pane,
    ) -> egui_tiles::UiResponse {
        if *pane == Pane::Viewport {
            self.viewport.ui(ui, self.state);
            return egui_tiles::UiResponse::None;
        }
        egui::Frame::central_panel(ui.style()).show(ui, |ui| {
            egui::ScrollArea::vertical()
                .id_salt(pane.title())
                .auto_shrink([false, false])
                .show(ui, |ui| match pane {
                    Pane::Tools => self.tools.ui(ui, self.state),
                    Pane::Outliner => self.outliner.ui(ui, self.state),
                    Pane::History => self.history.ui(ui, self.state),
                    Pane::Styling => self.styling.ui(ui, self.state),
                    Pane::Scene => self.scene.ui(ui, self.state, self.viewport),
                    Pane::Strands => self.viewport.settings_ui(ui, self.state),
                    Pane::Layout => self.layout.ui(ui, self.state),
                    Pane::Viewport => {}
                });
        });
        egui_tiles::UiResponse::None
    }

    fn simplification_options(&self) -> egui_tiles::SimplificationOptions {
        egui_tiles::SimplificationOptions {
            all_panes_must_have_tabs: true,
            ..Default::default()
        }
    }

    fn is_tab_bar_visible(&self, _tile_id: egui_tiles::TileId, tabs: &egui_tiles::Tabs) -> bool {
        // The viewport alone in a tab group needs no tab bar; every other pane shows its title.
        tabs.children.len() > 1 || tabs.active.is_none()
    }
}

impl eframe::App for HairloomApp {
    fn on_exit(&mut self) {
        self.remember_view();
        self.panels.remember(&self.layout);
        if let Some(job) = &self.export {
            // Let the export finish writing (each file is atomic either way).
            let _ = job.wait();
        }
        if let Some(import) = &self.groom_import {
            import.cancel_and_wait();
        }
        // Unsaved work survives a quit; nothing unsaved leaves no recovery file behind.
        if self.state.is_dirty() && !self.quitting {
            let _ = self.recovery.write(&self.state);
        } else if self.offer.is_none() {
            self.recovery.discard();
        }
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.autosave(ui.input(|i| i.time));
        if self.state.tick_playback(ui.input(|i| i.time)) {
            ui.ctx().request_repaint();
        }
        // The window's close button asks first, like File ▸ Quit.
        if ui.input(|i| i.viewport().close_requested()) && !self.quitting {
            ui.ctx()
                .send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.request(AfterConfirm::Quit);
        }
        if self.quitting && !self.close_sent {
            ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
            self.close_sent = true;
        }
        self.modals(ui);
        self.shortcuts(ui);
        self.viewport.keyboard_blocked = self.dialog_open();
        let title = self.state.title();
        if title != self.title {
            ui.ctx()
                .send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        egui::CentralPanel::no_frame().show(ui, |ui| {
            let mut panes = PaneUi {
                state: &mut self.state,
                tools: &mut self.tools,
                outliner: &mut self.outliner,
                history: &mut self.history,
                styling: &mut self.styling,
                scene: &mut self.scene,
                layout: &mut self.layout_panel,
                viewport: &mut self.viewport,
            };
            self.layout.ui(&mut panes, ui);
        });
        // A divider or tab is stored once it is let go, not at every step of its drag.
        if !ui.input(|i| i.pointer.any_down()) {
            self.panels.remember(&self.layout);
        }
    }
}

/// The editor's keyboard shortcuts, shared by the handler and the menus that show them.
mod shortcut {
    use egui::{Key, KeyboardShortcut, Modifiers};

    pub const UNDO: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
    pub const REDO: KeyboardShortcut =
        KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::Z);
    pub const REDO_Y: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);
    pub const SAVE: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::S);
    pub const SAVE_AS: KeyboardShortcut =
        KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::S);
    pub const OPEN: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
    pub const NEW: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::N);
    pub const QUIT: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Q);
    /// Deletes the selected bundles (bundle mode, nothing typed into).
    pub const DELETE: KeyboardShortcut = KeyboardShortcut::new(Modifiers::NONE, Key::Delete);
}

/// The File menu's name of an Alembic target, with the axes and units it gets.
fn alembic_target_label(target: AlembicTarget) -> &'static str {
    match target {
        AlembicTarget::Blender => "Blender (y up, m)",
        AlembicTarget::Houdini => "Houdini (y up, m)",
        AlembicTarget::Maya => "Maya (y up, cm)",
        AlembicTarget::Unity => "Unity (y up, cm)",
        AlembicTarget::Unreal => "Unreal (z up, cm)",
    }
}
