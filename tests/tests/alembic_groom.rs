//! Alembic grooms read back by an independent reader (`ogawa-rs`, written against the C++
//! library's files): objects, counts, points, bounds and every `groom_*` attribute, and the
//! guides each strand names really are its bundle's corner columns.

use hairloom_core::io::alembic::groom::{GUIDE_POINTS_PER_LAYER, Groom};
use hairloom_core::io::alembic::{AlembicTarget, GROOM_VERSION, groom_animation, groom_file};
use hairloom_core::io::project;
use hairloom_core::model::document::Document;
use hairloom_core::model::styling::StylingGroup;
use hairloom_core::strands::reference::{StrandOptions, generate};
use hairloom_tests::sample_paths;
use ogawa_rs::{
    Archive, ArchiveReader, FileReader, ObjectReader, PodArray, PropertyReader, Schema,
};

const WIDTH_M: f32 = 8e-5;

fn sample(name: &str) -> Document {
    let path = sample_paths()
        .into_iter()
        .find(|p| p.to_string_lossy().contains(name))
        .expect("sample");
    project::load(&path).expect("sample loads").document
}

/// The curly sample with its first 40 bundles in a styling group of their own, so the
/// groom has two groups.
fn grouped_sample() -> Document {
    let mut document = sample("head_curly");
    let params = document.styling.global.clone();
    document.styling.groups.push(StylingGroup {
        name: "fringe".into(),
        bundles: (0..40).collect(),
        params,
    });
    document
}

/// The sub-property `name` of compound `$compound`, which must be a `$kind` (the crate's
/// reader types cannot be named outside it, so this is a macro, not a function).
macro_rules! sub_property {
    ($compound:expr, $name:expr, $kind:ident, $r:expr, $archive:expr) => {
        match $compound
            .load_sub_property_by_name($name, $r, $archive)
            .expect($name)
        {
            Some(PropertyReader::$kind(property)) => property,
            _ => panic!("{} is not a {}", $name, stringify!($kind)),
        }
    };
}

/// `bytes` as ogawa-rs opens a file: the reader and the archive.
fn open_archive(bytes: &[u8]) -> (FileReader, Archive) {
    let mut file = tempfile::tempfile().expect("temp file");
    std::io::Write::write_all(&mut file, bytes).expect("write");
    let mut reader = FileReader::new(file).expect("reader");
    let archive = Archive::new(&mut reader).expect("ogawa-rs opens the file");
    (reader, archive)
}

/// Child `i` of `parent`, read with the archive's metadata table and time samplings.
fn load_child(
    parent: &ObjectReader,
    i: usize,
    reader: &mut FileReader,
    archive: &Archive,
) -> ObjectReader {
    parent
        .load_child(
            i,
            reader,
            &archive.indexed_meta_data,
            &archive.time_samplings,
        )
        .expect("child")
}

struct Read {
    counts: Vec<i32>,
    points: Vec<[f32; 3]>,
    bounds: [f64; 6],
    width: Vec<f32>,
    arb: std::collections::BTreeMap<String, (Option<String>, PodArray)>,
    user: std::collections::BTreeMap<String, String>,
}

fn read_curves(obj: &ObjectReader, r: &mut dyn ArchiveReader, archive: &Archive) -> Read {
    let Ok(Schema::Curves(curves)) = Schema::parse(obj, r, archive) else {
        panic!("{} is not an ICurves", obj.header.full_name);
    };
    let counts = curves.load_n_vertices_sample(0, r).expect("nVertices");
    let points = curves.load_positions_sample(0, r).expect("P");
    let (kind, wrap, basis) = curves.load_curve_type_sample(0, r).expect("type");
    assert_eq!(
        format!("{kind:?}/{wrap:?}/{basis:?}"),
        "Linear/NonPeriodic/None"
    );
    let width = curves
        .load_widths_sample(0, r)
        .expect("width")
        .expect("width present");
    let props = obj.properties().expect("properties");
    let geom = sub_property!(props, ".geom", Compound, r, archive);
    let bounds = sub_property!(geom, ".selfBnds", Scalar, r, archive);
    let PodArray::F64(b) = bounds.load_sample(0, r).expect("bounds") else {
        panic!("bounds are f64")
    };
    let mut arb = std::collections::BTreeMap::new();
    let params = sub_property!(geom, ".arbGeomParams", Compound, r, archive);
    for i in 0..params.sub_property_count() {
        if let PropertyReader::Array(a) = params.load_sub_property(i, r, archive).expect("param") {
            let scope = a.header.meta_data.tokens.get("geoScope").cloned();
            arb.insert(
                a.name().to_string(),
                (scope, a.load_sample(0, r).expect("sample")),
            );
        }
    }
    let mut user = std::collections::BTreeMap::new();
    let props = sub_property!(geom, ".userProperties", Compound, r, archive);
    for i in 0..props.sub_property_count() {
        if let PropertyReader::Scalar(s) = props.load_sub_property(i, r, archive).expect("user") {
            user.insert(
                s.name().to_string(),
                format!("{:?}", s.load_sample(0, r).expect("value")),
            );
        }
    }
    Read {
        counts,
        points,
        bounds: b.try_into().expect("6 bounds"),
        width,
        arb,
        user,
    }
}

fn read_file(bytes: Vec<u8>) -> (Read, Read, String) {
    let (mut reader, archive) = open_archive(&bytes);
    let root = archive.load_root_object(&mut reader).expect("root");
    assert_eq!(root.child_count(), 2);
    let mut objects = Vec::new();
    for i in 0..root.child_count() {
        let child = load_child(&root, i, &mut reader, &archive);
        assert_eq!(
            child
                .header
                .meta_data
                .tokens
                .get("schemaObjTitle")
                .map(String::as_str),
            Some("AbcGeom_Curve_v2:.geom"),
            "Unreal recognises curves by schemaObjTitle"
        );
        objects.push((
            child.header.name.clone(),
            read_curves(&child, &mut reader, &archive),
        ));
    }
    let names: Vec<&str> = objects.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["hair", "guides"]);
    let guides = objects.pop().expect("guides").1;
    let hair = objects.pop().expect("hair").1;
    (hair, guides, archive.root_header.meta_data.serialize())
}

fn i32s(read: &Read, name: &str, scope: &str) -> Vec<i32> {
    match read.arb.get(name) {
        Some((Some(s), PodArray::I32(v))) if s == scope => v.clone(),
        other => panic!("{name}: {other:?}"),
    }
}

fn f32s(read: &Read, name: &str, scope: &str) -> Vec<f32> {
    match read.arb.get(name) {
        Some((Some(s), PodArray::F32(v))) if s == scope => v.clone(),
        other => panic!("{name}: {other:?}"),
    }
}

#[test]
fn groom_reads_back_with_every_attribute() {
    let document = grouped_sample();
    let strands = generate(
        &document,
        &StrandOptions {
            strands_per_bundle: 6,
            vertices_log2: 3,
            ..StrandOptions::default()
        },
    );
    let groom = Groom::new(&document, &strands, WIDTH_M);
    for target in [AlembicTarget::Unreal, AlembicTarget::Blender] {
        let (hair, guides, archive_metadata) =
            read_file(groom_file(&groom, target).expect("a consistent groom"));
        assert!(
            archive_metadata.contains("_ai_Application=Hairloom"),
            "{archive_metadata}"
        );

        // Strands: counts, points (in the target's axes and units), bounds.
        assert_eq!(hair.counts.len(), strands.len());
        assert!(
            hair.counts
                .iter()
                .zip(&strands)
                .all(|(&c, s)| c as usize == s.points.len())
        );
        let expected: Vec<[f32; 3]> = strands
            .iter()
            .flat_map(|s| {
                s.points
                    .iter()
                    .map(|p| target.to_file(p.as_vec3().to_array()))
            })
            .collect();
        assert_eq!(hair.points, expected);
        for k in 0..3 {
            let lo = hair
                .points
                .iter()
                .map(|p| p[k])
                .fold(f32::INFINITY, f32::min);
            let hi = hair
                .points
                .iter()
                .map(|p| p[k])
                .fold(f32::NEG_INFINITY, f32::max);
            assert_eq!(
                (hair.bounds[k], hair.bounds[k + 3]),
                (f64::from(lo), f64::from(hi))
            );
        }
        // Up is the file's z for Unreal, y for the others: its range is the model's
        // vertical (y) range in the target's units.
        let scale = target.units_per_m();
        let up = if target.z_up() { 2 } else { 1 };
        let model_y = strands
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.y as f32 * scale));
        let (lo_y, hi_y) = model_y.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), y| {
            (lo.min(y), hi.max(y))
        });
        assert_eq!(
            (hair.bounds[up], hair.bounds[up + 3]),
            (f64::from(lo_y), f64::from(hi_y))
        );
        // Widths per point, in file units, tapering from the root width to 40 % at the
        // tip, as `width` and as `groom_width`; a colour per point.
        assert_eq!(hair.width.len(), hair.points.len());
        assert_eq!(hair.width, f32s(&hair, "groom_width", "vtx"));
        let mut start = 0;
        for &count in &hair.counts {
            let widths = &hair.width[start..start + count as usize];
            assert!((widths[0] - WIDTH_M * scale).abs() <= 1e-6 * WIDTH_M * scale);
            let tip = widths[widths.len() - 1];
            assert!((tip - 0.4 * WIDTH_M * scale).abs() <= 1e-6 * WIDTH_M * scale);
            assert!(widths.windows(2).all(|w| w[1] < w[0]), "{widths:?}");
            start += count as usize;
        }
        let colors = f32s(&hair, "groom_color", "vtx");
        assert_eq!(colors.len(), 3 * hair.points.len());
        assert!(
            colors
                .iter()
                .all(|c| c.is_finite() && (0.0..=1.0).contains(c))
        );
        assert!(
            colors.chunks(3).any(|a| a != &colors[..3]),
            "colour varies along and between strands"
        );
        assert!(i32s(&hair, "groom_guide", "uni").iter().all(|&g| g == 0));
        let uvs = f32s(&hair, "groom_root_uv", "uni");
        assert_eq!(uvs.len(), 2 * strands.len());
        assert!(
            strands
                .iter()
                .enumerate()
                .all(|(i, s)| uvs[2 * i] == s.root_uv.x as f32
                    && uvs[2 * i + 1] == s.root_uv.y as f32)
        );
        let groups = i32s(&hair, "groom_group_id", "uni");
        assert!(
            strands
                .iter()
                .zip(&groups)
                .all(|(s, &g)| g == i32::from(s.bundle < 40))
        );
        for (name, value) in [
            ("groom_version_major", GROOM_VERSION.0),
            ("groom_version_minor", GROOM_VERSION.1),
        ] {
            assert_eq!(
                hair.user.get(name),
                Some(&format!("I16([{value}])")),
                "{name}"
            );
        }
        assert!(hair.user["groom_tool"].contains("Hairloom"));

        // Guides: one curve per (group, column), ids before the strands', flagged as guides.
        assert!(i32s(&guides, "groom_guide", "uni").iter().all(|&g| g == 1));
        let guide_ids = i32s(&guides, "groom_id", "uni");
        let strand_ids = i32s(&hair, "groom_id", "uni");
        assert_eq!(
            guide_ids,
            (0..guides.counts.len() as i32).collect::<Vec<_>>()
        );
        assert_eq!(strand_ids[0], guides.counts.len() as i32);
        let guide_groups = i32s(&guides, "groom_group_id", "uni");
        assert!(guide_groups.contains(&1) && guide_groups.contains(&0));

        // Each strand's guides are in its group, their weights sum to one, and blending the
        // guides' roots by them puts the strand's root inside its root face.
        let closest = i32s(&hair, "groom_closest_guides", "uni");
        let weights = f32s(&hair, "groom_guide_weights", "uni");
        let mut guide_start = vec![0usize];
        for &c in &guides.counts {
            guide_start.push(guide_start.last().copied().unwrap_or(0) + c as usize);
        }
        for (i, strand) in strands.iter().enumerate() {
            let ids = &closest[3 * i..3 * i + 3];
            let w = &weights[3 * i..3 * i + 3];
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-5, "{w:?}");
            assert!(ids.iter().all(|&g| guide_groups[g as usize] == groups[i]));
            let root = glam::Vec3::from(target.to_file(strand.points[0].as_vec3().to_array()));
            let blended: glam::Vec3 = ids
                .iter()
                .zip(w)
                .map(|(&g, &w)| glam::Vec3::from(guides.points[guide_start[g as usize]]) * w)
                .sum();
            let bundle = &document.hair_mesh.bundles[strand.bundle as usize];
            let edge = bundle
                .vertices
                .windows(2)
                .map(|c| {
                    (document.hair_mesh.columns[c[0] as usize].positions[0]
                        - document.hair_mesh.columns[c[1] as usize].positions[0])
                        .length()
                })
                .fold(0.0, f64::max) as f32;
            assert!(
                (blended - root).length() <= 0.5 * edge * scale,
                "strand {i}: guides blend to {blended}, root {root}, face edge {edge}"
            );
        }
        // One guide per (group, column) of the bundles that grow hair: counted from the
        // document, per group.
        for group in [0, 1] {
            let mut columns: Vec<u32> = document
                .hair_mesh
                .bundles
                .iter()
                .enumerate()
                .filter(|(b, bundle)| {
                    !bundle.removed && bundle.layers > 0 && i32::from(*b < 40) == group
                })
                .flat_map(|(_, bundle)| bundle.vertices.iter().copied())
                .collect();
            columns.sort_unstable();
            columns.dedup();
            let guides_in_group = guide_groups.iter().filter(|&&g| g == group).count();
            assert_eq!(guides_in_group, columns.len(), "group {group}");
        }
        // Each guide is its column's curve, GUIDE_POINTS_PER_LAYER points per layer, from the
        // column's root.
        let roots: Vec<[f32; 3]> = document
            .hair_mesh
            .columns
            .iter()
            .map(|c| target.to_file(c.positions[0].as_vec3().to_array()))
            .collect();
        for (g, &start) in guide_start[..guides.counts.len()].iter().enumerate() {
            assert!(
                roots.contains(&guides.points[start]),
                "guide {g} does not start at a column root"
            );
            assert_eq!((guides.counts[g] - 1) % GUIDE_POINTS_PER_LAYER as i32, 0);
        }
    }
    // A groom whose arrays disagree is refused by name, not written.
    let mut broken = groom.clone();
    broken.strands.root_uv.pop();
    let error = groom_file(&broken, AlembicTarget::Unreal).expect_err("refused");
    assert!(error.contains("root_uv"), "{error}");
    let mut broken = groom.clone();
    broken.strands.widths_m[3] = f32::NAN;
    let error = groom_file(&broken, AlembicTarget::Blender).expect_err("refused");
    assert!(error.contains("width NaN"), "{error}");
}

/// An animated groom stores the first frame where `ogawa-rs` reads it (it reads only the
/// first sample of an array: a known limitation of that crate), and refuses frames whose
/// curves differ.
#[test]
fn animated_groom_reads_back_its_first_frame_and_refuses_mismatched_frames() {
    let document = sample("head_short");
    let options = StrandOptions {
        strands_per_bundle: 2,
        vertices_log2: 2,
        ..StrandOptions::default()
    };
    let strands = generate(&document, &options);
    let first = Groom::new(&document, &strands, WIDTH_M);
    let mut moved = first.clone();
    for p in moved
        .strands
        .points
        .iter_mut()
        .chain(moved.guides.points.iter_mut())
    {
        p[0] += 0.01;
    }
    let bytes = groom_animation(&[first.clone(), moved.clone()], 24.0, AlembicTarget::Maya)
        .expect("animation");
    let (hair, _, metadata) = read_file(bytes);
    assert!(metadata.contains("_ai_DCC_FPS=24.000000"), "{metadata}");
    let expected: Vec<[f32; 3]> = first
        .strands
        .points
        .iter()
        .map(|&p| AlembicTarget::Maya.to_file(p))
        .collect();
    assert_eq!(hair.points, expected);

    let mut fewer = moved;
    fewer.strands.vertex_counts.pop();
    let target = AlembicTarget::default();
    assert!(groom_animation(&[first.clone(), fewer], 24.0, target).is_err());
    assert!(groom_animation(&[], 24.0, target).is_err());
    assert!(groom_animation(&[first], f64::NAN, target).is_err());
}

/// Past 253 distinct metadata strings (and for any longer than 255 bytes) the writer puts
/// metadata inline in the headers instead of the indexed table: readers find both.
#[test]
fn metadata_past_the_indexed_table_is_written_inline_and_read_back() {
    use hairloom_core::io::alembic::archive::{Archive, Metadata, Object};
    let long = "x".repeat(300);
    let objects: Vec<Object> = (0..300)
        .map(|i| Object {
            name: format!("object_{i}"),
            metadata: Metadata::new(&[
                ("index", &i.to_string()),
                ("note", if i == 5 { &long } else { "short" }),
            ]),
            properties: Vec::new(),
            children: Vec::new(),
        })
        .collect();
    let bytes = Archive {
        objects,
        metadata: Metadata::default(),
        frames_per_second: 24.0,
    }
    .write();
    let (mut reader, archive) = open_archive(&bytes);
    let root = archive.load_root_object(&mut reader).expect("root");
    assert_eq!(root.child_count(), 300);
    for i in [0, 5, 252, 253, 299] {
        let child = load_child(&root, i, &mut reader, &archive);
        let tokens = &child.header.meta_data.tokens;
        assert_eq!(tokens.get("index"), Some(&i.to_string()), "object {i}");
        let note = if i == 5 { long.as_str() } else { "short" };
        assert_eq!(
            tokens.get("note").map(String::as_str),
            Some(note),
            "object {i}"
        );
    }
}
