//! `hairloom bench shading`: accuracy against time of the lighting effects. Each head sample
//! at near, middle and far framing (the hair's bounding sphere spans 60%, 20% and 2% of the
//! picture's height, as in seed 001's Fig. 5) is path-traced on the CPU
//! ([`hairloom_core::light::reference_render`]: the f64 reference strands as fibres, the same
//! fibre model, exact shadows, many bounces) and rendered on the GPU in every configuration;
//! each GPU picture's ꟻLIP error against the reference (NVIDIA's metric, `nv-flip`) sits beside
//! its frame time. Writes `shading.csv` and one PNG grid per sample and framing (reference and
//! configurations on top, ꟻLIP maps below).

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;
use hairloom_core::light::reference_render::{
    Fibres, ReferenceCamera, ReferenceSettings, render_reference,
};
use hairloom_core::model::scene::{Effects, FarHair, Fur, FurShells, Scene};
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{DEFAULT_SAMPLE_SEED, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::strands::reference::{StrandOptions, generate_parallel};
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::hair_asset::HairAsset;
use hairloom_render::preview::{Camera, PreviewRenderer, default_scene, default_strand_width_m};
use hairloom_render::renderer::strand_gen::StrandGenRenderer;

/// The framings: name and the fraction of the picture's height the hair (its box's largest
/// side) spans.
pub const FRAMINGS: [(&str, f32); 3] = [("near", 0.6), ("middle", 0.2), ("far", 0.02)];

/// The GPU configurations, each adding to the one before it (seed 001's comparison),
/// everything with width-based coverage, and the full scene with fewer offsets averaged
/// across thin fibres (2 and 1 instead of 3).
pub fn configurations(scene: &Effects) -> Vec<(&'static str, Effects)> {
    let none = scene.none();
    let list = [
        ("kajiya-kay", "none"),
        ("marschner", "marschner"),
        (
            "+ opacity shadow maps",
            "marschner,opacity-shadow-maps,body-shadows",
        ),
        (
            "+ deep opacity maps",
            "marschner,deep-opacity-maps,body-shadows",
        ),
        (
            "+ dual scattering",
            "marschner,deep-opacity-maps,body-shadows,dual-scattering",
        ),
        (
            "+ width-based OIT",
            "marschner,deep-opacity-maps,body-shadows,dual-scattering,width-oit",
        ),
    ];
    let mut configurations: Vec<(&'static str, Effects)> = list
        .iter()
        .map(|(name, effects)| {
            (
                *name,
                none.parse_list(effects).expect("the configurations parse"),
            )
        })
        .collect();
    // The accuracy switch of thin fibres: fewer offsets across them, cheaper and less exact.
    let full = configurations[4].1.clone();
    for (name, offsets) in [("  h: 2 points", 2), ("  h: 1 point", 1)] {
        configurations.push((
            name,
            Effects {
                fibre_offsets: offsets,
                ..full.clone()
            },
        ));
    }
    // Far hair (seed 001) over the full scene: thick hairs where strands would be thinner
    // than ε_w, against the row above it with strand LOD alone.
    configurations.push((
        "+ far hair (aggregated)",
        Effects {
            far_hair: FarHair::Aggregated,
            ..full
        },
    ));
    configurations
}

/// `hairloom bench far`'s framings: seed 001 Fig. 7's sweep of the hair's size on screen.
pub const FAR_SWEEP: [(&str, f32); 8] = [
    ("50%", 0.5),
    ("20%", 0.2),
    ("10%", 0.1),
    ("5%", 0.05),
    ("2%", 0.02),
    ("1%", 0.01),
    ("0.5%", 0.005),
    ("0.3%", 0.003),
];

/// `hairloom bench far`'s methods over the full scene (deep opacity maps, body shadows, dual
/// scattering): every strand at full detail, seed 000's strand and vertex LOD, and seed 001's
/// far hair over that LOD.
pub fn far_configurations(scene: &Effects) -> Vec<(&'static str, Effects)> {
    let full = scene
        .none()
        .parse_list("marschner,deep-opacity-maps,body-shadows,dual-scattering")
        .expect("the configurations parse");
    vec![
        (NO_LOD, full.clone()),
        ("strands + LOD (seed 000)", full.clone()),
        (
            "far hair (seed 001)",
            Effects {
                far_hair: FarHair::Aggregated,
                ..full
            },
        ),
    ]
}

/// `hairloom bench fur`'s methods over the full scene: strands with LOD, shells and fins
/// alone (seed 002 as written: whatever the distance), and the cross-fade a scene gets by
/// default (strands near, shells and fins far).
pub fn fur_configurations(scene: &Effects) -> Vec<(&'static str, Effects)> {
    let full = scene
        .none()
        .parse_list("marschner,deep-opacity-maps,body-shadows,dual-scattering")
        .expect("the configurations parse");
    let shells = FurShells {
        shells_below_px: 1e5,
        strands_above_px: 1e5,
        ..scene.fur_shells.clone()
    };
    vec![
        ("strands + LOD", full.clone()),
        (
            "shells + fins (seed 002)",
            Effects {
                fur: Fur::ShellsFins,
                fur_shells: shells,
                ..full.clone()
            },
        ),
        (
            "blended",
            Effects {
                fur: Fur::ShellsFins,
                ..full
            },
        ),
    ]
}

/// `bench fur`'s framings: the furry object's largest side as a share of the picture.
pub const FUR_FRAMINGS: [(&str, f32); 3] = [("near", 0.6), ("middle", 0.2), ("far", 0.05)];

/// The configuration drawn with strand and vertex LOD off.
const NO_LOD: &str = "strands, no LOD";

/// What a run measures: the shading configurations at [`FRAMINGS`], or far hair's methods
/// over [`FAR_SWEEP`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadingBench {
    Shading,
    Far,
    /// Fur (seed 002): strands, shells and fins, and the two cross-faded, at [`FUR_FRAMINGS`].
    Fur,
}

pub struct ShadingSettings {
    pub bench: ShadingBench,
    pub samples: Vec<String>,
    pub size: u32,
    pub strands_per_bundle: u32,
    pub samples_per_pixel: u32,
    pub max_bounces: u32,
    pub max_seconds: f64,
    pub runs: usize,
    pub out: PathBuf,
}

/// A camera that shows the sphere `(center, radius)` spanning `fraction` of the picture's
/// height, looking from `direction`.
pub fn framing_camera(center: Vec3, radius: f32, direction: Vec3, fraction: f32) -> Camera {
    let fov_y_rad = 30f32.to_radians();
    let distance = radius / (0.5 * fov_y_rad * fraction).tan();
    Camera {
        eye: center + direction.normalize() * distance,
        target: center,
        up: Vec3::Y,
        fov_y_rad,
    }
}

pub fn run(settings: &ShadingSettings) -> anyhow::Result<()> {
    let context = GpuContext::new_headless()?;
    let generator = StrandGenRenderer::new(&context);
    let renderer = PreviewRenderer::new(&context);
    std::fs::create_dir_all(&settings.out)?;
    let far_bench = settings.bench == ShadingBench::Far;
    let fur_bench = settings.bench == ShadingBench::Fur;
    let stem = match settings.bench {
        ShadingBench::Shading => "shading",
        ShadingBench::Far => "far",
        ShadingBench::Fur => "fur",
    };
    let csv_path = settings.out.join(format!("{stem}.csv"));
    let mut csv = std::fs::File::create(&csv_path)?;
    writeln!(
        csv,
        "sample,framing,configuration,flip_mean,frame_ms,segments,far_bundles,reference_seconds,reference_spp"
    )?;
    if far_bench {
        println!(
            "Far hair: strands, strand LOD and far hair's thick hairs as the head shrinks on \
             screen; ꟻLIP against the CPU path tracer on full geometry, frame time, segments"
        );
    } else if fur_bench {
        println!(
            "Fur: strands, shells + fins and the two cross-faded as the object shrinks on \
             screen; ꟻLIP against the CPU path tracer on the strands, frame time, memory"
        );
    } else {
        println!("Shading accuracy against time: ꟻLIP against the CPU path tracer, GPU frame time");
    }
    println!("adapter: {}", describe(&context.adapter_info));
    println!("machine: {}", super::machine());
    println!(
        "{}x{} pixels, {} strands per bundle, reference {} samples per pixel, {} bounces",
        settings.size,
        settings.size,
        settings.strands_per_bundle,
        settings.samples_per_pixel,
        settings.max_bounces
    );
    println!(
        "{:<20} {:<7} {:<26} {:>8} {:>10} {:>9} {:>5}",
        "sample", "framing", "configuration", "ꟻLIP", "frame ms", "segments", "far"
    );
    let framings: Vec<(&str, f32)> = match settings.bench {
        ShadingBench::Shading => FRAMINGS.to_vec(),
        ShadingBench::Far => FAR_SWEEP.to_vec(),
        ShadingBench::Fur => FUR_FRAMINGS.to_vec(),
    };
    let rows_of = |effects: &Effects| match settings.bench {
        ShadingBench::Shading => configurations(effects),
        ShadingBench::Far => far_configurations(effects),
        ShadingBench::Fur => fur_configurations(effects),
    };
    let size = settings.size.max(16);
    for name in &settings.samples {
        let path = hairloom_core::samples::default_sample_path()
            .with_file_name(format!("{name}.hairloom"));
        let document = hairloom_core::io::project::load(&path)?.document;
        let mut asset = HairAsset::from_document(
            &context,
            &generator,
            &document,
            &RuntimeOptions {
                strands_per_bundle: settings.strands_per_bundle,
                ..RuntimeOptions::default()
            },
        )
        .map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
        asset
            .ensure_far_hair(&context)
            .map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
        if fur_bench {
            let started = Instant::now();
            asset
                .ensure_fur(&context, &document.scene.effects.fur_shells)
                .map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
            let fur = asset.fur().expect("made above");
            println!(
                "{name}: fur made in {:.2} s: {} patches, {} shells of {}², {:.2} MB on the GPU \
                 (all levels, strand directions, patches; seed 002's own set for these \
                 settings: {:.2} MB)",
                started.elapsed().as_secs_f64(),
                fur.patch_count,
                fur.layer_count,
                document.scene.effects.fur_shells.shell_resolution,
                fur.bytes() as f64 / 1e6,
                fur.seed_bytes as f64 / 1e6,
            );
        }
        let (lo, hi) = asset.bounds();
        let width_m = default_strand_width_m(lo, hi);
        let fibres = reference_fibres(&document, settings.strands_per_bundle, width_m as f64);
        // The framings size the hair by its largest side.
        let (center, radius) = ((lo + hi) * 0.5, (hi - lo).max_element() * 0.5);
        for &(framing, fraction) in &framings {
            let camera = framing_camera(center, radius, Vec3::new(0.75, 0.25, 1.0), fraction);
            let started = Instant::now();
            let reference = render_reference(
                &fibres,
                &document.body,
                &document.scene,
                &ReferenceCamera {
                    eye: camera.eye.as_dvec3(),
                    target: camera.target.as_dvec3(),
                    up: camera.up.as_dvec3(),
                    fov_y_rad: camera.fov_y_rad as f64,
                    width: size,
                    height: size,
                },
                &ReferenceSettings {
                    samples_per_pixel: settings.samples_per_pixel,
                    max_bounces: settings.max_bounces,
                    max_seconds: settings.max_seconds,
                    ..ReferenceSettings::default()
                },
            );
            let reference_seconds = started.elapsed().as_secs_f64();
            let background: [u8; 4] = reference.pixels[..4].try_into().unwrap_or([0; 4]);
            let mut row_images = vec![reference.pixels.clone()];
            let black: Vec<u8> = [0, 0, 0, 255].repeat((size * size) as usize);
            let mut flip_images = vec![black];
            for (configuration, effects) in rows_of(&document.scene.effects) {
                let lighting = Scene {
                    effects,
                    ..document.scene.clone()
                };
                let lod = LodSettings {
                    enabled: configuration != NO_LOD,
                    ..LodSettings::default()
                };
                let scene = default_scene(
                    asset.body(),
                    asset.source(&generator, Filtering::Exact, lod),
                    17,
                    (lo, hi),
                    camera,
                    &lighting,
                );
                // A still camera: far hair at the levels it settles on.
                renderer.settle_far_levels(&context, &scene, size, size)?;
                let plan = renderer.plan(&scene, size, size);
                let pixels = renderer.render(&context, &scene, &plan, size, size)?;
                let timing = super::bench::median_timing(
                    || renderer.time_frame(&context, &scene, size, size),
                    settings.runs,
                    |t| t.wall_ms,
                )?;
                let (mean, map) = flip(&reference.pixels, &pixels, size, background);
                let segments = timing.vertices - timing.strands + timing.far_segments as usize;
                println!(
                    "{:<20} {:<7} {:<26} {:>8.4} {:>10.1} {:>9} {:>5}",
                    name,
                    framing,
                    configuration,
                    mean,
                    timing.wall_ms,
                    segments,
                    timing.far_bundles
                );
                writeln!(
                    csv,
                    "{name},{framing},{configuration},{mean:.5},{:.2},{segments},{},{reference_seconds:.1},{}",
                    timing.wall_ms, timing.far_bundles, reference.samples_per_pixel
                )?;
                row_images.push(pixels);
                flip_images.push(map);
            }
            let grid_path = settings.out.join(format!(
                "{stem}_{name}_{}.png",
                framing.trim_end_matches('%')
            ));
            write_grid(&grid_path, &[row_images, flip_images], size)?;
            println!(
                "{:<20} {:<7} reference: {} spp in {reference_seconds:.1} s ({:.1} M rays) -> {}",
                name,
                framing,
                reference.samples_per_pixel,
                reference.rays as f64 / 1e6,
                grid_path.display()
            );
        }
        if far_bench || fur_bench {
            println!("{name}: dolly from 60 % to 2 % of the picture in {DOLLY_FRAMES} frames");
            for (configuration, effects) in rows_of(&document.scene.effects) {
                let lighting = Scene {
                    effects,
                    ..document.scene.clone()
                };
                let lod = LodSettings {
                    enabled: configuration != NO_LOD,
                    ..LodSettings::default()
                };
                let (worst, mean) = dolly_psnr(
                    &context,
                    &renderer,
                    |camera| {
                        default_scene(
                            asset.body(),
                            asset.source(&generator, Filtering::Exact, lod),
                            17,
                            (lo, hi),
                            camera,
                            &lighting,
                        )
                    },
                    (center, radius),
                    size,
                )?;
                println!(
                    "{:<20} dolly   {:<26} worst PSNR {worst:>6.2} dB, mean {mean:>6.2} dB",
                    name, configuration
                );
                writeln!(csv, "{name},dolly,{configuration},{worst:.3},{mean:.3},,,,")?;
            }
        }
    }
    println!("CSV: {}", csv_path.display());
    Ok(())
}

/// Frames of `bench far`'s dolly.
pub const DOLLY_FRAMES: usize = 40;

/// PSNR (dB, RGB) between two RGBA8 pictures of the same size.
pub fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let (mut sum, mut count) = (0.0f64, 0usize);
    for (pa, pb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for c in 0..3 {
            let d = pa[c] as f64 - pb[c] as f64;
            sum += d * d;
            count += 1;
        }
    }
    let mse = sum / count.max(1) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

/// Seed 001 Fig. 9: the camera moves away from the hair (sphere `sphere`) from 60 % to 2 % of
/// the picture in [`DOLLY_FRAMES`] frames at a constant ratio, each frame planned from the last
/// (far hair's levels follow eq. 16 frame by frame, as in the editor); returns the worst and
/// mean PSNR between consecutive frames (a pop is a low one).
fn dolly_psnr<'a>(
    context: &GpuContext,
    renderer: &PreviewRenderer,
    scene_for: impl Fn(Camera) -> hairloom_render::preview::PreviewScene<'a>,
    (center, radius): (Vec3, f32),
    size: u32,
) -> anyhow::Result<(f64, f64)> {
    let ratio = (0.02f32 / 0.6).powf(1.0 / (DOLLY_FRAMES - 1) as f32);
    let mut previous: Option<Vec<u8>> = None;
    let (mut worst, mut sum) = (f64::INFINITY, 0.0);
    for frame in 0..DOLLY_FRAMES {
        let fraction = 0.6 * ratio.powi(frame as i32);
        let camera = framing_camera(center, radius, Vec3::new(0.75, 0.25, 1.0), fraction);
        let scene = scene_for(camera);
        let plan = renderer.plan(&scene, size, size);
        let pixels = renderer.render(context, &scene, &plan, size, size)?;
        if let Some(previous) = &previous {
            let value = psnr(previous, &pixels);
            worst = worst.min(value);
            sum += value.min(99.0);
        }
        previous = Some(pixels);
    }
    Ok((worst, sum / (DOLLY_FRAMES - 1) as f64))
}

/// The document's f64 reference strands as fibres, with their root indices and the colour map
/// at their roots.
pub fn reference_fibres(
    document: &hairloom_core::Document,
    strands_per_bundle: u32,
    width_m: f64,
) -> Fibres {
    let options = StrandOptions {
        strands_per_bundle,
        vertices_log2: 4,
        sample_seed: DEFAULT_SAMPLE_SEED,
        ..StrandOptions::default()
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let strands = generate_parallel(document, &options, threads);
    let mut fibres = Fibres {
        width_m,
        ..Fibres::default()
    };
    let roots = hairloom_core::strands::reference::root_indices(&strands);
    for (strand, root) in strands.iter().zip(roots) {
        let paint = document.root_maps.sample_colour(strand.root_uv);
        fibres.push_painted(&strand.points, root, paint);
    }
    fibres
}

/// Mean ꟻLIP of `test` against `reference` (RGBA8, sRGB) over the screen-space box of what
/// the reference draws (pixels unlike `background`: hair and body, as seed 001 reports it), and
/// the whole error map (magma, RGBA8).
pub fn flip(reference: &[u8], test: &[u8], size: u32, background: [u8; 4]) -> (f32, Vec<u8>) {
    let rgb =
        |rgba: &[u8]| -> Vec<u8> { rgba.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let reference = nv_flip::FlipImageRgb8::with_data(size, size, &rgb(reference));
    let test = nv_flip::FlipImageRgb8::with_data(size, size, &rgb(test));
    let drawn: Vec<(u32, u32)> = reference
        .to_vec()
        .chunks(3)
        .enumerate()
        .filter(|(_, p)| p[..] != background[..3])
        .map(|(i, _)| (i as u32 % size, i as u32 / size))
        .collect();
    let error = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let values = error.to_vec();
    let (x0, x1) = (
        drawn.iter().map(|p| p.0).min(),
        drawn.iter().map(|p| p.0).max(),
    );
    let (y0, y1) = (
        drawn.iter().map(|p| p.1).min(),
        drawn.iter().map(|p| p.1).max(),
    );
    let mean = match (x0, x1, y0, y1) {
        (Some(x0), Some(x1), Some(y0), Some(y1)) => {
            let mut sum = 0.0f64;
            for y in y0..=y1 {
                for x in x0..=x1 {
                    sum += values[(y * size + x) as usize] as f64;
                }
            }
            (sum / ((x1 - x0 + 1) * (y1 - y0 + 1)) as f64) as f32
        }
        _ => nv_flip::FlipPool::from_image(&error).mean(),
    };
    let map = error.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    let rgba = map
        .chunks(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    (mean, rgba)
}

/// Writes rows of `size × size` RGBA8 pictures side by side as one PNG.
fn write_grid(path: &Path, rows: &[Vec<Vec<u8>>], size: u32) -> anyhow::Result<()> {
    let columns = rows.iter().map(Vec::len).max().unwrap_or(0) as u32;
    let mut grid = image::RgbaImage::new(columns * size, rows.len() as u32 * size);
    for (r, row) in rows.iter().enumerate() {
        for (c, pixels) in row.iter().enumerate() {
            let tile = image::RgbaImage::from_raw(size, size, pixels.clone())
                .ok_or_else(|| anyhow::anyhow!("a {size}x{size} picture"))?;
            image::imageops::replace(
                &mut grid,
                &tile,
                (c as u32 * size) as i64,
                (r as u32 * size) as i64,
            );
        }
    }
    grid.save(path)?;
    Ok(())
}
