//! Strokes a sample with the grooming brushes, dab by dab as the editor's Groom drag does
//! (Tools ▸ Drag: Groom): the fringe combed across from the left, a mirrored puff on the
//! crown. Makes the README's brush picture and times the dabs.
//!
//! `cargo run --release -p hairloom-core --example brush_strokes -- IN.hairloom OUT.hairloom`

use glam::DVec3;
use hairloom_core::edit::{BrushDab, BrushKind, apply_brush};
use hairloom_core::simulate::BodySdf;
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, output] = args.as_slice() else {
        return Err("usage: brush_strokes IN.hairloom OUT.hairloom".into());
    };
    let mut project = hairloom_core::io::project::load(std::path::Path::new(input))?;
    let doc = project.document.clone();
    let built = std::time::Instant::now();
    let sdf = BodySdf::for_hair(&doc.body, &doc.hair_mesh);
    println!(
        "the body's distance field: {:.0} ms",
        built.elapsed().as_secs_f64() * 1e3
    );
    let mut mesh = doc.hair_mesh.clone();
    let (lo, hi) = mesh.bounds().ok_or("the project has no hair mesh")?;
    let cx = doc.mirror_plane_x();
    let mut dabs = 0usize;
    let started = std::time::Instant::now();
    // A stroke of 24 dabs from `from` to `to`, each moving the brush by its step.
    let mut stroke = |mesh: &mut hairloom_core::HairMesh,
                      brush: BrushDab,
                      from: DVec3,
                      to: DVec3|
     -> Result<(), hairloom_core::edit::EditError> {
        let n = 24;
        for i in 0..n {
            let a = from.lerp(to, i as f64 / n as f64);
            let b = from.lerp(to, (i + 1) as f64 / n as f64);
            let dab = BrushDab {
                centre_m: b.to_array(),
                motion_m: (b - a).to_array(),
                ..brush
            };
            *mesh = apply_brush(mesh, &sdf, &dab)?.mesh;
            dabs += 1;
        }
        Ok(())
    };
    let brush = |kind, radius_m, strength, mirror_x| BrushDab {
        kind,
        centre_m: [0.0; 3],
        radius_m,
        strength,
        invert: false,
        motion_m: [0.0; 3],
        view_direction: None,
        mirror_x,
        mirror_plane_x: cx,
    };
    let (top, z, width) = (hi.y, 0.5 * (lo.z + hi.z), hi.x - lo.x);
    // A side sweep: the fringe and crown combed from the left across to the right.
    for dz in [0.06, 0.03, 0.0] {
        stroke(
            &mut mesh,
            brush(BrushKind::Comb, 0.05, 0.8, false),
            DVec3::new(cx - 0.25 * width, top - 0.02, z + dz),
            DVec3::new(cx + 0.3 * width, top - 0.03, z + dz),
        )?;
    }
    // Volume at the crown, on both sides of the head's centre.
    stroke(
        &mut mesh,
        brush(BrushKind::Puff, 0.06, 0.6, true),
        DVec3::new(cx, top, z - 0.03),
        DVec3::new(cx, top, z + 0.03),
    )?;
    let elapsed = started.elapsed();
    println!(
        "{dabs} dabs in {:.1} ms ({:.2} ms a dab) on {} columns",
        elapsed.as_secs_f64() * 1e3,
        elapsed.as_secs_f64() * 1e3 / dabs as f64,
        doc.hair_mesh.columns.len()
    );
    project.document.hair_mesh = mesh;
    hairloom_core::io::project::save(std::path::Path::new(output), &project)?;
    Ok(())
}
