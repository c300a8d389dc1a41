//! GPU strand generation against its CPU mirror (`TexturePath::position`) on the bundled
//! samples: exact filtering within 1e-5 × model size; hardware filtering within the bound the
//! CPU emulation of 8-bit weights documents. Runs on lavapipe in CI.

use hairloom_core::atlas::Atlas;
use hairloom_core::gpu_types::StrandRoot;
use hairloom_core::roots::{SampleDomain, progressive_samples};
use hairloom_core::runtime::{Filtering, Precision, RuntimeTextures, TexturePath};
use hairloom_render::device::GpuContext;
use hairloom_render::strand_gen::StrandGenRenderer;

fn context() -> Option<GpuContext> {
    match GpuContext::new_headless() {
        Ok(context) => Some(context),
        Err(error) if std::env::var("HAIRLOOM_REQUIRE_GPU").as_deref() != Ok("1") => {
            eprintln!("skipped: {error} (set HAIRLOOM_REQUIRE_GPU=1 to make this a failure)");
            None
        }
        Err(error) => panic!("{error}"),
    }
}

#[test]
fn gpu_positions_match_the_cpu_mirror() {
    let Some(context) = context() else { return };
    eprintln!(
        "adapter: {}",
        hairloom_render::device::describe(&context.adapter_info)
    );
    let renderer = StrandGenRenderer::new(&context);
    let samples_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/samples");
    for name in ["head_curly", "teapot_fur"] {
        let project = hairloom_core::project::load(&samples_dir.join(format!("{name}.hairloom")))
            .expect("sample");
        let mesh = &project.document.hair_mesh;
        let size = mesh.size() as f32;
        for precision in [Precision::F32, Precision::F16] {
            let textures = RuntimeTextures::build(mesh, precision);
            let hair_mesh = renderer.upload_hair_mesh(&context, &textures);
            let quad = progressive_samples(6, SampleDomain::Square, 5);
            let triangle = progressive_samples(6, SampleDomain::Triangle, 5);
            let mut roots = Vec::new();
            let mut expected_coords = Vec::new();
            for (index, block) in textures.atlas.blocks.iter().enumerate() {
                for sample in if Atlas::is_triangle(block) {
                    &triangle
                } else {
                    &quad
                } {
                    let (s, t) = Atlas::sample_block_coords(block, *sample);
                    roots.push(StrandRoot {
                        texel: [
                            block.origin[0] as f32 + 0.5 + s as f32,
                            block.origin[1] as f32 + 0.5 + t as f32,
                        ],
                        layers: block.layers,
                        _padding: 0,
                    });
                    expected_coords.push((index, s as f32, t as f32, block.layers));
                }
            }
            let vertex_count = 17u32;
            for filtering in [Filtering::Exact, Filtering::Hardware8Bit] {
                let positions = match renderer.generate_positions(
                    &context,
                    &textures,
                    &hair_mesh,
                    &roots,
                    vertex_count,
                    filtering,
                ) {
                    Ok(positions) => positions,
                    Err(error) => panic!("{name} {precision:?} {filtering:?}: {error}"),
                };
                assert_eq!(positions.len(), roots.len() * vertex_count as usize);
                let mirror = TexturePath {
                    textures: &textures,
                    filtering: Filtering::Exact,
                };
                let mut worst = 0.0f32;
                for (strand, &(index, s, t, layers)) in expected_coords.iter().enumerate() {
                    for k in 0..vertex_count {
                        let tau = layers.max(1) as f32 * k as f32 / (vertex_count - 1) as f32;
                        let expected = mirror.position(index, s, t, tau);
                        let got = positions[strand * vertex_count as usize + k as usize];
                        let got = glam::Vec3::new(got[0], got[1], got[2]);
                        assert!(got.is_finite(), "{name}: non-finite GPU position");
                        worst = worst.max(got.distance(expected));
                    }
                }
                let bound = match filtering {
                    Filtering::Exact => 1e-5 * size,
                    // Texture units quantise weights (8 bits on most GPUs): the CPU emulation
                    // of that moves these samples by up to ~2e-3 of the model size.
                    Filtering::Hardware8Bit => 2e-3 * size,
                };
                eprintln!(
                    "{name} {precision:?} {filtering:?}: max |GPU − CPU mirror| = {worst:.3e} (bound {bound:.3e})"
                );
                assert!(
                    worst <= bound,
                    "{name} {precision:?} {filtering:?}: {worst} > {bound}"
                );
            }
        }
    }
}

#[test]
fn generation_runs_in_batches_with_bounded_scratch() {
    use hairloom_render::strand_gen::BATCH_STRANDS;
    let Some(context) = context() else { return };
    let renderer = StrandGenRenderer::new(&context);
    let samples_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/samples");
    let project =
        hairloom_core::project::load(&samples_dir.join("teapot_fur.hairloom")).expect("sample");
    let textures = RuntimeTextures::build(&project.document.hair_mesh, Precision::F16);
    let texture = renderer.upload_hair_mesh(&context, &textures);
    let small = textures.strand_roots(4, 1);
    let large = textures.strand_roots(160, 1); // 288 bundles × 160 = 46,080 strands: 2 batches
    assert!(large.len() > BATCH_STRANDS);
    let vertex_count = 5;
    let a = renderer
        .time_generation(
            &context,
            &textures,
            &texture,
            &small,
            vertex_count,
            Filtering::Exact,
        )
        .expect("timing");
    let b = renderer
        .time_generation(
            &context,
            &textures,
            &texture,
            &large,
            vertex_count,
            Filtering::Exact,
        )
        .expect("timing");
    assert_eq!((a.batches, b.batches), (1, 2));
    // Scratch is one batch, whatever the strand count.
    assert_eq!(
        b.scratch_bytes,
        (BATCH_STRANDS as u64) * vertex_count as u64 * 16
    );
    assert!(b.scratch_bytes <= 64 << 20);
    if context
        .device
        .features()
        .contains(wgpu::Features::TIMESTAMP_QUERY)
    {
        let (ta, tb) = (a.gpu_ms.expect("timestamps"), b.gpu_ms.expect("timestamps"));
        assert!(
            ta.is_finite() && tb.is_finite() && ta >= 0.0 && tb > 0.0,
            "{ta} {tb}"
        );
    }
}
