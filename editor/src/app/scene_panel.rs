//! Scene panel: every effect's switch with its measured cost beside it (what the frame costs
//! with the effect and without, timed on a worker thread), the hair material, the lights
//! (each with a direction widget) and the environment. Every change is an undoable scene edit
//! (a drag is one step), validated with the field named; the viewport draws it on the next
//! frame.

use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::motion::Motion;
use hairloom_core::model::scene::{
    Coverage, Effects, FIBRE_OFFSET_CHOICES, FarHair, Fur, HairMaterial, Light, LightSource,
    MAX_LIGHTS, MultipleScattering, OPACITY_LAYER_CHOICES, Ombre, Pigment, Scene, SelfShadowing,
    Shading,
};
use hairloom_render::measure::EffectCost;

use super::state::EditorState;
use super::viewport::{EffectCostResult, Viewport};

#[derive(Default)]
pub struct ScenePanel {
    /// The last cost measurement: the document revision it was made at and the costs.
    pub costs: Option<(u64, EffectCostResult)>,
    measuring: Option<(u64, std::sync::mpsc::Receiver<EffectCostResult>)>,
}

/// Applies `change` to the scene as one edit named `label`; a change that leaves the scene
/// invalid is undone and named in the status bar. Drags commit on release.
fn edit_scene(
    state: &mut EditorState,
    response: &egui::Response,
    label: &str,
    change: impl FnOnce(&mut Scene),
) {
    if response.changed() {
        let before = state.document().scene.clone();
        let document = state.edit(ChangeKind::Scene, label);
        change(&mut document.scene);
        if let Err(error) = document.scene.validate() {
            document.scene = before;
            state.message = format!("scene.{error}");
        }
    }
    if response.drag_stopped() || (response.changed() && !response.dragged()) {
        state.commit_edit();
    }
}

impl ScenePanel {
    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState, viewport: &Viewport) {
        self.receive(ui);
        ui.heading("Motion");
        motion_ui(ui, state);
        ui.separator();
        ui.heading("Effects");
        self.effects_ui(ui, state, viewport);
        ui.separator();
        egui::CollapsingHeader::new("Hair material")
            .default_open(true)
            .show(ui, |ui| material_ui(ui, state));
        egui::CollapsingHeader::new("Lights")
            .default_open(true)
            .show(ui, |ui| lights_ui(ui, state));
        egui::CollapsingHeader::new("Environment")
            .default_open(false)
            .show(ui, |ui| environment_ui(ui, state));
    }

    /// A finished measurement lands here (the worker never touches the panel).
    fn receive(&mut self, ui: &egui::Ui) {
        if let Some((revision, receiver)) = &self.measuring {
            match receiver.try_recv() {
                Ok(result) => {
                    self.costs = Some((*revision, result));
                    self.measuring = None;
                }
                Err(std::sync::mpsc::TryRecvError::Empty) => {
                    ui.ctx()
                        .request_repaint_after(std::time::Duration::from_millis(100));
                }
                Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                    self.costs = Some((*revision, Err("the measurement stopped".into())));
                    self.measuring = None;
                }
            }
        }
    }

    /// The cost of switching `name`: what it adds when on, what it would add when off.
    fn cost_label(&self, state: &EditorState, name: &str, on: bool) -> String {
        let Some((revision, Ok(costs))) = &self.costs else {
            return String::new();
        };
        if *revision != state.revision {
            return String::new();
        }
        let (Some(scene), Some(switched)) = (
            costs.first(),
            costs.iter().find(|c: &&EffectCost| c.name == name),
        ) else {
            return String::new();
        };
        let (with, without) = if on {
            (scene.frame_ms, switched.frame_ms)
        } else {
            (switched.frame_ms, scene.frame_ms)
        };
        let cost = with - without;
        // Differences within a few percent of the frame are the machine's noise.
        let noise = 0.03 * scene.frame_ms.max(switched.frame_ms);
        match (on, cost.abs() < noise) {
            (true, true) => format!("costs ≈ 0 ms (< {noise:.0} ms)"),
            (false, true) => format!("would add ≈ 0 ms (< {noise:.0} ms)"),
            (true, false) => format!("costs {cost:.1} ms"),
            (false, false) => format!("would add {cost:.1} ms"),
        }
    }

    fn effects_ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState, viewport: &Viewport) {
        let effects = state.document().scene.effects.clone();
        egui::Grid::new("scene effects")
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                let mut shading = effects.shading;
                let response = egui::ComboBox::from_label("Shading")
                    .selected_text(match shading {
                        Shading::KajiyaKay => "Kajiya-Kay",
                        Shading::Marschner => "Marschner (R / TT / TRT)",
                    })
                    .show_ui(ui, |ui| {
                        ui.selectable_value(&mut shading, Shading::KajiyaKay, "Kajiya-Kay")
                            | ui.selectable_value(
                                &mut shading,
                                Shading::Marschner,
                                "Marschner (R / TT / TRT)",
                            )
                    });
                if let Some(inner) = response.inner {
                    edit_scene(state, &inner, "Scene: shading", |s| {
                        s.effects.shading = shading
                    });
                }
                ui.weak(self.cost_label(state, "marschner", effects.shading == Shading::Marschner));
                ui.end_row();

                let mut shadowing = effects.self_shadowing;
                let response = egui::ComboBox::from_label("Self-shadowing")
                    .selected_text(shadowing_name(shadowing))
                    .show_ui(ui, |ui| {
                        let mut any =
                            ui.selectable_value(&mut shadowing, SelfShadowing::None, "None");
                        for kind in [
                            SelfShadowing::OpacityShadowMaps,
                            SelfShadowing::DeepOpacityMaps,
                        ] {
                            any |= ui.selectable_value(&mut shadowing, kind, shadowing_name(kind));
                        }
                        any
                    });
                if let Some(inner) = response.inner {
                    edit_scene(state, &inner, "Scene: self-shadowing", |s| {
                        s.effects.self_shadowing = shadowing
                    });
                }
                ui.weak(self.cost_label(
                    state,
                    "self-shadowing",
                    effects.self_shadowing != SelfShadowing::None,
                ));
                ui.end_row();

                let mut body_shadows = effects.body_shadows;
                let response = ui.checkbox(&mut body_shadows, "Body shadows");
                edit_scene(state, &response, "Scene: body shadows", |s| {
                    s.effects.body_shadows = body_shadows
                });
                ui.weak(self.cost_label(state, "body-shadows", effects.body_shadows));
                ui.end_row();

                let mut dual = effects.multiple_scattering == MultipleScattering::DualScattering;
                let response = ui
                    .add_enabled(
                        effects.shading == Shading::Marschner,
                        egui::Checkbox::new(&mut dual, "Dual scattering"),
                    )
                    .on_disabled_hover_text("dual scattering extends the Marschner model");
                edit_scene(state, &response, "Scene: dual scattering", |s| {
                    s.effects.multiple_scattering = if dual {
                        MultipleScattering::DualScattering
                    } else {
                        MultipleScattering::None
                    }
                });
                ui.weak(self.cost_label(
                    state,
                    "dual-scattering",
                    effects.multiple_scattering == MultipleScattering::DualScattering,
                ));
                ui.end_row();

                let mut oit = effects.coverage == Coverage::WidthOit;
                let response = ui
                    .checkbox(&mut oit, "Width-based coverage (OIT)")
                    .on_hover_text(
                        "strands thinner than a pixel drawn a pixel wide with their true \
                         coverage, blended order-independently: no aliasing or popping",
                    );
                edit_scene(state, &response, "Scene: coverage", |s| {
                    s.effects.coverage = if oit {
                        Coverage::WidthOit
                    } else {
                        Coverage::Msaa
                    }
                });
                ui.weak(self.cost_label(
                    state,
                    "width-oit",
                    effects.coverage == Coverage::WidthOit,
                ));
                ui.end_row();

                let mut far = effects.far_hair == FarHair::Aggregated;
                let response = ui
                    .checkbox(&mut far, "Far hair (aggregated)")
                    .on_hover_text(
                        "bundles whose strands would be thinner than the far width draw a few \
                         thick hairs each, shaded as the clusters they stand for (seed 001); \
                         building the hierarchy takes a moment the first time",
                    );
                edit_scene(state, &response, "Scene: far hair", |s| {
                    s.effects.far_hair = if far {
                        FarHair::Aggregated
                    } else {
                        FarHair::Strands
                    }
                });
                ui.weak(self.cost_label(
                    state,
                    "far-hair",
                    effects.far_hair == FarHair::Aggregated,
                ));
                ui.end_row();

                let mut fur = effects.fur == Fur::ShellsFins;
                let response = ui.checkbox(&mut fur, "Fur (shells + fins)").on_hover_text(
                    "where the hair looks short on screen, shells along the hair mesh's \
                         columns and fins at its silhouette draw it, textured from a volume \
                         of real strands (seed 002); strands near, cross-faded by distance",
                );
                edit_scene(state, &response, "Scene: fur", |s| {
                    s.effects.fur = if fur { Fur::ShellsFins } else { Fur::Off }
                });
                ui.weak(self.cost_label(state, "fur", effects.fur == Fur::ShellsFins));
                ui.end_row();
            });
        ui.add_enabled_ui(effects.shading == Shading::Marschner, |ui| {
            let mut offsets = effects.fibre_offsets;
            let response = egui::ComboBox::from_label("Thin-fibre offsets")
                .selected_text(offsets.to_string())
                .show_ui(ui, |ui| {
                    let mut any = None::<egui::Response>;
                    for choice in FIBRE_OFFSET_CHOICES {
                        let r = ui.selectable_value(&mut offsets, choice, choice.to_string());
                        any = Some(match any {
                            Some(a) => a | r,
                            None => r,
                        });
                    }
                    any
                });
            response.response.on_hover_text(
                "offsets averaged across strands thinner than two pixels (Gauss-Legendre \
                 points): each is one more fibre evaluation per light",
            );
            if let Some(Some(inner)) = response.inner {
                edit_scene(state, &inner, "Scene: thin-fibre offsets", |s| {
                    s.effects.fibre_offsets = offsets
                });
            }
        });
        ui.add_enabled_ui(effects.needs_shadow_maps(), |ui| {
            ui.horizontal_wrapped(|ui| {
                let mut layers = effects.opacity_layers;
                let response = egui::ComboBox::from_label("Opacity layers")
                    .selected_text(layers.to_string())
                    .show_ui(ui, |ui| {
                        let mut any = None::<egui::Response>;
                        for choice in OPACITY_LAYER_CHOICES {
                            let r = ui.selectable_value(&mut layers, choice, choice.to_string());
                            any = Some(match any {
                                Some(a) => a | r,
                                None => r,
                            });
                        }
                        any
                    });
                if let Some(Some(inner)) = response.inner {
                    edit_scene(state, &inner, "Scene: opacity layers", |s| {
                        s.effects.opacity_layers = layers
                    });
                }
                let mut resolution = effects.shadow_resolution;
                let response = egui::ComboBox::from_label("Shadow map")
                    .selected_text(format!("{resolution}²"))
                    .show_ui(ui, |ui| {
                        let mut any = None::<egui::Response>;
                        for choice in [256, 512, 1024, 2048, 4096] {
                            let r =
                                ui.selectable_value(&mut resolution, choice, format!("{choice}²"));
                            any = Some(match any {
                                Some(a) => a | r,
                                None => r,
                            });
                        }
                        any
                    });
                if let Some(Some(inner)) = response.inner {
                    edit_scene(state, &inner, "Scene: shadow map size", |s| {
                        s.effects.shadow_resolution = resolution
                    });
                }
            });
        });
        ui.horizontal(|ui| {
            let measure = ui
                .add_enabled(
                    viewport.has_gpu() && self.measuring.is_none(),
                    egui::Button::new("Measure costs"),
                )
                .on_hover_text(
                    "Times this viewport's frame with the scene's effects, then with each \
                     effect switched, on a worker thread",
                );
            if measure.clicked()
                && let Some(receiver) = viewport.spawn_effect_costs(state.document(), ui.ctx())
            {
                self.measuring = Some((state.revision, receiver));
            }
            if self.measuring.is_some() {
                ui.spinner();
                ui.weak("measuring…");
                return;
            }
            match &self.costs {
                Some((_, Err(error))) => {
                    ui.colored_label(ui.visuals().error_fg_color, error);
                }
                Some((revision, Ok(_))) if *revision != state.revision => {
                    ui.weak("the scene changed since the last measurement");
                }
                Some((_, Ok(costs))) => {
                    if let Some(scene) = costs.first() {
                        ui.weak(format!(
                            "frame {:.1} ms, {:.1} MB on {}",
                            scene.frame_ms,
                            scene.live_bytes as f64 / 1e6,
                            viewport.adapter
                        ));
                    }
                }
                None => {
                    ui.weak("costs not measured yet");
                }
            }
        });
    }
}

fn shadowing_name(kind: SelfShadowing) -> &'static str {
    match kind {
        SelfShadowing::None => "None",
        SelfShadowing::OpacityShadowMaps => "Opacity shadow maps",
        SelfShadowing::DeepOpacityMaps => "Deep opacity maps",
    }
}

type MaterialField = fn(&mut HairMaterial) -> &mut f32;

fn material_ui(ui: &mut egui::Ui, state: &mut EditorState) {
    let material = state.document().scene.material.clone();
    // The pigment: melanin, a colour, or absorption.
    let kinds = ["Melanin", "Colour", "Absorption"];
    let kind = match material.pigment {
        Pigment::Melanin { .. } => 0,
        Pigment::Color { .. } => 1,
        Pigment::Absorption { .. } => 2,
    };
    let mut chosen = kind;
    let response = egui::ComboBox::from_label("Pigment")
        .selected_text(kinds[kind])
        .show_ui(ui, |ui| {
            let mut any = ui.selectable_value(&mut chosen, 0, kinds[0]);
            any |= ui.selectable_value(&mut chosen, 1, kinds[1]);
            any | ui.selectable_value(&mut chosen, 2, kinds[2])
        });
    if let Some(inner) = response.inner
        && chosen != kind
    {
        // Convert so the hair keeps its look: every pigment becomes the same absorption.
        let fibre = hairloom_core::light::material::Fibre::new(&material);
        let sigma_a = fibre.sigma_a_root;
        let pigment = match chosen {
            0 => Pigment::Melanin {
                eumelanin: 1.0,
                pheomelanin: 0.3,
            },
            1 => Pigment::Color {
                rgb: fibre.color(sigma_a).map(|c| c as f32),
            },
            _ => Pigment::Absorption {
                sigma_a: sigma_a.map(|s| s as f32),
            },
        };
        edit_scene(state, &inner, "Scene: pigment", |s| {
            s.material.pigment = pigment
        });
    }
    match material.pigment {
        Pigment::Melanin {
            eumelanin,
            pheomelanin,
        } => {
            let (mut eu, mut pheo) = (eumelanin, pheomelanin);
            let r = ui.add(
                egui::Slider::new(&mut eu, 0.0..=8.0)
                    .logarithmic(true)
                    .smallest_positive(0.01)
                    .text("Eumelanin")
                    .clamping(egui::SliderClamping::Never),
            );
            edit_scene(state, &r, "Scene: eumelanin", |s| {
                s.material.pigment = Pigment::Melanin {
                    eumelanin: eu,
                    pheomelanin: pheo,
                }
            });
            let r = ui.add(
                egui::Slider::new(&mut pheo, 0.0..=4.0)
                    .logarithmic(true)
                    .smallest_positive(0.01)
                    .text("Pheomelanin")
                    .clamping(egui::SliderClamping::Never),
            );
            edit_scene(state, &r, "Scene: pheomelanin", |s| {
                s.material.pigment = Pigment::Melanin {
                    eumelanin: eu,
                    pheomelanin: pheo,
                }
            });
        }
        Pigment::Color { rgb } => {
            let mut rgb = rgb;
            let r = ui
                .horizontal(|ui| {
                    let r = ui.color_edit_button_rgb(&mut rgb);
                    ui.label("Hair colour");
                    r
                })
                .inner;
            edit_scene(state, &r, "Scene: hair colour", |s| {
                s.material.pigment = Pigment::Color { rgb }
            });
        }
        Pigment::Absorption { sigma_a } => {
            let mut sigma_a = sigma_a;
            ui.horizontal(|ui| {
                ui.label("Absorption σa (r, g, b)");
                for c in 0..3 {
                    let r = ui.add(
                        egui::DragValue::new(&mut sigma_a[c])
                            .speed(0.01)
                            .range(0.0..=1000.0),
                    );
                    edit_scene(state, &r, "Scene: absorption", |s| {
                        s.material.pigment = Pigment::Absorption { sigma_a }
                    });
                }
            });
        }
    }
    let sliders: [(&str, MaterialField, (f32, f32), &str); 6] = [
        (
            "Longitudinal roughness",
            |m| &mut m.longitudinal_roughness,
            (0.0, 1.0),
            "",
        ),
        (
            "Azimuthal roughness",
            |m| &mut m.azimuthal_roughness,
            (0.0, 1.0),
            "",
        ),
        (
            "Cuticle tilt",
            |m| &mut m.cuticle_tilt_deg,
            (-10.0, 10.0),
            "°",
        ),
        ("Index of refraction", |m| &mut m.ior, (1.0, 2.5), ""),
        (
            "Tip absorption",
            |m| &mut m.tip_absorption_factor,
            (0.0, 2.0),
            "×",
        ),
        (
            "Strand variation",
            |m| &mut m.strand_absorption_variation,
            (0.0, 1.0),
            "",
        ),
    ];
    for (label, field, (lo, hi), suffix) in sliders {
        let mut value = *field(&mut material.clone());
        let r = ui.add(
            egui::Slider::new(&mut value, lo..=hi)
                .text(label)
                .suffix(suffix)
                .clamping(egui::SliderClamping::Never),
        );
        edit_scene(
            state,
            &r,
            &format!("Scene: {}", label.to_lowercase()),
            |s| *field(&mut s.material) = value,
        );
    }
    ombre_ui(ui, state, material.ombre);
}

/// Colour along the strand: on, the tip colour and where along the strand it turns. Each
/// slider keeps the span ordered (moving the start past the end takes the end along).
fn ombre_ui(ui: &mut egui::Ui, state: &mut EditorState, ombre: Option<Ombre>) {
    let mut on = ombre.is_some();
    let r = ui.checkbox(&mut on, "Ombré").on_hover_text(
        "Colour along the strand: toward the tip the hair turns from its own (or painted) \
         colour to the tip colour",
    );
    edit_scene(state, &r, "Scene: ombré", |s| {
        s.material.ombre = on.then(Ombre::default)
    });
    let Some(ombre) = ombre else {
        return;
    };
    let mut tip_rgb = ombre.tip_rgb;
    let r = ui
        .horizontal(|ui| {
            let r = ui.color_edit_button_rgb(&mut tip_rgb);
            ui.label("Tip colour");
            r
        })
        .inner;
    edit_scene(state, &r, "Scene: tip colour", |s| {
        if let Some(o) = &mut s.material.ombre {
            o.tip_rgb = tip_rgb;
        }
    });
    let (mut start, mut end) = (ombre.start, ombre.end);
    let r = ui.add(
        egui::Slider::new(&mut start, 0.0..=1.0)
            .text("Ombré starts")
            .suffix(" of the length"),
    );
    edit_scene(state, &r, "Scene: ombré starts", |s| {
        if let Some(o) = &mut s.material.ombre {
            o.start = start;
            o.end = o.end.max(start);
        }
    });
    let r = ui.add(
        egui::Slider::new(&mut end, 0.0..=1.0)
            .text("Ombré ends")
            .suffix(" of the length"),
    );
    edit_scene(state, &r, "Scene: ombré ends", |s| {
        if let Some(o) = &mut s.material.ombre {
            o.end = end;
            o.start = o.start.min(end);
        }
    });
}

/// Azimuth (about the up axis, from +Z toward +X) and elevation of a direction, in degrees.
fn angles(v: [f32; 3]) -> (f32, f32) {
    let v = glam::Vec3::from(v).normalize_or(glam::Vec3::Y);
    (
        v.x.atan2(v.z).to_degrees(),
        v.y.clamp(-1.0, 1.0).asin().to_degrees(),
    )
}

fn direction_from(azimuth_deg: f32, elevation_deg: f32) -> [f32; 3] {
    let (a, e) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    [e.cos() * a.sin(), e.sin(), e.cos() * a.cos()]
}

/// A disk showing where the light comes from seen from above-front (drag to aim it).
fn direction_widget(ui: &mut egui::Ui, direction: &mut [f32; 3]) -> egui::Response {
    let size = egui::vec2(64.0, 64.0);
    let (rect, mut response) = ui.allocate_exact_size(size, egui::Sense::drag());
    let center = rect.center();
    let radius = rect.width() * 0.45;
    if let Some(pointer) = response.interact_pointer_pos() {
        let offset = (pointer - center) / radius;
        let planar = offset.length().min(1.0);
        let scale = if offset.length() > 1.0 {
            1.0 / offset.length()
        } else {
            1.0
        };
        let (x, z) = (offset.x * scale, offset.y * scale);
        let y = (1.0 - planar * planar).max(0.0).sqrt();
        *direction = [x, y.max(0.05), z];
        response.mark_changed();
    }
    let painter = ui.painter_at(rect);
    let visuals = ui.visuals();
    painter.circle_stroke(center, radius, visuals.widgets.noninteractive.fg_stroke);
    let v = glam::Vec3::from(*direction).normalize_or(glam::Vec3::Y);
    let dot = center + egui::vec2(v.x, v.z) * radius;
    let color = if v.y >= 0.0 {
        visuals.selection.bg_fill
    } else {
        visuals.weak_text_color()
    };
    painter.line_segment([center, dot], egui::Stroke::new(1.0, color));
    painter.circle_filled(dot, 4.0, color);
    response.on_hover_text("where the light comes from, seen from above (front is down)")
}

fn lights_ui(ui: &mut egui::Ui, state: &mut EditorState) {
    let lights = state.document().scene.lights.clone();
    let mut remove = None;
    for (i, light) in lights.iter().enumerate() {
        egui::CollapsingHeader::new(format!("Light {}: {}", i + 1, light.name))
            .id_salt(("light", i))
            .default_open(i == 0)
            .show(ui, |ui| {
                if let LightSource::Directional { to_light } = light.source {
                    let mut direction = to_light;
                    ui.horizontal(|ui| {
                        let r = direction_widget(ui, &mut direction);
                        edit_scene(state, &r, "Scene: light direction", |s| {
                            s.lights[i].source = LightSource::Directional {
                                to_light: direction,
                            }
                        });
                        ui.vertical(|ui| {
                            let (mut azimuth, mut elevation) = angles(to_light);
                            let r = ui.add(
                                egui::Slider::new(&mut azimuth, -180.0..=180.0)
                                    .text("Azimuth")
                                    .suffix("°"),
                            );
                            edit_scene(state, &r, "Scene: light direction", |s| {
                                s.lights[i].source = LightSource::Directional {
                                    to_light: direction_from(azimuth, elevation),
                                }
                            });
                            let r = ui.add(
                                egui::Slider::new(&mut elevation, -89.0..=89.0)
                                    .text("Elevation")
                                    .suffix("°"),
                            );
                            edit_scene(state, &r, "Scene: light direction", |s| {
                                s.lights[i].source = LightSource::Directional {
                                    to_light: direction_from(azimuth, elevation),
                                }
                            });
                        });
                    });
                } else if let LightSource::Point { position_m } = light.source {
                    let mut position = position_m;
                    ui.horizontal(|ui| {
                        ui.label("Position (m)");
                        for c in 0..3 {
                            let r = ui.add(egui::DragValue::new(&mut position[c]).speed(0.01));
                            edit_scene(state, &r, "Scene: light position", |s| {
                                s.lights[i].source = LightSource::Point {
                                    position_m: position,
                                }
                            });
                        }
                    });
                }
                let mut color = light.color;
                let r = ui
                    .horizontal(|ui| {
                        let r = ui.color_edit_button_rgb(&mut color);
                        ui.label("Colour");
                        r
                    })
                    .inner;
                edit_scene(state, &r, "Scene: light colour", |s| {
                    s.lights[i].color = color
                });
                let mut intensity = light.intensity;
                let r = ui.add(
                    egui::Slider::new(&mut intensity, 0.0..=10.0)
                        .text("Intensity")
                        .clamping(egui::SliderClamping::Never),
                );
                edit_scene(state, &r, "Scene: light intensity", |s| {
                    s.lights[i].intensity = intensity
                });
                let mut shadows = light.casts_shadows;
                let r = ui.checkbox(&mut shadows, "Casts shadows");
                edit_scene(state, &r, "Scene: light shadows", |s| {
                    s.lights[i].casts_shadows = shadows
                });
                if ui.button("Remove light").clicked() {
                    remove = Some(i);
                }
            });
    }
    if let Some(i) = remove {
        state
            .edit(ChangeKind::Scene, "Scene: remove light")
            .scene
            .lights
            .remove(i);
        state.commit_edit();
    }
    ui.horizontal(|ui| {
        if ui
            .add_enabled(lights.len() < MAX_LIGHTS, egui::Button::new("Add light"))
            .clicked()
        {
            let n = lights.len() + 1;
            state
                .edit(ChangeKind::Scene, "Scene: add light")
                .scene
                .lights
                .push(Light::directional(
                    &format!("light {n}"),
                    [0.0, 1.0, 0.3],
                    [1.0; 3],
                    1.0,
                ));
            state.commit_edit();
        }
        if ui
            .button("Default rig")
            .on_hover_text("key, fill and rim lights")
            .clicked()
        {
            state
                .edit(ChangeKind::Scene, "Scene: default lights")
                .scene
                .lights = Scene::default().lights;
            state.commit_edit();
        }
    });
}

fn environment_ui(ui: &mut egui::Ui, state: &mut EditorState) {
    let scene = state.document().scene.clone();
    let mut ambient = scene.ambient;
    let r = ui
        .horizontal(|ui| {
            let r = ui.color_edit_button_rgb(&mut ambient);
            ui.label("Ambient light");
            r
        })
        .inner;
    edit_scene(state, &r, "Scene: ambient", |s| s.ambient = ambient);
    let mut background = scene.background;
    let r = ui
        .horizontal(|ui| {
            let r = ui.color_edit_button_rgb(&mut background);
            ui.label("Background");
            r
        })
        .inner;
    edit_scene(state, &r, "Scene: background", |s| {
        s.background = background
    });
    let mut body = scene.body_color;
    let r = ui
        .horizontal(|ui| {
            let r = ui.color_edit_button_rgb(&mut body);
            ui.label("Body colour");
            r
        })
        .inner;
    edit_scene(state, &r, "Scene: body colour", |s| s.body_color = body);
    let mut exposure = scene.exposure;
    let r = ui.add(
        egui::Slider::new(&mut exposure, 0.05..=8.0)
            .logarithmic(true)
            .text("Exposure"),
    );
    edit_scene(state, &r, "Scene: exposure", |s| s.exposure = exposure);
    if ui.button("Reset effects to the defaults").clicked() {
        state
            .edit(ChangeKind::Scene, "Scene: default effects")
            .scene
            .effects = Effects::default();
        state.commit_edit();
    }
}

/// The longest time the motion's time slider reaches.
const MAX_SCRUB_S: f64 = 60.0;

/// A slider over a motion parameter: one undoable scene edit per change (a drag is one step).
fn motion_slider(
    ui: &mut egui::Ui,
    state: &mut EditorState,
    label: &str,
    value: f64,
    range: std::ops::RangeInclusive<f64>,
    set: impl FnOnce(&mut Motion, f64),
) {
    let mut v = value;
    let r = ui.add(egui::Slider::new(&mut v, range).text(label));
    edit_scene(
        state,
        &r,
        &format!("Scene: {}", label.to_lowercase()),
        |s| {
            if let Some(motion) = s.motion.as_mut() {
                set(motion, v);
            }
        },
    );
}

/// The scene's motion (a switch, presets, wind, physics, accuracy) and the timeline: Play,
/// Reset and a time slider. Without motion nothing is simulated, and the panel says so.
fn motion_ui(ui: &mut egui::Ui, state: &mut EditorState) {
    let motion = state.document().scene.motion.clone();
    let mut on = motion.is_some();
    let r = ui
        .checkbox(&mut on, "Simulate motion")
        .on_hover_text("Off: the hair stays as modelled and no simulation runs");
    edit_scene(state, &r, "Scene: motion", |s| {
        s.motion = on.then(|| Motion::head_turn(0.3, 0.6, 70.0));
    });
    let Some(motion) = motion else {
        ui.label(egui::RichText::new("No motion: nothing is simulated.").weak());
        return;
    };
    ui.horizontal(|ui| {
        let playing = state.playback.playing;
        if ui
            .button(if playing { "Pause" } else { "Play" })
            .on_hover_text("Simulate in real time")
            .clicked()
        {
            state.playback.playing = !playing;
        }
        if ui
            .button("Reset")
            .on_hover_text("Back to the modelled shape at 0 s")
            .clicked()
        {
            state.playback.reset();
        }
    });
    // Scrubbing re-simulates from the start when it goes back; a seek longer than a frame
    // runs on a worker with its progress and Cancel below.
    let end_s = (motion.duration_s() + 2.0).clamp(4.0, MAX_SCRUB_S);
    let mut time_s = state
        .playback
        .seeking
        .as_ref()
        .map_or(state.playback.time_s(), |job| job.time_s);
    let r = ui.add(egui::Slider::new(&mut time_s, 0.0..=end_s).text("Time s"));
    if r.changed() {
        state.playback.playing = false;
        state.seek_playback(time_s);
    }
    if let Some(job) = &state.playback.seeking {
        let label = format!(
            "simulating to {:.2} s: about {} left",
            job.time_s,
            hairloom_core::simulate::duration_text(job.seconds_left())
        );
        let fraction = job.fraction();
        let mut cancel = false;
        ui.horizontal(|ui| {
            ui.add(
                egui::ProgressBar::new(fraction)
                    .text(label)
                    .desired_width(ui.available_width() - 70.0),
            );
            cancel = ui.button("Cancel").clicked();
        });
        if cancel {
            state.playback.cancel_seek();
            state.message = "seek cancelled: the motion stays where it was".into();
        }
    }
    ui.label(
        egui::RichText::new(format!(
            "{} steps at {} Hz × {} sub-steps × {} iterations{}",
            state.playback.steps,
            motion.quality.rate_hz,
            motion.quality.substeps,
            motion.quality.iterations,
            state
                .playback
                .step_ms
                .map(|ms| format!("; simulating costs {ms:.2} ms per step"))
                .unwrap_or_default()
        ))
        .small()
        .weak(),
    );
    ui.horizontal(|ui| {
        if ui.button("Head turn").clicked() {
            let keys = Motion::head_turn(0.3, 0.6, 70.0).head_animation;
            if let Some(motion) = state
                .edit(ChangeKind::Scene, "Scene: head turn")
                .scene
                .motion
                .as_mut()
            {
                motion.head_animation = keys;
            }
            state.commit_edit();
        }
        if ui.button("Still head").clicked() {
            if let Some(motion) = state
                .edit(ChangeKind::Scene, "Scene: still head")
                .scene
                .motion
                .as_mut()
            {
                motion.head_animation.clear();
            }
            state.commit_edit();
        }
    });
    egui::CollapsingHeader::new("Wind and gravity")
        .default_open(false)
        .show(ui, |ui| {
            motion_slider(
                ui,
                state,
                "Wind m/s",
                motion.wind.speed_m_per_s,
                0.0..=30.0,
                |m, v| m.wind.speed_m_per_s = v,
            );
            motion_slider(
                ui,
                state,
                "Gusts",
                motion.wind.gust_strength,
                0.0..=1.0,
                |m, v| m.wind.gust_strength = v,
            );
            motion_slider(
                ui,
                state,
                "Gravity m/s²",
                motion.gravity_m_per_s2,
                0.0..=20.0,
                |m, v| m.gravity_m_per_s2 = v,
            );
        });
    egui::CollapsingHeader::new("Physics")
        .default_open(false)
        .show(ui, |ui| {
            let p = &motion.physics;
            type Set = fn(&mut Motion, f64);
            let sliders: [(&str, f64, std::ops::RangeInclusive<f64>, Set); 6] = [
                ("Bend stiffness", p.bend_stiffness, 0.0..=1.0, |m, v| {
                    m.physics.bend_stiffness = v
                }),
                ("Shape stiffness", p.shape_stiffness, 0.0..=1.0, |m, v| {
                    m.physics.shape_stiffness = v
                }),
                ("Style hold at root", p.retention_root, 0.0..=1.0, |m, v| {
                    m.physics.retention_root = v
                }),
                ("Style hold at tip", p.retention_tip, 0.0..=1.0, |m, v| {
                    m.physics.retention_tip = v
                }),
                ("Damping /s", p.damping_per_s, 0.0..=20.0, |m, v| {
                    m.physics.damping_per_s = v
                }),
                ("Friction", p.friction, 0.0..=2.0, |m, v| {
                    m.physics.friction = v
                }),
            ];
            for (label, value, range, set) in sliders {
                motion_slider(ui, state, label, value, range, set);
            }
        });
    egui::CollapsingHeader::new("Accuracy")
        .default_open(false)
        .show(ui, |ui| {
            let q = &motion.quality;
            motion_slider(
                ui,
                state,
                "Sub-steps",
                q.substeps as f64,
                1.0..=16.0,
                |m, v| m.quality.substeps = v.round() as u32,
            );
            motion_slider(
                ui,
                state,
                "Iterations",
                q.iterations as f64,
                1.0..=16.0,
                |m, v| m.quality.iterations = v.round() as u32,
            );
        });
}
