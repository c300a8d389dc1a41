//! Generation by task and mesh shaders (`shaders/strand_mesh.wgsl`) against the vertex-shader
//! path, whose strips it must reproduce triangle for triangle: whole frames with every pass
//! that draws the hair (opacity-map and body shadows, depth pre-pass, lit pass, width-based
//! coverage), with LOD (several vertex counts, morphing, several strands per mesh group) and
//! with strands long enough to be cut into chunks (257 vertices).
//!
//! Mesh shaders are an optional adapter feature: where the device lacks it these tests say
//! they skipped, unless `HAIRLOOM_REQUIRE_MESH_SHADERS=1` (then they fail). `make test` runs
//! them once more on Mesa 25's lavapipe, which has `VK_EXT_mesh_shader` (see the Makefile's
//! `mesh-shader-test`).

mod common;

use glam::Vec3;
use hairloom_core::model::scene::{Coverage, SelfShadowing};
use hairloom_core::runtime::frame_plan::{FramePlan, LodSettings};
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_render::device::{GpuContext, describe, headless_for_test};
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, default_scene};
use hairloom_render::renderer::preview_body::GpuBody;
use hairloom_render::renderer::strand_gen::{
    GenerationPath, StrandGenError, StrandGenRenderer, mesh_shaders_available,
};

/// A device with mesh shaders, or `None` after saying why the test skipped.
fn mesh_context(test: &str) -> Option<GpuContext> {
    let context = headless_for_test(test)?;
    if mesh_shaders_available(&context.device) {
        return Some(context);
    }
    let why = format!(
        "{} has no mesh shaders (EXPERIMENTAL_MESH_SHADER)",
        describe(&context.adapter_info)
    );
    assert!(
        std::env::var("HAIRLOOM_REQUIRE_MESH_SHADERS").as_deref() != Ok("1"),
        "{test}: {why} (HAIRLOOM_REQUIRE_MESH_SHADERS=1)"
    );
    eprintln!("skipped: {test}: {why}");
    None
}

/// The same frame drawn by each of `paths`, as RGBA8 pictures, and its frame plan.
fn frames(
    context: &GpuContext,
    sample: &str,
    strands_per_bundle: u32,
    vertex_count: u32,
    lod: LodSettings,
    eye_direction: Vec3,
    paths: &[GenerationPath],
) -> (Vec<Vec<u8>>, FramePlan) {
    let document = common::sample(sample);
    let runtime = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle,
            ..RuntimeOptions::default()
        },
    );
    let mut scene = document.scene.clone();
    scene.effects.self_shadowing = SelfShadowing::DeepOpacityMaps;
    scene.effects.body_shadows = true;
    scene.effects.coverage = Coverage::WidthOit;
    let body = GpuBody::upload(context, &document.body);
    let (lo, hi) = runtime.textures.hair_bounds().expect("hair");
    let camera = Camera::framing(lo, hi, eye_direction);
    let preview = PreviewRenderer::new(context);
    let (width, height) = (160, 160);
    let mut plans = Vec::new();
    let pictures = paths
        .iter()
        .map(|&path| {
            let generator = StrandGenRenderer::with_path(context, path);
            let hair = generator.upload(context, &runtime).expect("upload");
            let frame = default_scene(
                &body,
                HairSource::Generated {
                    generator: &generator,
                    hair: &hair,
                    filtering: Filtering::Exact,
                    lod,
                },
                vertex_count,
                (lo, hi),
                camera,
                &scene,
            );
            let plan = preview.plan(&frame, width, height);
            assert!(plan.strands > 0);
            let picture = preview
                .render(context, &frame, &plan, width, height)
                .expect("frame");
            plans.push(plan);
            picture
        })
        .collect();
    assert!(
        plans.windows(2).all(|p| p[0] == p[1]),
        "one plan for every path"
    );
    (pictures, plans.swap_remove(0))
}

/// Pixels of `b` that differ from `a` by more than 2/255 in a channel, and pixels of `a`
/// unlike its top-left corner (the background).
fn compare(a: &[u8], b: &[u8]) -> (usize, usize) {
    let differing = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(x, y)| x.iter().zip(*y).any(|(p, q)| p.abs_diff(*q) > 2))
        .count();
    let drawn = a.chunks(4).filter(|p| p[..3] != a[..3]).count();
    (differing, drawn)
}

#[test]
fn mesh_shader_frames_match_vertex_shader_frames() {
    let Some(context) = mesh_context(module_path!()) else {
        return;
    };
    // LOD on with a wide morph window (λ = 1): partial strand counts, several vertex levels,
    // morphed odd vertices; up to 33 vertices per strand, so 3 or more strands per mesh group.
    let (_, lod) = common::morphing_lod(Vec3::ZERO, Vec3::ONE);
    let (pictures, plan) = frames(
        &context,
        "head_curly",
        12,
        33,
        lod,
        Vec3::new(0.6, 0.2, 1.0),
        &[GenerationPath::VertexShader, GenerationPath::MeshShader],
    );
    let runs: Vec<_> = plan.batches.iter().flatten().collect();
    let mut vertex_counts: Vec<u32> = runs.iter().map(|r| r.vertex_count).collect();
    vertex_counts.sort_unstable();
    vertex_counts.dedup();
    eprintln!("vertex counts {vertex_counts:?} in {} runs", runs.len());
    assert!(vertex_counts.len() >= 2, "{vertex_counts:?}");
    assert!(runs.iter().any(|r| r.gamma > 0.0), "some runs morph");
    let pixels = pictures[0].len() / 4;
    let (differing, drawn) = compare(&pictures[0], &pictures[1]);
    eprintln!("LOD on: {differing} of {pixels} pixels differ by more than 2/255 ({drawn} drawn)");
    assert!(drawn > pixels / 10, "the head is in the picture");
    assert!(differing * 1000 <= pixels, "{differing} of {pixels} differ");
}

#[test]
fn strands_longer_than_a_mesh_group_are_drawn_in_chunks() {
    let Some(context) = mesh_context(module_path!()) else {
        return;
    };
    // 257 vertices per strand: three chunks of at most 127 vertices each, whose end
    // vertices evaluate their neighbour beyond the chunk for the tangent.
    let lod = LodSettings {
        enabled: false,
        ..LodSettings::default()
    };
    let (pictures, plan) = frames(
        &context,
        "head_long_wavy",
        4,
        257,
        lod,
        Vec3::new(-0.3, 0.1, -1.0),
        &[GenerationPath::VertexShader, GenerationPath::MeshShader],
    );
    assert!(plan.batches.iter().flatten().all(|r| r.vertex_count == 257));
    let pixels = pictures[0].len() / 4;
    let (differing, drawn) = compare(&pictures[0], &pictures[1]);
    eprintln!(
        "257 vertices: {differing} of {pixels} pixels differ by more than 2/255 ({drawn} drawn)"
    );
    assert!(drawn > pixels / 10, "the head is in the picture");
    assert!(differing * 1000 <= pixels, "{differing} of {pixels} differ");
}

/// Where the device lacks mesh shaders the path is refused by name, never half-built; this
/// part runs on every adapter.
#[test]
fn mesh_shaders_are_refused_by_name_where_the_device_lacks_them() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let has = mesh_shaders_available(&context.device);
    assert_eq!(GenerationPath::MeshShader.available(&context.device), has);
    assert_eq!(
        GenerationPath::preferred(&context.device) == GenerationPath::MeshShader,
        has
    );
    match StrandGenRenderer::check_path(&context, GenerationPath::MeshShader) {
        Ok(()) => assert!(has),
        Err(error) => {
            assert!(!has);
            assert!(matches!(error, StrandGenError::NoMeshShaders { .. }));
            let message = error.to_string();
            assert!(
                message.contains(&context.adapter_info.name) && message.contains("mesh shaders"),
                "{message}"
            );
        }
    }
    for path in [
        GenerationPath::ComputePerStrand,
        GenerationPath::ComputePerVertex,
        GenerationPath::VertexShader,
    ] {
        assert!(StrandGenRenderer::check_path(&context, path).is_ok());
    }
}
