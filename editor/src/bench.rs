//! `hairloom bench …`: timings printed as tables with the machine named. Numbers go to
//! BENCHMARKS.md; tests never assert on time.

use std::time::Instant;

use clap::Subcommand;
use glam::DVec3;
use hairloom_core::edit::{ExtrudeDirection, VertexTransform, extrude, transform_vertices};
use hairloom_core::interior::place_interior;
use hairloom_core::{HairMesh, Topology, VertexRef};

#[derive(Subcommand)]
pub enum Which {
    /// Interior-vertex placement at about 200, 2K and 8K hair-mesh vertices.
    Interior {
        /// Repetitions per size (the median is reported).
        #[arg(long, default_value_t = 15)]
        repeat: usize,
    },
    /// Error and time of every accuracy switch against the f64 reference; writes CSV.
    Accuracy {
        /// Project to measure (default: the long wavy head sample).
        #[arg(long)]
        project: Option<std::path::PathBuf>,
        /// Folder for accuracy.csv.
        #[arg(long, default_value = "target/bench")]
        out: std::path::PathBuf,
        /// Strands per bundle measured.
        #[arg(long, default_value_t = 8)]
        strands: u32,
    },
    /// GPU strand generation (timestamp queries) at 10K / 100K / 300K strands, exact vs
    /// hardware filtering, f32 vs f16 textures, with memory against explicit storage.
    Gpu {
        #[arg(long)]
        project: Option<std::path::PathBuf>,
        /// Vertices per strand: 2^N + 1.
        #[arg(long, default_value_t = 5)]
        vertices_log2: u32,
    },
    /// Styled strand vertices per second on all cores at 10K and 100K strands.
    Cpu {
        #[arg(long)]
        project: Option<std::path::PathBuf>,
    },
}

pub fn run(which: Which) -> anyhow::Result<()> {
    match which {
        Which::Interior { repeat } => interior(repeat.max(1)),
        Which::Accuracy {
            project,
            out,
            strands,
        } => crate::accuracy::run(project, &out, strands.max(1)),
        Which::Cpu { project } => crate::accuracy::cpu(project),
        Which::Gpu {
            project,
            vertices_log2,
        } => gpu(project, vertices_log2.min(8)),
    }
}

/// A curved `n × n` scalp (a spherical cap) extruded `layers` times, shaped like hair: each
/// layer is offset along the normal and bent, so interior vertices have real work to do.
fn cap(n: usize, layers: u32) -> anyhow::Result<HairMesh> {
    let mut mesh = hairloom_core::samples::grid_scalp(n, n, |s, t| {
        let (x, y) = (s * 2.0 - 1.0, t * 2.0 - 1.0);
        DVec3::new(x, y, (4.0 - x * x - y * y).sqrt()) * 0.1
    });
    let all: Vec<u32> = (0..mesh.bundles.len() as u32).collect();
    for _ in 0..layers {
        mesh = extrude(
            &mesh,
            &all,
            ExtrudeDirection::AlongNormal { distance: 0.02 },
        )?
        .mesh;
    }
    Ok(mesh)
}

fn median(mut samples: Vec<f64>) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn interior(repeat: usize) -> anyhow::Result<()> {
    println!("Interior-vertex placement (affine fit + harmonic residual, f64), median of {repeat}");
    println!("machine: {}", crate::bench::machine());
    println!(
        "{:>9} {:>9} {:>9} {:>14} {:>14} {:>16}",
        "vertices", "interior", "layers", "all layers ms", "one layer ms", "drag (edit) ms"
    );
    for (n, layers) in [(6usize, 4u32), (20, 4), (40, 4)] {
        let mesh = cap(n, layers)?;
        let topology = Topology::build(&mesh);
        let interior_count = (0..mesh.columns.len())
            .map(|c| {
                (0..mesh.columns[c].positions.len())
                    .filter(|&k| mesh.is_interior(&topology, c, k))
                    .count()
            })
            .sum::<usize>();
        let mut all_layers = Vec::new();
        let mut one_layer = Vec::new();
        let mut drag = Vec::new();
        // A rim vertex on layer 2 moved as in an interactive drag (transform + placement).
        let rim = VertexRef {
            column: 0,
            layer: 2,
        };
        for r in 0..repeat {
            let mut scratch = mesh.clone();
            let start = Instant::now();
            place_interior(&mut scratch, None);
            all_layers.push(start.elapsed().as_secs_f64() * 1e3);
            let start = Instant::now();
            place_interior(&mut scratch, Some(&[2]));
            one_layer.push(start.elapsed().as_secs_f64() * 1e3);
            let offset = [0.001 * (r as f64 + 1.0), 0.0, 0.0];
            let start = Instant::now();
            let _edited =
                transform_vertices(&mesh, &[rim], VertexTransform::Translate { offset }, 0.05)?;
            drag.push(start.elapsed().as_secs_f64() * 1e3);
        }
        println!(
            "{:>9} {:>9} {:>9} {:>14.3} {:>14.3} {:>16.3}",
            mesh.vertex_count(),
            interior_count,
            layers,
            median(all_layers),
            median(one_layer),
            median(drag)
        );
    }
    Ok(())
}

/// CPU model and core count, for the header of every table.
pub fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    format!("{model}, {cores} cores")
}

fn gpu(project: Option<std::path::PathBuf>, vertices_log2: u32) -> anyhow::Result<()> {
    use hairloom_core::runtime::{Filtering, Precision, RuntimeTextures};
    use hairloom_render::device::{GpuContext, describe};
    use hairloom_render::strand_gen::StrandGenRenderer;
    let path = project.unwrap_or_else(|| {
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../assets/samples/head_long_wavy.hairloom")
    });
    let project = hairloom_core::project::load(&path)?;
    let mesh = &project.document.hair_mesh;
    let context = GpuContext::new_headless()?;
    let renderer = StrandGenRenderer::new(&context);
    let vertex_count = (1u32 << vertices_log2) + 1;
    println!(
        "GPU strand generation (positions from the hair-mesh texture; no styling yet): {}",
        path.display()
    );
    println!("adapter: {}", describe(&context.adapter_info));
    println!("machine: {}", machine());
    println!(
        "{:>8} {:>8} {:>9} {:>10} {:>9} {:>11} {:>10} {:>12} {:>12} {:>8}",
        "strands",
        "textures",
        "filtering",
        "GPU ms",
        "wall ms",
        "M verts/s",
        "scratch MB",
        "textures MB",
        "explicit MB",
        "ratio"
    );
    for precision in [Precision::F32, Precision::F16] {
        let textures = RuntimeTextures::build(mesh, precision);
        let bundles = textures.atlas.blocks.len().max(1);
        for target in [10_000usize, 100_000, 300_000] {
            let per_bundle = target.div_ceil(bundles);
            let samples = hairloom_core::runtime::RootSamples::progressive(
                hairloom_core::strands::sample_set_size(per_bundle as u32),
                1,
            );
            let roots = textures.document_roots(&project.document.styling, &samples, per_bundle);
            let hair = renderer.upload(
                &context,
                &textures,
                &roots,
                &hairloom_core::gpu_types::styling_array(&project.document.styling),
            );
            let vertices = roots.len() as f64 * vertex_count as f64;
            // Explicit storage: every strand vertex as three f32.
            let explicit_mb = vertices * 12.0 / 1e6;
            let textures_mb = textures.gpu_bytes() as f64 / 1e6;
            for filtering in [Filtering::Exact, Filtering::Hardware8Bit] {
                let time = || renderer.time_generation(&context, &hair, vertex_count, filtering);
                // One warm-up run (pipeline compilation, first-touch allocations), then the median of 3.
                let _ = time();
                let mut runs = Vec::new();
                for _ in 0..3 {
                    match time() {
                        Ok(timing) => runs.push(timing),
                        Err(error) => {
                            println!(
                                "{:>8} {:>8?} {:>9?}   skipped: {error}",
                                roots.len(),
                                precision,
                                filtering
                            );
                            break;
                        }
                    }
                }
                if runs.is_empty() {
                    continue;
                }
                runs.sort_by(|a, b| a.wall_ms.total_cmp(&b.wall_ms));
                let timing = runs[runs.len() / 2];
                let gpu_ms = timing.gpu_ms.unwrap_or(f64::NAN);
                let rate_ms = if gpu_ms.is_finite() && gpu_ms > 0.0 {
                    gpu_ms
                } else {
                    timing.wall_ms
                };
                println!(
                    "{:>8} {:>8} {:>9} {:>10.2} {:>9.2} {:>11.1} {:>10.1} {:>12.3} {:>12.1} {:>7.0}×",
                    roots.len(),
                    format!("{precision:?}"),
                    if filtering == Filtering::Exact {
                        "exact"
                    } else {
                        "hardware"
                    },
                    gpu_ms,
                    timing.wall_ms,
                    vertices / rate_ms / 1e3,
                    timing.scratch_bytes as f64 / 1e6,
                    textures_mb,
                    explicit_mb,
                    explicit_mb / textures_mb
                );
            }
        }
    }
    Ok(())
}
