//! The grooming brushes in the viewport. With Drag ▸ Groom (Tools panel), a left drag strokes
//! the hair: each step of the pointer of a tenth of the brush's diameter is one dab
//! ([`hairloom_core::edit::apply_brush`]) on the mesh the stroke has made so far, the whole
//! stroke one undo step. Ctrl inverts the brush (cut, flatten, spread); a tablet's pressure,
//! where egui reports it, scales the strength. The brush sits where the pointer's ray meets
//! the hair mesh in front of the head (unless X-ray is on), and where it meets none, at the
//! depth it last touched; its circle is drawn at that size in the viewport. Alt held
//! (navigation) pauses the stroke; an undo or any other change of the document during the
//! stroke ends it.

use std::hash::{Hash, Hasher};
use std::sync::Arc;

use glam::DVec3;
use hairloom_core::edit::paint_maps::{MapDab, RootMapRaster, paint_dab};
use hairloom_core::edit::{BrushDab, apply_brush, pick::pick_bundle};
use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::document::BodyMesh;
use hairloom_core::model::root_maps::{DEFAULT_ROOT_MAP_SIDE, RootMapChannel, RootMaps};
use hairloom_core::simulate::BodySdf;

use super::camera::Projector;
use super::{DragTool, EditorState, Viewport};

/// The body's distance field for one body (a fingerprint of its mesh): building on a worker
/// thread, built (and whether on the worker), or failed there. It takes about 0.4 s for the
/// head scan, so it starts when the Groom tool is chosen rather than at the first stroke,
/// where it froze the pointer.
pub(super) enum BodyField {
    Building(u64, std::thread::JoinHandle<BodySdf>),
    Ready {
        key: u64,
        field: Arc<BodySdf>,
        on_worker: bool,
    },
    /// The worker panicked (it never has): not tried again on the worker for this body; a
    /// stroke builds it on the UI thread.
    Failed(u64),
}

impl BodyField {
    fn key(&self) -> u64 {
        match self {
            Self::Building(key, _) | Self::Ready { key, .. } | Self::Failed(key) => *key,
        }
    }
}

/// A stroke in progress.
pub(super) struct Stroke {
    /// Where the last dab was applied, on screen and on the hair.
    last_pointer: egui::Pos2,
    last_centre: DVec3,
    /// The document revision after the stroke's last change: another change ends it.
    revision: u64,
    /// The body's distance field, for the whole stroke.
    field: Arc<BodySdf>,
    dabs: usize,
    held_back: usize,
    /// Map painting: where each map texel's root lies (built once per stroke).
    raster: Option<Arc<RootMapRaster>>,
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
/// The most dabs one frame applies (a fast stroke over a slow frame).
const MAX_DABS_PER_FRAME: usize = 16;
/// Hair this far behind the body's surface along the pointer's ray still counts as in
/// front (the hair mesh's root layer lies on the scalp).
const IN_FRONT_TOLERANCE_M: f64 = 0.003;

/// How far along the pointer's ray a map brush looks for the scalp (model units).
const MAP_RAY_MAX_M: f64 = 1.0e3;

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
    /// Where the brush touches: the hair mesh under `pointer` (in front of the head unless
    /// `through_body`), else the point at the depth of `fallback` (the last centre of the
    /// stroke), else nothing. The flag says whether it touches hair.
    fn brush_centre(
        state: &EditorState,
        projector: &Projector,
        field: Option<&BodySdf>,
        pointer: egui::Pos2,
        fallback: Option<DVec3>,
    ) -> Option<(DVec3, bool)> {
        let (origin, direction) = projector.ray(pointer);
        // A map brush paints the scalp under the hair: it aims at the body where there is one.
        if state.tool.brush.paint.is_some()
            && let Some(body_m) = field.and_then(|f| f.ray_hit_m(origin, direction, MAP_RAY_MAX_M))
        {
            return Some((origin + direction.normalize() * body_m, true));
        }
        let hit = pick_bundle(&state.document().hair_mesh, origin, direction)
            .map(|(_, t)| origin + direction * t)
            .filter(|&at| {
                let Some(field) = field.filter(|_| !state.tool.xray) else {
                    return true;
                };
                let hair_m = at.distance(origin);
                field
                    .ray_hit_m(origin, direction, hair_m + 1.0)
                    .is_none_or(|body_m| hair_m <= body_m + IN_FRONT_TOLERANCE_M)
            });
        match hit {
            Some(at) => Some((at, true)),
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

    /// The fingerprint of the document's body, hashed again only when the document changed
    /// (it is asked for every frame while Groom is the drag tool; a large body hashes tens
    /// of megabytes).
    fn body_key(&mut self, state: &EditorState) -> u64 {
        match self.body_key {
            Some((revision, key)) if revision == state.revision => key,
            _ => {
                let key = body_fingerprint(&state.document().body);
                self.body_key = Some((state.revision, key));
                key
            }
        }
    }

    /// Starts building the distance field of the document's body on a worker thread, unless
    /// it is built, building or failed for this body. A build for a body that changed since
    /// is left to finish on its own (its result is dropped).
    fn prepare_body_field(&mut self, state: &EditorState) {
        let key = self.body_key(state);
        if self.body_field.as_ref().is_some_and(|f| f.key() == key) {
            return;
        }
        let document = state.document();
        let (body, hair) = (document.body.clone(), document.hair_mesh.clone());
        let build = std::thread::Builder::new()
            .name("brush body field".into())
            .spawn(move || BodySdf::for_hair(&body, &hair));
        self.body_field = Some(match build {
            Ok(handle) => BodyField::Building(key, handle),
            // No thread to be had: build it here, as the first stroke once did.
            Err(_) => BodyField::Ready {
                key,
                field: Arc::new(BodySdf::for_hair(&document.body, &document.hair_mesh)),
                on_worker: false,
            },
        });
    }

    /// The field once it is built, without waiting (the hover circle).
    fn ready_body_field(&mut self) -> Option<Arc<BodySdf>> {
        if let Some(BodyField::Building(_, handle)) = &self.body_field
            && !handle.is_finished()
        {
            return None;
        }
        self.take_built_field()
    }

    /// The field for the document's body, waiting for a build in flight (a stroke begun
    /// right after choosing Groom).
    fn body_field(&mut self, state: &EditorState) -> Arc<BodySdf> {
        self.prepare_body_field(state);
        if let Some(field) = self.take_built_field() {
            return field;
        }
        // The worker failed: build it here.
        let document = state.document();
        let field = Arc::new(BodySdf::for_hair(&document.body, &document.hair_mesh));
        self.body_field = Some(BodyField::Ready {
            key: self.body_key(state),
            field: field.clone(),
            on_worker: false,
        });
        field
    }

    /// Joins a finished (or, waiting, an unfinished) build and keeps its field; `None` when
    /// there is none or the worker failed.
    fn take_built_field(&mut self) -> Option<Arc<BodySdf>> {
        match self.body_field.take()? {
            BodyField::Ready {
                key,
                field,
                on_worker,
            } => {
                self.body_field = Some(BodyField::Ready {
                    key,
                    field: field.clone(),
                    on_worker,
                });
                Some(field)
            }
            BodyField::Building(key, handle) => match handle.join() {
                Ok(field) => {
                    let field = Arc::new(field);
                    self.body_field = Some(BodyField::Ready {
                        key,
                        field: field.clone(),
                        on_worker: true,
                    });
                    Some(field)
                }
                Err(_) => {
                    self.body_field = Some(BodyField::Failed(key));
                    None
                }
            },
            BodyField::Failed(key) => {
                self.body_field = Some(BodyField::Failed(key));
                None
            }
        }
    }

    /// Whether the brushes' body field is built on the worker thread ("ready"), built on
    /// the UI thread ("ready here"), building, failed, or not asked for ("none"): tests
    /// check that choosing Groom builds it off the UI thread.
    pub fn brush_field_status(&self) -> &'static str {
        match &self.body_field {
            None => "none",
            Some(BodyField::Building(_, handle)) if !handle.is_finished() => "building",
            Some(BodyField::Building(..)) => "built, not yet joined",
            Some(BodyField::Ready {
                on_worker: true, ..
            }) => "ready",
            Some(BodyField::Ready { .. }) => "ready here",
            Some(BodyField::Failed(_)) => "failed",
        }
    }

    /// Ends the stroke, keeping what it did as one undo step.
    fn end_stroke(&mut self, state: &mut EditorState, why: &str) {
        let Some(stroke) = self.stroke.take() else {
            return;
        };
        state.commit_edit();
        let kind = state.tool.brush.label();
        state.message = format!(
            "{kind}: {} dabs{}{why}",
            stroke.dabs,
            if stroke.held_back > 0 && state.tool.brush.paint.is_some() {
                format!(
                    ", {} changed nothing (no scalp under the brush, or the map there already \
                     holds the value)",
                    stroke.held_back
                )
            } else if stroke.held_back > 0 {
                format!(
                    ", {} left the hair as it was (no hair under the brush, or the step would \
                     have turned a layer over, crowded it or reached into the head)",
                    stroke.held_back
                )
            } else {
                String::new()
            }
        );
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
            self.end_stroke(state, " (the drag tool changed)");
            return false;
        }
        // An undo, a redo or any other edit during the stroke ends it (its dabs so far are
        // one step; the next dab would start from a document the stroke did not make).
        if self
            .stroke
            .as_ref()
            .is_some_and(|stroke| stroke.revision != state.revision)
        {
            self.stroke = None;
            state.message = format!(
                "{}: the stroke ended (the document changed under it)",
                state.tool.brush.label()
            );
        }
        let brush = state.tool.brush;
        if self.stroke.is_none() {
            self.prepare_body_field(state);
        }
        // The stroke's field, or before a stroke the one built (the hover circle).
        let field = match &self.stroke {
            Some(stroke) => Some(stroke.field.clone()),
            None => self.ready_body_field(),
        };
        let pointer = response.interact_pointer_pos().or(response.hover_pos());
        let fallback = self.stroke.as_ref().map(|s| s.last_centre);
        let under = pointer.and_then(|p| {
            Some((
                p,
                Self::brush_centre(state, &projector, field.as_deref(), p, fallback)?,
            ))
        });
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
            let field = self.body_field(state);
            // The start is picked again with the field: never a point behind the head.
            let start = pointer.and_then(|p| {
                Some((
                    p,
                    Self::brush_centre(state, &projector, Some(&field), p, None)?,
                ))
            });
            // A map stroke finds each texel's root once, at the maps' size.
            let raster = brush.paint.map(|_| {
                let maps = &state.document().root_maps;
                let (width, height) = if maps.is_empty() {
                    (DEFAULT_ROOT_MAP_SIDE, DEFAULT_ROOT_MAP_SIDE)
                } else {
                    (maps.width(), maps.height())
                };
                Arc::new(RootMapRaster::new(
                    &state.document().hair_mesh,
                    width,
                    height,
                ))
            });
            self.stroke = start.map(|(p, (centre, _))| Stroke {
                last_pointer: p,
                last_centre: centre,
                revision: state.revision,
                field,
                dabs: 0,
                held_back: 0,
                raster,
            });
            if self.stroke.is_none() {
                state.message = format!("{}: start the stroke on the hair", brush.label());
            }
        }
        if self.stroke.is_none() {
            return response.dragged_by(egui::PointerButton::Primary) && !alt;
        }
        if response.drag_stopped() {
            self.end_stroke(state, "");
            return true;
        }
        let (Some((at, _)), Some(stroke)) = (under, self.stroke.as_mut()) else {
            return true;
        };
        if alt {
            // Navigating: the stroke waits, and resumes from where the pointer is then.
            stroke.last_pointer = at;
            return true;
        }
        let spacing_px =
            (self.brush_cursor.map_or(8.0, |c| c.radius_px) * 2.0 * SPACING_OF_DIAMETER).max(2.0);
        let travel = at.distance(stroke.last_pointer);
        if travel < spacing_px {
            return true;
        }
        // Pressure from a pen or touch, where egui reports one.
        let pressure = ui.input(|i| {
            i.events.iter().rev().find_map(|event| match event {
                egui::Event::Touch {
                    force: Some(force), ..
                } => Some(force.clamp(0.0, 1.0) as f64),
                _ => None,
            })
        });
        let invert = ui.input(|i| i.modifiers.command);
        let plane_x = state.document().mirror_plane_x();
        let steps = ((travel / spacing_px) as usize).clamp(1, MAX_DABS_PER_FRAME);
        let from = stroke.last_pointer;
        for step in 1..=steps {
            let Some(stroke) = self.stroke.as_ref() else {
                break;
            };
            let point = from + (at - from) * (step as f32 / steps as f32);
            let field = stroke.field.clone();
            let Some((centre, _)) = Self::brush_centre(
                state,
                &projector,
                Some(&field),
                point,
                Some(stroke.last_centre),
            ) else {
                continue;
            };
            if let (Some(channel), Some(raster)) = (brush.paint, stroke.raster.clone()) {
                let mut maps = state.document().root_maps.clone();
                if maps.is_empty() {
                    maps = RootMaps::blank(DEFAULT_ROOT_MAP_SIDE, DEFAULT_ROOT_MAP_SIDE)
                        .expect("the default side is within the limit");
                }
                // Ctrl paints the unpainted value back: 1, or no colour.
                let value = match (channel, invert) {
                    (RootMapChannel::Colour, true) => 0.0,
                    (RootMapChannel::Colour, false) => brush.colour_weight,
                    (_, true) => 1.0,
                    (_, false) => brush.paint_value,
                };
                let dab = MapDab {
                    channel,
                    centre_m: centre.to_array(),
                    radius_m: brush.radius_m,
                    value,
                    colour_srgb: brush.paint_colour,
                    strength: brush.strength * pressure.unwrap_or(1.0),
                    view_direction: brush.front_only.then(|| projector.ray(point).1.to_array()),
                    mirror_x: brush.mirror_x,
                    mirror_plane_x: plane_x,
                };
                let changed = paint_dab(&mut maps, &raster, &dab);
                let Some(stroke) = self.stroke.as_mut() else {
                    break;
                };
                stroke.last_pointer = point;
                stroke.last_centre = centre;
                if changed == 0 {
                    stroke.held_back += 1;
                } else {
                    stroke.dabs += 1;
                    state.edit(ChangeKind::Restyle, &brush.label()).root_maps = maps;
                    if let Some(stroke) = self.stroke.as_mut() {
                        stroke.revision = state.revision;
                    }
                }
                continue;
            }
            let motion = projector.unproject(point, stroke.last_centre)
                - projector.unproject(stroke.last_pointer, stroke.last_centre);
            let dab = BrushDab {
                kind: brush.kind,
                centre_m: centre.to_array(),
                radius_m: brush.radius_m,
                strength: brush.strength * pressure.unwrap_or(1.0),
                invert,
                motion_m: motion.to_array(),
                view_direction: brush.front_only.then(|| projector.ray(point).1.to_array()),
                mirror_x: brush.mirror_x,
                mirror_plane_x: plane_x,
            };
            let result = apply_brush(&state.document().hair_mesh, &field, &dab);
            let Some(stroke) = self.stroke.as_mut() else {
                break;
            };
            stroke.last_pointer = point;
            stroke.last_centre = centre;
            match result {
                Ok(outcome) if outcome.affected_bundles.is_empty() => stroke.held_back += 1,
                Ok(outcome) => {
                    stroke.dabs += 1;
                    let label = format!("{} brush", brush.kind.label());
                    state.edit(ChangeKind::Reshape, &label).hair_mesh = outcome.mesh;
                    stroke.revision = state.revision;
                }
                Err(error) => state.message = format!("{}: {error}", brush.kind.label()),
            }
        }
        true
    }
}
