//! `hairloom bench accuracy` and `hairloom bench cpu`.
//!
//! Accuracy: every switch of the strand-evaluation path is compared with the f64 reference
//! (column blend of centripetal Catmull-Rom columns, exact cubics) at the same strands and
//! curve parameters, and timed on the CPU. Vertex counts are compared, styled, against a
//! 257-vertex styled reference. Errors are in model units (metres for the samples) and in
//! percent of the mean root-edge length ("bundle width").

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use glam::{DVec2, DVec3};
use hairloom_core::geometry::curve::{CurveDefinition, ReferenceStrand, SegmentForm};
use hairloom_core::runtime::atlas::Atlas;
use hairloom_core::runtime::strand_gen::{Filtering, StrandGen};
use hairloom_core::runtime::textures::{Precision, RuntimeTextures};
use hairloom_core::strands::reference::{StrandOptions, generate, generate_parallel};
use hairloom_core::strands::roots::{SampleDomain, progressive_samples};

/// Vertices per strand used for the curve switches.
const CURVE_VERTICES: usize = 33;

fn default_project() -> PathBuf {
    hairloom_core::samples::default_sample_path()
}

fn load(project: Option<PathBuf>) -> anyhow::Result<(PathBuf, hairloom_core::Project)> {
    let path = project.unwrap_or_else(default_project);
    let loaded = hairloom_core::io::project::load(&path)
        .with_context(|| "the accuracy benchmark needs a project (--project FILE)")?;
    Ok((path, loaded))
}

/// One measured switch.
struct Row {
    switch: String,
    max_error: f64,
    mean_error: f64,
    /// Max error against the f64 two-quadratic model (what the texture path implements):
    /// isolates filtering and storage error from the curve approximation.
    max_vs_quadratics: Option<f64>,
    ms_per_million: f64,
    /// What the storage costs: the five textures' GPU bytes per hair-mesh vertex (texture
    /// path rows only).
    texture_bytes_per_vertex: Option<f64>,
}

/// Strands to measure: (atlas block index, block coords, bundle-corner weights).
fn strand_set(textures: &RuntimeTextures, per_bundle: u32) -> Vec<(usize, DVec2, [f64; 4])> {
    let quad = progressive_samples(per_bundle as usize, SampleDomain::Square, 7);
    let triangle = progressive_samples(per_bundle as usize, SampleDomain::Triangle, 7);
    let mut out = Vec::new();
    for (index, block) in textures.atlas.blocks.iter().enumerate() {
        let samples = if Atlas::is_triangle(block) {
            &triangle
        } else {
            &quad
        };
        for sample in samples {
            let (s, t) = Atlas::sample_block_coords(block, *sample);
            let coords = DVec2::new(s, t);
            out.push((
                index,
                coords,
                Atlas::corner_weights(block, coords.x, coords.y),
            ));
        }
    }
    out
}

fn taus(layers: u32) -> impl Iterator<Item = f64> {
    (0..CURVE_VERTICES).map(move |k| layers as f64 * k as f64 / (CURVE_VERTICES - 1) as f64)
}

pub fn run(project: Option<PathBuf>, out: &Path, per_bundle: u32) -> anyhow::Result<()> {
    let (path, project) = load(project)?;
    let document = &project.document;
    let mesh = &document.hair_mesh;
    let f32_textures = RuntimeTextures::build(mesh, Precision::F32);
    let f16_textures = RuntimeTextures::build(mesh, Precision::F16);
    let strands = strand_set(&f32_textures, per_bundle);
    let bundle_width = mean_root_edge(mesh);
    let layers_of = |block: usize| f32_textures.atlas.blocks[block].layers;

    // Every measured strand by the f64 evaluator, with the time it took.
    let evaluate = |definition: CurveDefinition, form: SegmentForm| -> (Vec<Vec<DVec3>>, f64) {
        let start = Instant::now();
        let points: Vec<Vec<DVec3>> = strands
            .iter()
            .filter_map(|(block, _, weights)| {
                let bundle = f32_textures.atlas.blocks[*block].bundle as usize;
                let strand = ReferenceStrand::with_weights(mesh, bundle, *weights)?;
                Some(
                    taus(layers_of(*block))
                        .map(|t| strand.point(t, definition, form))
                        .collect(),
                )
            })
            .collect();
        let vertices = (points.len() * CURVE_VERTICES).max(1) as f64;
        (points, start.elapsed().as_secs_f64() * 1e3 * 1e6 / vertices)
    };
    let (reference, reference_ms) = evaluate(CurveDefinition::ColumnBlend, SegmentForm::ExactCubic);
    let vertex_total = (reference.len() * CURVE_VERTICES) as f64;

    let (quadratic_model, _) = evaluate(CurveDefinition::ColumnBlend, SegmentForm::TwoQuadratics);
    let compare_with = |points: &[Vec<DVec3>], against: &[Vec<DVec3>]| -> (f64, f64) {
        let mut max: f64 = 0.0;
        let mut sum = 0.0;
        let mut count = 0usize;
        for (a, b) in points.iter().zip(against) {
            for (p, q) in a.iter().zip(b) {
                let d = p.distance(*q);
                max = max.max(d);
                sum += d;
                count += 1;
            }
        }
        (max, sum / count.max(1) as f64)
    };
    let compare = |points: &[Vec<DVec3>]| compare_with(points, &reference);
    let mut rows = vec![Row {
        switch: "reference: f64, column blend, exact cubic".into(),
        max_error: 0.0,
        mean_error: 0.0,
        max_vs_quadratics: None,
        ms_per_million: reference_ms,
        texture_bytes_per_vertex: None,
    }];
    for (name, definition, form) in [
        (
            "f64, per-strand centripetal (2009 definition)",
            CurveDefinition::PerStrandCentripetal,
            SegmentForm::ExactCubic,
        ),
        (
            "f64, column blend, two quadratics",
            CurveDefinition::ColumnBlend,
            SegmentForm::TwoQuadratics,
        ),
    ] {
        let (points, ms) = evaluate(definition, form);
        let (max, mean) = compare(&points);
        rows.push(Row {
            switch: name.into(),
            max_error: max,
            mean_error: mean,
            max_vs_quadratics: None,
            ms_per_million: ms,
            texture_bytes_per_vertex: None,
        });
    }
    for (name, textures, filtering) in [
        (
            "texture path f32, exact filtering",
            &f32_textures,
            Filtering::Exact,
        ),
        (
            "texture path f32, 8-bit hardware weights",
            &f32_textures,
            Filtering::Hardware8Bit,
        ),
        (
            "texture path f16, exact filtering",
            &f16_textures,
            Filtering::Exact,
        ),
        (
            "texture path f16, 8-bit hardware weights",
            &f16_textures,
            Filtering::Hardware8Bit,
        ),
    ] {
        let path = StrandGen {
            textures,
            filtering,
        };
        let start = Instant::now();
        let points: Vec<Vec<DVec3>> = strands
            .iter()
            .map(|(block, coords, _)| {
                taus(layers_of(*block))
                    .map(|t| {
                        path.position(*block, coords.x as f32, coords.y as f32, t as f32)
                            .as_dvec3()
                    })
                    .collect()
            })
            .collect();
        let ms = start.elapsed().as_secs_f64() * 1e3 * 1e6 / vertex_total;
        let (max, mean) = compare(&points);
        let (vs_quadratics, _) = compare_with(&points, &quadratic_model);
        rows.push(Row {
            switch: name.into(),
            max_error: max,
            mean_error: mean,
            max_vs_quadratics: Some(vs_quadratics),
            ms_per_million: ms,
            texture_bytes_per_vertex: Some(
                textures.gpu_bytes() as f64 / mesh.vertex_count().max(1) as f64,
            ),
        });
    }
    rows.extend(vertex_count_rows(document, per_bundle)?);

    println!(
        "Accuracy vs time: {} ({} strands, bundle width {:.2} mm)",
        path.display(),
        reference.len(),
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
fn chart(rows: &[Row], bundle_width: f64, path: &Path) -> anyhow::Result<()> {
    use plotters::prelude::*;
    let fail = |e: &dyn std::fmt::Debug| anyhow::anyhow!("{e:?}");
    // Registering again in the same process fails harmlessly.
    let _ = plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    );
    let plotted: Vec<&Row> = rows.iter().filter(|r| r.max_error > 0.0).collect();
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

/// Styled strands with 5, 9, 17, 33 and 65 vertices against a 257-vertex styled reference:
/// each reference vertex is compared with the coarse polyline at the same curve parameter.
fn vertex_count_rows(
    document: &hairloom_core::Document,
    per_bundle: u32,
) -> anyhow::Result<Vec<Row>> {
    let options = |log2: u32| StrandOptions {
        strands_per_bundle: per_bundle,
        vertices_log2: log2,
        ..StrandOptions::default()
    };
    let reference = generate(document, &options(8));
    let mut rows = Vec::new();
    for log2 in 2..=6u32 {
        let start = Instant::now();
        let coarse = generate(document, &options(log2));
        let vertices = coarse.iter().map(|s| s.points.len()).sum::<usize>() as f64;
        let ms = start.elapsed().as_secs_f64() * 1e3 * 1e6 / vertices;
        let (mut max, mut sum, mut count): (f64, f64, usize) = (0.0, 0.0, 0);
        for (fine, coarse) in reference.iter().zip(&coarse) {
            let segments = coarse.points.len() - 1;
            for (i, p) in fine.points.iter().enumerate() {
                let t = i as f64 / (fine.points.len() - 1) as f64 * segments as f64;
                let k = (t.floor() as usize).min(segments - 1);
                let q = coarse.points[k].lerp(coarse.points[k + 1], t - k as f64);
                let d = p.distance(q);
                max = max.max(d);
                sum += d;
                count += 1;
            }
        }
        rows.push(Row {
            switch: format!("styled, {} vertices vs 257", (1 << log2) + 1),
            max_error: max,
            mean_error: sum / count.max(1) as f64,
            max_vs_quadratics: None,
            ms_per_million: ms,
            texture_bytes_per_vertex: None,
        });
    }
    Ok(rows)
}

fn mean_root_edge(mesh: &hairloom_core::HairMesh) -> f64 {
    let mut total = 0.0;
    let mut count = 0;
    for bundle in &mesh.bundles {
        let n = bundle.vertices.len();
        for i in 0..n {
            let a = mesh.columns[bundle.vertices[i] as usize].positions[0];
            let b = mesh.columns[bundle.vertices[(i + 1) % n] as usize].positions[0];
            total += a.distance(b);
            count += 1;
        }
    }
    if count == 0 {
        1.0
    } else {
        total / count as f64
    }
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
