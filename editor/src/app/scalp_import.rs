//! File ▸ Import scalp…, for a file that offers a choice: where hair grows. A whole body
//! imported face for face would make every face of the face, neck and shoulders a bundle;
//! here the artist picks the scalp by the file's materials or by a mask painted into its
//! vertex colours (the count updates as they choose), or imports every face and keeps only
//! a box-selected region afterwards (Edit ▸ Keep only selected bundles). The whole mesh stays the
//! body either way. A file with one material and no vertex colours imports at once.
//!
//! A file of several meshes (a character whose scalp, face, eyes and clothes are separate)
//! first asks which mesh hair grows on ([`MeshChoice`]); every mesh then becomes the body.
//!
//! glTF counts in metres, and so do the tools (a 3 cm brush, a 2 cm extrusion). A file
//! whose size is implausible in metres (the bundled head scan is 8.6 units across: a 4.9 m
//! head) is asked about too: the modal offers a scale (metres, centimetres, millimetres,
//! inches or any factor) and shows the size it gives, so the brushes fit the head.

use std::path::PathBuf;

use hairloom_core::io::import::ImportedMesh;
use hairloom_core::io::scalp_region::{ColourChannel, ScalpRegion, face_count, material_faces};
use hairloom_core::model::document::BodyMesh;

/// How the artist names the scalp.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Choice {
    Everything,
    Materials,
    VertexColour,
}

/// The question, with the mesh already read (the file is read once).
pub struct ScalpImport {
    pub path: PathBuf,
    /// Boxed: a mesh is large and this sits in the app.
    pub mesh: Box<ImportedMesh>,
    /// The body when it is more than `mesh` (every mesh of a file of several).
    pub body: Option<BodyMesh>,
    choice: Choice,
    /// Each material, its face count and whether it is chosen.
    materials: Vec<(String, usize, bool)>,
    channel: ColourChannel,
    above: bool,
    threshold: f64,
    /// The region last counted and its count (or why it is no region): counted again only
    /// when the choice changes, not every frame.
    counted: Option<(ScalpRegion, Result<usize, String>)>,
    /// Model units (metres) per file unit, applied to the scalp and the body.
    scale: f64,
    /// The largest side of the file's box, in file units.
    extent: f64,
}

/// Sizes of a head or a body in metres: outside them, the file is asked about its units.
pub const PLAUSIBLE_EXTENT_M: std::ops::RangeInclusive<f64> = 0.05..=3.0;

/// Units offered for a file's size, with their scale to metres.
const UNITS: [(&str, f64); 4] = [
    ("metres", 1.0),
    ("centimetres", 0.01),
    ("millimetres", 0.001),
    ("inches", 0.0254),
];

/// The largest side of the box around `mesh`'s finite positions (0 without one).
pub fn extent(mesh: &ImportedMesh) -> f64 {
    let mut finite = mesh.positions.iter().filter(|p| p.is_finite());
    let Some(first) = finite.next() else {
        return 0.0;
    };
    let (lo, hi) = finite.fold((*first, *first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    (hi - lo).max_element()
}

/// What the modal asks of the app.
pub enum ScalpImportAction {
    Waiting,
    /// Cancel: nothing is imported.
    Closed,
    /// Import with hair on this region, scaled by this much (model units per file unit).
    Import(ScalpRegion, f64),
}

/// Material names that suggest where hair grows: chosen by default.
fn looks_like_scalp(name: &str) -> bool {
    let name = name.to_ascii_lowercase();
    ["scalp", "hair", "head_skin"]
        .iter()
        .any(|word| name.contains(word))
}

impl ScalpImport {
    /// Whether the file offers a choice: several materials, one material on only some of
    /// the faces, or vertex colours.
    pub fn offers_choice(mesh: &ImportedMesh) -> bool {
        let materials = material_faces(mesh);
        let with_material: usize = materials.iter().map(|(_, faces)| faces).sum();
        materials.len() > 1
            || (materials.len() == 1 && with_material < mesh.faces.len())
            || mesh.face_colours.is_some()
            || !Self::plausible_in_metres(mesh)
    }

    /// Whether the file's size reads as a head or a body in metres.
    pub fn plausible_in_metres(mesh: &ImportedMesh) -> bool {
        PLAUSIBLE_EXTENT_M.contains(&extent(mesh))
    }

    pub fn new(path: PathBuf, mesh: ImportedMesh) -> Self {
        let materials: Vec<(String, usize, bool)> = material_faces(&mesh)
            .into_iter()
            .map(|(name, faces)| {
                let chosen = looks_like_scalp(&name);
                (name, faces, chosen)
            })
            .collect();
        let choice = if materials.iter().any(|m| m.2) {
            Choice::Materials
        } else {
            Choice::Everything
        };
        let extent = extent(&mesh);
        Self {
            path,
            mesh: Box::new(mesh),
            body: None,
            choice,
            materials,
            channel: ColourChannel::Red,
            above: true,
            threshold: 0.5,
            counted: None,
            scale: 1.0,
            extent,
        }
    }

    /// The file's units: a factor and the size it gives, when the size is implausible in
    /// metres (else one line saying the size).
    fn size_ui(&mut self, ui: &mut egui::Ui) {
        let size_m = self.extent * self.scale;
        if self.scale == 1.0 && PLAUSIBLE_EXTENT_M.contains(&self.extent) {
            ui.label(format!("{size_m:.2} m across (glTF counts in metres)"));
            return;
        }
        ui.label(format!(
            "The file is {:.3} units across. glTF counts in metres, and so do the brushes and \
             extrusions: give its units, or a scale that makes it the size it is.",
            self.extent
        ));
        ui.horizontal_wrapped(|ui| {
            for (name, factor) in UNITS {
                ui.selectable_value(&mut self.scale, factor, name);
            }
        });
        ui.horizontal(|ui| {
            let label = ui.label("Scale");
            ui.add(
                egui::DragValue::new(&mut self.scale)
                    .range(1e-6..=1e6)
                    .speed(0.001)
                    .max_decimals(6),
            )
            .labelled_by(label.id);
            let size = if size_m >= 1.0 {
                format!("{size_m:.2} m")
            } else {
                format!("{:.1} cm", size_m * 100.0)
            };
            let note = if PLAUSIBLE_EXTENT_M.contains(&size_m) {
                ""
            } else {
                " (still not a head's or a body's size)"
            };
            ui.label(format!("gives {size} across{note}"));
        });
    }

    /// The region as chosen now.
    pub fn region(&self) -> ScalpRegion {
        match self.choice {
            Choice::Everything => ScalpRegion::All,
            Choice::Materials => ScalpRegion::Materials(
                self.materials
                    .iter()
                    .filter(|m| m.2)
                    .map(|m| m.0.clone())
                    .collect(),
            ),
            Choice::VertexColour => ScalpRegion::VertexColour {
                channel: self.channel,
                above: self.above,
                threshold: self.threshold,
            },
        }
    }

    pub fn ui(&mut self, ui: &mut egui::Ui) -> ScalpImportAction {
        let mut action = ScalpImportAction::Waiting;
        let total = self.mesh.faces.len();
        let modal = egui::Modal::new(egui::Id::unique("hairloom import scalp")).show(ui.ctx(), |ui| {
            ui.heading("Import scalp");
            ui.label(self.path.display().to_string());
            self.size_ui(ui);
            ui.separator();
            ui.label(format!(
                "Hair grows on (all {total} faces of \"{}\" stay the body):",
                self.mesh.mesh_name
            ));
            ui.radio_value(
                &mut self.choice,
                Choice::Everything,
                format!("every face ({total})"),
            );
            if !self.materials.is_empty() {
                ui.radio_value(
                    &mut self.choice,
                    Choice::Materials,
                    "faces with these materials",
                );
                ui.add_enabled_ui(self.choice == Choice::Materials, |ui| {
                    ui.indent("materials", |ui| {
                        // A body may have hundreds of materials: the buttons stay in view.
                        egui::ScrollArea::vertical()
                            .max_height(240.0)
                            .show(ui, |ui| {
                                for (name, faces, chosen) in &mut self.materials {
                                    ui.checkbox(
                                        chosen,
                                        format!("{name} ({})", face_count(*faces)),
                                    );
                                }
                            });
                    });
                });
            }
            if self.mesh.face_colours.is_some() {
                ui.radio_value(
                    &mut self.choice,
                    Choice::VertexColour,
                    "faces painted in the vertex colours",
                );
                ui.add_enabled_ui(self.choice == Choice::VertexColour, |ui| {
                    ui.indent("mask", |ui| {
                        ui.horizontal(|ui| {
                            let label = ui.label("channel");
                            egui::ComboBox::from_id_salt("mask channel")
                                .selected_text(channel_name(self.channel))
                                .show_ui(ui, |ui| {
                                    for channel in ColourChannel::ALL {
                                        ui.selectable_value(
                                            &mut self.channel,
                                            channel,
                                            channel_name(channel),
                                        );
                                    }
                                })
                                .response
                                .labelled_by(label.id);
                            ui.selectable_value(&mut self.above, true, "above");
                            ui.selectable_value(&mut self.above, false, "below");
                            ui.add(
                                egui::Slider::new(&mut self.threshold, 0.0..=1.0)
                                    .text("mask threshold"),
                            );
                        });
                    });
                });
            }
            let region = self.region();
            if self.counted.as_ref().is_none_or(|(r, _)| *r != region) {
                let count = region
                    .faces(&self.mesh)
                    .map(|keep| keep.iter().filter(|k| **k).count())
                    .map_err(|e| e.to_string());
                self.counted = Some((region, count));
            }
            let ready = match self.counted.as_ref().map(|(_, count)| count) {
                Some(Ok(count)) => {
                    ui.label(format!("{count} of {total} faces become bundles"));
                    true
                }
                Some(Err(error)) => {
                    ui.colored_label(ui.visuals().warn_fg_color, error);
                    false
                }
                None => false,
            };
            ui.label(
                "Or import every face, box-select the scalp and use Edit > Keep only selected bundles.",
            );
            ui.horizontal(|ui| {
                let scaled = self.scale.is_finite() && self.scale > 0.0;
                if ui
                    .add_enabled(ready && scaled, egui::Button::new("Import"))
                    .clicked()
                {
                    action = ScalpImportAction::Import(self.region(), self.scale);
                }
                if ui.button("Cancel").clicked() {
                    action = ScalpImportAction::Closed;
                }
            });
        });
        // Escape (or a click outside) closes it, as the other dialogs do.
        if modal.should_close() && matches!(action, ScalpImportAction::Waiting) {
            action = ScalpImportAction::Closed;
        }
        action
    }
}

/// The first question for a file of several meshes: which one grows hair.
pub struct MeshChoice {
    pub path: PathBuf,
    names: Vec<String>,
    chosen: usize,
}

/// What the mesh question asks of the app.
pub enum MeshChoiceAction {
    Waiting,
    Closed,
    /// Read this mesh as the scalp (and every mesh as the body).
    Read(String),
}

impl MeshChoice {
    /// A mesh whose name says scalp or hair is chosen by default.
    pub fn new(path: PathBuf, names: Vec<String>) -> Self {
        let chosen = names.iter().position(|n| looks_like_scalp(n)).unwrap_or(0);
        Self {
            path,
            names,
            chosen,
        }
    }

    pub fn ui(&mut self, ui: &mut egui::Ui) -> MeshChoiceAction {
        let mut action = MeshChoiceAction::Waiting;
        let modal =
            egui::Modal::new(egui::Id::unique("hairloom import scalp mesh")).show(ui.ctx(), |ui| {
                ui.heading("Import scalp");
                ui.label(self.path.display().to_string());
                ui.label(format!(
                    "The file has {} meshes; hair grows on (all of them stay the body):",
                    self.names.len()
                ));
                egui::ScrollArea::vertical()
                    .max_height(240.0)
                    .show(ui, |ui| {
                        for (i, name) in self.names.iter().enumerate() {
                            ui.radio_value(&mut self.chosen, i, name);
                        }
                    });
                ui.horizontal(|ui| {
                    if ui.button("Next").clicked() {
                        action = MeshChoiceAction::Read(self.names[self.chosen].clone());
                    }
                    if ui.button("Cancel").clicked() {
                        action = MeshChoiceAction::Closed;
                    }
                });
            });
        if modal.should_close() && matches!(action, MeshChoiceAction::Waiting) {
            action = MeshChoiceAction::Closed;
        }
        action
    }
}

fn channel_name(channel: ColourChannel) -> &'static str {
    match channel {
        ColourChannel::Red => "red",
        ColourChannel::Green => "green",
        ColourChannel::Blue => "blue",
        ColourChannel::Alpha => "alpha",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hairloom_core::io::import::{ImportOptions, import_slice};

    #[test]
    fn a_file_offers_a_choice_when_its_faces_differ() {
        let mut mesh = import_slice(
            &hairloom_tests::body_with_materials_glb(),
            None,
            "body.glb",
            &ImportOptions::default(),
        )
        .expect("valid");
        assert!(
            ScalpImport::offers_choice(&mesh),
            "two materials and colours"
        );
        mesh.face_colours = None;
        assert!(ScalpImport::offers_choice(&mesh), "two materials");
        // A "Scalp" material on some faces, none on the rest: still a choice.
        mesh.primitive_materials[1] = None;
        assert!(
            ScalpImport::offers_choice(&mesh),
            "one material on some faces"
        );
        // One material on every face, or none at all: nothing to choose.
        mesh.primitive_materials[1] = mesh.primitive_materials[0].clone();
        assert!(!ScalpImport::offers_choice(&mesh));
        mesh.primitive_materials = vec![None, None];
        assert!(!ScalpImport::offers_choice(&mesh));
        // The scalp material is chosen by default.
        let mesh = import_slice(
            &hairloom_tests::body_with_materials_glb(),
            None,
            "body.glb",
            &ImportOptions::default(),
        )
        .expect("valid");
        let import = ScalpImport::new("body.glb".into(), mesh);
        assert_eq!(
            import.region(),
            ScalpRegion::Materials(vec!["Scalp".into()])
        );
    }

    #[test]
    fn a_file_of_implausible_size_in_metres_is_asked_about() {
        let scan = std::fs::read(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../assets/head/LeePerrySmith.glb"),
        )
        .expect("the head scan");
        let mut mesh = import_slice(&scan, None, "LeePerrySmith.glb", &ImportOptions::default())
            .expect("valid");
        // One material, no colours: only its size (8.6 units, a 4.9 m head) asks.
        assert!((8.0..9.0).contains(&extent(&mesh)), "{}", extent(&mesh));
        assert!(!ScalpImport::plausible_in_metres(&mesh));
        assert!(ScalpImport::offers_choice(&mesh));
        for p in &mut mesh.positions {
            *p *= 0.045;
        }
        assert!(ScalpImport::plausible_in_metres(&mesh), "a 39 cm bust");
        assert!(!ScalpImport::offers_choice(&mesh), "nothing left to ask");
        mesh.positions.clear();
        assert_eq!(extent(&mesh), 0.0);
    }
}
