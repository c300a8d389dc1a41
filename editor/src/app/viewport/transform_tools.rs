//! Modal transforms (G / R / S / E) and the on-screen gizmo: what they act on, the preview
//! while dragging, and the edit they commit.

use super::*;

/// Which modal transform runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransformKind {
    Move,
    Rotate,
    Scale,
    /// E: the selected bundles grow a layer whose distance follows the pointer.
    Extrude,
}

impl TransformKind {
    /// What the gesture asks of the hair asset: moved vertices reshape, a new layer rebuilds.
    pub(super) fn change(self) -> ChangeKind {
        match self {
            Self::Move | Self::Rotate | Self::Scale => ChangeKind::Reshape,
            Self::Extrude => ChangeKind::Rebuild,
        }
    }

    pub(super) fn label(self) -> &'static str {
        match self {
            Self::Move => "Move",
            Self::Rotate => "Rotate",
            Self::Scale => "Scale",
            Self::Extrude => "Extrude",
        }
    }
}

/// A G / R / S gesture in progress: edits preview from the mesh it started on.
pub(super) struct ActiveTransform {
    pub(super) kind: TransformKind,
    /// Locked axis (0 = x, 1 = y, 2 = z).
    pub(super) axis: Option<usize>,
    pub(super) start_pointer: egui::Pos2,
    pub(super) vertices: Vec<VertexRef>,
    pub(super) pivot: DVec3,
    /// Extrude: the bundles, the direction pointer motion is measured along and the
    /// distance at the start pointer.
    pub(super) bundles: Vec<u32>,
    pub(super) direction: DVec3,
    pub(super) base_distance_m: f64,
    /// Sign of the locked axis as the artist named it (Z-up's Y is the scene's −Z).
    pub(super) axis_sign: f64,
    /// A value typed during the gesture (`G Z 0.02 Enter`); it replaces the pointer.
    pub(super) typed: String,
    /// What was last applied (recomputed only when the pointer, axis, typed value or soft
    /// radius change).
    pub(super) applied: Option<(egui::Pos2, Option<usize>, u64, String)>,
}

/// The scene axis (0 = x, 1 = y, 2 = z) and sign an axis key names under the artist's
/// convention. The scene is Y-up with +z toward the front view; Blender is Z-up with +y
/// away from the front view.
pub fn scene_axis(key_axis: usize, z_up: bool) -> (usize, f64) {
    match (key_axis, z_up) {
        (1, true) => (2, -1.0),
        (2, true) => (1, 1.0),
        (axis, _) => (axis, 1.0),
    }
}

/// The axis (0 = X, 1 = Y, 2 = Z) the artist calls scene axis `axis`.
pub(super) fn artist_axis(axis: usize, z_up: bool) -> usize {
    match (axis, z_up) {
        (1, true) => 2,
        (2, true) => 1,
        (axis, _) => axis,
    }
}

/// The axis name the artist uses for scene axis `axis`.
fn axis_name(axis: usize, z_up: bool) -> &'static str {
    match (axis, z_up) {
        (1, true) => "Z (up)",
        (2, true) => "Y (depth)",
        (1, false) => "Y (up)",
        (2, false) => "Z (depth)",
        _ => "X",
    }
}

/// The transform a typed `value` asks for: metres along the locked axis (X when none) for
/// Move, degrees about it (the view axis when none) for Rotate, a factor for Scale.
pub(super) fn typed_transform(
    active: &ActiveTransform,
    value: f64,
    projector: Projector,
) -> VertexTransform {
    let mut axis_vector = DVec3::ZERO;
    axis_vector[active.axis.unwrap_or(0)] = active.axis_sign;
    match active.kind {
        TransformKind::Move | TransformKind::Extrude => VertexTransform::Translate {
            offset: (axis_vector * value).to_array(),
        },
        TransformKind::Rotate => {
            let axis = if active.axis.is_some() {
                axis_vector
            } else {
                let pivot_screen = projector
                    .project(active.pivot)
                    .unwrap_or(active.start_pointer);
                projector.ray(pivot_screen).1.normalize_or(DVec3::NEG_Z)
            };
            VertexTransform::Rotate {
                axis: axis.to_array(),
                angle_rad: value.to_radians(),
                pivot: active.pivot.to_array(),
            }
        }
        TransformKind::Scale => scale_about_pivot(active, value),
    }
}

/// What the selection's transform targets depend on.
#[derive(Clone, PartialEq)]
pub(super) struct TargetsKey {
    pub(super) revision: u64,
    pub(super) mode: SelectMode,
    pub(super) bundles: std::collections::BTreeSet<u32>,
    pub(super) vertices: std::collections::BTreeSet<VertexRef>,
}

/// The mean position of `vertices` (`None` when none exists).
pub(super) fn centre_of(mesh: &hairloom_core::HairMesh, vertices: &[VertexRef]) -> Option<DVec3> {
    let positions: Vec<DVec3> = vertices.iter().filter_map(|v| mesh.position(*v)).collect();
    (!positions.is_empty()).then(|| positions.iter().sum::<DVec3>() / positions.len() as f64)
}

/// Previews `transform` of `vertices` from the document as the running edit began (soft
/// selection and interior placement included) and says what it did in the status bar.
pub(super) fn preview_transform(
    state: &mut EditorState,
    kind: TransformKind,
    axis: Option<usize>,
    vertices: &[VertexRef],
    transform: VertexTransform,
) {
    let moved = edit::transform_vertices(
        &state.edit_start().hair_mesh,
        vertices,
        transform,
        state.tool.soft_radius_m,
    );
    match moved {
        Ok(outcome) => {
            state.edit(kind.change(), kind.label()).hair_mesh = outcome.mesh;
            state.message = describe_transform(kind, axis, state.tool.z_up, transform)
                + &format!(", soft radius {:.3} m", state.tool.soft_radius_m);
        }
        Err(error) => state.message = format!("{}: {error}", kind.label()),
    }
}

/// Scale by `factor` about the gesture's pivot: uniform, or along the locked axis only.
fn scale_about_pivot(active: &ActiveTransform, factor: f64) -> VertexTransform {
    let mut factors = [factor; 3];
    if let Some(axis) = active.axis {
        factors = [1.0; 3];
        factors[axis] = factor;
    }
    VertexTransform::Scale {
        factors,
        pivot: active.pivot.to_array(),
    }
}

/// The transform the pointer asks for: screen motion mapped at the pivot's depth.
pub(super) fn transform_for(
    active: &ActiveTransform,
    pointer: egui::Pos2,
    projector: Projector,
) -> VertexTransform {
    let axis_vector = active.axis.map(|a| {
        let mut v = DVec3::ZERO;
        v[a] = 1.0;
        v
    });
    let pivot_screen = projector
        .project(active.pivot)
        .unwrap_or(active.start_pointer);
    match active.kind {
        TransformKind::Move => {
            let offset = projector.unproject(pointer, active.pivot)
                - projector.unproject(active.start_pointer, active.pivot);
            let offset = axis_vector.map_or(offset, |axis| axis * offset.dot(axis));
            VertexTransform::Translate {
                offset: offset.to_array(),
            }
        }
        TransformKind::Rotate => {
            let angle = |p: egui::Pos2| (p.y - pivot_screen.y).atan2(p.x - pivot_screen.x) as f64;
            let turn = angle(pointer) - angle(active.start_pointer);
            // Into the screen: a clockwise pointer turn (screen y points down) turns the
            // model clockwise as seen.
            let forward = projector.ray(pivot_screen).1.normalize_or(DVec3::NEG_Z);
            let axis =
                axis_vector.map_or(
                    forward,
                    |axis| {
                        if axis.dot(forward) < 0.0 { -axis } else { axis }
                    },
                );
            VertexTransform::Rotate {
                axis: axis.to_array(),
                angle_rad: turn,
                pivot: active.pivot.to_array(),
            }
        }
        TransformKind::Extrude => VertexTransform::Translate { offset: [0.0; 3] },
        TransformKind::Scale => {
            let start = active.start_pointer.distance(pivot_screen).max(1.0);
            scale_about_pivot(active, (pointer.distance(pivot_screen) / start) as f64)
        }
    }
}

/// One line for the status bar.
pub(super) fn describe_transform(
    kind: TransformKind,
    axis: Option<usize>,
    z_up: bool,
    transform: VertexTransform,
) -> String {
    let convention = if z_up { "Z-up" } else { "Y-up" };
    let axis = axis.map_or(format!(" [{convention}]"), |a| {
        format!(" along {} [{convention}]", axis_name(a, z_up))
    });
    match transform {
        VertexTransform::Translate { offset } => {
            // In the artist's axes, as the header names them: Z-up is the scene's (x, −z, y)
            // (see `scene_axis`), so a move up reads (0, 0, d), not the scene's (0, d, 0).
            let shown = if z_up {
                [offset[0], -offset[2], offset[1]]
            } else {
                offset
            }
            // No "-0.0000" for an axis that did not move.
            .map(|v| v + 0.0);
            format!(
                "{}{axis}: ({:.4}, {:.4}, {:.4}) m",
                kind.label(),
                shown[0],
                shown[1],
                shown[2]
            )
        }
        VertexTransform::Rotate { angle_rad, .. } => {
            format!("{}{axis}: {:.1}°", kind.label(), angle_rad.to_degrees())
        }
        VertexTransform::Scale { factors, .. } => format!(
            "{}{axis}: ×{:.3}",
            kind.label(),
            factors
                .iter()
                .copied()
                .fold(1.0, |a: f64, f| if (f - 1.0).abs() > (a - 1.0).abs() {
                    f
                } else {
                    a
                })
        ),
    }
}

impl Viewport {
    /// The modal tool running (G / R / S / E), which owns the keyboard until it ends.
    pub fn modal_tool(&self) -> Option<&'static str> {
        self.transform
            .as_ref()
            .map(|t| t.kind.label())
            .or_else(|| self.styling_drag().map(|h| h.label()))
    }

    pub(super) fn begin_transform(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        kind: TransformKind,
    ) {
        state.commit_edit();
        state.stop_playback_for_editing();
        let (vertices, pivot) = self.selection_targets(state);
        let Some(pivot) = pivot else {
            state.message = format!(
                "{}: nothing selected (interior vertices place themselves)",
                kind.label()
            );
            return;
        };
        let start_pointer = ui
            .input(|i| i.pointer.hover_pos())
            .unwrap_or(egui::Pos2::ZERO);
        self.transform = Some(ActiveTransform {
            kind,
            axis: None,
            start_pointer,
            vertices,
            pivot,
            bundles: Vec::new(),
            direction: DVec3::ZERO,
            base_distance_m: 0.0,
            axis_sign: 1.0,
            typed: String::new(),
            applied: None,
        });
        state.message = format!(
            "{}: move the pointer or type a value; X / Y / Z lock an axis ({}); click or Enter confirms, Esc cancels",
            kind.label(),
            if state.tool.z_up { "Z-up" } else { "Y-up" }
        );
    }

    /// The gizmo at the selection's centre; `true` when it has the pointer (a click or drag
    /// there moves the selection instead of selecting). A drag is one undo step.
    pub(super) fn drive_gizmo(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        response: &egui::Response,
        projector: Projector,
    ) -> bool {
        self.gizmo_shown = false;
        self.gizmo_centre = None;
        if !self.settings.gizmo || ui.input(|i| i.modifiers.alt) {
            return false;
        }
        // The targets are fixed while a drag runs (the document changes under it);
        // otherwise they follow the selection, recomputed only when it or the document changes.
        let (vertices, pivot) = match &self.gizmo_drag {
            Some(drag) => drag.clone(),
            None => self.selection_targets(state),
        };
        let Some(pivot) = pivot else {
            return false;
        };
        self.gizmo_shown = true;
        self.gizmo_centre = projector.project(pivot);
        let projection = projector.view_projection * projector.view.inverse();
        let step = self.gizmo.update(
            state.tool.gizmo,
            ui,
            response,
            projector.rect,
            projector.view,
            projection,
            pivot,
        );
        match step {
            GizmoStep::Dragging(transform) => {
                if self.gizmo_drag.is_none() {
                    state.commit_edit();
                    self.gizmo_drag = Some((vertices.clone(), Some(pivot)));
                }
                let kind = match transform {
                    VertexTransform::Translate { .. } => TransformKind::Move,
                    VertexTransform::Rotate { .. } => TransformKind::Rotate,
                    VertexTransform::Scale { .. } => TransformKind::Scale,
                };
                preview_transform(state, kind, None, &vertices, transform);
                true
            }
            GizmoStep::Released => {
                state.commit_edit();
                self.gizmo_drag = None;
                true
            }
            GizmoStep::Idle => self.gizmo.is_hovered(ui.input(|i| i.pointer.hover_pos())),
        }
    }

    /// The selection's transform targets and their centre, cached per selection key.
    pub(super) fn selection_targets(
        &mut self,
        state: &EditorState,
    ) -> (Vec<VertexRef>, Option<DVec3>) {
        let key = TargetsKey {
            revision: state.revision,
            mode: state.tool.mode,
            bundles: state.selection.clone(),
            vertices: state.vertex_selection.clone(),
        };
        if self
            .targets_cache
            .as_ref()
            .is_none_or(|(k, _, _)| *k != key)
        {
            let targets = state.transform_targets();
            let pivot = centre_of(&state.document().hair_mesh, &targets);
            self.targets_cache = Some((key, targets, pivot));
        }
        self.targets_cache
            .as_ref()
            .map(|(_, targets, pivot)| (targets.clone(), *pivot))
            .unwrap_or_default()
    }

    /// E over the viewport: extrude the selected bundles by `distance_m` at once, then let
    /// the pointer change the distance until a click confirms (one undo step) or Esc cancels.
    pub fn begin_extrude(&mut self, ui: &egui::Ui, state: &mut EditorState, distance_m: f64) {
        state.commit_edit();
        let bundles: Vec<u32> = state.selection.iter().copied().collect();
        let mesh = &state.document().hair_mesh;
        let mut tips = Vec::new();
        let mut direction = DVec3::ZERO;
        for bundle in bundles.iter().filter_map(|&b| mesh.bundles.get(b as usize)) {
            if let Some(tip) = edit::bundle_layer_centre(mesh, bundle, bundle.layers as usize) {
                tips.push(tip);
                direction += edit::growth_direction(mesh, bundle).unwrap_or(DVec3::ZERO);
            }
        }
        if tips.is_empty() {
            state.message = "Extrude: nothing selected".into();
            return;
        }
        let start_pointer = ui
            .input(|i| i.pointer.hover_pos())
            .unwrap_or(egui::Pos2::ZERO);
        self.transform = Some(ActiveTransform {
            kind: TransformKind::Extrude,
            axis: None,
            start_pointer,
            vertices: Vec::new(),
            pivot: tips.iter().sum::<DVec3>() / tips.len() as f64,
            bundles,
            direction: direction.normalize_or(DVec3::Z),
            base_distance_m: distance_m,
            axis_sign: 1.0,
            typed: String::new(),
            applied: None,
        });
    }

    /// Follows the pointer during G / R / S / E; confirms or cancels.
    pub(super) fn drive_transform(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        response: &egui::Response,
        projector: Projector,
    ) {
        let Some(active) = self.transform.as_mut() else {
            return;
        };
        use egui::{Key, Modifiers};
        let cancel = ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Escape))
            || response.secondary_clicked();
        if cancel {
            state.cancel_edit();
            state.message = format!("{} cancelled", active.kind.label());
            self.transform = None;
            return;
        }
        for (key, key_axis) in [(Key::X, 0), (Key::Y, 1), (Key::Z, 2)] {
            if ui.input_mut(|i| i.consume_key(Modifiers::NONE, key)) {
                let (axis, sign) = scene_axis(key_axis, state.tool.z_up);
                active.axis = if active.axis == Some(axis) {
                    None
                } else {
                    Some(axis)
                };
                active.axis_sign = sign;
            }
        }
        // Typed digits, in the order pressed (Blender's numeric input).
        ui.input_mut(|i| {
            i.events.retain(|event| {
                let egui::Event::Key {
                    key,
                    pressed: true,
                    modifiers,
                    ..
                } = event
                else {
                    return true;
                };
                if modifiers.command || modifiers.alt {
                    return true;
                }
                let typed = &mut active.typed;
                match key {
                    Key::Backspace => {
                        typed.pop();
                    }
                    Key::Minus => {
                        if typed.starts_with('-') {
                            typed.remove(0);
                        } else {
                            typed.insert(0, '-');
                        }
                    }
                    Key::Period | Key::Comma if !typed.contains('.') => typed.push('.'),
                    key => match key.name().parse::<u8>() {
                        Ok(digit) if digit <= 9 && key.name().len() == 1 => {
                            typed.push(char::from(b'0' + digit));
                        }
                        _ => return true,
                    },
                }
                false
            });
        });
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            let radius = &mut state.tool.soft_radius_m;
            *radius = if *radius <= 0.0 && scroll > 0.0 {
                0.005
            } else {
                (*radius * (scroll as f64 * 0.004).exp()).clamp(0.0, 1.0)
            };
        }
        let pointer = ui
            .input(|i| i.pointer.hover_pos())
            .unwrap_or(active.start_pointer);
        let radius_bits = state.tool.soft_radius_m.to_bits();
        let applied = Some((pointer, active.axis, radius_bits, active.typed.clone()));
        let typed_value = active.typed.parse::<f64>().ok().filter(|v| v.is_finite());
        if active.applied != applied {
            active.applied = applied;
            if active.kind == TransformKind::Extrude {
                let moved = projector.unproject(pointer, active.pivot)
                    - projector.unproject(active.start_pointer, active.pivot);
                let distance =
                    typed_value.unwrap_or(active.base_distance_m + moved.dot(active.direction));
                let extruded = edit::extrude(
                    &state.edit_start().hair_mesh,
                    &active.bundles,
                    edit::ExtrudeDirection::AlongNormal { distance },
                );
                match extruded {
                    Ok(outcome) => {
                        state
                            .edit(active.kind.change(), active.kind.label())
                            .hair_mesh = outcome.mesh;
                        state.message = format!("Extrude: {distance:.4} m");
                    }
                    Err(error) => state.message = format!("Extrude: {error}"),
                }
            } else {
                let transform = match typed_value {
                    Some(value) => typed_transform(active, value, projector),
                    None => transform_for(active, pointer, projector),
                };
                preview_transform(state, active.kind, active.axis, &active.vertices, transform);
                if !active.typed.is_empty() {
                    state.message = format!("typed {} · {}", active.typed, state.message);
                }
            }
        }
        let confirm =
            response.clicked() || ui.input_mut(|i| i.consume_key(Modifiers::NONE, Key::Enter));
        if confirm {
            state.commit_edit();
            self.transform = None;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_move_is_shown_in_the_axes_its_header_names() {
        // Issue 35's bug: "Move along Z (up)" showed the scene's (0, 0.02, 0).
        let up = VertexTransform::Translate {
            offset: [0.0, 0.02, 0.0],
        };
        assert_eq!(
            describe_transform(TransformKind::Move, Some(1), true, up),
            "Move along Z (up) [Z-up]: (0.0000, 0.0000, 0.0200) m"
        );
        assert_eq!(
            describe_transform(TransformKind::Move, Some(1), false, up),
            "Move along Y (up) [Y-up]: (0.0000, 0.0200, 0.0000) m"
        );
        // Blender's +Y points away from the front view: the scene's −z.
        let away = VertexTransform::Translate {
            offset: [0.0, 0.0, -0.01],
        };
        assert_eq!(
            describe_transform(TransformKind::Move, Some(2), true, away),
            "Move along Y (depth) [Z-up]: (0.0000, 0.0100, 0.0000) m"
        );
    }
}
