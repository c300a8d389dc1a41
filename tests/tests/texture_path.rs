//! The texture-path mirror (what the GPU shader computes, from the five runtime textures
//! alone, in f32) against the f64 reference generator, strand for strand, on the bundled
//! samples with every styling op switched on.

use hairloom_core::geometry::curve::{FaceCoord, SegmentForm};
use hairloom_core::model::styling::Twist;
use hairloom_core::runtime::strand_gen::{Filtering, StrandGen};
use hairloom_core::runtime::textures::{Precision, RuntimeTextures};
use hairloom_core::strands::reference::{StrandContext, StrandOptions};
use hairloom_core::strands::roots::{SampleDomain, progressive_samples};
use hairloom_tests::sample_paths;

#[test]
fn styled_texture_path_matches_the_reference_generator() {
    for path in sample_paths() {
        let mut document = hairloom_core::io::project::load(&path)
            .expect("sample")
            .document;
        // Every op the sample has, plus twist (the one that needs the centre strand).
        document.styling.global.twist = Twist { turns_per_m: 4.0 };
        let textures = RuntimeTextures::build(&document.hair_mesh, Precision::F32);
        let context = StrandContext::new(&document);
        let options = StrandOptions {
            form: SegmentForm::TwoQuadratics,
            ..StrandOptions::default()
        };
        let quad = progressive_samples(8, SampleDomain::Square, 3);
        let triangle = progressive_samples(8, SampleDomain::Triangle, 3);
        let size = document.hair_mesh.size();
        for filtering in [Filtering::Exact, Filtering::Hardware8Bit] {
            let mirror = StrandGen {
                textures: &textures,
                filtering,
            };
            let mut worst: f64 = 0.0;
            for (index, block) in textures.atlas.blocks.iter().enumerate().step_by(7) {
                let bundle = &document.hair_mesh.bundles[block.bundle as usize];
                let params = document.styling.params_for(block.bundle);
                let samples = if bundle.vertices.len() == 3 {
                    &triangle
                } else {
                    &quad
                };
                for sample in samples {
                    let gpu_like = mirror.styled_strand_of_sample(index, *sample, 17, params);
                    let coord = FaceCoord {
                        s: sample.x,
                        t: sample.y,
                    };
                    let Some(reference) =
                        context.strand(block.bundle as usize, coord, 17, &options)
                    else {
                        // Not grown (the hairline op at the border): the mirror's strand
                        // lies at its root.
                        assert!(gpu_like.iter().all(|p| *p == gpu_like[0]));
                        continue;
                    };
                    for (a, b) in gpu_like.iter().zip(&reference.points) {
                        worst = worst.max(a.as_dvec3().distance(*b));
                    }
                }
            }
            let bound = match filtering {
                // f32 storage and arithmetic only.
                Filtering::Exact => 1e-5 * size,
                // 8-bit weights move positions by up to ~1/512 of a texel step and the frame
                // and w likewise; styling amplifies the w error through its frequencies.
                Filtering::Hardware8Bit => 2e-3 * size,
            };
            eprintln!(
                "{}: {filtering:?}: max {worst:.3e} m (bound {bound:.3e})",
                path.display()
            );
            assert!(
                worst < bound,
                "{}: {filtering:?}: {worst} ≥ {bound}",
                path.display()
            );
        }
    }
}

/// `export --curve runtime` writes what the runtime draws: each strand is the texture path's
/// strand of its bundle and manifest sample, in the GPU's order, and matches the reference
/// generator's two-quadratic strand at that root within the f32 bound above.
#[test]
fn runtime_strands_are_the_texture_path_strands_of_each_sample() {
    use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions, sample_rank};
    use hairloom_core::runtime::strand_gen::runtime_strands;
    let path = sample_paths()
        .into_iter()
        .find(|p| p.to_string_lossy().contains("head_short_straight"))
        .expect("the short sample");
    let document = hairloom_core::io::project::load(&path)
        .expect("sample")
        .document;
    let options = RuntimeOptions {
        strands_per_bundle: 3,
        ..RuntimeOptions::default()
    };
    let hair = RuntimeHair::from_document(&document, &options);
    let strands = runtime_strands(&hair, 9, Filtering::Exact);
    // Each block grows its share of 3 (`Bundle::density`); the hairline op's strands that
    // do not grow are kept, at their root, as the GPU draws them.
    let grown: usize = (0..hair.textures.atlas.blocks.len())
        .map(|block| hair.block_strand_count(block) as usize)
        .sum();
    assert_eq!(strands.len(), grown);
    assert!(
        strands.iter().any(|s| s.length_fraction == 0.0),
        "the sample's hairline is thinned"
    );
    let context = StrandContext::new(&document);
    let reference_options = StrandOptions {
        form: SegmentForm::TwoQuadratics,
        ..StrandOptions::default()
    };
    let bound = 1e-5 * document.hair_mesh.size();
    let mut compared = 0;
    for strand in strands.iter().step_by(5) {
        assert_eq!(strand.points.len(), 9);
        let rank = sample_rank(strand.root as usize % 3, 3) as f64;
        let reference = context.strand_ranked(
            strand.bundle as usize,
            strand.coord,
            rank,
            9,
            &reference_options,
        );
        let Some(reference) = reference else {
            // The hairline op does not grow it: the runtime draws it at its root.
            assert_eq!(strand.length_fraction, 0.0);
            assert!(strand.points.iter().all(|p| *p == strand.points[0]));
            continue;
        };
        compared += 1;
        for (a, b) in strand.points.iter().zip(&reference.points) {
            assert!(
                a.distance(*b) < bound,
                "bundle {}: {a} against {b}",
                strand.bundle
            );
        }
    }
    assert!(compared * 2 > strands.len() / 5, "most strands grow");
}
