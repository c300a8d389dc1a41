//! Autosave and crash recovery: while there are unsaved changes, the project (history
//! included) is written every [`AUTOSAVE_SECONDS`] to a recovery file, atomically; quitting
//! with unsaved changes keeps it. On the next start the editor offers to recover it. Saving
//! (or a clean quit with nothing unsaved, or Discard) removes it.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use hairloom_core::io::project;

use super::state::EditorState;

/// Seconds between autosaves while the document has unsaved changes.
pub const AUTOSAVE_SECONDS: f64 = 120.0;
/// Overrides the recovery folder (tests; several editors side by side).
pub const RECOVERY_DIR_ENV: &str = "HAIRLOOM_RECOVERY_DIR";

const PROJECT_FILE: &str = "recovery.hairloom";
/// The path the recovered work was last saved to (one line), if it had one.
const ORIGIN_FILE: &str = "recovery-origin.txt";

/// A recovery file found at start-up.
#[derive(Clone, Debug, PartialEq)]
pub struct PendingRecovery {
    pub modified: Option<SystemTime>,
    pub origin: Option<PathBuf>,
}

#[derive(Clone, Debug)]
pub struct Recovery {
    dir: PathBuf,
}

impl Recovery {
    pub fn in_dir(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// `$HAIRLOOM_RECOVERY_DIR`, else `$XDG_DATA_HOME/hairloom`, else
    /// `~/.local/share/hairloom`, else the temporary folder.
    pub fn default_location() -> Self {
        let env = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
        let dir = env(RECOVERY_DIR_ENV)
            .map(PathBuf::from)
            .or_else(|| env("XDG_DATA_HOME").map(|d| PathBuf::from(d).join("hairloom")))
            .or_else(|| env("HOME").map(|h| PathBuf::from(h).join(".local/share/hairloom")))
            .unwrap_or_else(|| std::env::temp_dir().join("hairloom"));
        Self { dir }
    }

    pub fn project_path(&self) -> PathBuf {
        self.dir.join(PROJECT_FILE)
    }

    fn origin_path(&self) -> PathBuf {
        self.dir.join(ORIGIN_FILE)
    }

    /// Writes the state's project (and where it came from) for recovery.
    pub fn write(&self, state: &EditorState) -> std::io::Result<()> {
        std::fs::create_dir_all(&self.dir)?;
        let origin = state
            .path
            .as_deref()
            .map(|p| p.display().to_string())
            .unwrap_or_default();
        project::write_atomic(&self.origin_path(), origin.as_bytes(), |_| {})?;
        // Never the document in the middle of an open gesture without its history step:
        // that file would not verify, and Recover would lose the work.
        project::write_atomic(
            &self.project_path(),
            &project::to_bytes(&state.consistent_project()),
            |_| {},
        )
    }

    /// The recovery file left by an earlier run, if any.
    pub fn pending(&self) -> Option<PendingRecovery> {
        let metadata = std::fs::metadata(self.project_path()).ok()?;
        let origin = std::fs::read_to_string(self.origin_path())
            .ok()
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .map(PathBuf::from);
        Some(PendingRecovery {
            modified: metadata.modified().ok(),
            origin,
        })
    }

    /// Loads the recovered work: unsaved (dirty), saving to where it came from. When the
    /// history does not verify (an autosave from an older build, a damaged file) but the
    /// document does, the document is recovered without its undo history and the message
    /// says so: Recover never throws away a valid document. The recovery file is kept
    /// until the work is saved.
    pub fn load(&self) -> Result<EditorState, String> {
        let path = self.project_path();
        let (mut state, message) = match EditorState::open(&path) {
            Ok(state) => (
                state,
                format!("recovered unsaved work from {}", path.display()),
            ),
            Err(full_error) => {
                let document_only =
                    Self::document_without_history(&path).map_err(|_| full_error.to_string())?;
                (
                    document_only,
                    format!(
                        "recovered the document from {}, but not its undo history ({full_error})",
                        path.display()
                    ),
                )
            }
        };
        state.path = self.pending().and_then(|p| p.origin);
        state.mark_unsaved(message);
        Ok(state)
    }

    /// The recovery file's document alone (its history dropped), if that is valid.
    fn document_without_history(path: &Path) -> Result<EditorState, String> {
        let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
        let mut value: serde_json::Value =
            serde_json::from_slice(&bytes).map_err(|e| e.to_string())?;
        let object = value.as_object_mut().ok_or("not a JSON object")?;
        object.remove("history");
        let bytes = serde_json::to_vec(&value).map_err(|e| e.to_string())?;
        let project = project::from_bytes(&bytes, path).map_err(|e| e.to_string())?;
        Ok(EditorState::from_project(project, None, String::new()))
    }

    /// Removes the recovery file (after a save, a clean quit, or Discard).
    pub fn discard(&self) {
        for path in [self.project_path(), self.origin_path()] {
            let _ = std::fs::remove_file(path);
        }
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn write_pending_load_and_discard() {
        let dir = tempfile::tempdir().expect("temp dir");
        let recovery = Recovery::in_dir(dir.path().join("nested"));
        assert!(recovery.pending().is_none());
        let mut state = EditorState::sample();
        state.edit("curl").styling.global.curl.radius_m = 0.003;
        state.commit_edit();
        recovery.write(&state).expect("autosave");
        let pending = recovery.pending().expect("pending");
        assert_eq!(pending.origin, None, "the sample has no file");
        let recovered = recovery.load().expect("load");
        assert_eq!(recovered.project, state.project, "history included");
        assert!(
            recovered.is_dirty(),
            "recovered work is unsaved until saved"
        );
        assert!(recovered.path.is_none());
        recovery.discard();
        assert!(recovery.pending().is_none());
    }

    /// Issue "The editor as artists use it", bug 1: an autosave during an open gesture
    /// (G held for minutes) was unloadable and Recover lost the work.
    #[test]
    fn an_autosave_during_an_open_gesture_recovers_it_whole() {
        let dir = tempfile::tempdir().expect("temp dir");
        let recovery = Recovery::in_dir(dir.path());
        let mut state = EditorState::sample();
        state.edit("curl").styling.global.curl.radius_m = 0.003;
        state.commit_edit();
        // The gesture is still open when the autosave runs.
        if let Some(p) = state.edit("Move").hair_mesh.columns[25]
            .positions
            .last_mut()
        {
            p.x += 0.01;
        }
        let during = state.document().clone();
        recovery.write(&state).expect("autosave");
        hairloom_core::io::project::load(&recovery.project_path())
            .expect("the autosave is a valid project (hairloom check accepts it)");
        let mut recovered = recovery.load().expect("recovers");
        assert_eq!(recovered.document(), &during, "the moved vertex survives");
        assert!(recovered.message.starts_with("recovered unsaved work"));
        // Undo takes back the gesture, then the curl, as two steps.
        recovered.undo();
        recovered.undo();
        assert_eq!(recovered.document(), EditorState::sample().document());
        // The live state's gesture is untouched by the autosave.
        state.cancel_edit();
        assert_eq!(state.document().styling.global.curl.radius_m, 0.003);
    }

    #[test]
    fn a_recovery_file_whose_history_is_damaged_still_recovers_its_document() {
        let dir = tempfile::tempdir().expect("temp dir");
        let recovery = Recovery::in_dir(dir.path());
        let mut state = EditorState::sample();
        state.edit("curl").styling.global.curl.radius_m = 0.003;
        state.commit_edit();
        recovery.write(&state).expect("autosave");
        // The old bug's file: the document moved on without its history step.
        let mut value: serde_json::Value =
            serde_json::from_slice(&std::fs::read(recovery.project_path()).expect("read"))
                .expect("json");
        value["document"]["styling"]["global"]["curl"]["radius_m"] = serde_json::json!(0.007);
        std::fs::write(
            recovery.project_path(),
            serde_json::to_vec(&value).expect("json"),
        )
        .expect("write");
        assert!(hairloom_core::io::project::load(&recovery.project_path()).is_err());
        let recovered = recovery.load().expect("the document is recovered");
        assert_eq!(recovered.document().styling.global.curl.radius_m, 0.007);
        assert!(recovered.is_dirty());
        assert!(
            recovered.message.contains("not its undo history"),
            "{}",
            recovered.message
        );
        assert!(!recovered.can_undo());
    }
}
