//! `hairloom simulate`: the scene's motion (or a preset) simulated at its fixed rate and
//! written as a PNG sequence, and with `--usda` / `--abc` as strands animated over time.
//!
//! The simulator steps at the scene's rate whatever `--fps` is: a frame shows the state at
//! its time, rounded to whole steps.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::ValueEnum;
use glam::Vec3;
use hairloom_core::io::alembic::{AlembicTarget, groom::Groom, groom_animation};
use hairloom_core::io::strand_files::{
    ScalpMesh, StrandExportSize, StrandLook, UsdFrame, usda_animation,
};
use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::motion::{Motion, Wind};
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::simulate::{posed_document, simulator};
use hairloom_editor::files::STRAND_WIDTH_M;
use hairloom_render::device::{GpuContext, describe};

use super::render::{
    HeadlessRenderer, MAX_SIMULATED_S, RenderSettings, parse_size, parse_view, write_png,
};

/// The most frames one command writes.
pub const MAX_FRAMES: usize = 10_000;
/// Vertices per strand in the animated USD: 2^3 + 1 (a sequence is many copies).
pub const USDA_VERTICES_LOG2: u32 = 3;

/// What moves the hair.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MotionArg {
    /// The project scene's own motion (refused when it has none).
    Scene,
    /// The head turns 70° to the left and back.
    HeadTurn,
    /// A 6 m/s gusting wind from the left.
    Wind,
    /// Gravity only: the hair settles.
    Gravity,
}

impl MotionArg {
    pub fn motion(self, scene: Option<&Motion>) -> anyhow::Result<Motion> {
        Ok(match self {
            Self::Scene => match scene {
                Some(motion) => motion.clone(),
                None => bail!(
                    "the project's scene has no motion; choose --motion head-turn, wind or gravity"
                ),
            },
            Self::HeadTurn => Motion::head_turn(0.3, 0.6, 70.0),
            Self::Wind => Motion {
                wind: Wind {
                    speed_m_per_s: 6.0,
                    direction: [1.0, 0.0, 0.3],
                    ..Wind::default()
                },
                ..Motion::default()
            },
            Self::Gravity => Motion::default(),
        })
    }
}

#[derive(clap::Args)]
pub struct SimulateSettings {
    pub project: PathBuf,
    /// Folder for frame_0000.png, frame_0001.png, …
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long, default_value_t = 3.0)]
    pub seconds: f64,
    #[arg(long, default_value_t = 24.0)]
    pub fps: f64,
    /// What moves the hair: the scene's own motion, or a preset for a scene without one.
    #[arg(long, value_enum, default_value_t = MotionArg::Scene)]
    pub motion: MotionArg,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "480x480")]
    pub size: String,
    /// A camera preset of the scene, or x,y,z.
    #[arg(long, default_value = "three-quarter")]
    pub view: String,
    /// Override the scene's optional effects (as for render).
    #[arg(long)]
    pub effects: Option<String>,
    /// Strands per bundle drawn (and written with --usda / --abc).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub strands_per_bundle: u32,
    /// Also write OUT/hair.usda: the strands at every frame as USD time samples.
    #[arg(long)]
    pub usda: bool,
    /// Also write OUT/hair.abc: an Alembic groom (strands and guides) whose points are
    /// time samples, one per frame.
    #[arg(long)]
    pub abc: bool,
    /// The application hair.abc is for (axes and units), as for export's --for.
    #[arg(long = "for", default_value = "blender", value_parser = AlembicTarget::parse)]
    pub alembic_for: AlembicTarget,
    /// Write the strands only (with --usda / --abc), no pictures.
    #[arg(long)]
    pub no_render: bool,
}

pub fn run(settings: &SimulateSettings) -> anyhow::Result<()> {
    let (seconds, fps) = (settings.seconds, settings.fps);
    if !(seconds.is_finite() && (0.0..=MAX_SIMULATED_S).contains(&seconds)) {
        bail!("--seconds {seconds}: must be between 0 and {MAX_SIMULATED_S}");
    }
    if !(fps.is_finite() && (0.1..=240.0).contains(&fps)) {
        bail!("--fps {fps}: must be between 0.1 and 240");
    }
    let frame_count = (seconds * fps).round() as usize + 1;
    if frame_count > MAX_FRAMES {
        bail!("{frame_count} frames are more than the {MAX_FRAMES} one command writes");
    }
    let keep_strands = settings.usda || settings.abc;
    if settings.no_render && !keep_strands {
        bail!("nothing to write: --no-render without --usda or --abc");
    }
    let (width, height) = parse_size(&settings.size)?;
    let project = hairloom_core::io::project::load(&settings.project)?;
    let mut document = project.document;
    let motion = settings.motion.motion(document.scene.motion.as_ref())?;
    motion.validate().map_err(|e| {
        anyhow::anyhow!(
            "scene.{}: {}",
            e.path.trim_start_matches("scene."),
            e.message
        )
    })?;
    document.scene.motion = Some(motion.clone());
    if keep_strands {
        // Every frame's strands are held until the file is written: bound them all.
        let one = StrandExportSize::of(
            &document.hair_mesh,
            settings.strands_per_bundle,
            USDA_VERTICES_LOG2,
        );
        let frames = frame_count as u64;
        StrandExportSize {
            strands: one.strands.saturating_mul(frames),
            points: one.points.saturating_mul(frames),
            ..one
        }
        .check()
        .map_err(|e| {
            anyhow::anyhow!(
                "--usda / --abc over {frame_count} frames: {e}; lower --strands-per-bundle, --fps or --seconds"
            )
        })?;
    }
    let direction = parse_view(&settings.view, &document.scene)?;
    let render_settings = RenderSettings {
        effects: settings.effects.clone(),
        ..RenderSettings::default()
    };
    let options = RuntimeOptions {
        strands_per_bundle: settings.strands_per_bundle,
        ..RuntimeOptions::default()
    };
    std::fs::create_dir_all(&settings.out)
        .with_context(|| format!("creating {}", settings.out.display()))?;

    // One camera for the whole sequence: a box around the modelled hair large enough for it
    // to turn in, so the view does not follow the motion.
    let modelled = RuntimeHair::from_document(&document, &options);
    let (lo, hi) = modelled
        .textures
        .hair_bounds()
        .context("nothing to simulate: no bundle grows hair")?;
    let (centre, reach) = ((lo + hi) * 0.5, (hi - lo).length() * 0.3);
    let frame = (centre - Vec3::splat(reach), centre + Vec3::splat(reach));

    let mut gpu = if !settings.no_render {
        let context = GpuContext::new_headless()?;
        let renderer = HeadlessRenderer::new(&context, render_settings.generation);
        println!("adapter: {}", describe(&context.adapter_info));
        Some((context, renderer))
    } else {
        None
    };
    let started = Instant::now();
    let mut sim = simulator(&document, &motion);
    println!(
        "{}: {} particles, {} constraints, {} Hz × {} sub-steps × {} iterations; {frame_count} frames at {fps} fps",
        settings.project.display(),
        sim.particle_count(),
        sim.constraint_count(),
        motion.quality.rate_hz,
        motion.quality.substeps,
        motion.quality.iterations
    );
    // What the whole sequence will cost, said before it runs (it prints frame by frame).
    let estimate = hairloom_core::simulate::SimulationEstimate::measure(&sim, seconds);
    if estimate.over_budget() {
        eprintln!("{}", estimate.describe(seconds));
    }
    let mut simulate_s = 0.0;
    let mut strand_frames = Vec::new();
    let mut grooms = Vec::new();
    for i in 0..frame_count {
        let time_s = i as f64 / fps;
        let before = Instant::now();
        sim.seek(time_s);
        simulate_s += before.elapsed().as_secs_f64();
        let posed = posed_document(&document, &sim);
        if let Some((context, renderer)) = &mut gpu {
            // The first frame uploads the asset; later poses move its textures in place.
            let kind = if i == 0 {
                ChangeKind::Rebuild
            } else {
                ChangeKind::Reshape
            };
            renderer.show(context, RuntimeHair::from_document(&posed, &options), kind)?;
            let (pixels, _) =
                renderer.draw(context, (width, height), frame, direction, &render_settings)?;
            let path = settings.out.join(format!("frame_{i:04}.png"));
            write_png(&path, &pixels, width, height)?;
        }
        if keep_strands {
            let strands = hairloom_editor::files::generate_strands(
                &posed,
                settings.strands_per_bundle,
                USDA_VERTICES_LOG2,
                &mut |_| std::ops::ControlFlow::Continue(()),
            )?
            .unwrap_or_default();
            if settings.abc {
                grooms.push(Groom::new(&posed, &strands, STRAND_WIDTH_M));
            }
            if settings.usda {
                strand_frames.push(UsdFrame {
                    strands,
                    scalp: ScalpMesh::of(&posed.hair_mesh),
                });
            }
        }
        let depth_mm = 1e3 * sim.deepest_penetration_m();
        println!(
            "frame {i:>4} at {time_s:>6.3} s: {} steps so far, {}",
            sim.stats().steps,
            if depth_mm > 0.0 {
                format!("deepest vertex {depth_mm:.2} mm inside the body")
            } else {
                "no vertex inside the body".to_string()
            }
        );
    }
    if settings.usda {
        let first = strand_frames.first().map_or(&[][..], |f| &f.strands[..]);
        let look = StrandLook::new(
            first,
            STRAND_WIDTH_M,
            &document.scene.material,
            &document.root_maps,
        );
        let text = usda_animation(&strand_frames, &look, fps).map_err(anyhow::Error::msg)?;
        let path = settings.out.join("hair.usda");
        hairloom_core::io::project::write_atomic(&path, text.as_bytes(), |_| {})
            .with_context(|| format!("writing {}", path.display()))?;
        println!(
            "{}: {} frames of {} strands, {:.1} MiB",
            path.display(),
            strand_frames.len(),
            strand_frames.first().map_or(0, |f| f.strands.len()),
            text.len() as f64 / (1 << 20) as f64
        );
    }
    if settings.abc {
        let bytes =
            groom_animation(&grooms, fps, settings.alembic_for).map_err(anyhow::Error::msg)?;
        let path = settings.out.join("hair.abc");
        hairloom_core::io::project::write_atomic(&path, &bytes, |_| {})
            .with_context(|| format!("writing {}", path.display()))?;
        println!(
            "{}: {} frames of {} strands and {} guides, {:.1} MiB",
            path.display(),
            grooms.len(),
            grooms.first().map_or(0, |g| g.strands.vertex_counts.len()),
            grooms.first().map_or(0, |g| g.guides.vertex_counts.len()),
            bytes.len() as f64 / (1 << 20) as f64
        );
    }
    println!(
        "simulated {:.2} s in {:.1} ms ({:.2} ms per simulated 60 Hz frame); {:.1} s in all",
        sim.time_s(),
        simulate_s * 1e3,
        simulate_s * 1e3 / (sim.time_s() * 60.0).max(1.0),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
