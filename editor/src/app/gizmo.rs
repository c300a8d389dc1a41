//! The on-screen move / rotate / scale gizmo: a small adapter over the `transform-gizmo`
//! core crate (its egui adapter lags behind egui 0.37). It converts our camera and pointer
//! into the crate's types, turns its result into a [`VertexTransform`] from the start of the
//! drag (so soft selection and interior placement work exactly as with G / R / S), and draws
//! its triangles as an egui mesh.

use glam::{DVec3, Mat4};
use hairloom_core::edit::VertexTransform;
use transform_gizmo::math::{DMat4, Transform};
use transform_gizmo::prelude::{
    EnumSet, Gizmo, GizmoConfig, GizmoInteraction, GizmoMode, GizmoOrientation, GizmoResult,
};

/// Which handles the gizmo shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GizmoKind {
    Move,
    Rotate,
    Scale,
}

impl GizmoKind {
    pub fn label(self) -> &'static str {
        match self {
            Self::Move => "Move",
            Self::Rotate => "Rotate",
            Self::Scale => "Scale",
        }
    }

    fn modes(self) -> EnumSet<GizmoMode> {
        match self {
            Self::Move => {
                GizmoMode::TranslateX
                    | GizmoMode::TranslateY
                    | GizmoMode::TranslateZ
                    | GizmoMode::TranslateView
            }
            Self::Rotate => {
                GizmoMode::RotateX | GizmoMode::RotateY | GizmoMode::RotateZ | GizmoMode::RotateView
            }
            Self::Scale => {
                GizmoMode::ScaleX | GizmoMode::ScaleY | GizmoMode::ScaleZ | GizmoMode::ScaleUniform
            }
        }
    }
}

/// What one frame of the gizmo asks for.
pub enum GizmoStep {
    /// Not touched.
    Idle,
    /// Dragging: the transform from where the drag began.
    Dragging(VertexTransform),
    /// The drag ended this frame.
    Released,
}

#[derive(Default)]
pub struct GizmoAdapter {
    gizmo: Gizmo,
    dragging: bool,
}

fn to_gizmo_matrix(m: Mat4) -> DMat4 {
    DMat4::from_cols_array(&m.as_dmat4().to_cols_array())
}

impl GizmoAdapter {
    /// Whether the pointer is over a handle (clicks there are the gizmo's, not selection).
    pub fn is_hovered(&self, pointer: Option<egui::Pos2>) -> bool {
        self.dragging || pointer.is_some_and(|p| self.gizmo.pick_preview((p.x, p.y)))
    }

    pub fn is_dragging(&self) -> bool {
        self.dragging
    }

    /// Updates the gizmo for this frame at `pivot` with the camera's `view` and `projection`
    /// (viewport `rect`, in points), and reports what the pointer did with it.
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        kind: GizmoKind,
        ui: &egui::Ui,
        response: &egui::Response,
        rect: egui::Rect,
        view: Mat4,
        projection: Mat4,
        pivot: DVec3,
    ) -> GizmoStep {
        let viewport = transform_gizmo::math::Rect::from_min_max(
            transform_gizmo::math::Pos2::new(rect.left(), rect.top()),
            transform_gizmo::math::Pos2::new(rect.right(), rect.bottom()),
        );
        self.gizmo.update_config(GizmoConfig {
            view_matrix: to_gizmo_matrix(view).into(),
            projection_matrix: to_gizmo_matrix(projection).into(),
            viewport,
            modes: kind.modes(),
            orientation: GizmoOrientation::Global,
            pixels_per_point: ui.ctx().pixels_per_point(),
            ..GizmoConfig::default()
        });
        let pointer = ui.input(|i| i.pointer.hover_pos());
        let interaction = GizmoInteraction {
            cursor_pos: pointer.map_or((f32::NAN, f32::NAN), |p| (p.x, p.y)),
            hovered: response.hovered() || self.dragging,
            drag_started: response.drag_started_by(egui::PointerButton::Primary),
            dragging: response.dragged_by(egui::PointerButton::Primary),
        };
        let target = Transform::from_scale_rotation_translation(
            transform_gizmo::math::DVec3::ONE,
            transform_gizmo::math::DQuat::IDENTITY,
            transform_gizmo::math::DVec3::new(pivot.x, pivot.y, pivot.z),
        );
        match self.gizmo.update(interaction, &[target]) {
            Some((result, targets)) => {
                self.dragging = true;
                GizmoStep::Dragging(vertex_transform(result, targets.first(), pivot))
            }
            None if self.dragging => {
                self.dragging = false;
                GizmoStep::Released
            }
            None => GizmoStep::Idle,
        }
    }

    /// Draws the handles over the viewport.
    pub fn paint(&self, painter: &egui::Painter) {
        let data = self.gizmo.draw();
        if data.indices.is_empty() {
            return;
        }
        let vertices = data
            .vertices
            .iter()
            .zip(&data.colors)
            .map(|(&[x, y], &[r, g, b, a])| egui::epaint::Vertex {
                pos: egui::pos2(x, y),
                uv: egui::epaint::WHITE_UV,
                color: egui::Rgba::from_rgba_premultiplied(r, g, b, a).into(),
            })
            .collect();
        let mesh = egui::Mesh {
            indices: data.indices,
            vertices,
            ..egui::Mesh::default()
        };
        painter.add(egui::Shape::mesh(mesh));
    }
}

/// The gizmo's total change since the drag began, as a vertex transform about `pivot`.
fn vertex_transform(
    result: GizmoResult,
    target: Option<&Transform>,
    pivot: DVec3,
) -> VertexTransform {
    let pivot_array = pivot.to_array();
    match result {
        GizmoResult::Translation { total, .. } => VertexTransform::Translate {
            offset: [total.x, total.y, total.z],
        },
        GizmoResult::Scale { total } => VertexTransform::Scale {
            factors: [total.x, total.y, total.z],
            pivot: pivot_array,
        },
        GizmoResult::Rotation { .. } | GizmoResult::Arcball { .. } => {
            // The updated target holds the total rotation with the crate's conventions.
            let rotation = target.map_or(glam::DQuat::IDENTITY, |t| {
                glam::DQuat::from_xyzw(t.rotation.v.x, t.rotation.v.y, t.rotation.v.z, t.rotation.s)
            });
            let (axis, angle_rad) = rotation.to_axis_angle();
            VertexTransform::Rotate {
                axis: axis.to_array(),
                angle_rad,
                pivot: pivot_array,
            }
        }
    }
}
