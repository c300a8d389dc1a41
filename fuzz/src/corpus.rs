//! The seed corpus: small valid inputs of every kind, and every crafted hostile case of the
//! issue "Hostile and oversized input" (each was a panic, a read outside the input's folder
//! or an unbounded cost before it was fixed). `hairloom-fuzz seed` writes them to
//! `fuzz/corpus/<target>/`; the smoke test checks the committed corpus still holds them.

use hairloom_core::io::runtime_bundle::runtime_bundle;
use hairloom_core::runtime::hair::RuntimeOptions;
use hairloom_core::{BodyMesh, Document, Project};
use hairloom_tests::GltfBuilder;
use serde_json::{Value, json};

use crate::targets::{Target, bundle_input, manifest_of};

/// `(file name, bytes)` seeds of `target`.
pub fn seeds(target: Target) -> Vec<(String, Vec<u8>)> {
    match target {
        Target::ProjectLoad => project_seeds(),
        Target::GltfImport => gltf_seeds(),
        Target::RuntimeBundle => bundle_seeds(),
        Target::Ktx2 => ktx2_seeds(),
        Target::StrandExport => strand_export_seeds(),
        Target::GroomIn => groom_seeds(),
    }
}

/// Issue 36: grooms as other tools hand them over — our own exports of the grid project in
/// every groom format (Alembic for Blender and Unreal, USD, cyHair) — and crafted files that
/// claim more than they hold, reach outside their folder or break the formats' structure.
fn groom_seeds() -> Vec<(String, Vec<u8>)> {
    use crate::targets::groom_input;
    use hairloom_core::io::alembic::{AlembicTarget, groom::Groom, groom_file};
    use hairloom_core::io::strand_files::{ScalpMesh, StrandLook, hair_file, usda_file};
    use hairloom_core::strands::reference::{StrandOptions, generate};
    let projects = project_seeds();
    let project = hairloom_core::io::project::from_bytes(
        &projects[0].1,
        std::path::Path::new("grid.hairloom"),
    )
    .expect("the grid project loads");
    let document = &project.document;
    let strands = generate(
        document,
        &StrandOptions {
            strands_per_bundle: 4,
            vertices_log2: 2,
            ..StrandOptions::default()
        },
    );
    let look = StrandLook::new(
        &strands,
        1e-4,
        &document.scene.material,
        &document.root_maps,
    );
    let hair = hair_file(&strands, &look);
    let usda = usda_file(&strands, &ScalpMesh::of(&document.hair_mesh), &look);
    let groom = Groom::new(document, &strands, 1e-4);
    let abc = |target| groom_file(&groom, target).expect("the grid's groom writes");
    let blender = abc(AlembicTarget::Blender);
    let mut seeds = vec![
        ("grid.hair".to_string(), groom_input("hair", &hair)),
        ("grid_blender.abc".into(), groom_input("abc", &blender)),
        (
            "grid_unreal.abc".into(),
            groom_input("abc", &abc(AlembicTarget::Unreal)),
        ),
        ("grid.usda".into(), groom_input("usda", usda.as_bytes())),
        // Curves under nested transforms, written by the Alembic C++ library.
        (
            "xform_groom.abc".into(),
            groom_input("abc", include_bytes!("../../assets/grooms/xform_groom.abc")),
        ),
    ];
    // cyHair: a header that claims 2³¹ strands of 2¹⁶ points over an empty body.
    let mut claims = hair[..128.min(hair.len())].to_vec();
    claims[4..8].copy_from_slice(&(1u32 << 31).to_le_bytes());
    claims[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    seeds.push((
        "crafted_hair_claims_2e31_strands.hair".into(),
        groom_input("hair", &claims),
    ));
    // Alembic cut in half: offsets that point past the end.
    seeds.push((
        "crafted_abc_truncated.abc".into(),
        groom_input("abc", &blender[..blender.len() / 2]),
    ));
    // USD: a stage whose only hair is a reference outside the groom's folder (the resolver
    // refuses it: no curves), and curve counts past the caps.
    let outside = "#usda 1.0\ndef \"Root\" (\n    references = @../../../etc/hair.usda@\n)\n{\n}\n";
    seeds.push((
        "crafted_usda_reference_outside_folder.usda".into(),
        groom_input("usda", outside.as_bytes()),
    ));
    // What the target found: a prim name and a path with a brace (the library recursed
    // without end on the one and looped on the other).
    seeds.push((
        "crafted_usda_prim_name_with_brace.usda".into(),
        groom_input("usda", b"#usda 1.0\ndef \"}\nRoot\" (\n)\n{\n}\n"),
    ));
    seeds.push((
        "crafted_usda_path_with_brace.usda".into(),
        groom_input(
            "usda",
            b"#usda 1.0\ndef \"Root\" (\n    references = </}A>\n)\n{\n}\n",
        ),
    ));
    // A review's bypasses of the first check: a block comment before the name, a
    // triple-quoted string ending in a backslash, a variant name with a brace.
    seeds.push((
        "crafted_usda_block_comment_before_name.usda".into(),
        groom_input("usda", b"#usda 1.0\ndef /**/ \"}Root\"\n{\n}\n"),
    ));
    seeds.push((
        "crafted_usda_triple_quoted_backslash.usda".into(),
        groom_input(
            "usda",
            b"#usda 1.0\n(\n    doc = \"\"\"C:\\\"\"\"\n)\ndef \"}Root\"\n{\n}\n",
        ),
    ));
    seeds.push((
        "crafted_usda_variant_name_with_brace.usda".into(),
        groom_input(
            "usda",
            b"#usda 1.0\ndef \"Root\" (\n    variantSets = \"v\"\n)\n{\n    variantSet \"v\" = {\n        \"a}\" {\n        }\n    }\n}\n",
        ),
    ));
    // The grid and the brace name in a binary crate file (`.usdc`), whose names sit in a
    // token table the text check cannot see; the writer overflows on a brace itself, so the
    // crafted name is patched into a name of the same length.
    let crate_of = |text: &str| {
        let data = openusd::usda::parse(text).expect("our USD text parses");
        let mut bytes = std::io::Cursor::new(Vec::new());
        openusd::usdc::CrateWriter::write(&data, &mut bytes).expect("the crate writes");
        bytes.into_inner()
    };
    seeds.push(("grid.usdc".into(), groom_input("usdc", &crate_of(&usda))));
    let mut brace = crate_of("#usda 1.0\ndef \"Zq9Wk\"\n{\n}\n");
    if let Some(at) = brace.windows(5).position(|w| w == b"Zq9Wk") {
        brace[at] = b'}';
    }
    seeds.push((
        "crafted_usdc_prim_name_with_brace.usdc".into(),
        groom_input("usdc", &brace),
    ));
    let huge = usda.replacen(
        "int[] curveVertexCounts = [",
        "int[] curveVertexCounts = [2147483647, 2147483647, ",
        1,
    );
    seeds.push((
        "crafted_usda_counts_2e31.usda".into(),
        groom_input("usda", huge.as_bytes()),
    ));
    seeds
}

/// Issue "Nothing lost, nothing blocked": exports at every documented maximum (4096
/// strands per bundle, 1025 vertices per strand) and past it, over a small project and one
/// of 20,000 layers; and small exports that are generated and written.
fn strand_export_seeds() -> Vec<(String, Vec<u8>)> {
    use crate::targets::strand_export_input;
    let projects = project_seeds();
    let (_, grid) = &projects[0];
    let (_, deep) = &projects[1];
    vec![
        (
            "grid_1_strand_3_vertices".into(),
            strand_export_input(1, 1, grid),
        ),
        (
            "grid_8_strands_17_vertices".into(),
            strand_export_input(8, 4, grid),
        ),
        (
            "crafted_grid_at_the_maxima".into(),
            strand_export_input(4096, 10, grid),
        ),
        (
            "crafted_grid_past_the_maxima".into(),
            strand_export_input(4097, 11, grid),
        ),
        (
            "crafted_layers_20000_at_the_maxima".into(),
            strand_export_input(4096, 10, deep),
        ),
    ]
}

/// 4 × 2 painted maps: density, length and clump each falling across u, and a colour map
/// (copper on the left at full weight, none on the right).
fn painted_maps() -> hairloom_core::model::root_maps::RootMaps {
    use hairloom_core::model::root_maps::{RootMapChannel, RootMaps};
    let mut maps = RootMaps::blank(4, 2).expect("maps");
    for channel in RootMapChannel::ALL {
        maps.set_channel_from_image(channel, 2, 1, &[0.2, 0.9])
            .expect("map");
    }
    maps.set_colour_from_image(2, 1, &[[0.7, 0.3, 0.1, 1.0], [0.7, 0.3, 0.1, 0.0]])
        .expect("colour");
    maps
}

fn project_seeds() -> Vec<(String, Vec<u8>)> {
    use hairloom_core::edit::{ExtrudeDirection, extrude};
    let mut project = Project::new(Document::new(
        "grid",
        hairloom_tests::grid_mesh(2, 2, 1, 0.1),
    ));
    let extruded = extrude(
        &project.document.hair_mesh,
        &[0, 1],
        ExtrudeDirection::AlongNormal { distance: 0.1 },
    )
    .expect("extrude");
    let mut after = project.document.clone();
    after.hair_mesh = extruded.mesh;
    project
        .history
        .commit(&mut project.document, "Extrude", after);
    let mut curled = project.document.clone();
    curled.styling.global.curl.radius_m = 0.01;
    project
        .history
        .commit(&mut project.document, "Curl", curled);
    let _ = project.history.undo(&mut project.document);
    // Painted maps, in the document and in a history step.
    let mut painted = project.document.clone();
    painted.root_maps = painted_maps();
    project
        .history
        .commit(&mut project.document, "Paint density", painted);
    let valid = hairloom_core::io::project::to_bytes(&project);
    let mut deep: Value = serde_json::from_slice(&valid).expect("json");
    deep["document"]["hair_mesh"]["bundles"][0]["layers"] = json!(20_000);
    let mut index: Value = serde_json::from_slice(&valid).expect("json");
    index["document"]["hair_mesh"]["bundles"][0]["vertices"][0] = json!(4_294_967_295u64);
    // A hostile scene: a light with no direction, a huge shadow map, a NaN-like roughness.
    let mut scene: Value = serde_json::from_slice(&valid).expect("json");
    scene["document"]["scene"]["lights"][0]["source"]["directional"]["to_light"] = json!([0, 0, 0]);
    scene["document"]["scene"]["effects"]["shadow_resolution"] = json!(4_294_967_295u64);
    scene["document"]["scene"]["material"]["longitudinal_roughness"] = json!(1e39);
    // An ombré that ends before it starts, with tip colours out of range.
    let mut ombre: Value = serde_json::from_slice(&valid).expect("json");
    ombre["document"]["scene"]["material"]["ombre"] =
        json!({"tip_rgb": [1e39, -1.0, 0.5], "start": 0.9, "end": 0.1});
    // Painted maps claiming 4096² texels with 8 bytes of them.
    let mut maps: Value = serde_json::from_slice(&valid).expect("json");
    maps["document"]["root_maps"] =
        json!({"width": 4096, "height": 4096, "rgba8_base64": "AAAAAAAAAAA="});
    vec![
        ("grid_with_history.hairloom".into(), valid),
        (
            "crafted_layers_20000.hairloom".into(),
            serde_json::to_vec(&deep).expect("json"),
        ),
        (
            "crafted_vertex_index_u32_max.hairloom".into(),
            serde_json::to_vec(&index).expect("json"),
        ),
        (
            "crafted_scene_zero_light_huge_shadow_map.hairloom".into(),
            serde_json::to_vec(&scene).expect("json"),
        ),
        (
            "crafted_scene_ombre_reversed.hairloom".into(),
            serde_json::to_vec(&ombre).expect("json"),
        ),
        (
            "crafted_root_maps_4096_short.hairloom".into(),
            serde_json::to_vec(&maps).expect("json"),
        ),
    ]
}

fn quad_builder() -> GltfBuilder {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    builder
}

fn gltf_seeds() -> Vec<(String, Vec<u8>)> {
    let builder = quad_builder();
    let glb = |json: &Value| builder.glb(json);
    let edited = |edit: &dyn Fn(&mut Value)| {
        let mut json = builder.json();
        edit(&mut json);
        json
    };
    let mut seeds = vec![
        ("quad.glb".to_string(), glb(&builder.json())),
        // Two materials and 8-bit vertex colours: where hair grows on a body.
        (
            "body_materials_colours.glb".to_string(),
            hairloom_tests::body_with_materials_glb(),
        ),
        // A character of two meshes: every mesh is read as the body.
        ("two_meshes.glb".to_string(), hairloom_tests::two_mesh_glb()),
    ];
    // The same quad as glTF JSON with its buffer in a data URI.
    let data = {
        use base64::Engine as _;
        base64::engine::general_purpose::STANDARD.encode(&builder.bin)
    };
    let text = edited(&|json| {
        json["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{data}"));
    });
    seeds.push((
        "quad_data_uri.gltf".into(),
        serde_json::to_vec(&text).expect("json"),
    ));
    // Crafted: each was a panic or an outside read.
    seeds.push((
        "crafted_accessor_index_9.glb".into(),
        glb(&edited(&|json| {
            json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(9);
        })),
    ));
    seeds.push((
        "crafted_node_cycle.glb".into(),
        glb(&edited(&|json| {
            json["nodes"] = json!([{"children": [1], "mesh": 0}, {"children": [0, 42]}]);
        })),
    ));
    let mut short = b"glTF".to_vec();
    short.extend_from_slice(&2u32.to_le_bytes());
    short.extend_from_slice(&4u32.to_le_bytes());
    short.extend_from_slice(&[0; 12]);
    seeds.push(("crafted_glb_length_4.glb".into(), short));
    for (name, uri) in [
        ("parent", "../../outside.bin"),
        ("absolute", "/etc/passwd"),
        ("file_scheme", "file:///etc/passwd"),
        ("proc_environ", "/proc/self/environ"),
        ("dev_zero", "/dev/zero"),
    ] {
        let json = edited(&|json| json["buffers"][0]["uri"] = json!(uri));
        seeds.push((
            format!("crafted_uri_{name}.gltf"),
            serde_json::to_vec(&json).expect("json"),
        ));
    }
    // 4,097 primitives sharing one accessor (past the primitive cap; 10,000 of them took
    // 18 s and 2 GB before the cap and the accessor cache).
    let mut many = builder.json();
    let primitive = many["meshes"][0]["primitives"][0].clone();
    many["meshes"][0]["primitives"] = Value::Array(vec![primitive; 4097]);
    seeds.push(("crafted_primitives_4097.glb".into(), glb(&many)));
    seeds
}

/// A small valid bundle with a body and painted maps, so every file kind is present.
pub fn bundle_with_body_files() -> Vec<(String, Vec<u8>)> {
    let mut document = hairloom_tests::bundle_variant(0);
    document.root_maps = painted_maps();
    document.body = BodyMesh {
        positions: vec![[0.0, 0.0, -0.1], [3.0, 0.0, -0.1], [0.0, 3.0, -0.1]],
        triangles: vec![[0, 1, 2]],
    };
    runtime_bundle(&document, &RuntimeOptions::default()).expect("the base bundle exports")
}

fn bundle_seeds() -> Vec<(String, Vec<u8>)> {
    let files = bundle_with_body_files();
    let manifest_index = files.len() - 1;
    let mut seeds: Vec<(String, Vec<u8>)> = files
        .iter()
        .enumerate()
        .map(|(i, (name, bytes))| (format!("file_{i}_{name}"), bundle_input(i, bytes)))
        .collect();
    let manifest = serde_json::to_value(manifest_of(&files)).expect("json");
    let crafted = |name: &str, edit: &dyn Fn(&mut Value)| {
        let mut value = manifest.clone();
        edit(&mut value);
        (
            format!("crafted_{name}.json"),
            bundle_input(manifest_index, &serde_json::to_vec(&value).expect("json")),
        )
    };
    seeds.extend([
        crafted("origin_u32_max", &|m| {
            m["bundles"][0]["origin"] = json!([4_294_967_295u64, 0]);
        }),
        crafted("strands_100000", &|m| {
            m["strands_per_bundle"] = json!(100_000)
        }),
        crafted("max_layers_20000", &|m| m["max_layers"] = json!(20_000)),
        crafted("texture_65536x65536x2e28", &|m| {
            m["hair_mesh"]["size"] = json!([65536, 65536, 268_435_456]);
        }),
        crafted("texture_parent_path", &|m| {
            m["w"]["file"] = json!("../../etc/passwd")
        }),
        crafted("body_absolute_path", &|m| m["body"] = json!("/etc/passwd")),
        crafted("max_vertices_log2_40", &|m| {
            m["lod"]["max_vertices_log2"] = json!(40)
        }),
    ]);
    // The far-hair file (format version 3): a header claiming u32::MAX thick hairs, and a
    // first thick hair whose corner strand is u32::MAX.
    if let Some(far_index) = files.iter().position(|(n, _)| n.starts_with("far_hair")) {
        let far = &files[far_index].1;
        let word = |bytes: &mut Vec<u8>, at: usize| {
            if let Some(slot) = bytes.get_mut(at..at + 4) {
                slot.copy_from_slice(&u32::MAX.to_le_bytes());
            }
        };
        let mut huge = far.clone();
        word(&mut huge, 16);
        seeds.push((
            "crafted_far_hair_thick_hairs_u32_max".into(),
            bundle_input(far_index, &huge),
        ));
        let entries = far
            .get(12..16)
            .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
        let mut corner = far.clone();
        word(&mut corner, 24 + 16 * entries);
        seeds.push((
            "crafted_far_hair_corner_u32_max".into(),
            bundle_input(far_index, &corner),
        ));
    }
    seeds
}

fn ktx2_seeds() -> Vec<(String, Vec<u8>)> {
    let files = bundle_with_body_files();
    let mut seeds: Vec<(String, Vec<u8>)> = files
        .iter()
        .filter(|(name, _)| name.ends_with(".ktx2"))
        .map(|(name, bytes)| (name.clone(), bytes.clone()))
        .collect();
    let (_, base) = &files[0];
    let dfd_offset = u32::from_le_bytes([base[48], base[49], base[50], base[51]]) as usize;
    // A texel-block dimension byte of 255 panicked inside the ktx2 crate's DFD parser.
    let mut dimension = base.clone();
    dimension[dfd_offset + 4 + 12..dfd_offset + 4 + 16].fill(255);
    seeds.push(("crafted_dfd_block_dimension_255.ktx2".into(), dimension));
    // 65536 x 65536 x 2^28 texels: the byte count wrapped to 0 and passed the length check.
    let mut huge = base.clone();
    huge[20..24].copy_from_slice(&65536u32.to_le_bytes());
    huge[24..28].copy_from_slice(&65536u32.to_le_bytes());
    huge[28..32].copy_from_slice(&(1u32 << 28).to_le_bytes());
    seeds.push(("crafted_size_65536x65536x2e28.ktx2".into(), huge));
    seeds
}
