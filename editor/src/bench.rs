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
