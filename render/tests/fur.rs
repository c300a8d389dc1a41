//! Fur in whole frames (seed 002): the furry teapot seen from afar draws shells and fins in
//! place of its strands and keeps their look (coverage and colour within bounds), keeps its
//! strands up close, cross-fades between the two as the camera moves with no pop, and grows
//! on degenerate root faces without a non-finite pixel; a hair with no root faces is refused
//! by name.

mod common;

use glam::{DVec3, Vec3};
use hairloom_core::model::document::Document;
use hairloom_core::model::scene::{Effects, Fur, FurShells, Scene};
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::RuntimeOptions;
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_render::device::{GpuContext, headless_for_test};
use hairloom_render::hair_asset::HairAsset;
use hairloom_render::preview::{Camera, PreviewRenderer, PreviewScene, default_scene};
use hairloom_render::renderer::strand_gen::{GenerationPath, StrandGenRenderer};

const SIZE: u32 = 128;

/// Pixels unlike the background and their mean sRGB colour.
fn hair_pixels(pixels: &[u8], background: [u8; 3]) -> (usize, [f64; 3]) {
    let mut count = 0;
    let mut sum = [0.0f64; 3];
    for p in pixels.chunks_exact(4) {
        if (0..3).any(|c| (p[c] as i32 - background[c] as i32).abs() > 3) {
            count += 1;
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
        }
    }
    (count, sum.map(|s| s / count.max(1) as f64))
}

struct Teapot {
    generator: StrandGenRenderer,
    asset: HairAsset,
    scene: Scene,
}

fn teapot(context: &GpuContext, effects: Effects) -> Teapot {
    let document = common::sample("teapot_fur");
    furry(context, &document, effects, 16)
}

fn furry(
    context: &GpuContext,
    document: &Document,
    effects: Effects,
    strands_per_bundle: u32,
) -> Teapot {
    let generator = StrandGenRenderer::with_path(context, GenerationPath::ComputePerStrand);
    let mut asset = HairAsset::from_document(
        context,
        &generator,
        document,
        &RuntimeOptions {
            strands_per_bundle,
            ..RuntimeOptions::default()
        },
    )
    .expect("asset");
    let scene = Scene {
        effects,
        ..document.scene.clone()
    };
    if scene.effects.fur == Fur::ShellsFins {
        asset
            .ensure_fur(context, &scene.effects.fur_shells)
            .expect("fur");
    }
    Teapot {
        generator,
        asset,
        scene,
    }
}

/// A frame of `teapot` seen from `distance` × the framing distance.
fn frame(teapot: &Teapot, distance: f32) -> PreviewScene<'_> {
    let (lo, hi) = teapot.asset.bounds();
    let mut camera = Camera::framing(lo, hi, Vec3::new(0.3, 0.4, 1.0));
    camera.eye = camera.target + (camera.eye - camera.target) * distance;
    default_scene(
        teapot.asset.body(),
        teapot
            .asset
            .source(&teapot.generator, Filtering::Exact, LodSettings::default()),
        9,
        (lo, hi),
        camera,
        &teapot.scene,
    )
}

/// The frame of `teapot` seen from `distance` × the framing distance: its pixels and the
/// strands its plan drew.
fn draw(context: &GpuContext, teapot: &Teapot, distance: f32, size: u32) -> (Vec<u8>, usize) {
    let scene = frame(teapot, distance);
    let renderer = PreviewRenderer::new(context);
    let plan = renderer.plan(&scene, size, size);
    let pixels = renderer
        .render(context, &scene, &plan, size, size)
        .expect("frame");
    (pixels, plan.strands)
}

fn effects(fur: Fur) -> Effects {
    let none = Effects::default().none();
    Effects {
        fur,
        ..none
            .parse_list("marschner,deep-opacity-maps,body-shadows")
            .expect("effects")
    }
}

#[test]
fn a_far_teapot_draws_shells_and_fins_that_keep_the_strands_look() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let strands = teapot(&context, effects(Fur::Off));
    let fur = teapot(&context, effects(Fur::ShellsFins));
    let (strand_pixels, strand_count) = draw(&context, &strands, 2.5, SIZE);
    let (fur_pixels, fur_strands) = draw(&context, &fur, 2.5, SIZE);
    // The teapot sits in the middle: the corner is the background.
    let background = [strand_pixels[0], strand_pixels[1], strand_pixels[2]];
    assert!(strand_count > 0);
    assert_eq!(fur_strands, 0, "far away the shells alone draw the fur");
    let (n_strands, colour_strands) = hair_pixels(&strand_pixels, background);
    let (n_fur, colour_fur) = hair_pixels(&fur_pixels, background);
    // The teapot covers the same pixels (fins on its silhouette stand in for the strands'
    // fringe) and its colour stays near the strands' (the body shows through both).
    let coverage = n_fur as f64 / n_strands as f64;
    assert!(
        (0.85..1.2).contains(&coverage),
        "coverage {n_fur} vs {n_strands}"
    );
    for c in 0..3 {
        assert!(
            (colour_fur[c] - colour_strands[c]).abs() < 40.0,
            "colour {colour_fur:?} vs {colour_strands:?}"
        );
    }
    // And the shells are not the strands: fur changes the picture.
    let changed = fur_pixels
        .chunks_exact(4)
        .zip(strand_pixels.chunks_exact(4))
        .filter(|(a, b)| (0..3).any(|c| (a[c] as i32 - b[c] as i32).abs() > 8))
        .count();
    assert!(changed > 50, "{changed} pixels differ");
}

#[test]
fn up_close_the_strands_draw_the_fur() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let strands = teapot(&context, effects(Fur::Off));
    let fur = teapot(&context, effects(Fur::ShellsFins));
    // 2048 pixels high: the fur is tens of pixels long.
    let renderer = PreviewRenderer::new(&context);
    let plan_of = |teapot: &Teapot| renderer.plan(&frame(teapot, 1.0), 2048, 2048);
    assert_eq!(plan_of(&fur).strands, plan_of(&strands).strands);
}

/// PSNR (dB) between two RGBA8 pictures.
fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let mse = a
        .chunks_exact(4)
        .zip(b.chunks_exact(4))
        .map(|(p, q)| {
            (0..3)
                .map(|c| (p[c] as f64 - q[c] as f64).powi(2))
                .sum::<f64>()
                / 3.0
        })
        .sum::<f64>()
        / (a.len() / 4) as f64;
    10.0 * (255.0f64 * 255.0 / mse.max(1e-12)).log10()
}

#[test]
fn a_dolly_through_the_cross_fade_does_not_pop() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let strands = teapot(&context, effects(Fur::Off));
    let fur = teapot(&context, effects(Fur::ShellsFins));
    // From strands only through the cross-fade to shells only (at 128 pixels the fur is
    // about 5 px long at distance 1, so the cross-fade lies between 0.1 and 0.4).
    let frames = 24;
    let distance = |i: usize| 0.08 * (6.0f32).powf(i as f32 / (frames - 1) as f32);
    let worst = |teapot: &Teapot| {
        let mut last: Option<Vec<u8>> = None;
        let mut worst = f64::INFINITY;
        for i in 0..frames {
            let (pixels, _) = draw(&context, teapot, distance(i), SIZE);
            if let Some(last) = &last {
                worst = worst.min(psnr(last, &pixels));
            }
            last = Some(pixels);
        }
        worst
    };
    let (strands_worst, fur_worst) = (worst(&strands), worst(&fur));
    assert!(
        fur_worst > strands_worst - 3.0,
        "worst step with fur {fur_worst:.2} dB, strands alone {strands_worst:.2} dB"
    );
}

#[test]
fn fur_grows_on_degenerate_root_faces_and_refuses_a_hair_with_none() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    use hairloom_core::samples::{grid_scalp, straight_layers};
    // A 3 × 3 patch whose middle row is squashed to zero area, with one layer of short hair.
    let scalp = grid_scalp(3, 3, |s, t| {
        let t = if (0.3..0.7).contains(&t) { 0.5 } else { t };
        DVec3::new(s * 0.05, t * 0.05, 0.0)
    });
    let mesh = straight_layers(scalp, 1, DVec3::new(0.0, 0.0, 0.01));
    let mut document = Document::new("degenerate fur", mesh);
    // Shells only, of dense fur (a thousand strands a bundle) on a small tile.
    document.scene.effects = Effects {
        fur_shells: FurShells {
            shells_below_px: 1e5,
            strands_above_px: 1e5,
            tile_width_m: Some(0.004),
            preset: hairloom_core::fur::volume::FurPreset::Dense,
            ..FurShells::default()
        },
        ..effects(Fur::ShellsFins)
    };
    let effects = document.scene.effects.clone();
    let patch = furry(&context, &document, effects.clone(), 1024);
    let (pixels, strands) = draw(&context, &patch, 2.0, 64);
    assert_eq!(strands, 0);
    let (covered, _) = hair_pixels(&pixels, [pixels[0], pixels[1], pixels[2]]);
    assert!(covered > 20, "the shells draw: {covered} pixels");
    // Every bundle removed: no root faces to grow on.
    let mut bare = document.clone();
    for bundle in &mut bare.hair_mesh.bundles {
        bundle.removed = true;
    }
    bare.hair_mesh.bundles[0].removed = false;
    bare.hair_mesh.bundles[0].layers = 1;
    let generator = StrandGenRenderer::with_path(&context, GenerationPath::ComputePerStrand);
    let mut asset = HairAsset::from_document(
        &context,
        &generator,
        &bare,
        &RuntimeOptions {
            strands_per_bundle: 4,
            ..RuntimeOptions::default()
        },
    )
    .expect("asset");
    assert!(asset.ensure_fur(&context, &effects.fur_shells).is_ok());
    let mut runtime = asset.hair().clone();
    runtime.fur_base = Default::default();
    let mut empty = HairAsset::upload(&context, &generator, runtime).expect("asset");
    let error = empty
        .ensure_fur(&context, &effects.fur_shells)
        .expect_err("no root faces");
    assert!(error.to_string().contains("no root faces"), "{error}");
}
