use glam::DVec3;

use super::lapped::{DirectionField, LappedError, LappedParams, LappedSurface};
use super::lighting::{KajiyaKayLighting, banks_self_shadow};
use super::textures::{
    FIN_HEIGHT, FIN_WIDTH, FinTexture, FurTextureError, Layers, ShellParams, ShellTextures, over,
    shell_level,
};
use super::volume::{FurPreset, FurVolume, FurVolumeError, FurVolumeParams};
use crate::samples::sphere_body;

/// A small volume so the tests stay fast: a quarter of the preset's strands.
fn small(preset: FurPreset) -> FurVolume {
    let mut params = preset.params();
    params.strand_count /= 4;
    FurVolume::grow(&params).expect("preset parameters are valid")
}

fn small_shells(volume: &FurVolume) -> ShellTextures {
    ShellTextures::sample(
        volume,
        ShellParams {
            layer_count: 16,
            resolution: 64,
            opaque_skin: true,
        },
    )
    .expect("valid shell parameters")
}

#[test]
fn volumes_grow_deterministically_inside_their_box() {
    for preset in FurPreset::ALL {
        let params = preset.params();
        let a = FurVolume::grow(&params).expect("valid test input");
        let b = FurVolume::grow(&params).expect("valid test input");
        assert_eq!(a, b, "{}: same seed, same strands", preset.name());
        assert_eq!(a.strands.len(), params.strand_count as usize);
        for strand in &a.strands {
            assert_eq!(strand.points.len(), params.steps as usize + 1);
            let root = strand.points[0];
            assert_eq!(root.z, 0.0);
            assert!((0.0..params.tile_width_m).contains(&root.x));
            assert!((0.0..params.tile_width_m).contains(&root.y));
            for p in &strand.points {
                assert!(p.is_finite());
                assert!(
                    (0.0..=params.length_m).contains(&p.z),
                    "{}: z {}",
                    preset.name(),
                    p.z
                );
            }
            // Strands rise: the tip is well above the root.
            let tip = *strand.points.last().expect("a strand has points");
            assert!(
                tip.z > 0.3 * params.length_m,
                "{}: tip at {}",
                preset.name(),
                tip.z
            );
        }
    }
}

/// Mean distance of a strand's points from the straight line root → tip.
fn mean_bend(volume: &FurVolume) -> f64 {
    let mut sum = 0.0;
    let mut count = 0;
    for s in &volume.strands {
        let (a, b) = (s.points[0], *s.points.last().expect("a strand has points"));
        let axis = (b - a).normalize();
        for p in &s.points {
            let d = *p - a;
            sum += (d - axis * d.dot(axis)).length();
            count += 1;
        }
    }
    sum / count as f64
}

#[test]
fn curly_fur_bends_more_than_straight_fur() {
    let straight = mean_bend(&small(FurPreset::Straight));
    let curly = mean_bend(&small(FurPreset::Curly));
    assert!(
        curly > 2.0 * straight,
        "curly {curly} vs straight {straight}"
    );
}

#[test]
fn bad_volume_parameters_are_named() {
    let base = FurPreset::Straight.params();
    let cases = [
        FurVolumeParams {
            tile_width_m: f64::NAN,
            ..base
        },
        FurVolumeParams {
            strand_count: u32::MAX,
            ..base
        },
        FurVolumeParams {
            strand_count: 0,
            ..base
        },
        FurVolumeParams {
            steps: 1 << 30,
            ..base
        },
        FurVolumeParams {
            strand_radius_m: 1.0,
            ..base
        },
        FurVolumeParams {
            slant: f64::INFINITY,
            ..base
        },
    ];
    let names = [
        "tile_width_m",
        "strand_count",
        "strand_count",
        "steps",
        "strand_radius_m",
        "slant",
    ];
    for (params, name) in cases.iter().zip(names) {
        match FurVolume::grow(params) {
            Err(FurVolumeError::OutOfRange { name: got, .. }) => assert_eq!(got, name),
            other => panic!("{name}: expected a named error, got {other:?}"),
        }
    }
}

#[test]
fn shells_cover_more_where_fur_is_denser_and_thin_out_toward_the_tips() {
    let sparse = small_shells(&small(FurPreset::Sparse));
    let dense = small_shells(&small(FurPreset::Dense));
    for shells in [&sparse, &dense] {
        let level = &shells.levels[0];
        assert_eq!(level.layer_count(), 16);
        assert!(
            level.layer(0).iter().all(|t| t[3] == 255),
            "the skin layer is opaque"
        );
        // Strands vary in length, so fewer reach the outer shells.
        let inner = level.mean_alpha(2);
        let outer = level.mean_alpha(15);
        assert!(inner > 0.02, "inner shell coverage {inner}");
        assert!(outer < inner, "outer {outer} vs inner {inner}");
    }
    for layer in 1..16 {
        assert!(
            dense.levels[0].mean_alpha(layer) > sparse.levels[0].mean_alpha(layer),
            "layer {layer}: dense {} vs sparse {}",
            dense.levels[0].mean_alpha(layer),
            sparse.levels[0].mean_alpha(layer)
        );
    }
}

#[test]
fn shells_wrap_around_the_tile() {
    // One strand standing on the tile's corner shows in all four corners of each shell.
    let params = FurVolumeParams {
        strand_count: 1,
        wander: 0.0,
        slant: 0.0,
        length_variation: 0.0,
        ..FurPreset::Straight.params()
    };
    let mut volume = FurVolume::grow(&params).expect("valid test input");
    for p in &mut volume.strands[0].points {
        p.x = 0.0;
        p.y = 0.0;
    }
    let shells = small_shells(&volume);
    let layer = shells.levels[0].layer(8);
    let side = 64;
    let at = |x: usize, y: usize| layer[y * side + x][3];
    for (x, y) in [(0, 0), (side - 1, 0), (0, side - 1), (side - 1, side - 1)] {
        assert!(at(x, y) > 0, "corner ({x}, {y}) is empty");
    }
    assert_eq!(
        at(side / 2, side / 2),
        0,
        "the middle is far from the strand"
    );
}

#[test]
fn slanted_fur_stores_its_lean_in_the_direction_layers() {
    let params = FurVolumeParams {
        slant: 0.8,
        wander: 0.1,
        strand_count: 300,
        ..FurPreset::Straight.params()
    };
    let shells = small_shells(&FurVolume::grow(&params).expect("valid test input"));
    let (mut lean_x, mut lean_y) = (0.0, 0.0);
    for (colour, direction) in shells.levels[0]
        .layer(6)
        .iter()
        .zip(shells.directions.layer(6))
    {
        let w = colour[3] as f64;
        lean_x += w * (direction[0] as f64 / 255.0 * 2.0 - 1.0);
        lean_y += w * (direction[1] as f64 / 255.0 * 2.0 - 1.0);
    }
    assert!(
        lean_x > 0.0 && lean_x > 4.0 * lean_y.abs(),
        "lean {lean_x} {lean_y}"
    );
}

#[test]
fn bad_shell_parameters_are_named() {
    let volume = small(FurPreset::Sparse);
    for (params, expected) in [
        (
            ShellParams {
                layer_count: 12,
                resolution: 64,
                opaque_skin: true,
            },
            FurTextureError::LayerCount(12),
        ),
        (
            ShellParams {
                layer_count: 1 << 20,
                resolution: 64,
                opaque_skin: true,
            },
            FurTextureError::LayerCount(1 << 20),
        ),
        (
            ShellParams {
                layer_count: 16,
                resolution: u32::MAX,
                opaque_skin: true,
            },
            FurTextureError::Resolution(u32::MAX),
        ),
    ] {
        assert_eq!(ShellTextures::sample(&volume, params), Err(expected));
    }
}

/// Transmittance through the shells of a level from `first` out, at each texel: compositing
/// pairs must keep it (up to 8-bit rounding), or the fur would thin or thicken as it recedes.
fn transmittance(level: &Layers, first: usize) -> Vec<f64> {
    let size = (level.resolution * level.resolution) as usize;
    (0..size)
        .map(|i| {
            (first..level.layer_count())
                .map(|l| 1.0 - level.layer(l)[i][3] as f64 / 255.0)
                .product::<f64>()
        })
        .collect()
}

#[test]
fn shell_levels_halve_and_keep_the_fur_opacity() {
    let shells = small_shells(&small(FurPreset::Straight));
    let counts: Vec<usize> = shells.levels.iter().map(Layers::layer_count).collect();
    assert_eq!(counts, [16, 8, 4, 2, 1]);
    // Level 1's shell k holds fine shells 2k and 2k+1; past the skin pair, their combined
    // transmittance is what level 0's pair lets through.
    let fine = &shells.levels[0];
    let coarse = &shells.levels[1];
    let size = (fine.resolution * fine.resolution) as usize;
    let mut worst: f64 = 0.0;
    for k in 1..8 {
        for i in 0..size {
            let pair = (1.0 - fine.layer(2 * k)[i][3] as f64 / 255.0)
                * (1.0 - fine.layer(2 * k + 1)[i][3] as f64 / 255.0);
            let merged = 1.0 - coarse.layer(k)[i][3] as f64 / 255.0;
            worst = worst.max((pair - merged).abs());
        }
    }
    assert!(worst <= 1.0 / 255.0, "transmittance error {worst}");
    // Through every shell above the skin pair (which level 1 folds into the skin), the
    // product is kept to rounding.
    let t0 = transmittance(fine, 2);
    let t1 = transmittance(coarse, 1);
    let mean_error = t0.iter().zip(&t1).map(|(a, b)| (a - b).abs()).sum::<f64>() / t0.len() as f64;
    assert!(mean_error < 0.01, "mean transmittance drift {mean_error}");
    assert!(shells.levels[4].layer(0).iter().all(|t| t[3] == 255));
}

#[test]
fn over_is_the_porter_duff_operator() {
    let clear = [0, 0, 0, 0];
    let texel = [200, 100, 50, 128];
    assert_eq!(over(clear, texel), texel);
    assert_eq!(over(texel, clear), texel);
    assert_eq!(over([10, 20, 30, 255], texel), [10, 20, 30, 255]);
    let both = over([255, 255, 255, 128], [0, 0, 0, 128]);
    assert_eq!(both[3], 192, "α = ½ + ½·½");
    assert!((both[0] as i32 - 170).abs() <= 1, "colour {both:?}");
}

#[test]
fn shell_level_follows_distance_smoothly_and_stays_in_range() {
    assert_eq!(shell_level(64.0, 16), 0.0, "near: every shell");
    assert_eq!(shell_level(0.5, 16), 4.0, "sub-pixel fur: one shell");
    assert_eq!(shell_level(0.0, 16), 4.0);
    assert_eq!(shell_level(f64::NAN, 16), 4.0);
    assert!((shell_level(4.0, 16) - 2.0).abs() < 1e-12);
    // Continuous: no step larger than the change in distance explains.
    let mut last = shell_level(32.0, 16);
    let mut px = 32.0;
    while px > 0.5 {
        px *= 0.99;
        let level = shell_level(px, 16);
        assert!(
            level >= last && level - last < 0.02,
            "{px}: {last} → {level}"
        );
        last = level;
    }
}

#[test]
fn fin_coverage_follows_the_slab_and_thins_toward_the_tips() {
    let volume = small(FurPreset::Straight);
    let thin = FinTexture::sample(&volume, 0.0005, FIN_WIDTH / 8, FIN_HEIGHT / 2);
    let thick = FinTexture::sample(&volume, 0.002, FIN_WIDTH / 8, FIN_HEIGHT / 2);
    let mean = |fin: &FinTexture| {
        (0..fin.height as usize)
            .map(|r| fin.row_alpha(r))
            .sum::<f64>()
            / fin.height as f64
    };
    assert!(
        mean(&thick) > 1.5 * mean(&thin),
        "{} vs {}",
        mean(&thick),
        mean(&thin)
    );
    let rows = thick.height as usize;
    assert!(thick.row_alpha(rows - 1) < thick.row_alpha(rows / 4));
    let hostile = FinTexture::sample(&volume, f64::NAN, u32::MAX, u32::MAX);
    assert!(hostile.width <= 4096 && hostile.height <= 1024);
}

#[test]
fn the_seeds_texture_set_is_its_stated_1_6_mb() {
    // 16 layers of 128² and one 512 × 64 fin, 32-bit texels with mip maps: 1.6 MB (§4).
    let volume = small(FurPreset::Sparse);
    let shells = ShellTextures::sample(&volume, ShellParams::default()).expect("valid test input");
    let fin = FinTexture::sample(&volume, 0.001, FIN_WIDTH, FIN_HEIGHT);
    let seed = shells.seed_memory_bytes(true) + fin.memory_bytes(true);
    assert!((1_500_000..1_700_000).contains(&seed), "{seed} bytes");
    // Ours adds the coarser levels and the direction layers.
    assert!(shells.memory_bytes(true) > seed);
}

#[test]
fn kajiya_kay_table_matches_the_formula_and_stays_finite() {
    let model = KajiyaKayLighting {
        ambient: [0.05, 0.04, 0.03],
        diffuse: [0.5, 0.4, 0.3],
        specular: [0.3, 0.3, 0.3],
        diffuse_power: 2.0,
        specular_power: 40.0,
    };
    // u = 0 (light across the hair): full diffuse; v = 0 (half vector across): full specular.
    let peak = model.evaluate(0.0, 0.0);
    assert!((peak[0] - 0.85).abs() < 1e-6);
    let along = model.evaluate(1.0, 1.0);
    assert!(
        (along[0] - 0.05).abs() < 1e-6,
        "light along the hair: ambient only"
    );
    assert!(model.evaluate(f32::NAN, 2.0).iter().all(|c| c.is_finite()));
    let table = model.table();
    assert_eq!(table.len(), 32 * 32);
    assert!(table.iter().all(|texel| (0..3).all(|c| texel[c].is_finite()
        && texel[c] >= model.ambient[c]
        && texel[c] <= model.ambient[c] + model.diffuse[c] + model.specular[c])));
    assert!(banks_self_shadow(1.0, 0.3, 16, 0.1) == 1.0);
    assert!(banks_self_shadow(0.0, 0.3, 16, 0.1) == 0.1);
    assert!(banks_self_shadow(0.5, 0.1, 16, 0.0) < banks_self_shadow(0.75, 0.1, 16, 0.0));
}

fn sphere(rings: u32, segments: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let body = sphere_body(0.1, rings, segments);
    (
        body.positions
            .iter()
            .map(|p| glam::Vec3::from_array(*p).as_dvec3())
            .collect(),
        body.triangles,
    )
}

fn params(direction: DirectionField) -> LappedParams {
    LappedParams {
        tile_width_m: 0.01,
        patch_radius_m: 0.03,
        direction,
        seed: 5,
    }
}

/// Faces of each patch, connected through shared edges: a patch is one piece of surface.
fn assert_patches_cover_once_and_connect(surface: &LappedSurface, triangles: &[[u32; 3]]) {
    let n = surface.patch_count as usize;
    assert!(n >= 1);
    let mut faces_of = vec![Vec::new(); n];
    for (f, &p) in surface.face_patch.iter().enumerate() {
        assert!((p as usize) < n, "face {f} has no patch");
        faces_of[p as usize].push(f);
    }
    for (p, faces) in faces_of.iter().enumerate() {
        assert!(!faces.is_empty(), "patch {p} is empty");
        let mut reached = vec![faces[0]];
        let mut frontier = vec![faces[0]];
        while let Some(f) = frontier.pop() {
            for &g in faces {
                if reached.contains(&g) {
                    continue;
                }
                let shared = triangles[f]
                    .iter()
                    .filter(|v| triangles[g].contains(v))
                    .count();
                if shared >= 2 {
                    reached.push(g);
                    frontier.push(g);
                }
            }
        }
        assert_eq!(reached.len(), faces.len(), "patch {p} is in pieces");
    }
    assert!(
        surface
            .face_uvs
            .iter()
            .flatten()
            .flatten()
            .all(|c| c.is_finite())
    );
}

/// The gradient of `u` and `v` over a face, in world space.
fn uv_gradients(p: [DVec3; 3], uv: [[f32; 2]; 3]) -> Option<(DVec3, DVec3, DVec3)> {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let n = e1.cross(e2);
    if n.length() < 1e-12 {
        return None;
    }
    let du1 = (uv[1][0] - uv[0][0]) as f64;
    let du2 = (uv[2][0] - uv[0][0]) as f64;
    let dv1 = (uv[1][1] - uv[0][1]) as f64;
    let dv2 = (uv[2][1] - uv[0][1]) as f64;
    let grad = |d1: f64, d2: f64| (e2.cross(n) * d1 + n.cross(e1) * d2) / n.length_squared();
    Some((grad(du1, du2), grad(dv1, dv2), n.normalize()))
}

#[test]
fn patches_cover_a_sphere_once_following_the_direction_field() {
    let (positions, triangles) = sphere(24, 48);
    let down = DVec3::new(0.0, -1.0, 0.3);
    let surface = LappedSurface::build(
        &positions,
        &triangles,
        &params(DirectionField::Global(down)),
    )
    .expect("valid test input");
    assert_patches_cover_once_and_connect(&surface, &triangles);
    assert!(surface.patch_count > 4, "the sphere needs many patches");
    assert!(
        surface.patch_count < triangles.len() as u32 / 4,
        "patches grow beyond single faces: {}",
        surface.patch_count
    );
    let (mut aligned, mut judged) = (0, 0);
    for (f, t) in triangles.iter().enumerate() {
        let p = t.map(|v| positions[v as usize]);
        let Some((grad_u, grad_v, normal)) = uv_gradients(p, surface.face_uvs[f]) else {
            continue;
        };
        // The map keeps the face's orientation (no folds).
        assert!(grad_u.cross(grad_v).dot(normal) > 0.0, "face {f} is folded");
        let field = (down - normal * down.dot(normal)).try_normalize();
        if let Some(field) = field
            && down.normalize().dot(normal).abs() < 0.9
        {
            judged += 1;
            if grad_u.normalize().dot(field) > 20f64.to_radians().cos() {
                aligned += 1;
            }
        }
    }
    assert!(
        aligned as f64 > 0.9 * judged as f64,
        "{aligned} of {judged} faces run with the field within 20°"
    );
}

#[test]
fn isotropic_patches_cover_and_fins_span_every_edge() {
    let (positions, triangles) = sphere(12, 24);
    let surface = LappedSurface::build(&positions, &triangles, &params(DirectionField::Isotropic))
        .expect("valid test input");
    assert_patches_cover_once_and_connect(&surface, &triangles);
    let mut edges = std::collections::BTreeSet::new();
    for t in &triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                edges.insert((a.min(b), a.max(b)));
            }
        }
    }
    assert_eq!(surface.fin_edges.len(), edges.len());
    for e in &surface.fin_edges {
        let length = positions[e.vertices[0] as usize].distance(positions[e.vertices[1] as usize]);
        assert!((e.u_length as f64 - length / 0.01).abs() < 1e-4);
        assert!((0.0..1.0).contains(&e.u_start));
    }
}

#[test]
fn degenerate_meshes_are_covered_with_finite_maps() {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    // One triangle.
    let single = LappedSurface::build(
        &[p(0.0, 0.0, 0.0), p(0.1, 0.0, 0.0), p(0.0, 0.1, 0.0)],
        &[[0, 1, 2]],
        &params(DirectionField::Global(DVec3::X)),
    )
    .expect("valid test input");
    assert_eq!(single.patch_count, 1);
    // A zero-area face and a repeated index among real faces, and a non-manifold edge
    // (three faces on edge 0–1).
    let positions = [
        p(0.0, 0.0, 0.0),
        p(0.02, 0.0, 0.0),
        p(0.0, 0.02, 0.0),
        p(0.0, -0.02, 0.0),
        p(0.01, 0.0, 0.02),
        p(0.01, 0.0, 0.0),
    ];
    let triangles = [[0, 1, 2], [1, 0, 3], [0, 1, 4], [0, 5, 1], [2, 2, 1]];
    let surface = LappedSurface::build(
        &positions,
        &triangles,
        &params(DirectionField::Global(DVec3::Y)),
    )
    .expect("valid test input");
    assert_eq!(surface.face_patch.len(), triangles.len());
    assert!(surface.face_patch.iter().all(|&p| p < surface.patch_count));
    assert!(
        surface
            .face_uvs
            .iter()
            .flatten()
            .flatten()
            .all(|c| c.is_finite())
    );
    assert!(surface.vertex_normals.iter().all(|n| n.is_finite()));
    // The sphere's poles are rings of coincident vertices: zero-area faces all around.
    let (positions, triangles) = sphere(6, 8);
    let surface = LappedSurface::build(&positions, &triangles, &params(DirectionField::Isotropic))
        .expect("valid test input");
    assert!(surface.face_patch.iter().all(|&p| p < surface.patch_count));
}

#[test]
fn meshes_that_cannot_be_covered_get_named_errors() {
    let p = DVec3::new;
    let tri = [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.0), p(0.0, 1.0, 0.0)];
    let iso = params(DirectionField::Isotropic);
    assert_eq!(
        LappedSurface::build(&tri, &[], &iso),
        Err(LappedError::NoTriangles)
    );
    assert_eq!(
        LappedSurface::build(&[tri[0]; 3], &[[0, 1, 2]], &iso),
        Err(LappedError::NoArea)
    );
    assert_eq!(
        LappedSurface::build(&[tri[0], tri[1], p(f64::NAN, 0.0, 0.0)], &[[0, 1, 2]], &iso),
        Err(LappedError::NonFinitePosition { vertex: 2 })
    );
    assert_eq!(
        LappedSurface::build(&tri, &[[0, 1, 7]], &iso),
        Err(LappedError::IndexOutOfRange {
            triangle: 0,
            index: 7,
            count: 3
        })
    );
    assert_eq!(
        LappedSurface::build(
            &tri,
            &[[0, 1, 2]],
            &params(DirectionField::PerVertex(vec![DVec3::X]))
        ),
        Err(LappedError::DirectionCount { given: 1, count: 3 })
    );
    let bad_tile = LappedParams {
        tile_width_m: -1.0,
        ..iso.clone()
    };
    assert!(matches!(
        LappedSurface::build(&tri, &[[0, 1, 2]], &bad_tile),
        Err(LappedError::BadParameter {
            name: "tile_width_m",
            ..
        })
    ));
}

#[test]
fn the_fur_base_is_the_hair_meshs_root_faces_and_columns() {
    use super::base::{FUR_COLUMN_POINTS, FurBase, FurGeometry};
    use crate::runtime::textures::{Precision, RuntimeTextures};
    use crate::samples::{grid_scalp, straight_layers};
    let scalp = grid_scalp(4, 3, |s, t| DVec3::new(s * 0.04, t * 0.03, 0.0));
    let mut mesh = straight_layers(scalp, 2, DVec3::new(0.0, 0.0, 0.005));
    mesh.bundles[5].removed = true;
    let base = FurBase::from_textures(&RuntimeTextures::build(&mesh, Precision::F32));
    assert_eq!(
        base.triangles.len(),
        2 * 11,
        "quads split in two, the removed one left out"
    );
    assert_eq!(
        base.columns.len(),
        20,
        "corners shared between bundles are one vertex"
    );
    assert!((base.area_m2() - 11.0 * 0.01 * 0.01).abs() < 1e-9);
    assert!((base.mean_length_m() - 0.01).abs() < 1e-6);
    for column in &base.columns {
        for k in 0..FUR_COLUMN_POINTS {
            let expected = column[0].z + 0.01 * k as f32 / (FUR_COLUMN_POINTS - 1) as f32;
            assert!(
                (column[k].z - expected).abs() < 1e-6,
                "even arc-length steps"
            );
        }
    }
    let geometry = FurGeometry::build(&base, 0.01, 0.03, 1).expect("valid test input");
    assert_eq!(geometry.corners.len(), 3 * base.triangles.len());
    assert!(
        geometry
            .corners
            .iter()
            .all(|c| (c.vertex as usize) < geometry.columns.len())
    );
    // Normals point along the columns here (+z).
    assert!(geometry.columns.iter().all(|c| c.normal[2].abs() > 0.99));
}

#[test]
fn shell_points_follow_the_column_and_fins_fade_toward_facing_the_eye() {
    use super::base::{fin_fade, shell_point};
    use glam::Vec3;
    let column = [
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(1.0, 1.0, 1.0),
    ];
    assert_eq!(shell_point(&column, 0.0), column[0]);
    assert_eq!(shell_point(&column, 1.0), column[3]);
    assert!((shell_point(&column, 0.5) - Vec3::new(0.5, 0.0, 1.0)).length() < 1e-6);
    assert_eq!(
        shell_point(&column, f32::NAN),
        column[0],
        "NaN reads as the root"
    );
    assert_eq!(shell_point(&column, 7.0), column[3]);
    // Seed 002 §2.3: max(0, 2|p| − 1).
    let normal = Vec3::X;
    assert_eq!(
        fin_fade(normal, Vec3::X),
        1.0,
        "fin faces the eye: the silhouette"
    );
    assert_eq!(fin_fade(normal, -Vec3::X), 1.0);
    assert_eq!(fin_fade(normal, Vec3::Y), 0.0, "seen edge-on: gone");
    let at_60 = fin_fade(normal, Vec3::new(0.5, 0.75f32.sqrt(), 0.0));
    assert!(at_60.abs() < 1e-6, "|p| = ½ is where fins start");
    assert_eq!(fin_fade(Vec3::ZERO, Vec3::X), 0.0);
}
