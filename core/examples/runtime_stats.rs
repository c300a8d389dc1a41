//! Prints runtime-texture sizes of each sample: atlas, texture dimensions, bytes per
//! hair-mesh vertex. `cargo run --release -p hairloom-core --example runtime_stats`
use hairloom_core::runtime::textures::{Precision, RuntimeTextures};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!(
        "{:<22} {:>7} {:>9} {:>8} {:>13} {:>10} {:>10}",
        "sample", "bundles", "vertices", "texels", "hair-mesh tex", "B/vtx f32", "B/vtx f16"
    );
    for entry in std::fs::read_dir("assets/samples")? {
        let path = entry?.path();
        let project = hairloom_core::io::project::load(&path)?;
        let mesh = &project.document.hair_mesh;
        let full = RuntimeTextures::build(mesh, Precision::F32);
        let half = RuntimeTextures::build(mesh, Precision::F16);
        let vertices = mesh.vertex_count() as f64;
        let t = &full.hair_mesh;
        println!(
            "{:<22} {:>7} {:>9} {:>8} {:>13} {:>10.1} {:>10.1}",
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            full.atlas.blocks.len(),
            mesh.vertex_count(),
            full.atlas.used_texels(),
            format!("{}x{}x{}", t.width, t.height, t.depth),
            full.gpu_bytes() as f64 / vertices,
            half.gpu_bytes() as f64 / vertices
        );
    }
    Ok(())
}
