//! The interactive editor (eframe on wgpu): a 3D viewport with live GPU strands, a styling
//! panel, a history panel, menus and a status bar. `state` is the model; panels follow the
//! egui demo pattern `fn ui(&mut self, ui, state)`.

pub mod history_panel;
pub mod recovery;
pub mod state;
pub mod styling_panel;
pub mod tools_panel;
pub mod viewport;

pub use state::EditorState;

use history_panel::HistoryPanel;
use recovery::{AUTOSAVE_SECONDS, PendingRecovery, Recovery};
use styling_panel::StylingPanel;
use tools_panel::ToolsPanel;
use viewport::Viewport;

pub struct HairloomApp {
    pub state: EditorState,
    pub styling: StylingPanel,
    pub history: HistoryPanel,
    pub tools: ToolsPanel,
    pub viewport: Viewport,
    pub recovery: Recovery,
    /// A recovery file from an earlier run, offered until recovered or discarded.
    pub offer: Option<PendingRecovery>,
    /// Time (s) and document revision of the last autosave.
    autosaved: (f64, u64),
    title: String,
}

impl HairloomApp {
    pub fn new(cc: &eframe::CreationContext<'_>, state: EditorState) -> Self {
        Self::with_recovery(cc, state, Recovery::default_location())
    }

    /// The app with its autosaves in `recovery` (tests use a temporary folder).
    pub fn with_recovery(
        cc: &eframe::CreationContext<'_>,
        state: EditorState,
        recovery: Recovery,
    ) -> Self {
        Self {
            viewport: Viewport::new(cc.wgpu_render_state.as_ref()),
            offer: recovery.pending(),
            autosaved: (0.0, state.revision),
            recovery,
            state,
            styling: StylingPanel::default(),
            history: HistoryPanel,
            tools: ToolsPanel::default(),
            title: String::new(),
        }
    }

    /// Writes the recovery file when there is unsaved work newer than the last autosave.
    fn autosave(&mut self, now: f64) {
        if now - self.autosaved.0 < AUTOSAVE_SECONDS || self.offer.is_some() {
            return;
        }
        if self.state.is_dirty() && self.state.revision != self.autosaved.1 {
            match self.recovery.write(&self.state) {
                Ok(()) => self.state.message = "autosaved".into(),
                Err(error) => {
                    self.state.message = format!(
                        "autosave to {} failed: {error}",
                        self.recovery.dir().display()
                    )
                }
            }
        }
        self.autosaved = (now, self.state.revision);
    }

    /// The recovery offer, as a modal window.
    fn recovery_offer(&mut self, ui: &mut egui::Ui) {
        let Some(offer) = self.offer.clone() else {
            return;
        };
        let mut choice = None;
        egui::Modal::new(egui::Id::unique("hairloom recovery offer")).show(ui.ctx(), |ui| {
            ui.heading("Recover unsaved work?");
            let age = offer
                .modified
                .and_then(|m| m.elapsed().ok())
                .map_or("some time".into(), |d| format!("{} min", d.as_secs() / 60));
            ui.label(format!(
                "Hairloom did not close normally {age} ago. Its unsaved work{} was autosaved.",
                offer
                    .origin
                    .as_ref()
                    .map_or(String::new(), |p| format!(" on {}", p.display()))
            ));
            ui.horizontal(|ui| {
                if ui.button("Recover").clicked() {
                    choice = Some(true);
                }
                if ui.button("Discard").clicked() {
                    choice = Some(false);
                }
            });
        });
        match choice {
            Some(true) => match self.recovery.load() {
                Ok(state) => {
                    self.state = state;
                    self.offer = None;
                }
                Err(error) => {
                    self.state.message = format!("recovery failed: {error}");
                    self.offer = None;
                }
            },
            Some(false) => {
                self.recovery.discard();
                self.offer = None;
                self.state.message = "discarded the autosaved work".into();
            }
            None => {}
        }
    }

    fn shortcuts(&mut self, ui: &mut egui::Ui) {
        use egui::{Key, KeyboardShortcut, Modifiers};
        let redo_shift = KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
        let redo_y = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);
        let undo = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
        let save = KeyboardShortcut::new(Modifiers::COMMAND, Key::S);
        // The most specific shortcut first: Ctrl+Shift+Z would also match Ctrl+Z.
        if ui.input_mut(|i| i.consume_shortcut(&redo_shift) || i.consume_shortcut(&redo_y)) {
            self.state.redo();
        }
        if ui.input_mut(|i| i.consume_shortcut(&undo)) {
            self.state.undo();
        }
        if ui.input_mut(|i| i.consume_shortcut(&save)) {
            self.save();
        }
        // Single-key tools only when no text field has the keyboard.
        if !ui.ctx().egui_wants_keyboard_input()
            && ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::E))
        {
            self.tools.extrude(&mut self.state);
        }
    }

    /// Saves; a saved project needs no recovery file.
    pub fn save(&mut self) {
        if self.state.save().is_ok() {
            self.recovery.discard();
        }
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Save").clicked() {
                    self.save();
                    ui.close();
                }
            });
            ui.menu_button("Edit", |ui| {
                if ui
                    .add_enabled(self.state.can_undo(), egui::Button::new("Undo"))
                    .clicked()
                {
                    self.state.undo();
                    ui.close();
                }
                if ui
                    .add_enabled(self.state.can_redo(), egui::Button::new("Redo"))
                    .clicked()
                {
                    self.state.redo();
                    ui.close();
                }
            });
            ui.menu_button("View", |ui| {
                let settings = &mut self.viewport.settings;
                ui.checkbox(&mut settings.wireframe, "Hair-mesh wireframe");
                ui.checkbox(&mut settings.lod.enabled, "Level of detail");
                ui.add(
                    egui::Slider::new(&mut settings.strands_per_bundle, 1..=256)
                        .text("Strands per bundle"),
                );
                ui.horizontal(|ui| {
                    ui.label("Filtering");
                    ui.selectable_value(
                        &mut settings.filtering,
                        hairloom_core::runtime::Filtering::Exact,
                        "exact",
                    );
                    ui.selectable_value(
                        &mut settings.filtering,
                        hairloom_core::runtime::Filtering::Hardware8Bit,
                        "hardware",
                    );
                });
                ui.horizontal(|ui| {
                    ui.label("Textures");
                    ui.selectable_value(
                        &mut settings.precision,
                        hairloom_core::runtime::Precision::F32,
                        "f32",
                    );
                    ui.selectable_value(
                        &mut settings.precision,
                        hairloom_core::runtime::Precision::F16,
                        "f16",
                    );
                });
            });
        });
    }

    fn status_bar(&self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            ui.label(&self.state.message);
            ui.separator();
            ui.label(format!(
                "{} strands, {} vertices drawn",
                self.viewport.drawn_strands, self.viewport.drawn_vertices
            ));
            ui.separator();
            ui.label(format!(
                "fps {:.0}",
                1.0 / ui.input(|i| i.stable_dt).max(1e-3)
            ));
            ui.separator();
            ui.label(&self.viewport.adapter);
        });
    }
}

impl eframe::App for HairloomApp {
    fn on_exit(&mut self) {
        // Unsaved work survives a quit; nothing unsaved leaves no recovery file behind.
        if self.state.is_dirty() {
            let _ = self.recovery.write(&self.state);
        } else if self.offer.is_none() {
            self.recovery.discard();
        }
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.autosave(ui.input(|i| i.time));
        self.recovery_offer(ui);
        self.shortcuts(ui);
        let title = self.state.title();
        if title != self.title {
            ui.ctx()
                .send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        egui::Panel::left("tools")
            .default_size(240.0)
            .show(ui, |ui| {
                self.tools.ui(ui, &mut self.state);
                ui.separator();
                self.history.ui(ui, &mut self.state);
            });
        egui::Panel::right("styling")
            .default_size(320.0)
            .show(ui, |ui| self.styling.ui(ui, &mut self.state));
        egui::CentralPanel::no_frame().show(ui, |ui| self.viewport.ui(ui, &mut self.state));
    }
}
