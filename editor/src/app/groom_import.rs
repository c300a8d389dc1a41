//! File ▸ Import groom…: a groom made in another tool (Alembic, USD, `.hair`) becomes this
//! project's hair mesh and styling. The artist picks the scalp (the project's own, or one
//! built from the groom's roots); reading, fitting and measuring run on a worker with a
//! progress bar and Cancel; the result lands as one undo step, and the fit's error against
//! the input is reported (the same numbers `hairloom fit` prints).

use std::path::PathBuf;

use hairloom_core::Document;
use hairloom_core::fit::measure::{MeasureOptions, measure};
use hairloom_core::fit::{FitOptions, ScalpSource, fit};
use hairloom_core::io::groom_in::{GroomLimits, read_groom};

use super::files::WorkerJob;

/// Shares of the progress bar: reading, fitting, then measuring the result.
const READ_SHARE: f64 = 0.3;
const FIT_SHARE: f64 = 0.6;

/// A fitted groom: the document, and a one-line report of its error.
pub struct FittedGroom {
    /// Boxed: a document is large, and this travels through enums.
    pub document: Box<Document>,
    /// Strands per bundle that give the input's strand count (the viewport shows that many).
    pub strands_per_bundle: u32,
    pub summary: String,
}

/// The fit's own steps as one rising fraction (the columns take most of the time; a curly
/// groom fits its columns twice, so the bar goes back once).
fn fit_fraction(step: &str, fraction: f64) -> f64 {
    let (start, end) = match step {
        "scalp" => (0.0, 0.05),
        "roots" => (0.05, 0.1),
        "columns" => (0.1, 0.9),
        _ => (0.9, 1.0),
    };
    start + (end - start) * fraction.clamp(0.0, 1.0)
}

/// The scalp question, then the running fit.
pub enum GroomImport {
    /// The groom is chosen; which scalp to fit it on.
    Choosing {
        groom: PathBuf,
        use_project_scalp: bool,
    },
    Fitting {
        groom: PathBuf,
        job: WorkerJob<FittedGroom>,
    },
}

/// What the import's modal asks of the app.
pub enum GroomImportAction {
    /// Nothing yet.
    Waiting,
    /// The artist closed it (Cancel on the question).
    Closed,
    /// Fitting finished: the result, or the error's message ("cancelled" after Cancel).
    Done(Result<FittedGroom, String>),
}

impl GroomImport {
    pub fn choose(groom: PathBuf, project_has_scalp: bool) -> Self {
        Self::Choosing {
            groom,
            use_project_scalp: project_has_scalp,
        }
    }

    /// Reads, fits and measures `groom` on a worker.
    fn start(groom: PathBuf, scalp: ScalpSource) -> WorkerJob<FittedGroom> {
        WorkerJob::start("groom import", move |progress| {
            let started = std::time::Instant::now();
            let input = read_groom(&groom, GroomLimits::default(), &mut |f| {
                progress.report(READ_SHARE * f)
            })
            .map_err(|e| e.to_string())?;
            let name = groom
                .file_stem()
                .map_or_else(|| "groom".into(), |s| s.to_string_lossy().into_owned());
            let fitted = fit(
                &input,
                scalp,
                &name,
                &FitOptions::default(),
                &mut |step, f| progress.report(READ_SHARE + FIT_SHARE * fit_fraction(step, f)),
            )
            .map_err(|e| e.to_string())?;
            if progress.report(READ_SHARE + FIT_SHARE).is_break() {
                return Err("cancelled".into());
            }
            let report = measure(&input, &fitted, &MeasureOptions::default());
            let summary = format!(
                "groom {name}: {} curves fitted to {} bundles, error {:.2} % mean / {:.2} % p95 of its size, \
                 roots {:.2} %, strand length {:.1} % (in {:.1} s)",
                input.curve_count(),
                report.growing_bundles,
                100.0 * report.pooled.mean,
                100.0 * report.pooled.p95,
                100.0 * report.root_placement.max,
                100.0 * report.length_error,
                started.elapsed().as_secs_f64()
            );
            Ok(FittedGroom {
                strands_per_bundle: fitted.strands_per_bundle,
                document: Box::new(fitted.document),
                summary,
            })
        })
    }

    /// The modal: the scalp question, or the progress bar with Cancel. `project` is the
    /// open document (its scalp is offered when it has root faces).
    pub fn ui(&mut self, ui: &mut egui::Ui, project: &Document) -> GroomImportAction {
        let mut action = GroomImportAction::Waiting;
        let mut start = None;
        match self {
            Self::Choosing {
                groom,
                use_project_scalp,
            } => {
                let faces = project.hair_mesh.bundles.len();
                egui::Modal::new(egui::Id::unique("hairloom import groom")).show(ui.ctx(), |ui| {
                    ui.heading("Import groom");
                    ui.label(groom.display().to_string());
                    ui.label("Fit its strands on:");
                    ui.add_enabled(
                        faces > 0,
                        egui::RadioButton::new(
                            *use_project_scalp,
                            format!("this project's scalp ({faces} faces)"),
                        ),
                    )
                    .clicked()
                    .then(|| *use_project_scalp = true);
                    if ui
                        .radio(!*use_project_scalp, "a scalp built from the groom's roots")
                        .clicked()
                    {
                        *use_project_scalp = false;
                    }
                    ui.horizontal(|ui| {
                        if ui.button("Fit").clicked() {
                            let scalp = if *use_project_scalp && faces > 0 {
                                ScalpSource::Given {
                                    scalp: project.hair_mesh.clone(),
                                    body: project.body.clone(),
                                }
                            } else {
                                ScalpSource::FromRoots
                            };
                            start = Some((groom.clone(), scalp));
                        }
                        if ui.button("Cancel").clicked() {
                            action = GroomImportAction::Closed;
                        }
                    });
                });
            }
            Self::Fitting { groom, job } => match job.finished() {
                Some(outcome) => action = GroomImportAction::Done(outcome),
                None => {
                    let label = groom.display().to_string();
                    if super::files::progress_modal(ui, "Fitting groom", &label, job.fraction()) {
                        job.cancel();
                    }
                }
            },
        }
        if let Some((groom, scalp)) = start {
            let job = Self::start(groom.clone(), scalp);
            *self = Self::Fitting { groom, job };
            ui.ctx().request_repaint();
        }
        action
    }

    /// Cancels a running fit and waits for its worker to stop (quitting during an import:
    /// the import changes nothing until it lands, so nothing is lost).
    pub fn cancel_and_wait(&self) {
        if let Self::Fitting { job, .. } = self {
            job.cancel();
            let _ = job.wait();
        }
    }
}
