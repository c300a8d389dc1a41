//! Paints a colour map on the long wavy sample — two light "money piece" streaks at the
//! front and a copper panel over one side of the head — with the colour brush's own machinery: each map
//! texel's scalp point found by [`RootMapRaster`], its colour and weight set from where that
//! point lies on the head. Makes the README's painted-colour picture (render the output with
//! `hairloom render OUT --view front|back`), and times a colour dab and the per-root colour
//! resolve the renderers do when the map changes.
//!
//! `cargo run --release -p hairloom-core --example painted_colour -- IN.hairloom OUT.hairloom`

use glam::DVec3;
use hairloom_core::edit::paint_maps::{MapDab, RootMapRaster, paint_dab};
use hairloom_core::model::history::Command;
use hairloom_core::model::root_maps::{DEFAULT_ROOT_MAP_SIDE, RootMapChannel, RootMaps};

/// `t` eased from 0 at `edge0` to 1 at `edge1`.
fn smoothstep(edge0: f64, edge1: f64, x: f64) -> f64 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The colour (sRGB bytes) and weight painted at scalp point `p`, for hair bounds `lo … hi`
/// (+z the face, +y up).
fn paint_at(p: DVec3, lo: DVec3, hi: DVec3) -> ([f64; 3], f64) {
    let size = hi - lo;
    let centre = 0.5 * (lo + hi);
    let front = smoothstep(0.55, 0.75, (p.z - lo.z) / size.z);
    // Two streaks a fifth of the head's width apart, each a tenth wide.
    let side = ((p.x - centre.x).abs() / size.x - 0.1).abs();
    let streak = front * (1.0 - smoothstep(0.03, 0.06, side));
    // The copper panel: the head's left side (−x) beyond a sixth of its width.
    let panel = smoothstep(0.15, 0.22, (centre.x - p.x) / size.x);
    if streak >= panel {
        ([0.93, 0.80, 0.60], streak)
    } else {
        ([0.62, 0.22, 0.08], panel)
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, output] = args.as_slice() else {
        return Err("usage: painted_colour IN.hairloom OUT.hairloom".into());
    };
    let mut project = hairloom_core::io::project::load(std::path::Path::new(input))?;
    let before = project.document.clone();
    let side = DEFAULT_ROOT_MAP_SIDE;
    let raster = RootMapRaster::new(&before.hair_mesh, side, side);
    // The scalp's own bounds (the roots'), not the hair's: long hair reaches far behind.
    let roots: Vec<DVec3> = (0..side * side)
        .filter_map(|i| raster.root_of(i % side, i / side))
        .collect();
    let lo = roots.iter().fold(DVec3::INFINITY, |a, p| a.min(*p));
    let hi = roots.iter().fold(DVec3::NEG_INFINITY, |a, p| a.max(*p));
    println!("scalp roots from {lo} to {hi}");
    let mut image = vec![[0.0; 4]; (side * side) as usize];
    for y in 0..side {
        for x in 0..side {
            if let Some(root) = raster.root_of(x, y) {
                let (rgb, weight) = paint_at(root, lo, hi);
                image[(y * side + x) as usize] = [rgb[0], rgb[1], rgb[2], weight];
            }
        }
    }
    let mut maps = RootMaps::default();
    maps.set_colour_from_image(side, side, &image)?;
    // The brush's cost: 100 colour dabs of the editor's default size over the crown, as a
    // stroke paints them (onto a copy: the picture is the map above).
    let mut scratch = maps.clone();
    let started = std::time::Instant::now();
    let mut changed = 0;
    for i in 0..100 {
        let t = i as f64 / 99.0;
        let centre = DVec3::new(lo.x + (hi.x - lo.x) * t, hi.y, 0.5 * (lo.z + hi.z));
        changed += paint_dab(
            &mut scratch,
            &raster,
            &MapDab {
                channel: RootMapChannel::Colour,
                centre_m: centre.to_array(),
                radius_m: 0.03,
                value: 1.0,
                colour_srgb: [170, 70, 35],
                strength: 0.5,
                view_direction: None,
                mirror_x: true,
                mirror_plane_x: before.mirror_plane_x(),
            },
        );
    }
    println!(
        "100 colour dabs (3 cm, mirrored, {side}² map): {:.3} ms a dab, {changed} texel changes",
        started.elapsed().as_secs_f64() * 1e3 / 100.0
    );
    project.document.root_maps = maps;
    // What the renderers redo when the map changes: every root's colour, once.
    let runtime = hairloom_core::runtime::hair::RuntimeHair::from_document(
        &project.document,
        &hairloom_core::runtime::hair::RuntimeOptions::default(),
    );
    let started = std::time::Instant::now();
    let paint = runtime.root_paint();
    println!(
        "per-root colours of {} roots: {:.2} ms",
        paint.len(),
        started.elapsed().as_secs_f64() * 1e3
    );
    if let Some(command) = Command::record("Paint colour", &before, &project.document) {
        project.history.push(command);
    }
    hairloom_core::io::project::save(std::path::Path::new(output), &project)?;
    println!("→ {output}");
    Ok(())
}
