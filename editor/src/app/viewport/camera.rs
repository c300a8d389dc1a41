//! The viewport camera: the orbit around the hair, the projector between screen and
//! world, framing the selection and Blender-style navigation.

use super::*;

/// Where the camera looks from, around the hair's centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub yaw_rad: f32,
    pub pitch_rad: f32,
    /// Distance relative to the framing distance.
    pub zoom: f32,
    /// Pan offset in units of the hair's size, in the view plane.
    pub pan: [f32; 2],
}

impl Default for Orbit {
    fn default() -> Self {
        Self {
            yaw_rad: 0.64,
            pitch_rad: 0.2,
            zoom: 1.0,
            pan: [0.0, 0.0],
        }
    }
}

impl Orbit {
    pub(super) fn direction(&self) -> Vec3 {
        Vec3::new(
            self.yaw_rad.sin() * self.pitch_rad.cos(),
            self.pitch_rad.sin(),
            self.yaw_rad.cos() * self.pitch_rad.cos(),
        )
    }

    pub fn camera(&self, lo: Vec3, hi: Vec3) -> Camera {
        let pad = (hi - lo) * 0.05;
        let framed = Camera::framing(lo - pad, hi + pad, self.direction());
        let size = (hi - lo).length();
        let forward = (framed.target - framed.eye).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        let up = right.cross(forward);
        let shift = (right * self.pan[0] + up * self.pan[1]) * size;
        let target = framed.target + shift;
        Camera {
            eye: target + (framed.eye - framed.target) * self.zoom,
            target,
            ..framed
        }
    }
}

/// The camera of the last frame: what screen point a model point lands on, and back.
#[derive(Clone, Copy)]
pub(super) struct Projector {
    pub(super) view: glam::Mat4,
    pub(super) view_projection: glam::Mat4,
    pub(super) rect: egui::Rect,
}

impl Projector {
    pub(super) fn project(&self, p: DVec3) -> Option<egui::Pos2> {
        let clip = self.view_projection * p.as_vec3().extend(1.0);
        (clip.w > 1e-6).then(|| {
            let ndc = clip.truncate() / clip.w;
            egui::pos2(
                self.rect.left() + (ndc.x + 1.0) * 0.5 * self.rect.width(),
                self.rect.top() + (1.0 - ndc.y) * 0.5 * self.rect.height(),
            )
        })
    }

    /// Screen position relative to the viewport's corner, and view depth (clip w).
    pub(super) fn project_local_depth(&self, p: DVec3) -> Option<[f64; 3]> {
        let clip = self.view_projection * p.as_vec3().extend(1.0);
        (clip.w > 1e-6).then(|| {
            let ndc = clip.truncate() / clip.w;
            [
                ((ndc.x + 1.0) * 0.5 * self.rect.width()) as f64,
                ((1.0 - ndc.y) * 0.5 * self.rect.height()) as f64,
                clip.w as f64,
            ]
        })
    }

    pub(super) fn project_xy(&self, p: DVec3) -> Option<[f64; 2]> {
        self.project(p).map(|q| [q.x as f64, q.y as f64])
    }

    /// Normalised device x, y of screen position `at`.
    pub(super) fn ndc_xy(&self, at: egui::Pos2) -> (f32, f32) {
        (
            (at.x - self.rect.left()) / self.rect.width().max(1.0) * 2.0 - 1.0,
            1.0 - (at.y - self.rect.top()) / self.rect.height().max(1.0) * 2.0,
        )
    }

    /// The model point at screen position `at`, at the depth (NDC z) of `depth_of`.
    pub(super) fn unproject(&self, at: egui::Pos2, depth_of: DVec3) -> DVec3 {
        let clip = self.view_projection * depth_of.as_vec3().extend(1.0);
        let z = clip.z / clip.w.max(1e-6);
        let (x, y) = self.ndc_xy(at);
        self.view_projection
            .inverse()
            .project_point3(Vec3::new(x, y, z))
            .as_dvec3()
    }

    /// The ray under screen position `at`: origin and direction.
    pub(super) fn ray(&self, at: egui::Pos2) -> (DVec3, DVec3) {
        let inverse = self.view_projection.inverse();
        let (x, y) = self.ndc_xy(at);
        let near = inverse.project_point3(Vec3::new(x, y, 0.0)).as_dvec3();
        let far = inverse.project_point3(Vec3::new(x, y, 1.0)).as_dvec3();
        (near, far - near)
    }
}

impl Viewport {
    /// The camera the picture and overlay use (the mesh's box before the first picture).
    pub(super) fn projector(&self, state: &EditorState, rect: egui::Rect) -> Option<Projector> {
        let (lo, hi) = self.camera_bounds.or_else(|| {
            let (lo, hi) = state.document().hair_mesh.bounds()?;
            Some((lo.as_vec3(), hi.as_vec3()))
        })?;
        let camera = self.orbit.camera(lo, hi);
        Some(Projector {
            view: glam::Mat4::look_at_rh(camera.eye, camera.target, camera.up),
            view_projection: camera.view_projection(rect.width() / rect.height().max(1.0)),
            rect,
        })
    }

    /// Frames the selection (the whole hair without one).
    pub(super) fn frame_selection(&mut self, state: &EditorState) {
        self.orbit.zoom = 1.0;
        self.orbit.pan = [0.0, 0.0];
        let targets = state.transform_targets();
        let mesh = &state.document().hair_mesh;
        let points: Vec<DVec3> = if targets.is_empty() {
            state
                .selection
                .iter()
                .filter_map(|&b| select::bundle_centre(mesh, b))
                .collect()
        } else {
            targets.iter().filter_map(|v| mesh.position(*v)).collect()
        };
        let (Some((lo, hi)), false) = (self.camera_bounds, points.is_empty()) else {
            return;
        };
        let centre = points.iter().sum::<DVec3>() / points.len() as f64;
        let extent = points
            .iter()
            .map(|p| p.distance(centre))
            .fold(0.0, f64::max);
        let camera = self.orbit.camera(lo, hi);
        let forward = (camera.target - camera.eye).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        let up = right.cross(forward);
        let size = (hi - lo).length().max(1e-6);
        let offset = centre.as_vec3() - camera.target;
        self.orbit.pan = [offset.dot(right) / size, offset.dot(up) / size];
        // Room around the selection: its diameter fills about half the view.
        self.orbit.zoom = ((extent as f32 * 4.0) / size).clamp(0.08, 1.0);
    }

    pub(super) fn navigate(&mut self, ui: &egui::Ui, response: &egui::Response) {
        let delta = response.drag_delta();
        let modifiers = ui.input(|i| i.modifiers);
        let navigating = response.dragged_by(egui::PointerButton::Middle)
            || (response.dragged_by(egui::PointerButton::Primary) && modifiers.alt);
        if navigating && delta != egui::Vec2::ZERO {
            if modifiers.shift {
                let scale = 1.0 / response.rect.height().max(1.0);
                self.orbit.pan[0] -= delta.x * scale * self.orbit.zoom;
                self.orbit.pan[1] += delta.y * scale * self.orbit.zoom;
            } else {
                self.orbit.yaw_rad -= delta.x * 0.01;
                self.orbit.pitch_rad = (self.orbit.pitch_rad + delta.y * 0.01).clamp(-1.5, 1.5);
            }
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.orbit.zoom = (self.orbit.zoom * (-scroll * 0.002).exp()).clamp(0.05, 20.0);
            }
            // Front / side / top turn the view and keep its zoom and pan (Blender's numpad).
            ui.input(|i| {
                let mut view = |yaw: f32, pitch: f32| {
                    self.orbit.yaw_rad = yaw;
                    self.orbit.pitch_rad = pitch;
                };
                if i.key_pressed(egui::Key::Num1) {
                    view(0.0, 0.05);
                }
                if i.key_pressed(egui::Key::Num3) {
                    view(std::f32::consts::FRAC_PI_2, 0.05);
                }
                if i.key_pressed(egui::Key::Num7) {
                    view(0.0, 1.5);
                }
            });
        }
    }
}
