//! The runtime asset a game loads and the GPU draws from, and the CPU mirrors of the GPU
//! stages. Each shader `shaders/X.wgsl` has its mirror here in `X.rs` (functions named after
//! the WGSL ones) and its renderer in `render/src/renderer/X.rs`.

pub mod atlas;
pub mod far_lod;
pub mod frame_plan;
pub mod gpu_types;
pub mod hair;
pub mod half;
pub mod linear_hair_skinning;
pub mod preview_hair;
pub mod strand_gen;
pub mod strand_mesh;
pub mod textures;
pub mod thick_hair;

#[cfg(test)]
pub(crate) mod test_meshes {
    use glam::DVec3;

    use crate::model::mesh::HairMesh;
    use crate::model::mesh::test_meshes::grid;

    /// A 4 × 3 grid of three layers bent into curved columns: every segment a real cubic.
    pub(crate) fn curved_mesh() -> HairMesh {
        let mut mesh = grid(4, 3, 3, 0.4);
        for column in &mut mesh.columns {
            let r = column.positions[0];
            for (k, p) in column.positions.iter_mut().enumerate() {
                let k = k as f64;
                *p += DVec3::new(0.2 * k * k, 0.1 * (r.x + k).sin(), 0.05 * r.y * k);
            }
        }
        mesh.update_w();
        mesh
    }
}
