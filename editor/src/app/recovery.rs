//! Autosave and crash recovery: while there are unsaved changes, the project (history
//! included) is written every [`AUTOSAVE_SECONDS`] to a recovery file, atomically; quitting
//! with unsaved changes keeps it. On the next start the editor offers to recover it. Saving
//! (or a clean quit with nothing unsaved, or Discard) removes it.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use hairloom_core::io::input_files::read_regular_file;
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

/// Caps on the small per-user files kept beside the recovery file: read under the same rules
/// as any input (regular files only, a FIFO cannot block, the cap holds while reading).
const MAX_ORIGIN_BYTES: u64 = 64 * 1024;

#[derive(Clone, Debug)]
pub struct Recovery {
    dir: PathBuf,
    /// A folder of this session only, when no folder of the user's could be used: removed
    /// when the editor closes (the last clone drops it).
    _session: Option<std::sync::Arc<tempfile::TempDir>>,
    /// Why the user's own folder is not used, for the status bar.
    note: Option<String>,
}

impl Recovery {
    pub fn in_dir(dir: impl Into<PathBuf>) -> Self {
        Self {
            dir: dir.into(),
            _session: None,
            note: None,
        }
    }

    /// `$HAIRLOOM_RECOVERY_DIR`, else `$XDG_DATA_HOME/hairloom`, else
    /// `~/.local/share/hairloom` (see [`Self::location_from`]).
    pub fn default_location() -> Self {
        Self::location_from(|name| std::env::var_os(name))
    }

    /// The recovery folder the environment `env` names. Never a folder shared by all users:
    /// with none of the variables set, or where the folder named belongs to another user
    /// (whose `recovery-origin.txt` would decide where Save writes), the editor keeps its
    /// autosaves, recent files and remembered views in a private folder of this session
    /// (mode 0700, removed on exit) and says so in [`Self::note`].
    pub fn location_from(env: impl Fn(&str) -> Option<std::ffi::OsString>) -> Self {
        let env = |name: &str| env(name).filter(|v| !v.is_empty());
        let dir = env(RECOVERY_DIR_ENV)
            .map(PathBuf::from)
            .or_else(|| env("XDG_DATA_HOME").map(|d| PathBuf::from(d).join("hairloom")))
            .or_else(|| env("HOME").map(|h| PathBuf::from(h).join(".local/share/hairloom")));
        let Some(dir) = dir else {
            return Self::for_this_session(format!(
                "neither HOME nor XDG_DATA_HOME is set (nor {RECOVERY_DIR_ENV})"
            ));
        };
        match not_ours(&dir) {
            None => Self::in_dir(dir),
            Some(problem) => Self::for_this_session(problem),
        }
    }

    /// A private folder of this session, and the note that says why.
    fn for_this_session(problem: String) -> Self {
        let mut builder = tempfile::Builder::new();
        builder.prefix("hairloom-session-");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt as _;
            builder.permissions(std::fs::Permissions::from_mode(0o700));
        }
        match builder.tempdir() {
            Ok(session) => Self {
                dir: session.path().to_path_buf(),
                note: Some(format!(
                    "{problem}: autosaves and recent files last only this session (in {})",
                    session.path().display()
                )),
                _session: Some(std::sync::Arc::new(session)),
            },
            // No private folder at all: a path that cannot exist, so every write fails
            // (and says so) and nothing is read.
            Err(error) => Self {
                dir: PathBuf::from("/nonexistent/hairloom-recovery"),
                note: Some(format!(
                    "{problem}, and no private folder could be made ({error}): autosave is off"
                )),
                _session: None,
            },
        }
    }

    /// Why autosaves do not go to the user's own folder this session, if they do not.
    pub fn note(&self) -> Option<&str> {
        self.note.as_deref()
    }

    pub fn project_path(&self) -> PathBuf {
        self.dir.join(PROJECT_FILE)
    }

    fn origin_path(&self) -> PathBuf {
        self.dir.join(ORIGIN_FILE)
    }

    /// Writes the state's project (and where it came from) for recovery. A folder made
    /// here is private to the user (0700).
    pub fn write(&self, state: &EditorState) -> std::io::Result<()> {
        create_private_dir(&self.dir)?;
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
        let origin = read_regular_file(&self.origin_path(), MAX_ORIGIN_BYTES, "a recovery note")
            .ok()
            .map(|bytes| String::from_utf8_lossy(&bytes).trim().to_string())
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
        let bytes = read_regular_file(path, project::MAX_PROJECT_BYTES, "a recovery file")
            .map_err(|e| e.to_string())?;
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

/// Why `dir` may not hold this user's recovery files: it exists and belongs to another user
/// (or is not a folder). `None` when it is missing (it is made private) or is ours.
fn not_ours(dir: &Path) -> Option<String> {
    let metadata = std::fs::metadata(dir).ok()?;
    if !metadata.is_dir() {
        return Some(format!("{} is not a folder", dir.display()));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        // This process's user is the owner of its own /proc entry (Linux); elsewhere the
        // check is skipped.
        if let Ok(me) = std::fs::metadata("/proc/self").map(|m| m.uid())
            && metadata.uid() != me
        {
            return Some(format!(
                "{} belongs to another user (uid {})",
                dir.display(),
                metadata.uid()
            ));
        }
    }
    None
}

/// Makes `dir` (and missing parents) with mode 0700 where the system has modes.
pub(crate) fn create_private_dir(dir: &Path) -> std::io::Result<()> {
    let mut builder = std::fs::DirBuilder::new();
    builder.recursive(true);
    #[cfg(unix)]
    std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
    builder.create(dir)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hairloom_core::model::change::ChangeKind;

    #[test]
    fn write_pending_load_and_discard() {
        let dir = tempfile::tempdir().expect("temp dir");
        let recovery = Recovery::in_dir(dir.path().join("nested"));
        assert!(recovery.pending().is_none());
        let mut state = EditorState::sample();
        state
            .edit(ChangeKind::Restyle, "curl")
            .styling
            .global
            .curl
            .radius_m = 0.003;
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
        state
            .edit(ChangeKind::Restyle, "curl")
            .styling
            .global
            .curl
            .radius_m = 0.003;
        state.commit_edit();
        // The gesture is still open when the autosave runs.
        if let Some(p) = state.edit(ChangeKind::Reshape, "Move").hair_mesh.columns[25]
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
        state
            .edit(ChangeKind::Restyle, "curl")
            .styling
            .global
            .curl
            .radius_m = 0.003;
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

    /// Issue "Nothing lost, nothing blocked": with neither HOME nor XDG_DATA_HOME the editor
    /// fell back to `/tmp/hairloom`, shared by every user, where another user's
    /// `recovery-origin.txt` decided where Save wrote.
    #[test]
    fn without_a_home_recovery_never_uses_a_folder_shared_by_all_users() {
        use std::os::unix::fs::{MetadataExt as _, PermissionsExt as _};
        let shared = std::env::temp_dir().join("hairloom");
        let recovery = Recovery::location_from(|_| None);
        assert_ne!(recovery.dir(), shared);
        assert!(!recovery.dir().starts_with(&shared));
        let note = recovery.note().expect("the status bar says why");
        assert!(note.contains("neither HOME nor XDG_DATA_HOME"), "{note}");
        let metadata = std::fs::metadata(recovery.dir()).expect("a session folder");
        assert_eq!(metadata.permissions().mode() & 0o777, 0o700);
        let me = std::fs::metadata("/proc/self").expect("/proc").uid();
        assert_eq!(metadata.uid(), me);
        // Another user's recovery files in the old shared place are never read.
        assert!(recovery.pending().is_none());
        let dir = recovery.dir().to_path_buf();
        drop(recovery);
        assert!(!dir.exists(), "the session folder goes with the editor");
    }

    #[test]
    fn a_recovery_folder_of_another_user_is_not_used() {
        let me = {
            use std::os::unix::fs::MetadataExt as _;
            std::fs::metadata("/proc/self").expect("/proc").uid()
        };
        let dir = tempfile::tempdir().expect("temp dir");
        let theirs = dir.path().join("theirs");
        std::fs::create_dir(&theirs).expect("folder");
        std::fs::write(theirs.join(ORIGIN_FILE), "/etc/passwd\n").expect("plant");
        std::fs::write(theirs.join(PROJECT_FILE), "{}").expect("plant");
        if std::os::unix::fs::chown(&theirs, Some(me + 1), None).is_err() {
            println!("skipped: only root can give a folder to another user here");
            return;
        }
        let recovery = Recovery::location_from(|name| {
            (name == RECOVERY_DIR_ENV).then(|| theirs.clone().into_os_string())
        });
        assert_ne!(recovery.dir(), theirs);
        assert!(recovery.pending().is_none());
        let note = recovery.note().expect("says why");
        assert!(note.contains("belongs to another user"), "{note}");
        // Our own folder (here: made fresh, 0700) is used as before.
        let ours = dir.path().join("ours");
        let recovery =
            Recovery::location_from(|name| (name == "HOME").then(|| ours.clone().into_os_string()));
        assert_eq!(recovery.dir(), ours.join(".local/share/hairloom"));
        assert!(recovery.note().is_none());
    }

    /// A FIFO where the recovery note should be cannot block the start.
    #[test]
    fn a_fifo_recovery_note_does_not_block() {
        let dir = tempfile::tempdir().expect("temp dir");
        let recovery = Recovery::in_dir(dir.path());
        recovery.write(&EditorState::sample()).expect("autosave");
        crate::app::test_support::make_fifo(&recovery.origin_path());
        let origin = crate::app::test_support::returns_promptly(move || {
            recovery.pending().map(|p| p.origin)
        });
        assert_eq!(origin, Some(None), "the FIFO is not read as an origin");
    }
}
