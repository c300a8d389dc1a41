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
        project::write_atomic(
            &self.project_path(),
            &project::to_bytes(&state.project),
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

    /// Loads the recovered work: unsaved (dirty), saving to where it came from.
    pub fn load(&self) -> Result<EditorState, String> {
        let path = self.project_path();
        let mut state = EditorState::open(&path).map_err(|e| e.to_string())?;
        state.path = self.pending().and_then(|p| p.origin);
        state.mark_unsaved(format!("recovered unsaved work from {}", path.display()));
        Ok(state)
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
}
