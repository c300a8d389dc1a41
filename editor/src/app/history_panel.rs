//! History panel: every command of the project's history, oldest first; clicking one undoes
//! or redoes to just after it ("Original" goes back to the start). Redo entries are greyed.

use super::state::EditorState;

#[derive(Default)]
pub struct HistoryPanel {
    /// The step shown as current last frame: when it changes, the list scrolls to it.
    shown_step: Option<usize>,
}

impl HistoryPanel {
    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        ui.heading("History");
        let history = &state.project.history;
        let applied = history.undo.len();
        let labels: Vec<String> = history
            .undo
            .iter()
            .chain(history.redo.iter().rev())
            .map(|c| c.label().to_string())
            .collect();
        let mut jump = None;
        egui::ScrollArea::vertical().show(ui, |ui| {
            let scroll = self.shown_step != Some(applied);
            let original = ui.selectable_label(applied == 0, "Original");
            if original.clicked() {
                jump = Some(0);
            }
            if scroll && applied == 0 {
                original.scroll_to_me(None);
            }
            for (i, label) in labels.iter().enumerate() {
                let text = if i < applied {
                    egui::RichText::new(label)
                } else {
                    egui::RichText::new(label).weak()
                };
                let step = ui.selectable_label(applied == i + 1, text);
                if step.clicked() {
                    jump = Some(i + 1);
                }
                if scroll && applied == i + 1 {
                    step.scroll_to_me(None);
                }
            }
        });
        self.shown_step = Some(applied);
        if let Some(position) = jump.filter(|&p| p != applied) {
            state.jump_to(position);
        }
    }
}
