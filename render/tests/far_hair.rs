//! Far hair in whole frames (seed 001): a head seen from afar draws bundles as thick hairs
//! shaded by the aggregated BCSDF instead of their strands, keeps the strands' look (colour
//! and coverage within bounds), settles on its levels under a still camera, draws in the
//! shadow views too, and is refused by name where it cannot be drawn. (The mesh-shader path
//! draws it too: `tests/strand_mesh.rs`.)

mod common;

use glam::Vec3;
use hairloom_core::model::scene::{Effects, FarHair, Scene, SelfShadowing};
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::thick_hair::FarHair as FarTable;
use hairloom_render::device::headless_for_test;
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, default_scene};
use hairloom_render::renderer::preview_body::GpuBody;
use hairloom_render::renderer::strand_gen::{GenerationPath, GpuFarHair, StrandGenRenderer};

const SIZE: u32 = 160;

/// Hair pixels (those the background colour does not fill) and their mean sRGB colour.
fn hair_pixels(pixels: &[u8], background: [u8; 3]) -> (usize, [f64; 3]) {
    let mut count = 0;
    let mut sum = [0.0f64; 3];
    for p in pixels.chunks_exact(4) {
        let differs = (0..3).any(|c| (p[c] as i32 - background[c] as i32).abs() > 3);
        if differs {
            count += 1;
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
        }
    }
    (count, sum.map(|s| s / count.max(1) as f64))
}

#[test]
fn a_far_head_draws_thick_hairs_that_keep_the_strands_look() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let document = common::sample("head_long_wavy");
    let hair = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 16,
            ..RuntimeOptions::default()
        },
    );
    let generator = StrandGenRenderer::with_path(&context, GenerationPath::ComputePerStrand);
    let gpu_hair = generator.upload(&context, &hair).expect("upload");
    let far = GpuFarHair::upload(&context, FarTable::build(&hair, 9).expect("hierarchy"));
    // No body: the pictures hold only hair, so coverage and colour are the hair's.
    let body = GpuBody::upload(&context, &Default::default());
    let (lo, hi) = hair.textures.hair_bounds().expect("hair");
    let mut camera = Camera::framing(lo, hi, Vec3::new(0.2, 0.1, 1.0));
    camera.eye = camera.target + (camera.eye - camera.target) * 3.0;
    let strands_scene = Scene {
        effects: Effects {
            self_shadowing: SelfShadowing::OpacityShadowMaps,
            shadow_resolution: 128,
            ..Effects::default()
        },
        ..document.scene.clone()
    };
    let far_scene = Scene {
        effects: Effects {
            far_hair: FarHair::Aggregated,
            ..strands_scene.effects.clone()
        },
        ..strands_scene.clone()
    };
    let renderer = PreviewRenderer::new(&context);
    let draw = |lighting: &Scene| {
        let scene = default_scene(
            &body,
            HairSource::Generated {
                generator: &generator,
                hair: &gpu_hair,
                filtering: Filtering::Exact,
                lod: LodSettings::default(),
                far: Some(&far),
                fur: None,
            },
            9,
            (lo, hi),
            camera,
            lighting,
        );
        let steps = renderer
            .settle_far_levels(&context, &scene, SIZE, SIZE)
            .expect("settles");
        let plan = renderer.plan(&scene, SIZE, SIZE);
        let pixels = renderer
            .render(&context, &scene, &plan, SIZE, SIZE)
            .expect("drawn");
        // Drawing once more from the same place changes no level (eq. 16 has settled).
        let again = renderer.plan(&scene, SIZE, SIZE);
        assert_eq!(again.far_levels, plan.far_levels);
        (pixels, plan, steps, renderer.participants())
    };
    let (strand_pixels, strand_plan, strand_steps, _) = draw(&strands_scene);
    let (far_pixels, far_plan, far_steps, participants) = draw(&far_scene);
    assert_eq!((strand_steps, strand_plan.far_bundles), (0, 0));
    assert!(strand_plan.far_levels.is_empty());
    // Far away most bundles draw thick hairs; their strands are not generated.
    let bundles = gpu_hair.bundles.len();
    assert!(
        far_plan.far_bundles * 2 > bundles,
        "{} of {bundles} bundles as far hair",
        far_plan.far_bundles
    );
    assert!(far_plan.strands < strand_plan.strands);
    let deepest = far.table.blocks.iter().map(Vec::len).max().unwrap_or(0);
    assert!(far_steps <= deepest, "{far_steps} steps, {deepest} levels");
    let named: Vec<&str> = participants.iter().map(|(name, _)| *name).collect();
    assert!(named.contains(&"far hair"), "{named:?}");
    // The look is kept: as much of the picture is hair, in about the same colour.
    // The corner is background: the head fills the middle third.
    let background = [strand_pixels[0], strand_pixels[1], strand_pixels[2]];
    let (strand_count, strand_mean) = hair_pixels(&strand_pixels, background);
    let (far_count, far_mean) = hair_pixels(&far_pixels, background);
    assert!(strand_count > 200, "{strand_count} hair pixels");
    let coverage_ratio = far_count as f64 / strand_count as f64;
    assert!(
        (0.75..=1.3).contains(&coverage_ratio),
        "hair pixels: strands {strand_count}, far {far_count}"
    );
    for c in 0..3 {
        assert!(
            (far_mean[c] - strand_mean[c]).abs() < 40.0,
            "mean colour: strands {strand_mean:?}, far {far_mean:?}"
        );
    }
    assert_ne!(
        far_pixels, strand_pixels,
        "far hair drew nothing of its own"
    );
    eprintln!(
        "far hair: {} of {bundles} bundles, {} vs {} strands; hair pixels {far_count} vs \
         {strand_count}; mean sRGB {far_mean:.1?} vs {strand_mean:.1?}",
        far_plan.far_bundles, far_plan.strands, strand_plan.strands
    );
    // An ombré to blue over the whole strand turns far hair blue, within the look's bounds of
    // the strands' (far hair takes it in its ambient term; its aggregated lobes keep the
    // material's own colour, its tables being per material).
    let blue = |scene: &Scene| {
        let mut scene = scene.clone();
        scene.material.ombre = Some(hairloom_core::model::scene::Ombre {
            tip_rgb: [0.05, 0.12, 0.5],
            start: 0.0,
            end: 0.05,
        });
        scene
    };
    let (blue_strands, ..) = draw(&blue(&strands_scene));
    let (blue_far, blue_plan, ..) = draw(&blue(&far_scene));
    assert!(blue_plan.far_bundles * 2 > bundles);
    let (_, strand_blue) = hair_pixels(&blue_strands, background);
    let (_, far_blue) = hair_pixels(&blue_far, background);
    eprintln!("blue ends: mean sRGB far {far_blue:.1?}, strands {strand_blue:.1?}");
    assert!(
        strand_blue[2] > strand_blue[0] && far_blue[2] > far_blue[0],
        "blue ends: strands {strand_blue:?}, far {far_blue:?}"
    );
    for c in 0..3 {
        assert!(
            (far_blue[c] - strand_blue[c]).abs() < 40.0,
            "blue ends: strands {strand_blue:?}, far {far_blue:?}"
        );
    }
}

#[test]
fn far_hair_is_refused_by_name_where_it_is_not_drawn() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let document = common::sample("head_short_straight");
    let hair = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 2,
            ..RuntimeOptions::default()
        },
    );
    let body = GpuBody::upload(&context, &hair.body);
    let (lo, hi) = hair.textures.hair_bounds().expect("hair");
    let lighting = Scene {
        effects: Effects {
            far_hair: FarHair::Aggregated,
            ..Effects::default().none()
        },
        ..Scene::default()
    };
    let renderer = PreviewRenderer::new(&context);
    // Stored strands have no hierarchy.
    let vertices = vec![[0.0f32, 0.0, 0.0, 0.0]; 2 * 9];
    let scene = default_scene(
        &body,
        HairSource::Vertices(&vertices),
        9,
        (lo, hi),
        Camera::framing(lo, hi, Vec3::Z),
        &lighting,
    );
    let plan = renderer.plan(&scene, 32, 32);
    let error = renderer
        .render(&context, &scene, &plan, 32, 32)
        .expect_err("refused")
        .to_string();
    assert!(
        error.contains("scene.effects.far_hair") && error.contains("generated"),
        "{error}"
    );
}

/// Issue 33: the viewport's far hair does not stall its frame. `prepare_far_hair` starts the
/// hierarchy's build on a worker and returns at once (the frame draws strands meanwhile);
/// a later call uploads what the worker made, the same table `ensure_far_hair` builds in
/// place; a rebuild of the asset drops a build under way.
#[test]
fn far_hair_builds_on_a_worker_without_stalling_the_frame() {
    use hairloom_render::hair_asset::HairAsset;
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let generator = StrandGenRenderer::with_path(&context, GenerationPath::ComputePerStrand);
    let document = common::sample("head_long_wavy");
    let options = RuntimeOptions {
        strands_per_bundle: 16,
        ..RuntimeOptions::default()
    };
    let mut asset =
        HairAsset::from_document(&context, &generator, &document, &options).expect("asset");
    assert!(!asset.prepare_far_hair(&context).expect("started"));
    assert!(asset.far_hair_building() && asset.far_hair().is_none());
    let started = std::time::Instant::now();
    let ready = loop {
        if asset.prepare_far_hair(&context).expect("builds") {
            break true;
        }
        if started.elapsed() > std::time::Duration::from_secs(600) {
            break false;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    assert!(ready, "the worker finished");
    assert!(!asset.far_hair_building());
    let mut in_place =
        HairAsset::from_document(&context, &generator, &document, &options).expect("asset");
    in_place.ensure_far_hair(&context).expect("built in place");
    let (worker, here) = (
        &asset.far_hair().expect("uploaded").table,
        &in_place.far_hair().expect("uploaded").table,
    );
    assert_eq!(worker, here, "the worker builds what a build in place does");
    // Once ready, it stays: no second build.
    assert!(asset.prepare_far_hair(&context).expect("ready"));
    assert!(!asset.far_hair_building());
    // ensure_far_hair joins a build under way rather than starting another.
    let mut joined =
        HairAsset::from_document(&context, &generator, &document, &options).expect("asset");
    assert!(!joined.prepare_far_hair(&context).expect("started"));
    joined.ensure_far_hair(&context).expect("joined");
    assert!(!joined.far_hair_building());
    assert_eq!(&joined.far_hair().expect("uploaded").table, here);
}
