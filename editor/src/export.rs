//! `hairloom export`: runtime bundle and strand files, each written atomically, with a
//! progress line on standard error for long exports.

use std::io::{IsTerminal, Write};
use std::path::Path;

use anyhow::{Context, bail};
use hairloom_core::export::{
    RuntimeExportOptions, glb_lines, hair_file, runtime_bundle, usda_file,
};
use hairloom_core::project::write_atomic;
use hairloom_core::runtime::Precision;
use hairloom_core::strands::{StrandContext, StrandOptions, StrandPlan};

/// Strand width written to the strand files (80 µm, a typical human hair).
const STRAND_WIDTH_M: f32 = 8e-5;

pub fn run(
    project_path: &Path,
    runtime: Option<&Path>,
    strand_files: &[std::path::PathBuf],
    strands_per_bundle: u32,
    vertices_log2: u32,
    precision: Precision,
) -> anyhow::Result<()> {
    if runtime.is_none() && strand_files.is_empty() {
        bail!("nothing to export: give --runtime DIR and/or --strands FILE.{{hair,usda,glb}}");
    }
    if vertices_log2 > 10 {
        bail!("--vertices-log2 {vertices_log2} is more than 10 (1025 vertices per strand)");
    }
    for file in strand_files {
        let extension = file.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !matches!(extension, "hair" | "usda" | "glb") {
            bail!(
                "{}: unknown strand format (use .hair, .usda or .glb)",
                file.display()
            );
        }
    }
    let project = hairloom_core::project::load(project_path)?;
    let document = &project.document;
    if let Some(dir) = runtime {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let options = RuntimeExportOptions {
            precision,
            strands_per_bundle,
            ..RuntimeExportOptions::default()
        };
        let files = runtime_bundle(document, &options)
            .with_context(|| format!("exporting {}", project_path.display()))?;
        for (name, bytes) in &files {
            let path = dir.join(name);
            write_atomic(&path, bytes, |_| {})
                .with_context(|| format!("writing {}", path.display()))?;
        }
        let total: usize = files.iter().map(|(_, b)| b.len()).sum();
        println!(
            "{}: runtime bundle, {} files, {:.1} KiB",
            dir.display(),
            files.len(),
            total as f64 / 1024.0
        );
    }
    if !strand_files.is_empty() {
        let strands = generate_with_progress(document, strands_per_bundle, vertices_log2);
        for file in strand_files {
            let bytes = match file.extension().and_then(|e| e.to_str()) {
                Some("hair") => hair_file(&strands, STRAND_WIDTH_M, [0.35, 0.22, 0.12]),
                Some("usda") => usda_file(&strands, STRAND_WIDTH_M).into_bytes(),
                _ => glb_lines(&strands),
            };
            write_atomic(file, &bytes, |_| {})
                .with_context(|| format!("writing {}", file.display()))?;
            let points: usize = strands.iter().map(|s| s.points.len()).sum();
            println!(
                "{}: {} strands, {} points, {:.1} KiB",
                file.display(),
                strands.len(),
                points,
                bytes.len() as f64 / 1024.0
            );
        }
    }
    Ok(())
}

/// Generates every strand, printing the percentage done to standard error.
fn generate_with_progress(
    document: &hairloom_core::Document,
    strands_per_bundle: u32,
    vertices_log2: u32,
) -> Vec<hairloom_core::strands::Strand> {
    let options = StrandOptions {
        strands_per_bundle,
        vertices_log2,
        ..StrandOptions::default()
    };
    let context = StrandContext::new(document);
    let plan = StrandPlan::new(&options);
    let bundle_count = document.hair_mesh.bundles.len();
    let mut strands = Vec::new();
    let mut last_percent = usize::MAX;
    let mut stderr = std::io::stderr();
    // Redrawn in place on a terminal; logs and pipes get nothing.
    let show_progress = stderr.is_terminal();
    for index in 0..bundle_count {
        strands.extend(plan.bundle_strands(&context, index));
        let percent = (index + 1) * 100 / bundle_count.max(1);
        if show_progress && percent != last_percent {
            let filled = percent / 5;
            let _ = write!(
                stderr,
                "\rgenerating strands [{}{}] {percent:>3}%",
                "#".repeat(filled),
                " ".repeat(20 - filled)
            );
            last_percent = percent;
        }
    }
    if show_progress {
        let _ = writeln!(stderr);
    }
    strands
}
