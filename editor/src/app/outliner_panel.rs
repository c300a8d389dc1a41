//! Outliner: the bundle list (click selects, ctrl/shift-click adds or removes), All / None.

use super::state::EditorState;

#[derive(Default)]
pub struct OutlinerPanel;

impl OutlinerPanel {
    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        let count = state.document().hair_mesh.bundles.len();
        ui.horizontal(|ui| {
            ui.label(format!("Bundles ({} selected)", state.selection.len()));
            if ui.small_button("All").clicked() {
                state.selection = (0..count as u32).collect();
            }
            if ui.small_button("None").clicked() {
                state.selection.clear();
            }
        });
        let row_height = ui.text_style_height(&egui::TextStyle::Body) + 4.0;
        egui::ScrollArea::vertical().id_salt("outliner").show_rows(
            ui,
            row_height,
            count,
            |ui, rows| {
                for index in rows {
                    let bundle = &state.document().hair_mesh.bundles[index];
                    let text = format!(
                        "Bundle {index} · {} layers{}",
                        bundle.layers,
                        if bundle.removed { " · removed" } else { "" }
                    );
                    let selected = state.selection.contains(&(index as u32));
                    let response = ui.selectable_label(selected, text);
                    if response.clicked() {
                        let add = ui.input(|i| i.modifiers.command || i.modifiers.shift);
                        if !add {
                            state.selection.clear();
                        }
                        if selected && add {
                            state.selection.remove(&(index as u32));
                        } else {
                            state.selection.insert(index as u32);
                        }
                    }
                }
            },
        );
        // Drop selections the document no longer has (after undoing a subdivide, say).
        state.prune_selection();
    }
}
