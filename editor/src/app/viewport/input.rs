//! Pointer and keyboard input: click, box, lasso and paint selection, and the viewport's keys.

use super::*;

/// Applies region hits to a selection: replace it, add to it, or (`remove`) take them out.
/// Returns how many were hit.
pub(super) fn apply_hits<T: Ord + Copy>(
    selection: &mut std::collections::BTreeSet<T>,
    hits: &[T],
    replace: bool,
    remove: bool,
) -> usize {
    if replace {
        selection.clear();
    }
    for hit in hits {
        if remove {
            selection.remove(hit);
        } else {
            selection.insert(*hit);
        }
    }
    hits.len()
}

/// Pick distance for vertices, in points.
pub(super) const PICK_RADIUS_PX: f64 = 10.0;

impl Viewport {
    /// Click and region selection (see the module documentation).
    pub(super) fn select(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        response: &egui::Response,
        projector: Projector,
    ) {
        let modifiers = ui.input(|i| i.modifiers);
        // Without X-ray only what the body leaves in view is picked (no selecting through
        // the head). The depth map is built only for a click or a finished region.
        let gesture_ends =
            response.clicked() || (response.drag_stopped() && self.drag_path.len() > 1);
        if gesture_ends {
            state.stop_playback_for_editing();
        }
        let mesh = &state.document().hair_mesh;
        let depth = (gesture_ends && !state.tool.xray).then(|| self.body_depth(state, &projector));
        let seen = |p: DVec3| {
            depth.as_ref().is_none_or(|depth| {
                projector
                    .project_local_depth(p)
                    .is_some_and(|q| depth.visible(q))
            })
        };
        let project_seen = |p: DVec3| seen(p).then(|| projector.project_xy(p)).flatten();
        if response.clicked()
            && let Some(pointer) = response.interact_pointer_pos()
        {
            let add = modifiers.command || modifiers.shift;
            match state.tool.mode {
                SelectMode::Bundles => {
                    let (origin, direction) = projector.ray(pointer);
                    let hit = hairloom_core::edit::pick::pick_bundle(mesh, origin, direction)
                        .filter(|&(_, t)| seen(origin + direction * t));
                    if !add {
                        state.selection.clear();
                    }
                    if let Some((bundle, _)) = hit {
                        if !state.selection.insert(bundle) {
                            state.selection.remove(&bundle);
                        }
                        state.message = format!("bundle {bundle}");
                    }
                }
                SelectMode::Vertices => {
                    let topology = Topology::build(mesh);
                    let hit = select::nearest_vertex(
                        mesh,
                        &topology,
                        project_seen,
                        [pointer.x as f64, pointer.y as f64],
                        PICK_RADIUS_PX,
                    );
                    if !add {
                        state.vertex_selection.clear();
                    }
                    if let Some(v) = hit {
                        if !state.vertex_selection.insert(v) {
                            state.vertex_selection.remove(&v);
                        }
                        state.message = format!("vertex: column {} layer {}", v.column, v.layer);
                    }
                }
            }
            return;
        }
        let selecting = response.dragged_by(egui::PointerButton::Primary) && !modifiers.alt;
        if response.drag_started_by(egui::PointerButton::Primary) {
            self.drag_path.clear();
        }
        if selecting && let Some(pointer) = response.interact_pointer_pos() {
            self.drag_path.push(pointer);
        }
        if response.drag_stopped() && self.drag_path.len() > 1 {
            let points: Vec<[f64; 2]> = std::mem::take(&mut self.drag_path)
                .iter()
                .map(|p| [p.x as f64, p.y as f64])
                .collect();
            let region = match state.tool.drag {
                DragTool::Box => Region::Box {
                    a: points[0],
                    b: points[points.len() - 1],
                },
                DragTool::Lasso => Region::Lasso(points),
                DragTool::Paint => Region::Paint {
                    points,
                    radius_px: state.tool.paint_radius_px as f64,
                },
                // A groom drag strokes the hair (`groom_brush.rs`); it never reaches here.
                DragTool::Groom => return,
            };
            let project = project_seen;
            let replace = !modifiers.shift && !modifiers.command;
            let remove = modifiers.command;
            let count = match state.tool.mode {
                SelectMode::Bundles => {
                    let hits = select::bundles_in_region(mesh, project, &region);
                    apply_hits(&mut state.selection, &hits, replace, remove)
                }
                SelectMode::Vertices => {
                    let topology = Topology::build(mesh);
                    let hits = select::vertices_in_region(mesh, &topology, project, &region);
                    apply_hits(&mut state.vertex_selection, &hits, replace, remove)
                }
            };
            state.message = format!("{count} in the region");
        }
    }

    /// Single-key commands while the pointer is over the viewport.
    pub(super) fn keys(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        response: &egui::Response,
    ) {
        if !response.hovered() || ui.ctx().text_edit_focused() || self.keyboard_blocked {
            return;
        }
        use egui::{Key, Modifiers};
        let pressed = |key| ui.input_mut(|i| i.consume_key(Modifiers::NONE, key));
        for (key, kind) in [
            (Key::G, TransformKind::Move),
            (Key::R, TransformKind::Rotate),
            (Key::S, TransformKind::Scale),
        ] {
            if pressed(key) {
                self.begin_transform(ui, state, kind);
                return;
            }
        }
        // Alt+A first: egui's matching ignores an Alt the pattern does not name, so plain
        // A would also take Alt+A.
        if ui.input_mut(|i| i.consume_key(Modifiers::ALT, Key::A)) {
            state.select_all(false);
        }
        if pressed(Key::A) {
            state.select_all(true);
        }
        let grows = ui.input_mut(|i| {
            i.count_and_consume_key(Modifiers::COMMAND, Key::Plus)
                + i.count_and_consume_key(Modifiers::COMMAND, Key::Equals)
        });
        for _ in 0..grows {
            state.grow_selection(true);
        }
        for _ in 0..ui.input_mut(|i| i.count_and_consume_key(Modifiers::COMMAND, Key::Minus)) {
            state.grow_selection(false);
        }
        if pressed(Key::F) {
            self.frame_selection(state);
        }
    }

    /// Whether the pointer is over the viewport (the app routes E here then).
    pub fn is_hovered(&self, ui: &egui::Ui) -> bool {
        let pointer = ui.input(|i| i.pointer.hover_pos());
        self.rect
            .zip(pointer)
            .is_some_and(|(rect, pointer)| rect.contains(pointer))
    }
}
