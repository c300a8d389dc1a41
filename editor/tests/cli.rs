//! The `hairloom` command line: `check` accepts every sample and rejects corrupted copies
//! with a message naming the problem (exit 2); `info` prints counts; `import` writes a
//! project that `check` accepts.

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
    let project = hairloom_core::project::load(&sample).expect("load");
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
