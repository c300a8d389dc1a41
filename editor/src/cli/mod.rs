//! The `hairloom` command line: one file per command family (`render`, `bench`, `accuracy`),
//! the rest here. Subcommands work headless: `check` validates a project (exit 0, or 2 with a message
//! naming the problem), `info` prints counts, `import` turns a glTF scalp into a project,
//! `adapters` lists the GPU adapters wgpu finds, and `bench` measures.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use hairloom_core::io::alembic::AlembicTarget;
use hairloom_core::io::project;
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::textures::Precision;
use hairloom_render::renderer::strand_gen::GenerationPath;

mod accuracy;
mod bench;
mod bench_crowd;
mod bench_effects;
mod bench_shading;
mod bench_sim;
mod bench_switches;
mod fit;
mod maps;
mod render;
mod simulate;

use hairloom_editor::files;

#[derive(Parser)]
#[command(
    name = "hairloom",
    version,
    about = "Hair-mesh modeling and styling editor"
)]
#[command(args_conflicts_with_subcommands = true)]
struct Cli {
    /// A project to open in the editor (without one, the editor opens a bundled sample).
    file: Option<PathBuf>,
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a project file: exit 0 when valid, 2 with a message naming the problem.
    Check { file: PathBuf },
    /// Print counts of a project: root faces, bundles, vertices, layers.
    Info {
        file: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Bring density, length, clump and colour maps painted in another tool (grey images over the
    /// scalp's uv layout) into a project, as one undo step.
    Maps(maps::MapsArgs),
    /// Create a project from a glTF/GLB scalp (every face becomes a bare bundle).
    Import {
        scalp: PathBuf,
        /// Project file to write.
        #[arg(long)]
        out: PathBuf,
        /// Mesh to read when the file has several.
        #[arg(long)]
        mesh: Option<String>,
        /// Model units per file unit.
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        /// Replace the file's uv with a seamless generated projection.
        #[arg(long)]
        generate_uv: bool,
        /// Where hair grows (the whole mesh stays the body): `all`, `material:NAME[,NAME…]`
        /// (faces using those glTF materials) or `colour:r>0.5` / `colour:g<0.5` (a mask
        /// painted into the vertex colours, channel r, g, b or a).
        #[arg(long, default_value = "all")]
        hair_on: hairloom_core::io::scalp_region::ScalpRegion,
        /// Every mesh of the file becomes the body (a character made of several meshes),
        /// not only the one hair grows on (`--mesh`).
        #[arg(long)]
        whole_body: bool,
        /// Raise the import cap on vertices (default 4,000,000; triangles may be twice as
        /// many). See docs/resource-policy.md.
        #[arg(long)]
        max_vertices: Option<usize>,
    },
    /// Fit an editable hair mesh and styling to a groom made elsewhere (.abc, .usda, .usdc,
    /// .usdz or .hair) and print its error against the input (closest-point distances both
    /// ways, root placement, strand length, time).
    Fit(fit::FitArgs),
    /// Export the runtime bundle (manifest + KTX2 textures), strands for other tools and/or
    /// hair cards.
    Export {
        project: PathBuf,
        /// Folder for the runtime bundle.
        #[arg(long)]
        runtime: Option<PathBuf>,
        /// Strand file; the format follows the extension: .hair, .usda, .glb or .abc (an Alembic
        /// groom with guides, for Unreal and Unity).
        #[arg(long)]
        strands: Vec<PathBuf>,
        /// Strands per bundle (at most 4096, the runtime bundle's cap).
        #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=4096))]
        strands_per_bundle: u32,
        /// Strands have 2^N + 1 vertices (default: 5, or more where the styling's curls and
        /// waves need 8 segments a turn).
        #[arg(long)]
        vertices_log2: Option<u32>,
        /// Runtime texture precision (also of `--curve runtime` strands).
        #[arg(long, value_enum, default_value_t = PrecisionArg::F32)]
        precision: PrecisionArg,
        /// What the strand files hold: the exact cubic curves, or the strands as the runtime
        /// generates them from the textures (quadratics, precision) to compare a loader with.
        #[arg(long, value_enum, default_value_t = files::StrandCurve::Exact)]
        curve: files::StrandCurve,
        /// Folder for hair cards: one GLB per level of detail and the baked atlas (albedo,
        /// coverage, depth, flow, root-to-tip, id) as PNG, from the strands of
        /// --strands-per-bundle and --vertices-log2.
        #[arg(long)]
        cards: Option<PathBuf>,
        /// The application an .abc is for: blender, houdini (y up, metres), maya, unity (y
        /// up, centimetres) or unreal (z up, centimetres), each upright and at its size with
        /// its default import settings (README, "Strands in other tools").
        #[arg(long = "for", default_value = "blender", value_parser = AlembicTarget::parse)]
        alembic_for: AlembicTarget,
    },
    /// Render a project, or an exported runtime bundle folder, headless to a PNG: strands
    /// generated on the GPU from the runtime textures, lit by the scene (its lights,
    /// material and effects: shadows, Marschner shading, dual scattering, coverage), MSAA.
    Render {
        /// A .hairloom project or a runtime bundle folder.
        input: PathBuf,
        #[arg(long)]
        out: PathBuf,
        /// Image size, WIDTHxHEIGHT.
        #[arg(long, default_value = "960x960")]
        size: String,
        /// Strands per bundle (default: the bundle's own count, or 64 for a project; at most
        /// 4096).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
        strands_per_bundle: Option<u32>,
        /// Camera direction from the model: a camera preset of the scene (front, side, back,
        /// three-quarter, top by default), or x,y,z.
        #[arg(long, default_value = "three-quarter")]
        view: String,
        /// Override the scene's optional effects for this render: none, all, or a list of
        /// marschner, opacity-shadow-maps, deep-opacity-maps, body-shadows, dual-scattering,
        /// width-oit, far-aggregated (those on, the rest off).
        #[arg(long)]
        effects: Option<String>,
        /// Camera distance as a multiple of the distance that frames the hair (1): 10 sees
        /// the head at a tenth of the size (far hair, LOD).
        #[arg(long, default_value_t = 1.0)]
        distance: f32,
        /// Strands have 2^N + 1 vertices (default: what the styling's curls and waves need,
        /// 8 segments per turn, 4 to 7).
        #[arg(long)]
        vertices_log2: Option<u32>,
        /// Texture precision of a project render (a runtime bundle has its own).
        #[arg(long, value_enum, default_value_t = PrecisionArg::F32)]
        precision: PrecisionArg,
        /// Texture filtering in the generation shader.
        #[arg(long, value_enum, default_value_t = FilteringArg::Exact)]
        filtering: FilteringArg,
        /// Where strands are generated: compute (one invocation per strand, into a scratch
        /// buffer), compute-per-vertex, or vertex-shader (in the ribbons, no scratch).
        #[arg(long, value_enum, default_value_t = GenerationArg::Compute)]
        generation: GenerationArg,
        /// Draw every strand at full detail (no strand or vertex LOD).
        #[arg(long)]
        no_lod: bool,
        /// Strand LOD α (eq. 7): larger keeps more strands at a distance.
        #[arg(long, default_value_t = hairloom_core::runtime::frame_plan::DEFAULT_ALPHA_STRANDS)]
        alpha_strands: f64,
        /// Vertex LOD α (eq. 7): larger keeps more vertices at a distance.
        #[arg(long, default_value_t = hairloom_core::runtime::frame_plan::DEFAULT_ALPHA_VERTICES)]
        alpha_vertices: f64,
        /// Vertex LOD morph window λ in [0, 1] (eq. 10-12); 0 switches levels abruptly.
        #[arg(long, default_value_t = hairloom_core::runtime::frame_plan::DEFAULT_LAMBDA)]
        lambda: f64,
        /// Simulate the scene's motion from 0 to this time (seconds) and render that moment
        /// (a scene without motion renders as modelled).
        #[arg(long, default_value_t = 0.0)]
        time: f64,
        /// A turntable: N pictures (OUT_000.png …) with the camera and the lights going once
        /// round the hair from --view, as if the model turned under studio lights (at most
        /// 360).
        #[arg(long, default_value_t = 0)]
        turntable: u32,
    },
    /// Simulate a project's motion and write the frames as a PNG sequence (and, with
    /// --usda / --abc, the strands animated over time).
    Simulate(simulate::SimulateSettings),
    /// List the GPU adapters wgpu can use and the one Hairloom would pick.
    Adapters,
    /// Measure performance; prints a table (see BENCHMARKS.md).
    Bench {
        #[command(subcommand)]
        which: bench::Which,
    },
}

/// Texture precision on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum PrecisionArg {
    F32,
    F16,
}

impl From<PrecisionArg> for Precision {
    fn from(value: PrecisionArg) -> Self {
        match value {
            PrecisionArg::F32 => Precision::F32,
            PrecisionArg::F16 => Precision::F16,
        }
    }
}

/// Texture filtering on the command line: exact (manual, f32 weights) or hardware.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum FilteringArg {
    Exact,
    Hardware,
}

/// Where strands are generated, on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum GenerationArg {
    Compute,
    ComputePerVertex,
    VertexShader,
    /// Task and mesh shaders (adapters with `EXPERIMENTAL_MESH_SHADER`).
    MeshShader,
}

impl From<GenerationArg> for GenerationPath {
    fn from(value: GenerationArg) -> Self {
        match value {
            GenerationArg::Compute => GenerationPath::ComputePerStrand,
            GenerationArg::ComputePerVertex => GenerationPath::ComputePerVertex,
            GenerationArg::VertexShader => GenerationPath::VertexShader,
            GenerationArg::MeshShader => GenerationPath::MeshShader,
        }
    }
}

impl From<FilteringArg> for Filtering {
    fn from(value: FilteringArg) -> Self {
        match value {
            FilteringArg::Exact => Filtering::Exact,
            FilteringArg::Hardware => Filtering::Hardware8Bit,
        }
    }
}

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => return editor(cli.file.as_deref()),
        Some(Command::Check { file }) => return check(&file),
        Some(Command::Info { file, json }) => info(&file, json),
        Some(Command::Import {
            scalp,
            out,
            mesh,
            scale,
            generate_uv,
            hair_on,
            whole_body,
            max_vertices,
        }) => import(
            &scalp,
            &out,
            mesh,
            scale,
            (&hair_on, whole_body),
            generate_uv,
            max_vertices,
        ),
        Some(Command::Fit(args)) => fit::run(args),
        Some(Command::Maps(args)) => maps::run(args),
        Some(Command::Export {
            project,
            runtime,
            strands,
            strands_per_bundle,
            vertices_log2,
            precision,
            curve,
            cards,
            alembic_for,
        }) => (|| -> anyhow::Result<()> {
            if runtime.is_some() || !strands.is_empty() || cards.is_none() {
                let options = files::ExportOptions {
                    strands_per_bundle,
                    vertices_log2,
                    precision: precision.into(),
                    curve,
                    alembic: alembic_for,
                };
                files::run(&project, runtime.as_deref(), &strands, &options)?;
            }
            if let Some(dir) = cards {
                let document = hairloom_core::io::project::load(&project)?.document;
                let vertices_log2 =
                    vertices_log2.unwrap_or_else(|| files::export_vertices_log2(&document));
                println!(
                    "{}",
                    files::write_cards(&document, &dir, strands_per_bundle, vertices_log2)?
                );
            }
            Ok(())
        })(),
        Some(Command::Render {
            input,
            out,
            size,
            strands_per_bundle,
            view,
            effects,
            distance,
            vertices_log2,
            precision,
            filtering,
            generation,
            no_lod,
            alpha_strands,
            alpha_vertices,
            lambda,
            time,
            turntable,
        }) => {
            if !(distance.is_finite() && (0.1..=1000.0).contains(&distance)) {
                eprintln!("error: --distance {distance} must be between 0.1 and 1000");
                return ExitCode::from(2);
            }
            let lod_values = [alpha_strands, alpha_vertices, lambda];
            if lod_values.iter().any(|v| !v.is_finite() || *v < 0.0) || lambda > 1.0 {
                eprintln!(
                    "error: --alpha-strands and --alpha-vertices must be finite and ≥ 0, --lambda in [0, 1]"
                );
                return ExitCode::from(2);
            }
            if let Some(n) = vertices_log2
                && n > 8
            {
                eprintln!("error: --vertices-log2 {n} is more than 8");
                return ExitCode::from(2);
            }
            let settings = render::RenderSettings {
                size,
                strands_per_bundle,
                view,
                effects,
                distance,
                vertices_log2,
                precision: precision.into(),
                filtering: filtering.into(),
                generation: generation.into(),
                lod: hairloom_core::runtime::frame_plan::LodSettings {
                    enabled: !no_lod,
                    cull: true,
                    alpha_strands,
                    alpha_vertices,
                    lambda,
                    strand_keep: 1.0,
                },
                time_s: time,
                turntable,
                turn_rad: 0.0,
            };
            render::run(&input, &out, &settings)
        }
        Some(Command::Simulate(settings)) => simulate::run(&settings),
        Some(Command::Adapters) => adapters(),
        Some(Command::Bench { which }) => bench::run(which),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::from(2)
        }
    }
}

/// Opens the interactive editor on `file`, or on the embedded sample.
fn editor(file: Option<&Path>) -> ExitCode {
    use hairloom_editor::app::{EditorState, HairloomApp};
    let state = match file {
        Some(path) => match EditorState::open(path) {
            Ok(state) => state,
            Err(error) => {
                eprintln!("error: {error}");
                return ExitCode::from(2);
            }
        },
        None => EditorState::sample(),
    };
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1400.0, 900.0])
            .with_title(state.title()),
        renderer: eframe::Renderer::Wgpu,
        wgpu_options: eframe::egui_wgpu::WgpuConfiguration {
            wgpu_setup: hairloom_editor::app::wgpu_setup(),
            ..Default::default()
        },
        ..Default::default()
    };
    match eframe::run_native(
        "Hairloom",
        options,
        Box::new(|cc| Ok(Box::new(HairloomApp::new(cc, state)))),
    ) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!(
                "error: cannot open the editor window: {error}\n(no display? `hairloom render FILE --out PICTURE.png` works headless)"
            );
            ExitCode::from(2)
        }
    }
}

fn check(file: &Path) -> ExitCode {
    match project::load(file) {
        Ok(project) => {
            let stats = project.document.hair_mesh.stats();
            println!(
                "{}: valid (format {}, {} bundles, {} vertices, {} undo steps)",
                file.display(),
                project.format_version,
                stats.root_faces,
                stats.vertices,
                project.history.undo.len()
            );
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!("{error}");
            ExitCode::from(2)
        }
    }
}

fn info(file: &Path, json: bool) -> anyhow::Result<()> {
    let project = project::load(file)?;
    let document = &project.document;
    let stats = document.hair_mesh.stats();
    if json {
        let value = serde_json::json!({
            "name": document.name,
            "stats": stats,
            "body_triangles": document.body.triangles.len(),
            "undo_steps": project.history.undo.len(),
            "redo_steps": project.history.redo.len(),
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    println!("name:             {}", document.name);
    if !document.source.is_empty() {
        println!("source:           {}", document.source);
    }
    println!(
        "root faces:       {} ({} quads, {} triangles, {} removed)",
        stats.root_faces, stats.quads, stats.triangles, stats.removed_bundles
    );
    println!("bundles:          {} with hair", stats.hair_bundles);
    println!("root vertices:    {}", stats.root_vertices);
    println!(
        "vertices:         {} ({} interior, placed automatically)",
        stats.vertices, stats.interior_vertices
    );
    println!(
        "layers:           {} to {}",
        stats.min_layers, stats.max_layers
    );
    println!("body triangles:   {}", document.body.triangles.len());
    println!(
        "history:          {} undo, {} redo (limit {})",
        project.history.undo.len(),
        project.history.redo.len(),
        project.history.limit
    );
    Ok(())
}

fn import(
    scalp: &Path,
    out: &Path,
    mesh: Option<String>,
    scale: f64,
    (hair_on, whole_body): (&hairloom_core::io::scalp_region::ScalpRegion, bool),
    generate_uv: bool,
    max_vertices: Option<usize>,
) -> anyhow::Result<()> {
    let mut limits = hairloom_core::io::import::ImportLimits::default();
    if let Some(max_vertices) = max_vertices {
        limits.max_vertices = max_vertices;
        limits.max_triangles = limits.max_triangles.max(max_vertices.saturating_mul(2));
    }
    let options = hairloom_core::io::import::ImportOptions {
        mesh_name: mesh,
        scale,
        limits,
        ..hairloom_core::io::import::ImportOptions::default()
    };
    let (mut document, mut summary) = files::scalp_document(scalp, &options, hair_on, generate_uv)?;
    if whole_body {
        let (body, skipped) = hairloom_core::io::import::import_body(
            scalp,
            &hairloom_core::io::import::ImportOptions {
                mesh_name: None,
                ..options
            },
        )?;
        summary += &format!("; body: every mesh ({} triangles)", body.triangles.len());
        if !skipped.is_empty() {
            summary += &format!(", left out (not triangles): {}", skipped.join(", "));
        }
        document.body = body;
    }
    if let Some((lo, hi)) = document.body.bounds() {
        let across_m = (hi - lo).max_element() as f64;
        if !hairloom_editor::app::scalp_import::PLAUSIBLE_EXTENT_M.contains(&across_m) {
            eprintln!(
                "note: the body is {across_m:.3} units across; glTF counts in metres, and so do \
                 the editor's brushes and extrusions: if that is not its size, import it again \
                 with --scale (e.g. 0.01 for centimetres)"
            );
        }
    }
    project::save(out, &hairloom_core::Project::new(document))?;
    println!("{summary} → {}", out.display());
    Ok(())
}

fn adapters() -> anyhow::Result<()> {
    let all = hairloom_render::device::list_adapters();
    if all.is_empty() {
        println!(
            "no adapter found (install mesa-vulkan-drivers for the lavapipe software adapter)"
        );
    }
    for info in &all {
        println!("{}", hairloom_render::device::describe(info));
    }
    match hairloom_render::device::GpuContext::new_headless() {
        Ok(context) => println!(
            "chosen: {}",
            hairloom_render::device::describe(&context.adapter_info)
        ),
        Err(error) => println!("chosen: none ({error})"),
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
