//! The styling-direction gizmo (seed 004 §3.1: a local frame of styling directions on a
//! wisp, the active one dragged). Shown at the roots of the selected bundles instead of the
//! move gizmo when View ▸ Styling-direction gizmo is on:
//!
//! - the uvw frame: û red, v̂ green, ŵ blue (the frame generation styles in);
//! - **wave** (yellow): an arrow in the û v̂ plane along the wave's displacement; drag its
//!   tip around the faint track to point the wave;
//! - **twist** (cyan): a ring about ŵ above the roots whose handle sits at the angle the tips
//!   are turned; drag it around (past full turns) to twist the bundle;
//! - **curl** (magenta): a smaller ring about ŵ whose arrowheads show which way the helix
//!   winds; sweep its handle the other way to mirror the curl.
//!
//! A drag edits the styling group the selected bundles share (the global parameters when
//! none is grouped) as one undo step, live; Esc or a right-click cancels it. The maths lives
//! in core (`edit::styling_direction`) with its tests.

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use hairloom_core::edit::styling_direction::{
    StylingAxes, shared_group, solve_in_basis, styling_axes, wave_direction_rad,
};
use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::styling::StylingParams;

use super::Viewport;
use super::camera::Projector;
use crate::app::state::EditorState;

/// The gizmo's arrows are this long on screen, whatever the zoom.
const ARROW_PX: f64 = 70.0;
/// A press this close to a handle grabs it.
const GRAB_PX: f32 = 10.0;
/// The twist ring's radius and height, in arrow lengths.
const TWIST_RING: (f64, f64) = (0.6, 1.0);
/// The curl ring's radius and height, in arrow lengths.
const CURL_RING: (f64, f64) = (0.3, 0.5);
/// A sweep shorter than this (≈ 11°) does not mirror the curl: a click is not a drag.
const CURL_MIN_SWEEP_RAD: f64 = 0.2;

/// A handle of the styling-direction gizmo.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StylingHandle {
    Wave,
    Twist,
    Curl,
}

impl StylingHandle {
    pub fn label(self) -> &'static str {
        match self {
            Self::Wave => "Wave direction",
            Self::Twist => "Twist",
            Self::Curl => "Curl direction",
        }
    }
}

/// The gizmo as placed this frame: the frame it stands in and its size in model units.
#[derive(Clone, Copy, Debug)]
pub(super) struct Placed {
    axes: StylingAxes,
    /// One arrow length, metres.
    arrow_m: f64,
    group: Option<usize>,
}

/// A running drag on one handle.
#[derive(Clone, Debug)]
pub(super) struct StylingDrag {
    handle: StylingHandle,
    placed: Placed,
    /// The pointer's angle about the ring at the last frame (twist and curl), or its wave
    /// direction where the handle was grabbed (so grabbing beside the tip does not snap).
    last: Option<f64>,
    /// The angle swept about ŵ since the drag began.
    swept_rad: f64,
    /// The parameters when the drag began.
    start: StylingParams,
}

/// Screen positions of the gizmo's handles, for the tests to drag.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StylingGizmoHandles {
    pub centre: egui::Pos2,
    pub wave: egui::Pos2,
    pub twist: egui::Pos2,
    /// The centres of the twist and curl rings.
    pub twist_ring: egui::Pos2,
    pub curl_ring: egui::Pos2,
    /// `None` when the group has no curl (nothing winds to mirror).
    pub curl: Option<egui::Pos2>,
}

impl Placed {
    /// Where a ring about ŵ of `(radius, height)` (in arrow lengths) stands: its centre and
    /// its in-plane axes (e₁ along û across ŵ, e₂ = ŵ × e₁, so angles follow the right-hand
    /// rule about ŵ).
    fn ring(&self, (radius, height): (f64, f64)) -> (DVec3, DVec3, DVec3, f64) {
        let axes = &self.axes;
        let e1 = axes
            .u
            .reject_from_normalized(axes.w)
            .try_normalize()
            .unwrap_or_else(|| axes.w.any_orthonormal_vector());
        let e2 = axes.w.cross(e1);
        (
            axes.origin + axes.w * (height * self.arrow_m),
            e1,
            e2,
            radius * self.arrow_m,
        )
    }

    fn on_ring(&self, ring: (f64, f64), angle_rad: f64) -> DVec3 {
        let (centre, e1, e2, radius) = self.ring(ring);
        centre + (angle_rad.cos() * e1 + angle_rad.sin() * e2) * radius
    }

    fn handles(
        &self,
        params: &StylingParams,
        projector: &Projector,
    ) -> Option<StylingGizmoHandles> {
        let axes = &self.axes;
        let tip_rad = axes.tip_twist_about_w_rad(params.twist.turns_per_m);
        Some(StylingGizmoHandles {
            centre: projector.project(axes.origin)?,
            wave: projector.project(
                axes.origin + axes.wave_vector(params.wave.direction_rad) * self.arrow_m,
            )?,
            twist: projector.project(self.on_ring(TWIST_RING, tip_rad))?,
            twist_ring: projector.project(self.ring(TWIST_RING).0)?,
            curl_ring: projector.project(self.ring(CURL_RING).0)?,
            curl: if params.curl.radius_m > 0.0 && params.curl.turns_per_m != 0.0 {
                projector.project(self.on_ring(CURL_RING, std::f64::consts::FRAC_PI_2))
            } else {
                None
            },
        })
    }

    /// The pointer's angle about a ring's centre on screen, as a turn about ŵ: screen
    /// angles (y down) turn clockwise, so they count negatively when ŵ faces the camera.
    /// Measured on screen, like Blender's rotate, so a ring seen at a grazing angle still
    /// turns with the pointer instead of jumping through its far side.
    fn pointer_angle(
        &self,
        ring: (f64, f64),
        projector: &Projector,
        at: egui::Pos2,
    ) -> Option<f64> {
        let centre = projector.project(self.ring(ring).0)?;
        let d = at - centre;
        if d.length() < 2.0 {
            return None;
        }
        let toward_camera = projector.view.row(2).truncate().as_dvec3();
        let sign = if self.axes.w.dot(toward_camera) > 0.0 {
            -1.0
        } else {
            1.0
        };
        Some(sign * f64::from(d.y).atan2(f64::from(d.x)))
    }
}

/// The parameters a gizmo on `group` edits; `None` when the group no longer exists (the
/// document changed under a drag).
fn params_of(state: &EditorState, group: Option<usize>) -> Option<&StylingParams> {
    let styling = &state.document().styling;
    match group {
        None => Some(&styling.global),
        Some(g) => styling.groups.get(g).map(|g| &g.params),
    }
}

/// The name of whose parameters a gizmo edits.
fn whose(state: &EditorState, group: Option<usize>) -> String {
    match group.and_then(|g| state.document().styling.groups.get(g)) {
        Some(g) => format!("group {}", g.name),
        None => "all bundles (global)".into(),
    }
}

impl Viewport {
    /// Places the gizmo on the selected bundles, or says why it cannot stand there.
    /// The frame and group are found once per document revision and selection (the frame
    /// needs the whole root layer's frames), not every frame the gizmo is driven and drawn.
    fn place_styling_gizmo(
        &mut self,
        state: &EditorState,
        projector: &Projector,
    ) -> Result<Placed, String> {
        let bundles: Vec<u32> = state.selection.iter().copied().collect();
        let key = (state.revision, bundles);
        let found = match &self.styling_frame {
            Some((cached, found)) if *cached == key => found.clone(),
            _ => {
                let document = state.document();
                let found = shared_group(&document.styling, &key.1).and_then(|group| {
                    styling_axes(&document.hair_mesh, &key.1)
                        .map(|axes| (axes, group))
                        .ok_or_else(|| {
                            "the selected bundles have no styling frame (collapsed roots)"
                                .to_string()
                        })
                });
                self.styling_frame = Some((key, found.clone()));
                found
            }
        };
        let (axes, group) = found?;
        // Pixels per metre at the roots, along the camera's right.
        let right = projector.view.row(0).truncate().as_dvec3();
        let probe_m = 1e-3;
        let (a, b) = (
            projector.project(axes.origin),
            projector.project(axes.origin + right * probe_m),
        );
        let (Some(a), Some(b)) = (a, b) else {
            return Err("the selected bundles' roots are behind the camera".into());
        };
        let px_per_m = f64::from(a.distance(b)) / probe_m;
        if !(px_per_m.is_finite() && px_per_m > 1e-6) {
            return Err("the selected bundles' roots are out of view".into());
        }
        Ok(Placed {
            axes,
            arrow_m: ARROW_PX / px_per_m,
            group,
        })
    }

    /// The styling-direction gizmo's part of a frame: starts, runs and ends drags on its
    /// handles. `true` when it has the pointer (the press is not a selection click).
    pub(super) fn drive_styling_gizmo(
        &mut self,
        ui: &egui::Ui,
        state: &mut EditorState,
        response: &egui::Response,
        projector: Projector,
    ) -> bool {
        self.styling_handles = None;
        // A cancelled drag keeps the pointer until the button is let go: the rest of the
        // press is not a box selection.
        if self.styling_hold {
            self.styling_hold = ui.input(|i| i.pointer.primary_down());
            return true;
        }
        if let Some(mut drag) = self.styling_drag.take() {
            let cancel = ui.input(|i| i.key_pressed(egui::Key::Escape))
                || response.clicked_by(egui::PointerButton::Secondary);
            let gone = params_of(state, drag.placed.group).is_none();
            if cancel || gone {
                state.cancel_edit();
                state.message = if gone {
                    format!(
                        "{}: the styling group is gone; cancelled",
                        drag.handle.label()
                    )
                } else {
                    format!("{} cancelled", drag.handle.label())
                };
                self.styling_hold = ui.input(|i| i.pointer.primary_down());
                return true;
            }
            if let Some(at) = ui.input(|i| i.pointer.hover_pos()) {
                apply_drag(&mut drag, state, &projector, at);
            }
            self.styling_handles = params_of(state, drag.placed.group)
                .and_then(|params| drag.placed.handles(params, &projector));
            if ui.input(|i| i.pointer.primary_down()) {
                self.styling_drag = Some(drag);
            } else {
                state.commit_edit();
            }
            return true;
        }
        // Alt+drag orbits (a trackpad's middle button), never grabs a handle.
        if ui.input(|i| i.modifiers.alt) {
            return false;
        }
        let placed = match self.place_styling_gizmo(state, &projector) {
            Ok(placed) => placed,
            Err(_) => return false,
        };
        let Some(params) = params_of(state, placed.group).cloned() else {
            return false;
        };
        let Some(handles) = placed.handles(&params, &projector) else {
            return false;
        };
        self.styling_handles = Some(handles);
        let near = |at: egui::Pos2| {
            [
                (StylingHandle::Wave, Some(handles.wave)),
                (StylingHandle::Twist, Some(handles.twist)),
                (StylingHandle::Curl, handles.curl),
            ]
            .into_iter()
            .filter_map(|(handle, pos)| Some((handle, pos?.distance(at))))
            .filter(|(_, d)| *d <= GRAB_PX)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(handle, _)| handle)
        };
        if response.drag_started_by(egui::PointerButton::Primary)
            && let Some(handle) = ui.input(|i| i.pointer.press_origin()).and_then(near)
        {
            state.commit_edit();
            state.stop_playback_for_editing();
            self.drag_path.clear();
            let mut drag = StylingDrag {
                handle,
                placed,
                last: None,
                swept_rad: 0.0,
                start: params,
            };
            // Measured from where the press began, so the handle does not jump to it.
            if let Some(origin) = ui.input(|i| i.pointer.press_origin()) {
                apply_drag(&mut drag, state, &projector, origin);
            }
            if let Some(at) = ui.input(|i| i.pointer.hover_pos()) {
                apply_drag(&mut drag, state, &projector, at);
            }
            state.message = format!(
                "{} of {}: drag around; release to keep, Esc cancels",
                handle.label(),
                whose(state, placed.group)
            );
            self.styling_drag = Some(drag);
            return true;
        }
        ui.input(|i| i.pointer.hover_pos()).and_then(near).is_some()
    }

    /// The handle being dragged, if any (a modal tool: it owns the keyboard).
    pub fn styling_drag(&self) -> Option<StylingHandle> {
        self.styling_drag.as_ref().map(|d| d.handle)
    }

    /// Draws the gizmo over the picture.
    pub(super) fn paint_styling_gizmo(
        &mut self,
        painter: &egui::Painter,
        state: &EditorState,
        projector: &Projector,
    ) {
        let placed = match &self.styling_drag {
            Some(drag) => drag.placed,
            None => match self.place_styling_gizmo(state, projector) {
                Ok(placed) => placed,
                Err(why) => {
                    // Said where the artist looks: over the picture, not in a log.
                    painter.text(
                        projector.rect.left_bottom() + egui::vec2(10.0, -10.0),
                        egui::Align2::LEFT_BOTTOM,
                        format!("Styling-direction gizmo: {why}"),
                        egui::FontId::proportional(13.0),
                        egui::Color32::from_rgb(250, 210, 60),
                    );
                    return;
                }
            },
        };
        let Some(params) = params_of(state, placed.group) else {
            return;
        };
        let project = |p: DVec3| projector.project(p);
        let axes = &placed.axes;
        let Some(centre) = project(axes.origin) else {
            return;
        };
        let arrow = |to: DVec3, colour: egui::Color32, width: f32| {
            if let Some(tip) = project(to) {
                painter.arrow(centre, tip - centre, egui::Stroke::new(width, colour));
            }
        };
        let line = |points: Vec<egui::Pos2>, colour: egui::Color32, width: f32| {
            painter.add(egui::Shape::line(points, egui::Stroke::new(width, colour)));
        };
        let red = egui::Color32::from_rgb(230, 70, 70);
        let green = egui::Color32::from_rgb(110, 200, 80);
        let blue = egui::Color32::from_rgb(80, 140, 240);
        let yellow = egui::Color32::from_rgb(250, 210, 60);
        let cyan = egui::Color32::from_rgb(70, 220, 230);
        let magenta = egui::Color32::from_rgb(230, 90, 220);
        let m = placed.arrow_m;
        for (axis, colour, name) in [
            (axes.u, red, "u"),
            (axes.v, green, "v"),
            (axes.w, blue, "w"),
        ] {
            let reach = if name == "w" { 1.15 } else { 0.8 };
            arrow(axes.origin + axis * m * reach, colour, 1.5);
            if let Some(tip) = project(axes.origin + axis * m * (reach + 0.12)) {
                painter.text(
                    tip,
                    egui::Align2::CENTER_CENTER,
                    name,
                    egui::FontId::proportional(12.0),
                    colour,
                );
            }
        }
        // The wave: its track in the û v̂ plane, the arrow, the handle.
        let track: Vec<_> = (0..=48)
            .filter_map(|i| {
                project(axes.origin + axes.wave_vector(i as f64 / 48.0 * std::f64::consts::TAU) * m)
            })
            .collect();
        line(track, yellow.gamma_multiply(0.35), 1.0);
        let wave_on = params.wave.amplitude_m > 0.0;
        let wave_colour = if wave_on {
            yellow
        } else {
            yellow.gamma_multiply(0.5)
        };
        arrow(
            axes.origin + axes.wave_vector(params.wave.direction_rad) * m,
            wave_colour,
            2.5,
        );
        // A ring about ŵ, with an arc from its start to `angle_rad`.
        let ring = |spec: (f64, f64), colour: egui::Color32, angle_rad: f64| {
            let full: Vec<_> = (0..=48)
                .filter_map(|i| {
                    project(placed.on_ring(spec, i as f64 / 48.0 * std::f64::consts::TAU))
                })
                .collect();
            line(full, colour.gamma_multiply(0.4), 1.0);
            let steps =
                ((angle_rad.abs() / std::f64::consts::TAU * 48.0).ceil() as usize).clamp(1, 480);
            let arc: Vec<_> = (0..=steps)
                .filter_map(|i| project(placed.on_ring(spec, angle_rad * i as f64 / steps as f64)))
                .collect();
            line(arc, colour, 2.5);
        };
        let twist_rad = axes.tip_twist_about_w_rad(params.twist.turns_per_m);
        ring(TWIST_RING, cyan, twist_rad);
        // What the handles hold, in words, where the artist reads (bottom left).
        let whose = whose(state, placed.group);
        let curl = match axes.curl_sense(params.curl.turns_per_m) {
            s if params.curl.radius_m <= 0.0 || s == 0.0 => "no curl".to_string(),
            s if s > 0.0 => "curl counter-clockwise about w".to_string(),
            _ => "curl clockwise about w".to_string(),
        };
        painter.text(
            projector.rect.left_bottom() + egui::vec2(10.0, -10.0),
            egui::Align2::LEFT_BOTTOM,
            format!(
                "{whose}: wave {:.0}° from u{} · twist {:+.2} turns at tips · {curl}",
                params.wave.direction_rad.to_degrees(),
                if wave_on { "" } else { " (amplitude 0)" },
                twist_rad / TAU,
            ),
            egui::FontId::proportional(13.0),
            egui::Color32::WHITE,
        );
        if params.curl.radius_m > 0.0 && params.curl.turns_per_m != 0.0 {
            // Arrowheads along the curl ring the way the helix winds.
            let sense = axes.curl_sense(params.curl.turns_per_m);
            ring(CURL_RING, magenta, 0.0);
            for k in 0..3 {
                let a = k as f64 * std::f64::consts::TAU / 3.0;
                if let (Some(from), Some(to)) = (
                    project(placed.on_ring(CURL_RING, a)),
                    project(placed.on_ring(CURL_RING, a + 0.5 * sense)),
                ) {
                    painter.arrow(from, to - from, egui::Stroke::new(2.0, magenta));
                }
            }
        }
        if let Some(handles) = self.styling_handles {
            painter.circle_filled(handles.wave, 5.0, wave_colour);
            painter.circle_filled(handles.twist, 5.0, cyan);
            if let Some(curl) = handles.curl {
                painter.rect_filled(
                    egui::Rect::from_center_size(curl, egui::vec2(9.0, 9.0)),
                    1.0,
                    magenta,
                );
            }
        }
    }
}

/// Moves the dragged handle with the pointer at `at`, editing the group's parameters. The
/// first call of a drag (at the press) only records where it began.
fn apply_drag(
    drag: &mut StylingDrag,
    state: &mut EditorState,
    projector: &Projector,
    at: egui::Pos2,
) {
    let placed = drag.placed;
    let mut params = drag.start.clone();
    match drag.handle {
        StylingHandle::Wave => {
            let (Some(c), Some(u), Some(v)) = (
                projector.project(placed.axes.origin),
                projector.project(placed.axes.origin + placed.axes.u * placed.arrow_m),
                projector.project(placed.axes.origin + placed.axes.v * placed.arrow_m),
            ) else {
                return;
            };
            let (su, sv, p) = (u - c, v - c, at - c);
            let Some(alpha) = solve_in_basis(
                [su.x.into(), su.y.into()],
                [sv.x.into(), sv.y.into()],
                [p.x.into(), p.y.into()],
            )
            .and_then(|(a, b)| wave_direction_rad(a, b)) else {
                return;
            };
            let Some(grabbed) = drag.last else {
                drag.last = Some(alpha);
                return;
            };
            let turned = (alpha - grabbed + PI).rem_euclid(TAU) - PI;
            let direction = (drag.start.wave.direction_rad + turned + PI).rem_euclid(TAU) - PI;
            // Rounded to a micro-radian: a stored value that reads back as typed.
            params.wave.direction_rad = (direction * 1e6).round() / 1e6;
        }
        StylingHandle::Twist | StylingHandle::Curl => {
            let spec = if drag.handle == StylingHandle::Twist {
                TWIST_RING
            } else {
                CURL_RING
            };
            let Some(now) = placed.pointer_angle(spec, projector, at) else {
                return;
            };
            if let Some(last) = drag.last {
                // Unwrapped: dragging round and round keeps adding turns.
                drag.swept_rad += (now - last + PI).rem_euclid(TAU) - PI;
            }
            drag.last = Some(now);
            if drag.handle == StylingHandle::Twist {
                match placed
                    .axes
                    .twist_after_sweep(drag.start.twist.turns_per_m, drag.swept_rad)
                {
                    Some(turns) => params.twist.turns_per_m = turns,
                    None => {
                        state.message =
                            "Twist: the selected bundles have no length to twist".into();
                        return;
                    }
                }
            } else {
                params.curl.turns_per_m = placed.axes.curl_turns_for_sweep(
                    drag.start.curl.turns_per_m,
                    drag.swept_rad,
                    CURL_MIN_SWEEP_RAD,
                );
            }
        }
    }
    match params_of(state, placed.group) {
        Some(current) if *current != params => {}
        _ => return,
    }
    let document = state.edit(ChangeKind::Restyle, drag.handle.label());
    match placed.group {
        Some(g) => document.styling.groups[g].params = params,
        None => document.styling.global = params,
    }
}
