//! Recording generation: the bindings strand_gen's passes share, the runs and parameters of a
//! batch, the scratch buffer, and the compute dispatches.

use hairloom_core::runtime::frame_plan::FramePlan;
use hairloom_core::runtime::gpu_types::{
    BundleGpu, FILTERING_EXACT, FILTERING_HARDWARE, StrandGenParams, StrandRun, StylingGpu,
};
use hairloom_core::runtime::strand_gen::Filtering;
use wgpu::util::DeviceExt;

use super::*;
use crate::device::GpuContext;
use crate::resources::Tracked;

/// Where the ribbon vertex shader binds strand_gen's resources: their compute bindings plus
/// this (`shaders/shared/ribbon_generated.wgsl`).
pub const GENERATED_BINDING_OFFSET: u32 = 16;

/// strand_gen's bindings other than its output (4) and runs (10).
const SOURCE_BINDINGS: [u32; 11] = [0, 1, 2, 3, 5, 6, 7, 8, 9, 11, 15];

/// The layout entries of strand_gen's resources other than its output and runs (params,
/// bundles, the five textures and their sampler, styling, samples) at their compute bindings
/// plus `offset`: the compute layout's (offset 0) and the generating ribbons'
/// ([`GENERATED_BINDING_OFFSET`]). 32-bit float textures are only filterable with
/// `FLOAT32_FILTERABLE`; without it the layout declares them unfilterable and hardware
/// filtering is refused ([`StrandGenRenderer::check_filtering`]).
pub fn source_layout_entries(
    device: &wgpu::Device,
    offset: u32,
    visibility: wgpu::ShaderStages,
) -> Vec<wgpu::BindGroupLayoutEntry> {
    let float32_filterable = device
        .features()
        .contains(wgpu::Features::FLOAT32_FILTERABLE);
    let storage = |size: u64| wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only: true },
        has_dynamic_offset: false,
        min_binding_size: wgpu::BufferSize::new(size),
    };
    let texture = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float {
            filterable: float32_filterable,
        },
        view_dimension: wgpu::TextureViewDimension::D3,
        multisampled: false,
    };
    SOURCE_BINDINGS
        .iter()
        .map(|&binding| wgpu::BindGroupLayoutEntry {
            binding: binding + offset,
            visibility,
            ty: match binding {
                0 => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: wgpu::BufferSize::new(size_of::<StrandGenParams>() as u64),
                },
                1 => storage(size_of::<BundleGpu>() as u64),
                3 => wgpu::BindingType::Sampler(if float32_filterable {
                    wgpu::SamplerBindingType::Filtering
                } else {
                    wgpu::SamplerBindingType::NonFiltering
                }),
                9 => storage(size_of::<StylingGpu>() as u64),
                11 => storage(8),
                // The painted maps: read with textureLoad, never filtered.
                15 => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                _ => texture,
            },
            count: None,
        })
        .collect()
}

/// Workgroup size of `main` in `strand_gen.wgsl`.
const WORKGROUP_SIZE: u32 = 64;

impl StrandGenRenderer {
    /// Refuses hardware filtering of f32 textures on adapters that cannot filter them.
    pub fn check_filtering(
        &self,
        context: &GpuContext,
        filtering: Filtering,
    ) -> Result<(), StrandGenError> {
        if filtering == Filtering::Hardware8Bit && !self.float32_filterable {
            return Err(StrandGenError::NoFloat32Filtering {
                adapter: context.adapter_info.name.clone(),
            });
        }
        Ok(())
    }

    /// Uploads the runs of every batch of `plan`, one after another ([`upload_runs`]).
    pub fn upload_runs(&self, context: &GpuContext, plan: &FramePlan) -> wgpu::Buffer {
        upload_runs(context, plan)
    }

    /// Records the generation of one batch (`runs[first_run..][..batch.len()]` of the uploaded
    /// `runs` buffer, equal to `batch`) into `output` as one compute pass of `encoder`.
    #[expect(
        clippy::too_many_arguments,
        reason = "one dispatch's resources, passed through unchanged"
    )]
    pub fn encode(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        hair: &GpuHair,
        runs: &wgpu::Buffer,
        first_run: usize,
        batch: &[StrandRun],
        filtering: Filtering,
        output: &wgpu::Buffer,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let vertex_total = FramePlan::batch_vertices(batch) as u32;
        let strand_total: u32 = batch.iter().map(|run| run.strand_count).sum();
        let params = self.params_buffer(context, hair, filtering, first_run as u32, batch);
        let mut entries = self.source_entries(0, hair, &params);
        entries.push(wgpu::BindGroupEntry {
            binding: 4,
            resource: output.as_entire_binding(),
        });
        entries.push(wgpu::BindGroupEntry {
            binding: 10,
            resource: runs.as_entire_binding(),
        });
        let bind_group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("strand_gen"),
                layout: &self.bind_group_layout,
                entries: &entries,
            });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("strand_gen"),
            timestamp_writes,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        let invocations = match self.path {
            GenerationPath::ComputePerVertex => vertex_total,
            _ => strand_total,
        };
        pass.dispatch_workgroups(invocations.div_ceil(WORKGROUP_SIZE), 1, 1);
    }

    /// The uniform parameters of generating `batch` (`runs[first_run..]` of the uploaded runs).
    pub fn params_buffer(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        filtering: Filtering,
        first_run: u32,
        batch: &[StrandRun],
    ) -> wgpu::Buffer {
        let params = StrandGenParams {
            position_offset: [
                hair.position_offset[0],
                hair.position_offset[1],
                hair.position_offset[2],
                0.0,
            ],
            vertex_total: FramePlan::batch_vertices(batch) as u32,
            run_count: batch.len() as u32,
            filtering: match filtering {
                Filtering::Exact => FILTERING_EXACT,
                Filtering::Hardware8Bit => FILTERING_HARDWARE,
            },
            first_run,
            per_bundle: hair.per_bundle.max(1),
            sample_set: hair.sample_set,
            strand_total: batch.iter().map(|run| run.strand_count).sum(),
            _padding: 0,
        };
        context
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("strand_gen_params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            })
    }

    /// The bind-group entries of `hair` for [`source_layout_entries`] at `offset`.
    pub fn source_entries<'a>(
        &'a self,
        offset: u32,
        hair: &'a GpuHair,
        params: &'a wgpu::Buffer,
    ) -> Vec<wgpu::BindGroupEntry<'a>> {
        let view = |binding: u32, view: &'a wgpu::TextureView| wgpu::BindGroupEntry {
            binding: binding + offset,
            resource: wgpu::BindingResource::TextureView(view),
        };
        let buffer = |binding: u32, buffer: &'a wgpu::Buffer| wgpu::BindGroupEntry {
            binding: binding + offset,
            resource: buffer.as_entire_binding(),
        };
        vec![
            buffer(0, params),
            buffer(1, &hair.bundle_buffer),
            view(2, &hair.hair_mesh),
            wgpu::BindGroupEntry {
                binding: 3 + offset,
                resource: wgpu::BindingResource::Sampler(&self.sampler),
            },
            view(5, &hair.uv),
            view(6, &hair.w),
            view(7, &hair.u),
            view(8, &hair.v),
            buffer(9, &hair.styling),
            buffer(11, &hair.samples),
            view(15, &hair.root_maps_view),
        ]
    }

    /// A scratch buffer for the largest batch of `plan`.
    pub fn scratch(&self, context: &GpuContext, plan: &FramePlan) -> Tracked<wgpu::Buffer> {
        scratch_buffer(context, plan)
    }
}

/// A scratch buffer for the largest batch of `plan`: what generation, or skinning in its
/// place, writes each batch's vertices into.
pub fn scratch_buffer(context: &GpuContext, plan: &FramePlan) -> Tracked<wgpu::Buffer> {
    context.resources.buffer(
        &context.device,
        &wgpu::BufferDescriptor {
            label: Some("strand_gen_scratch"),
            size: scratch_bytes(plan),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        },
    )
}

/// The runs of every batch of `plan`, one after another (one empty run where there is none:
/// a storage binding is never empty): what generation, or skinning in its place, reads.
pub fn upload_runs(context: &GpuContext, plan: &FramePlan) -> wgpu::Buffer {
    let mut runs: Vec<StrandRun> = plan.batches.iter().flatten().copied().collect();
    if runs.is_empty() {
        runs.push(StrandRun::default());
    }
    context
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("strand_gen_runs"),
            contents: bytemuck::cast_slice(&runs),
            usage: wgpu::BufferUsages::STORAGE,
        })
}
