//! A game that simulates the hair mesh must rebuild the runtime textures every frame. This
//! test is such a game, written from `docs/runtime-format.md` ("Animating the hair mesh")
//! alone: it reads the manifest as JSON and the textures as loaded, moves every hair-mesh
//! vertex (a turn of the head and a sway that grows toward the tips), rebuilds the hair-mesh,
//! u and v slices of every texel with the document's formulas, and must match what the
//! exporter writes for the moved hair mesh.

use std::collections::HashMap;

use glam::{DMat3, DVec2, DVec3};
use hairloom_core::io::project;
use hairloom_core::io::runtime_bundle::{load_runtime_bundle_from, runtime_bundle};
use hairloom_core::runtime::hair::RuntimeOptions;
use hairloom_core::runtime::textures::{Precision, RuntimeTextures};
use hairloom_tests::sample_paths;
use serde_json::Value;

/// Where the simulation put vertex `k` of a column whose rest position is `p`.
fn moved(p: DVec3, k: usize) -> DVec3 {
    let turned = DMat3::from_rotation_y(0.4) * DMat3::from_rotation_x(-0.15) * p;
    let sway = k as f64 * k as f64 * 0.0015;
    turned
        + DVec3::new(
            sway * (9.0 * p.y).sin(),
            -0.3 * sway,
            sway * (7.0 * p.x).cos(),
        )
}

/// The document's centripetal Catmull-Rom segment `k` of `p` as its two quadratics' inner
/// control points `(q0, q1)`.
fn control_points(p: &[DVec3], k: usize) -> (DVec3, DVec3) {
    let c = p.len() - 1;
    let at = |i: isize| -> DVec3 {
        if i < 0 {
            2.0 * p[0] - p[1]
        } else if i as usize > c {
            2.0 * p[c] - p[c - 1]
        } else {
            p[i as usize]
        }
    };
    let k = k as isize;
    let (pm, p0, p1, p2) = (at(k - 1), at(k), at(k + 1), at(k + 2));
    let d1 = (p0 - pm).length().sqrt();
    let d2 = (p1 - p0).length().sqrt();
    let d3 = (p2 - p1).length().sqrt();
    let b1 = if d1 <= 1e-150 || d1 + d2 <= 1e-150 {
        p0
    } else {
        p0 + (d1 * d1 * (p1 - p0) + d2 * d2 * (p0 - pm)) / (3.0 * d1 * (d1 + d2))
    };
    let b2 = if d3 <= 1e-150 || d3 + d2 <= 1e-150 {
        p1
    } else {
        p1 + (d3 * d3 * (p0 - p1) + d2 * d2 * (p1 - p2)) / (3.0 * d3 * (d3 + d2))
    };
    (p0 + 0.75 * (b1 - p0), p1 + 0.75 * (b2 - p1))
}

/// The document's orthonormal fallback frame around `n`.
fn fallback(n: DVec3) -> (DVec3, DVec3) {
    let n = n.try_normalize().unwrap_or(DVec3::Z);
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// The document's completion of a frame from one direction `a` and the normal `n`.
fn complete(a: DVec3, n: DVec3) -> (DVec3, DVec3) {
    match (a - n * a.dot(n)).try_normalize() {
        Some(u) => (u, n.cross(u)),
        None => fallback(n),
    }
}

/// A face as the game sees it: columns and uvs in face order.
struct Face {
    columns: Vec<usize>,
    uvs: Vec<DVec2>,
    layers: usize,
}

/// Frames `(û, v̂)` of every column at layer `k` from the faces that reach it.
fn layer_frames(
    faces: &[Face],
    positions: &[Vec<DVec3>],
    k: usize,
) -> HashMap<usize, (DVec3, DVec3)> {
    let mut normal: HashMap<usize, DVec3> = HashMap::new();
    let mut largest: HashMap<usize, f64> = HashMap::new();
    let mut found = Vec::new();
    for face in faces.iter().filter(|f| f.layers >= k) {
        let n = face.columns.len();
        for f in 0..n {
            let (next, prev) = ((f + 1) % n, (f + n - 1) % n);
            let c = face.columns[f];
            let p = |i: usize| positions[face.columns[i]][k];
            let (e1, e2) = (p(next) - p(f), p(prev) - p(f));
            *normal.entry(c).or_default() += e1.cross(e2);
            let (du1, du2) = (face.uvs[next] - face.uvs[f], face.uvs[prev] - face.uvs[f]);
            let det = du1.x * du2.y - du2.x * du1.y;
            if det == 0.0 || !det.is_finite() {
                continue;
            }
            let u = (e1 * du2.y - e2 * du1.y) / det;
            let v = (e2 * du1.x - e1 * du2.x) / det;
            if !(u.is_finite() && v.is_finite()) {
                continue;
            }
            let area = 0.5 * det.abs();
            let most = largest.entry(c).or_default();
            *most = most.max(area);
            found.push((c, area, u, v));
        }
    }
    let mut sums: HashMap<usize, (DVec3, DVec3)> = HashMap::new();
    for (c, area, u, v) in found {
        if area > 1e-10 * largest[&c] {
            let sum = sums.entry(c).or_default();
            sum.0 += u * area;
            sum.1 += v * area;
        }
    }
    normal
        .iter()
        .map(|(&c, &normal_sum)| {
            let n = normal_sum.try_normalize().unwrap_or(DVec3::Z);
            let (su, sv) = sums.get(&c).copied().unwrap_or_default();
            let frame = match (su.try_normalize(), sv.try_normalize()) {
                (Some(u), Some(v)) if u.cross(v).length() > 1e-6 => (u, v),
                (Some(u), _) => complete(u, n),
                (None, Some(v)) => {
                    let (_, w_side) = complete(v, n);
                    (-w_side, v)
                }
                (None, None) => fallback(n),
            };
            (c, frame)
        })
        .collect()
}

#[test]
fn a_game_rebuilds_the_textures_of_a_moving_hair_mesh_from_the_bundle_and_the_document() {
    let path = sample_paths()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("head_long_wavy"))
        .expect("sample");
    let mut document = project::load(&path).expect("loads").document;
    // A bald face at the edge of the scalp: it grows no hair, but its corners weigh in on
    // its neighbours' root frames, and one of them is held by no texel at all.
    let mesh = &mut document.hair_mesh;
    let mut uses = vec![0; mesh.columns.len()];
    for bundle in &mesh.bundles {
        for &c in &bundle.vertices {
            uses[c as usize] += 1;
        }
    }
    let bald = mesh
        .bundles
        .iter()
        .position(|b| b.vertices.iter().any(|&c| uses[c as usize] == 1))
        .expect("a bundle at the edge");
    mesh.bundles[bald].layers = 0;
    let options = RuntimeOptions {
        precision: Precision::F32,
        ..RuntimeOptions::default()
    };
    let files: HashMap<String, Vec<u8>> = runtime_bundle(&document, &options)
        .expect("exports")
        .into_iter()
        .collect();
    let manifest: Value = serde_json::from_slice(&files["manifest.json"]).expect("JSON");
    let rest = load_runtime_bundle_from(&files, "memory")
        .expect("loads")
        .textures;

    // What the game's simulation knows: each column's vertices, moved. Rest positions come
    // from the hair-mesh texture (slice 3k of any texel holding the column).
    let column_layers: Vec<usize> = manifest["column_layers"]
        .as_array()
        .expect("column_layers")
        .iter()
        .map(|l| l.as_u64().expect("a count") as usize)
        .collect();
    let offsets = [[0, 0], [1, 0], [1, 1], [0, 1]];
    let bundles = manifest["bundles"].as_array().expect("bundles");
    let mut positions: Vec<Vec<DVec3>> = vec![Vec::new(); column_layers.len()];
    let mut faces = Vec::new();
    // Each bundle's block corners: their texel and the column it holds.
    let mut blocks: Vec<Vec<((u32, u32), usize)>> = Vec::new();
    for bundle in bundles {
        let origin: Vec<u32> = serde_json::from_value(bundle["origin"].clone()).expect("origin");
        let columns: Vec<usize> =
            serde_json::from_value(bundle["columns"].clone()).expect("columns");
        let corners: Vec<((u32, u32), usize)> = offsets
            .iter()
            .zip(&columns)
            .map(|(o, &c)| ((origin[0] + o[0], origin[1] + o[1]), c))
            .collect();
        let corner_of_block: Vec<usize> =
            serde_json::from_value(bundle["corner_of_block"].clone()).expect("corners");
        let triangle = bundle["triangle"].as_bool().expect("triangle");
        let mut face = Face {
            columns: Vec::new(),
            uvs: Vec::new(),
            layers: bundle["layers"].as_u64().expect("layers") as usize,
        };
        // Face corner f is the first block corner b with corner_of_block[b] = f.
        for f in 0..if triangle { 3 } else { 4 } {
            let b = corner_of_block
                .iter()
                .position(|&c| c == f)
                .expect("every face corner");
            let ((x, y), c) = corners[b];
            let uv = rest.uv.get(x, y, 0);
            face.columns.push(c);
            face.uvs.push(DVec2::new(uv.x as f64, uv.y as f64));
            if positions[c].is_empty() {
                positions[c] = (0..=column_layers[c])
                    .map(|k| {
                        let p = rest.hair_mesh.get(x, y, 3 * k as u32);
                        moved(p.truncate().as_dvec3(), k)
                    })
                    .collect();
            }
        }
        faces.push(face);
        blocks.push(corners);
    }
    let bare_faces = manifest["bare_faces"].as_array().expect("the bald face");
    assert_eq!(bare_faces.len(), 1);
    for face in bare_faces {
        let columns: Vec<usize> = serde_json::from_value(face["columns"].clone()).expect("columns");
        let uvs: Vec<[f64; 2]> = serde_json::from_value(face["uvs"].clone()).expect("uvs");
        let rest: Vec<[f64; 3]> =
            serde_json::from_value(face["positions"].clone()).expect("positions");
        for (&c, p) in columns.iter().zip(&rest) {
            if positions[c].is_empty() {
                // Held by no texel: only its root, which the bald face needs.
                positions[c] = vec![moved(DVec3::from(*p), 0)];
            }
        }
        faces.push(Face {
            columns,
            uvs: uvs.into_iter().map(DVec2::from).collect(),
            layers: 0,
        });
    }
    assert!(
        positions.iter().any(|p| p.len() == 1),
        "a corner of the bald face is held by no texel"
    );

    // The exporter's textures of the same moved hair mesh.
    let mut moved_mesh = document.hair_mesh.clone();
    for column in &mut moved_mesh.columns {
        for (k, p) in column.positions.iter_mut().enumerate() {
            *p = moved(p.as_vec3().as_dvec3(), k);
        }
    }
    let expected = RuntimeTextures::build(&moved_mesh, Precision::F32);

    let max_layers = manifest["max_layers"].as_u64().expect("max_layers") as usize;
    let frames: Vec<_> = (0..=max_layers)
        .map(|k| layer_frames(&faces, &positions, k))
        .collect();
    let size = {
        let (lo, hi) = moved_mesh.bounds().expect("bounds");
        (hi - lo).length()
    };
    let (mut worst_position, mut worst_frame, mut texels) = (0.0f64, 0.0f64, 0);
    for &((x, y), c) in blocks.iter().flatten() {
        let p = &positions[c];
        let top = column_layers[c];
        for k in 0..=max_layers {
            let layer = k.min(top);
            let check = |got: DVec3, want: glam::Vec4| (got - want.truncate().as_dvec3()).length();
            let z = 3 * k as u32;
            worst_position = worst_position.max(check(p[layer], expected.hair_mesh.get(x, y, z)));
            if k < max_layers {
                let (q0, q1) = if k < top {
                    control_points(p, k)
                } else {
                    (p[top], p[top])
                };
                worst_position = worst_position
                    .max(check(q0, expected.hair_mesh.get(x, y, z + 1)))
                    .max(check(q1, expected.hair_mesh.get(x, y, z + 2)));
            }
            let (u, v) = frames[layer][&c];
            worst_frame = worst_frame
                .max(check(u, expected.u.get(x, y, k as u32)))
                .max(check(v, expected.v.get(x, y, k as u32)));
            // w is the styling coordinate: the rest values stay.
            assert_eq!(rest.w.get(x, y, k as u32), expected.w.get(x, y, k as u32));
        }
        texels += 1;
    }
    assert!(texels > 1000);
    assert!(
        worst_position <= 1e-6 * size,
        "positions and control points off by {worst_position} for a {size} model"
    );
    // The bundle's uvs are f32 and the exporter's f64: on the smallest uv triangles that
    // moves a frame by up to about 2e-5 (0.001°); with the f64 uvs the two agree to f32
    // rounding (checked while writing this test).
    assert!(worst_frame <= 5e-5, "frames off by {worst_frame}");
    // And the motion is real: the moved textures differ from the rest ones.
    assert_ne!(expected.hair_mesh, rest.hair_mesh);
}
