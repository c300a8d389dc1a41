//! Running generation to completion: timed (benches), stored (the stored-vertex baseline) and
//! read back (tests against the CPU mirror).

use hairloom_core::runtime::frame_plan::FramePlan;
use hairloom_core::runtime::strand_gen::{Filtering, FilteringMeasure};

use super::*;
use crate::device::{GpuContext, read_buffer};

/// Measured cost of generating a set of strands.
#[derive(Clone, Copy, Debug)]
pub struct GenerationTiming {
    /// Sum of the compute passes' GPU time (timestamp queries); `None` without
    /// `TIMESTAMP_QUERY`.
    pub gpu_ms: Option<f64>,
    /// Wall time from the first submit to the GPU going idle.
    pub wall_ms: f64,
    /// Bytes of the transient output buffer.
    pub scratch_bytes: u64,
    pub batches: usize,
}

impl StrandGenRenderer {
    /// Generates every batch of `plan` into one reused scratch buffer and measures the GPU
    /// time (nothing is read back: this is the cost of generation).
    pub fn time_generation(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        plan: &FramePlan,
        filtering: Filtering,
    ) -> Result<GenerationTiming, StrandGenError> {
        self.check_filtering(context, filtering)?;
        let device = &context.device;
        let output = self.scratch(context, plan);
        let runs = self.upload_runs(context, plan);
        let timer = crate::device::PassTimer::new(context, plan.batches.len());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("strand_gen_timing"),
        });
        let mut first_run = 0;
        for batch in &plan.batches {
            let timestamp_writes = timer.as_ref().and_then(|t| t.compute_pass());
            self.encode(
                context,
                &mut encoder,
                hair,
                &runs,
                first_run,
                batch,
                filtering,
                &output,
                timestamp_writes,
            );
            first_run += batch.len();
        }
        let (wall_ms, gpu_ms) = crate::device::submit_timed(context, encoder, timer)
            .map_err(StrandGenError::Readback)?;
        Ok(GenerationTiming {
            gpu_ms,
            wall_ms,
            scratch_bytes: output.size(),
            batches: plan.batches.len(),
        })
    }

    /// Generates `plan` batch after batch, one submission each: `finish` receives the
    /// batch's encoder (generation recorded), the scratch buffer and the batch's bytes, adds
    /// what it needs (copies) and submits.
    fn each_batch(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        plan: &FramePlan,
        filtering: Filtering,
        mut finish: impl FnMut(wgpu::CommandEncoder, &wgpu::Buffer, u64) -> Result<(), StrandGenError>,
    ) -> Result<(), StrandGenError> {
        self.check_filtering(context, filtering)?;
        let output = self.scratch(context, plan);
        let runs = self.upload_runs(context, plan);
        let mut first_run = 0;
        for batch in &plan.batches {
            let bytes = FramePlan::batch_vertices(batch) as u64 * 16;
            let mut encoder =
                context
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("strand_gen"),
                    });
            self.encode(
                context,
                &mut encoder,
                hair,
                &runs,
                first_run,
                batch,
                filtering,
                &output,
                None,
            );
            first_run += batch.len();
            if bytes > 0 {
                finish(encoder, &output, bytes)?;
            }
        }
        Ok(())
    }

    /// Generates every batch of `plan` once into a persistent vertex buffer (batch after
    /// batch): the explicit-storage baseline, which a renderer then only draws.
    pub fn store(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        plan: &FramePlan,
        filtering: Filtering,
    ) -> Result<wgpu::Buffer, StrandGenError> {
        let stored = context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stored_strands"),
            size: (plan.vertices.max(1) * 16) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut offset = 0u64;
        self.each_batch(
            context,
            hair,
            plan,
            filtering,
            |mut encoder, output, bytes| {
                encoder.copy_buffer_to_buffer(output, 0, &stored, offset, bytes);
                context.queue.submit([encoder.finish()]);
                offset += bytes;
                Ok(())
            },
        )?;
        context
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| StrandGenError::Readback(e.to_string()))?;
        Ok(stored)
    }

    /// Generates every batch of `plan` and reads the vertices back, batch after batch in
    /// scratch order: (position, fraction along the strand).
    pub fn generate_positions(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        plan: &FramePlan,
        filtering: Filtering,
    ) -> Result<Vec<[f32; 4]>, StrandGenError> {
        let mut positions = Vec::with_capacity(plan.vertices);
        self.each_batch(
            context,
            hair,
            plan,
            filtering,
            |mut encoder, output, bytes| {
                let readback = context.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("strand_gen_readback"),
                    size: bytes,
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                });
                encoder.copy_buffer_to_buffer(output, 0, &readback, 0, bytes);
                context.queue.submit([encoder.finish()]);
                let data = read_buffer(context, &readback).map_err(StrandGenError::Readback)?;
                positions.extend_from_slice(bytemuck::cast_slice(&data));
                Ok(())
            },
        )?;
        Ok(positions)
    }

    /// Measures the two filterings on this adapter over up to [`FILTERING_MEASURE_STRANDS`]
    /// of `hair`'s strands at `vertex_count` vertices: generation time of each (GPU
    /// timestamps where they mean something, else wall time; median of three after a
    /// warm-up) and the distance of every hardware-filtered vertex from its exact one.
    /// `tolerance_m` is the error [`FilteringMeasure::choice`] allows.
    pub fn measure_filtering(
        &self,
        context: &GpuContext,
        hair: &GpuHair,
        vertex_count: u32,
        tolerance_m: f64,
    ) -> Result<FilteringMeasure, StrandGenError> {
        let strands = hair.root_count.min(FILTERING_MEASURE_STRANDS);
        let plan = full_detail_plan(strands, vertex_count);
        let trust_timestamps = !context.is_cpu();
        let time = |filtering| -> Result<f64, StrandGenError> {
            self.time_generation(context, hair, &plan, filtering)?;
            let mut times = (0..3)
                .map(|_| {
                    let timing = self.time_generation(context, hair, &plan, filtering)?;
                    Ok(match timing.gpu_ms {
                        Some(ms) if ms > 0.0 && trust_timestamps => ms,
                        _ => timing.wall_ms,
                    })
                })
                .collect::<Result<Vec<f64>, StrandGenError>>()?;
            times.sort_by(f64::total_cmp);
            Ok(times[1])
        };
        let exact_ms = time(Filtering::Exact)?;
        let mut measure = FilteringMeasure {
            exact_ms,
            hardware_ms: None,
            hardware_error_max_m: 0.0,
            hardware_error_mean_m: 0.0,
            tolerance_m,
            strands,
        };
        if self
            .check_filtering(context, Filtering::Hardware8Bit)
            .is_err()
            || strands == 0
        {
            return Ok(measure);
        }
        measure.hardware_ms = Some(time(Filtering::Hardware8Bit)?);
        let exact = self.generate_positions(context, hair, &plan, Filtering::Exact)?;
        let hardware = self.generate_positions(context, hair, &plan, Filtering::Hardware8Bit)?;
        let distances: Vec<f64> = exact
            .iter()
            .zip(&hardware)
            .map(|(a, b)| {
                glam::Vec3::from_slice(&a[..3]).distance(glam::Vec3::from_slice(&b[..3])) as f64
            })
            .collect();
        // A non-finite distance is an unbounded error (`f64::max` would drop a NaN).
        measure.hardware_error_max_m = distances.iter().copied().fold(0.0, |max, d| {
            if d.is_finite() {
                max.max(d)
            } else {
                f64::INFINITY
            }
        });
        measure.hardware_error_mean_m =
            distances.iter().sum::<f64>() / distances.len().max(1) as f64;
        Ok(measure)
    }
}

/// Strands [`StrandGenRenderer::measure_filtering`] generates each way (the first ones, in
/// root order): a quarter of a batch, enough to fill a GPU and short on a CPU adapter.
pub const FILTERING_MEASURE_STRANDS: usize = 8192;
