//! The editor's file work: file dialogs behind [`FileDialogs`] (native ones through rfd; tests
//! script the answers), recent files, and exports run on a worker thread with a progress bar
//! and a Cancel button, so the editor stays responsive and never loses the document.

use std::collections::VecDeque;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc;

use hairloom_core::Document;
use hairloom_core::io::alembic::AlembicTarget;
use hairloom_core::runtime::textures::Precision;

use crate::files::{STRAND_EXTENSIONS, generate_strands, write_runtime_bundle, write_strand_file};

/// What a file dialog is asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileRequest {
    OpenProject,
    SaveProjectAs,
    ImportScalp,
    /// A groom made elsewhere (`.abc`, `.usd*`, `.hair`), fitted to a hair mesh.
    ImportGroom,
    /// A folder for the runtime bundle.
    ExportRuntime,
    /// A `.hair`, `.usda` or `.glb` file.
    ExportStrands,
}

impl FileRequest {
    pub fn title(self) -> &'static str {
        match self {
            Self::OpenProject => "Open project",
            Self::SaveProjectAs => "Save project as",
            Self::ImportScalp => "Import scalp (glTF / GLB)",
            Self::ImportGroom => "Import groom (Alembic, USD, .hair)",
            Self::ExportRuntime => "Export runtime bundle to folder",
            Self::ExportStrands => "Export strands (.hair, .usda, .glb, .abc)",
        }
    }

    /// `(filter name, extensions)`; empty for a folder.
    pub fn filters(self) -> &'static [(&'static str, &'static [&'static str])] {
        match self {
            Self::OpenProject | Self::SaveProjectAs => &[("Hairloom project", &["hairloom"])],
            Self::ImportScalp => &[("glTF scalp", &["glb", "gltf"])],
            Self::ImportGroom => &[(
                "Groom (Alembic, USD, Cem Yuksel .hair)",
                &["abc", "usda", "usdc", "usdz", "usd", "hair"],
            )],
            Self::ExportRuntime => &[],
            Self::ExportStrands => &[
                ("Cem Yuksel .hair", &["hair"]),
                ("USD (text)", &["usda"]),
                ("glTF lines", &["glb"]),
                ("Alembic groom", &["abc"]),
            ],
        }
    }

    pub fn is_save(self) -> bool {
        matches!(self, Self::SaveProjectAs | Self::ExportStrands)
    }
}

/// A dialog's answer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DialogAnswer {
    Chosen(PathBuf),
    Cancelled,
    /// No native dialog can be shown here; the editor asks for a typed path instead.
    Unavailable,
}

/// Shows file dialogs. The editor only talks to this trait, so tests answer for the user.
pub trait FileDialogs {
    fn ask(&mut self, request: FileRequest, suggested: Option<&Path>) -> DialogAnswer;
}

/// Native dialogs: the XDG desktop portal (libdbus loaded at run time) or zenity.
pub struct NativeDialogs;

impl NativeDialogs {
    /// Whether rfd has anything to show a dialog with: a session bus for the portal, or
    /// zenity on the `PATH`. Without either it would silently return "cancelled".
    fn available() -> bool {
        let has_bus = std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some_and(|v| !v.is_empty());
        let has_zenity = std::env::var_os("PATH").is_some_and(|paths| {
            std::env::split_paths(&paths).any(|dir| dir.join("zenity").is_file())
        });
        has_bus || has_zenity
    }
}

impl FileDialogs for NativeDialogs {
    fn ask(&mut self, request: FileRequest, suggested: Option<&Path>) -> DialogAnswer {
        if !Self::available() {
            return DialogAnswer::Unavailable;
        }
        let mut dialog = rfd::FileDialog::new().set_title(request.title());
        for (name, extensions) in request.filters() {
            dialog = dialog.add_filter(*name, extensions);
        }
        if let Some(path) = suggested {
            if let Some(dir) = path.parent().filter(|d| d.is_dir()) {
                dialog = dialog.set_directory(dir);
            }
            if let Some(name) = path.file_name() {
                dialog = dialog.set_file_name(name.to_string_lossy());
            }
        }
        let chosen = match request {
            FileRequest::ExportRuntime => dialog.pick_folder(),
            _ if request.is_save() => dialog.save_file(),
            _ => dialog.pick_file(),
        };
        chosen.map_or(DialogAnswer::Cancelled, DialogAnswer::Chosen)
    }
}

/// Answers from a script, in order (tests); records what was asked.
#[derive(Default)]
pub struct ScriptedDialogs {
    pub answers: VecDeque<DialogAnswer>,
    pub asked: Vec<FileRequest>,
}

impl ScriptedDialogs {
    pub fn new(answers: impl IntoIterator<Item = DialogAnswer>) -> Self {
        Self {
            answers: answers.into_iter().collect(),
            asked: Vec::new(),
        }
    }
}

impl FileDialogs for ScriptedDialogs {
    fn ask(&mut self, request: FileRequest, _suggested: Option<&Path>) -> DialogAnswer {
        self.asked.push(request);
        self.answers.pop_front().unwrap_or(DialogAnswer::Cancelled)
    }
}

/// The typed-path prompt shown where no native dialog is available.
pub struct PathPrompt {
    pub request: FileRequest,
    pub text: String,
    /// Whether the field has been given the keyboard (once, when the prompt opens: typing
    /// and Enter then work without a click into it).
    pub focused: bool,
}

/// Recently opened or saved projects, newest first, kept in a small text file.
pub struct RecentFiles {
    file: PathBuf,
    pub paths: Vec<PathBuf>,
}

impl RecentFiles {
    pub const MAX: usize = 8;

    /// Larger files are not read (eight paths take a few kilobytes).
    const MAX_FILE_BYTES: u64 = 64 * 1024;

    /// The list stored in `file` (empty when it does not exist or cannot be read; read as
    /// any input file is: regular files only, capped).
    pub fn load(file: PathBuf) -> Self {
        let paths = hairloom_core::io::input_files::read_regular_file(
            &file,
            Self::MAX_FILE_BYTES,
            "the recent files",
        )
        .map(|bytes| {
            let text = String::from_utf8_lossy(&bytes);
            text.lines()
                .filter(|l| !l.trim().is_empty())
                .map(PathBuf::from)
                .take(Self::MAX)
                .collect()
        })
        .unwrap_or_default();
        Self { file, paths }
    }

    /// Moves `path` to the front and stores the list (a failure to store is not an error
    /// worth interrupting the artist for: the list is a convenience).
    pub fn push(&mut self, path: &Path) {
        let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        self.paths.retain(|p| p != &path);
        self.paths.insert(0, path);
        self.paths.truncate(Self::MAX);
        let text: String = self
            .paths
            .iter()
            .map(|p| format!("{}\n", p.display()))
            .collect();
        if let Some(dir) = self.file.parent() {
            let _ = super::recovery::create_private_dir(dir);
        }
        let _ = hairloom_core::io::project::write_atomic(&self.file, text.as_bytes(), |_| {});
    }
}

/// What an export writes.
#[derive(Clone, Debug, PartialEq)]
pub enum ExportTarget {
    Runtime {
        dir: PathBuf,
        precision: Precision,
    },
    Strands {
        file: PathBuf,
        vertices_log2: u32,
        /// Axes and units of an `.abc`.
        alembic: AlembicTarget,
    },
}

/// Work on a worker thread with a progress fraction and a Cancel flag, so the editor stays
/// responsive (exports, groom imports).
pub struct WorkerJob<T> {
    /// Fraction done × 10⁶.
    progress: Arc<AtomicU32>,
    cancel: Arc<AtomicBool>,
    result: mpsc::Receiver<Result<T, String>>,
    /// What the job is, for "… stopped unexpectedly".
    what: &'static str,
}

/// The worker's side of a [`WorkerJob`]: report progress, see Cancel.
#[derive(Clone)]
pub struct JobProgress {
    progress: Arc<AtomicU32>,
    cancel: Arc<AtomicBool>,
}

impl JobProgress {
    /// Reports `fraction` (0 to 1) done; breaks once Cancel was pressed.
    pub fn report(&self, fraction: f64) -> ControlFlow<()> {
        self.progress
            .store((fraction.clamp(0.0, 1.0) * 1e6) as u32, Ordering::Relaxed);
        if self.cancel.load(Ordering::Relaxed) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

impl<T: Send + 'static> WorkerJob<T> {
    pub fn start(
        what: &'static str,
        work: impl FnOnce(&JobProgress) -> Result<T, String> + Send + 'static,
    ) -> Self {
        let progress = Arc::new(AtomicU32::new(0));
        let cancel = Arc::new(AtomicBool::new(false));
        let (sender, result) = mpsc::channel();
        let worker = JobProgress {
            progress: progress.clone(),
            cancel: cancel.clone(),
        };
        std::thread::spawn(move || {
            let outcome = work(&worker);
            worker.progress.store(1_000_000, Ordering::Relaxed);
            let _ = sender.send(outcome);
        });
        Self {
            progress,
            cancel,
            result,
            what,
        }
    }

    pub fn fraction(&self) -> f32 {
        self.progress.load(Ordering::Relaxed) as f32 / 1e6
    }

    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// The outcome once the worker is done (its result or the error's message).
    pub fn finished(&self) -> Option<Result<T, String>> {
        match self.result.try_recv() {
            Ok(outcome) => Some(outcome),
            Err(mpsc::TryRecvError::Empty) => None,
            Err(mpsc::TryRecvError::Disconnected) => {
                Some(Err(format!("the {} stopped unexpectedly", self.what)))
            }
        }
    }

    /// Blocks until the worker is done (tests, and quitting during a job).
    pub fn wait(&self) -> Result<T, String> {
        self.result
            .recv()
            .unwrap_or_else(|_| Err(format!("the {} stopped unexpectedly", self.what)))
    }
}

/// A modal with a heading, what is being worked on, a progress bar and Cancel (it keeps
/// repainting while shown). Returns whether Cancel was clicked.
pub fn progress_modal(ui: &mut egui::Ui, heading: &str, label: &str, fraction: f32) -> bool {
    let mut cancelled = false;
    egui::Modal::new(egui::Id::unique(heading)).show(ui.ctx(), |ui| {
        ui.heading(heading);
        ui.label(label);
        ui.add(
            egui::ProgressBar::new(fraction)
                .show_percentage()
                .desired_width(360.0),
        );
        cancelled = ui.button("Cancel").clicked();
    });
    ui.ctx().request_repaint();
    cancelled
}

/// An export running on a worker thread on a copy of the document.
pub struct ExportJob {
    pub target: ExportTarget,
    job: WorkerJob<String>,
}

impl ExportJob {
    pub fn start(document: Document, target: ExportTarget, strands_per_bundle: u32) -> Self {
        let work_target = target.clone();
        let job = WorkerJob::start("export", move |progress| match work_target {
            ExportTarget::Runtime { dir, precision } => write_runtime_bundle(
                &document,
                &dir,
                precision,
                strands_per_bundle,
                crate::files::export_vertices_log2(&document),
            )
            .map_err(|e| format!("{e:#}")),
            ExportTarget::Strands {
                file,
                vertices_log2,
                alembic,
            } => crate::files::check_strand_file(&file)
                .map_err(|e| format!("{e:#}"))
                .and_then(|()| {
                    generate_strands(&document, strands_per_bundle, vertices_log2, &mut |f| {
                        progress.report(f64::from(f))
                    })
                    .map_err(|e| format!("{e:#}"))?
                    .ok_or_else(|| "cancelled".to_string())
                })
                .and_then(|strands| {
                    write_strand_file(&strands, &document, &file, alembic)
                        .map_err(|e| format!("{e:#}"))
                }),
        });
        Self { target, job }
    }

    pub fn fraction(&self) -> f32 {
        self.job.fraction()
    }

    pub fn cancel(&self) {
        self.job.cancel();
    }

    /// The outcome once the worker is done (a summary or the error's message).
    pub fn finished(&self) -> Option<Result<String, String>> {
        self.job.finished()
    }

    /// Blocks until the worker is done (tests, and quitting during an export).
    pub fn wait(&self) -> Result<String, String> {
        self.job.wait()
    }
}

/// Whether `path` names a strand format (the dialog's filter is only a hint).
pub fn is_strand_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| STRAND_EXTENSIONS.contains(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_files_are_newest_first_unique_and_persist() {
        let dir = tempfile::tempdir().expect("temp dir");
        let store = dir.path().join("recent.txt");
        let mut recent = RecentFiles::load(store.clone());
        assert!(recent.paths.is_empty());
        for i in 0..10 {
            recent.push(&dir.path().join(format!("p{i}.hairloom")));
        }
        recent.push(&dir.path().join("p5.hairloom"));
        assert_eq!(recent.paths.len(), RecentFiles::MAX);
        assert!(recent.paths[0].ends_with("p5.hairloom"));
        assert_eq!(
            recent
                .paths
                .iter()
                .filter(|p| p.ends_with("p5.hairloom"))
                .count(),
            1
        );
        assert_eq!(RecentFiles::load(store).paths, recent.paths);
    }

    #[test]
    fn a_strand_export_can_be_cancelled_and_a_bad_target_is_named() {
        let document = super::super::EditorState::sample().document().clone();
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("strands.glb");
        let job = ExportJob::start(
            document.clone(),
            ExportTarget::Strands {
                file: file.clone(),
                vertices_log2: 5,
                alembic: AlembicTarget::default(),
            },
            // Big bundles: the first one is still generating when Cancel arrives.
            2048,
        );
        job.cancel();
        assert_eq!(job.wait(), Err("cancelled".into()));
        assert!(!file.exists(), "a cancelled export writes nothing");
        let bad = ExportJob::start(
            document,
            ExportTarget::Strands {
                file: dir.path().join("strands.obj"),
                vertices_log2: 5,
                alembic: AlembicTarget::default(),
            },
            4,
        );
        let error = bad.wait().expect_err("unknown format");
        assert!(error.contains("strands.obj"), "{error}");
    }
}
