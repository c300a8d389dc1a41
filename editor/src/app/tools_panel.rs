//! Tools and outliner: the bundle list (click selects, ctrl/shift-click adds), selection
//! helpers, and the topology tools on the selection — extrude (E), insert and delete a layer,
//! remove / restore, subdivide. Each tool is one undo step; errors go to the status bar.

use hairloom_core::edit::{self, ExtrudeDirection};

use super::state::EditorState;

pub struct ToolsPanel {
    /// Extrusion distance along the top layer's normals (model units).
    pub extrude_distance_m: f64,
    /// Layer index for insert (a new layer below it) and delete.
    pub layer: u32,
}

impl Default for ToolsPanel {
    fn default() -> Self {
        Self {
            extrude_distance_m: 0.02,
            layer: 1,
        }
    }
}

impl ToolsPanel {
    pub fn extrude(&self, state: &mut EditorState) {
        let distance = self.extrude_distance_m;
        state.edit_mesh("Extrude", |mesh, bundles| {
            edit::extrude(mesh, bundles, ExtrudeDirection::AlongNormal { distance })
        });
    }

    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        ui.heading("Tools");
        ui.horizontal(|ui| {
            if ui.button("Extrude").on_hover_text("E").clicked() {
                self.extrude(state);
            }
            let label = ui.label("by");
            ui.add(
                egui::DragValue::new(&mut self.extrude_distance_m)
                    .speed(0.001)
                    .range(-1.0..=1.0)
                    .suffix(" m"),
            )
            .labelled_by(label.id);
        });
        ui.horizontal(|ui| {
            let layer = self.layer;
            if ui.button("Insert layer").clicked() {
                state.edit_mesh("Insert layer", |mesh, bundles| {
                    edit::insert_layer(mesh, bundles, layer)
                });
            }
            if ui.button("Delete layer").clicked() {
                state.edit_mesh("Delete layer", |mesh, bundles| {
                    edit::delete_layer(mesh, bundles, layer)
                });
            }
            let label = ui.label("layer");
            ui.add(egui::DragValue::new(&mut self.layer).range(0..=64))
                .labelled_by(label.id);
        });
        ui.horizontal(|ui| {
            if ui.button("Remove").clicked() {
                state.edit_mesh("Remove bundles", |mesh, bundles| {
                    edit::set_removed(mesh, bundles, true)
                });
            }
            if ui.button("Restore").clicked() {
                state.edit_mesh("Restore bundles", |mesh, bundles| {
                    edit::set_removed(mesh, bundles, false)
                });
            }
            if ui.button("Subdivide").clicked() {
                state.edit_mesh("Subdivide", edit::subdivide);
            }
        });
        ui.separator();
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
        egui::ScrollArea::vertical()
            .id_salt("outliner")
            .max_height(260.0)
            .show_rows(ui, row_height, count, |ui, rows| {
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
        state.selection.retain(|&b| (b as usize) < count);
    }
}
