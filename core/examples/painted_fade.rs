//! Paints a length map that makes a skin fade of the short sample — full length on top, a
//! tenth of it over the sides and back, blended over about a centimetre — with the map brush's
//! own machinery: each map texel's scalp point found by [`RootMapRaster`], the length set
//! from where that point lies on the head. Makes the README's painted-maps picture (render
//! the output with `hairloom render OUT --view side|back`) and times the map brush's dabs.
//!
//! `cargo run --release -p hairloom-core --example painted_fade -- IN.hairloom OUT.hairloom`

use glam::DVec3;
use hairloom_core::edit::paint_maps::{MapDab, RootMapRaster, paint_dab};
use hairloom_core::model::history::Command;
use hairloom_core::model::root_maps::{DEFAULT_ROOT_MAP_SIDE, RootMapChannel, RootMaps};

/// The share of its length the hair keeps at scalp point `p` (head-scan metres): 1 inside an
/// ellipse over the top of the head, a tenth outside it, smoothly between.
fn fade(p: DVec3) -> f64 {
    let r = ((p.x / 0.05).powi(2) + ((p.z - 0.005) / 0.085).powi(2)).sqrt();
    let t = ((1.12 - r) / 0.25).clamp(0.0, 1.0);
    0.1 + 0.9 * t * t * (3.0 - 2.0 * t)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, output] = args.as_slice() else {
        return Err("usage: painted_fade IN.hairloom OUT.hairloom".into());
    };
    let mut project = hairloom_core::io::project::load(std::path::Path::new(input))?;
    let before = project.document.clone();
    let side = DEFAULT_ROOT_MAP_SIDE;
    let started = std::time::Instant::now();
    let raster = RootMapRaster::new(&before.hair_mesh, side, side);
    println!(
        "the scalp rasterised into {side}² map texels: {} covered, {:.1} ms",
        raster.covered(),
        started.elapsed().as_secs_f64() * 1e3
    );
    let mut values = vec![1.0; (side * side) as usize];
    for y in 0..side {
        for x in 0..side {
            if let Some(root) = raster.root_of(x, y) {
                values[(y * side + x) as usize] = fade(root);
            }
        }
    }
    let mut maps = RootMaps::default();
    maps.set_channel_from_image(RootMapChannel::Length, side, side, &values)?;
    // The brush's cost: 100 dabs of the editor's default size over the crown, as a stroke
    // paints them (onto a copy: the fade above is the picture).
    let (lo, hi) = before.hair_mesh.bounds().ok_or("no hair mesh")?;
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
                channel: RootMapChannel::Density,
                centre_m: centre.to_array(),
                radius_m: 0.03,
                value: 0.0,
                colour_srgb: [0; 3],
                strength: 0.5,
                view_direction: None,
                mirror_x: true,
                mirror_plane_x: before.mirror_plane_x(),
            },
        );
    }
    println!(
        "100 density dabs (3 cm, mirrored): {:.2} ms a dab, {changed} texel changes",
        started.elapsed().as_secs_f64() * 1e3 / 100.0
    );
    project.document.root_maps = maps;
    if let Some(command) = Command::record("Paint length", &before, &project.document) {
        project.history.push(command);
    }
    hairloom_core::io::project::save(std::path::Path::new(output), &project)?;
    println!("→ {output}");
    Ok(())
}
