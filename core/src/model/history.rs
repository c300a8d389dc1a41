//! Undo/redo as commands over the document (Fyrox/Graphite style).
//!
//! A [`Command`] stores what it changed as a [`DocumentDiff`]: for every changed bundle and
//! column, the value before and after. Applying writes the "after" values, reverting writes
//! the "before" values, so every edit — topology or property — is an exact swap and undo
//! restores the document bit for bit. Edits are computed once (by [`crate::edit`]) and
//! replayed from the diff on redo, so redo cannot drift from what the user saw.
//!
//! Groups apply their children in order and revert them in reverse. A drag is one
//! [`Transaction`]: it records the document when the drag starts and becomes one command
//! when it ends, or nothing if nothing changed.
//!
//! Reverting and applying check that the document holds the values the diff expects, so a
//! tampered or mismatched history is reported instead of silently corrupting the document.

use serde::{Deserialize, Serialize};

use crate::model::change::ChangeKind;
use crate::model::document::{BodyMesh, Document};
use crate::model::mesh::{Bundle, Column, VertexRef, WMode};
use crate::model::root_maps::RootMaps;
use crate::model::scene::Scene;
use crate::model::styling::StylingSet;

/// Default number of undo steps kept.
pub const DEFAULT_HISTORY_LIMIT: usize = 200;

/// A change of one element of a vector: `None` means "not present" (the vector was shorter).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ElementChange<T> {
    pub index: u32,
    pub before: Option<T>,
    pub after: Option<T>,
}

/// The changes between two versions of a vector.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VecDiff<T> {
    pub len_before: u32,
    pub len_after: u32,
    pub changes: Vec<ElementChange<T>>,
}

impl<T> Default for VecDiff<T> {
    fn default() -> Self {
        Self {
            len_before: 0,
            len_after: 0,
            changes: Vec::new(),
        }
    }
}

/// The history does not match the document it is applied to.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct HistoryMismatch {
    pub path: String,
    pub message: String,
}

impl<T: Clone + PartialEq> VecDiff<T> {
    pub fn between(before: &[T], after: &[T]) -> Self {
        let mut changes = Vec::new();
        for i in 0..before.len().max(after.len()) {
            let b = before.get(i);
            let a = after.get(i);
            if b != a {
                changes.push(ElementChange {
                    index: i as u32,
                    before: b.cloned(),
                    after: a.cloned(),
                });
            }
        }
        Self {
            len_before: before.len() as u32,
            len_after: after.len() as u32,
            changes,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.changes.is_empty() && self.len_before == self.len_after
    }

    /// Writes the "after" side (`forward`) or the "before" side into `target`.
    fn write(&self, target: &mut Vec<T>, forward: bool, path: &str) -> Result<(), HistoryMismatch> {
        let (len_from, len_to) = if forward {
            (self.len_before, self.len_after)
        } else {
            (self.len_after, self.len_before)
        };
        if target.len() != len_from as usize {
            return Err(HistoryMismatch {
                path: path.to_string(),
                message: format!("expected {len_from} elements, found {}", target.len()),
            });
        }
        for change in &self.changes {
            let expected = if forward {
                &change.before
            } else {
                &change.after
            };
            if target.get(change.index as usize) != expected.as_ref() {
                return Err(HistoryMismatch {
                    path: format!("{path}[{}]", change.index),
                    message: "the document does not hold the value this history entry changed"
                        .into(),
                });
            }
        }
        // Shrinking first, then element writes in ascending order, then growth in order.
        target.truncate(len_to as usize);
        for change in &self.changes {
            let value = if forward {
                &change.after
            } else {
                &change.before
            };
            let index = change.index as usize;
            match value {
                Some(value) if index < target.len() => target[index] = value.clone(),
                Some(value) if index == target.len() => target.push(value.clone()),
                Some(_) => {
                    return Err(HistoryMismatch {
                        path: format!("{path}[{index}]"),
                        message: "history entry leaves a gap".into(),
                    });
                }
                None => {}
            }
        }
        if target.len() != len_to as usize {
            return Err(HistoryMismatch {
                path: path.to_string(),
                message: format!(
                    "history entry yields {} elements, expected {len_to}",
                    target.len()
                ),
            });
        }
        Ok(())
    }
}

/// A before/after pair of a value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Swap<T> {
    pub before: T,
    pub after: T,
}

impl<T: Clone + PartialEq> Swap<T> {
    /// The pair when the value changed.
    fn between(before: &T, after: &T) -> Option<Self> {
        (before != after).then(|| Self {
            before: before.clone(),
            after: after.clone(),
        })
    }

    /// Refuses to write when `value` is not the side this entry starts from.
    fn check(&self, value: &T, forward: bool, path: &str) -> Result<(), HistoryMismatch> {
        let expected = if forward { &self.before } else { &self.after };
        if value != expected {
            return Err(HistoryMismatch {
                path: path.into(),
                message: "the document does not hold the value this history entry changed".into(),
            });
        }
        Ok(())
    }

    fn write(&self, target: &mut T, forward: bool) {
        *target = if forward {
            self.after.clone()
        } else {
            self.before.clone()
        };
    }
}

/// Everything one command changed in a [`Document`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DocumentDiff {
    #[serde(default)]
    pub bundles: VecDiff<Bundle>,
    #[serde(default)]
    pub columns: VecDiff<Column>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub w_mode: Option<Swap<WMode>>,
    /// Boxed: only Lock, Unlock and Drape change it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub locked: Option<Box<Swap<Vec<VertexRef>>>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<Swap<String>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<Swap<String>>,
    /// Boxed: a body is large and only an import changes it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<Box<Swap<BodyMesh>>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    /// Boxed: a styling set is large and most commands do not change it.
    pub styling: Option<Box<Swap<StylingSet>>>,
    /// Boxed: only scene edits change it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<Box<Swap<Scene>>>,
    /// Boxed: only map painting changes them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub root_maps: Option<Box<RootMapsChange>>,
}

/// A change of the painted maps. A stroke keeps their size, and only the texels it changed
/// are kept (a few thousand of a 256² map's 65,536): a history of 200 strokes holding both
/// whole maps each was up to 100 MB in memory and in the project file. A change of size
/// (the first stroke, clearing the last map, an import, the colour map's first stroke or its
/// clearing) keeps both whole. Texel indices run over the grey maps' texels, then the
/// colour map's ([`RootMaps::stacked_texels`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RootMapsChange {
    Texels {
        width: u32,
        height: u32,
        changes: Vec<TexelChange>,
    },
    Whole(Swap<RootMaps>),
}

/// One texel of the painted maps, before and after.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TexelChange {
    pub index: u32,
    pub before: [u8; 4],
    pub after: [u8; 4],
}

impl RootMapsChange {
    fn between(before: &RootMaps, after: &RootMaps) -> Option<Self> {
        if before == after {
            return None;
        }
        let same_size = (before.width(), before.height()) == (after.width(), after.height())
            && before.has_colour() == after.has_colour();
        if !same_size || before.is_empty() {
            return Some(Self::Whole(Swap {
                before: before.clone(),
                after: after.clone(),
            }));
        }
        // Indices run over both textures, the colour map's after the grey maps'.
        let changes = before
            .stacked_texels()
            .zip(after.stacked_texels())
            .enumerate()
            .filter(|(_, (b, a))| b != a)
            .map(|(index, (b, a))| TexelChange {
                index: index as u32,
                before: *b,
                after: *a,
            })
            .collect();
        Some(Self::Texels {
            width: after.width(),
            height: after.height(),
            changes,
        })
    }

    /// Refuses to write when `maps` is not the side this entry starts from (of another size,
    /// or a changed texel holding another value, or out of range in a damaged history).
    fn check(&self, maps: &RootMaps, forward: bool, path: &str) -> Result<(), HistoryMismatch> {
        match self {
            Self::Whole(swap) => swap.check(maps, forward, path),
            Self::Texels {
                width,
                height,
                changes,
            } => {
                let mismatch = |message: String| HistoryMismatch {
                    path: path.into(),
                    message,
                };
                if maps.is_empty() || (maps.width(), maps.height()) != (*width, *height) {
                    return Err(mismatch(format!(
                        "the maps are {} × {}, this history entry changed maps of {width} × {height}",
                        maps.width(),
                        maps.height()
                    )));
                }
                for change in changes {
                    let expected = if forward { change.before } else { change.after };
                    if maps.stacked_texel(change.index as usize) != Some(&expected) {
                        return Err(mismatch(format!(
                            "texel {} does not hold the value this history entry changed",
                            change.index
                        )));
                    }
                }
                Ok(())
            }
        }
    }

    /// Writes the entry's side into `maps` (checked first by [`Self::check`]).
    fn write(&self, maps: &mut RootMaps, forward: bool) {
        match self {
            Self::Whole(swap) => swap.write(maps, forward),
            Self::Texels { changes, .. } => {
                for change in changes {
                    if let Some(texel) = maps.stacked_texel_mut(change.index as usize) {
                        *texel = if forward { change.after } else { change.before };
                    }
                }
            }
        }
    }
}

impl DocumentDiff {
    pub fn between(before: &Document, after: &Document) -> Self {
        Self {
            bundles: VecDiff::between(&before.hair_mesh.bundles, &after.hair_mesh.bundles),
            columns: VecDiff::between(&before.hair_mesh.columns, &after.hair_mesh.columns),
            w_mode: Swap::between(&before.hair_mesh.w_mode, &after.hair_mesh.w_mode),
            locked: Swap::between(&before.hair_mesh.locked, &after.hair_mesh.locked).map(Box::new),
            name: Swap::between(&before.name, &after.name),
            source: Swap::between(&before.source, &after.source),
            body: Swap::between(&before.body, &after.body).map(Box::new),
            styling: Swap::between(&before.styling, &after.styling).map(Box::new),
            scene: Swap::between(&before.scene, &after.scene).map(Box::new),
            root_maps: RootMapsChange::between(&before.root_maps, &after.root_maps).map(Box::new),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.bundles.is_empty()
            && self.columns.is_empty()
            && self.w_mode.is_none()
            && self.locked.is_none()
            && self.name.is_none()
            && self.source.is_none()
            && self.body.is_none()
            && self.styling.is_none()
            && self.scene.is_none()
            && self.root_maps.is_none()
    }

    fn write(&self, document: &mut Document, forward: bool) -> Result<(), HistoryMismatch> {
        // Check every whole-value swap before anything is written so a mismatch never
        // leaves the document half-written; vectors are checked inside their `write`
        // before any change, on a copy of the bundles.
        if let Some(swap) = &self.w_mode {
            swap.check(&document.hair_mesh.w_mode, forward, "hair_mesh.w_mode")?;
        }
        if let Some(swap) = &self.locked {
            swap.check(&document.hair_mesh.locked, forward, "hair_mesh.locked")?;
        }
        if let Some(swap) = &self.name {
            swap.check(&document.name, forward, "name")?;
        }
        if let Some(swap) = &self.source {
            swap.check(&document.source, forward, "source")?;
        }
        if let Some(swap) = &self.body {
            swap.check(&document.body, forward, "body")?;
        }
        if let Some(swap) = &self.styling {
            swap.check(&document.styling, forward, "styling")?;
        }
        if let Some(swap) = &self.scene {
            swap.check(&document.scene, forward, "scene")?;
        }
        if let Some(swap) = &self.root_maps {
            swap.check(&document.root_maps, forward, "root_maps")?;
        }
        let mut bundles = document.hair_mesh.bundles.clone();
        self.bundles
            .write(&mut bundles, forward, "hair_mesh.bundles")?;
        self.columns.write(
            &mut document.hair_mesh.columns,
            forward,
            "hair_mesh.columns",
        )?;
        document.hair_mesh.bundles = bundles;
        if let Some(swap) = &self.w_mode {
            swap.write(&mut document.hair_mesh.w_mode, forward);
        }
        if let Some(swap) = &self.locked {
            swap.write(&mut document.hair_mesh.locked, forward);
        }
        if let Some(swap) = &self.name {
            swap.write(&mut document.name, forward);
        }
        if let Some(swap) = &self.source {
            swap.write(&mut document.source, forward);
        }
        if let Some(swap) = &self.body {
            swap.write(&mut document.body, forward);
        }
        if let Some(swap) = &self.styling {
            swap.write(&mut document.styling, forward);
        }
        if let Some(swap) = &self.scene {
            swap.write(&mut document.scene, forward);
        }
        if let Some(swap) = &self.root_maps {
            swap.write(&mut document.root_maps, forward);
        }
        Ok(())
    }
}

/// One undoable step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Command {
    /// An edit recorded as a diff.
    Edit { label: String, diff: DocumentDiff },
    /// Several commands as one step: applied in order, reverted in reverse.
    Group {
        label: String,
        children: Vec<Command>,
    },
}

impl Command {
    /// Records the change from `before` to `after`; `None` when nothing changed.
    pub fn record(label: impl Into<String>, before: &Document, after: &Document) -> Option<Self> {
        let diff = DocumentDiff::between(before, after);
        (!diff.is_empty()).then(|| Self::Edit {
            label: label.into(),
            diff,
        })
    }

    pub fn label(&self) -> &str {
        match self {
            Self::Edit { label, .. } | Self::Group { label, .. } => label,
        }
    }

    pub fn apply(&self, document: &mut Document) -> Result<(), HistoryMismatch> {
        match self {
            Self::Edit { diff, .. } => diff.write(document, true),
            Self::Group { children, .. } => {
                for (i, child) in children.iter().enumerate() {
                    if let Err(error) = child.apply(document) {
                        // Roll back the children already applied: all or nothing.
                        for done in children[..i].iter().rev() {
                            let _ = done.revert(document);
                        }
                        return Err(error);
                    }
                }
                Ok(())
            }
        }
    }

    pub fn revert(&self, document: &mut Document) -> Result<(), HistoryMismatch> {
        match self {
            Self::Edit { diff, .. } => diff.write(document, false),
            Self::Group { children, .. } => {
                for (i, child) in children.iter().enumerate().rev() {
                    if let Err(error) = child.revert(document) {
                        for done in children[i + 1..].iter() {
                            let _ = done.apply(document);
                        }
                        return Err(error);
                    }
                }
                Ok(())
            }
        }
    }
}

/// One step undone or redone: its label, and what it asks of the hair asset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Step {
    pub label: String,
    pub kind: ChangeKind,
}

impl Step {
    fn of(command: &Command) -> Self {
        Self {
            label: command.label().to_string(),
            kind: command.change_kind(),
        }
    }
}

/// The undo and redo stacks. Saved in project files.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct History {
    /// Oldest first; the last entry is undone first.
    pub undo: Vec<Command>,
    /// The last entry is redone first.
    pub redo: Vec<Command>,
    /// Most undo steps kept; older ones are dropped.
    pub limit: usize,
}

impl Default for History {
    fn default() -> Self {
        Self::with_limit(DEFAULT_HISTORY_LIMIT)
    }
}

impl History {
    pub fn with_limit(limit: usize) -> Self {
        Self {
            undo: Vec::new(),
            redo: Vec::new(),
            limit: limit.max(1),
        }
    }

    /// Records an already-applied edit (the document is now `after`). Clears redo.
    pub fn push(&mut self, command: Command) {
        self.redo.clear();
        self.undo.push(command);
        if self.undo.len() > self.limit {
            let excess = self.undo.len() - self.limit;
            self.undo.drain(..excess);
        }
    }

    /// Replaces `document` with `after` as one undoable step named `label`. Returns false
    /// when nothing changed (no history entry is made).
    pub fn commit(&mut self, document: &mut Document, label: &str, after: Document) -> bool {
        match Command::record(label, document, &after) {
            Some(command) => {
                *document = after;
                self.push(command);
                true
            }
            None => false,
        }
    }

    /// Undoes the last step; `Ok(None)` when there is nothing to undo.
    pub fn undo(&mut self, document: &mut Document) -> Result<Option<Step>, HistoryMismatch> {
        let Some(command) = self.undo.pop() else {
            return Ok(None);
        };
        if let Err(error) = command.revert(document) {
            self.undo.push(command);
            return Err(error);
        }
        let step = Step::of(&command);
        self.redo.push(command);
        Ok(Some(step))
    }

    /// Redoes the last undone step; `Ok(None)` when there is nothing to redo.
    pub fn redo(&mut self, document: &mut Document) -> Result<Option<Step>, HistoryMismatch> {
        let Some(command) = self.redo.pop() else {
            return Ok(None);
        };
        if let Err(error) = command.apply(document) {
            self.redo.push(command);
            return Err(error);
        }
        let step = Step::of(&command);
        self.undo.push(command);
        Ok(Some(step))
    }

    /// Undoes or redoes until `undo.len() == position` (the history panel's "jump here");
    /// returns what the steps taken ask of the hair asset together.
    pub fn jump_to(
        &mut self,
        document: &mut Document,
        position: usize,
    ) -> Result<ChangeKind, HistoryMismatch> {
        let mut kind = ChangeKind::Scene;
        while self.undo.len() > position {
            if let Some(step) = self.undo(document)? {
                kind = kind.and(step.kind);
            }
        }
        while self.undo.len() < position && !self.redo.is_empty() {
            if let Some(step) = self.redo(document)? {
                kind = kind.and(step.kind);
            }
        }
        Ok(kind)
    }

    /// Checks that the whole history replays on `document`: undoing every step and redoing
    /// them gives valid documents and ends where it began. Used when loading a project.
    pub fn verify(&self, document: &Document) -> Result<(), HistoryMismatch> {
        let mut scratch = document.clone();
        let mut copy = self.clone();
        let steps = copy.undo.len();
        let redo_steps = copy.redo.len();
        let check = |doc: &Document, what: &str| {
            doc.validate().map_err(|e| HistoryMismatch {
                path: format!("history ({what}): document.{}", e.path),
                message: e.message,
            })
        };
        for i in 0..redo_steps {
            copy.redo(&mut scratch)
                .map_err(|e| prefix(e, &format!("history.redo[{}]", redo_steps - 1 - i)))?;
            check(&scratch, "after redo")?;
        }
        for i in 0..steps + redo_steps {
            let index = steps + redo_steps - 1 - i;
            copy.undo(&mut scratch)
                .map_err(|e| prefix(e, &format!("history step {index}")))?;
            check(&scratch, "after undo")?;
        }
        for _ in 0..steps {
            copy.redo(&mut scratch)
                .map_err(|e| prefix(e, "history (redo)"))?;
        }
        if &scratch != document {
            return Err(HistoryMismatch {
                path: "history".into(),
                message: "undoing and redoing the history does not return to the saved document"
                    .into(),
            });
        }
        Ok(())
    }
}

fn prefix(error: HistoryMismatch, what: &str) -> HistoryMismatch {
    HistoryMismatch {
        path: format!("{what}: document.{}", error.path),
        message: error.message,
    }
}

/// A drag or other multi-step gesture that becomes one undo step, with the kind of change it
/// makes (what the hair asset redoes while it runs).
#[derive(Clone, Debug)]
pub struct Transaction {
    start: Document,
    label: String,
    kind: ChangeKind,
}

impl Transaction {
    /// Starts a transaction on the current document that makes changes of `kind`.
    pub fn begin(document: &Document, label: impl Into<String>, kind: ChangeKind) -> Self {
        Self {
            start: document.clone(),
            label: label.into(),
            kind,
        }
    }

    /// The document as it was when the transaction began (to preview edits from it).
    pub fn start(&self) -> &Document {
        &self.start
    }

    pub fn label(&self) -> &str {
        &self.label
    }

    /// The kind of change the gesture makes.
    pub fn kind(&self) -> ChangeKind {
        self.kind
    }

    /// The gesture goes on with a change of `kind` too.
    pub fn widen(&mut self, kind: ChangeKind) {
        self.kind = self.kind.and(kind);
    }

    /// Ends the gesture: one history entry, or none if the document is unchanged.
    pub fn commit(self, history: &mut History, document: &Document) -> bool {
        match Command::record(self.label, &self.start, document) {
            Some(command) => {
                // The kind said while the gesture ran decided what the asset redid: the
                // history's own diff must not ask for more.
                debug_assert!(
                    command.change_kind() <= self.kind,
                    "{}: declared {:?}, its diff is {:?}",
                    command.label(),
                    self.kind,
                    command.change_kind()
                );
                history.push(command);
                true
            }
            None => false,
        }
    }

    /// Abandons the gesture and restores the document.
    pub fn cancel(self, document: &mut Document) {
        *document = self.start;
    }
}

#[cfg(test)]
mod root_maps_tests {
    use super::*;
    use crate::model::root_maps::{RootMapChannel, RootMaps};

    fn document() -> Document {
        Document::new("grid", crate::model::mesh::test_meshes::grid(2, 2, 1, 0.1))
    }

    /// The command recording `before` → `after`, and what it keeps of the painted maps.
    fn recorded_maps_change(
        label: &str,
        before: &Document,
        after: &Document,
    ) -> (Command, RootMapsChange) {
        let command = Command::record(label, before, after).expect("a change");
        let Command::Edit { diff, .. } = &command else {
            panic!("an edit");
        };
        let change = diff.root_maps.as_deref().expect("the maps changed").clone();
        (command, change)
    }

    /// A stroke keeps only the texels it changed; the first stroke (maps made) and clearing
    /// the last map keep both whole; undo and redo go through each exactly; a damaged entry
    /// is a named mismatch, never a panic.
    #[test]
    fn a_stroke_keeps_only_the_texels_it_changed() {
        let mut document = document();
        let mut history = History::default();
        // The first stroke: the maps come into being, whole.
        let mut first = document.clone();
        first.root_maps = RootMaps::blank(256, 256).expect("maps");
        first.root_maps.texels_mut()[10][0] = 0;
        let (_, change) = recorded_maps_change("Paint density", &document, &first);
        assert!(matches!(change, RootMapsChange::Whole(_)));
        history.commit(&mut document, "Paint density", first.clone());
        // The next stroke: 100 texels of 65,536.
        let mut second = document.clone();
        for texel in &mut second.root_maps.texels_mut()[1000..1100] {
            texel[1] = 128;
        }
        let (command, change) = recorded_maps_change("Paint length", &document, &second);
        let RootMapsChange::Texels { changes, .. } = &change else {
            panic!("texels, not whole maps");
        };
        assert_eq!(changes.len(), 100);
        let stored = serde_json::to_vec(&command).expect("json");
        assert!(
            stored.len() < 10_000,
            "{} bytes for 100 texels",
            stored.len()
        );
        history.commit(&mut document, "Paint length", second.clone());
        // Clearing every map: whole again (the maps go).
        let mut cleared = document.clone();
        cleared.root_maps.clear_channel(RootMapChannel::Density);
        cleared.root_maps.clear_channel(RootMapChannel::Length);
        assert!(cleared.root_maps.is_empty());
        history.commit(&mut document, "Clear", cleared.clone());
        history.verify(&document).expect("a consistent history");
        history.undo(&mut document).expect("undo");
        assert_eq!(document.root_maps, second.root_maps);
        history.undo(&mut document).expect("undo");
        assert_eq!(document.root_maps, first.root_maps);
        history.redo(&mut document).expect("redo");
        assert_eq!(document.root_maps, second.root_maps);
        // A damaged entry: a texel past the maps, or one holding another value.
        for damage in [u32::MAX, 1000] {
            let mut entry =
                RootMapsChange::between(&first.root_maps, &second.root_maps).expect("a change");
            let RootMapsChange::Texels { changes, .. } = &mut entry else {
                panic!("texels");
            };
            changes[0].index = damage;
            if damage == 1000 {
                changes[0].before = [1, 2, 3, 4];
            }
            let error = entry
                .check(&first.root_maps, true, "root_maps")
                .expect_err("damaged");
            assert!(error.message.contains("texel"), "{error}");
        }
        // Maps of another size than the entry's.
        let entry = RootMapsChange::between(&first.root_maps, &second.root_maps).expect("a change");
        let other = RootMaps::blank(8, 8).expect("maps");
        let error = entry.check(&other, true, "root_maps").expect_err("size");
        assert!(error.message.contains("8 × 8"), "{error}");
    }

    #[test]
    fn colour_strokes_keep_only_their_texels_and_undo() {
        let mut document = document();
        let mut history = History::default();
        let mut first = document.clone();
        first.root_maps = RootMaps::blank(64, 64).expect("maps");
        first.root_maps.texels_mut()[3][0] = 0;
        history.commit(&mut document, "Paint density", first.clone());
        // The colour map's first stroke: whole (the map appears).
        let mut second = document.clone();
        second.root_maps.colour_texels_mut()[10] = [200, 40, 10, 255];
        let (_, change) = recorded_maps_change("Paint colour", &document, &second);
        assert!(matches!(change, RootMapsChange::Whole(_)));
        history.commit(&mut document, "Paint colour", second.clone());
        // The next: only its texels, indexed after the grey maps' 4096.
        let mut third = document.clone();
        third.root_maps.colour_texels_mut()[11] = [10, 40, 200, 128];
        let (_, change) = recorded_maps_change("Paint colour", &document, &third);
        let RootMapsChange::Texels { changes, .. } = &change else {
            panic!("texels");
        };
        assert_eq!(
            changes.iter().map(|c| c.index).collect::<Vec<_>>(),
            vec![4096 + 11]
        );
        history.commit(&mut document, "Paint colour", third.clone());
        history.verify(&document).expect("a consistent history");
        history.undo(&mut document).expect("undo");
        assert_eq!(document.root_maps, second.root_maps);
        history.undo(&mut document).expect("undo");
        assert_eq!(document.root_maps, first.root_maps);
        history.redo(&mut document).expect("redo");
        history.redo(&mut document).expect("redo");
        assert_eq!(document.root_maps, third.root_maps);
    }
}
