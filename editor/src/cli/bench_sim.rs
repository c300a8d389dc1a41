//! `hairloom bench sim`: what the simulator's accuracy switch (sub-steps × iterations) costs
//! and buys. Each head sample turns its head in a gusting wind for a second and a half; every
//! configuration runs the same motion, and its vertex positions at each checkpoint are
//! compared with a converged reference run. Side by side in one run: RMS and worst position
//! error, CPU time per simulated second and per 60 Hz frame (one core), and the simulator's
//! memory. The default quality is marked. Also timed: re-placing the interior vertices
//! from the exterior each frame, the alternative to simulating them.

use std::path::Path;
use std::time::Instant;

use anyhow::Context;
use hairloom_core::geometry::interior::place_interior;
use hairloom_core::model::motion::{Motion, SimQuality, Wind};
use hairloom_core::simulate::{BodySdf, HairSim};

/// Checkpoints per run where positions are compared (evenly spaced, the last at the end).
const CHECKPOINTS: usize = 6;

/// The benchmark's motion: a 70° head turn and back in a 5 m/s gusting wind.
fn motion(quality: SimQuality) -> Motion {
    Motion {
        wind: Wind {
            speed_m_per_s: 5.0,
            direction: [1.0, 0.0, 0.4],
            ..Wind::default()
        },
        quality,
        ..Motion::head_turn(0.1, 0.4, 70.0)
    }
}

/// Positions at each checkpoint and the CPU time spent stepping.
fn simulate(
    document: &hairloom_core::Document,
    sdf: &BodySdf,
    quality: SimQuality,
    seconds: f64,
) -> (Vec<Vec<glam::DVec3>>, f64, usize) {
    let motion = motion(quality);
    let mut sim = HairSim::new(&document.hair_mesh, sdf.clone(), &motion, &[]);
    let bytes = sim.memory_bytes();
    let mut snapshots = Vec::with_capacity(CHECKPOINTS);
    let mut spent_s = 0.0;
    for checkpoint in 1..=CHECKPOINTS {
        let started = Instant::now();
        sim.seek(seconds * checkpoint as f64 / CHECKPOINTS as f64);
        spent_s += started.elapsed().as_secs_f64();
        snapshots.push(sim.positions().to_vec());
    }
    (snapshots, spent_s, bytes)
}

pub fn run(
    samples: &[String],
    seconds: f64,
    (reference_substeps, reference_iterations): (u32, u32),
    out: &Path,
) -> anyhow::Result<()> {
    if !(seconds.is_finite() && (0.1..=60.0).contains(&seconds)) {
        anyhow::bail!("--seconds {seconds}: must be between 0.1 and 60");
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let default = SimQuality::default();
    println!(
        "Simulator accuracy against time: {seconds} s of a head turn in wind, 60 Hz steps, one core"
    );
    println!("machine: {}", super::machine());
    println!(
        "reference: {reference_substeps} sub-steps × {reference_iterations} iterations; default {} × {}",
        default.substeps, default.iterations
    );
    let mut csv = String::from(
        "sample,particles,constraints,substeps,iterations,rms_error_mm,max_error_mm,ms_per_simulated_s,ms_per_60hz_frame,memory_kib\n",
    );
    let mut points = Vec::new();
    for name in samples {
        let path = hairloom_core::samples::default_sample_path()
            .with_file_name(format!("{name}.hairloom"));
        let document = hairloom_core::io::project::load(&path)?.document;
        let started = Instant::now();
        let sdf = BodySdf::for_hair(&document.body, &document.hair_mesh);
        let sdf_ms = started.elapsed().as_secs_f64() * 1e3;
        let reference_quality = SimQuality {
            substeps: reference_substeps,
            iterations: reference_iterations,
            ..default.clone()
        };
        let (reference, reference_s, _) = simulate(&document, &sdf, reference_quality, seconds);
        let sim = HairSim::new(
            &document.hair_mesh,
            sdf.clone(),
            &motion(default.clone()),
            &[],
        );
        let (particles, constraints) = (sim.particle_count(), sim.constraint_count());
        // The alternative to simulating interior vertices: re-place them every frame.
        let mut posed = sim.posed_mesh();
        let started = Instant::now();
        let repeats = 5;
        for _ in 0..repeats {
            place_interior(&mut posed, None);
        }
        let replace_ms = started.elapsed().as_secs_f64() * 1e3 / repeats as f64;
        println!(
            "\n{name}: {particles} particles, {constraints} constraints; body field {} KiB built in {sdf_ms:.0} ms; reference took {reference_s:.1} s",
            sdf.memory_bytes() / 1024
        );
        println!(
            "  re-placing the interior from the exterior: {replace_ms:.2} ms per frame (simulating it costs nothing extra: it is in the rows below)"
        );
        println!(
            "  {:>8} {:>10} {:>9} {:>9} {:>12} {:>13} {:>9}",
            "substeps", "iterations", "RMS mm", "max mm", "ms per sim s", "ms per 60 Hz", "memory"
        );
        for substeps in [1u32, 2, 4, 8] {
            for iterations in [1u32, 2, 4, 8] {
                let quality = SimQuality {
                    substeps,
                    iterations,
                    ..default.clone()
                };
                let (snapshots, spent_s, bytes) = simulate(&document, &sdf, quality, seconds);
                let (mut sum, mut count, mut worst) = (0.0, 0usize, 0.0f64);
                for (a, b) in snapshots.iter().zip(&reference) {
                    for (p, q) in a.iter().zip(b) {
                        let d = p.distance(*q);
                        sum += d * d;
                        count += 1;
                        worst = worst.max(d);
                    }
                }
                let rms_mm = 1e3 * (sum / count.max(1) as f64).sqrt();
                let ms_per_s = spent_s * 1e3 / seconds;
                let per_frame = ms_per_s / 60.0;
                let marker = if substeps == default.substeps && iterations == default.iterations {
                    "  ← default"
                } else {
                    ""
                };
                println!(
                    "  {substeps:>8} {iterations:>10} {rms_mm:>9.3} {:>9.3} {ms_per_s:>12.1} {per_frame:>13.3} {:>6} KiB{marker}",
                    1e3 * worst,
                    bytes / 1024
                );
                csv.push_str(&format!(
                    "{name},{particles},{constraints},{substeps},{iterations},{rms_mm:.4},{:.4},{ms_per_s:.2},{per_frame:.4},{}\n",
                    1e3 * worst,
                    bytes / 1024
                ));
                points.push((name.clone(), per_frame, rms_mm, substeps * iterations));
            }
        }
    }
    let csv_path = out.join("sim.csv");
    std::fs::write(&csv_path, csv).with_context(|| format!("writing {}", csv_path.display()))?;
    let png_path = out.join("sim.png");
    chart(&points, samples, &png_path)?;
    println!("\nwrote {} and {}", csv_path.display(), png_path.display());
    Ok(())
}

/// Error against time per frame, log-log, one colour per sample; bigger dots are more
/// sweeps (sub-steps × iterations).
fn chart(
    points: &[(String, f64, f64, u32)],
    samples: &[String],
    path: &Path,
) -> anyhow::Result<()> {
    const SIZE: u32 = 480;
    const MARGIN: f64 = 40.0;
    let mut image = image::RgbaImage::from_pixel(SIZE, SIZE, image::Rgba([255, 255, 255, 255]));
    let finite = |v: f64| v.is_finite() && v > 0.0;
    let (xs, ys): (Vec<f64>, Vec<f64>) = points
        .iter()
        .filter(|p| finite(p.1) && finite(p.2))
        .map(|p| (p.1.log10(), p.2.log10()))
        .unzip();
    let range = |v: &[f64]| {
        let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() && hi > lo {
            (lo, hi)
        } else {
            (0.0, 1.0)
        }
    };
    let ((x0, x1), (y0, y1)) = (range(&xs), range(&ys));
    let span = SIZE as f64 - 2.0 * MARGIN;
    for i in 0..SIZE {
        for axis in [(MARGIN as u32, i), (i, SIZE - MARGIN as u32)] {
            image.put_pixel(axis.0, axis.1.min(SIZE - 1), image::Rgba([0, 0, 0, 255]));
        }
    }
    let colours = [[200, 60, 40], [40, 120, 200], [60, 160, 60], [160, 80, 180]];
    for (name, ms, error, sweeps) in points {
        if !(finite(*ms) && finite(*error)) {
            continue;
        }
        let colour = samples.iter().position(|s| s == name).unwrap_or(0) % colours.len();
        let [r, g, b] = colours[colour];
        let x = MARGIN + (ms.log10() - x0) / (x1 - x0) * span;
        let y = SIZE as f64 - MARGIN - (error.log10() - y0) / (y1 - y0) * span;
        let radius = 2.0 + (*sweeps as f64).log2();
        for dy in -6i32..=6 {
            for dx in -6i32..=6 {
                if ((dx * dx + dy * dy) as f64) <= radius * radius {
                    let (px, py) = (x as i32 + dx, y as i32 + dy);
                    if (0..SIZE as i32).contains(&px) && (0..SIZE as i32).contains(&py) {
                        image.put_pixel(px as u32, py as u32, image::Rgba([r, g, b, 255]));
                    }
                }
            }
        }
    }
    image
        .save(path)
        .with_context(|| format!("writing {}", path.display()))
}
