//! Rewrites `assets/samples/*.hairloom` from the originals in `assets/head` and `assets/teapot`.
//!
//! Run from the repository root: `cargo run -p hairloom-core --example make_samples`.
//! Optional first argument: the folder holding `head/` and `teapot/` (default `assets`).

use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let data = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "assets".into()));
    let out = PathBuf::from("assets/samples");
    std::fs::create_dir_all(&out)?;
    let glb = std::fs::read(data.join("head/LeePerrySmith.glb"))?;
    let mut projects = hairloom_core::samples::head_projects(&glb)?;
    let teapot = std::fs::read_to_string(data.join("teapot/utah_teapot.txt"))?;
    projects.push((
        "teapot_fur".into(),
        hairloom_core::samples::teapot_project(&teapot)?,
    ));
    for (name, project) in projects {
        let path = out.join(format!("{name}.hairloom"));
        hairloom_core::io::project::save(&path, &project)?;
        let stats = project.document.hair_mesh.stats();
        println!(
            "{}: {} bundles ({} quads, {} triangles), {} vertices ({} interior), {} layers, {} KiB",
            path.display(),
            stats.root_faces,
            stats.quads,
            stats.triangles,
            stats.vertices,
            stats.interior_vertices,
            stats.max_layers,
            std::fs::metadata(&path)?.len() / 1024
        );
    }
    Ok(())
}
