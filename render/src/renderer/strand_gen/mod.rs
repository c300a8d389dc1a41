//! GPU strand generation (`shaders/strand_gen.wgsl`): every styled strand vertex computed from
//! the five runtime textures, never stored between frames. Strands are generated in batches
//! of [`BATCH_STRANDS`] into one bounded scratch buffer, which the preview draws from right
//! away; tests and benchmarks read it back or time it.
//!
//! CPU mirror: `hairloom_core::runtime::strand_gen` (`StrandGen::main` for one batch).
//!
//! The stage's jobs, one file each: [`limits`] (what a device can take), [`path`] (where
//! strands are generated), [`upload`] (the asset on the GPU), [`encode`] (recording a batch)
//! and [`readback`] (timing, storing and reading back); [`thick`] generates far hair's thick
//! hairs from their corner strands. The mesh path's work distribution is
//! mirrored in `hairloom_core::runtime::strand_mesh`.

mod encode;
mod limits;
mod path;
mod readback;
mod thick;
mod upload;

pub use encode::*;
pub use hairloom_core::runtime::strand_mesh::{
    MESH_CHUNK_SEGMENTS, MESH_MAX_STRANDS, MESH_STRAND_VERTICES, mesh_groups,
};
pub use limits::*;
pub use path::*;
pub use readback::*;
pub use thick::*;
pub use upload::*;

use hairloom_core::runtime::gpu_types::StrandRun;

use crate::device::GpuContext;
use crate::resources::Tracked;

/// The WGSL source: `shaders/shared/strand_run.wgsl`, `shaders/shared/strand_vertex.wgsl`,
/// `shaders/shared/thick_hair.wgsl`, then `shaders/strand_gen.wgsl` (validated by naga in
/// `cargo test`).
pub const SHADER_SOURCE: &str = concat!(
    include_str!("../../../../shaders/shared/strand_run.wgsl"),
    include_str!("../../../../shaders/shared/thick_hair.wgsl"),
    include_str!("../../../../shaders/shared/strand_vertex.wgsl"),
    include_str!("../../../../shaders/strand_gen.wgsl")
);

/// Pipeline and bind-group layout of `strand_gen` (one per device).
pub struct StrandGenRenderer {
    path: GenerationPath,
    pipeline: Tracked<wgpu::ComputePipeline>,
    bind_group_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    float32_filterable: bool,
}

impl StrandGenRenderer {
    /// Generation by compute, one invocation per strand ([`GenerationPath::ComputePerStrand`]).
    pub fn new(context: &GpuContext) -> Self {
        Self::with_path(context, GenerationPath::default())
    }

    /// Generation where and as `path` says.
    pub fn with_path(context: &GpuContext, path: GenerationPath) -> Self {
        let device = &context.device;
        let float32_filterable = device
            .features()
            .contains(wgpu::Features::FLOAT32_FILTERABLE);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("strand_gen"),
            source: wgpu::ShaderSource::Wgsl(SHADER_SOURCE.into()),
        });
        let storage = |binding: u32, size: u64| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(size),
            },
            count: None,
        };
        let mut entries = source_layout_entries(device, 0, wgpu::ShaderStages::COMPUTE);
        entries.push(storage(4, 16));
        entries.push(wgpu::BindGroupLayoutEntry {
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: wgpu::BufferSize::new(size_of::<StrandRun>() as u64),
            },
            ..storage(10, 0)
        });
        let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("strand_gen"),
            entries: &entries,
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("strand_gen"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });
        let pipeline = context.resources.compute_pipeline(
            device,
            &wgpu::ComputePipelineDescriptor {
                label: Some("strand_gen"),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(match path {
                    GenerationPath::ComputePerVertex => "main_per_vertex",
                    _ => "main",
                }),
                compilation_options: Default::default(),
                cache: None,
            },
        );
        let filter = if float32_filterable {
            wgpu::FilterMode::Linear
        } else {
            wgpu::FilterMode::Nearest
        };
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("strand_gen_linear_clamp"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            address_mode_w: wgpu::AddressMode::ClampToEdge,
            mag_filter: filter,
            min_filter: filter,
            ..Default::default()
        });
        Self {
            path,
            pipeline,
            bind_group_layout,
            sampler,
            float32_filterable,
        }
    }

    /// Refuses a path the device cannot run (mesh shaders without
    /// `EXPERIMENTAL_MESH_SHADER`), naming the adapter.
    pub fn check_path(context: &GpuContext, path: GenerationPath) -> Result<(), StrandGenError> {
        if path.available(&context.device) {
            Ok(())
        } else {
            Err(StrandGenError::NoMeshShaders {
                adapter: crate::device::describe(&context.adapter_info),
            })
        }
    }

    /// Where strands are generated.
    pub fn path(&self) -> GenerationPath {
        self.path
    }
}
