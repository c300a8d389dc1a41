//! Outliner: the bundle list (click selects, ctrl/shift-click adds or removes), All / None.
//! A bundle picked elsewhere (the viewport) is scrolled into view.

use std::collections::BTreeSet;

use super::state::EditorState;

#[derive(Default)]
pub struct OutlinerPanel {
    /// The selection as the outliner last saw it (to notice bundles picked elsewhere).
    seen_selection: BTreeSet<u32>,
    /// Rows drawn last frame.
    visible_rows: std::ops::Range<usize>,
}

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
        let spacing = ui.spacing().item_spacing.y;
        let mut area = egui::ScrollArea::vertical().id_salt("outliner");
        // A bundle newly selected outside the rows in view: scroll to it.
        let newly = state
            .selection
            .difference(&self.seen_selection)
            .next()
            .map(|&b| b as usize);
        if let Some(row) = newly.filter(|row| !self.visible_rows.contains(row)) {
            area = area.vertical_scroll_offset(row as f32 * (row_height + spacing));
        }
        self.seen_selection = state.selection.clone();
        area.show_rows(ui, row_height, count, |ui, rows| {
            self.visible_rows = rows.clone();
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
        });
        // Drop selections the document no longer has (after undoing a subdivide, say).
        state.prune_selection();
        self.seen_selection = state.selection.clone();
    }
}
