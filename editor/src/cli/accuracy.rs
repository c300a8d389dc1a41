//! `hairloom bench accuracy` and `hairloom bench cpu`: printing and plotting what
//! `hairloom_core::strands::accuracy` measures (every switch of the strand-evaluation path
//! against the f64 reference; errors in model units and in percent of the mean root-edge
//! length, "bundle width"), and timing the CPU reference generator.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use hairloom_core::strands::accuracy::{CpuAccuracy, CpuAccuracyRow, measure_cpu_accuracy};
use hairloom_core::strands::reference::{StrandOptions, generate, generate_parallel};

fn default_project() -> PathBuf {
    hairloom_core::samples::default_sample_path()
}

fn load(project: Option<PathBuf>) -> anyhow::Result<(PathBuf, hairloom_core::Project)> {
    let path = project.unwrap_or_else(default_project);
    let loaded = hairloom_core::io::project::load(&path)
        .with_context(|| "the accuracy benchmark needs a project (--project FILE)")?;
    Ok((path, loaded))
}

pub fn run(project: Option<PathBuf>, out: &Path, per_bundle: u32) -> anyhow::Result<()> {
    let (path, project) = load(project)?;
    let CpuAccuracy {
        rows,
        strands,
        bundle_width,
    } = measure_cpu_accuracy(&project.document, per_bundle);
    let reference_ms = rows.first().map_or(1.0, |r| r.ms_per_million);
    println!(
        "Accuracy vs time: {} ({} strands, bundle width {:.2} mm)",
        path.display(),
        strands,
        bundle_width * 1e3
    );
    println!("machine: {} (CPU evaluation, one thread)", super::machine());
    println!(
        "{:<48} {:>11} {:>11} {:>9} {:>12} {:>13} {:>7} {:>8}",
        "switch",
        "max error",
        "mean error",
        "max % bw",
        "max vs quad",
        "ms / M verts",
        "× ref",
        "B / vtx"
    );
    let mut csv = String::from(
        "switch,max_error_m,mean_error_m,max_error_percent_bundle_width,max_error_vs_f64_quadratics_m,ms_per_million_vertices,time_ratio_to_reference,texture_bytes_per_hair_mesh_vertex\n",
    );
    for row in &rows {
        let percent = 100.0 * row.max_error / bundle_width;
        let ratio = row.ms_per_million / reference_ms;
        let vs_quadratics = row
            .max_vs_quadratics
            .map(|v| format!("{v:.3e}"))
            .unwrap_or_else(|| "-".into());
        let bytes = row
            .texture_bytes_per_vertex
            .map(|b| format!("{b:.1}"))
            .unwrap_or_else(|| "-".into());
        println!(
            "{:<48} {:>11.3e} {:>11.3e} {:>9.3} {:>12} {:>13.1} {:>7.2} {:>8}",
            row.switch,
            row.max_error,
            row.mean_error,
            percent,
            vs_quadratics,
            row.ms_per_million,
            ratio,
            bytes
        );
        csv.push_str(&format!(
            "\"{}\",{:e},{:e},{},{},{},{},{}\n",
            row.switch,
            row.max_error,
            row.mean_error,
            percent,
            row.max_vs_quadratics
                .map(|v| format!("{v:e}"))
                .unwrap_or_default(),
            row.ms_per_million,
            ratio,
            row.texture_bytes_per_vertex
                .map(|b| b.to_string())
                .unwrap_or_default()
        ));
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let csv_path = out.join("accuracy.csv");
    std::fs::write(&csv_path, csv).with_context(|| format!("writing {}", csv_path.display()))?;
    let chart_path = out.join("accuracy.png");
    chart(&rows, bundle_width, &chart_path)
        .with_context(|| format!("drawing {}", chart_path.display()))?;
    println!("wrote {} and {}", csv_path.display(), chart_path.display());
    Ok(())
}

/// Two bar panels sharing one row per switch: max error (log) on the left, CPU time on the
/// right — what each accuracy option costs, side by side.
fn chart(rows: &[CpuAccuracyRow], bundle_width: f64, path: &Path) -> anyhow::Result<()> {
    use plotters::prelude::*;
    let fail = |e: &dyn std::fmt::Debug| anyhow::anyhow!("{e:?}");
    // Registering again in the same process fails harmlessly.
    let _ = plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    );
    let plotted: Vec<&CpuAccuracyRow> = rows.iter().filter(|r| r.max_error > 0.0).collect();
    let n = plotted.len() as i32;
    let names: Vec<String> = plotted.iter().map(|r| r.switch.clone()).collect();
    let e_min = plotted
        .iter()
        .map(|r| r.max_error)
        .fold(f64::INFINITY, f64::min)
        / 10.0;
    let e_max = plotted.iter().map(|r| r.max_error).fold(0.0, f64::max) * 5.0;
    let t_max = rows.iter().map(|r| r.ms_per_million).fold(0.0, f64::max) * 1.25;
    let root = BitMapBackend::new(path, (1400, 620)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let root = root
        .titled(
            &format!("Hairloom accuracy switches: max error vs the f64 reference, and CPU time (bundle width {:.1} mm)", bundle_width * 1e3),
            ("sans-serif", 20),
        )
        .map_err(|e| fail(&e))?;
    let (left, right) = root.split_horizontally(900);
    let mut errors = ChartBuilder::on(&left)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(330)
        .build_cartesian_2d((e_min..e_max).log_scale(), (0..n).into_segmented())
        .map_err(|e| fail(&e))?;
    errors
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(n as usize)
        .y_label_formatter(&|v| match v {
            SegmentValue::CenterOf(i) => names.get(*i as usize).cloned().unwrap_or_default(),
            _ => String::new(),
        })
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .x_desc("max position error, model units (log)")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| fail(&e))?;
    let mut times = ChartBuilder::on(&right)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(10)
        .build_cartesian_2d(0.0..t_max, (0..n).into_segmented())
        .map_err(|e| fail(&e))?;
    times
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(0)
        .x_desc("CPU ms per million vertices (one thread)")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| fail(&e))?;
    for (i, row) in plotted.iter().enumerate() {
        let i = i as i32;
        let color = if row.switch.starts_with("styled") {
            RGBColor(200, 120, 40)
        } else {
            RGBColor(60, 110, 180)
        };
        errors
            .draw_series(std::iter::once(Rectangle::new(
                [
                    (e_min, SegmentValue::Exact(i)),
                    (row.max_error, SegmentValue::Exact(i + 1)),
                ],
                color.filled(),
            )))
            .map_err(|e| fail(&e))?;
        errors
            .draw_series(std::iter::once(Text::new(
                format!(
                    " {:.2e} ({:.1}% bw)",
                    row.max_error,
                    100.0 * row.max_error / bundle_width
                ),
                (row.max_error, SegmentValue::CenterOf(i)),
                ("sans-serif", 13),
            )))
            .map_err(|e| fail(&e))?;
        times
            .draw_series(std::iter::once(Rectangle::new(
                [
                    (0.0, SegmentValue::Exact(i)),
                    (row.ms_per_million, SegmentValue::Exact(i + 1)),
                ],
                color.mix(0.7).filled(),
            )))
            .map_err(|e| fail(&e))?;
        times
            .draw_series(std::iter::once(Text::new(
                format!(" {:.0}", row.ms_per_million),
                (row.ms_per_million, SegmentValue::CenterOf(i)),
                ("sans-serif", 13),
            )))
            .map_err(|e| fail(&e))?;
    }
    root.present().map_err(|e| fail(&e))?;
    Ok(())
}

pub fn cpu(project: Option<PathBuf>) -> anyhow::Result<()> {
    let (path, project) = load(project)?;
    let document = &project.document;
    let bundles = document
        .hair_mesh
        .bundles
        .iter()
        .filter(|b| !b.removed && b.layers > 0)
        .count()
        .max(1);
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    println!(
        "CPU reference strand generation (f64, styled, 33 vertices): {}",
        path.display()
    );
    println!("machine: {}, {threads} threads", super::machine());
    println!(
        "{:>9} {:>10} {:>10} {:>16} {:>16}",
        "strands", "vertices", "ms", "vertices / s", "1-thread ratio"
    );
    for target in [10_000usize, 100_000] {
        let per_bundle = target.div_ceil(bundles) as u32;
        let options = StrandOptions {
            strands_per_bundle: per_bundle,
            vertices_log2: 5,
            ..StrandOptions::default()
        };
        let start = Instant::now();
        let strands = generate_parallel(document, &options, threads);
        let seconds = start.elapsed().as_secs_f64();
        let vertices = strands.iter().map(|s| s.points.len()).sum::<usize>();
        let single = if target <= 10_000 {
            let start = Instant::now();
            let _ = generate(document, &options);
            format!("{:.2}×", start.elapsed().as_secs_f64() / seconds)
        } else {
            "-".into()
        };
        println!(
            "{:>9} {:>10} {:>10.0} {:>16.3e} {:>16}",
            strands.len(),
            vertices,
            seconds * 1e3,
            vertices as f64 / seconds,
            single
        );
    }
    Ok(())
}
