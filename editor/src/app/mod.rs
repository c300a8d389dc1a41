//! The interactive editor (eframe on wgpu): a 3D viewport with live GPU strands, a styling
//! panel, a history panel, menus and a status bar. `state` is the model; panels follow the
//! egui demo pattern `fn ui(&mut self, ui, state)`.

pub mod history_panel;
pub mod state;
pub mod styling_panel;
pub mod tools_panel;
pub mod viewport;

pub use state::EditorState;

use history_panel::HistoryPanel;
use styling_panel::StylingPanel;
use tools_panel::ToolsPanel;
use viewport::Viewport;

pub struct HairloomApp {
    pub state: EditorState,
    pub styling: StylingPanel,
    pub history: HistoryPanel,
    pub tools: ToolsPanel,
    pub viewport: Viewport,
    title: String,
}

impl HairloomApp {
    pub fn new(cc: &eframe::CreationContext<'_>, state: EditorState) -> Self {
        Self {
            viewport: Viewport::new(cc.wgpu_render_state.as_ref()),
            state,
            styling: StylingPanel::default(),
            history: HistoryPanel,
            tools: ToolsPanel::default(),
            title: String::new(),
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
            let _ = self.state.save();
        }
        // Single-key tools only when no text field has the keyboard.
        if !ui.ctx().egui_wants_keyboard_input()
            && ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::E))
        {
            self.tools.extrude(&mut self.state);
        }
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Save").clicked() {
                    let _ = self.state.save();
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
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
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
