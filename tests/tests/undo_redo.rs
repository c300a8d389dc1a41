//! Undo/redo property tests: random sequences of ≥ 50 commands over a small hair mesh.
//! Undo all → the start document, byte-identical as JSON; redo all → the end document;
//! saving and reloading in the middle does not change what undo/redo do next.

use glam::{DVec2, DVec3};
use hairloom_core::edit::{self, ExtrudeDirection, VertexTransform};
use hairloom_core::io::project;
use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::history::{Command, History, Transaction};
use hairloom_core::{Document, Project, Topology, VertexRef, WMode};
use hairloom_tests::grid_mesh;
use proptest::prelude::*;

/// One random edit, described by numbers so proptest can shrink it.
#[derive(Clone, Debug)]
enum Op {
    Extrude {
        bundle: usize,
        distance: f64,
    },
    ExtrudeVector {
        bundle: usize,
        offset: [f64; 3],
    },
    InsertLayer {
        bundle: usize,
        layer: u32,
    },
    DeleteLayer {
        bundle: usize,
        layer: u32,
    },
    Remove {
        bundle: usize,
    },
    Restore {
        bundle: usize,
    },
    Subdivide {
        bundle: usize,
    },
    Move {
        vertex: usize,
        offset: [f64; 3],
        falloff: f64,
    },
    Rotate {
        vertex: usize,
        angle: f64,
    },
    Scale {
        vertex: usize,
        factor: f64,
    },
    SetW {
        vertex: usize,
        scale: f64,
    },
    WMode {
        manual: bool,
    },
    Uv {
        bundle: usize,
        corner: usize,
        uv: [f64; 2],
    },
    /// A drag: several moves merged into one transaction.
    Drag {
        vertex: usize,
        steps: usize,
    },
    /// A group of two edits as one undo step.
    Group {
        a: usize,
        b: usize,
    },
    /// A styling slider (curl radius) moved.
    Styling {
        radius_m: f64,
    },
}

fn op_strategy() -> impl Strategy<Value = Op> {
    let small = -0.5f64..0.5;
    prop_oneof![
        (0usize..1000, 0.05f64..0.5)
            .prop_map(|(bundle, distance)| Op::Extrude { bundle, distance }),
        (0usize..1000, [small.clone(), small.clone(), 0.1f64..0.6])
            .prop_map(|(bundle, offset)| Op::ExtrudeVector { bundle, offset }),
        (0usize..1000, 1u32..4).prop_map(|(bundle, layer)| Op::InsertLayer { bundle, layer }),
        (0usize..1000, 1u32..4).prop_map(|(bundle, layer)| Op::DeleteLayer { bundle, layer }),
        (0usize..1000).prop_map(|bundle| Op::Remove { bundle }),
        (0usize..1000).prop_map(|bundle| Op::Restore { bundle }),
        (0usize..1000).prop_map(|bundle| Op::Subdivide { bundle }),
        (
            0usize..10_000,
            [small.clone(), small.clone(), small.clone()],
            0.0f64..1.5
        )
            .prop_map(|(vertex, offset, falloff)| Op::Move {
                vertex,
                offset,
                falloff
            }),
        (0usize..10_000, -1.0f64..1.0).prop_map(|(vertex, angle)| Op::Rotate { vertex, angle }),
        (0usize..10_000, 0.5f64..1.5).prop_map(|(vertex, factor)| Op::Scale { vertex, factor }),
        (0usize..10_000, 0.0f64..1.0).prop_map(|(vertex, scale)| Op::SetW { vertex, scale }),
        any::<bool>().prop_map(|manual| Op::WMode { manual }),
        (0usize..1000, 0usize..4, [0.0f64..1.0, 0.0f64..1.0])
            .prop_map(|(bundle, corner, uv)| Op::Uv { bundle, corner, uv }),
        (0usize..10_000, 2usize..5).prop_map(|(vertex, steps)| Op::Drag { vertex, steps }),
        (0usize..1000, 0usize..1000).prop_map(|(a, b)| Op::Group { a, b }),
        (0.0f64..0.01).prop_map(|radius_m| Op::Styling { radius_m }),
    ]
}

fn exterior_vertices(document: &Document) -> Vec<VertexRef> {
    let mesh = &document.hair_mesh;
    let topology = Topology::build(mesh);
    let mut out = Vec::new();
    for (c, column) in mesh.columns.iter().enumerate() {
        for k in 0..column.positions.len() {
            if !mesh.is_interior(&topology, c, k) {
                out.push(VertexRef {
                    column: c as u32,
                    layer: k as u32,
                });
            }
        }
    }
    out
}

/// Computes the edited document for `op`, or `None` when the edit is refused (which must
/// leave no trace in the history).
fn edited(document: &Document, op: &Op) -> Option<Document> {
    let mesh = &document.hair_mesh;
    let bundle_count = mesh.bundles.len().max(1);
    let pick = |b: usize| (b % bundle_count) as u32;
    let exterior = exterior_vertices(document);
    let vertex = |v: usize| exterior[v % exterior.len().max(1)];
    let result = match op {
        Op::Extrude { bundle, distance } => {
            if mesh.max_layers() >= 5 {
                return None;
            }
            edit::extrude(
                mesh,
                &[pick(*bundle)],
                ExtrudeDirection::AlongNormal {
                    distance: *distance,
                },
            )
        }
        Op::ExtrudeVector { bundle, offset } => {
            if mesh.max_layers() >= 5 {
                return None;
            }
            edit::extrude(
                mesh,
                &[pick(*bundle)],
                ExtrudeDirection::Vector { offset: *offset },
            )
        }
        Op::InsertLayer { bundle, layer } => {
            if mesh.max_layers() >= 5 {
                return None;
            }
            edit::insert_layer(mesh, &[pick(*bundle)], *layer)
        }
        Op::DeleteLayer { bundle, layer } => edit::delete_layer(mesh, &[pick(*bundle)], *layer),
        Op::Remove { bundle } => edit::set_removed(mesh, &[pick(*bundle)], true),
        Op::Restore { bundle } => edit::set_removed(mesh, &[pick(*bundle)], false),
        Op::Subdivide { bundle } => {
            if mesh.bundles.len() > 40 {
                return None;
            }
            edit::subdivide(mesh, &[pick(*bundle)])
        }
        Op::Move {
            vertex: v,
            offset,
            falloff,
        } => edit::transform_vertices(
            mesh,
            &[vertex(*v)],
            VertexTransform::Translate { offset: *offset },
            *falloff,
        ),
        Op::Rotate { vertex: v, angle } => {
            let pivot = mesh.columns[vertex(*v).column as usize].positions[0].to_array();
            edit::transform_vertices(
                mesh,
                &[vertex(*v), vertex(*v + 1)],
                VertexTransform::Rotate {
                    axis: [0.3, 1.0, 0.2],
                    angle_rad: *angle,
                    pivot,
                },
                0.0,
            )
        }
        Op::Scale { vertex: v, factor } => edit::transform_vertices(
            mesh,
            &[vertex(*v), vertex(*v + 3)],
            VertexTransform::Scale {
                factors: [*factor; 3],
                pivot: [1.0, 1.0, 0.0],
            },
            0.0,
        ),
        Op::SetW { vertex: v, scale } => {
            let target = vertex(*v);
            let w = &mesh.columns[target.column as usize].w;
            let k = target.layer as usize;
            if k == 0 {
                return None;
            }
            // Stay between the neighbours so w keeps increasing.
            let upper = w.get(k + 1).copied().unwrap_or(w[k] + 1.0);
            edit::set_w(mesh, target, w[k - 1] + (upper - w[k - 1]) * scale)
        }
        Op::WMode { manual } => edit::set_w_mode(
            mesh,
            if *manual {
                WMode::Manual
            } else {
                WMode::FromPathLength
            },
        ),
        Op::Uv { bundle, corner, uv } => {
            let b = pick(*bundle);
            let corner = (*corner % mesh.bundles[b as usize].vertices.len()) as u32;
            edit::set_corner_uvs(mesh, &[(b, corner, DVec2::from(*uv))])
        }
        Op::Styling { radius_m } => {
            let mut after = document.clone();
            after.styling.global.curl.radius_m = *radius_m;
            return Some(after);
        }
        Op::Drag { .. } | Op::Group { .. } => return None,
    };
    let outcome = result.ok()?;
    let mut after = document.clone();
    after.hair_mesh = outcome.mesh;
    Some(after)
}

/// Applies `op` through the history, the way the editor does. Returns whether a step was
/// recorded.
fn perform(document: &mut Document, history: &mut History, op: &Op, index: usize) -> bool {
    match op {
        Op::Drag { vertex, steps } => {
            let transaction = Transaction::begin(document, "Drag", ChangeKind::Reshape);
            for step in 0..*steps {
                let nudge = Op::Move {
                    vertex: *vertex,
                    offset: [0.01 * step as f64, 0.02, -0.01],
                    falloff: 0.0,
                };
                if let Some(next) = edited(document, &nudge) {
                    *document = next;
                }
            }
            transaction.commit(history, document)
        }
        Op::Group { a, b } => {
            let first = Op::Move {
                vertex: *a,
                offset: [0.05, 0.0, 0.0],
                falloff: 0.8,
            };
            let second = Op::Remove { bundle: *b };
            let start = document.clone();
            let Some(mid) = edited(document, &first) else {
                return false;
            };
            let Some(end) = edited(&mid, &second) else {
                return false;
            };
            let children: Vec<Command> = [
                Command::record("Move", &start, &mid),
                Command::record("Remove", &mid, &end),
            ]
            .into_iter()
            .flatten()
            .collect();
            if children.is_empty() {
                return false;
            }
            *document = end;
            history.push(Command::Group {
                label: format!("Group {index}"),
                children,
            });
            true
        }
        _ => match edited(document, op) {
            Some(after) => history.commit(document, &format!("{op:?}"), after),
            None => false,
        },
    }
}

fn json(document: &Document) -> String {
    serde_json::to_string(document).unwrap_or_default()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, max_shrink_iters: 200, ..ProptestConfig::default() })]

    #[test]
    fn random_command_sequences_undo_and_redo_exactly(ops in prop::collection::vec(op_strategy(), 90..110), save_at in 0usize..50) {
        let start = Document::new("grid", grid_mesh(3, 3, 2, 0.4));
        let start_json = json(&start);
        let mut document = start.clone();
        let mut history = History::with_limit(1000);
        let mut states = vec![document.clone()];
        for (index, op) in ops.iter().enumerate() {
            let recorded = perform(&mut document, &mut history, op, index);
            document.validate().map_err(|e| TestCaseError::fail(format!("{op:?}: {e}")))?;
            if recorded {
                states.push(document.clone());
            } else {
                prop_assert_eq!(&document, states.last().expect("state"), "a refused edit changed the document");
            }
        }
        let end = document.clone();
        let steps = history.undo.len();
        prop_assert_eq!(steps + 1, states.len());
        // Most random edits apply (refusals are the exception), so the sequence is long.
        prop_assert!(steps >= 50, "only {} of {} edits applied", steps, ops.len());

        // Undo everything, checking every intermediate state.
        for pair in states.windows(2).rev() {
            let (before, after) = (&pair[0], &pair[1]);
            let step = history.undo(&mut document).map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert_eq!(&document, before);
            // What the hair asset redoes for the step: never less than the mesh change needs.
            let kind = step.expect("a step to undo").kind;
            let (a, b) = (&before.hair_mesh, &after.hair_mesh);
            if a.bundles.len() != b.bundles.len() || a.columns.len() != b.columns.len() {
                prop_assert_eq!(kind, ChangeKind::Rebuild);
            } else if a != b {
                prop_assert!(kind >= ChangeKind::Reshape, "{:?} for a mesh change", kind);
            }
        }
        prop_assert!(history.undo(&mut document).expect("nothing left").is_none());
        prop_assert_eq!(json(&document), start_json.clone());

        // Redo everything.
        for expected in states.iter().skip(1) {
            history.redo(&mut document).map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert_eq!(&document, expected);
        }
        prop_assert_eq!(&document, &end);

        // Jump to the middle, save, reload, and continue: identical behaviour.
        let middle = save_at.min(steps);
        history.jump_to(&mut document, middle).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(&document, &states[middle]);
        let saved = Project { history: history.clone(), ..Project::new(document.clone()) };
        let bytes = project::to_bytes(&saved);
        let loaded = project::from_bytes(&bytes, std::path::Path::new("mid.hairloom"))
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(&loaded, &saved);
        let (mut doc_a, mut hist_a) = (document.clone(), history.clone());
        let (mut doc_b, mut hist_b) = (loaded.document, loaded.history);
        hist_a.jump_to(&mut doc_a, 0).expect("undo all");
        hist_b.jump_to(&mut doc_b, 0).expect("undo all");
        prop_assert_eq!(json(&doc_a), start_json.clone());
        prop_assert_eq!(json(&doc_b), start_json);
        hist_a.jump_to(&mut doc_a, steps).expect("redo all");
        hist_b.jump_to(&mut doc_b, steps).expect("redo all");
        prop_assert_eq!(&doc_a, &end);
        prop_assert_eq!(&doc_b, &end);
    }
}

#[test]
fn history_limit_drops_the_oldest_steps() {
    let mut document = Document::new("grid", grid_mesh(2, 2, 1, 0.5));
    let mut history = History::with_limit(3);
    for i in 0..5 {
        let mut after = document.clone();
        after.hair_mesh.columns[0].positions[1] += DVec3::X * (i as f64 + 1.0);
        after.hair_mesh.update_w();
        assert!(history.commit(&mut document, &format!("step {i}"), after));
    }
    assert_eq!(history.undo.len(), 3);
    assert_eq!(history.undo[0].label(), "step 2");
    while history.undo(&mut document).expect("undo").is_some() {}
    assert!((document.hair_mesh.columns[0].positions[1].x - 3.0).abs() < 1e-12);
}

#[test]
fn a_drag_that_returns_to_its_start_records_nothing() {
    let mut document = Document::new("grid", grid_mesh(2, 2, 1, 0.5));
    let mut history = History::default();
    let transaction = Transaction::begin(&document, "Drag", ChangeKind::Reshape);
    let original = document.clone();
    document.hair_mesh.columns[0].positions[1] += DVec3::X;
    document = original;
    assert!(!transaction.commit(&mut history, &document));
    assert!(history.undo.is_empty());
}

#[test]
fn mismatched_history_is_an_error_not_corruption() {
    let mut document = Document::new("grid", grid_mesh(2, 2, 1, 0.5));
    let mut history = History::default();
    let mut after = document.clone();
    after.hair_mesh.columns[1].positions[1] += DVec3::Y;
    after.hair_mesh.update_w();
    history.commit(&mut document, "Move", after);
    // Someone edits the document outside the history.
    document.hair_mesh.columns[1].positions[1] += DVec3::Z;
    let snapshot = document.clone();
    let error = history.undo(&mut document).expect_err("mismatch");
    assert!(error.path.contains("columns[1]"), "{error}");
    assert_eq!(
        document, snapshot,
        "a failed undo must not touch the document"
    );
    assert_eq!(history.undo.len(), 1, "the step stays available");
}

#[test]
fn a_styling_only_change_is_recorded_and_undone() {
    // Regression: a diff that changed only the styling counted as empty, so styling edits
    // were silently left out of the history.
    let document = hairloom_core::io::project::load(&hairloom_tests::sample_paths()[0])
        .expect("sample")
        .document;
    let mut after = document.clone();
    after.styling.global.wave.amplitude_m += 0.01;
    let command = Command::record("wave", &document, &after).expect("recorded");
    let mut history = History::default();
    history.push(command);
    let mut current = after.clone();
    history.undo(&mut current).expect("undo");
    assert_eq!(current, document);
    history.redo(&mut current).expect("redo");
    assert_eq!(current, after);
}

#[test]
fn every_document_field_is_recorded_and_undone() {
    // Regression: the source and body were outside the diff, so undoing an import kept the
    // imported body and attribution. Change each whole-value field alone, then all at once.
    let document = hairloom_core::io::project::load(&hairloom_tests::sample_paths()[0])
        .expect("sample")
        .document;
    type Change = fn(&mut hairloom_core::Document);
    let changes: [(&str, Change); 5] = [
        ("name", |d| d.name.push_str(" copy")),
        ("source", |d| {
            d.source = "imported from elsewhere.glb".into()
        }),
        ("body", |d| {
            d.body.positions.push([0.0, 0.0, 0.0]);
        }),
        ("scene", |d| {
            d.scene.material.longitudinal_roughness = 0.2;
            d.scene.effects.body_shadows = false;
        }),
        ("all", |d| {
            d.name = "other".into();
            d.scene.lights.pop();
            d.source.clear();
            d.body = hairloom_core::model::document::BodyMesh::default();
            d.styling.global.seed += 1;
        }),
    ];
    for (what, change) in changes {
        let mut after = document.clone();
        change(&mut after);
        assert_ne!(after, document, "{what}");
        let command = Command::record(what, &document, &after)
            .unwrap_or_else(|| panic!("a change of {what} was not recorded"));
        let mut history = History::default();
        history.push(command);
        let mut current = after.clone();
        history.undo(&mut current).expect("undo");
        assert_eq!(current, document, "undo of {what}");
        history.redo(&mut current).expect("redo");
        assert_eq!(current, after, "redo of {what}");
    }
}
