//! Headless renders through the game's path (strands generated on the GPU from the runtime
//! textures): a runtime bundle renders exactly like its project, and every sample matches its
//! golden image within a mean-error tolerance.
//!
//! Golden images live in `editor/tests/golden/` and were rendered on lavapipe. After an
//! intended change of the picture, regenerate them with
//! `HAIRLOOM_UPDATE_GOLDEN=1 cargo test -p hairloom-editor --test render_golden`; on a
//! mismatch the new image is written under `target/golden-failures/` and its path printed.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Mean absolute difference per channel (0-255) a render may have from its golden image:
/// room for another rasteriser's MSAA and float rounding, far below a changed picture (a
/// different view of the same sample differs by > 10).
const MEAN_ERROR_TOLERANCE: f64 = 2.0;
const SIZE: &str = "192x192";

fn hairloom() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hairloom"))
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn samples() -> Vec<PathBuf> {
    let mut samples: Vec<PathBuf> = std::fs::read_dir(root().join("assets/samples"))
        .expect("samples")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "hairloom"))
        .collect();
    samples.sort();
    samples
}

/// Runs `hairloom render ARGS --out OUT`; `None` (skip) when there is no adapter and a GPU
/// is not required.
fn render(args: &[&std::ffi::OsStr], out: &Path) -> Option<image::RgbaImage> {
    let output = hairloom()
        .arg("render")
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .expect("run hairloom");
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success()
        && stderr.contains("no GPU adapter")
        && hairloom_render::device::skip_test_without_gpu("render", &stderr)
    {
        return None;
    }
    assert!(output.status.success(), "render {args:?}: {stderr}");
    Some(image::open(out).expect("a PNG").to_rgba8())
}

#[test]
fn a_runtime_bundle_renders_exactly_like_its_project() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (sample, precision) in [("teapot_fur", "f16"), ("head_curly", "f32")] {
        let project = root().join(format!("assets/samples/{sample}.hairloom"));
        let bundle = dir.path().join(format!("{sample}_runtime"));
        let output = hairloom()
            .arg("export")
            .arg(&project)
            .arg("--runtime")
            .arg(&bundle)
            .args(["--strands-per-bundle", "8", "--precision", precision])
            .output()
            .expect("export");
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let common = ["--size", SIZE, "--strands-per-bundle", "8"].map(std::ffi::OsStr::new);
        let mut project_args = vec![project.as_os_str()];
        project_args.extend(common);
        project_args.extend(["--precision", precision].map(std::ffi::OsStr::new));
        let Some(from_project) = render(&project_args, &dir.path().join("project.png")) else {
            return;
        };
        let mut bundle_args = vec![bundle.as_os_str()];
        bundle_args.extend(common);
        let from_bundle = render(&bundle_args, &dir.path().join("bundle.png")).expect("rendered");
        let differing = from_project
            .pixels()
            .zip(from_bundle.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(
            differing, 0,
            "{sample} ({precision}): {differing} pixels differ between the project and its runtime bundle"
        );
    }
}

/// Renders each `(name, args)` and compares it with `editor/tests/golden/{name}.png`
/// (or writes it there under `HAIRLOOM_UPDATE_GOLDEN=1`).
fn match_golden_images(cases: &[(String, Vec<std::ffi::OsString>)]) {
    let update = std::env::var("HAIRLOOM_UPDATE_GOLDEN").as_deref() == Ok("1");
    let dir = tempfile::tempdir().expect("temp dir");
    let failures_dir = root().join("target/golden-failures");
    let mut failures = Vec::new();
    for (name, args) in cases {
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
        let out = dir.path().join("render.png");
        let Some(image) = render(&args, &out) else {
            return;
        };
        // A golden image must show something: hair and body cover part of the frame.
        let background = image.get_pixel(0, 0).0;
        let drawn = common::drawn_pixels(&image, background);
        assert!(
            drawn > image.as_raw().len() / 4 / 20,
            "{name}: only {drawn} pixels drawn"
        );
        let golden_path = root().join(format!("editor/tests/golden/{name}.png"));
        if update {
            std::fs::create_dir_all(golden_path.parent().expect("folder")).expect("golden folder");
            image.save(&golden_path).expect("write golden image");
            eprintln!("updated {}", golden_path.display());
            continue;
        }
        let error = match image::open(&golden_path) {
            Ok(golden) => common::mean_error(&image, &golden.to_rgba8()),
            Err(e) => {
                eprintln!("{}: {e}", golden_path.display());
                f64::INFINITY
            }
        };
        eprintln!("{name}: mean error {error:.3} (tolerance {MEAN_ERROR_TOLERANCE})");
        if error > MEAN_ERROR_TOLERANCE {
            let new_path = failures_dir.join(format!("{name}.png"));
            std::fs::create_dir_all(new_path.parent().expect("folder")).expect("failure dir");
            image.save(&new_path).expect("write failed render");
            failures.push(format!(
                "{name}: mean error {error:.3} > {MEAN_ERROR_TOLERANCE}; new image: {}",
                new_path.display()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{}\n(HAIRLOOM_UPDATE_GOLDEN=1 regenerates the golden images)",
        failures.join("\n")
    );
}

fn os_args(args: &[&str]) -> Vec<std::ffi::OsString> {
    args.iter().map(std::ffi::OsString::from).collect()
}

#[test]
fn samples_match_their_golden_images() {
    let cases: Vec<_> = samples()
        .into_iter()
        .map(|sample| {
            let name = sample
                .file_stem()
                .expect("file name")
                .to_string_lossy()
                .into_owned();
            let mut args = vec![sample.into_os_string()];
            args.extend(os_args(&["--size", SIZE, "--strands-per-bundle", "16"]));
            (name, args)
        })
        .collect();
    match_golden_images(&cases);
}

/// Every effect alone and the combinations the scene presets use, on one sample: a change to
/// any effect's shader shows here.
pub const EFFECT_COMBINATIONS: [&str; 8] = [
    "none",
    "marschner",
    "marschner,opacity-shadow-maps",
    "marschner,deep-opacity-maps",
    "marschner,deep-opacity-maps,body-shadows",
    "marschner,deep-opacity-maps,dual-scattering",
    "kajiya-kay,deep-opacity-maps,body-shadows,width-oit",
    "all",
];

#[test]
fn effect_combinations_match_their_golden_images() {
    let sample = root().join("assets/samples/head_curly.hairloom");
    let cases: Vec<_> = EFFECT_COMBINATIONS
        .iter()
        .map(|effects| {
            let name = format!("effects/{}", effects.replace(',', "+"));
            let mut args = vec![sample.clone().into_os_string()];
            args.extend(os_args(&[
                "--size",
                "160x160",
                "--strands-per-bundle",
                "16",
                "--effects",
                effects,
            ]));
            (name, args)
        })
        .collect();
    match_golden_images(&cases);
}

/// Far hair (seed 001) on the long sample as it moves away: near (mostly strands), then most
/// bundles as thick hairs shaded by the aggregated BCSDF.
#[test]
fn far_hair_matches_its_golden_images_at_three_distances() {
    let sample = root().join("assets/samples/head_long_wavy.hairloom");
    let cases: Vec<_> = ["1", "2", "3"]
        .iter()
        .map(|distance| {
            let mut args = vec![sample.clone().into_os_string()];
            args.extend(os_args(&[
                "--size",
                SIZE,
                "--strands-per-bundle",
                "16",
                "--view",
                "front",
                "--distance",
                distance,
                "--effects",
                "marschner,deep-opacity-maps,body-shadows,dual-scattering,far-aggregated",
            ]));
            (format!("far/long_wavy_{distance}x"), args)
        })
        .collect();
    match_golden_images(&cases);
}

#[test]
fn the_golden_comparison_sees_a_changed_picture() {
    // The same sample from another side must fail the tolerance: the check can fail.
    let dir = tempfile::tempdir().expect("temp dir");
    let sample = root().join("assets/samples/head_long_wavy.hairloom");
    let args = [sample.as_os_str()]
        .into_iter()
        .chain(
            [
                "--size",
                SIZE,
                "--strands-per-bundle",
                "16",
                "--view",
                "side",
            ]
            .map(std::ffi::OsStr::new),
        )
        .collect::<Vec<_>>();
    let Some(side) = render(&args, &dir.path().join("side.png")) else {
        return;
    };
    let golden = image::open(root().join("editor/tests/golden/head_long_wavy.png"))
        .expect("golden image")
        .to_rgba8();
    let error = common::mean_error(&side, &golden);
    assert!(error > 5.0 * MEAN_ERROR_TOLERANCE, "{error}");
}
