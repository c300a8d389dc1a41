//! Numerically hard inputs through the whole CPU pipeline: interior placement, frames,
//! curves, styling, strand generation, runtime textures and the texture-path mirror, LOD and
//! tangents. Each case asserts finite output and a bound on it; a proptest over random meshes
//! and parameters counts non-finite outputs (there must be none).

use glam::{DVec2, DVec3};
use hairloom_core::geometry::curve::CurveDefinition;
use hairloom_core::geometry::frames::layer_frames;
use hairloom_core::geometry::interior::place_interior;
use hairloom_core::model::styling::{
    Clump, Curl, Frizz, LengthVariation, Noise, StylingParams, Twist, Wave,
};
use hairloom_core::runtime::strand_gen::{Filtering, StrandGen};
use hairloom_core::runtime::textures::{Precision, RuntimeTextures};
use hairloom_core::strands::lod::{
    morphed_tangents, strand_count, tangents, thickness_factor, vertex_lod,
};
use hairloom_core::strands::reference::{StrandOptions, generate};
use hairloom_core::{Document, HairMesh};
use hairloom_tests::grid_mesh;
use proptest::prelude::*;

/// Every op on (the shared set) with a tight, fast curl: the hardest case for the frames.
fn every_op() -> StylingParams {
    StylingParams {
        curl: Curl {
            radius_m: 0.01,
            turns_per_m: 30.0,
            ..Curl::default()
        },
        ..StylingParams::every_op()
    }
}

/// Runs the whole CPU pipeline and returns the largest distance of any output point from
/// the mesh's bounding box, after checking every output is finite.
fn run_pipeline(mesh: HairMesh, styling: StylingParams) -> f64 {
    let mut document = Document::new("hard", mesh);
    document.styling.global = styling.clone();
    place_interior(&mut document.hair_mesh, None);
    document.hair_mesh.update_w();
    for layer in 0..=document.hair_mesh.max_layers() {
        for frame in layer_frames(&document.hair_mesh, layer)
            .into_iter()
            .flatten()
        {
            assert!(
                frame.u.is_finite() && frame.v.is_finite() && frame.w.is_finite(),
                "frame {frame:?}"
            );
        }
    }
    let (lo, hi) = document.hair_mesh.bounds().expect("non-empty mesh");
    let mut worst: f64 = 0.0;
    for definition in [
        CurveDefinition::ColumnBlend,
        CurveDefinition::PerStrandCentripetal,
    ] {
        let options = StrandOptions {
            strands_per_bundle: 6,
            vertices_log2: 4,
            definition,
            ..StrandOptions::default()
        };
        for strand in generate(&document, &options) {
            for p in &strand.points {
                assert!(
                    p.is_finite(),
                    "strand point {p} in bundle {}",
                    strand.bundle
                );
                let outside = (lo - *p).max(*p - hi).max(DVec3::ZERO).length();
                worst = worst.max(outside);
            }
            for t in tangents(&strand.points)
                .iter()
                .chain(&morphed_tangents(&strand.points, 0.5))
            {
                assert!(
                    t.is_finite() && (t.length() - 1.0).abs() < 1e-9,
                    "tangent {t}"
                );
            }
        }
    }
    for precision in [Precision::F32, Precision::F16] {
        let textures = RuntimeTextures::build(&document.hair_mesh, precision);
        for filtering in [Filtering::Exact, Filtering::Hardware8Bit] {
            let path = StrandGen {
                textures: &textures,
                filtering,
            };
            for block in 0..textures.atlas.blocks.len() {
                for tau in [0.0f32, 0.3, 0.5, 1.0, 1.7, 2.0, 99.0] {
                    let p = path.position(block, 0.25, 0.75, tau);
                    assert!(
                        p.is_finite(),
                        "texture path {p} ({precision:?}, {filtering:?})"
                    );
                }
            }
        }
    }
    worst
}

/// Styling can push strands past the mesh by at most the sum of its amplitudes plus the
/// rotation of twist (bounded by the mesh size).
fn styling_reach(params: &StylingParams, mesh_size: f64) -> f64 {
    params.curl.radius_m * 1.5
        + params.noise.amplitude_m * 2.0
        + params.clump.strength * params.clump.radius_m * 1.5
        + params.frizz.amplitude_m
        + params.wave.amplitude_m
        + if params.twist.turns_per_m != 0.0 {
            mesh_size
        } else {
            0.0
        }
}

fn hair_grid() -> HairMesh {
    // 2 cm quads, 3 layers of 2 cm.
    let mut mesh = grid_mesh(3, 3, 3, 1.0);
    for column in &mut mesh.columns {
        for p in &mut column.positions {
            *p *= 0.02;
        }
    }
    mesh.update_w();
    mesh
}

fn size(mesh: &HairMesh) -> f64 {
    mesh.size()
}

fn check(mesh: HairMesh, styling: StylingParams) {
    let reach = styling_reach(&styling, size(&mesh));
    let worst = run_pipeline(mesh, styling);
    // Centripetal curves overshoot their control polygon a little: allow 25% of the size.
    assert!(worst.is_finite());
    assert!(
        worst <= reach + 0.25 * 0.12,
        "outside by {worst} (reach {reach})"
    );
}

#[test]
fn coincident_layer_vertices() {
    let mut mesh = hair_grid();
    for column in &mut mesh.columns {
        let p = column.positions[1];
        column.positions[2] = p;
        column.positions[3] = p;
    }
    mesh.update_w();
    check(mesh, every_op());
}

#[test]
fn zero_length_segments_everywhere() {
    let mut mesh = hair_grid();
    for column in &mut mesh.columns {
        let root = column.positions[0];
        column.positions.iter_mut().for_each(|p| *p = root);
    }
    mesh.update_w();
    check(mesh, every_op());
}

#[test]
fn fold_back_by_180_degrees() {
    let mut mesh = hair_grid();
    for column in &mut mesh.columns {
        let (a, b) = (column.positions[0], column.positions[1]);
        column.positions[2] = a; // back down to the root
        column.positions[3] = b; // and up again
    }
    mesh.update_w();
    check(mesh, every_op());
}

#[test]
fn zero_area_and_zero_uv_faces() {
    let mut mesh = hair_grid();
    // Collapse bundle 4's root face to a line and every uv of bundle 0 to a point.
    let v = mesh.bundles[4].vertices.clone();
    let anchor = mesh.columns[v[0] as usize].positions[0];
    for &c in &v[1..3] {
        mesh.columns[c as usize].positions[0] = anchor + DVec3::X * 1e-18;
    }
    mesh.bundles[0].uvs = vec![DVec2::splat(0.3); 4];
    mesh.update_w();
    check(mesh, every_op());
}

#[test]
fn parallel_u_and_v() {
    let mut mesh = hair_grid();
    for bundle in &mut mesh.bundles {
        for uv in &mut bundle.uvs {
            uv.y = uv.x; // v grows exactly like u: û ∥ v̂
        }
    }
    check(mesh, every_op());
}

#[test]
fn curl_frequency_far_above_the_vertex_count() {
    let params = StylingParams {
        curl: Curl {
            radius_m: 0.005,
            turns_per_m: 1e7,
            ..Curl::default()
        },
        noise: Noise {
            amplitude_m: 0.002,
            frequency_per_m: 1e9,
            octaves: 8,
        },
        ..StylingParams::default()
    };
    check(hair_grid(), params);
}

#[test]
fn tiny_huge_and_far_away_models() {
    for (scale, offset) in [(1e-4, 0.0), (1e4, 0.0), (1.0, 1e5)] {
        let mut mesh = hair_grid();
        for column in &mut mesh.columns {
            for p in &mut column.positions {
                *p = *p * scale + DVec3::splat(offset);
            }
        }
        mesh.update_w();
        let worst = run_pipeline(mesh.clone(), every_op());
        let reach = styling_reach(&every_op(), size(&mesh));
        assert!(
            worst <= reach + 0.25 * size(&mesh),
            "scale {scale}, offset {offset}: {worst}"
        );
    }
}

#[test]
fn vanishing_detail_and_no_transition_window() {
    for level in [0.0, 1e-300, 1e-9, 0.5, 1.0] {
        for lambda in [0.0, 0.5, 1.0] {
            let lod = vertex_lod(level, 5, lambda);
            assert!(lod.gamma.is_finite() && (0.0..=1.0).contains(&lod.gamma));
            assert!(lod.vertex_count() >= 2 && lod.vertex_count() <= 33);
        }
        assert!(strand_count(level, 64, 0.5) <= 64);
        let thickness = thickness_factor(level, 64);
        assert!(thickness.is_finite() && (1.0..=64.0).contains(&thickness));
    }
}

fn random_mesh_strategy() -> impl Strategy<Value = (HairMesh, StylingParams)> {
    (
        1usize..4,
        1usize..4,
        1u32..4,
        prop::collection::vec(-1.0f64..1.0, 64 * 3),
        prop::collection::vec(-2.0f64..2.0, 16 * 2),
        0.0f64..0.02,
        0.0f64..200.0,
        0.0f64..1.0,
    )
        .prop_map(
            |(nx, ny, layers, jitter, uv_jitter, amplitude, frequency, fraction)| {
                let mut mesh = grid_mesh(nx, ny, layers, 1.0);
                let mut i = 0;
                for column in &mut mesh.columns {
                    for p in column.positions.iter_mut().skip(1) {
                        // Large random displacements: folds, coincidences, inversions.
                        *p += DVec3::new(
                            jitter[i % jitter.len()],
                            jitter[(i + 1) % jitter.len()],
                            jitter[(i + 2) % jitter.len()],
                        ) * 1.5;
                        i += 3;
                    }
                }
                for (b, bundle) in mesh.bundles.iter_mut().enumerate() {
                    for (c, uv) in bundle.uvs.iter_mut().enumerate() {
                        let k = (b * 4 + c) % 16;
                        *uv += DVec2::new(uv_jitter[2 * k], uv_jitter[2 * k + 1]) * 0.5;
                    }
                }
                mesh.update_w();
                let params = StylingParams {
                    curl: Curl {
                        radius_m: amplitude,
                        turns_per_m: frequency,
                        ..Curl::default()
                    },
                    twist: Twist {
                        turns_per_m: frequency / 50.0,
                    },
                    noise: Noise {
                        amplitude_m: amplitude,
                        frequency_per_m: frequency,
                        octaves: 3,
                    },
                    clump: Clump {
                        strength: fraction,
                        ..Clump::default()
                    },
                    frizz: Frizz {
                        amplitude_m: amplitude,
                        fraction,
                        ..Frizz::default()
                    },
                    wave: Wave {
                        amplitude_m: amplitude,
                        frequency_per_m: frequency,
                        ..Wave::default()
                    },
                    length: LengthVariation { fraction },
                    ..StylingParams::default()
                };
                (mesh, params)
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Random meshes (with folds, coincident and inverted layers, random uv) and random
    /// styling: the pipeline produces no non-finite value (`run_pipeline` asserts each one).
    #[test]
    fn random_meshes_and_parameters_give_finite_output((mesh, params) in random_mesh_strategy()) {
        let worst = run_pipeline(mesh, params);
        prop_assert!(worst.is_finite());
    }
}
