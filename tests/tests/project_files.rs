//! Project files: round trips, validation errors that name the JSON path, version checks,
//! and atomic saves that survive a writer killed mid-write.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};

use hairloom_core::io::project::{self, ProjectError};
use hairloom_core::{Document, History, Project};
use hairloom_tests::{grid_mesh, sample_paths};

#[test]
fn every_sample_loads_validates_and_round_trips_exactly() {
    let paths = sample_paths();
    assert!(paths.len() >= 4, "samples: {paths:?}");
    let dir = tempfile::tempdir().expect("temp dir");
    for path in paths {
        let project = project::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let copy = dir.path().join("copy.hairloom");
        project::save(&copy, &project).expect("save");
        let again = project::load(&copy).expect("reload");
        assert_eq!(again, project, "{}", path.display());
        // Saving is deterministic: the committed sample is exactly what we write.
        assert_eq!(
            std::fs::read(&copy).expect("read"),
            std::fs::read(&path).expect("read")
        );
    }
}

fn corrupt(edit: impl FnOnce(&mut serde_json::Value)) -> Result<Project, ProjectError> {
    let mesh = grid_mesh(3, 2, 2, 0.5);
    let project = Project::new(Document::new("grid", mesh));
    let mut value: serde_json::Value =
        serde_json::from_slice(&project::to_bytes(&project)).expect("json");
    edit(&mut value);
    let bytes = serde_json::to_vec_pretty(&value).expect("json");
    project::from_bytes(&bytes, Path::new("corrupt.hairloom"))
}

fn invalid_at(result: Result<Project, ProjectError>) -> (String, String) {
    match result {
        Err(ProjectError::Invalid {
            json_path, message, ..
        }) => (json_path, message),
        Err(other) => panic!("expected a validation error, got: {other}"),
        Ok(_) => panic!("corrupted project was accepted"),
    }
}

#[test]
fn validation_names_the_json_path() {
    let (path, message) = invalid_at(corrupt(|v| {
        v["document"]["hair_mesh"]["bundles"][4]["vertices"][2] = 999.into()
    }));
    assert_eq!(path, "document.hair_mesh.bundles[4].vertices[2]");
    assert!(message.contains("out of range"), "{message}");

    let (path, _) = invalid_at(corrupt(|v| {
        v["document"]["hair_mesh"]["columns"][3]["w"][1] = "tall".into()
    }));
    assert_eq!(path, "document.hair_mesh.columns[3].w[1]");

    let (path, message) = invalid_at(corrupt(|v| {
        v["document"]["hair_mesh"]["bundles"][0]["layers"] = 7.into();
    }));
    assert!(path.starts_with("document.hair_mesh.columns["), "{path}");
    assert!(message.contains("tallest bundle"), "{message}");

    let (path, message) = invalid_at(corrupt(|v| {
        v["document"]["hair_mesh"]["columns"][2]["w"][2] = serde_json::json!(-1.0);
    }));
    assert_eq!(path, "document.hair_mesh.columns[2].w[2]");
    assert!(message.contains("decreases"), "{message}");

    let (path, _) = invalid_at(corrupt(|v| {
        v["document"]["hair_mesh"]["columns"][0]["positions"][0] =
            serde_json::json!([0.0, null, 1.0]);
    }));
    assert_eq!(path, "document.hair_mesh.columns[0].positions[0][1]");

    let (path, _) = invalid_at(corrupt(|v| {
        v["document"]["surprise"] = true.into();
    }));
    assert!(path.starts_with("document"), "{path}");
}

#[test]
fn non_finite_numbers_are_refused() {
    let mesh = grid_mesh(2, 2, 1, 0.5);
    let text = String::from_utf8(project::to_bytes(&Project::new(Document::new("g", mesh))))
        .expect("utf8");
    // JSON has no NaN; an overflowing literal is the way a file can carry infinity.
    let first_number =
        text.find("\"positions\": [[").expect("positions") + "\"positions\": [[".len();
    let end = first_number + text[first_number..].find(',').expect("comma");
    let broken = format!("{}1e999{}", &text[..first_number], &text[end..]);
    let error =
        project::from_bytes(broken.as_bytes(), Path::new("inf.hairloom")).expect_err("infinite");
    assert!(error.to_string().contains("inf.hairloom"), "{error}");
}

#[test]
fn versions_and_garbage() {
    let newer = corrupt(|v| v["format_version"] = 99.into()).expect_err("newer");
    assert!(
        matches!(newer, ProjectError::NewerVersion { found: 99, .. }),
        "{newer}"
    );
    assert!(newer.to_string().contains("newer Hairloom"), "{newer}");
    let missing = corrupt(|v| {
        v.as_object_mut().expect("object").remove("format_version");
    })
    .expect_err("missing version");
    assert!(missing.to_string().contains("format_version"), "{missing}");
    for garbage in [
        &b""[..],
        b"{",
        b"[1,2]",
        b"\x00\x01binary",
        b"{\"format_version\": 1}",
    ] {
        let error =
            project::from_bytes(garbage, Path::new("garbage.hairloom")).expect_err("garbage");
        assert!(error.to_string().starts_with("garbage.hairloom"), "{error}");
    }
}

#[test]
fn a_version_1_file_loads_with_the_default_scene_and_saves_as_the_current_version() {
    // A version-1 file: no scene anywhere, the format number 1.
    let mesh = grid_mesh(3, 2, 2, 0.5);
    let mut value: serde_json::Value = serde_json::from_slice(&project::to_bytes(&Project::new(
        Document::new("old", mesh),
    )))
    .expect("json");
    value["format_version"] = 1.into();
    value["document"]
        .as_object_mut()
        .expect("document")
        .remove("scene")
        .expect("the current format writes a scene");
    let bytes = serde_json::to_vec_pretty(&value).expect("json");
    let loaded = project::from_bytes(&bytes, Path::new("old.hairloom")).expect("migrates");
    assert_eq!(
        loaded.document.scene,
        hairloom_core::model::scene::Scene::default()
    );
    assert_eq!(loaded.format_version, project::FORMAT_VERSION);
    let saved: serde_json::Value =
        serde_json::from_slice(&project::to_bytes(&loaded)).expect("json");
    assert_eq!(saved["format_version"], project::FORMAT_VERSION);
    assert!(saved["document"]["scene"]["lights"].is_array());
    // A scene problem in a file is named by its JSON path, and nothing is half-loaded.
    let (path, message) = invalid_at(corrupt(|v| {
        v["document"]["scene"]["material"]["longitudinal_roughness"] = (-0.5).into()
    }));
    assert_eq!(path, "document.scene.material.longitudinal_roughness");
    assert!(message.contains("-0.5"), "{message}");
}

#[test]
fn tampered_history_is_refused() {
    let mesh = grid_mesh(3, 2, 2, 0.5);
    let mut document = Document::new("grid", mesh);
    let mut history = History::default();
    let edited = hairloom_core::edit::extrude(
        &document.hair_mesh,
        &[0, 1],
        hairloom_core::edit::ExtrudeDirection::AlongNormal { distance: 0.3 },
    )
    .expect("extrude");
    let mut after = document.clone();
    after.hair_mesh = edited.mesh;
    assert!(history.commit(&mut document, "Extrude", after));
    let project = Project {
        history,
        ..Project::new(document)
    };
    let mut value: serde_json::Value =
        serde_json::from_slice(&project::to_bytes(&project)).expect("json");
    project::from_bytes(
        &serde_json::to_vec(&value).expect("json"),
        Path::new("ok.hairloom"),
    )
    .expect("intact history loads");
    // Change the document under the history (still a valid document on its own): the
    // extrusion's record no longer matches what the document holds.
    value["document"]["hair_mesh"]["columns"][0]["positions"][0][0] = serde_json::json!(0.25);
    let error = project::from_bytes(
        &serde_json::to_vec(&value).expect("json"),
        Path::new("t.hairloom"),
    )
    .expect_err("tampered");
    assert!(error.to_string().contains("history"), "{error}");
}

#[test]
fn a_writer_killed_mid_save_leaves_the_previous_file_intact() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("work.hairloom");
    let original = Project::new(Document::new("original", grid_mesh(4, 4, 2, 0.5)));
    project::save(&path, &original).expect("first save");
    let before = std::fs::read(&path).expect("read");

    let mut child = Command::new(env!("CARGO_BIN_EXE_slow_save"))
        .arg(&path)
        .arg("200")
        .stdout(Stdio::piped())
        .spawn()
        .expect("spawn slow_save");
    let stdout = child.stdout.take().expect("stdout");
    let mut lines = BufReader::new(stdout).lines();
    // Wait until at least two chunks are in the temporary file, then kill the writer.
    let mut chunks = 0;
    for line in lines.by_ref() {
        let line = line.expect("line");
        assert!(line.starts_with("wrote"), "{line}");
        chunks += 1;
        if chunks == 2 {
            break;
        }
    }
    child.kill().expect("kill");
    let status = child.wait().expect("wait");
    assert!(
        !status.success(),
        "the writer finished before it was killed"
    );

    // The temporary file exists and is partial: the kill really happened mid-write.
    let temps: Vec<_> = std::fs::read_dir(dir.path())
        .expect("list")
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert_eq!(temps.len(), 1, "expected one partial temporary file");
    assert!(temps[0].metadata().expect("meta").len() >= 2 * project::WRITE_CHUNK_BYTES as u64);

    assert_eq!(
        std::fs::read(&path).expect("read"),
        before,
        "the previous file changed"
    );
    assert_eq!(project::load(&path).expect("still loads"), original);
    // A later save succeeds and removes the killed writer's leftover temporary file.
    project::save(&path, &original).expect("save again");
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .expect("list")
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "left behind: {leftovers:?}");
}

#[cfg(unix)]
#[test]
fn a_link_planted_at_a_guessable_temporary_name_is_not_followed() {
    let dir = tempfile::tempdir().expect("temp dir");
    let victim = dir.path().join("victim.txt");
    std::fs::write(&victim, b"precious").expect("victim");
    let path = dir.path().join("scalp.hairloom");
    // Every name an attacker could guess from our process id, in the old and new schemes.
    let pid = std::process::id();
    for name in [
        format!(".scalp.hairloom.tmp-{pid}"),
        format!(".scalp.hairloom.tmp-{pid}-"),
        format!(".scalp.hairloom.tmp-{}", pid + 1),
    ] {
        std::os::unix::fs::symlink(&victim, dir.path().join(name)).expect("plant link");
    }
    let project = hairloom_core::Project::new(hairloom_core::Document::new(
        "scalp",
        hairloom_tests::grid_mesh(2, 2, 1, 0.1),
    ));
    project::save(&path, &project).expect("save");
    assert_eq!(std::fs::read(&victim).expect("victim"), b"precious");
    assert_eq!(project::load(&path).expect("loads"), project);
    assert!(
        !std::fs::symlink_metadata(&path)
            .expect("saved")
            .file_type()
            .is_symlink()
    );
}

#[test]
fn head_samples_keep_hair_outside_the_cranium() {
    use hairloom_core::samples::{HEAD_CRANIUM_RADII, HEAD_SCALE, tips_inside_ellipsoid};
    for path in sample_paths()
        .iter()
        .filter(|p| p.to_string_lossy().contains("head_"))
    {
        let project = project::load(path).expect("sample");
        let mesh = &project.document.hair_mesh;
        let inside = tips_inside_ellipsoid(mesh, HEAD_CRANIUM_RADII * HEAD_SCALE);
        assert_eq!(
            inside,
            0,
            "{}: {inside} tips inside the head",
            path.display()
        );
        // And the growth is real: every tip is off the scalp.
        assert!(
            mesh.columns
                .iter()
                .all(|c| c.positions.len() < 2 || c.w.last().is_some_and(|w| *w > 0.005))
        );
    }
}

/// An export over an existing runtime bundle, killed after each file it writes (and once
/// mid-way through its first file), always leaves a bundle that loads as wholly old or
/// wholly new — never a mix of old and new textures.
#[test]
fn a_runtime_bundle_export_killed_at_any_point_loads_wholly_old_or_new() {
    use hairloom_core::io::runtime_bundle::{load_runtime_bundle, write_bundle_folder};
    let temp = tempfile::tempdir().expect("temp dir");
    let dir = temp.path().join("bundle");
    let old = hairloom_tests::bundle_variant_files(0);
    let new = hairloom_tests::bundle_variant_files(1);
    let textures = |files: &[(String, Vec<u8>)]| {
        let memory: std::collections::HashMap<String, Vec<u8>> = files.iter().cloned().collect();
        hairloom_core::io::runtime_bundle::load_runtime_bundle_from(&memory, "memory")
            .expect("loads from memory")
            .textures
    };
    let (old_textures, new_textures) = (textures(&old), textures(&new));
    assert_ne!(old_textures.hair_mesh, new_textures.hair_mesh);
    let (mut saw_old, mut saw_new) = (false, false);
    // Kill after 0..=files announcements; 0 kills during the first file's write.
    for kill_after in 0..=new.len() {
        let _ = std::fs::remove_dir_all(&dir);
        write_bundle_folder(&dir, &old, |_| {}).expect("old bundle");
        let mut child = Command::new(env!("CARGO_BIN_EXE_slow_bundle"))
            .arg(&dir)
            .arg("1")
            .arg("150")
            .stdout(Stdio::piped())
            .spawn()
            .expect("spawn slow_bundle");
        let stdout = child.stdout.take().expect("stdout");
        let mut lines = BufReader::new(stdout).lines();
        for _ in 0..kill_after {
            let line = lines.next().expect("a line").expect("utf-8");
            assert!(line.starts_with("wrote"), "{line}");
        }
        child.kill().expect("kill");
        let _ = child.wait();
        let loaded = load_runtime_bundle(&dir)
            .unwrap_or_else(|e| panic!("killed after {kill_after} files: {e}"))
            .textures;
        let is_old = loaded.hair_mesh == old_textures.hair_mesh && loaded.u == old_textures.u;
        let is_new = loaded.hair_mesh == new_textures.hair_mesh && loaded.u == new_textures.u;
        assert!(
            is_old || is_new,
            "killed after {kill_after} files: a mixed bundle"
        );
        saw_old |= is_old;
        saw_new |= is_new && kill_after == new.len();
    }
    assert!(
        saw_old && saw_new,
        "the kills covered before and after the commit"
    );
    // A finished export leaves exactly its own files and its ledger (stale ones and
    // temporaries gone, also those of a writer killed between its commit and its clean-up).
    write_bundle_folder(&dir, &new, |_| {}).expect("new bundle");
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    on_disk.sort();
    let mut expected: Vec<String> = new
        .iter()
        .map(|(n, _)| n.clone())
        .chain([hairloom_core::io::runtime_bundle::EXPORT_LEDGER_FILE.to_string()])
        .collect();
    expected.sort();
    assert_eq!(on_disk, expected);
}

/// Issue "Hostile and oversized input": a project is read only from a regular file, and its
/// history is capped so verification stays bounded.
#[test]
fn special_files_and_oversized_histories_are_refused_by_name() {
    #[cfg(unix)]
    {
        let error = project::load(Path::new("/dev/zero")).expect_err("a device");
        assert!(
            matches!(error, ProjectError::Input(_)) && error.to_string().contains("a device"),
            "{error}"
        );
    }
    let (json_path, message) = invalid_at(corrupt(|v| v["history"]["limit"] = 20_000.into()));
    assert_eq!(json_path, "history.limit");
    assert!(message.contains("cap of 10000"), "{message}");
    // 20,001 (empty) redo entries: refused before any is verified.
    let (json_path, message) = invalid_at(corrupt(|v| {
        v["history"]["redo"] = serde_json::Value::Array(vec![
            serde_json::json!({"kind": "group", "label": "x", "children": []});
            20_001
        ]);
    }));
    assert_eq!(json_path, "history", "{message}");
    assert!(message.contains("20001 undo and redo entries"), "{message}");
}

/// Measured with the body's own distance field (the simulator's): no hair-mesh vertex above
/// the scalp lies inside the head scan by more than the field's interpolation error.
#[test]
fn head_samples_keep_every_hair_mesh_vertex_out_of_the_body() {
    use hairloom_core::simulate::body_sdf::{BodySdf, DEFAULT_RESOLUTION};
    for path in sample_paths()
        .iter()
        .filter(|p| p.to_string_lossy().contains("head_"))
    {
        let document = project::load(path).expect("sample").document;
        let sdf = BodySdf::build(&document.body, DEFAULT_RESOLUTION, 0.02);
        let tolerance_m = 0.5 * sdf.cell_m();
        let inside: Vec<(usize, usize, f64)> = document
            .hair_mesh
            .columns
            .iter()
            .enumerate()
            .flat_map(|(c, column)| {
                column
                    .positions
                    .iter()
                    .enumerate()
                    .skip(1)
                    .map(move |(k, p)| (c, k, *p))
            })
            .map(|(c, k, p)| (c, k, sdf.distance_m(p)))
            .filter(|(_, _, d)| *d < -tolerance_m)
            .collect();
        assert!(
            inside.is_empty(),
            "{}: {} vertices inside the body, e.g. {:?}",
            path.display(),
            inside.len(),
            &inside[..inside.len().min(3)]
        );
    }
}
