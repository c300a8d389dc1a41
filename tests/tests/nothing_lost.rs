//! Issue "Nothing lost, nothing blocked": an export touches only its own files, keeps the
//! permissions of what it writes over, and cleans up after writers that were killed.

use hairloom_core::io::project;
use hairloom_core::io::runtime_bundle::{
    EXPORT_LEDGER_FILE, MANIFEST_FILE, load_runtime_bundle, write_bundle_folder,
};
use hairloom_tests::bundle_variant_files;

/// Sorted names of the entries of `dir`.
fn listing(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A process id no process can have (above Linux's largest `pid_max`, 2^22).
const DEAD_PID: u32 = 4_194_305;

#[test]
fn a_runtime_export_removes_only_files_it_wrote_itself() {
    let temp = tempfile::tempdir().expect("temp dir");
    let dir = temp.path();
    // The user's own files, some named exactly like files a bundle writes.
    let users: Vec<(String, Vec<u8>)> = [
        ("body.glb", b"the user's head mesh".as_slice()),
        ("uv.ktx2", b"a texture of theirs"),
        ("w.glb", b"another"),
        ("notes.txt", b"unrelated"),
        // A content-addressed name whose content does not hash to it.
        ("hair_mesh.0123456789abcdef.ktx2", b"not ours"),
    ]
    .iter()
    .map(|(n, b)| (n.to_string(), b.to_vec()))
    .collect();
    for (name, bytes) in &users {
        std::fs::write(dir.join(name), bytes).expect("user file");
    }
    let first = bundle_variant_files(0);
    let second = bundle_variant_files(1);
    write_bundle_folder(dir, &first, |_| {}).expect("first export");
    write_bundle_folder(dir, &second, |_| {}).expect("second export");
    load_runtime_bundle(dir).expect("the second bundle loads");
    for (name, bytes) in &users {
        assert_eq!(&std::fs::read(dir.join(name)).expect(name), bytes, "{name}");
    }
    // Exactly the user's files, the second bundle's and the export ledger: the first
    // bundle's are gone.
    let mut expected: Vec<String> = users
        .iter()
        .map(|(n, _)| n.clone())
        .chain(second.iter().map(|(n, _)| n.clone()))
        .chain([EXPORT_LEDGER_FILE.to_string()])
        .collect();
    expected.sort();
    expected.dedup();
    assert_eq!(listing(dir), expected);

    // A file the previous manifest names but the user changed since is theirs now: kept.
    write_bundle_folder(dir, &first, |_| {}).expect("third export");
    let (edited_name, _) = &first[0];
    std::fs::write(dir.join(edited_name), b"edited by hand").expect("edit");
    write_bundle_folder(dir, &second, |_| {}).expect("fourth export");
    assert_eq!(
        std::fs::read(dir.join(edited_name)).expect("kept"),
        b"edited by hand"
    );
}

#[test]
fn a_manifest_that_is_not_ours_is_never_written_over() {
    let temp = tempfile::tempdir().expect("temp dir");
    let dir = temp.path();
    let theirs = br#"{"name": "my web app", "version": 3}"#;
    std::fs::write(dir.join(MANIFEST_FILE), theirs).expect("their manifest");
    let error = write_bundle_folder(dir, &bundle_variant_files(0), |_| {})
        .expect_err("refused")
        .to_string();
    assert!(
        error.contains("not a Hairloom runtime manifest") && error.contains("empty folder"),
        "{error}"
    );
    assert_eq!(
        std::fs::read(dir.join(MANIFEST_FILE)).expect("kept"),
        theirs
    );
    assert_eq!(
        listing(dir),
        vec![MANIFEST_FILE.to_string()],
        "nothing written"
    );
}

#[test]
fn a_damaged_data_file_is_written_again_not_reused() {
    let temp = tempfile::tempdir().expect("temp dir");
    let dir = temp.path();
    let files = bundle_variant_files(0);
    write_bundle_folder(dir, &files, |_| {}).expect("export");
    let (name, bytes) = &files[0];
    // Damage at the same size: the name still exists and the length still matches.
    let mut damaged = bytes.clone();
    let middle = damaged.len() / 2;
    damaged[middle] ^= 0xff;
    std::fs::write(dir.join(name), &damaged).expect("damage");
    write_bundle_folder(dir, &files, |_| {}).expect("re-export");
    assert_eq!(&std::fs::read(dir.join(name)).expect("read"), bytes);
    load_runtime_bundle(dir).expect("loads");
}

#[test]
fn temporaries_of_killed_exports_go_whatever_the_next_export_writes() {
    let temp = tempfile::tempdir().expect("temp dir");
    let dir = temp.path();
    write_bundle_folder(dir, &bundle_variant_files(0), |_| {}).expect("export");
    // What a writer killed mid-file leaves: temporaries of data files this export will not
    // write (another content, so another name) and of the manifest.
    let leftovers = [
        format!(".hair_mesh.00000000deadbeef.ktx2.tmp-{DEAD_PID}-aBcDeF"),
        format!(".body.1111111111111111.glb.tmp-{DEAD_PID}-x1y2z3"),
        format!(".{MANIFEST_FILE}.tmp-{DEAD_PID}-q9w8e7"),
    ];
    // A temporary of a live writer (this process's parent) and a user file that merely
    // looks like one are kept.
    let parent = std::os::unix::process::parent_id();
    let kept = [
        format!(".w.2222222222222222.ktx2.tmp-{parent}-livewr"),
        format!(".notes.txt.tmp-{DEAD_PID}-theirs"),
    ];
    for name in leftovers.iter().chain(&kept) {
        std::fs::write(dir.join(name), b"partial").expect("plant");
    }
    write_bundle_folder(dir, &bundle_variant_files(1), |_| {}).expect("export other content");
    let after = listing(dir);
    for name in &leftovers {
        assert!(!after.contains(name), "left behind: {name}");
    }
    for name in &kept {
        assert!(after.contains(name), "removed: {name}");
    }
}

/// The process's umask, read without changing it (Linux's `/proc/self/status`).
fn umask() -> Option<u32> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("Umask:"))?;
    u32::from_str_radix(line.trim_start_matches("Umask:").trim(), 8).ok()
}

#[cfg(unix)]
#[test]
fn written_files_follow_the_umask_and_overwrites_keep_their_mode() {
    use std::os::unix::fs::PermissionsExt as _;
    let mode = |path: &std::path::Path| {
        std::fs::metadata(path)
            .expect("metadata")
            .permissions()
            .mode()
            & 0o777
    };
    let umask = umask().expect("this test reads the umask from /proc/self/status (Linux)");
    let temp = tempfile::tempdir().expect("temp dir");
    let project_path = temp.path().join("shared.hairloom");
    let document = hairloom_tests::bundle_variant(0);
    let saved = hairloom_core::Project::new(document);
    project::save(&project_path, &saved).expect("save");
    assert_eq!(
        mode(&project_path),
        0o666 & !umask,
        "a new file gets 0666 less the umask ({umask:03o})"
    );
    // Overwriting keeps whatever the owner chose, wider or narrower than the umask.
    for chosen in [0o664, 0o640, 0o600, 0o644] {
        std::fs::set_permissions(&project_path, std::fs::Permissions::from_mode(chosen))
            .expect("chmod");
        project::save(&project_path, &saved).expect("save over");
        assert_eq!(mode(&project_path), chosen, "{chosen:03o}");
    }
    // The same for every file of a runtime bundle, old or new.
    let bundle = temp.path().join("bundle");
    let first = bundle_variant_files(0);
    write_bundle_folder(&bundle, &first, |_| {}).expect("export");
    for (name, _) in &first {
        assert_eq!(mode(&bundle.join(name)), 0o666 & !umask, "{name}");
    }
    let manifest = bundle.join(MANIFEST_FILE);
    std::fs::set_permissions(&manifest, std::fs::Permissions::from_mode(0o664)).expect("chmod");
    write_bundle_folder(&bundle, &bundle_variant_files(1), |_| {}).expect("export again");
    assert_eq!(mode(&manifest), 0o664);
}

#[cfg(unix)]
#[test]
fn an_overwritten_file_keeps_its_group() {
    use std::os::unix::fs::MetadataExt as _;
    let temp = tempfile::tempdir().expect("temp dir");
    let path = temp.path().join("grouped.hairloom");
    let saved = hairloom_core::Project::new(hairloom_tests::bundle_variant(0));
    project::save(&path, &saved).expect("save");
    // Pick a group the file may be given: one of ours other than the file's, if any (root
    // may give any). Without one the property cannot be exercised here, and that is said.
    let current = std::fs::metadata(&path).expect("metadata").gid();
    let other = [current + 1, 100, 1000, 27, 4]
        .into_iter()
        .find(|&gid| gid != current && std::os::unix::fs::chown(&path, None, Some(gid)).is_ok());
    let Some(other) = other else {
        println!("skipped: this user may not give a file any other group");
        return;
    };
    project::save(&path, &saved).expect("save over");
    assert_eq!(std::fs::metadata(&path).expect("metadata").gid(), other);
}
