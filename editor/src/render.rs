//! `hairloom render`: a headless picture of a project through the preview renderer.
//!
//! Strands come from the styled CPU reference generator for now (uploaded as vertices); the
//! GPU generation stage renders unstyled strands bit-identically (see render/tests) and will
//! take over once styling runs in WGSL.

use std::path::Path;

use anyhow::{Context, bail};
use glam::Vec3;
use hairloom_core::strands::{StrandOptions, generate_parallel};
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::preview::{Camera, PreviewRenderer, PreviewScene};

/// Vertices per strand in previews: 2^4 + 1.
const PREVIEW_VERTICES_LOG2: u32 = 4;

fn parse_size(size: &str) -> anyhow::Result<(u32, u32)> {
    let (w, h) = size
        .split_once('x')
        .context("--size must look like 960x960")?;
    let (w, h): (u32, u32) = (w.trim().parse()?, h.trim().parse()?);
    if w == 0 || h == 0 || w > 8192 || h > 8192 {
        bail!("--size {w}x{h}: each side must be 1 to 8192 pixels");
    }
    Ok((w, h))
}

fn parse_view(view: &str) -> anyhow::Result<Vec3> {
    Ok(match view {
        "front" => Vec3::new(0.0, 0.1, 1.0),
        "side" => Vec3::new(1.0, 0.1, 0.0),
        "back" => Vec3::new(0.0, 0.2, -1.0),
        "three-quarter" => Vec3::new(0.75, 0.25, 1.0),
        custom => {
            let parts: Vec<f32> = custom
                .split(',')
                .map(|p| p.trim().parse())
                .collect::<Result<_, _>>()
                .with_context(|| format!("--view {custom:?}"))?;
            let [x, y, z] = parts[..] else {
                bail!("--view takes front, side, back, three-quarter or x,y,z")
            };
            let direction = Vec3::new(x, y, z);
            if !direction.is_finite() || direction.length() == 0.0 {
                bail!("--view {custom:?} is not a direction");
            }
            direction
        }
    })
}

pub fn run(
    project_path: &Path,
    out: &Path,
    size: &str,
    strands_per_bundle: u32,
    view: &str,
) -> anyhow::Result<()> {
    let (width, height) = parse_size(size)?;
    let direction = parse_view(view)?;
    let project = hairloom_core::project::load(project_path)?;
    let document = &project.document;
    let context = GpuContext::new_headless()?;
    let options = StrandOptions {
        strands_per_bundle,
        vertices_log2: PREVIEW_VERTICES_LOG2,
        ..StrandOptions::default()
    };
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let strands = generate_parallel(document, &options, threads);
    let vertex_count = (1u32 << PREVIEW_VERTICES_LOG2) + 1;
    let positions: Vec<[f32; 4]> = strands
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.as_vec3().extend(1.0).to_array()))
        .collect();
    // Frame the hair (the head scan's shoulders would make it tiny), padded by a margin.
    let (lo, hi) = document
        .hair_mesh
        .bounds()
        .context("the project has no hair mesh")?;
    let (lo, hi) = (lo.as_vec3(), hi.as_vec3());
    let pad = (hi - lo) * 0.05;
    let camera = Camera::framing(lo - pad, hi + pad, direction);
    let renderer = PreviewRenderer::new(&context);
    let scene = PreviewScene {
        body_positions: &document.body.positions,
        body_triangles: &document.body.triangles,
        strand_positions: &positions,
        vertex_count,
        strand_width_m: (hi - lo).length() * 0.0012,
        // Linear colours (the target is sRGB): dark brown roots, lighter tips.
        root_color: [0.018, 0.008, 0.004],
        tip_color: [0.16, 0.075, 0.03],
        body_color: [0.55, 0.38, 0.30],
        camera,
    };
    let pixels = renderer
        .render(&context, &scene, width, height)
        .map_err(|e| anyhow::anyhow!("rendering: {e}"))?;
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        &pixels,
        width,
        height,
        image::ExtendedColorType::Rgba8,
    )
    .context("encoding PNG")?;
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    hairloom_core::project::write_atomic(out, &png, |_| {})
        .with_context(|| format!("writing {}", out.display()))?;
    println!(
        "{}: {}x{}, {} strands × {} vertices, {}× MSAA, on {}",
        out.display(),
        width,
        height,
        strands.len(),
        vertex_count,
        renderer.sample_count,
        describe(&context.adapter_info)
    );
    Ok(())
}
