//! Project files (`*.hairloom`): the document and its undo history as readable JSON.
//!
//! - Versioned: `format_version` is read first; a file from a newer Hairloom is refused with
//!   a message saying so, before anything else is parsed.
//! - Validated: type errors name the JSON path (`document.hair_mesh.columns[3].w[1]`);
//!   structural problems (index ranges, layer counts, non-finite numbers) are found by
//!   [`Document::validate`]; the history must replay on the document ([`History::verify`]).
//! - Written atomically: the bytes go to a temporary file in the same folder, which is
//!   flushed to disk and renamed over the target, so a crash mid-save leaves the previous file
//!   intact ([`write_atomic`]).
//! - Compact but readable: objects are indented one key per line; arrays of numbers stay on
//!   one line ([`ProjectFormatter`]).

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::model::document::Document;
use crate::model::history::History;

/// The project file format this build writes and the newest it reads.
///
/// History: 1, the document and its history; 2, the document gains its scene (lights,
/// material, effects). A version-1 file loads with the default scene and is written back as
/// version 2 ([`from_bytes`] migrates it).
pub const FORMAT_VERSION: u32 = 2;
/// File extension of project files.
pub const EXTENSION: &str = "hairloom";

/// The contents of a project file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Project {
    pub format_version: u32,
    pub document: Document,
    #[serde(default)]
    pub history: History,
}

impl Project {
    pub fn new(document: Document) -> Self {
        Self {
            format_version: FORMAT_VERSION,
            document,
            history: History::default(),
        }
    }
}

/// Why a project could not be loaded or saved. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum ProjectError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: cannot write: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Not a regular file, or above [`MAX_PROJECT_BYTES`].
    #[error("{0}")]
    Input(crate::io::input_files::InputFileError),
    #[error("{path}: not a Hairloom project: {message}")]
    NotAProject { path: PathBuf, message: String },
    #[error(
        "{path}: written by a newer Hairloom (format version {found}; this build reads up to {supported}); update Hairloom to open it"
    )]
    NewerVersion {
        path: PathBuf,
        found: u64,
        supported: u32,
    },
    #[error("{path}: at {json_path}: {message}")]
    Invalid {
        path: PathBuf,
        json_path: String,
        message: String,
    },
}

/// Serialises a project to the bytes of a project file.
pub fn to_bytes(project: &Project) -> Vec<u8> {
    let mut bytes = Vec::new();
    let mut serializer =
        serde_json::Serializer::with_formatter(&mut bytes, ProjectFormatter::default());
    // Serialising plain data into memory cannot fail: every map key is a string and
    // non-finite floats are written as null (and refused again by validation on load).
    if project.serialize(&mut serializer).is_err() {
        bytes.clear();
    }
    bytes.push(b'\n');
    bytes
}

/// Parses and validates project bytes; `path` is only used in messages.
pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Project, ProjectError> {
    let not_a_project = |message: String| ProjectError::NotAProject {
        path: path.to_path_buf(),
        message,
    };
    // Read only the version first so a newer file is refused with the right message even
    // when its structure has changed.
    #[derive(Deserialize)]
    struct VersionOnly {
        format_version: Option<serde_json::Value>,
    }
    let version: VersionOnly =
        serde_json::from_slice(bytes).map_err(|e| not_a_project(e.to_string()))?;
    let Some(version) = version.format_version else {
        return Err(not_a_project("missing \"format_version\"".into()));
    };
    let Some(version) = version.as_u64() else {
        return Err(ProjectError::Invalid {
            path: path.to_path_buf(),
            json_path: "format_version".into(),
            message: format!("expected a whole number, found {version}"),
        });
    };
    if version > FORMAT_VERSION as u64 {
        return Err(ProjectError::NewerVersion {
            path: path.to_path_buf(),
            found: version,
            supported: FORMAT_VERSION,
        });
    }
    if version == 0 {
        return Err(ProjectError::Invalid {
            path: path.to_path_buf(),
            json_path: "format_version".into(),
            message: "version 0 does not exist".into(),
        });
    }
    let deserializer = &mut serde_json::Deserializer::from_slice(bytes);
    let mut project: Project =
        serde_path_to_error::deserialize(deserializer).map_err(|e| ProjectError::Invalid {
            path: path.to_path_buf(),
            json_path: e.path().to_string(),
            message: e.inner().to_string(),
        })?;
    // Migration: version 1 had no scene, and serde gave the document the default one; from
    // here on the project is the current version and saves as such.
    project.format_version = FORMAT_VERSION;
    project
        .document
        .validate()
        .map_err(|e| ProjectError::Invalid {
            path: path.to_path_buf(),
            json_path: format!("document.{}", e.path),
            message: e.message,
        })?;
    if project.history.limit == 0 {
        return Err(ProjectError::Invalid {
            path: path.to_path_buf(),
            json_path: "history.limit".into(),
            message: "the history limit must be at least 1".into(),
        });
    }
    let history = &project.history;
    if history.limit > MAX_HISTORY_ENTRIES {
        return Err(ProjectError::Invalid {
            path: path.to_path_buf(),
            json_path: "history.limit".into(),
            message: format!(
                "{} is above the cap of {MAX_HISTORY_ENTRIES} entries",
                history.limit
            ),
        });
    }
    let entries = history.undo.len() + history.redo.len();
    if entries > MAX_HISTORY_ENTRIES {
        return Err(ProjectError::Invalid {
            path: path.to_path_buf(),
            json_path: "history".into(),
            message: format!(
                "{entries} undo and redo entries are above the cap of {MAX_HISTORY_ENTRIES}"
            ),
        });
    }
    project
        .history
        .verify(&project.document)
        .map_err(|e| ProjectError::Invalid {
            path: path.to_path_buf(),
            json_path: e.path,
            message: e.message,
        })?;
    Ok(project)
}

/// The largest project file read (the head samples are about 1 MB).
pub const MAX_PROJECT_BYTES: u64 = 1 << 30;

/// The most history entries (and the largest history limit) a project file may hold, so
/// verifying the history on load stays bounded (20,000 entries took 5 s).
pub const MAX_HISTORY_ENTRIES: usize = 10_000;

/// Loads and validates a project file (a regular file of at most [`MAX_PROJECT_BYTES`]).
pub fn load(path: &Path) -> Result<Project, ProjectError> {
    use crate::io::input_files::{InputFileError, read_regular_file};
    let bytes =
        read_regular_file(path, MAX_PROJECT_BYTES, "a project file").map_err(
            |error| match error {
                InputFileError::Io { source, .. } => ProjectError::Read {
                    path: path.to_path_buf(),
                    source,
                },
                other => ProjectError::Input(other),
            },
        )?;
    from_bytes(&bytes, path)
}

/// Saves a project atomically (see [`write_atomic`]).
pub fn save(path: &Path, project: &Project) -> Result<(), ProjectError> {
    write_atomic(path, &to_bytes(project), |_| {}).map_err(|source| ProjectError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Bytes written between calls of the `after_chunk` hook of [`write_atomic`].
pub const WRITE_CHUNK_BYTES: usize = 64 * 1024;

/// Writes `bytes` to `path` so that `path` always holds either its old or its new content:
/// a temporary file next to it (same folder, so the rename cannot cross file systems) is
/// written, flushed with `fsync`, and renamed over `path`; then the folder is synced so the
/// rename itself is durable. On error the temporary file is removed.
///
/// The temporary is `.NAME.tmp-PID-RANDOM`, created exclusively (`O_EXCL`, by `tempfile`):
/// a file or link planted under a guessable name cannot be followed or overwritten.
/// Temporaries of the same target left by a writer that was killed (its process is gone)
/// are removed first.
///
/// Permissions (Unix): a new file gets `0666` less the process's umask, as any program's
/// new file does; a file written over keeps its permission bits and, where the writer may
/// set it, its group — so a project shared with a group stays shared after a save.
///
/// `after_chunk(bytes_written_so_far)` runs after every [`WRITE_CHUNK_BYTES`]; tests use it
/// to crash a writer halfway.
pub fn write_atomic(
    path: &Path,
    bytes: &[u8],
    mut after_chunk: impl FnMut(usize),
) -> std::io::Result<()> {
    let folder = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let file_name = path.file_name().ok_or_else(|| {
        std::io::Error::new(std::io::ErrorKind::InvalidInput, "the path names no file")
    })?;
    let file_name = file_name.to_string_lossy();
    remove_dead_writers_temporaries(&folder, |target| target == file_name);
    let mut temp = new_temporary(&folder, &file_name, path)?;
    let mut written = 0;
    for chunk in bytes.chunks(WRITE_CHUNK_BYTES) {
        temp.write_all(chunk)?;
        written += chunk.len();
        after_chunk(written);
    }
    temp.as_file().sync_all()?;
    // On failure `persist` hands the temporary back, and dropping it removes the file.
    temp.persist(path).map_err(|e| e.error)?;
    // Make the rename durable. Opening a folder for sync is not possible everywhere
    // (Windows); the file content is already durable, so failure here is not fatal.
    if let Ok(dir) = std::fs::File::open(&folder) {
        let _ = dir.sync_all();
    }
    Ok(())
}

/// The temporary [`write_atomic`] writes `target` (called `file_name`, in `folder`) through,
/// with the permissions the finished file must have.
fn new_temporary(
    folder: &Path,
    file_name: &str,
    target: &Path,
) -> std::io::Result<tempfile::NamedTempFile> {
    let prefix = format!("{}{}-", temp_prefix(file_name), std::process::id());
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        // Passed to open(2), which applies the umask: what a new file of any program gets.
        // (`tempfile`'s own default is 0600, which locked collaborators out of every file.)
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let temp = builder.tempfile_in(folder)?;
    #[cfg(unix)]
    if let Some(old) = std::fs::metadata(target)
        .ok()
        .filter(std::fs::Metadata::is_file)
    {
        use std::os::unix::fs::{MetadataExt as _, PermissionsExt as _};
        // The permission bits only: set-id bits are not carried onto a rewritten file.
        let mode = old.permissions().mode() & 0o777;
        temp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(mode))?;
        // Only the owner or root may change the group, and only to one of theirs; where
        // that is refused the file keeps the writer's group, as a new file would.
        let _ = std::os::unix::fs::fchown(temp.as_file(), None, Some(old.gid()));
    }
    #[cfg(not(unix))]
    let _ = target;
    Ok(temp)
}

/// Start of the names of [`write_atomic`]'s temporaries for a file called `file_name`.
pub(crate) fn temp_prefix(file_name: &str) -> String {
    format!(".{file_name}.tmp-")
}

/// Removes [`write_atomic`]'s temporaries in `folder` (`.TARGET.tmp-PID-…`, and the older
/// `.TARGET.tmp-PID`) whose `TARGET` passes `is_target` and whose writing process no longer
/// runs. Where liveness cannot be told (no `/proc`), only temporaries older than a day are
/// removed. Failures are ignored: this is housekeeping.
pub(crate) fn remove_dead_writers_temporaries(folder: &Path, is_target: impl Fn(&str) -> bool) {
    let Ok(entries) = std::fs::read_dir(folder) else {
        return;
    };
    let own_pid = std::process::id();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some((target, rest)) = name
            .to_str()
            .and_then(|n| n.strip_prefix('.'))
            .and_then(|n| n.rsplit_once(".tmp-"))
        else {
            continue;
        };
        if !is_target(target) {
            continue;
        }
        let Ok(pid) = rest.split('-').next().unwrap_or_default().parse::<u32>() else {
            continue;
        };
        // Never touch anything but plain files and links (a link is removed, not followed).
        let Ok(metadata) = entry.path().symlink_metadata() else {
            continue;
        };
        if metadata.is_dir() || pid == own_pid {
            continue;
        }
        let stale = match process_is_alive(pid) {
            Some(alive) => !alive,
            None => metadata
                .modified()
                .ok()
                .and_then(|m| m.elapsed().ok())
                .is_some_and(|age| age.as_secs() > 24 * 3600),
        };
        if stale {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Whether process `pid` runs, where the system can say (`/proc` on Linux).
fn process_is_alive(pid: u32) -> Option<bool> {
    let proc = Path::new("/proc");
    if cfg!(target_os = "linux") && proc.join("self").exists() {
        Some(proc.join(pid.to_string()).exists())
    } else {
        None
    }
}

/// A JSON formatter that indents objects and keeps arrays of scalars (and arrays of such
/// arrays, like positions) on one line. An array becomes multi-line only when it contains
/// an object, which keeps files diffable while about three times smaller than fully
/// pretty-printed JSON.
#[derive(Default)]
pub struct ProjectFormatter {
    /// One entry per open container: `true` for an object or a multi-line array.
    stack: Vec<Frame>,
    indent: usize,
}

#[derive(Clone, Copy)]
struct Frame {
    is_object: bool,
    multiline: bool,
    has_value: bool,
}

impl ProjectFormatter {
    fn newline<W: ?Sized + Write>(&self, writer: &mut W) -> std::io::Result<()> {
        writer.write_all(b"\n")?;
        for _ in 0..self.indent {
            writer.write_all(b"  ")?;
        }
        Ok(())
    }
}

impl serde_json::ser::Formatter for ProjectFormatter {
    fn begin_array<W: ?Sized + Write>(&mut self, writer: &mut W) -> std::io::Result<()> {
        self.stack.push(Frame {
            is_object: false,
            multiline: false,
            has_value: false,
        });
        writer.write_all(b"[")
    }

    fn end_array<W: ?Sized + Write>(&mut self, writer: &mut W) -> std::io::Result<()> {
        let frame = self.stack.pop();
        if let Some(frame) = frame
            && frame.multiline
        {
            self.indent -= 1;
            self.newline(writer)?;
        }
        writer.write_all(b"]")
    }

    fn begin_array_value<W: ?Sized + Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        if !first {
            writer.write_all(b",")?;
            if let Some(frame) = self.stack.last()
                && frame.multiline
            {
                self.newline(writer)?;
            }
        }
        Ok(())
    }

    fn end_array_value<W: ?Sized + Write>(&mut self, _writer: &mut W) -> std::io::Result<()> {
        if let Some(frame) = self.stack.last_mut() {
            frame.has_value = true;
        }
        Ok(())
    }

    fn begin_object<W: ?Sized + Write>(&mut self, writer: &mut W) -> std::io::Result<()> {
        // An object inside an array makes that array multi-line; the first element decides.
        if let Some(parent) = self.stack.last_mut()
            && !parent.is_object
            && !parent.multiline
            && !parent.has_value
        {
            parent.multiline = true;
            self.indent += 1;
            self.newline(writer)?;
        }
        self.stack.push(Frame {
            is_object: true,
            multiline: true,
            has_value: false,
        });
        self.indent += 1;
        writer.write_all(b"{")
    }

    fn end_object<W: ?Sized + Write>(&mut self, writer: &mut W) -> std::io::Result<()> {
        let frame = self.stack.pop();
        self.indent -= 1;
        if frame.is_some_and(|f| f.has_value) {
            self.newline(writer)?;
        }
        writer.write_all(b"}")
    }

    fn begin_object_key<W: ?Sized + Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        if !first {
            writer.write_all(b",")?;
        }
        self.newline(writer)
    }

    fn begin_object_value<W: ?Sized + Write>(&mut self, writer: &mut W) -> std::io::Result<()> {
        writer.write_all(b": ")
    }

    fn end_object_value<W: ?Sized + Write>(&mut self, _writer: &mut W) -> std::io::Result<()> {
        if let Some(frame) = self.stack.last_mut() {
            frame.has_value = true;
        }
        Ok(())
    }
}
