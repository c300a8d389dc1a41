//! The grooming brushes in the viewport. With Drag ▸ Groom (Tools panel), a left drag strokes
//! the hair: each step of the pointer of a fifth of the brush is one dab
//! ([`hairloom_core::edit::apply_brush`]) on the mesh the stroke has made so far, the whole
//! stroke one undo step. Ctrl inverts the brush (cut, flatten, spread). The brush sits where
//! the pointer's ray meets the hair mesh, and where it meets none, at the depth it last
//! touched; its circle is drawn at that size in the viewport.

use std::hash::{Hash, Hasher};
use std::sync::Arc;

use glam::DVec3;
use hairloom_core::edit::{BrushDab, apply_brush, pick::pick_bundle};
use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::document::BodyMesh;
use hairloom_core::simulate::BodySdf;

use super::camera::Projector;
use super::{DragTool, EditorState, Viewport};

/// A stroke in progress.
pub(super) struct Stroke {
    /// Where the last dab was applied, on screen and on the hair.
    last_pointer: egui::Pos2,
    last_centre: DVec3,
    dabs: usize,
    held_back: usize,
}

/// The brush under the pointer, for the overlay: its centre on screen and its radius in
/// points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrushCursor {
    pub centre: egui::Pos2,
    pub radius_px: f32,
    pub touches_hair: bool,
}

/// A dab every this share of the brush's diameter of pointer travel (Blender's spacing).
const SPACING_OF_DIAMETER: f32 = 0.1;

/// A cheap identity of a body mesh, so its distance field is built once per body.
fn body_fingerprint(body: &BodyMesh) -> u64 {
    let mut hasher = std::collections::hash_map::DefaultHasher::new();
    body.positions.len().hash(&mut hasher);
    body.triangles.hash(&mut hasher);
    for p in &body.positions {
        p.map(f32::to_bits).hash(&mut hasher);
    }
    hasher.finish()
}

impl Viewport {
    /// Where the brush touches: the hair mesh under `pointer`, else the point at the depth
    /// of `fallback` (the last centre of the stroke), else nothing.
    fn brush_centre(
        state: &EditorState,
        projector: &Projector,
        pointer: egui::Pos2,
        fallback: Option<DVec3>,
    ) -> Option<(DVec3, bool)> {
        let (origin, direction) = projector.ray(pointer);
        match pick_bundle(&state.document().hair_mesh, origin, direction) {
            Some((_, t)) => Some((origin + direction * t, true)),
            None => fallback.map(|at| (projector.unproject(pointer, at), false)),
        }
    }

    /// The brush's radius on screen at `centre`, in points.
    fn brush_radius_px(projector: &Projector, centre: DVec3, radius_m: f64, toward: DVec3) -> f32 {
        let side = toward.cross(DVec3::Y).try_normalize().unwrap_or(DVec3::X);
        match (
            projector.project(centre),
            projector.project(centre + side * radius_m),
        ) {
            (Some(a), Some(b)) => a.distance(b),
            _ => 0.0,
        }
    }

    /// The body's distance field for the document's body (built once per body).
    fn body_field(&mut self, state: &EditorState) -> Arc<BodySdf> {
        let document = state.document();
        let key = body_fingerprint(&document.body);
        if let Some((cached, field)) = &self.body_field
            && *cached == key
        {
            return field.clone();
        }
        let field = Arc::new(BodySdf::for_hair(&document.body, &document.hair_mesh));
        self.body_field = Some((key, field.clone()));
        field
    }

    /// Strokes the hair when the drag tool is Groom; `true` when it took the pointer this
    /// frame (a drag), so region selection does not also run. Clicks still select.
    pub(super) fn groom(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        response: &egui::Response,
        projector: Projector,
    ) -> bool {
        self.brush_cursor = None;
        if state.tool.drag != DragTool::Groom {
            self.stroke = None;
            return false;
        }
        let brush = state.tool.brush;
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let fallback = self.stroke.as_ref().map(|s| s.last_centre);
        let under =
            pointer.and_then(|p| Some((p, Self::brush_centre(state, &projector, p, fallback)?)));
        if let Some((at, (centre, touches_hair))) = under {
            let toward = projector.ray(at).1;
            self.brush_cursor = Some(BrushCursor {
                centre: at,
                radius_px: Self::brush_radius_px(&projector, centre, brush.radius_m, toward),
                touches_hair,
            });
        }
        let alt = ui.input(|i| i.modifiers.alt);
        if response.drag_started_by(egui::PointerButton::Primary) && !alt {
            state.commit_edit();
            state.stop_playback_for_editing();
            self.stroke = under
                .filter(|(_, (_, hair))| *hair)
                .map(|(p, (centre, _))| Stroke {
                    last_pointer: p,
                    last_centre: centre,
                    dabs: 0,
                    held_back: 0,
                });
            if self.stroke.is_none() {
                state.message = format!("{}: start the stroke on the hair", brush.kind.label());
            }
        }
        let Some(stroke) = self.stroke.as_mut() else {
            return response.dragged_by(egui::PointerButton::Primary) && !alt;
        };
        if response.drag_stopped() {
            state.commit_edit();
            state.message = format!(
                "{}: {} dabs{}",
                brush.kind.label(),
                stroke.dabs,
                if stroke.held_back > 0 {
                    format!(
                        ", {} left the hair as it was (no hair under the brush, or the step would \
                         have turned a layer over, crowded it or reached into the head)",
                        stroke.held_back
                    )
                } else {
                    String::new()
                }
            );
            self.stroke = None;
            return true;
        }
        let Some((at, (centre, _))) = under else {
            return true;
        };
        let spacing_px =
            (self.brush_cursor.map_or(8.0, |c| c.radius_px) * 2.0 * SPACING_OF_DIAMETER).max(2.0);
        if at.distance(stroke.last_pointer) < spacing_px {
            return true;
        }
        let motion = projector.unproject(at, stroke.last_centre)
            - projector.unproject(stroke.last_pointer, stroke.last_centre);
        let view = projector.ray(at).1;
        let dab = BrushDab {
            kind: brush.kind,
            centre_m: centre.to_array(),
            radius_m: brush.radius_m,
            strength: brush.strength,
            invert: ui.input(|i| i.modifiers.command),
            motion_m: motion.to_array(),
            view_direction: brush.front_only.then(|| view.to_array()),
            mirror_x: brush.mirror_x,
            mirror_plane_x: state.document().mirror_plane_x(),
        };
        let stroke_pointer = at;
        let field = self.body_field(state);
        let Some(stroke) = self.stroke.as_mut() else {
            return true;
        };
        stroke.last_pointer = stroke_pointer;
        stroke.last_centre = centre;
        match apply_brush(&state.document().hair_mesh, &field, &dab) {
            Ok(outcome) if outcome.affected_bundles.is_empty() => stroke.held_back += 1,
            Ok(outcome) => {
                stroke.dabs += 1;
                let label = format!("{} brush", brush.kind.label());
                state.edit(ChangeKind::Reshape, &label).hair_mesh = outcome.mesh;
            }
            Err(error) => state.message = format!("{}: {error}", brush.kind.label()),
        }
        true
    }
}
