//! The real editor app driven by widget labels (egui_kittest, no GPU: the viewport shows its
//! placeholder). Covers: a styling slider change is one undo step, Ctrl+Z / Edit ▸ Redo,
//! the history panel jumps, Ctrl+S saves a file that reopens equal.

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use hairloom_editor::app::{EditorState, HairloomApp};

/// The app on the sample, with autosaves in a fresh folder (no recovery offer).
fn harness() -> Harness<'static, HairloomApp> {
    let recovery_dir = std::env::temp_dir().join(format!(
        "hairloom-ui-test-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    let _ = std::fs::remove_dir_all(&recovery_dir);
    harness_with_recovery(&recovery_dir)
}

/// The app on the sample, with its autosaves (and any offer) in `recovery_dir`.
fn harness_with_recovery(recovery_dir: &std::path::Path) -> Harness<'static, HairloomApp> {
    let recovery = hairloom_editor::app::recovery::Recovery::in_dir(recovery_dir);
    let mut harness = Harness::new_eframe(move |cc| {
        HairloomApp::with_recovery(cc, EditorState::sample(), recovery)
    });
    harness.set_size(egui::vec2(1400.0, 900.0));
    harness.run();
    harness
}

#[test]
fn a_styling_slider_change_is_one_undo_step() {
    let mut harness = harness();
    let original = harness.state().state.document().clone();
    assert!(original.styling.global.wave.amplitude_m != 0.021);
    harness
        .get_by_role_and_label(Role::Slider, "Wave amplitude")
        .set_value_accesskit(0.021);
    harness.run();
    let changed = harness.state().state.document().clone();
    assert_eq!(changed.styling.global.wave.amplitude_m, 0.021);
    assert_eq!(harness.state().state.project.history.undo.len(), 1);
    assert!(harness.state().state.is_dirty());

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(harness.state().state.document(), &original, "Ctrl+Z undoes");

    harness.get_by_label("Edit").click();
    harness.run();
    harness.get_by_label("Redo").click();
    harness.run();
    assert_eq!(
        harness.state().state.document(),
        &changed,
        "Edit ▸ Redo redoes"
    );
}

#[test]
fn the_history_panel_jumps_to_a_clicked_step() {
    let mut harness = harness();
    let original = harness.state().state.document().clone();
    harness
        .get_by_role_and_label(Role::Slider, "Curl radius")
        .set_value_accesskit(0.004);
    harness.run();
    harness
        .get_by_role_and_label(Role::Slider, "Twist turns")
        .set_value_accesskit(3.0);
    harness.run();
    assert_eq!(harness.state().state.project.history.undo.len(), 2);
    harness.get_by_label("Original").click();
    harness.run();
    assert_eq!(harness.state().state.document(), &original);
    harness.get_by_label("set Twist turns").click();
    harness.run();
    let document = harness.state().state.document();
    assert_eq!(document.styling.global.curl.radius_m, 0.004);
    assert_eq!(document.styling.global.twist.turns_per_m, 3.0);
}

#[test]
fn ctrl_s_saves_a_file_that_reopens_equal() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("edited.hairloom");
    let mut harness = harness();
    harness
        .get_by_role_and_label(Role::Slider, "Noise amplitude")
        .set_value_accesskit(0.002);
    harness.run();
    harness.state_mut().state.path = Some(path.clone());
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    harness.run();
    assert!(
        !harness.state().state.is_dirty(),
        "{}",
        harness.state().state.message
    );
    let reopened = EditorState::open(&path).expect("reopen");
    assert_eq!(reopened.project, harness.state().state.project);
}

#[test]
fn select_a_bundle_extrude_and_undo() {
    let mut harness = harness();
    let original = harness.state().state.document().clone();
    let layers = original.hair_mesh.bundles[0].layers;
    // Nothing selected: the tool says so and changes nothing.
    harness.get_by_label("Extrude").click();
    harness.run();
    assert_eq!(harness.state().state.document(), &original);
    assert!(harness.state().state.message.contains("nothing selected"));

    harness
        .get_by_label(&format!("Bundle 0 · {layers} layers"))
        .click();
    harness.run();
    assert_eq!(
        harness
            .state()
            .state
            .selection
            .iter()
            .copied()
            .collect::<Vec<_>>(),
        [0]
    );
    harness.get_by_label("Extrude").click();
    harness.run();
    let extruded = &harness.state().state.document().hair_mesh;
    assert_eq!(extruded.bundles[0].layers, layers + 1, "one more layer");
    assert!(extruded.validate().is_ok());
    assert_eq!(harness.state().state.project.history.undo.len(), 1);

    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run();
    assert_eq!(harness.state().state.document(), &original, "undo restores");
    // E extrudes too.
    harness.key_press(egui::Key::E);
    harness.run();
    assert_eq!(
        harness.state().state.document().hair_mesh.bundles[0].layers,
        layers + 1
    );
}

/// A primary-button click at `pos` (the viewport has no accessible node to click by label).
fn click_at(harness: &mut Harness<'static, HairloomApp>, pos: egui::Pos2) {
    harness.hover_at(pos);
    harness.run();
    for pressed in [true, false] {
        harness.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
        harness.run();
    }
}

#[test]
fn a_click_in_the_viewport_selects_the_bundle_under_it() {
    let mut harness = harness();
    // The viewport fills the middle of the window; the hair covers its centre.
    let centre = egui::pos2(620.0, 430.0);
    click_at(&mut harness, centre);
    let selection = harness.state().state.selection.clone();
    assert_eq!(selection.len(), 1, "{}", harness.state().state.message);
    // A click on empty space (top-left corner of the viewport) clears it.
    let corner = egui::pos2(420.0, 50.0);
    click_at(&mut harness, corner);
    assert!(harness.state().state.selection.is_empty());
}

#[test]
fn unsaved_work_is_offered_for_recovery_on_the_next_start() {
    use hairloom_editor::app::recovery::Recovery;
    let dir = tempfile::tempdir().expect("temp dir");
    // An earlier session with unsaved work (as autosave or quit leaves it).
    let mut earlier = EditorState::sample();
    earlier.edit("wave").styling.global.wave.amplitude_m = 0.017;
    earlier.commit_edit();
    Recovery::in_dir(dir.path())
        .write(&earlier)
        .expect("autosave");

    let mut harness = harness_with_recovery(dir.path());
    harness.get_by_label("Recover").click();
    harness.run();
    let state = &harness.state().state;
    assert_eq!(
        state.project, earlier.project,
        "document and history recovered"
    );
    assert!(state.is_dirty());
    assert!(harness.state().offer.is_none());

    // Saving makes the recovery file unnecessary.
    let path = dir.path().join("saved.hairloom");
    harness.state_mut().state.path = Some(path.clone());
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    harness.run();
    assert!(path.exists());
    assert!(Recovery::in_dir(dir.path()).pending().is_none());
}

#[test]
fn discarding_the_offer_removes_the_autosave() {
    use hairloom_editor::app::recovery::Recovery;
    let dir = tempfile::tempdir().expect("temp dir");
    Recovery::in_dir(dir.path())
        .write(&EditorState::sample())
        .expect("autosave");
    let mut harness = harness_with_recovery(dir.path());
    harness.get_by_label("Discard").click();
    harness.run();
    assert!(Recovery::in_dir(dir.path()).pending().is_none());
    assert!(!harness.state().state.is_dirty());
}
