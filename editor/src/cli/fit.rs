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
    /// The scalp's mesh when the glTF has several (a character of scalp, face, eyes…);
    /// `#N` names an unnamed one.
    #[arg(long)]
    pub scalp_mesh: Option<String>,
    /// Where on the scalp mesh hair may grow, as `hairloom import --hair-on`: `all`,
    /// `material:NAME[,NAME…]` or `colour:r>0.5`.
    #[arg(long, default_value = "all")]
    pub hair_on: hairloom_core::io::scalp_region::ScalpRegion,
    /// Every mesh of the glTF becomes the body, not only the scalp's.
    #[arg(long)]
    pub whole_body: bool,
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

/// The scalp the artist named: a project's root layer (and body), or a glTF mesh (the one
/// `--scalp-mesh` names in a file of several, hair where `--hair-on` says; with
/// `--whole-body` every mesh is the body).
fn scalp_source(path: &Path, args: &FitArgs) -> anyhow::Result<ScalpSource> {
    let is_project = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("hairloom"));
    let document = if is_project {
        project::load(path)?.document
    } else {
        let options = ImportOptions {
            scale: args.scalp_scale,
            mesh_name: args.scalp_mesh.clone(),
            ..ImportOptions::default()
        };
        let mut document = files::scalp_document(path, &options, &args.hair_on, false)?.0;
        if args.whole_body {
            let everything = ImportOptions {
                mesh_name: None,
                ..options
            };
            document.body = hairloom_core::io::import::import_body(path, &everything)?.0;
        }
        document
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
        Some(path) => scalp_source(path, &args)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn args(scalp: &Path) -> FitArgs {
        FitArgs {
            groom: "groom.abc".into(),
            scalp: Some(scalp.to_path_buf()),
            scalp_scale: 1.0,
            scalp_mesh: None,
            hair_on: hairloom_core::io::scalp_region::ScalpRegion::All,
            whole_body: false,
            out: "out.hairloom".into(),
            report: None,
            layers: 12,
            scalp_faces: 0,
        }
    }

    /// Issue 36: `fit --scalp` on a glTF of several meshes names them; `--scalp-mesh` picks
    /// one, `--whole-body` keeps every mesh as the body, `--hair-on` a region of it.
    #[test]
    fn a_scalp_of_several_meshes_is_chosen_by_name_and_region() {
        let dir = tempfile::tempdir().expect("temp dir");
        let glb = dir.path().join("character.glb");
        std::fs::write(&glb, hairloom_tests::two_mesh_glb()).expect("write");
        let error = scalp_source(&glb, &args(&glb))
            .err()
            .expect("several meshes")
            .to_string();
        assert!(error.contains("body") && error.contains("scalp"), "{error}");
        let picked = FitArgs {
            scalp_mesh: Some("scalp".into()),
            ..args(&glb)
        };
        let Ok(ScalpSource::Given { scalp, body }) = scalp_source(&glb, &picked) else {
            panic!("the scalp mesh reads");
        };
        assert_eq!(scalp.bundles.len(), 1);
        assert_eq!(body.triangles.len(), 2, "the scalp's own mesh");
        let whole = FitArgs {
            whole_body: true,
            ..picked
        };
        let Ok(ScalpSource::Given { body, .. }) = scalp_source(&glb, &whole) else {
            panic!("the scalp mesh reads");
        };
        assert_eq!(body.triangles.len(), 4, "both meshes are the body");
        // A region of one mesh: the "Scalp" material's two quads of three.
        let strip = dir.path().join("strip.glb");
        std::fs::write(&strip, hairloom_tests::body_with_materials_glb()).expect("write");
        let region = FitArgs {
            hair_on: "material:Scalp".parse().expect("region"),
            ..args(&strip)
        };
        let Ok(ScalpSource::Given { scalp, body }) = scalp_source(&strip, &region) else {
            panic!("the strip reads");
        };
        assert_eq!(
            scalp.bundles.iter().filter(|b| !b.removed).count(),
            2,
            "{:?}",
            scalp.bundles.len()
        );
        assert_eq!(body.triangles.len(), 6, "the whole strip stays the body");
    }
}
