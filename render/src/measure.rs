//! Measuring the GPU path: every precision × filtering switch of strand generation, its
//! error against f32 textures with exact filtering and its time, side by side. The editor's
//! Strands & accuracy panel and `hairloom bench` both show these rows.

use glam::Vec3;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::textures::Precision;

use crate::device::GpuContext;
use crate::renderer::strand_gen::{StrandGenError, StrandGenRenderer, full_detail_plan};

/// One accuracy switch setting measured on the GPU against f32 textures with exact
/// filtering (the setting the CPU mirror tests pin to 1e-5 × size).
#[derive(Clone, Debug, PartialEq)]
pub struct AccuracyRow {
    pub precision: Precision,
    pub filtering: Filtering,
    pub max_error_m: f64,
    pub mean_error_m: f64,
    /// GPU time of generating every strand at full detail (timestamps), else wall time.
    pub generation_ms: f64,
    pub timed_on_gpu: bool,
    /// Submit-to-idle wall time of the same work (what a CPU adapter really costs).
    pub wall_ms: f64,
    /// Why this device cannot run the setting (then the numbers are NaN).
    pub unavailable: Option<String>,
}

/// Generates the document's strands (full detail, `vertex_count` vertices each) with every
/// precision × filtering setting and measures each against f32 + exact.
pub fn measure_accuracy(
    context: &GpuContext,
    generator: &StrandGenRenderer,
    document: &hairloom_core::Document,
    strands_per_bundle: u32,
    vertex_count: u32,
) -> Result<Vec<AccuracyRow>, StrandGenError> {
    let settings = [
        (Precision::F32, Filtering::Exact),
        (Precision::F32, Filtering::Hardware8Bit),
        (Precision::F16, Filtering::Exact),
        (Precision::F16, Filtering::Hardware8Bit),
    ];
    let mut reference: Option<Vec<[f32; 4]>> = None;
    let mut rows = Vec::new();
    for (precision, filtering) in settings {
        let hair = RuntimeHair::from_document(
            document,
            &RuntimeOptions {
                precision,
                strands_per_bundle,
                ..RuntimeOptions::default()
            },
        );
        let gpu = generator.upload(context, &hair)?;
        let plan = full_detail_plan(gpu.root_count, vertex_count);
        let generated = generator
            .generate_positions(context, &gpu, &plan, filtering)
            .and_then(|p| {
                Ok((
                    p,
                    generator.time_generation(context, &gpu, &plan, filtering)?,
                ))
            });
        let (positions, timing) = match generated {
            Ok(generated) => generated,
            // The reference must run; another setting may be unsupported by the device.
            Err(error) if reference.is_some() => {
                rows.push(AccuracyRow {
                    precision,
                    filtering,
                    max_error_m: f64::NAN,
                    mean_error_m: f64::NAN,
                    generation_ms: f64::NAN,
                    timed_on_gpu: false,
                    wall_ms: f64::NAN,
                    unavailable: Some(error.to_string()),
                });
                continue;
            }
            Err(error) => return Err(error),
        };
        let reference = reference.get_or_insert_with(|| positions.clone());
        let (mut max, mut sum) = (0.0f64, 0.0f64);
        for (a, b) in positions.iter().zip(reference.iter()) {
            let d = Vec3::from_slice(&a[..3]).distance(Vec3::from_slice(&b[..3])) as f64;
            max = max.max(d);
            sum += d;
        }
        rows.push(AccuracyRow {
            precision,
            filtering,
            max_error_m: max,
            mean_error_m: sum / positions.len().max(1) as f64,
            generation_ms: timing.gpu_ms.unwrap_or(timing.wall_ms),
            timed_on_gpu: timing.gpu_ms.is_some(),
            wall_ms: timing.wall_ms,
            unavailable: None,
        });
    }
    Ok(rows)
}
