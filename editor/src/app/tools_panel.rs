//! Tools: the topology tools on the selection — extrude (E), insert and delete a layer,
//! remove / restore, subdivide, split / merge. Each tool is one undo step; errors go to the status bar.

use hairloom_core::edit::{self, ExtrudeDirection};
use hairloom_core::model::change::ChangeKind;

use super::gizmo::GizmoKind;
use super::state::{BrushSettings, DragTool, EditorState, SelectMode};
use hairloom_core::edit::BrushKind;
use hairloom_core::model::root_maps::RootMapChannel;

pub struct ToolsPanel {
    /// Extrusion distance along the top layer's normals (model units).
    pub extrude_distance_m: f64,
    /// Layer index for insert (a new layer below it), delete and select.
    pub layer: u32,
    /// The bundle whose shape Copy shape took (wisp copy / paste).
    pub copied_shape: Option<u32>,
    /// The strand density Set density gives the selected bundles.
    pub density: f64,
}

impl Default for ToolsPanel {
    fn default() -> Self {
        Self {
            extrude_distance_m: 0.02,
            layer: 1,
            copied_shape: None,
            density: 0.5,
        }
    }
}

/// The grooming brush's settings: which brush, its size and strength, X-mirror and
/// front-facing only.
fn brush_ui(ui: &mut egui::Ui, brush: &mut BrushSettings) {
    ui.horizontal_wrapped(|ui| {
        ui.label("Brush:");
        for kind in BrushKind::ALL {
            let chosen = brush.paint.is_none() && brush.kind == kind;
            let response = ui.selectable_label(chosen, kind.label());
            if response.clicked() {
                brush.kind = kind;
                brush.paint = None;
            }
            response.on_hover_text(match kind {
                BrushKind::Comb => "Drag hair along the stroke; lengths stay",
                BrushKind::Length => "Grow the hair under the brush (Ctrl: cut)",
                BrushKind::Puff => "Lift hair off the scalp (Ctrl: flatten)",
                BrushKind::Smooth => "Relax kinks along and across the hair",
                BrushKind::Clump => "Gather the hair under the brush (Ctrl: spread)",
                BrushKind::Part => {
                    "Part the hair along the stroke (a stroke along the centre: a middle part)"
                }
            });
        }
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("Paint map:");
        for channel in RootMapChannel::PAINTABLE {
            let response = ui.selectable_label(
                brush.paint == Some(channel),
                format!("{} map", channel.label()),
            );
            if response.clicked() {
                brush.paint = Some(channel);
            }
            response.on_hover_text(match channel {
                RootMapChannel::Density => {
                    "Paint where hair grows over the scalp: the share of strands that grow"
                }
                RootMapChannel::Length => "Paint the share of its length the hair keeps",
                RootMapChannel::Clump => {
                    "Paint how strongly the hair clumps (the Clump op's share)"
                }
                RootMapChannel::Colour => {
                    "Paint the hair's colour by its root: dyed streaks, grey, tips (Ctrl: the material's own)"
                }
            });
        }
    });
    // Label first, a short slider after: the Tools panel is narrow, and a slider's own text
    // (drawn after it) is the first thing cut off.
    let labelled_slider = |ui: &mut egui::Ui, name: &str, slider: egui::Slider| {
        ui.horizontal(|ui| {
            ui.spacing_mut().slider_width = 56.0;
            let label = ui.label(name);
            ui.add(slider).labelled_by(label.id);
        });
    };
    labelled_slider(
        ui,
        "Brush size",
        egui::Slider::new(&mut brush.radius_m, 0.002..=0.2)
            .logarithmic(true)
            .suffix(" m"),
    );
    labelled_slider(
        ui,
        "Strength",
        egui::Slider::new(&mut brush.strength, 0.0..=1.0),
    );
    if brush.paint == Some(RootMapChannel::Colour) {
        ui.horizontal(|ui| {
            let label = ui.label("Paint colour");
            ui.color_edit_button_srgb(&mut brush.paint_colour)
                .labelled_by(label.id)
                .on_hover_text("The colour a mass of the painted hair shows");
        });
        labelled_slider(
            ui,
            "Colour weight",
            egui::Slider::new(&mut brush.colour_weight, 0.0..=1.0),
        );
    } else if brush.paint.is_some() {
        labelled_slider(
            ui,
            "Paint value",
            egui::Slider::new(&mut brush.paint_value, 0.0..=1.0),
        );
    }
    ui.horizontal(|ui| {
        ui.checkbox(&mut brush.mirror_x, "X mirror")
            .on_hover_text("Stroke both sides of the head at once (across its centre, x)");
        ui.checkbox(&mut brush.front_only, "Front only")
            .on_hover_text("Leave the hair on the far side of the head alone");
    });
}

impl ToolsPanel {
    pub fn extrude(&self, state: &mut EditorState) {
        let distance = self.extrude_distance_m;
        state.edit_mesh("Extrude", |mesh, bundles| {
            edit::extrude(mesh, bundles, ExtrudeDirection::AlongNormal { distance })
        });
    }

    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        ui.heading("Select");
        ui.horizontal(|ui| {
            ui.selectable_value(&mut state.tool.mode, SelectMode::Bundles, "Bundles")
                .on_hover_text("Tab switches");
            ui.selectable_value(&mut state.tool.mode, SelectMode::Vertices, "Vertices")
                .on_hover_text("Tab switches");
        });
        // What a left drag does, on one line with no heading (the Tools pane is narrow and
        // full: a second line pushes its last buttons out of view); wrapped rather than cut
        // where the pane is narrower still.
        ui.horizontal_wrapped(|ui| {
            ui.spacing_mut().item_spacing.x = 4.0;
            ui.selectable_value(&mut state.tool.drag, DragTool::Box, "Box")
                .on_hover_text("A left drag selects in a box");
            ui.selectable_value(&mut state.tool.drag, DragTool::Lasso, "Lasso")
                .on_hover_text("A left drag selects in a lasso");
            ui.selectable_value(&mut state.tool.drag, DragTool::Paint, "Paint")
                .on_hover_text("A left drag paints the selection");
            ui.selectable_value(&mut state.tool.drag, DragTool::Groom, "Groom")
                .on_hover_text("A left drag strokes the hair with the grooming brush");
        });
        if state.tool.drag == DragTool::Paint {
            ui.add(
                egui::Slider::new(&mut state.tool.paint_radius_px, 4.0..=120.0)
                    .text("Brush radius")
                    .suffix(" px"),
            );
        }
        if state.tool.drag == DragTool::Groom {
            brush_ui(ui, &mut state.tool.brush);
            if let Some(channel) = state.tool.brush.paint {
                let painted = state.document().root_maps.is_painted(channel);
                let label = format!("Clear {} map", channel.label().to_lowercase());
                if ui
                    .add_enabled(painted, egui::Button::new(&label))
                    .on_hover_text(if channel == RootMapChannel::Colour {
                        "Forget the painted colour: the material's everywhere again"
                    } else {
                        "Forget this painted map: 1 everywhere again"
                    })
                    .clicked()
                {
                    state.commit_edit();
                    state
                        .edit(ChangeKind::Restyle, &label)
                        .root_maps
                        .clear_channel(channel);
                    state.commit_edit();
                }
            }
        }
        ui.horizontal(|ui| {
            if ui.button("Grow").on_hover_text("Ctrl +").clicked() {
                state.grow_selection(true);
            }
            if ui.button("Shrink").on_hover_text("Ctrl -").clicked() {
                state.grow_selection(false);
            }
            if ui.button("Select layer").clicked() {
                state.select_layer(self.layer);
            }
        });
        ui.label(format!(
            "{} bundles, {} vertices selected",
            state.selection.len(),
            state.vertex_selection.len()
        ));
        ui.separator();
        ui.heading("Transform");
        ui.horizontal(|ui| {
            ui.label("Gizmo:");
            for kind in [GizmoKind::Move, GizmoKind::Rotate, GizmoKind::Scale] {
                ui.selectable_value(&mut state.tool.gizmo, kind, kind.label());
            }
        });
        ui.horizontal(|ui| {
            let label = ui.label("Soft radius");
            ui.add(
                egui::DragValue::new(&mut state.tool.soft_radius_m)
                    .speed(0.001)
                    .range(0.0..=1.0)
                    .suffix(" m"),
            )
            .labelled_by(label.id)
            .on_hover_text("Unselected vertices this close follow with a smooth falloff (wheel while transforming)");
        });
        // One row for both switches: the panel has no height to spare.
        ui.horizontal(|ui| {
            ui.checkbox(&mut state.tool.xray, "X-ray")
                .on_hover_text("Select through the head: clicks and regions also take bundles and vertices the body hides");
            ui.checkbox(&mut state.tool.z_up, "Z up (Blender axes)")
                .on_hover_text(
                    "Axis keys and typed values in G / R / S: on, Z is up and Y points away from \
                     the front view (Blender); off, the scene's own axes (Y up, Z toward the front)",
                );
        });
        ui.label(
            egui::RichText::new(
                "G move · R rotate · S scale in the viewport; X / Y / Z lock an axis; \
                 type a value (G Z 0.02 Enter); click or Enter confirms, Esc or right-click cancels",
            )
            .small()
            .weak(),
        );
        ui.separator();
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
        ui.horizontal(|ui| {
            if ui
                .button("Split")
                .on_hover_text(
                    "Split the selected bundles off their neighbours (roots stay): shape them as their own lock",
                )
                .clicked()
            {
                state.edit_mesh("Split bundles", edit::split_bundles);
            }
            if ui
                .button("Merge")
                .on_hover_text(
                    "Merge the selected bundles back with the bundles they were split from (shared vertices meet half-way)",
                )
                .clicked()
            {
                state.edit_mesh("Merge bundles", edit::merge_bundles);
            }
        });
        ui.horizontal(|ui| {
            ui.add(
                egui::DragValue::new(&mut self.density)
                    .range(0.0..=1.0)
                    .speed(0.01)
                    .max_decimals(2),
            )
            .on_hover_text("The fraction of their strands the bundles grow");
            if ui
                .button("Set density")
                .on_hover_text(
                    "Thin the selected bundles' strands (a hairline thins out instead of ending in a hard edge)",
                )
                .clicked()
            {
                let density = self.density;
                state.edit_mesh("Set density", |mesh, bundles| {
                    edit::set_density(mesh, bundles, density)
                });
            }
        });
        ui.horizontal(|ui| {
            if ui
                .button("Drape")
                .on_hover_text(
                    "Let the selected bundles (all without a selection) fall onto the body and settle",
                )
                .clicked()
            {
                let body = state.document().body.clone();
                let mut report = None;
                let draped = state.edit_mesh("Drape", |mesh, bundles| {
                    hairloom_core::simulate::drape(mesh, &body, bundles, &[]).map(
                        |(outcome, drape)| {
                            report = Some(drape);
                            outcome
                        },
                    )
                });
                if let (true, Some(report)) = (draped, report) {
                    state.message = format!(
                        "Drape: {} after {:.1} s simulated",
                        if report.settled { "settled" } else { "still moving (stopped)" },
                        report.simulated_s
                    );
                }
            }
            // Lock and Unlock share Drape's row: what Drape holds still.
            for (label, locked, hint) in [
                (
                    "Lock",
                    true,
                    "Keep the selected vertices (or the selected bundles') where they are: \
                     interior placement and Drape leave them alone",
                ),
                ("Unlock", false, "Return them to automatic placement"),
            ] {
                if ui.button(label).on_hover_text(hint).clicked() {
                    let vertices = state.lock_targets();
                    state.edit_mesh(
                        if locked {
                            "Lock vertices"
                        } else {
                            "Unlock vertices"
                        },
                        |mesh, _| edit::set_locked(mesh, &vertices, locked),
                    );
                }
            }
            let count = state.document().hair_mesh.locked.len();
            ui.label(egui::RichText::new(format!("{count} locked")).weak());
        });
        ui.separator();
        ui.heading("Wisps");
        ui.horizontal(|ui| {
            if ui
                .button("Copy shape")
                .on_hover_text("The one selected bundle's shape")
                .clicked()
            {
                match state.selection.iter().collect::<Vec<_>>()[..] {
                    [&one] => {
                        self.copied_shape = Some(one);
                        state.message = format!("copied the shape of bundle {one}");
                    }
                    _ => state.message = "Copy shape: select exactly one bundle".into(),
                }
            }
            if let Some(source) = self.copied_shape
                && ui
                    .button("Paste shape")
                    .on_hover_text(
                        "The whole shape (layer count, every corner's path) onto the selected \
                         bundles, turned into each one's frame",
                    )
                    .clicked()
            {
                state.edit_mesh("Paste shape", |mesh, bundles| {
                    edit::paste_shape(mesh, source, bundles)
                });
            }
            if ui
                .button("Mirror shape")
                .on_hover_text(
                    "The selected bundles' whole shapes and styling groups onto their mirror \
                     images across the model's centre (x)",
                )
                .clicked()
            {
                let document = state.document();
                let plane_x = document.mirror_plane_x();
                // Shape and styling groups in one undo step.
                state.commit_edit();
                state.stop_playback_for_editing();
                let sources: Vec<u32> = state.selection.iter().copied().collect();
                let document = state.document();
                let mut mirrored = Vec::new();
                match edit::mirror_shape(&document.hair_mesh, &sources, plane_x) {
                    Ok((outcome, pairs)) => {
                        let styling =
                            edit::mirror_styling(&document.styling, &outcome.mesh, &pairs);
                        let edited = state.edit(ChangeKind::Rebuild, "Mirror shape");
                        edited.hair_mesh = outcome.mesh;
                        edited.styling = styling;
                        state.commit_edit();
                        state.message = format!(
                            "Mirror shape: {} bundle(s) mirrored with their styling",
                            pairs.len()
                        );
                        mirrored = pairs.into_iter().map(|(_, t)| t).collect();
                    }
                    Err(error) => state.message = format!("Mirror shape: {error}"),
                }
                if !mirrored.is_empty() {
                    state.selection = mirrored.into_iter().collect();
                }
            }
        });
    }
}
