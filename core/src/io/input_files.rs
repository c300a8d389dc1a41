//! Reading input files under the resource policy (`docs/resource-policy.md`).
//!
//! A file that names other files (a `.gltf` naming its buffers, a runtime bundle manifest
//! naming its textures and body) may only name **regular files inside its own folder**:
//! no absolute path, no URI scheme other than `data:` (handled by the caller), no `..`
//! step, no link that leads outside the folder, no FIFO, device or folder. Every read has a
//! byte cap, checked on the open file (so a file that grows, or a `/proc` file that reports
//! size 0, still stops at the cap).
//!
//! Refusals name the offending reference and the rule, but never reveal anything about a
//! file outside the folder (not even whether it exists).

use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// Why an input file was not read.
#[derive(Debug, thiserror::Error)]
pub enum InputFileError {
    #[error("\"{name}\" is refused: {reason}; only files inside {folder} are read")]
    Refused {
        name: String,
        folder: String,
        reason: &'static str,
    },
    #[error("{path}: not a regular file ({kind}); only regular files are read")]
    NotRegular { path: String, kind: &'static str },
    #[error("{path}: larger than the cap of {cap_bytes} bytes for {what}")]
    TooLarge {
        path: String,
        cap_bytes: u64,
        what: &'static str,
    },
    #[error("{path}: cannot read: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
}

/// The folder an input file lives in; the only place its references may lead.
#[derive(Clone, Debug)]
pub struct InputFolder {
    /// Canonical (links resolved) path, for the containment check.
    canonical: PathBuf,
    /// As the user gave it, for messages.
    shown: PathBuf,
}

impl InputFolder {
    /// The folder holding `file` (which need not exist yet).
    pub fn of_file(file: &Path) -> Result<Self, InputFileError> {
        let folder = match file.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent,
            _ => Path::new("."),
        };
        Self::new(folder)
    }

    pub fn new(folder: &Path) -> Result<Self, InputFileError> {
        let canonical = folder.canonicalize().map_err(|source| InputFileError::Io {
            path: folder.display().to_string(),
            source,
        })?;
        Ok(Self {
            canonical,
            shown: folder.to_path_buf(),
        })
    }

    pub fn path(&self) -> &Path {
        &self.shown
    }

    /// The file `name` (a relative reference with `/` separators) refers to, after
    /// checking the policy. Errors name `name`.
    pub fn resolve(&self, name: &str) -> Result<PathBuf, InputFileError> {
        let refuse = |reason| InputFileError::Refused {
            name: name.to_string(),
            folder: self.shown.display().to_string(),
            reason,
        };
        if name.is_empty() {
            return Err(refuse("an empty name"));
        }
        if name.contains('\0') {
            return Err(refuse("a NUL byte in the name"));
        }
        if name.starts_with('/') || name.starts_with('\\') {
            return Err(refuse("an absolute path"));
        }
        // A scheme (`file:`, `http:`) or a drive letter (`C:`) before the first separator.
        let head = name.split(['/', '\\']).next().unwrap_or_default();
        if head.contains(':') {
            return Err(refuse(
                "a URI scheme or drive; only relative names are read",
            ));
        }
        let mut path = self.canonical.clone();
        for part in name.split(['/', '\\']) {
            match part {
                "" | "." => {}
                ".." => return Err(refuse("a parent-folder (..) step")),
                part => path.push(part),
            }
        }
        // Belt and braces: the joined path must still be below the folder lexically.
        if path
            .components()
            .any(|c| matches!(c, Component::ParentDir | Component::Prefix(_)))
        {
            return Err(refuse("a parent-folder (..) step"));
        }
        let shown = self.shown.join(name).display().to_string();
        let canonical = path.canonicalize().map_err(|source| InputFileError::Io {
            path: shown,
            source,
        })?;
        if !canonical.starts_with(&self.canonical) {
            return Err(refuse("a link that leads outside the folder"));
        }
        Ok(canonical)
    }

    /// Reads the file `name` refers to (see [`Self::resolve`]), at most `cap_bytes`.
    pub fn read(
        &self,
        name: &str,
        cap_bytes: u64,
        what: &'static str,
    ) -> Result<Vec<u8>, InputFileError> {
        let path = self.resolve(name)?;
        read_regular_file_as(&path, &self.shown.join(name), cap_bytes, what)
    }
}

/// Reads a regular file of at most `cap_bytes` (the file the user named: no folder rule).
/// A FIFO cannot block the open, and the cap holds while reading (a `/proc` file that
/// reports size 0, or a file that grows, stops there).
pub fn read_regular_file(
    path: &Path,
    cap_bytes: u64,
    what: &'static str,
) -> Result<Vec<u8>, InputFileError> {
    read_regular_file_as(path, path, cap_bytes, what)
}

/// Checks that `path` is a regular file of at most `cap_bytes` without reading it (for a
/// file a library then reads itself, such as a USD stage).
pub fn check_regular_file(
    path: &Path,
    cap_bytes: u64,
    what: &'static str,
) -> Result<(), InputFileError> {
    open_regular(path, path, cap_bytes, what).map(|_| ())
}

/// Opens `path` and checks, on the open file, that it is a regular file under the cap (so a
/// swap between a check and the open cannot slip a FIFO or device in).
fn open_regular(
    path: &Path,
    shown: &Path,
    cap_bytes: u64,
    what: &'static str,
) -> Result<(std::fs::File, u64), InputFileError> {
    let shown_text = || shown.display().to_string();
    let io = |source| InputFileError::Io {
        path: shown_text(),
        source,
    };
    let file = open_without_blocking(path).map_err(io)?;
    let metadata = file.metadata().map_err(io)?;
    let file_type = metadata.file_type();
    if !file_type.is_file() {
        return Err(InputFileError::NotRegular {
            path: shown_text(),
            kind: describe_file_type(&file_type),
        });
    }
    if metadata.len() > cap_bytes {
        return Err(InputFileError::TooLarge {
            path: shown_text(),
            cap_bytes,
            what,
        });
    }
    Ok((file, metadata.len()))
}

fn read_regular_file_as(
    path: &Path,
    shown: &Path,
    cap_bytes: u64,
    what: &'static str,
) -> Result<Vec<u8>, InputFileError> {
    let (file, len) = open_regular(path, shown, cap_bytes, what)?;
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(cap_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|source| InputFileError::Io {
            path: shown.display().to_string(),
            source,
        })?;
    if bytes.len() as u64 > cap_bytes {
        return Err(InputFileError::TooLarge {
            path: shown.display().to_string(),
            cap_bytes,
            what,
        });
    }
    Ok(bytes)
}

/// Opens for reading without blocking on a FIFO (which would otherwise wait forever for a
/// writer) and without following a link in the last component.
#[cfg(unix)]
fn open_without_blocking(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

#[cfg(not(unix))]
fn open_without_blocking(path: &Path) -> std::io::Result<std::fs::File> {
    std::fs::File::open(path)
}

fn describe_file_type(file_type: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a FIFO";
        }
        if file_type.is_char_device() || file_type.is_block_device() {
            return "a device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    if file_type.is_dir() {
        "a folder"
    } else {
        "not a plain file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder_with_file() -> (tempfile::TempDir, InputFolder) {
        let dir = tempfile::tempdir().expect("temp dir");
        std::fs::create_dir(dir.path().join("inside")).expect("mkdir");
        std::fs::write(dir.path().join("inside/a.bin"), b"abc").expect("write");
        std::fs::write(dir.path().join("secret.bin"), b"secret").expect("write");
        let folder = InputFolder::new(&dir.path().join("inside")).expect("folder");
        (dir, folder)
    }

    #[test]
    fn reads_a_file_inside_and_refuses_every_way_out() {
        let (dir, folder) = folder_with_file();
        assert_eq!(folder.read("a.bin", 10, "a test").expect("inside"), b"abc");
        assert_eq!(
            folder.read("./a.bin", 10, "a test").expect("inside"),
            b"abc"
        );
        let outside = dir.path().join("secret.bin").display().to_string();
        for name in [
            "../secret.bin",
            "x/../../secret.bin",
            outside.as_str(),
            "file:///etc/passwd",
            "/proc/self/environ",
            "C:\\x",
            "",
        ] {
            let error = folder.read(name, 1 << 20, "a test").expect_err(name);
            assert!(
                matches!(error, InputFileError::Refused { .. }),
                "{name}: {error}"
            );
        }
    }

    #[cfg(unix)]
    #[test]
    fn refuses_links_out_fifos_devices_and_oversized_files() {
        let (dir, folder) = folder_with_file();
        let inside = dir.path().join("inside");
        std::os::unix::fs::symlink(dir.path().join("secret.bin"), inside.join("link.bin"))
            .expect("symlink");
        let error = folder
            .read("link.bin", 100, "a test")
            .expect_err("link out");
        assert!(error.to_string().contains("outside the folder"), "{error}");
        std::os::unix::fs::symlink("/dev/zero", inside.join("zero.bin")).expect("symlink");
        assert!(folder.read("zero.bin", 100, "a test").is_err());
        let error = read_regular_file(Path::new("/dev/zero"), 100, "a test").expect_err("dev");
        assert!(error.to_string().contains("a device"), "{error}");
        let fifo = inside.join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            // Would block forever without O_NONBLOCK.
            let error = folder.read("fifo", 100, "a test").expect_err("fifo");
            assert!(error.to_string().contains("FIFO"), "{error}");
        }
        let error = folder.read("a.bin", 2, "a test").expect_err("cap");
        assert!(error.to_string().contains("cap of 2 bytes"), "{error}");
    }
}
