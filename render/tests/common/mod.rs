//! What several GPU tests share: the bundled samples and a camera that makes the frame plan
//! use every part of LOD, and whole frames drawn by several generation paths.
#![allow(
    dead_code,
    reason = "each test binary uses its own part of these helpers"
)]

use glam::{Mat4, Vec3};
use hairloom_core::runtime::frame_plan::{LodCamera, LodSettings};

/// A bundled sample project's document.
pub fn sample(name: &str) -> hairloom_core::model::document::Document {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../assets/samples/{name}.hairloom"));
    hairloom_core::io::project::load(&path)
        .expect("sample")
        .document
}

/// A 30° camera at `eye` looking at `target`, 1080 pixels high, as LOD sees it.
pub fn lod_camera(eye: Vec3, target: Vec3) -> LodCamera {
    let fov_y_rad = 30f32.to_radians();
    LodCamera {
        eye,
        view_projection: Mat4::perspective_rh(fov_y_rad, 1.0, 0.01, 100.0)
            * Mat4::look_at_rh(eye, target, Vec3::Y),
        fov_y_rad,
        resolution_px: 1080.0,
    }
}

/// A camera far enough from hair in the box `(lo, hi)` for partial strand counts and several
/// vertex levels, with a wide morph window (λ = 1) so that many bundles sit between two
/// levels (morphing).
pub fn morphing_lod(lo: Vec3, hi: Vec3) -> (LodCamera, LodSettings) {
    let centre = (lo + hi) * 0.5;
    let camera = lod_camera(centre + Vec3::new(0.0, 0.0, 6.0), centre);
    let lod = LodSettings {
        alpha_strands: 0.02,
        alpha_vertices: 0.005,
        lambda: 1.0,
        ..LodSettings::default()
    };
    (camera, lod)
}

/// The same frame of `sample` — deep opacity maps, body shadows, width-based coverage, so
/// every pass that draws the hair — drawn by each of `paths`, as RGBA8 pictures, and its
/// frame plan (one for every path).
pub fn frames(
    context: &hairloom_render::device::GpuContext,
    sample_name: &str,
    strands_per_bundle: u32,
    vertex_count: u32,
    lod: hairloom_core::runtime::frame_plan::LodSettings,
    eye_direction: glam::Vec3,
    paths: &[hairloom_render::renderer::strand_gen::GenerationPath],
) -> (Vec<Vec<u8>>, hairloom_core::runtime::frame_plan::FramePlan) {
    frames_of(
        context,
        &sample(sample_name),
        strands_per_bundle,
        vertex_count,
        lod,
        eye_direction,
        paths,
    )
}

/// As [`frames`], of `document`.
pub fn frames_of(
    context: &hairloom_render::device::GpuContext,
    document: &hairloom_core::model::document::Document,
    strands_per_bundle: u32,
    vertex_count: u32,
    lod: hairloom_core::runtime::frame_plan::LodSettings,
    eye_direction: glam::Vec3,
    paths: &[hairloom_render::renderer::strand_gen::GenerationPath],
) -> (Vec<Vec<u8>>, hairloom_core::runtime::frame_plan::FramePlan) {
    use hairloom_core::model::scene::{Coverage, SelfShadowing};
    use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
    use hairloom_core::runtime::strand_gen::Filtering;
    use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, default_scene};
    use hairloom_render::renderer::preview_body::GpuBody;
    use hairloom_render::renderer::strand_gen::StrandGenRenderer;
    let runtime = RuntimeHair::from_document(
        document,
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
                    far: None,
                    fur: None,
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
pub fn compare(a: &[u8], b: &[u8]) -> (usize, usize) {
    let differing = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(x, y)| x.iter().zip(*y).any(|(p, q)| p.abs_diff(*q) > 2))
        .count();
    let drawn = a.chunks(4).filter(|p| p[..3] != a[..3]).count();
    (differing, drawn)
}

/// Whether `context`'s adapter has mesh shaders. Without them `test` says it skipped its mesh
/// path, or fails where `HAIRLOOM_REQUIRE_MESH_SHADERS=1` (`make test` runs the mesh tests
/// again on an adapter that has them, where they must not skip).
pub fn has_mesh_shaders(context: &hairloom_render::device::GpuContext, test: &str) -> bool {
    if hairloom_render::renderer::strand_gen::mesh_shaders_available(&context.device) {
        return true;
    }
    let why = format!(
        "{} has no mesh shaders (EXPERIMENTAL_MESH_SHADER)",
        hairloom_render::device::describe(&context.adapter_info)
    );
    assert!(
        std::env::var("HAIRLOOM_REQUIRE_MESH_SHADERS").as_deref() != Ok("1"),
        "{test}: {why} (HAIRLOOM_REQUIRE_MESH_SHADERS=1)"
    );
    eprintln!("skipped the mesh path: {test}: {why}");
    false
}
