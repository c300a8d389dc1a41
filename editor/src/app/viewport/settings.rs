//! The Strands & accuracy panel: strand count, level of detail, and the accuracy switches
//! with their measured error and time (measured on a worker thread).

use super::*;

impl Viewport {
    /// Strand count, level of detail and the accuracy switches, each setting with its
    /// measured error and generation time beside it (measured on demand: it generates the
    /// whole document four times).
    pub fn settings_ui(&mut self, ui: &mut egui::Ui, state: &EditorState) {
        ui.heading("Strands");
        let settings = &mut self.settings;
        ui.add(
            egui::Slider::new(&mut settings.strands_per_bundle, 1..=MAX_STRANDS_PER_BUNDLE)
                .text("Strands per bundle"),
        );
        ui.checkbox(&mut settings.lod.enabled, "Level of detail");
        ui.add_enabled_ui(settings.lod.enabled, |ui| {
            ui.add(
                egui::Slider::new(&mut settings.lod.alpha_strands, 0.005..=0.5)
                    .logarithmic(true)
                    .text("Strand LOD alpha"),
            );
            ui.add(
                egui::Slider::new(&mut settings.lod.alpha_vertices, 0.005..=0.5)
                    .logarithmic(true)
                    .text("Vertex LOD alpha"),
            );
            ui.add(egui::Slider::new(&mut settings.lod.lambda, 0.0..=1.0).text("Morph lambda"));
        });
        ui.separator();
        ui.heading("Accuracy");
        let rows = match &self.accuracy {
            Some((revision, Ok(rows))) if *revision == state.revision => Some(rows.clone()),
            _ => None,
        };
        let row_for = |precision, filtering| {
            rows.as_ref().and_then(|rows| {
                rows.iter()
                    .find(|r| r.precision == precision && r.filtering == filtering)
                    .cloned()
            })
        };
        let size_m = state.document().hair_mesh.size().max(1e-9);
        egui::Grid::new("accuracy switches")
            .num_columns(4)
            .striped(true)
            .show(ui, |ui| {
                ui.label("Textures / filtering");
                ui.label("max error");
                ui.label("mean error");
                ui.label("generation");
                ui.end_row();
                for precision in [Precision::F32, Precision::F16] {
                    for filtering in [Filtering::Exact, Filtering::Hardware8Bit] {
                        let name = format!(
                            "{} / {}",
                            match precision {
                                Precision::F32 => "f32",
                                Precision::F16 => "f16",
                            },
                            match filtering {
                                Filtering::Exact => "exact",
                                Filtering::Hardware8Bit => "hardware",
                            }
                        );
                        let chosen = self.settings.precision == precision
                            && self.settings.filtering == filtering;
                        if ui.selectable_label(chosen, name).clicked() {
                            self.settings.precision = precision;
                            self.settings.filtering = filtering;
                        }
                        match row_for(precision, filtering) {
                            Some(AccuracyRow {
                                unavailable: Some(why),
                                ..
                            }) => {
                                ui.label("not on this GPU").on_hover_text(why);
                                ui.label("-");
                                ui.label("-");
                            }
                            Some(row) => {
                                ui.label(format!(
                                    "{:.3} mm ({:.2e} × size)",
                                    row.max_error_m * 1e3,
                                    row.max_error_m / size_m
                                ));
                                ui.label(format!("{:.4} mm", row.mean_error_m * 1e3));
                                ui.label(if row.timed_on_gpu {
                                    format!(
                                        "{:.2} ms GPU, {:.1} ms wall",
                                        row.generation_ms, row.wall_ms
                                    )
                                } else {
                                    format!("{:.1} ms wall", row.wall_ms)
                                });
                            }
                            None => {
                                ui.label("-");
                                ui.label("-");
                                ui.label("-");
                            }
                        }
                        ui.end_row();
                    }
                }
            });
        // A finished measurement lands here (the worker never touches the panel).
        if let Some((revision, receiver)) = &self.measuring {
            match receiver.try_recv() {
                Ok(result) => {
                    self.accuracy = Some((*revision, result));
                    self.measuring = None;
                }
                Err(std::sync::mpsc::TryRecvError::Empty) => {
                    ui.ctx()
                        .request_repaint_after(std::time::Duration::from_millis(50));
                }
                Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                    self.accuracy = Some((*revision, Err("the measurement stopped".into())));
                    self.measuring = None;
                }
            }
        }
        ui.horizontal(|ui| {
            let measure = ui
                .add_enabled(
                    self.gpu.is_some() && self.measuring.is_none(),
                    egui::Button::new("Measure"),
                )
                .on_hover_text(
                    "Generates every strand of the document (full detail, 17 vertices) with \
                     each setting on this GPU, on a worker thread; errors against f32 / exact",
                );
            if measure.clicked()
                && let Some((context, generator)) = self.gpu_handles()
            {
                let (sender, receiver) = std::sync::mpsc::channel();
                let document = state.document().clone();
                let strands_per_bundle = self.settings.strands_per_bundle;
                let ctx = ui.ctx().clone();
                std::thread::spawn(move || {
                    let result =
                        measure_accuracy(&context, &generator, &document, strands_per_bundle, 17)
                            .map_err(|e| format!("{e:#}"));
                    let _ = sender.send(result);
                    ctx.request_repaint();
                });
                self.measuring = Some((state.revision, receiver));
            }
            if self.measuring.is_some() {
                ui.spinner();
                ui.weak("measuring…");
                return;
            }
            match &self.accuracy {
                Some((_, Err(error))) => {
                    ui.colored_label(ui.visuals().error_fg_color, error);
                }
                Some((revision, Ok(_))) if *revision != state.revision => {
                    ui.weak("the document changed since the last measurement");
                }
                None => {
                    ui.weak("not measured yet");
                }
                _ => {
                    ui.weak(format!("on {}", self.adapter));
                }
            }
        });
    }
}
