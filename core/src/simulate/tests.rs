//! Hard and degenerate cases of the simulator, each one named: finite, out of the body,
//! energy bounded, deterministic.

use super::*;
use crate::model::motion::{HeadKey, Wind};
use crate::samples::{sphere_body, sphere_cap};
use std::ops::ControlFlow;

const HEAD_RADIUS_M: f64 = 0.1;
/// How far below the body's surface a vertex may end a step: collisions are projected last
/// in every iteration, so only the field's interpolation between grid points is left.
const PENETRATION_TOLERANCE_M: f64 = 0.001;

fn head() -> BodyMesh {
    sphere_body(HEAD_RADIUS_M, 24, 48)
}

fn cap(layers: u32) -> HairMesh {
    sphere_cap(HEAD_RADIUS_M, 0.6, 6, layers, 0.02)
}

fn sim(mesh: &HairMesh, motion: &Motion) -> HairSim {
    HairSim::with_body(mesh, &head(), motion, &[])
}

/// Steps `steps` times, checking after each that everything is finite, nothing is inside
/// the head beyond the tolerance and the energy stays under `energy_bound`.
fn run_checked(sim: &mut HairSim, steps: u32, energy_bound: f64, what: &str) {
    for step in 0..steps {
        sim.step();
        assert!(
            sim.positions().iter().all(|p| p.is_finite())
                && sim.velocities().iter().all(|v| v.is_finite()),
            "{what}: not finite at step {step}"
        );
        let depth = sim.deepest_penetration_m();
        assert!(
            depth <= PENETRATION_TOLERANCE_M,
            "{what}: {depth} m inside the body at step {step}"
        );
        let energy = sim.energy();
        assert!(
            energy <= energy_bound,
            "{what}: energy {energy} above {energy_bound} at step {step}"
        );
    }
}

fn bound_over(sim: &HairSim, slack_per_particle: f64) -> f64 {
    sim.energy() + slack_per_particle * sim.particle_count() as f64
}

#[test]
fn ten_thousand_steps_at_60_hz_stay_finite_with_bounded_energy() {
    let motion = Motion {
        head_animation: (0..40)
            .map(|i| HeadKey {
                yaw_deg: if i % 2 == 0 { -40.0 } else { 40.0 },
                pitch_deg: if i % 4 == 1 { 15.0 } else { 0.0 },
                ..HeadKey::at(i as f64 * 4.0)
            })
            .collect(),
        ..Motion::default()
    };
    let mut sim = sim(&cap(6), &motion);
    // Turning the head does work on the hair: allow 2 J/kg per particle, far below any
    // blow-up (a particle at 10 m/s holds 50).
    let bound = bound_over(&sim, 2.0);
    run_checked(&mut sim, 10_000, bound, "10K steps");
    assert_eq!(sim.stats().steps, 10_000);
}

#[test]
fn a_still_head_keeps_the_modelled_style_and_loses_energy() {
    let mesh = cap(5);
    let mut sim = sim(&mesh, &Motion::default());
    let start = sim.energy();
    run_checked(&mut sim, 180, start + 1e-9, "still head");
    // Retention holds the style against gravity: every vertex within a centimetre.
    let posed = sim.posed_mesh();
    let worst = posed
        .columns
        .iter()
        .zip(&mesh.columns)
        .flat_map(|(a, b)| a.positions.iter().zip(&b.positions))
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(worst < 0.01, "the style sagged by {worst} m");
    assert!(sim.max_speed_m_per_s() < 0.01);
}

#[test]
fn the_same_inputs_give_the_same_bytes_whatever_the_frame_rate() {
    let motion = Motion {
        wind: Wind {
            speed_m_per_s: 4.0,
            ..Wind::default()
        },
        ..Motion::head_turn(0.1, 0.4, 60.0)
    };
    let mesh = cap(4);
    let bytes = |frames: u32, fps: f64| {
        let mut sim = sim(&mesh, &motion);
        for _ in 0..frames {
            sim.advance(1.0 / fps);
        }
        assert_eq!(sim.stats().steps, 60, "{fps} fps");
        sim.positions()
            .iter()
            .flat_map(|p| p.to_array().map(f64::to_bits))
            .collect::<Vec<u64>>()
    };
    let at_30 = bytes(30, 30.0);
    assert_eq!(at_30, bytes(120, 120.0));
    assert_eq!(at_30, bytes(60, 60.0));
}

#[test]
fn a_time_step_spike_takes_bounded_steps() {
    let mut sim = sim(&cap(4), &Motion::head_turn(0.0, 0.3, 45.0));
    assert_eq!(sim.advance(0.1), 6);
    // A stalled frame of 5 s simulates at most MAX_FRAME_S.
    assert_eq!(sim.advance(5.0), 15);
    assert_eq!(sim.advance(f64::NAN), 0);
    assert_eq!(sim.advance(-1.0), 0);
    let bound = bound_over(&sim, 2.0);
    run_checked(&mut sim, 60, bound, "after a spike");
}

#[test]
fn a_teleporting_head_carries_the_hair() {
    let jump = |key: HeadKey| Motion {
        head_animation: vec![HeadKey::at(0.5), key],
        ..Motion::default()
    };
    for (what, key) in [
        (
            "1 m teleport",
            HeadKey {
                translation_m: [1.0, 0.0, 0.0],
                ..HeadKey::at(0.5 + 1e-4)
            },
        ),
        (
            "180° turn in one frame",
            HeadKey {
                yaw_deg: 180.0,
                ..HeadKey::at(0.5 + 1.0 / 60.0)
            },
        ),
    ] {
        let mesh = cap(5);
        let mut sim = sim(&mesh, &jump(key.clone()));
        let bound = bound_over(&sim, 0.5) + 9.81 * 1.0 * sim.particle_count() as f64;
        run_checked(&mut sim, 90, bound, what);
        // After the cut the hair is where the carried style is, not strewn between.
        let pose = sim.pose();
        let worst = sim
            .posed_mesh()
            .columns
            .iter()
            .zip(&mesh.columns)
            .flat_map(|(a, b)| a.positions.iter().zip(&b.positions))
            .map(|(a, b)| pose.inverse_apply(*a).distance(*b))
            .fold(0.0, f64::max);
        assert!(
            worst < 0.02,
            "{what}: hair {worst} m from the carried style"
        );
    }
}

#[test]
fn wind_at_100_m_per_s_stays_attached_and_bounded() {
    let motion = Motion {
        wind: Wind {
            speed_m_per_s: 100.0,
            direction: [1.0, 0.2, 0.0],
            gust_strength: 1.0,
            gust_frequency_hz: 5.0,
        },
        ..Motion::default()
    };
    let mesh = cap(6);
    let mut sim = sim(&mesh, &motion);
    // The air can at most bring particles to its own speed (1 + gusts + crosswind).
    let fastest_air = 100.0 * (1.0 + 1.0 + 0.5);
    let bound = bound_over(&sim, 0.5 * fastest_air * fastest_air);
    run_checked(&mut sim, 300, bound, "100 m/s wind");
    // Columns stay inextensible enough to hold together: no vertex farther from its root
    // than 1.5× its column's modelled length.
    let posed = sim.posed_mesh();
    for (column, modelled) in posed.columns.iter().zip(&mesh.columns) {
        let length = modelled.w.last().copied().unwrap_or(0.0);
        let reach =
            column.positions[0].distance(*column.positions.last().expect("a column has a root"));
        assert!(reach <= 1.5 * length + 1e-9, "{reach} > 1.5 × {length}");
    }
}

#[test]
fn zero_length_and_coincident_columns_stay_finite() {
    let mut mesh = cap(4);
    // Column 0: every layer at the root (zero length). Column 1: a copy of column 2.
    let root = mesh.columns[0].positions[0];
    for p in &mut mesh.columns[0].positions {
        *p = root;
    }
    mesh.columns[1].positions = mesh.columns[2].positions.clone();
    let mut sim = sim(&mesh, &Motion::head_turn(0.0, 0.5, 90.0));
    let bound = bound_over(&sim, 2.0);
    run_checked(&mut sim, 240, bound, "degenerate columns");
}

#[test]
fn a_bundle_with_60_layers_is_stable() {
    let mesh = sphere_cap(HEAD_RADIUS_M, 0.5, 2, 60, 0.005);
    let mut sim = sim(&mesh, &Motion::head_turn(0.0, 0.5, 90.0));
    let bound = bound_over(&sim, 2.0);
    run_checked(&mut sim, 240, bound, "60 layers");
}

#[test]
fn a_body_with_a_hole_still_keeps_hair_out() {
    let mut body = head();
    // Open the bottom (a scan open at the neck).
    body.triangles.truncate(body.triangles.len() - 4 * 2 * 48);
    let mesh = cap(5);
    let mut sim = HairSim::with_body(&mesh, &body, &Motion::head_turn(0.0, 0.4, 120.0), &[]);
    let bound = bound_over(&sim, 2.0);
    run_checked(&mut sim, 240, bound, "body with a hole");
}

#[test]
fn draping_a_helmet_brings_it_down_onto_the_head() {
    // A helmet: layers sticking straight out along the normals, far off the head.
    let mesh = sphere_cap(HEAD_RADIUS_M, 1.2, 6, 5, 0.03);
    let locked = VertexRef {
        column: 24,
        layer: 5,
    };
    let (outcome, report) = drape(&mesh, &head(), &[], &[locked]).expect("drape");
    eprintln!("{report:?}");
    assert!(report.settled, "{report:?}");
    assert!(
        report.deepest_penetration_m <= PENETRATION_TOLERANCE_M,
        "{report:?}"
    );
    outcome.mesh.validate().expect("valid after the drape");
    assert_eq!(outcome.mesh.position(locked), mesh.position(locked));
    // Tips fell: the mean tip height dropped by more than a layer step.
    let tip_height = |m: &HairMesh| {
        m.columns
            .iter()
            .map(|c| c.positions.last().expect("a column has a root").y)
            .sum::<f64>()
            / m.columns.len() as f64
    };
    let drop = tip_height(&mesh) - tip_height(&outcome.mesh);
    assert!(drop > 0.03, "tips dropped only {drop} m");
    // Roots never move.
    for (a, b) in outcome.mesh.columns.iter().zip(&mesh.columns) {
        assert_eq!(a.positions[0], b.positions[0]);
    }
    // The interior it settled is locked (a later edit's placement keeps it) and kept its
    // simulated column lengths: no column longer than modelled by more than 5%.
    let topology = crate::model::mesh::Topology::build(&mesh);
    let interior: Vec<VertexRef> = outcome
        .mesh
        .locked
        .iter()
        .copied()
        .filter(|v| mesh.is_interior(&topology, v.column as usize, v.layer as usize))
        .collect();
    assert!(!interior.is_empty(), "settled interior vertices are locked");
    let length = |m: &HairMesh, c: usize| -> f64 {
        m.columns[c]
            .positions
            .windows(2)
            .map(|w| (w[1] - w[0]).length())
            .sum()
    };
    for c in 0..mesh.columns.len() {
        let ratio = length(&outcome.mesh, c) / length(&mesh, c);
        assert!(ratio < 1.05, "column {c} is {ratio}× its length");
    }
    // A lock in the mesh holds like one passed in: drape again with the tip locked in the
    // document.
    let mut with_lock = mesh.clone();
    with_lock.set_locked(&[locked], true);
    let (again, _) = drape(&with_lock, &head(), &[], &[]).expect("drape");
    assert_eq!(again.mesh.position(locked), mesh.position(locked));
}

#[test]
fn draping_some_bundles_leaves_the_others_alone() {
    let mesh = sphere_cap(HEAD_RADIUS_M, 1.2, 6, 3, 0.03);
    let (outcome, _) = drape(&mesh, &head(), &[0, 1], &[]).expect("drape");
    assert_eq!(outcome.affected_bundles, vec![0, 1]);
    // Their exterior vertices stay exactly; interior ones follow the whole layer's exterior
    // (the placement is global per layer), so they may shift.
    let topology = crate::model::mesh::Topology::build(&mesh);
    let far = &mesh.bundles[35];
    for &c in &far.vertices {
        for layer in 0..=far.layers as usize {
            if !mesh.is_interior(&topology, c as usize, layer) {
                assert_eq!(
                    outcome.mesh.columns[c as usize].positions[layer],
                    mesh.columns[c as usize].positions[layer]
                );
            }
        }
    }
    assert!(matches!(
        drape(&mesh, &head(), &[999], &[]),
        Err(EditError::BundleOutOfRange { .. })
    ));
}

/// Issue "Nothing lost, nothing blocked": a seek says what it costs before it runs, can be
/// stopped part way at a valid state, and a later seek continues from there.
#[test]
fn a_seek_is_estimated_before_it_runs_and_can_be_stopped() {
    let motion = Motion::head_turn(0.3, 0.6, 70.0);
    let mut simulated = sim(&cap(3), &motion);
    let estimate = SimulationEstimate::measure(&simulated, 600.0);
    assert_eq!(estimate.steps, 36_000, "600 s at 60 Hz");
    assert_eq!(
        simulated.time_s(),
        0.0,
        "measuring does not move the simulation"
    );
    assert!(estimate.step_s > 0.0);
    let over = SimulationEstimate {
        steps: 36_000,
        step_s: 0.217,
    };
    let line = over.describe(600.0);
    assert!(
        line.contains("36000 steps") && line.contains("2 h 10 min") && line.contains("budget"),
        "{line}"
    );
    assert!(
        !SimulationEstimate {
            steps: 10,
            step_s: 0.001
        }
        .over_budget()
    );
    // Stopped after 30 steps, then continued to 1 s: the same state as one seek to 1 s.
    let mut calls = 0;
    let ran = simulated.seek_with(1.0, &mut |done, total| {
        assert_eq!(total, 60);
        calls += 1;
        if done == 30 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    assert_eq!((ran, calls), (30, 30));
    assert!((simulated.time_s() - 0.5).abs() < 1e-12);
    assert_eq!(simulated.steps_to(1.0), 30);
    simulated.seek(1.0);
    let mut straight = sim(&cap(3), &motion);
    straight.seek(1.0);
    assert_eq!(simulated.positions(), straight.positions());
    // Back in time: from the start.
    assert_eq!(simulated.steps_to(0.25), 15);
}
