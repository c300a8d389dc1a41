//! What generation can take on a device: the adapter's limits, the mesh path's group limits,
//! and the batch and scratch sizes that bound its memory.

use hairloom_core::runtime::frame_plan::FramePlan;
use hairloom_core::runtime::gpu_types::{BundleGpu, StrandRun};
use hairloom_core::runtime::hair::RuntimeHair;

use super::*;

/// Why generation failed.
#[derive(Debug, thiserror::Error)]
pub enum StrandGenError {
    #[error(
        "{adapter} cannot filter 32-bit float textures in hardware; use exact filtering or f16 textures"
    )]
    NoFloat32Filtering { adapter: String },
    #[error(
        "{adapter} has no mesh shaders (wgpu's EXPERIMENTAL_MESH_SHADER, Vulkan VK_EXT_mesh_shader); choose another generation path"
    )]
    NoMeshShaders { adapter: String },
    #[error("reading generated positions back failed: {0}")]
    Readback(String),
    /// A resource would exceed what the adapter allows; nothing was created.
    #[error("{what} is {value}, above this adapter's {limit_name} of {limit}{hint}")]
    AdapterLimit {
        what: String,
        value: u64,
        limit_name: &'static str,
        limit: u64,
        hint: String,
    },
}

/// Checks `hair` against the device's `limits` before any resource is made: every texture
/// extent against `max_texture_dimension_3d` (all five are 3D textures), and every storage
/// buffer against `max_storage_buffer_binding_size` and `max_buffer_size`. The error names
/// the texture, the limit and, for depth, the bundle with the most layers. (wgpu panics on
/// a descriptor above the limits, so this must come first.)
pub fn check_adapter_limits(
    limits: &wgpu::Limits,
    hair: &RuntimeHair,
) -> Result<(), StrandGenError> {
    let textures = &hair.textures;
    let tallest = textures
        .atlas
        .blocks
        .iter()
        .max_by_key(|b| b.layers)
        .map(|b| (b.bundle, b.layers));
    let max_3d = u64::from(limits.max_texture_dimension_3d);
    for (name, texture) in [
        ("hair_mesh", &textures.hair_mesh),
        ("uv", &textures.uv),
        ("w", &textures.w),
        ("u", &textures.u),
        ("v", &textures.v),
    ] {
        // Depth first: too many layers is the likelier cause, and its hint is the better one.
        for (axis, value) in [
            ("depth", texture.depth),
            ("width", texture.width),
            ("height", texture.height),
        ] {
            if u64::from(value) > max_3d {
                let hint = match (axis, tallest) {
                    ("depth", Some((bundle, layers))) => format!(
                        " (bundle {bundle} has {layers} layers; fewer layers per bundle fit)"
                    ),
                    _ => format!(
                        " ({} bundles need a {}x{} atlas; split the hair into smaller projects)",
                        textures.atlas.blocks.len(),
                        textures.atlas.width,
                        textures.atlas.height
                    ),
                };
                return Err(StrandGenError::AdapterLimit {
                    what: format!("the {name} texture's {axis}"),
                    value: value.into(),
                    limit_name: "max_texture_dimension_3d",
                    limit: max_3d,
                    hint,
                });
            }
        }
    }
    let blocks = textures.atlas.blocks.len() as u64;
    let per_bundle = u64::from(hair.strands_per_bundle);
    let sample_bytes = 2 * per_bundle.max(1) * 8;
    let bundle_bytes = blocks * std::mem::size_of::<BundleGpu>() as u64;
    for (what, bytes) in [
        ("the bundle placement buffer", bundle_bytes),
        ("the root sample buffer", sample_bytes),
    ] {
        for (limit_name, limit) in [
            (
                "max_storage_buffer_binding_size",
                limits.max_storage_buffer_binding_size,
            ),
            ("max_buffer_size", limits.max_buffer_size),
        ] {
            if bytes > limit {
                return Err(StrandGenError::AdapterLimit {
                    what: format!("{what} ({blocks} bundles, {per_bundle} strands each)"),
                    value: bytes,
                    limit_name,
                    limit,
                    hint: " bytes".into(),
                });
            }
        }
    }
    Ok(())
}

/// Refuses mesh-shader generation of `bundles` bundles of `per_bundle` strands at up to
/// `vertex_count` vertices when the task shaders would exceed the device's limits: one task
/// workgroup per bundle (`max_task_workgroup_total_count`), and one bundle's mesh workgroups
/// in one dimension (`max_mesh_workgroup_total_count`, `max_mesh_workgroups_per_dimension`,
/// which wgpu leaves to the driver).
pub fn check_mesh_groups(
    limits: &wgpu::Limits,
    bundles: usize,
    per_bundle: u32,
    vertex_count: u32,
) -> Result<(), StrandGenError> {
    let task_limit = u64::from(limits.max_task_workgroup_total_count);
    if bundles as u64 > task_limit {
        return Err(StrandGenError::AdapterLimit {
            what: "the task workgroups (one per bundle)".into(),
            value: bundles as u64,
            limit_name: "max_task_workgroup_total_count",
            limit: task_limit,
            hint: "; split the hair into smaller projects, or use another generation path".into(),
        });
    }
    let groups = mesh_groups(per_bundle, vertex_count);
    let (limit_name, limit) =
        if limits.max_mesh_workgroups_per_dimension < limits.max_mesh_workgroup_total_count {
            (
                "max_mesh_workgroups_per_dimension",
                limits.max_mesh_workgroups_per_dimension,
            )
        } else {
            (
                "max_mesh_workgroup_total_count",
                limits.max_mesh_workgroup_total_count,
            )
        };
    let limit = u64::from(limit);
    if groups > limit {
        return Err(StrandGenError::AdapterLimit {
            what: format!(
                "one bundle's mesh workgroups ({per_bundle} strands of {vertex_count} vertices)"
            ),
            value: groups,
            limit_name,
            limit,
            hint: "; use fewer strands per bundle or vertices, or another generation path".into(),
        });
    }
    Ok(())
}

/// Whether `device` was created with mesh shaders (wgpu's `EXPERIMENTAL_MESH_SHADER`, which
/// [`crate::device::GpuContext::new_headless`] requests where the adapter has it) and limits
/// that hold `strand_mesh.wgsl`'s groups: 96 invocations, 192 ribbon vertices and 192
/// triangles per mesh workgroup, and its task payload (what NVIDIA, AMD and DirectX 12
/// allow).
pub fn mesh_shaders_available(device: &wgpu::Device) -> bool {
    let limits = device.limits();
    device
        .features()
        .contains(wgpu::Features::EXPERIMENTAL_MESH_SHADER)
        && limits.max_mesh_invocations_per_workgroup >= 96
        && limits.max_mesh_invocations_per_dimension >= 96
        && limits.max_mesh_output_vertices >= 192
        && limits.max_mesh_output_primitives >= 192
        && limits.max_task_payload_size >= size_of::<StrandRun>() as u32
}

/// Strands generated per dispatch. The transient output buffer holds one batch, so scratch
/// memory is `BATCH_STRANDS × vertices × 16` bytes whatever the strand count (34 MB at 65
/// vertices, under the 64 MB bound).
pub const BATCH_STRANDS: usize = 32_768;

/// Vertices of one batch: [`BATCH_STRANDS`] strands at full detail.
pub fn batch_vertex_limit(max_vertex_count: u32) -> usize {
    BATCH_STRANDS * max_vertex_count as usize
}

/// Bytes of the scratch buffer `plan` needs: its largest batch (at most
/// [`batch_vertex_limit`] vertices), 16 bytes per vertex.
pub fn scratch_bytes(plan: &FramePlan) -> u64 {
    let vertices = plan
        .batches
        .iter()
        .map(|b| FramePlan::batch_vertices(b))
        .max()
        .unwrap_or(0);
    (vertices.max(1) * 16) as u64
}

/// Every root at `vertex_count` vertices, no LOD, split into batches of [`BATCH_STRANDS`]
/// strands: what generation without a camera does.
pub fn full_detail_plan(root_count: usize, vertex_count: u32) -> FramePlan {
    let mut plan = FramePlan::default();
    for start in (0..root_count).step_by(BATCH_STRANDS) {
        let strands = BATCH_STRANDS.min(root_count - start);
        let mut runs = hairloom_core::runtime::strand_gen::full_detail_runs(strands, vertex_count);
        for run in &mut runs {
            run.first_root += start as u32;
        }
        plan.batches.push(runs);
        plan.strands += strands;
        plan.vertices += strands * vertex_count as usize;
    }
    plan
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bundle_over_the_mesh_group_limit_is_refused_by_name() {
        let limits = wgpu::Limits {
            max_mesh_workgroup_total_count: 1024,
            max_mesh_workgroups_per_dimension: 65535,
            max_task_workgroup_total_count: 1000,
            ..wgpu::Limits::default()
        };
        assert!(check_mesh_groups(&limits, 500, 64, 33).is_ok());
        let error = check_mesh_groups(&limits, 1001, 64, 33).expect_err("too many bundles");
        assert!(error.to_string().contains("max_task_workgroup_total_count"));
        // 4,096 strands of 1,025 vertices: 11 chunks each.
        assert_eq!(mesh_groups(4096, 1025), 4096 * 11);
        let error = check_mesh_groups(&limits, 500, 4096, 1025).expect_err("over the limit");
        let message = error.to_string();
        assert!(
            message.contains("max_mesh_workgroup_total_count") && message.contains("45056"),
            "{message}"
        );
    }
}
