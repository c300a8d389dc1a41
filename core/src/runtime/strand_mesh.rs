//! Mirror of the mesh path's work distribution (`shaders/strand_mesh.wgsl` `mesh_work` and
//! `ts_main`): how many mesh workgroups a bundle's strands take and how strands and chunks
//! map onto them. The renderer writes these sizes into the shader
//! (`hairloom_render::renderer::shader_composer`) and checks the device's limits with
//! [`mesh_groups`].

/// Strand vertices (invocations) of one mesh workgroup in `strand_mesh.wgsl` (these three
/// sizes are written into the shader from here). 96: 192 ribbon vertices of 8 attribute slots
/// is 24 KiB of outputs, and the group's workgroup memory stays under NVIDIA's 28 KiB.
pub const MESH_STRAND_VERTICES: u32 = 96;
/// Segments per chunk of a strand longer than a mesh workgroup (even: chunks start on even
/// vertices).
pub const MESH_CHUNK_SEGMENTS: u32 = 94;
/// Most whole strands in one mesh workgroup.
pub const MESH_MAX_STRANDS: u32 = 16;

/// Mesh workgroups a task shader launches for `strands` strands of `vertex_count` vertices
/// (mirror of `strand_mesh.wgsl` `mesh_work` and `ts_main`).
pub fn mesh_groups(strands: u32, vertex_count: u32) -> u64 {
    let n = vertex_count.max(2);
    let (per_group, chunks) = if n <= MESH_STRAND_VERTICES {
        ((MESH_STRAND_VERTICES / n).min(MESH_MAX_STRANDS), 1)
    } else {
        (1, (n - 1).div_ceil(MESH_CHUNK_SEGMENTS))
    };
    u64::from(strands.div_ceil(per_group)) * u64::from(chunks)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mesh path's work distribution (as `strand_mesh.wgsl` `ms_main` maps groups and
    /// invocations): every segment of every strand is drawn exactly once, chunks start on
    /// even vertices, and no group exceeds its invocations or output arrays.
    #[test]
    fn mesh_groups_draw_every_segment_once() {
        for n in 2..=300u32 {
            for strands in [1u32, 3, 16, 17, 100] {
                let (per_group, chunks) = if n <= MESH_STRAND_VERTICES {
                    ((MESH_STRAND_VERTICES / n).min(MESH_MAX_STRANDS), 1)
                } else {
                    (1, (n - 1).div_ceil(MESH_CHUNK_SEGMENTS))
                };
                let chunk_vertices = if chunks == 1 {
                    n
                } else {
                    MESH_CHUNK_SEGMENTS + 1
                };
                let mut drawn = vec![0u32; (strands * (n - 1)) as usize];
                let groups = mesh_groups(strands, n);
                for group in 0..groups as u32 {
                    let first_strand = (group / chunks) * per_group;
                    let k0 = (group % chunks) * MESH_CHUNK_SEGMENTS;
                    assert!(first_strand < strands && k0 < n - 1, "n {n}, group {group}");
                    assert_eq!(k0 % 2, 0);
                    let in_group = per_group.min(strands - first_strand);
                    let chunk = chunk_vertices.min(n - k0);
                    assert!(in_group * chunk <= MESH_STRAND_VERTICES);
                    assert!(2 * in_group * (chunk - 1) <= 2 * MESH_STRAND_VERTICES);
                    for slot in 0..in_group {
                        for j in 0..chunk - 1 {
                            let strand = first_strand + slot;
                            drawn[(strand * (n - 1) + k0 + j) as usize] += 1;
                        }
                    }
                }
                assert!(
                    drawn.iter().all(|&d| d == 1),
                    "n {n}, {strands} strands: {:?}",
                    drawn.iter().position(|&d| d != 1)
                );
            }
        }
    }
}
