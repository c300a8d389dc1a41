//! `docs/runtime-format.md` says what the code does: its default scene is
//! `Scene::default()` field for field, and every numeric range in its table of valid scene
//! values is the one validation enforces (the bound itself loads, just past it is refused).

use hairloom_core::model::scene::{HairMaterial, Ombre, Scene};
use serde_json::Value;

fn document() -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/runtime-format.md");
    std::fs::read_to_string(path).expect("docs/runtime-format.md")
}

#[test]
fn the_documented_default_scene_is_the_code_s() {
    let text = document();
    let start = text
        .find("The default scene, in full")
        .expect("the default scene's paragraph");
    let block = &text[start..];
    let open = block.find("```json\n").expect("a json block") + "```json\n".len();
    let close = open + block[open..].find("```").expect("its end");
    let written: Value =
        serde_json::from_str(&format!("{{{}}}", &block[open..close])).expect("valid JSON");
    let code = serde_json::to_value(Scene::default()).expect("serialises");
    // Every key the code writes is written out (same objects, same array lengths) …
    assert_eq!(shape(&written["scene"]), shape(&code));
    // … and holds the code's value (read as the code reads it: f32).
    let read: Scene = serde_json::from_value(written["scene"].clone()).expect("a scene");
    assert_eq!(read, Scene::default());
}

/// Every path of `value` to a leaf, as `a/b/0/c`.
fn shape(value: &Value) -> Vec<String> {
    match value {
        Value::Object(map) => map
            .iter()
            .flat_map(|(k, v)| shape(v).into_iter().map(move |p| format!("{k}/{p}")))
            .collect(),
        Value::Array(items) => items
            .iter()
            .enumerate()
            .flat_map(|(i, v)| shape(v).into_iter().map(move |p| format!("{i}/{p}")))
            .collect(),
        _ => vec![String::new()],
    }
}

/// `(JSON pointer, lo, hi)` of every table row that names one field and a plain `[lo, hi]`.
fn documented_ranges(text: &str) -> Vec<(String, f64, f64)> {
    let table = &text[text
        .find("| field | valid values |")
        .expect("the range table")..];
    let mut ranges = Vec::new();
    for line in table.lines().skip(2).take_while(|l| l.starts_with('|')) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (field, value) = (cells[1], cells[2].replace('−', "-"));
        if field.matches('`').count() != 2 || !value.starts_with('[') || !value.ends_with(']') {
            continue;
        }
        let bounds: Vec<f64> = value[1..value.len() - 1]
            .split(',')
            .filter_map(|b| b.trim().parse().ok())
            .collect();
        if bounds.len() != 2 {
            continue;
        }
        let pointer = format!(
            "/{}",
            field
                .trim_matches('`')
                .replace("[i]", "/0")
                .replace('.', "/")
        );
        ranges.push((pointer, bounds[0], bounds[1]));
    }
    ranges
}

#[test]
fn the_documented_scene_ranges_are_the_ones_validation_enforces() {
    let ranges = documented_ranges(&document());
    assert!(ranges.len() >= 8, "{ranges:?}");
    // With an ombré spanning the whole strand, so that its fields are there to be set.
    let default = serde_json::to_value(Scene {
        material: HairMaterial {
            ombre: Some(Ombre {
                start: 0.0,
                end: 1.0,
                ..Ombre::default()
            }),
            ..HairMaterial::default()
        },
        ..Scene::default()
    })
    .expect("serialises");
    let loads = |pointer: &str, value: f64| -> bool {
        let mut scene = default.clone();
        let slot = scene
            .pointer_mut(pointer)
            .unwrap_or_else(|| panic!("{pointer}"));
        *slot = if slot.is_u64() {
            Value::from(value as u64)
        } else {
            Value::from(value)
        };
        match serde_json::from_value::<Scene>(scene) {
            Ok(scene) => scene.validate().is_ok(),
            Err(_) => false,
        }
    };
    for (pointer, lo, hi) in ranges {
        let step =
            |bound: f64| (bound.abs() * 0.01).max(if lo.fract() == 0.0 { 1.0 } else { 1e-3 });
        assert!(
            !loads(&pointer, hi + step(hi)),
            "{pointer} above {hi} loads"
        );
        if lo > 0.0 || default.pointer(&pointer).is_some_and(|v| !v.is_u64()) {
            assert!(
                !loads(&pointer, lo - step(lo)),
                "{pointer} below {lo} loads"
            );
        }
        // shells_below_px must also stay at most strands_above_px.
        if !pointer.ends_with("shells_below_px") {
            assert!(loads(&pointer, hi), "{pointer} at {hi} is refused");
        }
        assert!(loads(&pointer, lo), "{pointer} at {lo} is refused");
    }
}
