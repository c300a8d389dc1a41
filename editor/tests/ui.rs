//! The real editor app driven by widget labels (egui_kittest, no GPU: the viewport shows its
//! placeholder). Covers: a styling slider change is one undo step, Ctrl+Z / Edit ▸ Redo,
//! the history panel jumps, Ctrl+S saves a file that reopens equal.

use egui::accesskit::Role;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use hairloom_editor::app::{EditorState, HairloomApp};

fn harness() -> Harness<'static, HairloomApp> {
    let mut harness = Harness::new_eframe(|cc| HairloomApp::new(cc, EditorState::sample()));
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
