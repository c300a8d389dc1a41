//! What kind of change an edit made, worked out from the undo history's diff: what the hair
//! asset built from the document must redo. A curl tick restyles (the styling buffers are
//! rewritten), a vertex drag reshapes (the textures are rewritten in place), an extrude
//! rebuilds (the asset is made afresh); a light or a name changes no hair at all.
//!
//! The kinds are ordered: two changes in a row need what the larger of them needs
//! ([`ChangeKind::and`]).

use crate::model::history::{Command, DocumentDiff, VecDiff};
use crate::model::mesh::{Bundle, Column};

/// What a change of the document asks of its hair asset, smallest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ChangeKind {
    /// The hair asset is unchanged: the scene (lights, material, effects, motion), the
    /// name, the source or the locked vertices; frames read these every frame.
    Scene,
    /// Only styling (parameters or group assignments) or the painted maps: the styling
    /// buffers and the maps texture.
    Restyle,
    /// Positions moved (the hair mesh's vertices, w, uv, density, or the body) with the same
    /// bundles, layers and columns: the textures are rewritten in place where their layout
    /// allows.
    Reshape,
    /// Bundles or columns were added, removed or re-layered: the asset is made afresh.
    Rebuild,
}

impl ChangeKind {
    /// What two changes in a row ask for.
    pub fn and(self, other: ChangeKind) -> ChangeKind {
        self.max(other)
    }

    /// The kind of a bundle change: `None` when nothing the hair depends on changed.
    fn of_bundles(diff: &VecDiff<Bundle>) -> Option<ChangeKind> {
        if diff.len_before != diff.len_after {
            return Some(ChangeKind::Rebuild);
        }
        diff.changes
            .iter()
            .map(|change| match (&change.before, &change.after) {
                (Some(before), Some(after))
                    if before.vertices == after.vertices
                        && before.layers == after.layers
                        && before.removed == after.removed =>
                {
                    // Only uv or density: the same atlas, new texels.
                    ChangeKind::Reshape
                }
                _ => ChangeKind::Rebuild,
            })
            .max()
    }

    /// The kind of a column change: moved vertices reshape, new layers rebuild.
    fn of_columns(diff: &VecDiff<Column>) -> Option<ChangeKind> {
        if diff.len_before != diff.len_after {
            return Some(ChangeKind::Rebuild);
        }
        diff.changes
            .iter()
            .map(|change| match (&change.before, &change.after) {
                (Some(before), Some(after)) if before.positions.len() == after.positions.len() => {
                    ChangeKind::Reshape
                }
                _ => ChangeKind::Rebuild,
            })
            .max()
    }
}

impl DocumentDiff {
    /// What this diff asks of the hair asset (undone or redone alike: a swap's kind is the
    /// same both ways).
    pub fn change_kind(&self) -> ChangeKind {
        let mut kind = ChangeKind::Scene;
        // Painted maps are read per strand like styling: the maps texture is rewritten.
        if self.styling.is_some() || self.root_maps.is_some() {
            kind = kind.and(ChangeKind::Restyle);
        }
        if self.w_mode.is_some() || self.body.is_some() {
            kind = kind.and(ChangeKind::Reshape);
        }
        for part in [
            ChangeKind::of_bundles(&self.bundles),
            ChangeKind::of_columns(&self.columns),
        ]
        .into_iter()
        .flatten()
        {
            kind = kind.and(part);
        }
        kind
    }
}

impl Command {
    /// What applying or reverting this command asks of the hair asset.
    pub fn change_kind(&self) -> ChangeKind {
        match self {
            Command::Edit { diff, .. } => diff.change_kind(),
            Command::Group { children, .. } => children
                .iter()
                .map(Command::change_kind)
                .max()
                .unwrap_or(ChangeKind::Scene),
        }
    }
}

/// The kinds of the changes since a revision: each document revision with the kind of the
/// change that made it, so a consumer that last saw revision `r` asks what it must redo
/// ([`ChangeLog::since`]). Bounded: the oldest entries go, and a revision older than what is
/// kept asks for a rebuild.
#[derive(Clone, Debug)]
pub struct ChangeLog {
    /// `(revision, kind)`, revisions increasing.
    entries: std::collections::VecDeque<(u64, ChangeKind)>,
    /// Revisions at or before this are not in the log.
    starting_at: u64,
}

/// Changes a [`ChangeLog`] keeps.
const CHANGE_LOG_ENTRIES: usize = 4096;

impl ChangeLog {
    /// A log of the changes after revision `revision` (the document as first shown).
    pub fn starting_at(revision: u64) -> Self {
        Self {
            entries: Default::default(),
            starting_at: revision,
        }
    }

    /// The change of `kind` that made revision `revision` (greater than any logged).
    pub fn record(&mut self, revision: u64, kind: ChangeKind) {
        debug_assert!(self.entries.back().is_none_or(|(r, _)| *r < revision));
        if self.entries.len() == CHANGE_LOG_ENTRIES
            && let Some((dropped, _)) = self.entries.pop_front()
        {
            self.starting_at = dropped;
        }
        self.entries.push_back((revision, kind));
    }

    /// What a consumer that last saw revision `revision` must redo: `None` when nothing
    /// changed since, [`ChangeKind::Rebuild`] when the revision is older than the log.
    pub fn since(&self, revision: u64) -> Option<ChangeKind> {
        if revision < self.starting_at {
            return Some(ChangeKind::Rebuild);
        }
        self.entries
            .iter()
            .rev()
            .take_while(|(r, _)| *r > revision)
            .map(|(_, kind)| *kind)
            .max()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::document::Document;
    use crate::samples::{grid_scalp, straight_layers};
    use glam::DVec3;

    /// Nine bundles of three layers.
    fn document() -> Document {
        let scalp = grid_scalp(3, 3, |x, y| DVec3::new(x, y, 0.0));
        Document::new("grid", straight_layers(scalp, 3, DVec3::Z * 0.01))
    }

    fn kind(edit: impl FnOnce(&mut Document)) -> ChangeKind {
        let before = document();
        let mut after = before.clone();
        edit(&mut after);
        DocumentDiff::between(&before, &after).change_kind()
    }

    #[test]
    fn each_edit_has_the_kind_its_asset_needs() {
        assert_eq!(kind(|d| d.scene.background = [0.5; 3]), ChangeKind::Scene);
        assert_eq!(kind(|d| d.name = "renamed".into()), ChangeKind::Scene);
        assert_eq!(
            kind(|d| d.styling.global.curl.radius_m += 0.001),
            ChangeKind::Restyle
        );
        assert_eq!(
            kind(|d| d.hair_mesh.columns[3].positions[1].x += 0.01),
            ChangeKind::Reshape
        );
        assert_eq!(
            kind(|d| d.hair_mesh.bundles[0].density = 0.5),
            ChangeKind::Reshape
        );
        assert_eq!(
            kind(|d| d.hair_mesh.bundles[0].removed = true),
            ChangeKind::Rebuild
        );
        assert_eq!(
            kind(|d| {
                let column = &mut d.hair_mesh.columns[3];
                let tip = *column.positions.last().expect("a column has a root");
                column.positions.push(tip);
                column
                    .w
                    .push(*column.w.last().expect("a column has w") + 0.01);
            }),
            ChangeKind::Rebuild
        );
        // A curl tick with a drag in one command: the larger of the two.
        assert_eq!(
            kind(|d| {
                d.styling.global.curl.radius_m += 0.001;
                d.hair_mesh.columns[3].positions[1].x += 0.01;
            }),
            ChangeKind::Reshape
        );
    }

    #[test]
    fn a_group_asks_what_its_largest_child_asks() {
        let before = document();
        let mut restyled = before.clone();
        restyled.styling.global.twist.turns_per_m += 1.0;
        let mut removed = restyled.clone();
        removed.hair_mesh.bundles[1].removed = true;
        let group = Command::Group {
            label: "both".into(),
            children: vec![
                Command::record("restyle", &before, &restyled).expect("a restyle differs"),
                Command::record("remove", &restyled, &removed).expect("a removal differs"),
            ],
        };
        assert_eq!(group.change_kind(), ChangeKind::Rebuild);
    }

    #[test]
    fn the_log_says_what_changed_since_a_revision() {
        let mut log = ChangeLog::starting_at(10);
        assert_eq!(log.since(10), None);
        log.record(11, ChangeKind::Restyle);
        log.record(12, ChangeKind::Reshape);
        log.record(13, ChangeKind::Scene);
        assert_eq!(log.since(10), Some(ChangeKind::Reshape));
        assert_eq!(log.since(12), Some(ChangeKind::Scene));
        assert_eq!(log.since(13), None);
        // Older than the log: everything must be redone.
        assert_eq!(log.since(9), Some(ChangeKind::Rebuild));
        for revision in 14..14 + CHANGE_LOG_ENTRIES as u64 {
            log.record(revision, ChangeKind::Restyle);
        }
        assert_eq!(log.since(11), Some(ChangeKind::Rebuild));
        assert_eq!(
            log.since(13 + CHANGE_LOG_ENTRIES as u64 - 1),
            Some(ChangeKind::Restyle)
        );
    }
}
