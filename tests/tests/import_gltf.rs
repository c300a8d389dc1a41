//! glTF import: the real head scan, crafted valid files, and one crafted file per kind of
//! malformed input. Malformed input must give an error naming the file, mesh and accessor,
//! never a panic.

use hairloom_core::io::import::{ImportError, ImportOptions, import_file, import_slice};
use hairloom_tests::{GltfBuilder, assets_dir};

fn import(
    bytes: &[u8],
    options: &ImportOptions,
) -> Result<hairloom_core::io::import::ImportedMesh, ImportError> {
    import_slice(bytes, None, "crafted.glb", options)
}

fn error_text(bytes: &[u8]) -> String {
    match import(bytes, &ImportOptions::default()) {
        Ok(mesh) => panic!("expected an error, imported {} faces", mesh.faces.len()),
        Err(error) => error.to_string(),
    }
}

#[test]
fn head_scan_comes_back_as_quads() {
    let mesh = import_file(
        &assets_dir().join("head/LeePerrySmith.glb"),
        &ImportOptions::default(),
    )
    .expect("head imports");
    // The source mesh is 8,833 quads and 6 triangles stored as 17,672 triangles.
    assert_eq!(mesh.source_triangles, 17_672);
    assert!(mesh.quad_count() > 8_700, "{} quads", mesh.quad_count());
    assert!(
        mesh.triangle_count() < 200,
        "{} triangles",
        mesh.triangle_count()
    );
    assert!(mesh.has_uv);
    // Welding by position merges the uv-seam duplicates of the file's 9,223 vertices.
    assert!(mesh.positions.len() < 9_223);
    let scalp = mesh.to_hair_mesh(|_| true);
    scalp
        .validate()
        .expect("the imported scalp is a valid hair mesh");
}

#[test]
fn crafted_quad_imports_as_one_quad_with_corner_uv() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let glb = builder.glb(&builder.json());
    let mesh = import(&glb, &ImportOptions::default()).expect("valid file");
    assert_eq!(mesh.mesh_name, "scalp");
    assert_eq!(mesh.faces.len(), 1);
    assert_eq!(mesh.faces[0].len(), 4);
    let uv_sum: glam::DVec2 = mesh.uvs[0].iter().copied().sum();
    assert!((uv_sum - glam::DVec2::splat(2.0)).length() < 1e-12);
    // Without pairing it stays two triangles.
    let mesh = import(
        &glb,
        &ImportOptions {
            pair_quads: false,
            ..Default::default()
        },
    )
    .expect("valid");
    assert_eq!(mesh.faces.len(), 2);
}

#[test]
fn several_meshes_need_a_name_and_the_named_one_is_read() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("body");
    builder.add_quad_mesh("scalp");
    let glb = builder.glb(&builder.json());
    let message = error_text(&glb);
    assert!(
        message.contains("several meshes") && message.contains("\"scalp\""),
        "{message}"
    );
    let mesh = import(
        &glb,
        &ImportOptions {
            mesh_name: Some("scalp".into()),
            ..Default::default()
        },
    )
    .expect("named");
    assert_eq!(mesh.mesh_name, "scalp");
    let missing = import(
        &glb,
        &ImportOptions {
            mesh_name: Some("hair".into()),
            ..Default::default()
        },
    );
    assert!(
        missing
            .expect_err("no such mesh")
            .to_string()
            .contains("no mesh named \"hair\"")
    );
}

/// Issue 35: a character made of several meshes — hair on one, every mesh the body.
#[test]
fn every_mesh_of_a_file_becomes_the_body_under_one_cap() {
    use hairloom_core::io::import::import_body;
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    builder.add_quad_mesh("");
    builder.add_quad_mesh("lashes");
    let mut json = builder.json();
    // The second mesh has no name (it is "#1"); the third is drawn as lines.
    json["meshes"][1]
        .as_object_mut()
        .expect("mesh")
        .remove("name");
    json["meshes"][2]["primitives"][0]["mode"] = serde_json::json!(1);
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("character.glb");
    std::fs::write(&path, builder.glb(&json)).expect("write");
    match import_file(&path, &ImportOptions::default()) {
        Err(ImportError::SeveralMeshes { names, .. }) => {
            assert_eq!(names, vec!["scalp", "#1", "lashes"])
        }
        other => panic!("{:?}", other.map(|m| m.mesh_name)),
    }
    let unnamed = import_file(
        &path,
        &ImportOptions {
            mesh_name: Some("#1".into()),
            ..Default::default()
        },
    )
    .expect("an unnamed mesh by its index");
    assert_eq!(unnamed.mesh_name, "mesh 1");
    let (body, skipped) = import_body(&path, &ImportOptions::default()).expect("a body");
    assert_eq!(body.triangles.len(), 4, "two quads; the lines are left out");
    assert_eq!(body.positions.len(), 8);
    body.validate()
        .expect("indices stay in range across meshes");
    assert_eq!(skipped, vec!["lashes"]);
    // The caps count every mesh together: two quads are four triangles.
    let capped = import_body(
        &path,
        &ImportOptions {
            limits: hairloom_core::io::import::ImportLimits {
                max_triangles: 3,
                ..Default::default()
            },
            ..Default::default()
        },
    );
    let error = capped.expect_err("over the cap").to_string();
    assert!(
        error.contains("triangles") && error.contains("cap of 1"),
        "{error}"
    );
}

#[test]
fn truncated_file_is_an_error() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let glb = builder.glb(&builder.json());
    for cut in [0, 10, 30, glb.len() / 2, glb.len() - 4] {
        let message = error_text(&glb[..cut]);
        assert!(message.starts_with("crafted.glb:"), "{message}");
    }
}

#[test]
fn buffer_shorter_than_its_views_names_the_accessor() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let mut json = builder.json();
    // The position view claims more bytes than the buffer has.
    json["bufferViews"][0]["byteLength"] = serde_json::json!(4096);
    json["buffers"][0]["byteLength"] = serde_json::json!(5000);
    let message = error_text(&builder.glb(&json));
    assert!(message.contains("crafted.glb"), "{message}");
    // Either the loader or our reader refuses it; neither panics.
    let mut json = builder.json();
    json["accessors"][0]["count"] = serde_json::json!(400);
    let message = error_text(&builder.glb(&json));
    assert!(
        message.contains("accessor 0")
            && message.contains("POSITION")
            && message.contains("truncated"),
        "{message}"
    );
}

#[test]
fn missing_position_names_mesh_and_primitive() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let mut json = builder.json();
    json["meshes"][0]["primitives"][0]["attributes"]
        .as_object_mut()
        .expect("attributes")
        .remove("POSITION");
    let message = error_text(&builder.glb(&json));
    // The glTF loader's validation or our reader refuses it; either way the primitive and
    // the attribute are named.
    assert!(
        message.contains("POSITION")
            && (message.contains("primitive 0") || message.contains("primitives[0]")),
        "{message}"
    );
}

#[test]
fn index_out_of_range_names_the_index_accessor() {
    let mut builder = GltfBuilder::default();
    let p = builder.add_f32(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3", 3);
    let i = builder.add_indices(&[0, 1, 7]);
    builder.meshes.push(serde_json::json!({
        "name": "scalp",
        "primitives": [{"attributes": {"POSITION": p}, "indices": i}]
    }));
    let message = error_text(&builder.glb(&builder.json()));
    assert!(
        message.contains("accessor 1 (indices)")
            && message.contains("index 7")
            && message.contains("out of range"),
        "{message}"
    );
}

#[test]
fn nan_position_names_element_and_accessor() {
    let mut builder = GltfBuilder::default();
    let p = builder.add_f32(
        &[0.0, 0.0, 0.0, 1.0, f32::NAN, 0.0, 0.0, 1.0, 0.0],
        "VEC3",
        3,
    );
    builder.meshes.push(
        serde_json::json!({"name": "scalp", "primitives": [{"attributes": {"POSITION": p}}]}),
    );
    let message = error_text(&builder.glb(&builder.json()));
    assert!(
        message.contains("accessor 0 (POSITION)")
            && message.contains("element 1")
            && message.contains("not finite"),
        "{message}"
    );
}

#[test]
fn non_triangle_mode_is_refused() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let mut json = builder.json();
    json["meshes"][0]["primitives"][0]["mode"] = serde_json::json!(1); // LINES
    let message = error_text(&builder.glb(&json));
    assert!(
        message.contains("mesh \"scalp\", primitive 0") && message.contains("Lines"),
        "{message}"
    );
}

#[test]
fn wrong_accessor_type_and_missing_external_buffer() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let mut json = builder.json();
    json["accessors"][0]["type"] = serde_json::json!("VEC2");
    json["accessors"][0]["count"] = serde_json::json!(6);
    let message = error_text(&builder.glb(&json));
    assert!(
        message.contains("POSITION") && message.contains("expected 3 components"),
        "{message}"
    );

    // A .gltf whose buffer is an external file that does not exist.
    let dir = tempfile::tempdir().expect("temp dir");
    let mut json = builder.json();
    json["buffers"][0]["uri"] = serde_json::json!("missing.bin");
    let path = dir.path().join("scalp.gltf");
    std::fs::write(&path, serde_json::to_vec(&json).expect("json")).expect("write");
    let error = import_file(&path, &ImportOptions::default()).expect_err("missing buffer");
    assert!(
        error.to_string().contains("scalp.gltf") && error.to_string().contains("buffer"),
        "{error}"
    );
}

#[test]
fn collapsed_geometry_is_reported_not_panicked() {
    let mut builder = GltfBuilder::default();
    // Every vertex at the same place: welding collapses every triangle.
    let p = builder.add_f32(&[1.0; 9], "VEC3", 3);
    builder
        .meshes
        .push(serde_json::json!({"name": "dot", "primitives": [{"attributes": {"POSITION": p}}]}));
    let message = error_text(&builder.glb(&builder.json()));
    assert!(
        message.contains("mesh \"dot\" has no triangles"),
        "{message}"
    );
}

#[test]
fn random_byte_corruption_never_panics() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let glb = builder.glb(&builder.json());
    let mut state = 0x2545F4914F6CDD1Du64;
    for _ in 0..400 {
        let mut bytes = glb.clone();
        for _ in 0..4 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let at = (state as usize) % bytes.len();
            bytes[at] = (state >> 32) as u8;
        }
        // Either result is fine; a panic fails the test.
        let _ = import(&bytes, &ImportOptions::default());
    }
}

/// Hostile files of issue "Hostile and oversized input": each must be a named error.
#[test]
fn an_accessor_index_out_of_range_is_named_not_a_panic_in_gltf_json() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let mut json = builder.json();
    // gltf-json 1.4.1's validation indexes `accessors[9]` unchecked and panics.
    json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = serde_json::json!(9);
    let message = error_text(&builder.glb(&json));
    assert!(message.contains("accessor 9 does not exist"), "{message}");
    let mut json = builder.json();
    json["accessors"][0]["bufferView"] = serde_json::json!(77);
    let message = error_text(&builder.glb(&json));
    assert!(
        message.contains("buffer view 77 does not exist"),
        "{message}"
    );
    let mut json = builder.json();
    json["bufferViews"][0]["buffer"] = serde_json::json!(5);
    let message = error_text(&builder.glb(&json));
    assert!(message.contains("buffer 5 does not exist"), "{message}");
    // A node cycle and a node index out of range: the walk stays bounded.
    let mut json = builder.json();
    json["nodes"] = serde_json::json!([{"children": [1]}, {"children": [0, 42]}]);
    json["scenes"][0]["nodes"] = serde_json::json!([0, 99]);
    import(&builder.glb(&json), &ImportOptions::default()).expect("imports untransformed");
}

#[test]
fn a_glb_header_shorter_than_itself_is_named() {
    let mut glb = b"glTF".to_vec();
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&4u32.to_le_bytes());
    glb.extend_from_slice(&[0; 12]);
    let message = error_text(&glb);
    assert!(message.contains("declares 4 bytes"), "{message}");
}

#[test]
fn buffers_are_read_only_from_regular_files_inside_the_gltf_folder() {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let temp = tempfile::tempdir().expect("temp dir");
    let folder = temp.path().join("scalp");
    std::fs::create_dir(&folder).expect("mkdir");
    std::fs::write(temp.path().join("outside.bin"), &builder.bin).expect("write");
    std::fs::write(folder.join("inside bin.bin"), &builder.bin).expect("write");
    let path = folder.join("scalp.gltf");
    let import_with_uri = |uri: &str| {
        let mut json = builder.json();
        json["buffers"][0]["uri"] = serde_json::json!(uri);
        std::fs::write(&path, serde_json::to_vec(&json).expect("json")).expect("write");
        import_file(&path, &ImportOptions::default())
    };
    // Inside, %-encoded: read.
    import_with_uri("inside%20bin.bin").expect("a buffer inside the folder");
    let outside = temp.path().join("outside.bin").display().to_string();
    let file_uri = format!("file://{outside}");
    for uri in [
        "../outside.bin",
        "sub/../../outside.bin",
        outside.as_str(),
        file_uri.as_str(),
        "/proc/self/environ",
        "/dev/zero",
    ] {
        let message = import_with_uri(uri).expect_err(uri).to_string();
        assert!(message.contains("refused"), "{uri}: {message}");
        // Nothing about the outside file (such as its size) is revealed.
        assert!(
            !message.contains(&builder.bin.len().to_string()),
            "{uri}: {message}"
        );
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("/dev/zero", folder.join("zero.bin")).expect("link");
        let message = import_with_uri("zero.bin").expect_err("link").to_string();
        assert!(message.contains("refused"), "{message}");
        let fifo = folder.join("fifo.bin");
        if std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success())
        {
            // Would hang forever if opened blocking.
            let message = import_with_uri("fifo.bin").expect_err("fifo").to_string();
            assert!(message.contains("FIFO"), "{message}");
        }
    }
    // Embedded data (a base64 data URI) is fine, and an import from bytes alone refuses
    // external files.
    use base64::Engine as _;
    let data = base64::engine::general_purpose::STANDARD.encode(&builder.bin);
    import_with_uri(&format!("data:application/octet-stream;base64,{data}")).expect("data URI");
    let mut json = builder.json();
    json["buffers"][0]["uri"] = serde_json::json!("inside%20bin.bin");
    let message = error_text(&serde_json::to_vec(&json).expect("json"));
    assert!(message.contains("no folder"), "{message}");
}

#[test]
fn ten_thousand_primitives_sharing_an_accessor_hit_a_named_cap() {
    // 790 KB of this used to take 18 s and 2 GB: each primitive re-read the accessor.
    let mut builder = GltfBuilder::default();
    let positions: Vec<f32> = (0..3000 * 3)
        .map(|i| (i % 7) as f32 + i as f32 * 1e-3)
        .collect();
    let p = builder.add_f32(&positions, "VEC3", 3000);
    let primitive = serde_json::json!({"attributes": {"POSITION": p}});
    builder.meshes.push(serde_json::json!({
        "name": "many", "primitives": vec![primitive; 10_000]
    }));
    let glb = builder.glb(&builder.json());
    let message = error_text(&glb);
    assert!(
        message.contains("10000 primitives, above the import cap of 4096"),
        "{message}"
    );
    let options = ImportOptions {
        limits: hairloom_core::io::import::ImportLimits {
            max_primitives: 20_000,
            ..Default::default()
        },
        ..ImportOptions::default()
    };
    let message = import(&glb, &options).expect_err("vertex cap").to_string();
    assert!(
        message.contains("vertices, above the import cap of 4000000")
            && message.contains("--max-vertices"),
        "{message}"
    );
}

/// Issue "Scenes and effects on demand, part 2": a body animation in the glTF becomes the
/// head animation, moving the imported body exactly as the file moves the mesh.
#[test]
fn a_body_animation_in_the_file_becomes_the_head_animation() {
    use glam::DVec3;
    use hairloom_core::model::motion::Motion;
    let imported = import(
        &hairloom_tests::animated_quad_glb(|_| {}),
        &ImportOptions::default(),
    )
    .expect("imports");
    let keys = &imported.body_animation;
    assert_eq!(keys.len(), 2, "{keys:?}");
    assert_eq!((keys[0].time_s, keys[1].time_s), (0.0, 1.0));
    assert!(
        keys[0].yaw_deg.abs() < 1e-4 && (keys[1].yaw_deg - 90.0).abs() < 1e-3,
        "{keys:?}"
    );
    let motion = Motion {
        head_animation: keys.clone(),
        ..Motion::default()
    };
    motion.validate().expect("valid keys");
    // Each imported vertex goes where the file's animation puts it: at t, the node's
    // transform T(t) applied to the local vertex; imported, the rest pose T(0).
    let local = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
    ];
    for t in [0.0f64, 0.25, 0.5, 1.0, 2.0] {
        let f = t.min(1.0);
        let rotation = glam::DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2 * f);
        let translation = DVec3::new(0.0, 1.0 + 0.5 * f, 0.0);
        let pose = motion.head_pose(t);
        for p in local {
            let rest = DVec3::new(0.0, 1.0, 0.0) + p * 2.0;
            let expected = translation + rotation * (p * 2.0);
            let moved = pose.apply(rest);
            assert!(
                moved.distance(expected) < 1e-4,
                "t {t}: {p} went to {moved}, the file puts it at {expected}"
            );
        }
    }
    // No animation, no keys.
    let mut still = GltfBuilder::default();
    still.add_quad_mesh("body");
    let bytes = still.glb(&still.json());
    assert!(
        import(&bytes, &ImportOptions::default())
            .expect("imports")
            .body_animation
            .is_empty()
    );
}

#[test]
fn malformed_animations_are_refused_by_name() {
    type JsonEdit = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(JsonEdit, &str)> = vec![
        (
            Box::new(|j| j["animations"][0]["channels"][0]["sampler"] = 7.into()),
            "uses sampler 7",
        ),
        (
            Box::new(|j| j["animations"][0]["samplers"][0]["output"] = 99.into()),
            "accessor 99 does not exist",
        ),
        (
            // Times as the rotation's output: one component where four are needed.
            Box::new(|j| j["animations"][0]["samplers"][0]["output"] = 0.into()),
            "expected 4 components",
        ),
        (
            // The translation values (2 keys of VEC3) read as cubic-spline: 3 per key needed.
            Box::new(|j| j["animations"][0]["samplers"][1]["interpolation"] = "CUBICSPLINE".into()),
            "cubic-spline translation values",
        ),
    ];
    // Accessor indices: the quad uses 0-2, times 3, rotations 4, translations 5.
    for (edit, expected) in cases {
        let bytes = hairloom_tests::animated_quad_glb(|j| {
            edit(j);
            if j["animations"][0]["samplers"][0]["output"] == 0 {
                j["animations"][0]["samplers"][0]["output"] = 3.into();
            }
        });
        let text = error_text(&bytes);
        assert!(text.contains(expected), "expected {expected:?} in {text:?}");
        assert!(text.contains("crafted.glb"), "{text}");
    }
}

/// Issue 35: where hair grows on an imported body — by material, by a painted vertex-colour
/// mask, or by faces — and what each refuses by name.
#[test]
fn a_scalp_region_is_cut_by_material_or_painted_mask_and_the_body_stays_whole() {
    use hairloom_core::io::scalp_region::{ScalpRegion, ScalpRegionError, material_faces};
    let mesh = import(
        &hairloom_tests::body_with_materials_glb(),
        &ImportOptions::default(),
    )
    .expect("valid file");
    // Three quads, each one primitive's (that triangles of two primitives never pair is
    // `pair_quads`' own unit test).
    assert_eq!(mesh.quad_count(), 3, "{:?}", mesh.faces);
    assert_eq!(
        material_faces(&mesh),
        vec![("Scalp".to_string(), 2), ("Skin".to_string(), 1)]
    );
    let red: Vec<f64> = mesh
        .face_colours
        .as_ref()
        .expect("COLOR_0 read")
        .iter()
        .map(|c| c[0])
        .collect();
    let mut sorted = red.clone();
    sorted.sort_by(f64::total_cmp);
    assert_eq!(sorted, vec![0.0, 0.5, 1.0], "8-bit normalised colours");

    let centre_x = |face: usize| {
        mesh.faces[face]
            .iter()
            .map(|&v| mesh.positions[v as usize].x)
            .sum::<f64>()
            / 4.0
    };
    let hair_at = |region: &str| -> Vec<f64> {
        let keep = region
            .parse::<ScalpRegion>()
            .expect("parses")
            .faces(&mesh)
            .expect("a region");
        let mut xs: Vec<f64> = (0..mesh.faces.len())
            .filter(|&f| keep[f])
            .map(centre_x)
            .collect();
        xs.sort_by(f64::total_cmp);
        xs
    };
    assert_eq!(hair_at("all"), vec![0.5, 1.5, 2.5]);
    assert_eq!(hair_at("material:Scalp"), vec![0.5, 1.5]);
    assert_eq!(hair_at("material: Skin , Scalp"), vec![0.5, 1.5, 2.5]);
    assert_eq!(hair_at("colour:r>0.75"), vec![0.5]);
    assert_eq!(hair_at("color:R<0.75"), vec![1.5, 2.5]);
    assert_eq!(hair_at("colour:a>0.5"), vec![0.5, 1.5, 2.5]);

    // The scalp holds the region's faces only; the body is the whole mesh.
    let keep = ScalpRegion::Materials(vec!["Scalp".into()])
        .faces(&mesh)
        .expect("region");
    let scalp = mesh.to_hair_mesh(|f| keep[f]);
    scalp.validate().expect("a valid scalp");
    assert_eq!(scalp.bundles.len(), 2);
    assert_eq!(scalp.columns.len(), 6);
    assert_eq!(mesh.to_body().triangles.len(), 6);

    // Named errors.
    let error = ScalpRegion::Materials(vec!["Hair".into()])
        .faces(&mesh)
        .expect_err("no such material")
        .to_string();
    assert!(
        error.contains("\"Hair\"") && error.contains("\"Scalp\" (2 faces)"),
        "{error}"
    );
    let error = "colour:g>0.5"
        .parse::<ScalpRegion>()
        .expect("parses")
        .faces(&mesh)
        .expect_err("nothing is green");
    assert!(matches!(error, ScalpRegionError::Empty { .. }), "{error}");
    let error = ScalpRegion::Faces(vec![0, 3])
        .faces(&mesh)
        .expect_err("face 3 does not exist");
    assert!(error.to_string().contains("face 3"), "{error}");
    for bad in [
        "",
        "material:",
        "colour:r=0.5",
        "colour:x>0.5",
        "colour:r>2",
        "colour:r>nan",
        "grow:everywhere",
    ] {
        let error = bad.parse::<ScalpRegion>().expect_err(bad).to_string();
        assert!(error.contains(&format!("\"{bad}\"")), "{bad}: {error}");
    }
    // A file with no vertex colours cannot be cut by a mask.
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("scalp");
    let plain = import(&builder.glb(&builder.json()), &ImportOptions::default()).expect("valid");
    assert!(plain.face_colours.is_none());
    assert!(material_faces(&plain).is_empty());
    let error = "colour:r>0.5"
        .parse::<ScalpRegion>()
        .expect("parses")
        .faces(&plain)
        .expect_err("no COLOR_0");
    assert!(
        matches!(error, ScalpRegionError::NoVertexColour { .. }),
        "{error}"
    );
    // Colour round-trips through Display and FromStr.
    let region: ScalpRegion = "colour:b<0.25".parse().expect("parses");
    assert_eq!(region.to_string().parse::<ScalpRegion>(), Ok(region));
}

#[test]
fn a_colour_accessor_of_the_wrong_length_or_not_finite_is_named() {
    let mut glb_json = {
        let mut builder = GltfBuilder::default();
        builder.add_quad_mesh("scalp");
        let colours = builder.add_f32(&[1.0, 0.0, 0.0, f32::NAN, 0.0, 0.0], "VEC3", 2);
        let mut json = builder.json();
        json["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = serde_json::json!(colours);
        (builder, json)
    };
    let error = match import(&glb_json.0.glb(&glb_json.1), &ImportOptions::default()) {
        Ok(_) => panic!("a NaN colour must be refused"),
        Err(error) => error.to_string(),
    };
    assert!(
        error.contains("COLOR_0") && error.contains("not finite"),
        "{error}"
    );
    glb_json.1["accessors"][3]["count"] = serde_json::json!(1);
    let error = match import(&glb_json.0.glb(&glb_json.1), &ImportOptions::default()) {
        Ok(_) => panic!("too few colours must be refused"),
        Err(error) => error.to_string(),
    };
    assert!(
        error.contains("COLOR_0") && error.contains("1 colours for 4"),
        "{error}"
    );
}
