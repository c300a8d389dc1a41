//! Fitting on grooms whose hair mesh is known: our own generated strands, read back as a
//! groom from elsewhere would be. Every check compares against the known mesh or styling.

use std::ops::ControlFlow;

use glam::DVec3;

use super::measure::{MeasureOptions, measure};
use super::*;
use crate::io::groom_in::InputGroom;
use crate::samples::{grid_scalp, sphere_cap, straight_layers};
use crate::strands::reference::{StrandOptions, generate};

fn go() -> impl FnMut(&str, f64) -> ControlFlow<()> {
    |_, _| ControlFlow::Continue(())
}

/// The strands of `document` as a groom read from a file.
fn groom_of(document: &Document, strands_per_bundle: u32) -> InputGroom {
    let strands = generate(
        document,
        &StrandOptions {
            strands_per_bundle,
            vertices_log2: 6,
            ..StrandOptions::default()
        },
    );
    let mut groom = InputGroom {
        starts: vec![0],
        ..InputGroom::default()
    };
    for strand in &strands {
        groom
            .points
            .extend(strand.points.iter().map(|p| p.as_vec3().to_array()));
        groom.starts.push(groom.points.len() as u32);
    }
    groom
}

/// A 4 × 4 patch of 5 cm bundles, 20 cm of hair bending over, 6 layers.
fn bent_patch() -> Document {
    let scalp = grid_scalp(4, 4, |s, t| DVec3::new(0.2 * s, 0.0, 0.2 * t));
    let mut mesh = straight_layers(scalp, 6, DVec3::new(0.0, 0.033, 0.0));
    for column in &mut mesh.columns {
        let root = column.positions[0];
        for (k, p) in column.positions.iter_mut().enumerate() {
            let k = k as f64;
            *p = root + DVec3::new(0.004 * k * k, 0.03 * k, 0.002 * k * (root.x * 10.0));
        }
    }
    mesh.update_w();
    Document::new("patch", mesh)
}

fn given(document: &Document) -> ScalpSource {
    ScalpSource::Given {
        scalp: document.hair_mesh.clone(),
        body: BodyMesh::default(),
    }
}

#[test]
fn a_groom_of_known_shape_comes_back_within_the_targets() {
    let mut document = bent_patch();
    document.styling.global.length.fraction = 0.3;
    let groom = groom_of(&document, 64);
    let fitted = fit(
        &groom,
        given(&document),
        "patch",
        &FitOptions::default(),
        &mut go(),
    )
    .expect("fits");
    let report = measure(&groom, &fitted, &MeasureOptions::default());
    assert!(report.pooled.mean < 0.005, "{}", report.summary());
    assert!(report.pooled.p95 < 0.02, "{}", report.summary());
    assert!(
        report.root_placement.max < 1e-9,
        "roots lie on the given scalp"
    );
    assert!(report.length_error < 0.05, "{}", report.summary());
    let fraction = fitted.document.styling.global.length.fraction;
    assert!((fraction - 0.3).abs() < 0.08, "length variation {fraction}");
    // Every bundle holds strands, so every bundle grows, with the fit's layers.
    assert!(
        fitted
            .document
            .hair_mesh
            .bundles
            .iter()
            .all(|b| b.layers == 12)
    );
    assert!(fitted.document.validate().is_ok());
}

#[test]
fn a_curl_is_found_with_its_rate_and_radius() {
    let mut document = bent_patch();
    let curl = &mut document.styling.global.curl;
    curl.radius_m = 0.006;
    curl.turns_per_m = 30.0;
    curl.radius_jitter = 0.0;
    let groom = groom_of(&document, 32);
    let fitted = fit(
        &groom,
        given(&document),
        "curly",
        &FitOptions::default(),
        &mut go(),
    )
    .expect("fits");
    let found = &fitted.document.styling.global.curl;
    assert!(
        (found.turns_per_m - 30.0).abs() < 4.0,
        "turns per metre {}",
        found.turns_per_m
    );
    assert!(
        (found.radius_m - 0.006).abs() < 0.002,
        "radius {}",
        found.radius_m
    );
    // The curl restores most of the strands' length (a helix of these is 1.6 × its axis;
    // without the curl the error would be 37 %). 15.6 % today: the radius comes out 4.5 mm
    // on this sharply bent patch (6.5 mm on the curly sample, 4 % length error there).
    let report = measure(&groom, &fitted, &MeasureOptions::default());
    assert!(report.length_error < 0.2, "{}", report.summary());
}

#[test]
fn straight_hair_gets_no_curl() {
    let document = bent_patch();
    let groom = groom_of(&document, 32);
    let fitted = fit(
        &groom,
        given(&document),
        "straight",
        &FitOptions::default(),
        &mut go(),
    )
    .expect("fits");
    assert_eq!(fitted.document.styling.global.curl.radius_m, 0.0);
}

#[test]
fn a_scalp_is_built_from_the_roots_when_none_is_given() {
    let mesh = sphere_cap(0.1, 1.0, 10, 6, 0.02);
    let document = Document::new("cap", mesh);
    let groom = groom_of(&document, 32);
    let fitted = fit(
        &groom,
        ScalpSource::FromRoots,
        "cap",
        &FitOptions::default(),
        &mut go(),
    )
    .expect("fits");
    let report = measure(&groom, &fitted, &MeasureOptions::default());
    assert!(report.growing_bundles > 50, "{}", report.summary());
    // Roots lie on the built scalp to well under a millimetre on a 10 cm head.
    assert!(report.root_placement.p95 < 0.003, "{}", report.summary());
    assert!(report.pooled.mean < 0.005, "{}", report.summary());
    assert!(report.pooled.p95 < 0.02, "{}", report.summary());
}

#[test]
fn a_root_far_from_the_given_scalp_is_named() {
    let document = bent_patch();
    let mut groom = groom_of(&document, 8);
    // Lift curve 5 by 10 cm: its root is off the scalp.
    let range = groom.starts[5] as usize..groom.starts[6] as usize;
    for p in &mut groom.points[range] {
        p[1] += 0.1;
    }
    match fit(
        &groom,
        given(&document),
        "far",
        &FitOptions::default(),
        &mut go(),
    ) {
        Err(FitError::RootFarFromScalp { curve, .. }) => assert_eq!(curve, 5),
        Err(other) => panic!("wrong error: {other}"),
        Ok(_) => panic!("a root 10 cm off the scalp was accepted"),
    }
}

#[test]
fn degenerate_roots_give_errors_not_panics() {
    // Every root at one point, and every root on one line: no surface to build.
    for roots in [
        vec![[0.0f32, 0.0, 0.0]; 50],
        (0..50)
            .map(|i| [i as f32 * 0.01, 0.0, 0.0])
            .collect::<Vec<_>>(),
    ] {
        let mut groom = InputGroom {
            starts: vec![0],
            ..InputGroom::default()
        };
        for r in &roots {
            groom.points.push(*r);
            groom.points.push([r[0], r[1] + 0.1, r[2]]);
            groom.starts.push(groom.points.len() as u32);
        }
        match fit(
            &groom,
            ScalpSource::FromRoots,
            "degenerate",
            &FitOptions::default(),
            &mut go(),
        ) {
            Err(FitError::EmptyScalp) | Err(FitError::RootFarFromScalp { .. }) => {}
            Err(other) => panic!("unexpected error: {other}"),
            Ok(fitted) => {
                // A thin scalp is acceptable if it holds the roots and is valid.
                assert!(fitted.document.validate().is_ok());
            }
        }
    }
}

#[test]
fn fitting_is_deterministic_across_thread_counts_and_can_be_cancelled() {
    let document = bent_patch();
    let groom = groom_of(&document, 32);
    let one = FitOptions {
        threads: 1,
        ..FitOptions::default()
    };
    let three = FitOptions {
        threads: 3,
        ..FitOptions::default()
    };
    let a = fit(&groom, given(&document), "a", &one, &mut go()).expect("fits");
    let b = fit(&groom, given(&document), "a", &three, &mut go()).expect("fits");
    assert!(
        a.document == b.document,
        "one and three threads fitted different documents"
    );
    let cancelled = fit(&groom, given(&document), "a", &one, &mut |step, _| {
        if step == "columns" {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    assert!(matches!(cancelled, Err(FitError::Cancelled)));
}

#[test]
fn bad_layer_counts_are_refused() {
    let document = bent_patch();
    let groom = groom_of(&document, 4);
    for layers in [0, 65] {
        let options = FitOptions {
            layers,
            ..FitOptions::default()
        };
        assert!(matches!(
            fit(&groom, given(&document), "a", &options, &mut go()),
            Err(FitError::Layers(_))
        ));
    }
}

#[test]
fn strand_axes_keep_degenerate_strands_whole() {
    // A zero-length strand, a two-point one and a normal helix: every axis keeps its root
    // and stays finite.
    let mut groom = InputGroom {
        starts: vec![0],
        ..InputGroom::default()
    };
    let mut add = |points: Vec<[f32; 3]>| {
        groom.points.extend(points);
        groom.starts.push(groom.points.len() as u32);
    };
    add(vec![[0.1, 0.2, 0.3]; 5]);
    add(vec![[0.0, 0.0, 0.0], [0.0, 0.01, 0.0]]);
    add((0..200)
        .map(|k| {
            let t = k as f32 * 0.001;
            let phase = std::f32::consts::TAU * 40.0 * t;
            [0.005 * phase.cos(), t, 0.005 * phase.sin()]
        })
        .collect());
    let axes = super::styling::strand_axes(&groom, 40.0, 0.005);
    assert_eq!(axes.curve_count(), 3);
    for i in 0..3 {
        let axis = axes.curve(i);
        assert_eq!(axis[0], groom.curve(i)[0], "curve {i} keeps its root");
        assert!(axis.iter().flatten().all(|c| c.is_finite()), "curve {i}");
    }
    // The helix's axis lies on the y axis, away from the ends' half turn.
    let helix = axes.curve(2);
    let middle = &helix[helix.len() / 4..3 * helix.len() / 4];
    let off = middle
        .iter()
        .map(|p| (p[0] * p[0] + p[2] * p[2]).sqrt())
        .fold(0.0f32, f32::max);
    assert!(
        off < 0.0005,
        "the axis strays {off} m from the helix's axis"
    );
}
