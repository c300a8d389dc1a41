//! Linear hair skinning (`shaders/linear_hair_skinning.wgsl`): the LHS baseline of seed 000
//! §5. Every strand is stored with its guide bindings and offsets
//! ([`SkinnedHair`]); each frame rebuilds the guides' frames from their pose and skins the
//! frame plan's runs into the scratch buffer strand_gen would have written, so a frame draws
//! LHS through the same passes, level of detail included ([`crate::frame::HairSource::Skinned`]).
//!
//! CPU mirror: `hairloom_core::runtime::linear_hair_skinning` (`guide_frames`, `skin_main`).

use hairloom_core::runtime::frame_plan::FramePlan;
use hairloom_core::runtime::gpu_types::StrandRun;
use hairloom_core::runtime::linear_hair_skinning::{
    GUIDES_PER_STRAND, GuidePose, SkinParams, SkinnedHair, SkinningError,
};
use wgpu::util::DeviceExt;

use crate::device::GpuContext;
use crate::renderer::strand_gen::{GenerationTiming, scratch_buffer, upload_runs};
use crate::resources::Tracked;

/// The WGSL source: `shaders/shared/strand_run.wgsl`, then
/// `shaders/linear_hair_skinning.wgsl`.
pub const SHADER_SOURCE: &str = concat!(
    include_str!("../../../shaders/shared/strand_run.wgsl"),
    include_str!("../../../shaders/linear_hair_skinning.wgsl")
);

/// Workgroup size of both entry points.
const WORKGROUP_SIZE: u32 = 64;

/// The two pipelines (guide frames, skinning); one per device.
pub struct LinearHairSkinningRenderer {
    frames_pipeline: Tracked<wgpu::ComputePipeline>,
    skin_pipeline: Tracked<wgpu::ComputePipeline>,
}

/// A skinned hair on the GPU: its guides' pose and frames, and every strand's bindings and
/// offsets.
pub struct GpuSkinnedHair {
    guide_points: Tracked<wgpu::Buffer>,
    references: Tracked<wgpu::Buffer>,
    frames: Tracked<wgpu::Buffer>,
    bindings: Tracked<wgpu::Buffer>,
    offsets: [Tracked<wgpu::Buffer>; GUIDES_PER_STRAND],
    pub vertex_count: u32,
    pub guide_count: u32,
    pub strand_count: usize,
    /// What it keeps on the GPU ([`SkinnedHair::gpu_bytes`]).
    pub bytes: u64,
}

impl LinearHairSkinningRenderer {
    pub fn new(context: &GpuContext) -> Self {
        let device = &context.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("linear_hair_skinning"),
            source: wgpu::ShaderSource::Wgsl(SHADER_SOURCE.into()),
        });
        // Layouts derived per entry point: each binds only what it uses (the skinning pass's
        // eight storage buffers fit the default per-stage limit).
        let pipeline = |entry: &str| {
            context.resources.compute_pipeline(
                device,
                &wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: None,
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                },
            )
        };
        Self {
            frames_pipeline: pipeline("guide_frames"),
            skin_pipeline: pipeline("skin_main"),
        }
    }

    /// Uploads `hair`, posed at rest. Refuses a slot's offsets above the device's storage
    /// binding limit by name.
    pub fn upload(
        &self,
        context: &GpuContext,
        hair: &SkinnedHair,
    ) -> Result<GpuSkinnedHair, String> {
        let device = &context.device;
        let limit = device.limits().max_storage_buffer_binding_size;
        let slot_bytes = (hair.strand_count * hair.vertex_count as usize * 12) as u64;
        if slot_bytes > limit {
            return Err(format!(
                "linear hair skinning: {:.0} MB of offsets per guide slot exceed the adapter's storage binding limit ({:.0} MB)",
                slot_bytes as f64 / 1e6,
                limit as f64 / 1e6
            ));
        }
        let storage = |label: &str, contents: &[u8]| {
            context.resources.buffer_init(
                device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                },
            )
        };
        let guide_points = storage(
            "lhs_guide_points",
            bytemuck::cast_slice(&vec4s(&hair.rest.points)),
        );
        let references = storage(
            "lhs_references",
            bytemuck::cast_slice(&vec4s(&hair.rest.references)),
        );
        let frames = context.resources.buffer(
            device,
            &wgpu::BufferDescriptor {
                label: Some("lhs_guide_frames"),
                size: (hair.rest.points.len().max(1) * 32) as u64,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            },
        );
        let bindings = storage("lhs_bindings", bytemuck::cast_slice(&hair.bindings));
        let offsets = std::array::from_fn(|slot| {
            storage("lhs_offsets", bytemuck::cast_slice(&hair.offsets[slot]))
        });
        Ok(GpuSkinnedHair {
            guide_points,
            references,
            frames,
            bindings,
            offsets,
            vertex_count: hair.vertex_count,
            guide_count: hair.guides.len() as u32,
            strand_count: hair.strand_count,
            bytes: hair.gpu_bytes(),
        })
    }

    /// Moves the guides to `pose` (what a simulation hands over each frame).
    pub fn set_pose(
        &self,
        context: &GpuContext,
        gpu: &GpuSkinnedHair,
        hair: &SkinnedHair,
        pose: &GuidePose,
    ) -> Result<(), SkinningError> {
        hair.check_pose(pose)?;
        context.queue.write_buffer(
            &gpu.guide_points,
            0,
            bytemuck::cast_slice(&vec4s(&pose.points)),
        );
        context.queue.write_buffer(
            &gpu.references,
            0,
            bytemuck::cast_slice(&vec4s(&pose.references)),
        );
        Ok(())
    }

    fn params(
        &self,
        context: &GpuContext,
        gpu: &GpuSkinnedHair,
        first_run: u32,
        batch: &[StrandRun],
    ) -> wgpu::Buffer {
        let params = SkinParams {
            first_run,
            run_count: batch.len() as u32,
            strand_total: batch.iter().map(|run| run.strand_count).sum(),
            vertex_count: gpu.vertex_count,
            guide_count: gpu.guide_count,
            _padding: [0; 3],
        };
        context
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("lhs_params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            })
    }

    /// Records the guides' frames for the current pose: once per frame, before any batch.
    pub fn encode_frames(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        gpu: &GpuSkinnedHair,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let params = self.params(context, gpu, 0, &[]);
        let bind_group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("lhs_guide_frames"),
                layout: &self.frames_pipeline.get_bind_group_layout(0),
                entries: &[
                    entry(0, &params),
                    entry(1, &gpu.guide_points),
                    entry(2, &gpu.frames),
                    entry(3, &gpu.references),
                ],
            });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lhs_guide_frames"),
            timestamp_writes,
        });
        pass.set_pipeline(&self.frames_pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(gpu.guide_count.div_ceil(WORKGROUP_SIZE), 1, 1);
    }

    /// Records the skinning of one batch (`runs[first_run..][..batch.len()]` of the uploaded
    /// `runs`, equal to `batch`) into `output`, as strand_gen's `encode` generates one.
    #[expect(
        clippy::too_many_arguments,
        reason = "one dispatch's resources, passed through unchanged"
    )]
    pub fn encode(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        gpu: &GpuSkinnedHair,
        runs: &wgpu::Buffer,
        first_run: usize,
        batch: &[StrandRun],
        output: &wgpu::Buffer,
        timestamp_writes: Option<wgpu::ComputePassTimestampWrites>,
    ) {
        let params = self.params(context, gpu, first_run as u32, batch);
        let bind_group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("lhs_skin"),
                layout: &self.skin_pipeline.get_bind_group_layout(0),
                entries: &[
                    entry(0, &params),
                    entry(1, &gpu.guide_points),
                    entry(2, &gpu.frames),
                    entry(4, runs),
                    entry(5, &gpu.bindings),
                    entry(6, &gpu.offsets[0]),
                    entry(7, &gpu.offsets[1]),
                    entry(8, &gpu.offsets[2]),
                    entry(9, output),
                ],
            });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("lhs_skin"),
            timestamp_writes,
        });
        pass.set_pipeline(&self.skin_pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        let strands: u32 = batch.iter().map(|run| run.strand_count).sum();
        pass.dispatch_workgroups(strands.div_ceil(WORKGROUP_SIZE), 1, 1);
    }

    /// Skins every batch of `plan` (the guides' frames first) into one reused scratch
    /// buffer and measures it, as [`crate::renderer::strand_gen::StrandGenRenderer::time_generation`]
    /// measures generation.
    pub fn time_skinning(
        &self,
        context: &GpuContext,
        gpu: &GpuSkinnedHair,
        plan: &FramePlan,
    ) -> Result<GenerationTiming, String> {
        let output = scratch_buffer(context, plan);
        let runs = upload_runs(context, plan);
        let timer = crate::device::PassTimer::new(context, plan.batches.len() + 1);
        let mut encoder = context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("lhs_timing"),
            });
        self.encode_frames(
            context,
            &mut encoder,
            gpu,
            timer.as_ref().and_then(|t| t.compute_pass()),
        );
        let mut first_run = 0;
        for batch in &plan.batches {
            let timestamp_writes = timer.as_ref().and_then(|t| t.compute_pass());
            self.encode(
                context,
                &mut encoder,
                gpu,
                &runs,
                first_run,
                batch,
                &output,
                timestamp_writes,
            );
            first_run += batch.len();
        }
        let (wall_ms, gpu_ms) = crate::device::submit_timed(context, encoder, timer)?;
        Ok(GenerationTiming {
            gpu_ms,
            wall_ms,
            scratch_bytes: output.size(),
            batches: plan.batches.len(),
        })
    }

    /// Skins every batch of `plan` and reads the vertices back in scratch order (tests).
    pub fn skin_positions(
        &self,
        context: &GpuContext,
        gpu: &GpuSkinnedHair,
        plan: &FramePlan,
    ) -> Result<Vec<[f32; 4]>, String> {
        let runs_buffer = upload_runs(context, plan);
        let mut positions = Vec::with_capacity(plan.vertices);
        let mut first_run = 0;
        let mut encoder = context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        self.encode_frames(context, &mut encoder, gpu, None);
        context.queue.submit([encoder.finish()]);
        for batch in &plan.batches {
            let bytes = (FramePlan::batch_vertices(batch).max(1) * 16) as u64;
            let output = context.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lhs_output"),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = context.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lhs_readback"),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            let mut encoder = context
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            self.encode(
                context,
                &mut encoder,
                gpu,
                &runs_buffer,
                first_run,
                batch,
                &output,
                None,
            );
            encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
            context.queue.submit([encoder.finish()]);
            let data = crate::device::read_buffer(context, &readback)?;
            let vertices: &[[f32; 4]] = bytemuck::cast_slice(&data);
            positions.extend_from_slice(&vertices[..FramePlan::batch_vertices(batch)]);
            first_run += batch.len();
        }
        Ok(positions)
    }
}

fn entry(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buffer.as_entire_binding(),
    }
}

/// `points` as `vec4<f32>`s (w = 0), at least one (a storage binding is never empty).
fn vec4s(points: &[glam::Vec3]) -> Vec<[f32; 4]> {
    let mut out: Vec<[f32; 4]> = points.iter().map(|p| p.extend(0.0).to_array()).collect();
    if out.is_empty() {
        out.push([0.0; 4]);
    }
    out
}
