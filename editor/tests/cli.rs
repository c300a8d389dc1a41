//! The `hairloom` command line: `check` accepts every sample and rejects corrupted copies
//! with a message naming the problem (exit 2); `info` prints counts; `import` writes a
//! project that `check` accepts.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn hairloom() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hairloom"))
}

fn samples() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/samples");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("assets/samples")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "hairloom"))
        .collect();
    paths.sort();
    paths
}

fn run(command: &mut Command) -> (i32, String, String) {
    let output = command.output().expect("run hairloom");
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn check_accepts_every_sample() {
    let samples = samples();
    assert!(samples.len() >= 4);
    for sample in samples {
        let (code, stdout, stderr) = run(hairloom().arg("check").arg(&sample));
        assert_eq!(code, 0, "{}: {stderr}", sample.display());
        assert!(stdout.contains("valid"), "{stdout}");
    }
}

#[test]
fn check_rejects_corrupted_copies_with_a_named_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sample = samples()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("short"))
        .expect("short sample");
    let text = std::fs::read_to_string(&sample).expect("read sample");
    let mut value: serde_json::Value = serde_json::from_str(&text).expect("json");
    // (name, JSON pointer to corrupt, value written there, text the error must contain)
    let cases = [
        (
            "index",
            "/document/hair_mesh/bundles/7/vertices/1",
            serde_json::json!(123456),
            "document.hair_mesh.bundles[7].vertices[1]",
        ),
        (
            "type",
            "/document/hair_mesh/columns/5/positions/1",
            serde_json::json!("up"),
            "document.hair_mesh.columns[5].positions[1]",
        ),
        (
            "version",
            "/format_version",
            serde_json::json!(7),
            "newer Hairloom",
        ),
    ];
    for (name, pointer, bad, expected) in cases {
        let mut copy = value.clone();
        *copy.pointer_mut(pointer).expect("pointer exists") = bad;
        let path = dir.path().join(format!("{name}.hairloom"));
        std::fs::write(&path, serde_json::to_string(&copy).expect("json")).expect("write");
        let (code, _, stderr) = run(hairloom().arg("check").arg(&path));
        assert_eq!(code, 2, "{name}: {stderr}");
        assert!(
            stderr.contains(expected) && stderr.contains(&format!("{name}.hairloom")),
            "{name}: {stderr}"
        );
    }
    // Truncated file.
    let path = dir.path().join("truncated.hairloom");
    std::fs::write(&path, &text[..text.len() / 3]).expect("write");
    let (code, _, stderr) = run(hairloom().arg("check").arg(&path));
    assert_eq!(code, 2);
    assert!(
        stderr.contains("truncated.hairloom") && stderr.contains("not a Hairloom project"),
        "{stderr}"
    );
    // Missing file.
    let (code, _, stderr) = run(hairloom()
        .arg("check")
        .arg(dir.path().join("nope.hairloom")));
    assert_eq!(code, 2);
    assert!(
        stderr.contains("nope.hairloom") && stderr.contains("cannot read"),
        "{stderr}"
    );
    value["document"]["name"] = "still valid".into();
    let path = dir.path().join("renamed.hairloom");
    std::fs::write(&path, serde_json::to_string(&value).expect("json")).expect("write");
    assert_eq!(run(hairloom().arg("check").arg(&path)).0, 0);
}

#[test]
fn info_prints_counts() {
    let sample = samples()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("long_wavy"))
        .expect("sample");
    let (code, stdout, stderr) = run(hairloom().arg("info").arg("--json").arg(&sample));
    assert_eq!(code, 0, "{stderr}");
    let info: serde_json::Value = serde_json::from_str(&stdout).expect("json output");
    let project = hairloom_core::io::project::load(&sample).expect("load");
    let mesh = &project.document.hair_mesh;
    assert_eq!(info["stats"]["root_faces"], mesh.bundles.len());
    assert_eq!(info["stats"]["root_vertices"], mesh.columns.len());
    assert_eq!(info["stats"]["vertices"], mesh.vertex_count());
    assert_eq!(info["stats"]["max_layers"], mesh.max_layers());
    let (code, text, _) = run(hairloom().arg("info").arg(&sample));
    assert_eq!(code, 0);
    assert!(
        text.contains("root faces:") && text.contains("Lee Perry-Smith"),
        "{text}"
    );
}

#[test]
fn import_writes_a_valid_project() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("head.hairloom");
    let glb = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/head/LeePerrySmith.glb");
    let (code, stdout, stderr) = run(hairloom()
        .arg("import")
        .arg(&glb)
        .arg("--out")
        .arg(&out)
        .arg("--scale")
        .arg("0.045"));
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("quads"), "{stdout}");
    let (code, _, stderr) = run(hairloom().arg("check").arg(&out));
    assert_eq!(code, 0, "{stderr}");
    let (code, _, stderr) = run(hairloom()
        .arg("import")
        .arg(dir.path().join("missing.glb"))
        .arg("--out")
        .arg(&out));
    assert_eq!(code, 2);
    assert!(stderr.contains("missing.glb"), "{stderr}");
}

/// A glTF whose body is animated imports with that animation as the scene's head animation
/// (so the scene has motion), and says so.
#[test]
fn import_takes_the_body_animation_into_the_scene() {
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = dir.path().join("turning.glb");
    std::fs::write(&glb, hairloom_tests::animated_quad_glb(|_| {})).expect("write");
    let out = dir.path().join("turning.hairloom");
    let (code, stdout, stderr) = run(hairloom().arg("import").arg(&glb).arg("--out").arg(&out));
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("body animation: 2 keys over 1.00 s"),
        "{stdout}"
    );
    let project = hairloom_core::io::project::load(&out).expect("project");
    let motion = project.document.scene.motion.expect("the scene has motion");
    assert_eq!(motion.head_animation.len(), 2);
    assert!((motion.head_animation[1].yaw_deg - 90.0).abs() < 1e-3);
}

/// Issue 35: `--hair-on` names where hair grows on an imported body; the rest stays body.
#[test]
fn import_grows_hair_only_where_hair_on_says() {
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = dir.path().join("body.glb");
    std::fs::write(&glb, hairloom_tests::body_with_materials_glb()).expect("write");
    let out = dir.path().join("body.hairloom");
    let (code, stdout, stderr) = run(hairloom()
        .arg("import")
        .arg(&glb)
        .args(["--hair-on", "material:Scalp", "--out"])
        .arg(&out));
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("2 quads") && stdout.contains("(body only: 1 face)"),
        "{stdout}"
    );
    let document = hairloom_core::io::project::load(&out)
        .expect("project")
        .document;
    assert_eq!(document.hair_mesh.bundles.len(), 2);
    assert_eq!(document.body.triangles.len(), 6);

    let (code, _, stderr) = run(hairloom()
        .arg("import")
        .arg(&glb)
        .args(["--hair-on", "colour:r>0.75", "--out"])
        .arg(&out));
    assert_eq!(code, 0, "{stderr}");
    let document = hairloom_core::io::project::load(&out)
        .expect("project")
        .document;
    assert_eq!(document.hair_mesh.bundles.len(), 1);

    // Named refusals: no such material (the file's are listed), a malformed region.
    let (code, _, stderr) = run(hairloom()
        .arg("import")
        .arg(&glb)
        .args(["--hair-on", "material:Hair", "--out"])
        .arg(&out));
    assert_ne!(code, 0);
    assert!(
        stderr.contains("no material named \"Hair\"") && stderr.contains("\"Skin\" (1 face)"),
        "{stderr}"
    );
    let (code, _, stderr) = run(hairloom()
        .arg("import")
        .arg(&glb)
        .args(["--hair-on", "colour:r=1", "--out"])
        .arg(&out));
    assert_eq!(code, 2);
    assert!(stderr.contains("colour:r=1"), "{stderr}");
}

/// Issue 35: `--mesh` names the mesh hair grows on; `--whole-body` makes every mesh the
/// body.
#[test]
fn import_whole_body_takes_every_mesh_as_the_body() {
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = dir.path().join("character.glb");
    std::fs::write(&glb, hairloom_tests::two_mesh_glb()).expect("write");
    let out = dir.path().join("character.hairloom");
    let (code, _, stderr) = run(hairloom().arg("import").arg(&glb).arg("--out").arg(&out));
    assert_ne!(code, 0);
    assert!(
        stderr.contains("several meshes") && stderr.contains("\"scalp\""),
        "{stderr}"
    );
    for (whole, triangles) in [(false, 2), (true, 4)] {
        let mut command = hairloom();
        command
            .arg("import")
            .arg(&glb)
            .args(["--mesh", "scalp", "--out"])
            .arg(&out);
        if whole {
            command.arg("--whole-body");
        }
        let (code, stdout, stderr) = run(&mut command);
        assert_eq!(code, 0, "{stderr}");
        let document = hairloom_core::io::project::load(&out)
            .expect("project")
            .document;
        assert_eq!(document.hair_mesh.bundles.len(), 1);
        assert_eq!(document.body.triangles.len(), triangles, "{stdout}");
    }
}

/// Runs a validator; `None` when it is not installed (allowed outside `make test`).
fn validator(program: &Path, args: &[&Path], cwd: &Path) -> Option<(i32, String)> {
    if !program.exists() && program.components().count() > 1 {
        return None;
    }
    let output = Command::new(program)
        .args(args)
        .current_dir(cwd)
        .output()
        .ok()?;
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    Some((output.status.code().unwrap_or(-1), text))
}

#[test]
fn exports_of_every_sample_pass_third_party_validators() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let tools = root.join("tools/validate");
    let required = std::env::var("HAIRLOOM_REQUIRE_VALIDATORS").as_deref() == Ok("1");
    let dir = tempfile::tempdir().expect("temp dir");
    let mut glbs = Vec::new();
    let mut ktx2s = Vec::new();
    let mut usdas = Vec::new();
    let mut abcs = Vec::new();
    for (i, sample) in samples().iter().enumerate() {
        let name = sample
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let runtime = dir.path().join(format!("{name}_runtime"));
        let files: Vec<PathBuf> = ["hair", "usda", "glb", "abc"]
            .iter()
            .map(|e| dir.path().join(format!("{name}.{e}")))
            .collect();
        let precision = if i % 2 == 0 { "f32" } else { "f16" };
        let mut command = hairloom();
        command
            .arg("export")
            .arg(sample)
            .arg("--runtime")
            .arg(&runtime);
        // Hair cards of the first sample: GLBs for glTF-Validator, the atlas beside them.
        let cards = (i == 0).then(|| dir.path().join(format!("{name}_cards")));
        if let Some(cards) = &cards {
            command.arg("--cards").arg(cards);
        }
        for file in &files {
            command.arg("--strands").arg(file);
        }
        command.args([
            "--strands-per-bundle",
            "3",
            "--vertices-log2",
            "3",
            "--precision",
            precision,
        ]);
        let (code, stdout, stderr) = run(&mut command);
        assert_eq!(code, 0, "{name}: {stderr}");
        // Five textures, the far-hair file and the manifest, plus the body mesh every sample
        // has; the data files are content-addressed, so their names come from the manifest.
        let manifest: serde_json::Value = serde_json::from_slice(
            &std::fs::read(runtime.join("manifest.json")).expect("manifest"),
        )
        .expect("manifest JSON");
        let body = runtime.join(manifest["body"].as_str().expect("a body file"));
        assert!(body.exists(), "{name}: no body file");
        assert!(stdout.contains("runtime bundle, 8 files"), "{stdout}");
        let far = runtime.join(manifest["far_hair"]["file"].as_str().expect("far hair"));
        assert!(far.exists(), "{name}: no far-hair file");
        // The bundle's full detail is what --vertices-log2 asked for, like the strand files.
        assert_eq!(manifest["lod"]["max_vertices_log2"], 3, "{name}");
        glbs.push(body);
        if let Some(cards) = &cards {
            let manifest: serde_json::Value = serde_json::from_slice(
                &std::fs::read(cards.join("cards.json")).expect("cards.json"),
            )
            .expect("cards.json is JSON");
            let levels = manifest["levels"].as_array().expect("levels");
            assert_eq!(levels.len(), 3, "{manifest}");
            let triangles: Vec<u64> = levels
                .iter()
                .map(|l| l["triangles"].as_u64().expect("triangles"))
                .collect();
            assert!(triangles.windows(2).all(|w| w[1] < w[0]), "{triangles:?}");
            let (w, h) = (
                manifest["atlas"]["width"].as_u64().expect("width") as u32,
                manifest["atlas"]["height"].as_u64().expect("height") as u32,
            );
            for map in ["albedo", "coverage", "depth", "flow", "root_to_tip", "id"] {
                let png = image::open(cards.join(format!("{map}.png"))).expect("a map");
                assert_eq!((png.width(), png.height()), (w, h), "{map}");
            }
            // Unreal's card texture set beside them, with the channels its slots take.
            for (stem, channels) in [
                ("T_HairCards_Depth", 1),
                ("T_HairCards_Coverage", 1),
                ("T_HairCards_Tangent", 3),
                ("T_HairCards_Attribute", 4),
            ] {
                let file = manifest["atlas"]["unreal"][stem].as_str().expect(stem);
                let png = image::open(cards.join(file)).expect("an Unreal texture");
                assert_eq!((png.width(), png.height()), (w, h), "{stem}");
                assert_eq!(png.color().channel_count(), channels, "{stem}");
            }
            for level in levels {
                let glb = cards.join(level["file"].as_str().expect("file"));
                // Every map is embedded and named by the material's extras.
                let bytes = std::fs::read(&glb).expect("a card GLB");
                let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("4")) as usize;
                let json: serde_json::Value =
                    serde_json::from_slice(&bytes[20..20 + json_len]).expect("GLB JSON");
                let maps = &json["materials"][0]["extras"]["hairloom_maps"];
                for name in ["coverage", "depth", "flow", "root_to_tip", "id"] {
                    let texture = maps[name]["texture"].as_u64().expect(name) as usize;
                    let image = json["textures"][texture]["source"]
                        .as_u64()
                        .expect("source");
                    assert_eq!(json["images"][image as usize]["name"], name);
                }
                glbs.push(glb);
            }
        }
        // Our own reading of the .hair header: counts match what was generated.
        let hair = std::fs::read(&files[0]).expect("hair file");
        assert_eq!(&hair[..4], b"HAIR");
        let count = |at: usize| {
            u32::from_le_bytes([hair[at], hair[at + 1], hair[at + 2], hair[at + 3]]) as usize
        };
        let (strands, points, segments) = (count(4), count(8), count(16));
        assert_eq!(points, strands * (segments + 1));
        // Points, then a thickness and an RGB colour per point.
        assert_eq!(hair.len(), 128 + points * (12 + 4 + 12));
        usdas.push(files[1].clone());
        glbs.push(files[2].clone());
        abcs.push(files[3].clone());
        for texture in ["hair_mesh", "uv", "w", "u", "v"] {
            let file = manifest[texture]["file"].as_str().expect("a texture file");
            ktx2s.push(runtime.join(file));
        }
    }
    let mut node_args: Vec<&Path> = vec![Path::new("validate.mjs")];
    node_args.extend(glbs.iter().map(PathBuf::as_path));
    node_args.extend(ktx2s.iter().map(PathBuf::as_path));
    let node = if tools.join("node_modules/gltf-validator").exists() {
        validator(Path::new("node"), &node_args, &tools)
    } else {
        None
    };
    let python = root.join("target/validate-venv/bin/python");
    let mut usd_args: Vec<&Path> = vec![Path::new("check_usd.py")];
    usd_args.extend(usdas.iter().map(PathBuf::as_path));
    let usd = validator(&python, &usd_args, &tools);
    let mut abc_args: Vec<&Path> = vec![Path::new("check_abc.py")];
    abc_args.extend(abcs.iter().map(PathBuf::as_path));
    let abc = validator(&python, &abc_args, &tools);
    for (what, result) in [
        ("glTF-Validator/ktx-parse (npm)", node),
        ("usd-core (PyPI)", usd),
        ("alembic3d (PyPI)", abc),
    ] {
        match result {
            Some((code, text)) => {
                eprintln!("{text}");
                assert_eq!(code, 0, "{what} rejected an export:\n{text}");
                assert!(
                    !text.contains("MISMATCH") && !text.contains("INCONSISTENT"),
                    "{text}"
                );
            }
            None if required => {
                panic!("{what} is not installed; `make test` installs it (make deps)")
            }
            None => eprintln!("skipped {what}: not installed (run `make deps`)"),
        }
    }
}

#[test]
fn render_draws_shaded_hair_over_the_body() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("teapot.png");
    let sample = samples()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("teapot"))
        .expect("teapot sample");
    let (code, stdout, stderr) = run(hairloom()
        .arg("render")
        .arg(&sample)
        .arg("--out")
        .arg(&out)
        .args(["--size", "200x160", "--strands-per-bundle", "6"]));
    if code != 0
        && stderr.contains("no GPU adapter")
        && hairloom_render::device::skip_test_without_gpu("render", &stderr)
    {
        return;
    }
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("200x160"), "{stdout}");
    let image = image::open(&out).expect("a PNG").to_rgba8();
    assert_eq!(image.dimensions(), (200, 160));
    // Background is near-black grey; the body is light and warm; the hair is brown.
    let pixels: Vec<[u8; 4]> = image.pixels().map(|p| p.0).collect();
    let background = pixels[0];
    let differing = pixels
        .iter()
        .filter(|p| p.iter().zip(&background).any(|(a, b)| a.abs_diff(*b) > 12))
        .count();
    assert!(
        differing > pixels.len() / 20,
        "only {differing} of {} pixels drawn",
        pixels.len()
    );
    let hair_like = pixels
        .iter()
        .filter(|p| p[0] > p[2] + 8 && p[0] < 200)
        .count();
    assert!(hair_like > 100, "no brown strand pixels ({hair_like})");
    // Bad input is an error, not a panic.
    let (code, _, stderr) = run(hairloom()
        .arg("render")
        .arg(&sample)
        .arg("--out")
        .arg(&out)
        .args(["--size", "0x10"]));
    assert_eq!(code, 2);
    assert!(stderr.contains("--size"), "{stderr}");
}

#[test]
fn simulate_writes_a_moving_sequence_and_an_animated_usd() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sample = samples()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("short"))
        .expect("short sample");
    // The sample's scene is still: simulate refuses without a motion to play.
    let (code, _, stderr) = run(hairloom()
        .arg("simulate")
        .arg(&sample)
        .arg("--out")
        .arg(dir.path()));
    assert_eq!(code, 2);
    assert!(stderr.contains("no motion"), "{stderr}");

    let (code, stdout, stderr) = run(hairloom()
        .arg("simulate")
        .arg(&sample)
        .arg("--out")
        .arg(dir.path())
        .args(["--motion", "head-turn", "--seconds", "1", "--fps", "3"])
        .args(["--size", "96x96", "--effects", "none", "--view", "front"])
        .args(["--strands-per-bundle", "2", "--usda", "--abc"]));
    if code != 0
        && stderr.contains("no GPU adapter")
        && hairloom_render::device::skip_test_without_gpu("simulate", &stderr)
    {
        return;
    }
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("60 steps so far"), "{stdout}");
    let frames: Vec<image::RgbaImage> = (0..4)
        .map(|i| {
            image::open(dir.path().join(format!("frame_{i:04}.png")))
                .expect("a frame")
                .to_rgba8()
        })
        .collect();
    // The head turns: the last frame differs from the first.
    assert!(common::mean_error(&frames[0], &frames[3]) > 1.0);
    // The animated strands open in Pixar's USD with a time sample per frame.
    let usda = dir.path().join("hair.usda");
    let text = std::fs::read_to_string(&usda).expect("hair.usda");
    assert!(text.contains("points.timeSamples") && text.contains("endTimeCode = 3"));
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let tools = root.join("tools/validate");
    let python = root.join("target/validate-venv/bin/python");
    // And the Alembic groom opens in the Alembic library with a sample per frame.
    let abc = dir.path().join("hair.abc");
    for (what, script, file, expected) in [
        ("usd-core", "check_usd.py", &usda, "4 time sample(s)"),
        ("alembic3d", "check_abc.py", &abc, "4 sample(s)"),
    ] {
        match validator(&python, &[Path::new(script), file], &tools) {
            Some((code, text)) => {
                assert_eq!(code, 0, "{what} rejected the animation:\n{text}");
                assert!(text.contains(expected), "{text}");
            }
            None if std::env::var("HAIRLOOM_REQUIRE_VALIDATORS").as_deref() == Ok("1") => {
                panic!("{what} is not installed; `make test` installs it (make deps)")
            }
            None => eprintln!("skipped {what}: not installed (run `make deps`)"),
        }
    }
    // Hostile numbers are refused by name.
    for (flag, value) in [("--seconds", "1e9"), ("--fps", "0"), ("--seconds", "NaN")] {
        let (code, _, stderr) = run(hairloom()
            .arg("simulate")
            .arg(&sample)
            .arg("--out")
            .arg(dir.path())
            .args(["--motion", "gravity", flag, value]));
        assert_eq!(code, 2, "{flag} {value}");
        assert!(stderr.contains(flag), "{stderr}");
    }
}

/// `export --curve runtime` writes the strands as the runtime generates them (the
/// two-quadratic split at texture precision): as many as the exact curves, from the same
/// roots, but not the same points. (`tests/tests/texture_path.rs` checks them against the
/// reference generator point by point.)
#[test]
fn export_curve_runtime_writes_the_strands_the_runtime_draws() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sample = samples()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("head_short_straight"))
        .expect("the short sample");
    let read_hair = |curve: &str| {
        let file = dir.path().join(format!("{curve}.hair"));
        let (code, _, stderr) = run(hairloom()
            .arg("export")
            .arg(&sample)
            .arg("--strands")
            .arg(&file)
            .args(["--strands-per-bundle", "2", "--vertices-log2", "3"])
            .args(["--curve", curve]));
        assert_eq!(code, 0, "{curve}: {stderr}");
        let bytes = std::fs::read(&file).expect("hair file");
        let count = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        let (strands, points) = (count(4) as usize, count(8) as usize);
        let xyz: Vec<[f32; 3]> = bytes[128..128 + points * 12]
            .chunks_exact(12)
            .map(|c| {
                let f = |i: usize| f32::from_le_bytes(c[i..i + 4].try_into().expect("4 bytes"));
                [f(0), f(4), f(8)]
            })
            .collect();
        (strands, xyz)
    };
    let (exact_count, exact) = read_hair("exact");
    let (runtime_count, runtime) = read_hair("runtime");
    assert_eq!(exact_count, runtime_count);
    assert_eq!(exact.len(), runtime.len());
    assert_ne!(exact, runtime, "the runtime curves are not the exact ones");
    // Same roots (the first point of each 9-point strand), in some order.
    let roots = |points: &[[f32; 3]]| {
        let mut roots: Vec<[i64; 3]> = points
            .chunks_exact(9)
            .map(|s| s[0].map(|x| (x * 1e5).round() as i64))
            .collect();
        roots.sort();
        roots
    };
    assert_eq!(roots(&exact), roots(&runtime));
}

/// `--cards` alone still honours the strand caps: an oversized `--vertices-log2` is refused
/// by name before anything is generated or written.
#[test]
fn export_cards_refuses_oversized_strands_by_name() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sample = samples().into_iter().next().expect("a sample");
    let cards = dir.path().join("cards");
    let (code, _, stderr) = run(hairloom()
        .arg("export")
        .arg(&sample)
        .arg("--cards")
        .arg(&cards)
        .args(["--vertices-log2", "16"]));
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("--vertices-log2 16"), "{stderr}");
    assert!(!cards.exists());
}

/// Issue "Nothing lost, nothing blocked": every strand export at the documented maxima
/// (4096 strands per bundle, 1025 vertices per strand; a project of 115,200 bundles at the
/// defaults) is refused up front with the size it would need — never an allocation abort —
/// and writes nothing.
#[test]
fn strand_exports_at_the_documented_maxima_are_refused_with_their_size() {
    let dir = tempfile::tempdir().expect("temp dir");
    let teapot = samples()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("teapot"))
        .expect("teapot sample");
    let maxima = ["--strands-per-bundle", "4096", "--vertices-log2", "10"];
    let outputs = ["x.hair", "x.usda", "x.glb", "x.abc"].map(|name| dir.path().join(name));
    let mut cases: Vec<Vec<std::ffi::OsString>> = outputs
        .iter()
        .map(|out| vec!["--strands".into(), out.clone().into_os_string()])
        .collect();
    cases.push(vec![
        "--strands".into(),
        outputs[0].clone().into_os_string(),
        "--curve".into(),
        "runtime".into(),
    ]);
    cases.push(vec![
        "--cards".into(),
        dir.path().join("cards").into_os_string(),
    ]);
    for args in &cases {
        let (code, _, stderr) = run(hairloom()
            .arg("export")
            .arg(&teapot)
            .args(args)
            .args(maxima));
        assert_ne!(code, 0, "{args:?}");
        assert!(
            stderr.contains("1209139200 points")
                && stderr.contains("GB of memory")
                && stderr.contains("--strands-per-bundle"),
            "{args:?}: {stderr}"
        );
        // Exit code 2 is an error the program reported; an abort is a signal (-1 here).
        assert_eq!(code, 2, "{args:?}: {stderr}");
    }
    // A project of 115,200 bundles passes `check` and is refused at the default settings.
    let mut mesh = hairloom_tests::grid_mesh(360, 320, 1, 0.01);
    for column in &mut mesh.columns {
        for p in &mut column.positions {
            *p *= 0.01;
        }
    }
    let big = dir.path().join("big.hairloom");
    hairloom_core::io::project::save(
        &big,
        &hairloom_core::Project::new(hairloom_core::Document::new("big", mesh)),
    )
    .expect("save");
    let (code, _, stderr) = run(hairloom().arg("check").arg(&big));
    assert_eq!(code, 0, "{stderr}");
    let (code, _, stderr) = run(hairloom()
        .arg("export")
        .arg(&big)
        .arg("--strands")
        .arg(&outputs[0]));
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("7372800 strands × 33 vertices"), "{stderr}");
    let written: Vec<_> = std::fs::read_dir(dir.path())
        .expect("list")
        .map(|e| e.expect("entry").file_name())
        .filter(|name| name != "big.hairloom")
        .collect();
    assert!(written.is_empty(), "written: {written:?}");
}

/// Curls need vertices: the curly sample (45 turns/m, 1.2× at the tip, ~9.5 cm of w) is
/// drawn with 65 vertices per strand by default; plain straight hair keeps 17. Seventeen
/// vertices drew its ringlets as straw-like zigzags.
#[test]
fn renders_give_curly_styles_the_vertices_their_turns_need() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/samples");
    let log2 = |name: &str| {
        let project = hairloom_core::io::project::load(&dir.join(format!("{name}.hairloom")))
            .expect("sample loads");
        let document = project.document;
        let runtime = hairloom_core::runtime::hair::RuntimeHair::from_document(
            &document,
            &hairloom_core::runtime::hair::RuntimeOptions::default(),
        );
        assert_eq!(
            runtime.strand_vertices_log2(),
            document.strand_vertices_log2(),
            "{name}: the runtime reads the w the document has"
        );
        document.strand_vertices_log2()
    };
    assert_eq!(log2("head_curly"), 6);
    assert_eq!(log2("head_long_straight"), 4);
    assert!(log2("head_long_wavy") >= 5, "7 cycles/m over 30 cm");
    // Exports give games and other tools the curls too (never fewer than 33 vertices).
    let export = |name: &str| {
        let project = hairloom_core::io::project::load(&dir.join(format!("{name}.hairloom")))
            .expect("sample loads");
        hairloom_editor::files::export_vertices_log2(&project.document)
    };
    assert_eq!(export("head_curly"), 6);
    assert_eq!(export("head_long_straight"), 5);
}

/// Issue 35: `maps` brings a density map painted elsewhere (a grey PNG over the scalp's uv)
/// into a project as one undo step that `check` accepts and that thins the export; an
/// oversized image, a file that is not an image and an unknown map are refused by name,
/// leaving the project as it was.
#[test]
fn maps_brings_painted_images_in_as_one_undo_step_and_refuses_bad_ones_by_name() {
    use hairloom_core::model::root_maps::RootMapChannel;
    let dir = tempfile::tempdir().expect("temp dir");
    let sample = samples()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("short"))
        .expect("short sample");
    let project = dir.path().join("maps.hairloom");
    std::fs::copy(&sample, &project).expect("copy");
    let before = hairloom_core::io::project::load(&project).expect("load");
    // 16 × 8: black on the left half (no hair), white on the right.
    let density = dir.path().join("density.png");
    image::GrayImage::from_fn(16, 8, |x, _| image::Luma([if x < 8 { 0 } else { 255 }]))
        .save(&density)
        .expect("png");
    let (code, stdout, stderr) = run(hairloom()
        .arg("maps")
        .arg(&project)
        .arg("--density")
        .arg(&density));
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("density from"), "{stdout}");
    let after = hairloom_core::io::project::load(&project).expect("load");
    let maps = &after.document.root_maps;
    assert_eq!((maps.width(), maps.height()), (16, 8));
    let density_values = maps.channel_values(RootMapChannel::Density);
    assert_eq!(density_values[0], 0.0);
    assert_eq!(density_values[15], 1.0);
    assert_eq!(after.history.undo.len(), before.history.undo.len() + 1);
    assert_eq!(
        after.history.undo.last().expect("a step").label(),
        "Import maps"
    );
    let (code, _, stderr) = run(hairloom().arg("check").arg(&project));
    assert_eq!(code, 0, "{stderr}");
    let saved = std::fs::read(&project).expect("read");
    for (args, names) in [
        (
            vec!["--density".to_string(), "huge".to_string()],
            "larger than 4096",
        ),
        (
            vec!["--length".to_string(), "text".to_string()],
            "not an image",
        ),
        (vec!["--clear".to_string(), "fuzz".to_string()], "not a map"),
        (vec![], "nothing to do"),
    ] {
        let huge = dir.path().join("huge");
        image::GrayImage::new(4097, 1)
            .save_with_format(&huge, image::ImageFormat::Png)
            .expect("png");
        std::fs::write(dir.path().join("text"), "not a picture").expect("write");
        let mut command = hairloom();
        command.arg("maps").arg(&project).current_dir(dir.path());
        command.args(&args);
        let (code, _, stderr) = run(&mut command);
        assert_ne!(code, 0, "{args:?}");
        assert!(stderr.contains(names), "{args:?}: {stderr}");
        assert_eq!(
            std::fs::read(&project).expect("read"),
            saved,
            "left as it was"
        );
    }
    // A colour image (RGBA: its alpha the colour's weight) paints the colour map; the runtime
    // bundle carries it as an sRGB texture.
    let colour = dir.path().join("colour.png");
    image::RgbaImage::from_fn(16, 8, |x, _| {
        image::Rgba([200, 60, 20, if x < 8 { 255 } else { 0 }])
    })
    .save(&colour)
    .expect("png");
    let (code, stdout, stderr) = run(hairloom()
        .arg("maps")
        .arg(&project)
        .arg("--colour")
        .arg(&colour));
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("colour from"), "{stdout}");
    let coloured = hairloom_core::io::project::load(&project).expect("load");
    let maps = &coloured.document.root_maps;
    assert_eq!(maps.colour_texels()[0], [200, 60, 20, 255]);
    assert_eq!(maps.colour_texels()[15], [200, 60, 20, 0]);
    let bundle = dir.path().join("bundle");
    let (code, _, stderr) = run(hairloom()
        .arg("export")
        .arg(&project)
        .arg("--runtime")
        .arg(&bundle));
    assert_eq!(code, 0, "{stderr}");
    let manifest = std::fs::read_to_string(bundle.join("manifest.json")).expect("manifest");
    assert!(manifest.contains("R8G8B8A8_SRGB"), "{manifest}");
    // Clearing every painted map takes the textures away.
    let (code, _, stderr) = run(hairloom()
        .arg("maps")
        .arg(&project)
        .args(["--clear", "density", "--clear", "colour"]));
    assert_eq!(code, 0, "{stderr}");
    let cleared = hairloom_core::io::project::load(&project).expect("load");
    assert!(cleared.document.root_maps.is_empty());
}

/// Issue 35 (look-dev): `render --turntable N` writes N pictures going once round the hair,
/// the camera and the lights turning together: frame 0 is the plain picture from --view,
/// the others differ; frame 2 of 4 (half a turn) matches neither the front picture nor a
/// plain render from behind (the lights came round too). Too many frames are refused.
#[test]
fn render_turntable_goes_round_the_hair_with_its_lights() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sample = samples()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("short"))
        .expect("short sample");
    let render = |out: &Path, extra: &[&str]| {
        run(hairloom()
            .arg("render")
            .arg(&sample)
            .arg("--out")
            .arg(out)
            .args([
                "--size",
                "96x96",
                "--strands-per-bundle",
                "4",
                "--effects",
                "none",
            ])
            .args(extra))
    };
    let out = dir.path().join("turn.png");
    let (code, stdout, stderr) = render(&out, &["--view", "front", "--turntable", "4"]);
    if code != 0
        && stderr.contains("no GPU adapter")
        && hairloom_render::device::skip_test_without_gpu("render", &stderr)
    {
        return;
    }
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("(180°)"), "{stdout}");
    let frames: Vec<Vec<u8>> = (0..4)
        .map(|i| {
            let path = dir.path().join(format!("turn_{i:03}.png"));
            image::open(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .to_rgba8()
                .into_raw()
        })
        .collect();
    assert!(!dir.path().join("turn.png").exists(), "frames only");
    let plain = |view: &str| {
        let path = dir.path().join(format!("{view}.png"));
        let (code, _, stderr) = render(&path, &["--view", view]);
        assert_eq!(code, 0, "{stderr}");
        image::open(&path).expect("png").to_rgba8().into_raw()
    };
    assert_eq!(
        frames[0],
        plain("front"),
        "frame 0 is the picture from --view"
    );
    for i in 1..4 {
        assert_ne!(frames[i], frames[0], "frame {i} turned");
    }
    assert_ne!(
        frames[2],
        plain("0,0.1,-1"),
        "the lights turned with the camera"
    );
    let (code, _, stderr) = render(&out, &["--turntable", "361"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("at most 360"), "{stderr}");
}
