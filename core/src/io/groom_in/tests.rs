//! The readers on our own exports (every format holds the same strands) and on hostile
//! bytes (named errors, never a panic).

use std::ops::ControlFlow;
use std::path::Path;

use super::*;

fn no_progress() -> impl FnMut(f64) -> ControlFlow<()> {
    |_| ControlFlow::Continue(())
}

use crate::io::alembic::groom::Groom;
use crate::io::alembic::{AlembicTarget, groom_file};
use crate::io::strand_files::{ScalpMesh, StrandLook, hair_file, usda_file};
use crate::model::document::Document;
use crate::samples::{grid_scalp, straight_layers};
use crate::strands::reference::{Strand, StrandOptions, generate};

fn strands() -> (Document, Vec<Strand>) {
    let scalp = grid_scalp(3, 2, |s, t| glam::DVec3::new(0.1 * s, 0.0, 0.08 * t));
    let mesh = straight_layers(scalp, 4, glam::DVec3::new(0.01, 0.03, 0.0));
    let document = Document::new("grid", mesh);
    let options = StrandOptions {
        strands_per_bundle: 8,
        vertices_log2: 3,
        ..StrandOptions::default()
    };
    let strands = generate(&document, &options);
    (document, strands)
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).expect("write");
    path
}

/// Every format holds the same strands, points within f32 rounding, widths where written.
#[test]
fn our_exports_read_back_in_every_format() {
    let (document, strands) = strands();
    let look = StrandLook::new(
        &strands,
        8e-5,
        &document.scene.material,
        &document.root_maps,
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let groom = Groom::new(&document, &strands, 8e-5);
    let files = [
        write(dir.path(), "g.hair", &hair_file(&strands, &look)),
        write(
            dir.path(),
            "g.usda",
            usda_file(&strands, &ScalpMesh::of(&document.hair_mesh), &look).as_bytes(),
        ),
        write(
            dir.path(),
            "g.abc",
            &groom_file(&groom, AlembicTarget::Blender).expect("abc"),
        ),
    ];
    for file in &files {
        let read = read_groom(file, GroomLimits::default(), &mut no_progress())
            .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        assert_eq!(read.curve_count(), strands.len(), "{}", file.display());
        for (i, strand) in strands.iter().enumerate() {
            let curve = read.curve(i);
            assert_eq!(curve.len(), strand.points.len());
            for (p, q) in curve.iter().zip(&strand.points) {
                let d = glam::Vec3::from_array(*p).as_dvec3() - *q;
                assert!(
                    d.length() < 1e-6,
                    "{}: curve {i} off by {}",
                    file.display(),
                    d.length()
                );
            }
        }
        let widths = read.widths_m.as_ref().expect("widths");
        assert_eq!(widths.len(), read.points.len());
        assert!((widths[0] - 8e-5).abs() < 1e-9, "root width {}", widths[0]);
    }
}

fn parse_hair(bytes: &[u8]) -> Result<InputGroom, GroomReadError> {
    hair::parse(
        Path::new("x.hair"),
        bytes,
        GroomLimits::default(),
        &mut no_progress(),
    )
}

fn hair_bytes(counts: &[u16], points: &[[f32; 3]], declared_points: u32) -> Vec<u8> {
    let mut out = b"HAIR".to_vec();
    out.extend_from_slice(&(counts.len() as u32).to_le_bytes());
    out.extend_from_slice(&declared_points.to_le_bytes());
    out.extend_from_slice(&3u32.to_le_bytes()); // segments + points
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&[0u8; 20]);
    out.extend_from_slice(&[0u8; 88]);
    for c in counts {
        out.extend_from_slice(&c.to_le_bytes());
    }
    for p in points {
        for c in p {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    out
}

#[test]
fn hostile_hair_files_get_named_errors() {
    let good = [[0.0f32, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert!(parse_hair(&hair_bytes(&[1], &good, 2)).is_ok());
    // NaN point: named with its curve and point.
    let nan = [[0.0f32, 0.0, 0.0], [f32::NAN, 1.0, 0.0]];
    match parse_hair(&hair_bytes(&[1], &nan, 2)) {
        Err(GroomReadError::NonFinite {
            curve: 0, point: 1, ..
        }) => {}
        other => panic!("{other:?}"),
    }
    // A one-point curve (0 segments).
    match parse_hair(&hair_bytes(&[0, 1], &[[0.0; 3], [0.0; 3], [1.0; 3]], 3)) {
        Err(GroomReadError::SinglePointCurve { curve: 0, .. }) => {}
        other => panic!("{other:?}"),
    }
    // The header promises more points than the file holds: refused before reading them.
    match parse_hair(&hair_bytes(&[1], &good, 4_000_000)) {
        Err(GroomReadError::Format { message, .. }) => assert!(message.contains("promises")),
        other => panic!("{other:?}"),
    }
    // Absurd counts: over the caps, refused from the header alone.
    match parse_hair(&hair_bytes(&[1], &good, u32::MAX)) {
        Err(GroomReadError::TooMany { what: "points", .. }) => {}
        other => panic!("{other:?}"),
    }
    // Not a .hair file, and an empty one.
    assert!(matches!(
        parse_hair(b"nonsense"),
        Err(GroomReadError::Format { .. })
    ));
    match parse_hair(&hair_bytes(&[], &[], 0)) {
        Err(GroomReadError::NoCurves { .. }) => {}
        other => panic!("{other:?}"),
    }
}

#[test]
fn hostile_alembic_files_get_named_errors_not_panics() {
    let (document, strands) = strands();
    let groom = Groom::new(&document, &strands, 8e-5);
    let bytes = groom_file(&groom, AlembicTarget::Blender).expect("abc");
    let parse = |bytes: Vec<u8>| {
        alembic::parse(
            Path::new("x.abc"),
            bytes,
            GroomLimits::default(),
            &mut no_progress(),
        )
    };
    assert!(parse(bytes.clone()).is_ok());
    // Every truncation and a sweep of corrupted bytes: an error or a groom, never a panic
    // (a panic would fail this test) and never an allocation past the file's size.
    for cut in (0..bytes.len()).step_by(bytes.len() / 97 + 1) {
        let _ = parse(bytes[..cut].to_vec());
    }
    for at in (16..bytes.len()).step_by(bytes.len() / 211 + 1) {
        let mut bad = bytes.clone();
        bad[at] ^= 0xff;
        let _ = parse(bad);
    }
    // A blob that claims more bytes than the file has is refused by the tree check.
    let mut huge = bytes.clone();
    let root = u64::from_le_bytes(huge[8..16].try_into().expect("8 bytes")) as usize;
    huge[root..root + 8].copy_from_slice(&u64::MAX.to_le_bytes());
    match parse(huge) {
        Err(GroomReadError::Format { message, .. }) => {
            assert!(message.contains("past the file's end"), "{message}")
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        parse(b"not alembic".to_vec()),
        Err(GroomReadError::Format { .. })
    ));
    // A time sampling that claims 4 Gi samples (32 GiB) is refused before the crate
    // allocates them.
    let mut greedy = bytes.clone();
    let word = |b: &[u8], at: usize| u64::from_le_bytes(b[at..at + 8].try_into().expect("8"));
    let sampling = word(&greedy, root + 8 + 8 * 4) & !(1u64 << 63);
    let first_count = sampling as usize + 8 + 12;
    greedy[first_count..first_count + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    match parse(greedy) {
        Err(GroomReadError::Format { message, .. }) => {
            assert!(message.contains("time sampling"), "{message}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_usd_stage_reads_nothing_outside_its_folder() {
    let outside = tempfile::tempdir().expect("temp dir");
    let secret = write(
        outside.path(),
        "secret.usda",
        b"#usda 1.0\n(\n    defaultPrim = \"Hair\"\n)\ndef BasisCurves \"Hair\" {\n int[] curveVertexCounts = [2]\n point3f[] points = [(0,0,0), (0,1,0)]\n}\n",
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let stage = format!(
        "#usda 1.0\ndef \"Root\" (\n    references = @{}@\n)\n{{\n}}\n",
        secret.display()
    );
    let file = write(dir.path(), "groom.usda", stage.as_bytes());
    match read_groom(&file, GroomLimits::default(), &mut no_progress()) {
        Err(GroomReadError::NoCurves { .. }) | Err(GroomReadError::Format { .. }) => {}
        Ok(groom) => panic!(
            "read {} curves through a reference outside the folder",
            groom.curve_count()
        ),
        Err(other) => panic!("{other}"),
    }
    // The same reference inside the folder is followed.
    let inside = write(
        dir.path(),
        "hair.usda",
        &std::fs::read(&secret).expect("read"),
    );
    let stage = "#usda 1.0\ndef \"Root\" (\n    references = @./hair.usda@\n)\n{\n}\n";
    let _ = inside;
    let file = write(dir.path(), "groom2.usda", stage.as_bytes());
    let groom = read_groom(&file, GroomLimits::default(), &mut no_progress()).expect("reads");
    assert_eq!(groom.curve_count(), 1);
}

#[test]
fn usd_curve_counts_that_do_not_add_up_are_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = write(
        dir.path(),
        "bad.usda",
        b"#usda 1.0\ndef BasisCurves \"Hair\" {\n int[] curveVertexCounts = [3]\n point3f[] points = [(0,0,0), (0,1,0)]\n}\n",
    );
    match read_groom(&file, GroomLimits::default(), &mut no_progress()) {
        Err(GroomReadError::Format { message, .. }) => {
            assert!(message.contains("add up"), "{message}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn reading_can_be_cancelled_and_unknown_extensions_are_named() {
    let points: Vec<[f32; 3]> = (0..20_000)
        .flat_map(|i| [[i as f32, 0.0, 0.0], [i as f32, 1.0, 0.0]])
        .collect();
    let bytes = hair_bytes(&vec![1; 10_000], &points, 20_000);
    let cancelled = hair::parse(
        Path::new("x.hair"),
        &bytes,
        GroomLimits::default(),
        &mut |_| ControlFlow::Break(()),
    );
    assert!(matches!(cancelled, Err(GroomReadError::Cancelled { .. })));
    assert!(matches!(
        read_groom(
            Path::new("groom.obj"),
            GroomLimits::default(),
            &mut no_progress()
        ),
        Err(GroomReadError::UnknownFormat { .. })
    ));
}

#[test]
fn usd_axes_and_units_become_metres_y_up() {
    let dir = tempfile::tempdir().expect("temp dir");
    let curve = "def BasisCurves \"Hair\" {\n int[] curveVertexCounts = [2]\n point3f[] points = [(1,2,3), (1,2,13)]\n float[] widths = [0.5, 0.5]\n}\n";
    // Blender's default USD export: Z up, metres. Its front (−Y) turns to glTF's +Z.
    let z_up = write(
        dir.path(),
        "z_up.usda",
        format!("#usda 1.0\n(\n    metersPerUnit = 1\n    upAxis = \"Z\"\n)\n{curve}").as_bytes(),
    );
    let groom = read_groom(&z_up, GroomLimits::default(), &mut no_progress()).expect("reads");
    assert_eq!(groom.points, vec![[1.0, 3.0, -2.0], [1.0, 13.0, -2.0]]);
    assert!(
        groom.notes.iter().any(|n| n.contains("Z up")),
        "{:?}",
        groom.notes
    );
    // Centimetres, Y up; and no metadata at all means USD's fallback, centimetres.
    for (name, header) in [
        (
            "cm.usda",
            "(\n    metersPerUnit = 0.01\n    upAxis = \"Y\"\n)\n",
        ),
        ("bare.usda", ""),
    ] {
        let file = write(
            dir.path(),
            name,
            format!("#usda 1.0\n{header}{curve}").as_bytes(),
        );
        let groom = read_groom(&file, GroomLimits::default(), &mut no_progress()).expect("reads");
        let expected = [[0.01f32, 0.02, 0.03], [0.01, 0.02, 0.13]];
        for (p, e) in groom.points.iter().zip(&expected) {
            for (a, b) in p.iter().zip(e) {
                assert!((a - b).abs() < 1e-7, "{name}: {p:?} vs {e:?}");
            }
        }
        let widths = groom.widths_m.as_ref().expect("widths");
        assert!((widths[0] - 0.005).abs() < 1e-9, "{name}: {widths:?}");
    }
    // A frame that is neither is named.
    let odd = write(
        dir.path(),
        "odd.usda",
        format!("#usda 1.0\n(\n    upAxis = \"X\"\n)\n{curve}").as_bytes(),
    );
    match read_groom(&odd, GroomLimits::default(), &mut no_progress()) {
        Err(GroomReadError::Format { message, .. }) => {
            assert!(message.contains("upAxis"), "{message}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn usd_counts_that_overflow_and_absurd_units_are_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    // 16 × 2⁶⁰ wraps an unchecked i64 sum back to 2, the point count.
    let counts: Vec<String> = std::iter::repeat_n("1152921504606846976".to_string(), 16)
        .chain(["2".to_string()])
        .collect();
    let wrapping = write(
        dir.path(),
        "wrap.usda",
        format!(
            "#usda 1.0\n(\n    metersPerUnit = 1\n)\ndef BasisCurves \"Hair\" {{\n int64[] curveVertexCounts = [{}]\n point3f[] points = [(0,0,0), (0,1,0)]\n float[] widths = [0.5]\n}}\n",
            counts.join(", ")
        )
        .as_bytes(),
    );
    match read_groom(&wrapping, GroomLimits::default(), &mut no_progress()) {
        Err(GroomReadError::Format { message, .. }) => {
            assert!(message.contains("curveVertexCounts"), "{message}")
        }
        other => panic!("{other:?}"),
    }
    let absurd = write(
        dir.path(),
        "absurd.usda",
        b"#usda 1.0\n(\n    metersPerUnit = 1e39\n)\ndef BasisCurves \"Hair\" {\n int[] curveVertexCounts = [2]\n point3f[] points = [(0,0,0), (0,1,0)]\n}\n",
    );
    match read_groom(&absurd, GroomLimits::default(), &mut no_progress()) {
        Err(GroomReadError::Format { message, .. }) => {
            assert!(message.contains("metersPerUnit"), "{message}")
        }
        other => panic!("{other:?}"),
    }
}

/// Writes `bytes` as `name` and reads it: a named error that says `says`.
fn assert_refused(dir: &Path, name: &str, bytes: &[u8], says: &str) {
    let file = write(dir, name, bytes);
    let error = read_groom(&file, GroomLimits::default(), &mut no_progress())
        .expect_err(name)
        .to_string();
    assert!(
        error.contains(name) && error.contains(says),
        "{name}: {error}"
    );
}

/// Found by the `groom_in` fuzz target: `openusd` 0.6 recursed without end (a stack overflow,
/// which aborts the process) on a prim name with a brace or a line break, and looped forever
/// on a path literal with a brace. Such files are named errors before the library composes
/// them; a valid stage with a typed prim, comments, strings and asset paths still reads.
#[test]
fn usd_names_and_paths_the_library_cannot_compose_are_named_errors() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cases: [(&str, &str, &str); 8] = [
        (
            "brace_name.usda",
            "#usda 1.0\ndef \"}Root\" (\n)\n{\n}\n",
            "prim name",
        ),
        (
            "newline_name.usda",
            "#usda 1.0\ndef \"R\noot\"\n{\n}\n",
            "prim name",
        ),
        (
            "nested.usda",
            "#usda 1.0\ndef Xform \"Root\"\n{\n    def \"x}y\"\n    {\n    }\n}\n",
            "prim name",
        ),
        (
            "reference_path.usda",
            "#usda 1.0\ndef \"Root\" (\n    references = </}A>\n)\n{\n}\ndef \"A\"\n{\n}\n",
            "path </}A>",
        ),
        (
            "inherits_path.usda",
            "#usda 1.0\nover \"Root\" (\n    inherits = </A}>\n)\n{\n}\n",
            "path </A}>",
        ),
        // A block comment between the keyword and the name does not hide it.
        (
            "block_comment.usda",
            "#usda 1.0\ndef /**/ \"}\nRoot\"\n{\n}\n",
            "prim name",
        ),
        // Triple-quoted strings have no escapes: a backslash before the closing quotes.
        (
            "triple_quoted.usda",
            "#usda 1.0\n(\n    doc = \"\"\"C:\\\"\"\"\n)\ndef \"}Root\"\n{\n}\n",
            "prim name",
        ),
        (
            "variant_set.usda",
            "#usda 1.0\ndef \"Root\" (\n    variantSets = \"v\"\n)\n{\n    variantSet \"v\" = {\n        \"a}\" {\n        }\n    }\n}\n",
            "variant sets",
        ),
    ];
    for (name, text, says) in cases {
        assert_refused(dir.path(), name, text.as_bytes(), says);
    }
    let valid = "#usda 1.0\n(\n    doc = \"a } in a string, def \\\"x}\\\" too\"\n)\n\
        # a comment with def \"}\" in it\n/* and def \"{\" in a block */\n\
        def BasisCurves \"Hair_1\" (\n    assetInfo = {asset identifier = @./a}b.usda@}\n)\n{\n\
        int[] curveVertexCounts = [2]\n point3f[] points = [(0,0,0), (0,1,0)]\n}\n";
    let file = write(dir.path(), "valid.usda", valid.as_bytes());
    let groom = read_groom(&file, GroomLimits::default(), &mut no_progress())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(groom.curve_count(), 1);
}

/// USD text as a crate file (`.usdc`), written by the library's own writer (what a tool that
/// saves binary USD hands over), with the name `from` then changed to `to` in its token
/// table: the writer itself overflows its stack on a name with a brace, so such a crate is
/// made by patching a name of the same length (a lone token is stored as LZ4 literals).
fn usdc_of(text: &str, from: &str, to: &str) -> Vec<u8> {
    assert_eq!(from.len(), to.len(), "a patch keeps the token table's size");
    let data = openusd::usda::parse(text).expect("the text parses");
    let mut bytes = std::io::Cursor::new(Vec::new());
    openusd::usdc::CrateWriter::write(&data, &mut bytes).expect("the crate writes");
    let mut bytes = bytes.into_inner();
    if from != to {
        let at: Vec<usize> = bytes
            .windows(from.len())
            .enumerate()
            .filter(|(_, w)| *w == from.as_bytes())
            .map(|(i, _)| i)
            .collect();
        assert_eq!(at.len(), 1, "{from:?} appears once in the crate");
        bytes[at[0]..at[0] + to.len()].copy_from_slice(to.as_bytes());
    }
    bytes
}

/// The same names and paths in a binary crate file: its names sit in a token table the
/// text check never sees, so the crate's paths, child lists and path-valued fields are
/// checked too (without the check, the brace name aborted the process).
#[test]
fn usdc_names_and_paths_the_library_cannot_compose_are_named_errors() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cases: [(&str, &str, (&str, &str), &str); 5] = [
        (
            "brace_name.usdc",
            "#usda 1.0\ndef \"Zq9Wk\"\n{\n}\n",
            ("Zq9Wk", "}q9Wk"),
            "prim name \"}q9Wk\"",
        ),
        (
            "newline_name.usdc",
            "#usda 1.0\ndef \"R\noot\"\n{\n}\n",
            ("", ""),
            "prim name \"R\\noot\"",
        ),
        (
            "nested.usdc",
            "#usda 1.0\ndef Xform \"Root\"\n{\n    def \"Zq9Wk\"\n    {\n    }\n}\n",
            ("Zq9Wk", "x}9Wk"),
            "prim name \"x}9Wk\"",
        ),
        (
            "reference_path.usdc",
            "#usda 1.0\ndef \"Root\" (\n    references = </Zq9Wk>\n)\n{\n}\n",
            ("Zq9Wk", "}q9Wk"),
            "path </}q9Wk> in references of </Root>",
        ),
        (
            "inherits_path.usdc",
            "#usda 1.0\nover \"Root\" (\n    inherits = </Zq9Wk>\n)\n{\n}\n",
            ("Zq9Wk", "Zq9W}"),
            "path </Zq9W}> in inheritPaths of </Root>",
        ),
    ];
    for (name, text, (from, to), says) in cases {
        assert_refused(dir.path(), name, &usdc_of(text, from, to), says);
    }
    // Inside a `.usdz` package the crate is checked the same (the resolver opens each of a
    // package's layers); the package's own crate groom reads.
    let package = |name: &str, layer: &[u8]| {
        use std::io::Write as _;
        let mut bytes = std::io::Cursor::new(Vec::new());
        let mut zip = zip::ZipWriter::new(&mut bytes);
        let stored = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        zip.start_file(name, stored).expect("a package entry");
        zip.write_all(layer).expect("the layer");
        zip.finish().expect("the package");
        bytes.into_inner()
    };
    let brace = usdc_of("#usda 1.0\ndef \"Zq9Wk\"\n{\n}\n", "Zq9Wk", "}q9Wk");
    assert_refused(
        dir.path(),
        "brace.usdz",
        &package("brace.usdc", &brace),
        "brace.usdz[brace.usdc]: prim name \"}q9Wk\"",
    );
    // A crate groom of identifiers, namespaced properties and a reference reads.
    let valid = "#usda 1.0\ndef Xform \"Root\"\n{\n    def BasisCurves \"Hair_1\"\n    {\n\
        int[] curveVertexCounts = [2]\n        point3f[] points = [(0,0,0), (0,1,0)]\n\
        float[] primvars:widths = [0.001, 0.001]\n    }\n}\n\
        def \"Other\" (\n    references = </Root>\n)\n{\n}\n";
    let file = write(dir.path(), "valid.usdc", &usdc_of(valid, "", ""));
    let groom = read_groom(&file, GroomLimits::default(), &mut no_progress())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(groom.curve_count(), 2, "the curves and their reference");
    let file = write(
        dir.path(),
        "valid.usdz",
        &package("valid.usdc", &usdc_of(valid, "", "")),
    );
    let groom = read_groom(&file, GroomLimits::default(), &mut no_progress())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(groom.curve_count(), 2, "the package's curves");
}

/// Found by the `groom_in` fuzz target in the crate reader (`openusd` 0.6, patched in
/// `vendor/openusd`): sizes and counts read from a `.usdc` were allocated before a byte of
/// what they counted was read, and an allocation of exabytes aborts the process. Here every
/// eight bytes of a valid crate groom in turn claim 2⁶⁰ (and then 2³²): each read ends in
/// curves or a named error, and never in an abort.
#[test]
fn usdc_counts_that_claim_more_than_the_file_holds_are_errors() {
    let dir = tempfile::tempdir().expect("temp dir");
    let text = "#usda 1.0\n(\n    customLayerData = {\n        dictionary nested = {\n\
        string note = \"a\"\n        }\n    }\n)\ndef Xform \"Root\"\n{\n\
        def BasisCurves \"Hair_1\" (\n        references = </Other>\n    )\n    {\n\
        int[] curveVertexCounts = [4, 4]\n\
        point3f[] points = [(0,0,0), (0,1,0), (0,2,0), (0,3,0), (1,0,0), (1,1,0), (1,2,0), (1,3,0)]\n\
        float[] widths = [0.001, 0.001, 0.001, 0.001, 0.002, 0.002, 0.002, 0.002]\n    }\n}\n\
        def \"Other\"\n{\n}\n";
    let valid = usdc_of(text, "", "");
    let file = write(dir.path(), "valid.usdc", &valid);
    let groom = read_groom(&file, GroomLimits::default(), &mut no_progress())
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(groom.curve_count(), 2);
    let mut errors = 0;
    for claim in [1u64 << 60, 1u64 << 32] {
        for at in 8..valid.len().saturating_sub(8) {
            let mut bytes = valid.clone();
            bytes[at..at + 8].copy_from_slice(&claim.to_le_bytes());
            let file = write(dir.path(), "claims.usdc", &bytes);
            if let Err(error) = read_groom(&file, GroomLimits::default(), &mut no_progress()) {
                assert!(error.to_string().contains("claims.usdc"), "{error}");
                errors += 1;
            }
        }
    }
    assert!(
        errors > valid.len() / 2,
        "{errors} of the patched crates were refused"
    );
}

/// Curves under nested transforms, written by the Alembic C++ library
/// (`tools/make_xform_groom.py`: a Maya-style translate / axis-angle rotate / scale stack
/// over a matrix and x-rotation, and a sibling that does not inherit), land where the
/// library itself places them (its world points, in `xform_groom.json`).
#[test]
fn alembic_transforms_place_curves_as_the_alembic_library_does() {
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/grooms");
    let groom = read_groom(
        &assets.join("xform_groom.abc"),
        GroomLimits::default(),
        &mut no_progress(),
    )
    .expect("reads");
    let expected: std::collections::BTreeMap<String, Vec<[f64; 3]>> = serde_json::from_slice(
        &std::fs::read(assets.join("xform_groom.json")).expect("expected points"),
    )
    .expect("json");
    // Objects are read in file order: the tilted hair, then the detached strays.
    let wanted: Vec<[f64; 3]> = ["/groom_xform/tilted/hair", "/groom_xform/detached/strays"]
        .iter()
        .flat_map(|name| expected[*name].clone())
        .collect();
    assert_eq!(groom.points.len(), wanted.len());
    for (i, (got, want)) in groom.points.iter().zip(&wanted).enumerate() {
        let d = glam::Vec3::from_array(*got).as_dvec3() - glam::DVec3::from_array(*want);
        assert!(d.length() < 1e-6, "point {i}: {got:?} vs {want:?}");
    }
    assert!(
        groom
            .notes
            .iter()
            .any(|n| n.contains("2 curves objects placed")),
        "{:?}",
        groom.notes
    );
}

#[test]
fn transform_operations_compose_in_stack_order_and_refuse_non_finite_values() {
    use super::alembic::xform_matrix;
    let p = glam::DVec3::new(1.0, 0.0, 0.0);
    // Translate, then rotate 90° about z, then scale 2 (Maya's order in the stack): the
    // point is scaled first, then rotated, then moved.
    let m =
        xform_matrix(&[0x10, 0x60, 0x00], &[0.0, 0.0, 5.0, 90.0, 2.0, 2.0, 2.0]).expect("finite");
    assert!((m.transform_point3(p) - glam::DVec3::new(0.0, 2.0, 5.0)).length() < 1e-12);
    // A matrix op is Imath's rows, in order: the translation is the last row.
    let mut rows = [0.0; 16];
    for k in 0..4 {
        rows[5 * k] = 1.0;
    }
    rows[12..15].copy_from_slice(&[1.0, 2.0, 3.0]);
    let m = xform_matrix(&[0x30], &rows).expect("finite");
    assert_eq!(
        m.transform_point3(glam::DVec3::ZERO),
        glam::DVec3::new(1.0, 2.0, 3.0)
    );
    // Short values leave channels at 0 (a zero scale), unknown ops do nothing, a zero axis
    // leaves Imath's cos θ on the diagonal, and nothing is identity.
    assert_eq!(xform_matrix(&[], &[]), Ok(glam::DMat4::IDENTITY));
    assert_eq!(xform_matrix(&[0xF0], &[1.0]), Ok(glam::DMat4::IDENTITY));
    let zero_axis = xform_matrix(&[0x20], &[0.0, 0.0, 0.0, 60.0]).expect("finite");
    assert!((zero_axis.transform_point3(glam::DVec3::X) - glam::DVec3::X * 0.5).length() < 1e-12);
    let flat = xform_matrix(&[0x00], &[2.0]).expect("finite");
    assert_eq!(
        flat.transform_point3(glam::DVec3::ONE),
        glam::DVec3::new(2.0, 0.0, 0.0)
    );
    let error = xform_matrix(&[0x10], &[f64::NAN, 0.0, 0.0]).expect_err("NaN");
    assert!(error.contains("not finite"), "{error}");
    let error = xform_matrix(&[0x00, 0x00], &[1e300, 1e300, 1e300, 1e300, 1e300, 1e300])
        .expect_err("overflow");
    assert!(error.contains("not finite"), "{error}");
}
