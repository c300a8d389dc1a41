//! `hairloom fit`: a groom made elsewhere (.abc, .usda/.usdc/.usdz, .hair) turned into an
//! editable project, with its error report.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use anyhow::Context;
use hairloom_core::fit::measure::{MeasureOptions, measure};
use hairloom_core::fit::{FitOptions, ScalpSource, fit};
use hairloom_core::io::groom_in::{GroomLimits, read_groom};
use hairloom_core::io::import::ImportOptions;
use hairloom_core::io::project;

use hairloom_editor::files;
use hairloom_editor::progress::TerminalProgress;

#[derive(clap::Args)]
pub struct FitArgs {
    pub groom: PathBuf,
    /// The scalp: a glTF/GLB mesh or a .hairloom project's root layer. Without one, a
    /// scalp is built from the roots.
    #[arg(long)]
    pub scalp: Option<PathBuf>,
    /// Model units per scalp-file unit (glTF scalps).
    #[arg(long, default_value_t = 1.0)]
    pub scalp_scale: f64,
    /// Project file to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the error report as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Layers of every bundle.
    #[arg(long, default_value_t = 12)]
    pub layers: u32,
    /// Faces of a scalp built from the roots (0: one per 32 strands).
    #[arg(long, default_value_t = 0)]
    pub scalp_faces: usize,
}

/// The scalp the artist named: a project's root layer (and body), or a glTF mesh.
fn scalp_source(path: &Path, scale: f64) -> anyhow::Result<ScalpSource> {
    let is_project = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("hairloom"));
    let document = if is_project {
        project::load(path)?.document
    } else {
        let options = ImportOptions {
            scale,
            ..ImportOptions::default()
        };
        files::scalp_document(
            path,
            &options,
            &hairloom_core::io::scalp_region::ScalpRegion::All,
            false,
        )?
        .0
    };
    Ok(ScalpSource::Given {
        scalp: document.hair_mesh,
        body: document.body,
    })
}

pub fn run(args: FitArgs) -> anyhow::Result<()> {
    let started = std::time::Instant::now();
    let mut bar = TerminalProgress::new("reading");
    let groom = read_groom(&args.groom, GroomLimits::default(), &mut |f| {
        bar.update(f);
        ControlFlow::Continue(())
    })?;
    bar.finish();
    let read_s = started.elapsed().as_secs_f64();
    println!(
        "{}: {} curves, {} points ({}) in {read_s:.2} s",
        args.groom.display(),
        groom.curve_count(),
        groom.points.len(),
        groom.notes.join("; ")
    );
    let scalp = match &args.scalp {
        Some(path) => scalp_source(path, args.scalp_scale)
            .with_context(|| format!("reading the scalp {}", path.display()))?,
        None => ScalpSource::FromRoots,
    };
    let name = args
        .groom
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "groom".into());
    let options = FitOptions {
        layers: args.layers,
        scalp_faces: args.scalp_faces,
        ..FitOptions::default()
    };
    let mut bar = TerminalProgress::new("fitting");
    let fitted = fit(&groom, scalp, &name, &options, &mut |_, f| {
        bar.update(f);
        ControlFlow::Continue(())
    })?;
    bar.finish();
    project::save(
        &args.out,
        &hairloom_core::Project::new(fitted.document.clone()),
    )?;
    let measure_start = std::time::Instant::now();
    let mut report = measure(&groom, &fitted, &MeasureOptions::default());
    report.timings_s.insert(0, ("read".into(), read_s));
    report
        .timings_s
        .push(("measure".into(), measure_start.elapsed().as_secs_f64()));
    print!("{}", report.summary());
    println!("→ {}", args.out.display());
    if let Some(path) = &args.report {
        let json = serde_json::to_string_pretty(&report)?;
        project::write_atomic(path, json.as_bytes(), |_| {})
            .with_context(|| format!("writing {}", path.display()))?;
        println!("report → {}", path.display());
    }
    Ok(())
}
