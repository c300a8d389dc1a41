//! The editor's model: the project (document + history), where it lives on disk, and the
//! edit in progress. No egui here — panels call these methods, tests call them directly.
//!
//! Every change to the document goes through a [`Transaction`], so every change is one undo
//! step: a slider drag is begun on the first movement and committed on release.

use std::path::{Path, PathBuf};

use std::collections::BTreeSet;

use hairloom_core::edit::{self, select};
use hairloom_core::edit::{EditError, EditOutcome};
use hairloom_core::io::project::{self, Project};
use hairloom_core::model::change::{ChangeKind, ChangeLog};
use hairloom_core::model::document::Document;
use hairloom_core::model::history::Transaction;
use hairloom_core::{HairMesh, Topology, VertexRef};

/// The sample the editor opens with no file, embedded so it works from any folder.
const SAMPLE_PROJECT: &[u8] = include_bytes!("../../../assets/samples/head_long_wavy.hairloom");
const SAMPLE_NAME: &str = "head_long_wavy.hairloom (sample)";

/// A fresh document revision number (process-wide).
pub(super) fn next_revision() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// What a click or a region selects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SelectMode {
    Bundles,
    /// Exterior vertices (interior ones place themselves).
    Vertices,
}

/// What a left drag in the viewport does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DragTool {
    Box,
    Lasso,
    Paint,
    /// Stroke the hair with the grooming brush (`ToolSettings::brush`) instead of selecting.
    Groom,
}

/// The grooming brush a left drag strokes with under [`DragTool::Groom`] (view state: the
/// strokes themselves are edits of the document).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrushSettings {
    pub kind: hairloom_core::edit::BrushKind,
    /// In model units (metres for the bundled samples).
    pub radius_m: f64,
    /// 0 … 1.
    pub strength: f64,
    /// Also stroke the mirror image across the head's plane.
    pub mirror_x: bool,
    /// Leave hair whose scalp faces away from the view (never brush through the head).
    pub front_only: bool,
    /// Paint this map over the scalp instead of shaping the hair (`kind` is then unused).
    pub paint: Option<hairloom_core::model::root_maps::RootMapChannel>,
    /// The share the map brush paints toward (Ctrl: 1, the unpainted value).
    pub paint_value: f64,
    /// The colour map brush's colour (sRGB) and the weight it paints toward (Ctrl: 0, the
    /// material's own colour).
    pub paint_colour: [u8; 3],
    pub colour_weight: f64,
}

impl BrushSettings {
    /// What the brush is called in messages and the history.
    pub fn label(&self) -> String {
        match self.paint {
            Some(channel) => format!("Paint {}", channel.label().to_lowercase()),
            None => self.kind.label().to_string(),
        }
    }
}

impl Default for BrushSettings {
    fn default() -> Self {
        Self {
            kind: hairloom_core::edit::BrushKind::Comb,
            radius_m: 0.03,
            strength: 0.5,
            mirror_x: true,
            front_only: true,
            paint: None,
            paint_value: 0.0,
            // A copper red: visible on the samples' brown hair.
            paint_colour: [170, 70, 35],
            colour_weight: 1.0,
        }
    }
}

/// Selection and transform settings shared by the tools panel and the viewport (view state).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToolSettings {
    pub mode: SelectMode,
    pub drag: DragTool,
    pub paint_radius_px: f32,
    /// Soft-selection radius for move / rotate / scale (0 = off).
    pub soft_radius_m: f64,
    /// The on-screen gizmo's handles.
    pub gizmo: super::gizmo::GizmoKind,
    /// Axis keys and typed values during G / R / S follow Blender's Z-up convention (X
    /// right, Y away from the front view, Z up) instead of the scene's Y-up axes.
    pub z_up: bool,
    /// Pick and region-select through the body (and see hidden bundles' outlines).
    pub xray: bool,
    pub brush: BrushSettings,
}

impl Default for ToolSettings {
    fn default() -> Self {
        Self {
            mode: SelectMode::Bundles,
            drag: DragTool::Box,
            paint_radius_px: 24.0,
            soft_radius_m: 0.0,
            gizmo: super::gizmo::GizmoKind::Move,
            z_up: true,
            xray: false,
            brush: BrushSettings::default(),
        }
    }
}

pub struct EditorState {
    pub project: Project,
    /// Where Save writes; `None` for the embedded sample until Save As.
    pub path: Option<PathBuf>,
    /// The document as last loaded or saved (unsaved changes = differs from it).
    saved: Document,
    edit: Option<Transaction>,
    /// Changes whenever the document changes (the viewport rebuilds its GPU data). Unique
    /// across states, so a state replacing another (opened, recovered) never reuses one.
    pub revision: u64,
    /// The kind of change that made each revision (what the viewport's hair asset redoes).
    changes: ChangeLog,
    /// The last message for the status bar (errors included).
    pub message: String,
    /// Selected bundles: view state, never saved and never in the history.
    pub selection: BTreeSet<u32>,
    /// Selected exterior vertices (vertex mode).
    pub vertex_selection: BTreeSet<VertexRef>,
    pub tool: ToolSettings,
    /// Recovered work counts as unsaved even where it equals a file on disk.
    unsaved: bool,
    /// The scene's motion played back (view state).
    pub playback: super::playback::Playback,
    /// Whether the document is still the embedded sample (named as such until saved); an
    /// import that replaces its scalp makes it the artist's own.
    is_sample: bool,
}

impl EditorState {
    pub(super) fn from_project(project: Project, path: Option<PathBuf>, message: String) -> Self {
        let revision = next_revision();
        Self {
            saved: project.document.clone(),
            project,
            path,
            edit: None,
            revision,
            changes: ChangeLog::starting_at(revision),
            message,
            selection: BTreeSet::new(),
            vertex_selection: BTreeSet::new(),
            tool: ToolSettings::default(),
            unsaved: false,
            playback: Default::default(),
            is_sample: false,
        }
    }

    /// The embedded sample project.
    pub fn sample() -> Self {
        let project = project::from_bytes(SAMPLE_PROJECT, Path::new(SAMPLE_NAME))
            .expect("the embedded sample is a valid project (checked by `make test`)");
        Self {
            is_sample: true,
            ..Self::from_project(project, None, format!("opened {SAMPLE_NAME}"))
        }
    }

    /// A new, empty project (import a scalp to start).
    pub fn new_project() -> Self {
        let document = Document::new("untitled", HairMesh::empty());
        Self::from_project(
            Project::new(document),
            None,
            "new project: import a scalp with File > Import scalp...".into(),
        )
    }

    /// Replaces the scalp, body and name with an imported document's, keeping the styling:
    /// one undo step.
    pub fn import_scalp(&mut self, imported: Document, summary: &str) {
        self.replace_from(imported, "Import scalp", false, summary);
    }

    /// The name, source, hair mesh and body (and with `styling`, the styling) of `imported`
    /// replace the document's, as one undo step named `label`.
    fn replace_from(&mut self, imported: Document, label: &str, styling: bool, summary: &str) {
        self.commit_edit();
        let document = self.edit(ChangeKind::Rebuild, label);
        document.name = imported.name;
        document.source = imported.source;
        document.hair_mesh = imported.hair_mesh;
        document.body = imported.body;
        if styling {
            document.styling = imported.styling;
        }
        self.commit_edit();
        self.selection.clear();
        self.is_sample = false;
        self.message = format!("imported {summary}");
    }

    /// Replaces the hair mesh, scalp, body, name and styling with a fitted groom's, keeping
    /// the scene (lights, material, effects): one undo step.
    pub fn import_groom(&mut self, fitted: Document, summary: &str) {
        self.replace_from(fitted, "Import groom", true, summary);
    }

    /// Opens a project file; the error names the file and the problem.
    pub fn open(path: &Path) -> Result<Self, project::ProjectError> {
        let project = project::load(path)?;
        Ok(Self::from_project(
            project,
            Some(path.to_path_buf()),
            format!("opened {}", path.display()),
        ))
    }

    pub fn document(&self) -> &Document {
        &self.project.document
    }

    /// What the viewport draws: the document posed by the playing motion, or as modelled.
    pub fn shown_document(&self) -> &Document {
        self.playback.shown(&self.project.document, self.revision)
    }

    /// Changes whenever [`Self::shown_document`] does.
    pub fn shown_revision(&self) -> u64 {
        self.playback.shown_revision(self.revision)
    }

    /// Steps the playing motion by the wall clock; whether another frame is wanted.
    pub fn tick_playback(&mut self, now_s: f64) -> bool {
        self.playback
            .tick(&self.project.document, self.revision, now_s)
    }

    /// Selection and edits act on the modelled shape: a posed playback goes back to it first
    /// (what is picked is then what is drawn).
    pub fn stop_playback_for_editing(&mut self) {
        if self.playback.is_posed() {
            self.playback.reset();
            self.message = "playback reset: selection and edits act on the modelled shape".into();
        }
    }

    /// Shows the motion at `time_s`; a long simulation runs on a worker, and the status bar
    /// says what it will cost before it runs.
    pub fn seek_playback(&mut self, time_s: f64) {
        if let Some(estimate) = self
            .playback
            .seek(&self.project.document, self.revision, time_s)
        {
            self.message = format!("{} (in the background)", estimate.describe(time_s));
        }
    }

    /// The project's name as the user knows it: its file name, "untitled", or the sample's.
    pub fn display_name(&self) -> String {
        match self.path.as_deref().and_then(Path::file_name) {
            Some(name) => name.to_string_lossy().into_owned(),
            None if self.is_sample => SAMPLE_NAME.to_string(),
            // Not saved yet: the document's own name (an imported scalp's, or "untitled").
            None if self.project.document.name.is_empty() => "untitled".into(),
            None => self.project.document.name.clone(),
        }
    }

    /// Title for the window and the status bar.
    pub fn title(&self) -> String {
        format!(
            "{}{} — Hairloom",
            if self.is_dirty() { "* " } else { "" },
            self.display_name()
        )
    }

    /// Tab: bundles ↔ vertices.
    pub fn toggle_select_mode(&mut self) {
        self.tool.mode = match self.tool.mode {
            SelectMode::Bundles => SelectMode::Vertices,
            SelectMode::Vertices => SelectMode::Bundles,
        };
    }

    pub fn is_dirty(&self) -> bool {
        self.unsaved || self.project.document != self.saved
    }

    /// Marks the state as unsaved work (recovered from an autosave).
    pub fn mark_unsaved(&mut self, message: String) {
        self.unsaved = true;
        self.message = message;
    }

    /// Starts an edit (one undo step) making changes of `kind` unless one is running (which
    /// then goes on with changes of `kind` too); returns the document to change.
    pub fn edit(&mut self, kind: ChangeKind, label: &str) -> &mut Document {
        match &mut self.edit {
            Some(edit) => edit.widen(kind),
            None => self.edit = Some(Transaction::begin(&self.project.document, label, kind)),
        }
        self.bump_revision(kind);
        &mut self.project.document
    }

    /// A new revision, made by a change of `kind`.
    fn bump_revision(&mut self, kind: ChangeKind) {
        self.revision = next_revision();
        self.changes.record(self.revision, kind);
    }

    /// What changed in the document since `revision`: `None` when nothing did.
    pub fn change_since(&self, revision: u64) -> Option<ChangeKind> {
        if revision == self.revision {
            return None;
        }
        self.changes.since(revision)
    }

    /// The project as a consistent, loadable whole, without disturbing a running edit: an
    /// open gesture (a G drag, an extrude being sized) is folded in as its own history
    /// step, so the history verifies against the document. What autosave writes.
    pub fn consistent_project(&self) -> Project {
        let mut project = self.project.clone();
        if let Some(edit) = &self.edit
            && let Some(command) =
                hairloom_core::Command::record(edit.label(), edit.start(), &project.document)
        {
            project.history.push(command);
        }
        project
    }

    /// Whether an edit (a drag, a modal tool, a slider held) is running.
    pub fn edit_open(&self) -> bool {
        self.edit.is_some()
    }

    /// Ends the running edit: one command in the history if anything changed.
    pub fn commit_edit(&mut self) {
        if let Some(edit) = self.edit.take() {
            edit.commit(&mut self.project.history, &self.project.document);
        }
    }

    /// Abandons the running edit and restores the document as it was before it.
    pub fn cancel_edit(&mut self) {
        if let Some(edit) = self.edit.take() {
            let kind = edit.kind();
            edit.cancel(&mut self.project.document);
            self.bump_revision(kind);
        }
    }

    /// The document as it was when the running edit began (the current one otherwise).
    pub fn edit_start(&self) -> &Document {
        self.edit
            .as_ref()
            .map_or(&self.project.document, |edit| edit.start())
    }

    /// Selects everything (mode-aware); `false` deselects everything.
    pub fn select_all(&mut self, all: bool) {
        self.selection.clear();
        self.vertex_selection.clear();
        if !all {
            return;
        }
        let mesh = &self.project.document.hair_mesh;
        match self.tool.mode {
            SelectMode::Bundles => {
                self.selection = (0..mesh.bundles.len() as u32)
                    .filter(|&b| !mesh.bundles[b as usize].removed)
                    .collect();
            }
            SelectMode::Vertices => {
                let topology = Topology::build(mesh);
                self.vertex_selection = select::exterior_vertices(mesh, &topology)
                    .into_iter()
                    .collect();
            }
        }
    }

    /// Grows (`true`) or shrinks the selection by one ring of neighbours.
    pub fn grow_selection(&mut self, grow: bool) {
        let mesh = &self.project.document.hair_mesh;
        let topology = Topology::build(mesh);
        match self.tool.mode {
            SelectMode::Bundles => {
                self.selection = if grow {
                    select::grow_bundles(mesh, &topology, &self.selection)
                } else {
                    select::shrink_bundles(mesh, &topology, &self.selection)
                };
            }
            SelectMode::Vertices => {
                self.vertex_selection = if grow {
                    select::grow_vertices(mesh, &topology, &self.vertex_selection)
                } else {
                    select::shrink_vertices(mesh, &topology, &self.vertex_selection)
                };
            }
        }
    }

    /// Selects the exterior vertices of `layer` (of the selected bundles, or of all).
    pub fn select_layer(&mut self, layer: u32) {
        let mesh = &self.project.document.hair_mesh;
        let topology = Topology::build(mesh);
        let bundles = (!self.selection.is_empty()).then_some(&self.selection);
        self.vertex_selection = select::layer_vertices(mesh, &topology, bundles, layer);
        self.tool.mode = SelectMode::Vertices;
        self.message = format!(
            "layer {layer}: {} vertices selected",
            self.vertex_selection.len()
        );
    }

    /// What move / rotate / scale acts on: the selected vertices, or the selected bundles'
    /// exterior vertices above the scalp.
    /// What Lock and Unlock act on: the selected vertices in vertex mode, else every vertex
    /// above the root of the selected bundles.
    pub fn lock_targets(&self) -> Vec<VertexRef> {
        if self.tool.mode == SelectMode::Vertices {
            return self.vertex_selection.iter().copied().collect();
        }
        select::bundle_vertices_above_root(&self.project.document.hair_mesh, &self.selection)
            .into_iter()
            .collect()
    }

    pub fn transform_targets(&self) -> Vec<VertexRef> {
        let mesh = &self.project.document.hair_mesh;
        let topology = Topology::build(mesh);
        match self.tool.mode {
            SelectMode::Vertices => self
                .vertex_selection
                .iter()
                .copied()
                .filter(|v| {
                    mesh.position(*v).is_some()
                        && !mesh.is_interior(&topology, v.column as usize, v.layer as usize)
                })
                .collect(),
            SelectMode::Bundles => {
                select::bundle_transform_vertices(mesh, &topology, &self.selection)
            }
        }
    }

    /// Drops selected bundles and vertices the document no longer has (after an undo).
    pub fn prune_selection(&mut self) {
        let mesh = &self.project.document.hair_mesh;
        let count = mesh.bundles.len() as u32;
        self.selection.retain(|&b| b < count);
        self.vertex_selection
            .retain(|v| mesh.position(*v).is_some());
    }

    /// Deletes the selected bundles for good (`keep_selected`: every other one — a scalp cut
    /// from an imported body by selecting it), as one undo step. Their root faces stay in
    /// the body; styling groups follow the renumbering. The survivors stay selected after
    /// a keep; a delete clears the selection. Returns the renumbering (each old bundle's new
    /// index, `None` when deleted) for what else holds bundle indices, or `None` when
    /// nothing was deleted.
    pub fn delete_bundles(&mut self, keep_selected: bool) -> Option<Vec<Option<u32>>> {
        let label = if keep_selected {
            "Keep only selected bundles"
        } else {
            "Delete bundles"
        };
        self.commit_edit();
        self.stop_playback_for_editing();
        let count = self.project.document.hair_mesh.bundles.len();
        let gone: Vec<u32> = if keep_selected {
            if self.selection.is_empty() {
                self.message = format!("{label}: {}", EditError::EmptySelection);
                return None;
            }
            (0..count as u32)
                .filter(|b| !self.selection.contains(b))
                .collect()
        } else {
            self.selection.iter().copied().collect()
        };
        if keep_selected && gone.is_empty() {
            self.message = format!("{label}: every bundle is selected; nothing to delete");
            return None;
        }
        match edit::delete_bundles(&self.project.document.hair_mesh, &gone) {
            Ok(outcome) => {
                let kept = outcome.affected_bundles.len();
                let document = self.edit(ChangeKind::Rebuild, label);
                document.hair_mesh = outcome.mesh;
                let renumbering = edit::bundle_renumbering(count, &gone);
                document.styling.renumber_bundles(&renumbering);
                self.commit_edit();
                self.vertex_selection.clear();
                self.selection = if keep_selected {
                    (0..kept as u32).collect()
                } else {
                    BTreeSet::new()
                };
                self.message = format!(
                    "{label}: {} deleted, {kept} left (their faces stay in the body)",
                    gone.len()
                );
                Some(renumbering)
            }
            Err(error) => {
                self.message = format!("{label}: {error}");
                None
            }
        }
    }

    /// Applies a hair-mesh edit of the selected bundles as one undo step; an error (named in
    /// the status bar) leaves the document untouched.
    pub fn edit_mesh(
        &mut self,
        label: &str,
        edit: impl FnOnce(&HairMesh, &[u32]) -> Result<EditOutcome, EditError>,
    ) -> bool {
        self.commit_edit();
        self.stop_playback_for_editing();
        let selected: Vec<u32> = self.selection.iter().copied().collect();
        match edit(&self.project.document.hair_mesh, &selected) {
            Ok(outcome) => {
                // A merge renumbers columns: selected vertices would name other vertices.
                if outcome.mesh.columns.len() < self.project.document.hair_mesh.columns.len() {
                    self.vertex_selection.clear();
                }
                // One-shot mesh edits (extrude, split, merge…) may change topology.
                self.edit(ChangeKind::Rebuild, label).hair_mesh = outcome.mesh;
                self.commit_edit();
                self.message = format!(
                    "{label}: {} bundle(s) changed",
                    outcome.affected_bundles.len()
                );
                true
            }
            Err(error) => {
                self.message = format!("{label}: {error}");
                false
            }
        }
    }

    pub fn can_undo(&self) -> bool {
        !self.project.history.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.project.history.redo.is_empty()
    }

    pub fn undo(&mut self) {
        self.commit_edit();
        match self.project.history.undo(&mut self.project.document) {
            Ok(Some(step)) => self.changed(format!("undid {}", step.label), step.kind),
            Ok(None) => self.message = "nothing to undo".into(),
            Err(error) => self.message = format!("undo failed: {error}"),
        }
    }

    pub fn redo(&mut self) {
        self.commit_edit();
        match self.project.history.redo(&mut self.project.document) {
            Ok(Some(step)) => self.changed(format!("redid {}", step.label), step.kind),
            Ok(None) => self.message = "nothing to redo".into(),
            Err(error) => self.message = format!("redo failed: {error}"),
        }
    }

    /// Undoes or redoes until `position` commands are applied.
    pub fn jump_to(&mut self, position: usize) {
        self.commit_edit();
        match self
            .project
            .history
            .jump_to(&mut self.project.document, position)
        {
            Ok(kind) => self.changed(format!("history step {position}"), kind),
            Err(error) => {
                // The steps before the failing one were applied: the hair is made again.
                self.bump_revision(ChangeKind::Rebuild);
                self.message = format!("history jump failed: {error}");
            }
        }
    }

    fn changed(&mut self, message: String, kind: ChangeKind) {
        self.bump_revision(kind);
        self.message = message;
    }

    /// Saves to the current path (Save As for the embedded sample).
    pub fn save(&mut self) -> Result<PathBuf, String> {
        let Some(path) = self.path.clone() else {
            return Err("the sample has no file yet: use Save As".into());
        };
        self.save_as(&path)
    }

    pub fn save_as(&mut self, path: &Path) -> Result<PathBuf, String> {
        self.commit_edit();
        match project::save(path, &self.project) {
            Ok(()) => {
                self.path = Some(path.to_path_buf());
                self.saved = self.project.document.clone();
                self.unsaved = false;
                self.message = format!("saved {}", path.display());
                Ok(path.to_path_buf())
            }
            Err(error) => {
                self.message = format!("save failed: {error}");
                Err(self.message.clone())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_edit_is_one_undo_step_and_undo_restores_the_document() {
        let mut state = EditorState::sample();
        let original = state.document().clone();
        for step in 1..=5 {
            state
                .edit(ChangeKind::Restyle, "curl")
                .styling
                .global
                .curl
                .radius_m = 0.001 * step as f64;
        }
        state.commit_edit();
        assert!(state.is_dirty());
        assert_eq!(state.project.history.undo.len(), 1);
        state.undo();
        assert_eq!(state.document(), &original);
        assert!(!state.is_dirty());
        state.redo();
        assert_eq!(state.document().styling.global.curl.radius_m, 0.005);
    }

    #[test]
    fn save_and_reopen_round_trips_and_clears_dirty() {
        let dir = tempfile::tempdir().expect("temp dir");
        let mut state = EditorState::sample();
        assert!(state.save().is_err(), "the sample needs Save As");
        state
            .edit(ChangeKind::Restyle, "wave")
            .styling
            .global
            .wave
            .amplitude_m = 0.02;
        state.commit_edit();
        let path = dir.path().join("styled.hairloom");
        state.save_as(&path).expect("save");
        assert!(!state.is_dirty());
        let reopened = EditorState::open(&path).expect("open");
        assert_eq!(reopened.project, state.project);
        let bad = dir.path().join("missing.hairloom");
        assert!(EditorState::open(&bad).is_err());
    }
}
