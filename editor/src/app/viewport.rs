//! 3D viewport: the document's strands generated on the GPU from its runtime textures every
//! time the document or the view changes (the same path as `hairloom render` and a game),
//! drawn offscreen by the render crate and shown as an egui image.
//!
//! Navigation: drag (left or middle button) orbits, shift+drag pans, the wheel zooms,
//! F frames the hair, numpad 1 / 3 / 7 look from the front / side / top. A click selects the
//! bundle under the pointer (ctrl/shift+click adds or removes it; a click on nothing clears).

use std::sync::Arc;

use eframe::egui_wgpu;
use glam::Vec3;
use hairloom_core::lod::LodSettings;
use hairloom_core::runtime::{Filtering, Precision};
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer};
use hairloom_render::strand_gen::{GpuHair, StrandGenRenderer};

use super::state::EditorState;
use crate::render::{RenderableHair, default_scene};

/// Storage buffers per shader stage the generation and preview pipelines bind.
const MIN_STORAGE_BUFFERS_PER_STAGE: u32 = 8;

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
    fn direction(&self) -> Vec3 {
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

/// What the viewport shows and how it generates strands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSettings {
    /// Overlay the hair mesh: layer faces and columns, interior vertices in a second colour.
    pub wireframe: bool,
    pub strands_per_bundle: u32,
    pub precision: Precision,
    pub filtering: Filtering,
    pub lod: LodSettings,
}

impl Default for ViewSettings {
    fn default() -> Self {
        Self {
            wireframe: false,
            strands_per_bundle: 32,
            precision: Precision::F32,
            filtering: Filtering::Exact,
            lod: LodSettings::default(),
        }
    }
}

struct UploadedHair {
    gpu: GpuHair,
    bounds: (Vec3, Vec3),
    body: hairloom_core::document::BodyMesh,
}

/// GPU resources of the viewport (absent without a wgpu device).
struct GpuView {
    context: GpuContext,
    generator: StrandGenRenderer,
    preview: PreviewRenderer,
    egui_renderer: Arc<egui::mutex::RwLock<egui_wgpu::Renderer>>,
    hair: Option<UploadedHair>,
    texture: Option<(wgpu::Texture, egui::TextureId)>,
}

/// Key of what was last drawn, to draw again only when something changed.
#[derive(Clone, Copy, PartialEq)]
struct DrawnKey {
    revision: u64,
    settings: ViewSettings,
    orbit: Orbit,
    size: [u32; 2],
}

pub struct Viewport {
    gpu: Option<GpuView>,
    pub orbit: Orbit,
    pub settings: ViewSettings,
    uploaded: Option<(u64, ViewSettings)>,
    drawn: Option<DrawnKey>,
    /// Strands and vertices of the last frame, after culling and LOD.
    pub drawn_strands: usize,
    pub drawn_vertices: usize,
    pub adapter: String,
    pub error: Option<String>,
    /// Where the viewport was last drawn, in points (snapshot tests crop to it).
    pub rect: Option<egui::Rect>,
    /// The box the camera frames (the drawn hair's), for picking with the same camera.
    camera_bounds: Option<(Vec3, Vec3)>,
    /// Per column and layer, whether the vertex is interior, for the document revision it
    /// was computed at (the wireframe marks them; recomputed only when the document changes).
    interior: Option<(u64, Vec<Vec<bool>>)>,
}

impl Viewport {
    /// A viewport drawing through eframe's wgpu device, or a placeholder without one.
    pub fn new(render_state: Option<&egui_wgpu::RenderState>) -> Self {
        // Generation needs storage buffers in compute and vertex stages (the WebGPU default
        // of 8); a GL/WebGL2-limited device gets the placeholder and says why.
        let unsupported = render_state.and_then(|state| {
            let limits = state.device.limits();
            (limits.max_storage_buffers_per_shader_stage < MIN_STORAGE_BUFFERS_PER_STAGE).then(
                || {
                    format!(
                        "{}: {} storage buffers per shader stage, the viewport needs {}",
                        describe(&state.adapter.get_info()),
                        limits.max_storage_buffers_per_shader_stage,
                        MIN_STORAGE_BUFFERS_PER_STAGE
                    )
                },
            )
        });
        let render_state = render_state.filter(|_| unsupported.is_none());
        let gpu = render_state.map(|state| {
            let context = GpuContext::from_parts(
                state.adapter.clone(),
                state.device.clone(),
                state.queue.clone(),
            );
            GpuView {
                generator: StrandGenRenderer::new(&context),
                preview: PreviewRenderer::new(&context),
                egui_renderer: state.renderer.clone(),
                context,
                hair: None,
                texture: None,
            }
        });
        Self {
            adapter: gpu.as_ref().map_or_else(
                || unsupported.clone().unwrap_or("no GPU device".into()),
                |g| describe(&g.context.adapter_info),
            ),
            gpu,
            orbit: Orbit::default(),
            settings: ViewSettings::default(),
            uploaded: None,
            drawn: None,
            drawn_strands: 0,
            drawn_vertices: 0,
            error: None,
            rect: None,
            camera_bounds: None,
            interior: None,
        }
    }

    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        let (rect, response) =
            ui.allocate_exact_size(ui.available_size(), egui::Sense::click_and_drag());
        self.rect = Some(rect);
        self.navigate(ui, &response);
        if response.clicked()
            && let Some(pointer) = response.interact_pointer_pos()
        {
            self.select_at(ui, state, rect, pointer);
        }
        let Some(gpu) = self.gpu.as_mut() else {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "No GPU device: the viewport is off (hairloom render still works)",
                egui::FontId::proportional(14.0),
                ui.visuals().weak_text_color(),
            );
            return;
        };
        // The overlay does not change the picture: leave it out of what triggers GPU work.
        let settings = ViewSettings {
            wireframe: false,
            ..self.settings
        };
        let key = (state.revision, settings);
        if self.uploaded != Some(key) {
            let hair = RenderableHair::from_document(
                state.document(),
                self.settings.precision,
                self.settings.strands_per_bundle,
            );
            gpu.hair = hair.textures.hair_bounds().map(|bounds| UploadedHair {
                gpu: hair.upload(&gpu.context, &gpu.generator),
                bounds,
                body: hair.body,
            });
            self.uploaded = Some(key);
            self.drawn = None;
        }
        let pixels_per_point = ui.ctx().pixels_per_point();
        let size = [
            ((rect.width() * pixels_per_point).round() as u32).clamp(1, 8192),
            ((rect.height() * pixels_per_point).round() as u32).clamp(1, 8192),
        ];
        let drawn = DrawnKey {
            revision: state.revision,
            settings,
            orbit: self.orbit,
            size,
        };
        if self.drawn != Some(drawn) {
            self.error = None;
            match gpu.hair.as_ref() {
                Some(hair) => {
                    let (lo, hi) = hair.bounds;
                    self.camera_bounds = Some(hair.bounds);
                    let scene = default_scene(
                        &hair.body,
                        HairSource::Generated {
                            generator: &gpu.generator,
                            hair: &hair.gpu,
                            filtering: self.settings.filtering,
                            lod: self.settings.lod,
                        },
                        17,
                        hair.bounds,
                        self.orbit.camera(lo, hi),
                    );
                    let plan = gpu.preview.plan(&scene, size[0], size[1]);
                    self.drawn_strands = plan.strands;
                    self.drawn_vertices = plan.vertices;
                    match gpu
                        .preview
                        .render_texture(&gpu.context, &scene, &plan, size[0], size[1])
                    {
                        Ok(texture) => {
                            // egui composites gamma-encoded bytes: sample the sRGB image raw.
                            let view = texture.create_view(&wgpu::TextureViewDescriptor {
                                format: Some(PreviewRenderer::UI_VIEW_FORMAT),
                                ..Default::default()
                            });
                            let mut renderer = gpu.egui_renderer.write();
                            let id = match gpu.texture.take() {
                                Some((_, id)) => {
                                    renderer.update_egui_texture_from_wgpu_texture(
                                        &gpu.context.device,
                                        &view,
                                        wgpu::FilterMode::Linear,
                                        id,
                                    );
                                    id
                                }
                                None => renderer.register_native_texture(
                                    &gpu.context.device,
                                    &view,
                                    wgpu::FilterMode::Linear,
                                ),
                            };
                            gpu.texture = Some((texture, id));
                        }
                        Err(error) => self.error = Some(error.to_string()),
                    }
                }
                None => self.error = Some("no bundle grows hair".into()),
            }
            self.drawn = Some(drawn);
        }
        match (&gpu.texture, &self.error) {
            (_, Some(error)) => {
                ui.painter().text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    error,
                    egui::FontId::proportional(14.0),
                    ui.visuals().error_fg_color,
                );
            }
            (Some((_, id)), None) => {
                ui.painter().image(
                    *id,
                    rect,
                    egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                    egui::Color32::WHITE,
                );
            }
            (None, None) => {}
        }
        self.paint_overlay(ui, state, rect);
    }

    /// The hair-mesh wireframe (when on) and the selected bundles' outlines, drawn over the
    /// picture with the picture's camera (not depth-tested: an X-ray view).
    fn paint_overlay(&mut self, ui: &egui::Ui, state: &EditorState, rect: egui::Rect) {
        let mesh = &state.document().hair_mesh;
        let Some((lo, hi)) = self.camera_bounds else {
            return;
        };
        let view_projection = self
            .orbit
            .camera(lo, hi)
            .view_projection(rect.width() / rect.height().max(1.0));
        let project = |p: glam::DVec3| -> Option<egui::Pos2> {
            let clip = view_projection * p.as_vec3().extend(1.0);
            (clip.w > 1e-6).then(|| {
                let ndc = clip.truncate() / clip.w;
                egui::pos2(
                    rect.left() + (ndc.x + 1.0) * 0.5 * rect.width(),
                    rect.top() + (1.0 - ndc.y) * 0.5 * rect.height(),
                )
            })
        };
        let painter = ui.painter_at(rect);
        let outline = |bundle: &hairloom_core::Bundle, stroke: egui::Stroke| {
            for layer in 0..=bundle.layers as usize {
                let corners: Vec<_> = bundle
                    .vertices
                    .iter()
                    .filter_map(|&c| project(*mesh.columns.get(c as usize)?.positions.get(layer)?))
                    .collect();
                if corners.len() == bundle.vertices.len() {
                    painter.add(egui::Shape::closed_line(corners, stroke));
                }
            }
            for &c in &bundle.vertices {
                let Some(column) = mesh.columns.get(c as usize) else {
                    continue;
                };
                let points: Vec<_> = column.positions
                    [..=(bundle.layers as usize).min(column.positions.len() - 1)]
                    .iter()
                    .filter_map(|p| project(*p))
                    .collect();
                painter.add(egui::Shape::line(points, stroke));
            }
        };
        if self.settings.wireframe {
            let stroke = egui::Stroke::new(
                1.0,
                egui::Color32::from_rgba_unmultiplied(120, 170, 230, 110),
            );
            for bundle in mesh.bundles.iter().filter(|b| !b.removed) {
                outline(bundle, stroke);
            }
            if self
                .interior
                .as_ref()
                .is_none_or(|(r, _)| *r != state.revision)
            {
                let topology = hairloom_core::Topology::build(mesh);
                let interior = (0..mesh.columns.len())
                    .map(|c| {
                        (0..mesh.columns[c].positions.len())
                            .map(|layer| mesh.is_interior(&topology, c, layer))
                            .collect()
                    })
                    .collect();
                self.interior = Some((state.revision, interior));
            }
            let interior = self.interior.as_ref().map(|(_, i)| i);
            for (c, column) in mesh.columns.iter().enumerate() {
                for (layer, p) in column.positions.iter().enumerate() {
                    let Some(at) = project(*p) else { continue };
                    let is_interior = interior
                        .and_then(|i| i.get(c)?.get(layer).copied())
                        .unwrap_or(false);
                    let colour = if is_interior {
                        egui::Color32::from_rgb(240, 200, 80) // placed automatically
                    } else {
                        egui::Color32::from_rgb(120, 200, 255) // shaped by the artist
                    };
                    painter.circle_filled(at, 1.8, colour);
                }
            }
        }
        let selected = egui::Stroke::new(1.5, egui::Color32::from_rgb(255, 150, 40));
        for &b in &state.selection {
            if let Some(bundle) = mesh.bundles.get(b as usize) {
                outline(bundle, selected);
            }
        }
    }

    /// Selects the bundle under `pointer` (see the module documentation).
    fn select_at(
        &self,
        ui: &egui::Ui,
        state: &mut EditorState,
        rect: egui::Rect,
        pointer: egui::Pos2,
    ) {
        let Some((lo, hi)) = self.camera_bounds.or_else(|| {
            let (lo, hi) = state.document().hair_mesh.bounds()?;
            Some((lo.as_vec3(), hi.as_vec3()))
        }) else {
            return;
        };
        let camera = self.orbit.camera(lo, hi);
        let inverse = camera
            .view_projection(rect.width() / rect.height().max(1.0))
            .inverse();
        let x = (pointer.x - rect.left()) / rect.width().max(1.0) * 2.0 - 1.0;
        let y = 1.0 - (pointer.y - rect.top()) / rect.height().max(1.0) * 2.0;
        let near = inverse.project_point3(Vec3::new(x, y, 0.0)).as_dvec3();
        let far = inverse.project_point3(Vec3::new(x, y, 1.0)).as_dvec3();
        let hit = hairloom_core::pick::pick_bundle(&state.document().hair_mesh, near, far - near);
        let add = ui.input(|i| i.modifiers.command || i.modifiers.shift);
        match hit {
            Some((bundle, _)) => {
                if !add {
                    state.selection.clear();
                }
                if !state.selection.insert(bundle) {
                    state.selection.remove(&bundle);
                }
                state.message = format!("bundle {bundle}");
            }
            None if !add => state.selection.clear(),
            None => {}
        }
    }

    fn navigate(&mut self, ui: &egui::Ui, response: &egui::Response) {
        let delta = response.drag_delta();
        if response.dragged() && delta != egui::Vec2::ZERO {
            if ui.input(|i| i.modifiers.shift) {
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
            ui.input(|i| {
                if i.key_pressed(egui::Key::F) {
                    self.orbit.zoom = 1.0;
                    self.orbit.pan = [0.0, 0.0];
                }
                let view = |yaw: f32, pitch: f32| Orbit {
                    yaw_rad: yaw,
                    pitch_rad: pitch,
                    ..Orbit::default()
                };
                if i.key_pressed(egui::Key::Num1) {
                    self.orbit = view(0.0, 0.05);
                }
                if i.key_pressed(egui::Key::Num3) {
                    self.orbit = view(std::f32::consts::FRAC_PI_2, 0.05);
                }
                if i.key_pressed(egui::Key::Num7) {
                    self.orbit = view(0.0, 1.5);
                }
            });
        }
    }
}
