//! `hairloom bench …`: timings printed as tables with the machine named. Numbers go to
//! BENCHMARKS.md; tests never assert on time.

use std::time::Instant;

use clap::Subcommand;
use glam::DVec3;
use hairloom_core::edit::{ExtrudeDirection, VertexTransform, extrude, transform_vertices};
use hairloom_core::geometry::interior::place_interior;
use hairloom_core::{HairMesh, Topology, VertexRef};
use hairloom_editor::app::viewport::{FrameQuality, InteractiveEffort};

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
    /// GPU strand generation and frames (timestamp queries) at 10K / 100K / 300K strands:
    /// generation alone, frames with LOD off and on (near and far), and the same strands
    /// drawn from a pre-generated vertex buffer (the explicit-storage baseline), exact vs
    /// hardware filtering, f16 vs f32 textures; time and memory ratios side by side.
    Gpu {
        #[arg(long)]
        project: Option<std::path::PathBuf>,
        /// Vertices per strand at full detail: 2^N + 1.
        #[arg(long, default_value_t = 5)]
        vertices_log2: u32,
        /// Strand counts to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [10_000usize, 100_000, 300_000])]
        strands: Vec<usize>,
        /// Frame size, WIDTHxHEIGHT.
        #[arg(long, default_value = "1280x720")]
        size: String,
        /// Texture precisions to measure, comma-separated (f16, f32).
        #[arg(long, value_delimiter = ',', default_values_t = [String::from("f16"), String::from("f32")])]
        textures: Vec<String>,
        /// Measured runs per row after one warm-up (the median is reported).
        #[arg(long, default_value_t = 3)]
        runs: usize,
        /// Generation paths to measure, comma-separated: compute (one invocation per strand),
        /// compute-per-vertex, vertex-shader (in the ribbons, no scratch), mesh-shader (task
        /// and mesh shaders; a row says it skipped where the adapter has none).
        #[arg(long, value_enum, value_delimiter = ',', default_values = ["compute", "compute-per-vertex", "vertex-shader", "mesh-shader"])]
        paths: Vec<super::GenerationArg>,
        /// Filtering to measure, comma-separated (exact, hardware).
        #[arg(long, value_enum, value_delimiter = ',', default_values = ["exact", "hardware"])]
        filtering: Vec<super::FilteringArg>,
        /// Share of the strands that are guides in the linear hair skinning baseline (LHS,
        /// seed 000 §5: 1 %); 0 leaves LHS out.
        #[arg(long, default_value_t = hairloom_core::runtime::linear_hair_skinning::DEFAULT_GUIDE_SHARE)]
        guides: f64,
    },
    /// Edit-to-frame latency in the editor's viewport setting: a styling slider tick through
    /// a full rebuild and re-upload (the old path) and through the in-place styling update
    /// (the new one), a vertex drag (mesh edit, rebuild, upload), and a frame alone; each from
    /// the edit to the frame's pixels read back, median of `runs`. Then the slider tick while
    /// the artist interacts: the viewport's interactive frames (no optional effect, fewer
    /// pixels) against the full picture, the input-to-frame latency the frame budget buys.
    Edit {
        #[arg(long)]
        project: Option<std::path::PathBuf>,
        /// Frame size, WIDTHxHEIGHT.
        #[arg(long, default_value = "960x720")]
        size: String,
        #[arg(long, default_value_t = 9)]
        runs: usize,
        /// Folder for the full picture and the budget-adapted interactive frame (PNG), to
        /// look at what interaction shows.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
    },
    /// Styled strand vertices per second on all cores at 10K and 100K strands.
    Cpu {
        #[arg(long)]
        project: Option<std::path::PathBuf>,
    },
    /// Accuracy against time of the lighting effects: each head sample near, middle and far,
    /// path-traced on the CPU as the reference, and on the GPU in every configuration; the
    /// ꟻLIP error and frame time of each (CSV and PNG grids).
    Shading {
        /// Samples to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [String::from("head_long_wavy"), String::from("head_curly"), String::from("head_short_straight")])]
        samples: Vec<String>,
        #[command(flatten)]
        path_traced: PathTracedArgs,
    },
    /// Far hair (seed 001 Fig. 7): each head sample as it shrinks from 50% to 0.3% of the
    /// picture, every strand, strand LOD (seed 000) and far hair's thick hairs, each with its
    /// ꟻLIP against the CPU path tracer on full geometry, frame time and segments drawn.
    Far {
        /// Samples to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [String::from("head_long_wavy"), String::from("head_curly")])]
        samples: Vec<String>,
        #[command(flatten)]
        path_traced: PathTracedArgs,
    },
    /// Fur (seed 002): the furry teapot and a short-haired head at three sizes on screen,
    /// strands, shells + fins, and the two cross-faded, each with its ꟻLIP against the CPU
    /// path tracer on the strands, frame time, and the fur's memory beside seed 002's 1.6 MB.
    Fur {
        /// Samples to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [String::from("teapot_fur"), String::from("head_short_straight")])]
        samples: Vec<String>,
        #[command(flatten)]
        path_traced: PathTracedArgs,
    },
    /// What the method's switches cost, side by side in one run: styling on vs off, the
    /// material's ombré off vs on, MSAA 1× / 4× / 8×, exact vs hardware texture filtering with the hardware weights' error,
    /// and the filtering the game runtime chooses on this adapter.
    Switches {
        #[arg(long)]
        project: Option<std::path::PathBuf>,
        /// Strand counts to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [10_000usize, 100_000])]
        strands: Vec<usize>,
        /// Frame size, WIDTHxHEIGHT.
        #[arg(long, default_value = "1280x720")]
        size: String,
        /// Measured runs per row after one warm-up (the median is reported).
        #[arg(long, default_value_t = 3)]
        runs: usize,
        /// Vertices per strand at full detail: 2^N + 1.
        #[arg(long, default_value_t = 5)]
        vertices_log2: u32,
    },
    /// Many characters in one frame (the paper's Fig. 1 crowd): one uploaded bundle drawn N
    /// times with its own transform and LOD through the game runtime; frame time and GPU
    /// memory against N.
    Crowd {
        #[arg(long)]
        project: Option<std::path::PathBuf>,
        /// Character counts to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [1usize, 4, 16, 64])]
        characters: Vec<usize>,
        /// Strands per character (rounded up to whole bundles).
        #[arg(long, default_value_t = 10_000)]
        strands: usize,
        /// Frame size, WIDTHxHEIGHT.
        #[arg(long, default_value = "1280x720")]
        size: String,
        /// Measured runs per row after one warm-up (the median is reported).
        #[arg(long, default_value_t = 1)]
        runs: usize,
        /// Write each crowd's frame as crowd_N.png into this folder.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Generate in the ribbons' vertex shader (no compute pass, no scratch); the same as
        /// `--generation vertex-shader`.
        #[arg(long, conflicts_with = "generation")]
        vertex_shader: bool,
        /// Where strands are generated (default: the game runtime's choice, mesh shaders
        /// where the adapter has them, else compute per strand).
        #[arg(long, value_enum)]
        generation: Option<super::GenerationArg>,
        /// Every character with its own hair model, varied from `--samples` (styling,
        /// strand count): seed 000 Fig. 1 (heads) and Fig. 9 (`--samples teapot_fur
        /// --strands 50000`).
        #[arg(long)]
        unique: bool,
        /// Level of detail off: every strand at full detail (the paper's "without LOD").
        #[arg(long)]
        no_lod: bool,
        /// Samples the unique models are varied from, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [String::from("head_long_wavy"), String::from("head_curly"), String::from("head_short_straight"), String::from("head_long_straight"), String::from("head_ponytail")])]
        samples: Vec<String>,
    },
    /// What each lighting effect costs: the frame with none, each alone, the scene's own
    /// combination and everything, at 10K and 100K strands (time and GPU memory).
    Effects {
        #[arg(long)]
        project: Option<std::path::PathBuf>,
        /// Strand counts to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [10_000usize, 100_000])]
        strands: Vec<usize>,
        /// Frame size, WIDTHxHEIGHT.
        #[arg(long, default_value = "960x960")]
        size: String,
        /// Measured runs per row after one warm-up (the median is reported).
        #[arg(long, default_value_t = 3)]
        runs: usize,
    },
    /// The hair-mesh simulator's accuracy against time: sub-steps × iterations against a
    /// converged reference on each head sample turning its head in wind; position error,
    /// time per simulated second and per 60 Hz frame, memory (CSV and a PNG chart).
    Sim {
        /// Samples to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_values_t = [String::from("head_long_wavy"), String::from("head_curly"), String::from("head_short_straight")])]
        samples: Vec<String>,
        /// Simulated seconds per run.
        #[arg(long, default_value_t = 1.5)]
        seconds: f64,
        /// The converged reference: sub-steps and iterations.
        #[arg(long, default_value_t = 32)]
        reference_substeps: u32,
        #[arg(long, default_value_t = 24)]
        reference_iterations: u32,
        /// Folder for sim.csv and sim.png.
        #[arg(long, default_value = "target/bench")]
        out: std::path::PathBuf,
    },
}

/// What the path-traced benches (`shading`, `far`, `fur`) share: the picture, the hair, the
/// reference's budget and the timing runs.
#[derive(clap::Args)]
pub struct PathTracedArgs {
    /// Picture side in pixels.
    #[arg(long, default_value_t = 256)]
    size: u32,
    #[arg(long, default_value_t = 16)]
    strands_per_bundle: u32,
    /// Path-tracing samples per pixel of the reference.
    #[arg(long, default_value_t = 64)]
    spp: u32,
    #[arg(long, default_value_t = 24)]
    bounces: u32,
    /// Time budget of each reference picture (it stops after the pass that passes it).
    #[arg(long, default_value_t = 600.0)]
    max_seconds: f64,
    /// Measured GPU runs per row after one warm-up (the median is reported).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Folder for the CSV (named after the bench) and the PNG grids.
    #[arg(long, default_value = "target/bench")]
    out: std::path::PathBuf,
}

impl PathTracedArgs {
    fn settings(
        self,
        bench: super::bench_shading::ShadingBench,
        samples: Vec<String>,
    ) -> super::bench_shading::ShadingSettings {
        super::bench_shading::ShadingSettings {
            bench,
            samples,
            size: self.size,
            strands_per_bundle: self.strands_per_bundle.clamp(1, 4096),
            samples_per_pixel: self.spp.max(1),
            max_bounces: self.bounces,
            max_seconds: self.max_seconds,
            runs: self.runs.max(1),
            out: self.out,
        }
    }
}

pub fn run(which: Which) -> anyhow::Result<()> {
    match which {
        Which::Interior { repeat } => interior(repeat.max(1)),
        Which::Sim {
            samples,
            seconds,
            reference_substeps,
            reference_iterations,
            out,
        } => super::bench_sim::run(
            &samples,
            seconds,
            (reference_substeps, reference_iterations),
            &out,
        ),
        Which::Accuracy {
            project,
            out,
            strands,
        } => super::accuracy::run(project, &out, strands.max(1)),
        Which::Cpu { project } => super::accuracy::cpu(project),
        Which::Shading {
            samples,
            path_traced,
        } => super::bench_shading::run(
            &path_traced.settings(super::bench_shading::ShadingBench::Shading, samples),
        ),
        Which::Far {
            samples,
            path_traced,
        } => super::bench_shading::run(
            &path_traced.settings(super::bench_shading::ShadingBench::Far, samples),
        ),
        Which::Fur {
            samples,
            path_traced,
        } => super::bench_shading::run(
            &path_traced.settings(super::bench_shading::ShadingBench::Fur, samples),
        ),
        Which::Effects {
            project,
            strands,
            size,
            runs,
        } => super::bench_effects::run(project, &strands, &size, runs.max(1)),
        Which::Switches {
            project,
            strands,
            size,
            runs,
            vertices_log2,
        } => super::bench_switches::run(&super::bench_switches::SwitchSettings {
            project,
            strands,
            size,
            runs,
            vertices_log2,
        }),
        Which::Crowd {
            project,
            characters,
            strands,
            size,
            runs,
            out,
            vertex_shader,
            generation,
            unique,
            samples,
            no_lod,
        } => super::bench_crowd::run(&super::bench_crowd::CrowdSettings {
            unique,
            samples,
            no_lod,
            project,
            characters,
            strands,
            size,
            runs,
            out,
            generation: if vertex_shader {
                Some(hairloom_render::renderer::strand_gen::GenerationPath::VertexShader)
            } else {
                generation.map(Into::into)
            },
        }),
        Which::Edit {
            project,
            size,
            runs,
            out,
        } => edit_latency(project, &size, runs.max(1), out.as_deref()),
        Which::Gpu {
            project,
            vertices_log2,
            strands,
            size,
            textures,
            runs,
            paths,
            filtering,
            guides,
        } => {
            let paths: Vec<_> = paths.into_iter().map(Into::into).collect();
            let filterings: Vec<_> = filtering.into_iter().map(Into::into).collect();
            let precisions = textures
                .iter()
                .map(|t| match t.as_str() {
                    "f16" => Ok(hairloom_core::runtime::textures::Precision::F16),
                    "f32" => Ok(hairloom_core::runtime::textures::Precision::F32),
                    other => Err(anyhow::anyhow!(
                        "--textures takes f16 and f32, not {other:?}"
                    )),
                })
                .collect::<anyhow::Result<Vec<_>>>()?;
            gpu(
                project,
                vertices_log2.min(8),
                &strands,
                &size,
                &precisions,
                runs,
                &paths,
                &filterings,
                guides,
            )
        }
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
    println!("machine: {}", super::machine());
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

/// Median of `runs` measurements by wall time (after one warm-up), or the first error.
pub(super) fn median_timing<T: Copy, E>(
    mut measure: impl FnMut() -> Result<T, E>,
    runs: usize,
    wall_ms: impl Fn(&T) -> f64,
) -> Result<T, E> {
    measure()?;
    let mut timings = Vec::with_capacity(runs);
    for _ in 0..runs.max(1) {
        timings.push(measure()?);
    }
    timings.sort_by(|a, b| wall_ms(a).total_cmp(&wall_ms(b)));
    Ok(timings[timings.len() / 2])
}

/// GPU milliseconds when timestamp queries exist and mean something, else wall milliseconds
/// from submission to idle (marked `*`). A CPU adapter (lavapipe) runs passes on the same
/// cores as everything else and its compute timestamps do not cover the work, so wall time is
/// its true cost.
pub(super) fn gpu_or_wall(
    trust_timestamps: bool,
    gpu_ms: Option<f64>,
    wall_ms: f64,
) -> (f64, &'static str) {
    match gpu_ms {
        Some(ms) if ms > 0.0 && trust_timestamps => (ms, ""),
        _ => (wall_ms, "*"),
    }
}

#[expect(
    clippy::too_many_arguments,
    reason = "the command's options, passed through"
)]
fn gpu(
    project: Option<std::path::PathBuf>,
    vertices_log2: u32,
    counts: &[usize],
    size: &str,
    precisions: &[hairloom_core::runtime::textures::Precision],
    runs: usize,
    paths: &[hairloom_render::renderer::strand_gen::GenerationPath],
    filterings: &[hairloom_core::runtime::strand_gen::Filtering],
    guide_share: f64,
) -> anyhow::Result<()> {
    use hairloom_core::runtime::frame_plan::LodSettings;
    use hairloom_core::runtime::strand_gen::Filtering;
    use hairloom_render::device::{GpuContext, describe};
    use hairloom_render::preview::{Camera, HairSource, PreviewRenderer};
    use hairloom_render::renderer::shader_composer::RibbonInput;
    use hairloom_render::renderer::strand_gen::{
        GenerationPath, StrandGenRenderer, full_detail_plan,
    };
    let path = project.unwrap_or_else(hairloom_core::samples::default_sample_path);
    let (width, height) = super::render::parse_size(size)?;
    let document = hairloom_core::io::project::load(&path)?.document;
    let context = GpuContext::new_headless()?;
    let generator = StrandGenRenderer::new(&context);
    let generators: Vec<StrandGenRenderer> = paths
        .iter()
        .filter(
            |&&path| match StrandGenRenderer::check_path(&context, path) {
                Ok(()) => true,
                Err(error) => {
                    println!("{}: skipped: {error}", path.name());
                    false
                }
            },
        )
        .map(|&path| StrandGenRenderer::with_path(&context, path))
        .collect();
    let preview = PreviewRenderer::new(&context);
    let body = hairloom_render::renderer::preview_body::GpuBody::upload(&context, &document.body);
    // The method's own cost (generation against stored vertices): no optional effect, so the
    // rows compare with earlier runs; `hairloom bench effects` measures the effects.
    let unlit = hairloom_core::model::scene::Scene {
        effects: document.scene.effects.none(),
        ..document.scene.clone()
    };
    let vertex_count = (1u32 << vertices_log2.min(8)) + 1;
    let max_binding = context.device.limits().max_storage_buffer_binding_size;
    let trust = !context.is_cpu();
    println!(
        "GPU strand generation and drawing (styled, {vertex_count} vertices per strand at full detail): {}",
        path.display()
    );
    println!("adapter: {}", describe(&context.adapter_info));
    println!("machine: {}", super::machine());
    println!(
        "frame: {width}x{height}, {}× MSAA; times are GPU timestamps (* = wall time from submit to idle: no usable timestamps, e.g. a CPU adapter)",
        preview.sample_count
    );
    println!(
        "{:>8} {:>4} {:>8} {:<18} {:<22} {:>9} {:>9} {:>11} {:>10} {:>10} {:>9}",
        "strands",
        "tex",
        "filter",
        "path",
        "mode",
        "vertices",
        "ms",
        "vs stored",
        "scratch MB",
        "memory MB",
        "mem ratio"
    );
    for &precision in precisions {
        let mut renderable = hairloom_core::runtime::hair::RuntimeHair::from_document(
            &document,
            &hairloom_core::runtime::hair::RuntimeOptions {
                precision,
                strands_per_bundle: 1,
                ..Default::default()
            },
        );
        let bundles = renderable.textures.atlas.blocks.len().max(1);
        let (lo, hi) = renderable
            .textures
            .hair_bounds()
            .ok_or_else(|| anyhow::anyhow!("no bundle grows hair"))?;
        let pad = (hi - lo) * 0.05;
        let direction = glam::Vec3::new(0.75, 0.25, 1.0);
        let near = Camera::framing(lo - pad, hi + pad, direction);
        // The same head four times further away: what LOD is for.
        let far = Camera {
            eye: near.target + (near.eye - near.target) * 4.0,
            ..near
        };
        for &target in counts {
            renderable.set_strands_per_bundle(target.div_ceil(bundles) as u32)?;
            let hair = generator.upload(&context, &renderable)?;
            let full = full_detail_plan(hair.root_count, vertex_count);
            let stored_bytes = full.vertices as u64 * 16;
            let hair_mb = hair.bytes as f64 / 1e6;
            for &filtering in filterings {
                let filter_name = if filtering == Filtering::Exact {
                    "exact"
                } else {
                    "hardware"
                };
                let row = |path: &str,
                           mode: &str,
                           drawn: usize,
                           ms: (f64, &str),
                           versus: Option<f64>,
                           scratch: u64,
                           memory: f64,
                           ratio: Option<f64>| {
                    println!(
                        "{:>8} {:>4} {:>8} {:<18} {:<22} {:>9} {:>8.2}{:1} {:>11} {:>10.1} {:>10.2} {:>9}",
                        hair.root_count,
                        format!("{precision:?}"),
                        filter_name,
                        path,
                        mode,
                        drawn,
                        ms.0,
                        ms.1,
                        versus.map_or("".into(), |v| format!("{v:.2}×")),
                        scratch as f64 / 1e6,
                        memory,
                        ratio.map_or("".into(), |r| {
                            if r < 10.0 {
                                format!("{r:.2}×")
                            } else {
                                format!("{r:.0}×")
                            }
                        }),
                    );
                };
                // Generation alone, per compute path (the vertex-shader path generates
                // only while drawing).
                let mut generation = Vec::new();
                let mut refused = None;
                for generator in generators
                    .iter()
                    .filter(|g| g.path().ribbon_input() == RibbonInput::Buffer)
                {
                    match median_timing(
                        || generator.time_generation(&context, &hair, &full, filtering),
                        runs,
                        |t| t.wall_ms,
                    ) {
                        Ok(timing) => generation.push((generator.path(), timing)),
                        Err(error) => refused = Some(error),
                    }
                }
                if let Some(error) = refused {
                    println!(
                        "{:>8} {:>4?} {:>8}   skipped: {error}",
                        hair.root_count, precision, filter_name
                    );
                    continue;
                }
                // The explicit-storage baseline: the same strands generated once into a
                // persistent vertex buffer, then only drawn.
                let stored = if stored_bytes <= max_binding {
                    Some(generator.store(&context, &hair, &full, filtering)?)
                } else {
                    None
                };
                let scene = |hair_source, camera| {
                    hairloom_render::preview::default_scene(
                        &body,
                        hair_source,
                        vertex_count,
                        (lo, hi),
                        camera,
                        &unlit,
                    )
                };
                let frame = |source, camera| {
                    median_timing(
                        || preview.time_frame(&context, &scene(source, camera), width, height),
                        runs,
                        |t| t.wall_ms,
                    )
                };
                let stored_frame = match &stored {
                    Some(buffer) => Some(frame(
                        HairSource::Stored {
                            buffer,
                            strand_count: hair.root_count,
                        },
                        near,
                    )?),
                    None => None,
                };
                let stored_ms = stored_frame.map(|t| gpu_or_wall(trust, t.gpu_ms, t.wall_ms).0);
                let explicit_mb = stored_bytes as f64 / 1e6;
                for (path, timing) in &generation {
                    row(
                        path.name(),
                        "generate only",
                        full.vertices,
                        gpu_or_wall(trust, timing.gpu_ms, timing.wall_ms),
                        None,
                        timing.scratch_bytes,
                        hair_mb,
                        Some(explicit_mb / hair_mb),
                    );
                }
                let mut compute_frames = std::collections::HashMap::new();
                // Each method's frames: near and four times further, LOD off and on.
                let frame_modes = [
                    ("frame, LOD off", near, false),
                    ("frame, LOD on", near, true),
                    ("frame ×4 far, LOD off", far, false),
                    ("frame ×4 far, LOD on", far, true),
                ];
                for generator in &generators {
                    for (mode, camera, enabled) in frame_modes {
                        let lod = LodSettings {
                            enabled,
                            ..LodSettings::default()
                        };
                        let timing = frame(
                            HairSource::Generated {
                                generator,
                                hair: &hair,
                                filtering,
                                lod,
                                far: None,
                                fur: None,
                            },
                            camera,
                        )?;
                        let ms = gpu_or_wall(trust, timing.gpu_ms, timing.wall_ms);
                        if generator.path() == GenerationPath::ComputePerStrand {
                            compute_frames.insert(mode, ms.0);
                        }
                        row(
                            generator.path().name(),
                            mode,
                            timing.vertices,
                            ms,
                            stored_ms.map(|s| s / ms.0),
                            timing.scratch_bytes,
                            hair_mb,
                            Some(explicit_mb / hair_mb),
                        );
                    }
                }
                match stored_frame {
                    Some(timing) => row(
                        "stored",
                        "frame, stored vertices",
                        full.vertices,
                        gpu_or_wall(trust, timing.gpu_ms, timing.wall_ms),
                        Some(1.0),
                        0,
                        explicit_mb,
                        Some(1.0),
                    ),
                    None => println!(
                        "{:>8} {:>4?} {:>8} {:<18} {:<22} skipped: {explicit_mb:.0} MB exceeds the adapter's storage binding limit",
                        hair.root_count, precision, filter_name, "stored", "frame, stored vertices"
                    ),
                }
                // The LHS baseline (seed 000 §5): these strands, generated once and read
                // back, stored with 3 guides' weights and offsets, skinned every frame.
                if guide_share > 0.0 {
                    match skinned_baseline(
                        &context,
                        &generator,
                        &hair,
                        &full,
                        filtering,
                        vertex_count,
                        guide_share,
                    ) {
                        Ok((skinner, skinned)) => {
                            let lhs_mb = skinned.bytes as f64 / 1e6;
                            let mut ratios = Vec::new();
                            let skin = median_timing(
                                || skinner.time_skinning(&context, &skinned, &full),
                                runs,
                                |t| t.wall_ms,
                            )
                            .map_err(|e| anyhow::anyhow!(e))?;
                            let skin_ms = gpu_or_wall(trust, skin.gpu_ms, skin.wall_ms);
                            if let Some((_, generated)) = generation
                                .iter()
                                .find(|(path, _)| *path == GenerationPath::ComputePerStrand)
                            {
                                let generated =
                                    gpu_or_wall(trust, generated.gpu_ms, generated.wall_ms).0;
                                ratios.push(format!(
                                    "skin ÷ generate only {:.2}×",
                                    skin_ms.0 / generated
                                ));
                            }
                            row(
                                "linear skinning",
                                "skin only",
                                full.vertices,
                                skin_ms,
                                None,
                                skin.scratch_bytes,
                                lhs_mb,
                                Some(explicit_mb / lhs_mb),
                            );
                            for (mode, camera, enabled) in frame_modes {
                                let lod = LodSettings {
                                    enabled,
                                    ..LodSettings::default()
                                };
                                let timing = frame(
                                    HairSource::Skinned {
                                        skinner: &skinner,
                                        skinned: &skinned,
                                        hair: &hair,
                                        lod,
                                    },
                                    camera,
                                )?;
                                let ms = gpu_or_wall(trust, timing.gpu_ms, timing.wall_ms);
                                if let Some(generated) = compute_frames.get(mode) {
                                    ratios.push(format!("{mode} {:.2}×", ms.0 / generated));
                                }
                                row(
                                    "linear skinning",
                                    mode,
                                    timing.vertices,
                                    ms,
                                    stored_ms.map(|s| s / ms.0),
                                    timing.scratch_bytes,
                                    lhs_mb,
                                    Some(explicit_mb / lhs_mb),
                                );
                            }
                            println!(
                                "{:>8} {:>4?} {:>8}   LHS ({} guides, {:.1} %) frame ÷ generated (compute per strand): {}; memory {:.1} MB ÷ {:.2} MB = {:.0}×",
                                hair.root_count,
                                precision,
                                filter_name,
                                skinned.guide_count,
                                guide_share * 100.0,
                                ratios.join(", "),
                                lhs_mb,
                                hair_mb,
                                lhs_mb / hair_mb
                            );
                        }
                        Err(error) => println!(
                            "{:>8} {:>4?} {:>8} {:<18} skipped: {error}",
                            hair.root_count, precision, filter_name, "linear skinning"
                        ),
                    }
                }
            }
        }
    }
    println!(
        "vs stored: stored-vertex frame time ÷ this row's time (> 1: faster than the baseline)."
    );
    println!(
        "linear skinning (LHS): every strand stored with 3 guides' weights and offsets, guides' frames and every vertex skinned each frame; memory = offsets + bindings + guides (its mem ratio < 1: more than stored vertices). Seed 000 (RTX 4090, 300K strands, no LOD, no MSAA): generated 1.8 ms vs LHS 18 ms (LHS 10× slower); 39 KB of textures vs 340 MB for LHS (8,700×)."
    );
    println!(
        "memory: textures + bundle placements + root samples + styling on the GPU (stored: the vertex buffer); mem ratio: stored vertex bytes ÷ this memory."
    );
    Ok(())
}

/// The LHS baseline of `hair`: its strands generated at full detail (`full`), read back,
/// bound to `guide_share` of them as guides and uploaded.
fn skinned_baseline(
    context: &hairloom_render::device::GpuContext,
    generator: &hairloom_render::renderer::strand_gen::StrandGenRenderer,
    hair: &hairloom_render::renderer::strand_gen::GpuHair,
    full: &hairloom_core::runtime::frame_plan::FramePlan,
    filtering: hairloom_core::runtime::strand_gen::Filtering,
    vertex_count: u32,
    guide_share: f64,
) -> anyhow::Result<(
    hairloom_render::renderer::linear_hair_skinning::LinearHairSkinningRenderer,
    hairloom_render::renderer::linear_hair_skinning::GpuSkinnedHair,
)> {
    use hairloom_core::runtime::linear_hair_skinning::{SkinnedHair, check_size};
    use hairloom_render::renderer::linear_hair_skinning::LinearHairSkinningRenderer;
    check_size(full.vertices)?;
    let generated = generator.generate_positions(context, hair, full, filtering)?;
    let points: Vec<glam::Vec3> = generated
        .iter()
        .map(|p| glam::Vec3::from_slice(&p[..3]))
        .collect();
    drop(generated);
    let skinned = SkinnedHair::bind(&points, vertex_count, guide_share)?;
    drop(points);
    let skinner = LinearHairSkinningRenderer::new(context);
    let gpu = skinner
        .upload(context, &skinned)
        .map_err(|e| anyhow::anyhow!(e))?;
    Ok((skinner, gpu))
}

/// See [`Which::Edit`].
fn edit_latency(
    project: Option<std::path::PathBuf>,
    size: &str,
    runs: usize,
    out: Option<&std::path::Path>,
) -> anyhow::Result<()> {
    use hairloom_core::model::change::ChangeKind;
    use hairloom_core::runtime::frame_plan::LodSettings;
    use hairloom_core::runtime::hair::RuntimeOptions;
    use hairloom_core::runtime::strand_gen::Filtering;
    use hairloom_render::device::{GpuContext, describe};
    use hairloom_render::hair_asset::{AssetChange, HairAsset};
    use hairloom_render::preview::{Camera, PreviewRenderer};
    use hairloom_render::renderer::strand_gen::StrandGenRenderer;
    let path = project.unwrap_or_else(hairloom_core::samples::default_sample_path);
    let (width, height) = super::render::parse_size(size)?;
    let mut document = hairloom_core::io::project::load(&path)?.document;
    let context = GpuContext::new_headless()?;
    let generator = StrandGenRenderer::new(&context);
    let preview = PreviewRenderer::new(&context);
    // What the viewport draws by default.
    let view = hairloom_editor::app::viewport::ViewSettings::default();
    let options = RuntimeOptions {
        precision: view.precision,
        strands_per_bundle: view.strands_per_bundle,
        ..RuntimeOptions::default()
    };
    let vertex_count = (1u32 << super::render::PREVIEW_VERTICES_LOG2) + 1;
    // The viewport's asset: every edit below is a change of its kind taken to the GPU by
    // `HairAsset::apply`, as the viewport's paint callback does.
    let mut asset = HairAsset::from_document(&context, &generator, &document, &options)?;
    let bounds = asset.bounds();
    let pad = (bounds.1 - bounds.0) * 0.05;
    let camera = Camera::framing(
        bounds.0 - pad,
        bounds.1 + pad,
        glam::Vec3::new(0.75, 0.25, 1.0),
    );
    // The frame of `lighting` at `width × height` (the viewport's full picture with the
    // document's scene; an interactive frame without effects and smaller).
    let frame_of = |asset: &HairAsset,
                    lighting: &hairloom_core::model::scene::Scene,
                    quality: FrameQuality|
     -> anyhow::Result<Vec<u8>> {
        let [width, height] = quality.size([width, height]);
        let scene = hairloom_render::preview::default_scene(
            asset.body(),
            asset.source(
                &generator,
                Filtering::Exact,
                quality.lod(LodSettings::default()),
            ),
            vertex_count,
            bounds,
            camera,
            lighting,
        );
        let plan = preview.plan(&scene, width, height);
        Ok(preview.render(&context, &scene, &plan, width, height)?)
    };
    let full_scene = document.scene.clone();
    let frame = |asset: &HairAsset| frame_of(asset, &full_scene, FrameQuality::Full).map(|_| ());
    frame(&asset)?; // warm-up: pipelines, first allocations
    let timed = |mut step: Box<dyn FnMut(usize) -> anyhow::Result<()> + '_>| {
        let mut samples = Vec::with_capacity(runs);
        for run in 0..runs {
            let start = Instant::now();
            step(run)?;
            samples.push(start.elapsed().as_secs_f64() * 1e3);
        }
        anyhow::Ok(median(samples))
    };
    // Each edit is timed twice: to the GPU holding the new data (edit, build, upload, queue
    // idle) and to the frame's pixels read back (what the viewport shows).
    let idle = || {
        context
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map(|_| ())
            .map_err(|e| anyhow::anyhow!("{e}"))
    };
    let timed_both = |mut step: Box<dyn FnMut(usize, bool) -> anyhow::Result<()> + '_>| {
        let to_gpu = timed(Box::new(|run| step(run, false)))?;
        let to_pixels = timed(Box::new(|run| step(run, true)))?;
        anyhow::Ok([to_gpu, to_pixels])
    };
    // Takes `document`'s change of `kind` to the asset; says what the asset did.
    let apply = |asset: &mut HairAsset,
                 document: &hairloom_core::Document,
                 kind: ChangeKind|
     -> anyhow::Result<ChangeKind> {
        let change = AssetChange::build(document, kind, &options)
            .ok_or_else(|| anyhow::anyhow!("a {kind:?} leaves the asset alone"))?;
        Ok(asset.apply(&context, &generator, change)?)
    };
    let frame_only = timed(Box::new(|_| frame(&asset)))?;
    let curl = |run: usize| 0.002 + 0.0001 * run as f64;
    let mut styled = document.clone();
    let rebuild = timed_both(Box::new(|run, draw| {
        styled.styling.global.curl.radius_m = curl(run);
        apply(&mut asset, &styled, ChangeKind::Rebuild)?;
        if draw { frame(&asset) } else { idle() }
    }))?;
    let in_place = timed_both(Box::new(|run, draw| {
        document.styling.global.curl.radius_m = curl(run);
        apply(&mut asset, &document, ChangeKind::Restyle)?;
        if draw { frame(&asset) } else { idle() }
    }))?;
    let topology = Topology::build(&document.hair_mesh);
    let vertex = document
        .hair_mesh
        .columns
        .iter()
        .enumerate()
        .find_map(|(c, column)| {
            let k = column.positions.len() - 1;
            (k > 0 && !document.hair_mesh.is_interior(&topology, c, k)).then_some(VertexRef {
                column: c as u32,
                layer: k as u32,
            })
        })
        .ok_or_else(|| anyhow::anyhow!("no exterior tip vertex to drag"))?;
    let mut dragged = document.clone();
    let mut drag_in_place = true;
    let drag = timed_both(Box::new(|run, draw| {
        let outcome = transform_vertices(
            &document.hair_mesh,
            &[vertex],
            VertexTransform::Translate {
                offset: [0.0, 0.0005 * (run + 1) as f64, 0.0],
            },
            0.0,
        )?;
        dragged.hair_mesh = outcome.mesh;
        // A drag is a reshape: the runtime data is made again and its textures rewritten in
        // place (the body stays uploaded).
        drag_in_place &= apply(&mut asset, &dragged, ChangeKind::Reshape)? == ChangeKind::Reshape;
        if draw { frame(&asset) } else { idle() }
    }))?;
    println!(
        "edit-to-frame latency, {} ({} strands per bundle, {width}x{height}); {}; adapter {}",
        path.display(),
        options.strands_per_bundle,
        super::machine(),
        describe(&context.adapter_info)
    );
    println!(
        "{:<46} {:>12} {:>8} {:>12} {:>8}",
        "edit", "to GPU ms", "ratio", "to pixels ms", "ratio"
    );
    let row = |name: &str, [gpu_ms, pixels_ms]: [f64; 2], ratio: bool| {
        let versus = |ms: f64, base: f64| {
            if ratio {
                format!("{:.3}×", ms / base)
            } else {
                String::new()
            }
        };
        println!(
            "{name:<46} {gpu_ms:>12.2} {:>8} {pixels_ms:>12.2} {:>8}",
            versus(gpu_ms, rebuild[0]),
            versus(pixels_ms, rebuild[1])
        );
    };
    row(
        "styling slider, rebuild + re-upload (before)",
        rebuild,
        true,
    );
    row(
        "styling slider, styling buffers in place (now)",
        in_place,
        true,
    );
    row(
        if drag_in_place {
            "vertex drag, edit + runtime data, textures in place"
        } else {
            "vertex drag, edit + runtime data + re-upload"
        },
        drag,
        true,
    );
    row("frame alone (no edit)", [0.0, frame_only], false);

    // While the artist drags the slider the viewport draws interactive frames (see
    // `FRAME_BUDGET_MS`): no optional effect, a fraction of the pixels, a LOD detail bias.
    let interactive_scene = hairloom_core::model::scene::Scene {
        effects: full_scene.effects.none(),
        ..full_scene.clone()
    };
    println!(
        "input-to-frame while interacting (styling buffers in place; frame budget {} ms):",
        hairloom_editor::app::viewport::FRAME_BUDGET_MS
    );
    println!(
        "{:<46} {:>12} {:>8}",
        "slider tick, frame", "to pixels ms", "ratio"
    );
    let interactive = |scale, detail| FrameQuality::Interactive { scale, detail };
    let mut tick = 0;
    let mut slider_tick = |quality: FrameQuality, lighting| {
        tick += 1;
        document.styling.global.curl.radius_m = curl(tick);
        apply(&mut asset, &document, ChangeKind::Restyle)?;
        frame_of(&asset, lighting, quality)
    };
    let mut full_ms = 0.0;
    for (name, quality, lighting) in [
        (
            "full picture (every tick, before the budget)",
            FrameQuality::Full,
            &full_scene,
        ),
        (
            "interactive, no effects, 100% size",
            interactive(1.0, 1.0),
            &interactive_scene,
        ),
        (
            "interactive, no effects, 50% size",
            interactive(0.5, 1.0),
            &interactive_scene,
        ),
        (
            "interactive, no effects, 25% size",
            interactive(0.25, 1.0),
            &interactive_scene,
        ),
        (
            "interactive, 25% size, 25% LOD detail",
            interactive(0.25, 0.25),
            &interactive_scene,
        ),
        (
            "interactive, 25% size, 5% LOD detail",
            interactive(0.25, 0.05),
            &interactive_scene,
        ),
    ] {
        let ms = timed(Box::new(|_| slider_tick(quality, lighting).map(|_| ())))?;
        if quality == FrameQuality::Full {
            full_ms = ms;
            if let Some(out) = out {
                std::fs::create_dir_all(out)?;
                let pixels = slider_tick(quality, lighting)?;
                super::render::write_png(&out.join("edit_full.png"), &pixels, width, height)?;
            }
        }
        println!(
            "{name:<46} {ms:>12.2} {:>8}",
            format!("{:.3}×", ms / in_place[1])
        );
    }
    // What the viewport does: the effort starts at the budget's share of the full frame and
    // learns from each interactive frame; after it settles, the frames it draws.
    let mut effort = InteractiveEffort::from_full_frame(full_ms);
    let mut settled = Vec::new();
    for step in 0..12 {
        let start = Instant::now();
        slider_tick(effort.quality(), &interactive_scene)?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        effort.learn(ms);
        if step >= 8 {
            settled.push(ms);
        }
    }
    let FrameQuality::Interactive { scale, detail } = effort.quality() else {
        unreachable!("interactive efforts give interactive frames")
    };
    let ms = median(settled);
    if let Some(out) = out {
        let quality = effort.quality();
        let pixels = slider_tick(quality, &interactive_scene)?;
        let [w, h] = quality.size([width, height]);
        super::render::write_png(&out.join("edit_interactive.png"), &pixels, w, h)?;
    }
    println!(
        "{:<46} {ms:>12.2} {:>8}",
        format!(
            "budget-adapted ({:.0}% size, {:.0}% LOD detail)",
            scale * 100.0,
            detail * 100.0
        ),
        format!("{:.3}×", ms / in_place[1])
    );
    Ok(())
}
