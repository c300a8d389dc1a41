//! Styling panel: every op's parameters as sliders (with numeric entry by dragging or
//! double-click), for the global parameters or one styling group. A slider drag is one undo
//! step, and so is a typed value (committed when its field lets go of the keyboard).

use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::styling::StylingParams;

use super::state::EditorState;

type Field = fn(&mut StylingParams) -> &mut f64;

/// One slider: label, field, range, unit suffix.
type SliderSpec = (&'static str, Field, (f64, f64), &'static str);

/// Every slider, grouped by op.
const OPS: &[(&str, &[SliderSpec])] = &[
    (
        "Curl",
        &[
            ("Curl radius", |p| &mut p.curl.radius_m, (0.0, 0.03), " m"),
            (
                "Curl turns",
                |p| &mut p.curl.turns_per_m,
                (0.0, 80.0),
                " /m",
            ),
            ("Curl ramp-in", |p| &mut p.curl.ramp_in_m, (0.0, 0.2), " m"),
            (
                "Curl radius jitter",
                |p| &mut p.curl.radius_jitter,
                (0.0, 1.0),
                "",
            ),
            (
                "Ringlets (curl shared by a clump)",
                |p| &mut p.curl.clump_coherence,
                (0.0, 1.0),
                "",
            ),
            (
                "Curl radius at the tip",
                |p| &mut p.curl.radius_tip_scale,
                (0.0, 2.0),
                "×",
            ),
            (
                "Curl turns at the tip",
                |p| &mut p.curl.rate_tip_scale,
                (0.0, 2.0),
                "×",
            ),
        ],
    ),
    (
        "Twist",
        &[(
            "Twist turns",
            |p| &mut p.twist.turns_per_m,
            (-20.0, 20.0),
            " /m",
        )],
    ),
    (
        "Noise",
        &[
            (
                "Noise amplitude",
                |p| &mut p.noise.amplitude_m,
                (0.0, 0.03),
                " m",
            ),
            (
                "Noise frequency",
                |p| &mut p.noise.frequency_per_m,
                (0.0, 100.0),
                " /m",
            ),
        ],
    ),
    (
        "Clump",
        &[
            ("Clump strength", |p| &mut p.clump.strength, (0.0, 1.0), ""),
            (
                "Clumps per uv",
                |p| &mut p.clump.clumps_per_uv,
                (1.0, 200.0),
                "",
            ),
            ("Clump radius", |p| &mut p.clump.radius_m, (0.0, 0.05), " m"),
            (
                "Clump tightening",
                |p| &mut p.clump.tightening,
                (0.0, 5.0),
                "",
            ),
            (
                "Sub-clump strength",
                |p| &mut p.clump.sub_strength,
                (0.0, 1.0),
                "",
            ),
            (
                "Sub-clumps per uv",
                |p| &mut p.clump.sub_clumps_per_uv,
                (1.0, 800.0),
                "",
            ),
            (
                "Sub-clump radius",
                |p| &mut p.clump.sub_radius_m,
                (0.0, 0.02),
                " m",
            ),
        ],
    ),
    (
        "Frizz",
        &[
            (
                "Frizz amplitude",
                |p| &mut p.frizz.amplitude_m,
                (0.0, 0.01),
                " m",
            ),
            (
                "Frizz frequency",
                |p| &mut p.frizz.frequency_per_m,
                (0.0, 400.0),
                " /m",
            ),
            ("Frizz fraction", |p| &mut p.frizz.fraction, (0.0, 1.0), ""),
        ],
    ),
    (
        "Wave",
        &[
            (
                "Wave amplitude",
                |p| &mut p.wave.amplitude_m,
                (0.0, 0.05),
                " m",
            ),
            (
                "Wave frequency",
                |p| &mut p.wave.frequency_per_m,
                (0.0, 40.0),
                " /m",
            ),
            (
                "Wave direction",
                |p| &mut p.wave.direction_rad,
                (-3.2, 3.2),
                " rad",
            ),
            (
                "Wave phase spread",
                |p| &mut p.wave.phase_spread,
                (0.0, 1.0),
                "",
            ),
            (
                "Wave shared by a clump",
                |p| &mut p.wave.clump_coherence,
                (0.0, 1.0),
                "",
            ),
            (
                "Wave spread between clumps",
                |p| &mut p.wave.lock_phase_spread,
                (0.0, 1.0),
                "",
            ),
        ],
    ),
    (
        "Strays",
        &[
            ("Stray share", |p| &mut p.stray.fraction, (0.0, 0.3), ""),
            (
                "Stray drift",
                |p| &mut p.stray.amplitude_m,
                (0.0, 0.05),
                " m",
            ),
            (
                "Stray drift frequency",
                |p| &mut p.stray.frequency_per_m,
                (0.0, 40.0),
                " /m",
            ),
            (
                "Stray shortest length",
                |p| &mut p.stray.length_min,
                (0.0, 1.0),
                "",
            ),
        ],
    ),
    (
        "Hairline",
        &[
            (
                "Hairline falloff width",
                |p| &mut p.hairline.width_m,
                (0.0, 0.04),
                " m",
            ),
            (
                "Hairline edge density",
                |p| &mut p.hairline.edge_density,
                (0.0, 1.0),
                "",
            ),
            (
                "Hairline edge length",
                |p| &mut p.hairline.edge_length,
                (0.0, 1.0),
                "",
            ),
        ],
    ),
    (
        "Density",
        &[(
            "Strands per cm²",
            |p| &mut p.density.strands_per_cm2,
            (0.0, 400.0),
            " /cm²",
        )],
    ),
    (
        "Length",
        &[(
            "Length variation",
            |p| &mut p.length.fraction,
            (0.0, 1.0),
            "",
        )],
    ),
    (
        "Variation",
        &[(
            "Variation cells per uv",
            |p| &mut p.variation_per_uv,
            (1.0, 1000.0),
            "",
        )],
    ),
];

#[derive(Default)]
pub struct StylingPanel {
    /// `None`: global parameters; `Some(g)`: styling group `g`.
    pub group: Option<usize>,
    /// Parameters copied from one group (or the global set) to paste onto another: the
    /// styling half of the wisp copy / paste of seed 004.
    pub copied: Option<StylingParams>,
}

impl StylingPanel {
    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        ui.heading("Styling");
        let groups: Vec<String> = state
            .document()
            .styling
            .groups
            .iter()
            .map(|g| g.name.clone())
            .collect();
        if self.group.is_some_and(|g| g >= groups.len()) {
            self.group = None;
        }
        egui::ComboBox::from_label("Parameters of")
            .selected_text(self.group.map_or("all bundles (global)".into(), |g| {
                format!("group {}", groups[g])
            }))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut self.group, None, "all bundles (global)");
                for (g, name) in groups.iter().enumerate() {
                    ui.selectable_value(&mut self.group, Some(g), format!("group {name}"));
                }
            });
        self.group_tools(ui, state);
        let group = self.group;
        egui::ScrollArea::vertical().show(ui, |ui| {
            for (op, fields) in OPS {
                egui::CollapsingHeader::new(*op)
                    .default_open(true)
                    .show(ui, |ui| {
                        for (label, field, (lo, hi), suffix) in fields.iter() {
                            let mut current = selected(state, group).clone();
                            let mut value = *field(&mut current);
                            let response = ui.add(
                                egui::Slider::new(&mut value, *lo..=*hi)
                                    .text(*label)
                                    .suffix(*suffix)
                                    .clamping(egui::SliderClamping::Never),
                            );
                            if response.changed() && value.is_finite() {
                                let document =
                                    state.edit(ChangeKind::Restyle, &format!("set {label}"));
                                *field(params_mut(document, group)) = value;
                                if let Err(error) = document.styling.validate() {
                                    // Out of range (typed): put the old value back.
                                    *field(params_mut(document, group)) = *field(&mut current);
                                    state.message = error;
                                }
                            }
                            commit_when_done(state, &response);
                        }
                    });
            }
            ui.horizontal(|ui| {
                let mut seed = selected(state, group).seed;
                let label = ui.label("Seed");
                let response = ui
                    .add(egui::DragValue::new(&mut seed))
                    .labelled_by(label.id);
                if response.changed() {
                    params_mut(state.edit(ChangeKind::Restyle, "set seed"), group).seed = seed;
                }
                commit_when_done(state, &response);
            });
        });
    }
}

impl StylingPanel {
    /// Groups from the selection, and copy / paste of whole parameter sets.
    fn group_tools(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        let selection: Vec<u32> = state.selection.iter().copied().collect();
        let has_selection = !selection.is_empty();
        ui.horizontal_wrapped(|ui| {
            if ui
                .add_enabled(has_selection, egui::Button::new("New group from selection"))
                .clicked()
            {
                let styling = &mut state.edit(ChangeKind::Restyle, "New styling group").styling;
                let name = format!("{}", styling.groups.len() + 1);
                self.group = Some(styling.new_group(name, &selection));
                state.commit_edit();
            }
            if let Some(g) = self.group
                && ui
                    .add_enabled(has_selection, egui::Button::new("Assign selection"))
                    .clicked()
            {
                let result = state
                    .edit(ChangeKind::Restyle, "Assign to group")
                    .styling
                    .assign(&selection, Some(g));
                state.commit_edit();
                if let Err(error) = result {
                    state.message = error;
                }
            }
            if ui
                .add_enabled(has_selection, egui::Button::new("Selection to global"))
                .clicked()
            {
                let _ = state
                    .edit(ChangeKind::Restyle, "Back to global")
                    .styling
                    .assign(&selection, None);
                state.commit_edit();
            }
            if let Some(g) = self.group
                && ui.button("Select group").clicked()
            {
                state.selection = state.document().styling.groups[g]
                    .bundles
                    .iter()
                    .copied()
                    .collect();
            }
        });
        ui.horizontal(|ui| {
            if ui.button("Copy parameters").clicked() {
                self.copied = Some(selected(state, self.group).clone());
                state.message = "styling parameters copied".into();
            }
            if let Some(copied) = &self.copied
                && ui.button("Paste parameters").clicked()
            {
                *params_mut(state.edit(ChangeKind::Restyle, "Paste styling"), self.group) =
                    copied.clone();
                state.commit_edit();
            }
        });
    }
}

/// A drag is one undo step (committed on release), and so is a value typed into the field
/// (committed when the field lets go of the keyboard: it applies each keystroke as it is
/// typed, which made one step per keystroke); clicks and keys commit at once.
fn commit_when_done(state: &mut EditorState, response: &egui::Response) {
    if response.drag_stopped()
        || response.lost_focus()
        || (response.changed() && !response.dragged() && !response.has_focus())
    {
        state.commit_edit();
    }
}

fn params_mut(
    document: &mut hairloom_core::model::document::Document,
    group: Option<usize>,
) -> &mut StylingParams {
    match group {
        Some(g) => &mut document.styling.groups[g].params,
        None => &mut document.styling.global,
    }
}

fn selected(state: &EditorState, group: Option<usize>) -> &StylingParams {
    match group {
        Some(g) => &state.document().styling.groups[g].params,
        None => &state.document().styling.global,
    }
}
