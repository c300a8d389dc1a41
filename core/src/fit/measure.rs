//! How close a fitted groom is to its input, in numbers an artist can act on.
//!
//! Both strand sets are resampled at an even arc-length spacing (`1/400` of the input's box
//! diagonal, so the points' own spacing adds at most `1/800` of it to a distance), at most
//! `max_strands` strands of each taken at an even stride; every point's distance to the
//! nearest point of the other set is measured both ways (`kiddo` k-d trees). Distances are
//! shares of the input's box diagonal. Root placement is each input root's distance to the
//! scalp point its strand was given; strand length compares each bundle's mean input length
//! with the mean length of the strands the fitted bundle grows.

use glam::DVec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};

use super::Fitted;
use crate::io::groom_in::InputGroom;
use crate::strands::reference::{Strand, StrandOptions, generate_parallel};

/// Mean, 95th percentile and maximum of a set of distances, as shares of the groom's size.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Distances {
    pub mean: f64,
    pub p95: f64,
    pub max: f64,
    pub count: usize,
}

impl Distances {
    fn of(mut values: Vec<f64>, size: f64) -> Self {
        if values.is_empty() {
            return Self::default();
        }
        values.sort_by(f64::total_cmp);
        let n = values.len();
        Self {
            mean: values.iter().sum::<f64>() / n as f64 / size,
            p95: values[((n as f64 * 0.95) as usize).min(n - 1)] / size,
            max: values[n - 1] / size,
            count: n,
        }
    }
}

/// The error report `hairloom fit` prints and writes.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct FitReport {
    pub input_curves: usize,
    pub input_points: usize,
    /// The input's box diagonal, in its units: every share below is of this.
    pub size: f64,
    pub input_to_fit: Distances,
    pub fit_to_input: Distances,
    /// Both directions pooled: the number the targets are set on.
    pub pooled: Distances,
    pub root_placement: Distances,
    /// Mean over bundles (weighted by their input strands) of |generated − input| / input
    /// mean strand length.
    pub length_error: f64,
    pub generated_strands: usize,
    pub strands_per_bundle: u32,
    pub bundles: usize,
    pub growing_bundles: usize,
    pub columns: usize,
    pub vertices: usize,
    pub layers: u32,
    /// Interior vertices, and how many of them the fit locked where the strands put them.
    pub interior_vertices: usize,
    pub locked_interior: usize,
    pub timings_s: Vec<(String, f64)>,
}

impl FitReport {
    /// A short table for a terminal.
    pub fn summary(&self) -> String {
        let row = |name: &str, d: &Distances| {
            format!(
                "  {name:<22} mean {:>6.3} %   p95 {:>6.3} %   max {:>6.3} %\n",
                100.0 * d.mean,
                100.0 * d.p95,
                100.0 * d.max
            )
        };
        let mut text = format!(
            "input: {} curves, {} points, box diagonal {:.4}\nfitted: {} of {} bundles grow hair, {} columns, {} vertices ({} of {} interior ones locked where the strands put them), {} layers; {} strands per bundle → {} strands\nerrors (share of the box diagonal):\n",
            self.input_curves,
            self.input_points,
            self.size,
            self.growing_bundles,
            self.bundles,
            self.columns,
            self.vertices,
            self.locked_interior,
            self.interior_vertices,
            self.layers,
            self.strands_per_bundle,
            self.generated_strands
        );
        text += &row("input → fitted", &self.input_to_fit);
        text += &row("fitted → input", &self.fit_to_input);
        text += &row("both ways", &self.pooled);
        text += &row("root placement", &self.root_placement);
        text += &format!(
            "  strand length          {:.2} % (per bundle mean)\n",
            100.0 * self.length_error
        );
        text += "time:";
        for (step, seconds) in &self.timings_s {
            text += &format!(" {step} {seconds:.2} s,");
        }
        text.pop();
        text.push('\n');
        text
    }
}

/// What to measure with.
#[derive(Clone, Copy, Debug)]
pub struct MeasureOptions {
    pub max_strands: usize,
    pub vertices_log2: u32,
    pub threads: usize,
}

impl Default for MeasureOptions {
    fn default() -> Self {
        Self {
            max_strands: 20_000,
            vertices_log2: 5,
            threads: 0,
        }
    }
}

/// Most samples a strand adds beyond its own points: a strand that zigzags across the whole
/// groom would otherwise add hundreds per segment.
const MAX_SAMPLES_PER_STRAND: f64 = 1024.0;

fn resample(points: &[DVec3], spacing: f64, out: &mut Vec<[f64; 3]>) {
    let Some(first) = points.first() else {
        return;
    };
    let length: f64 = points.windows(2).map(|w| (w[1] - w[0]).length()).sum();
    let spacing = spacing.max(length / MAX_SAMPLES_PER_STRAND);
    out.push(first.to_array());
    for w in points.windows(2) {
        let len = (w[1] - w[0]).length();
        let steps = (len / spacing).ceil().max(1.0) as usize;
        for k in 1..=steps {
            out.push(w[0].lerp(w[1], k as f64 / steps as f64).to_array());
        }
    }
}

fn nearest_distances(
    tree: &ImmutableKdTree<f64, 3>,
    points: &[[f64; 3]],
    threads: usize,
) -> Vec<f64> {
    super::in_chunks(points.len(), threads, |range| {
        range
            .map(|i| {
                tree.query(&points[i])
                    .nearest_one::<SquaredEuclidean<f64>>()
                    .execute()
                    .distance
                    .sqrt()
            })
            .collect::<Vec<_>>()
    })
    .into_iter()
    .flatten()
    .collect()
}

/// The generated strands of `fitted` (at its strands per bundle).
pub fn fitted_strands(fitted: &Fitted, options: &MeasureOptions, threads: usize) -> Vec<Strand> {
    let strand_options = StrandOptions {
        strands_per_bundle: fitted.strands_per_bundle,
        vertices_log2: options.vertices_log2,
        ..StrandOptions::default()
    };
    generate_parallel(&fitted.document, &strand_options, threads)
}

/// Scores `fitted` against `groom` (see the module comment).
pub fn measure(groom: &InputGroom, fitted: &Fitted, options: &MeasureOptions) -> FitReport {
    let threads = if options.threads > 0 {
        options.threads
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    };
    let size = groom.diagonal().max(1e-12);
    let spacing = size / 400.0;
    let generated = fitted_strands(fitted, options, threads);
    let stride = |count: usize| count.div_ceil(options.max_strands.max(1)).max(1);
    let mut input_points = Vec::new();
    for i in (0..groom.curve_count()).step_by(stride(groom.curve_count())) {
        let curve: Vec<DVec3> = groom.curve(i).iter().map(|&p| super::to_d(p)).collect();
        resample(&curve, spacing, &mut input_points);
    }
    let mut fit_points = Vec::new();
    for strand in generated.iter().step_by(stride(generated.len())) {
        resample(&strand.points, spacing, &mut fit_points);
    }
    let mut report = FitReport {
        input_curves: groom.curve_count(),
        input_points: groom.points.len(),
        size,
        generated_strands: generated.len(),
        strands_per_bundle: fitted.strands_per_bundle,
        ..FitReport::default()
    };
    if !input_points.is_empty()
        && !fit_points.is_empty()
        && let (Ok(input_tree), Ok(fit_tree)) = (
            ImmutableKdTree::new_from_slice(&input_points),
            ImmutableKdTree::new_from_slice(&fit_points),
        )
    {
        let forward = nearest_distances(&fit_tree, &input_points, threads);
        let backward = nearest_distances(&input_tree, &fit_points, threads);
        let pooled: Vec<f64> = forward.iter().chain(&backward).copied().collect();
        report.input_to_fit = Distances::of(forward, size);
        report.fit_to_input = Distances::of(backward, size);
        report.pooled = Distances::of(pooled, size);
    }
    report.root_placement = Distances::of(fitted.hits.iter().map(|h| h.distance).collect(), size);
    // Strand length per bundle.
    let mesh = &fitted.document.hair_mesh;
    let mut input_sum = vec![(0.0f64, 0usize); mesh.bundles.len()];
    for (i, hit) in fitted.hits.iter().enumerate() {
        let entry = &mut input_sum[hit.face as usize];
        entry.0 += super::columns::arc_length(groom.curve(i));
        entry.1 += 1;
    }
    let mut generated_sum = vec![(0.0f64, 0usize); mesh.bundles.len()];
    for strand in &generated {
        let length: f64 = strand
            .points
            .windows(2)
            .map(|w| (w[1] - w[0]).length())
            .sum();
        let entry = &mut generated_sum[strand.bundle as usize];
        entry.0 += length;
        entry.1 += 1;
    }
    let (mut error, mut weight) = (0.0, 0.0);
    for (input, generated) in input_sum.iter().zip(&generated_sum) {
        if input.1 > 0 && generated.1 > 0 {
            let a = input.0 / input.1 as f64;
            let b = generated.0 / generated.1 as f64;
            error += input.1 as f64 * ((b - a).abs() / a.max(1e-300));
            weight += input.1 as f64;
        }
    }
    report.length_error = error / weight.max(1.0);
    report.bundles = mesh.bundles.len();
    report.growing_bundles = mesh.bundles.iter().filter(|b| b.layers > 0).count();
    report.columns = mesh.columns.len();
    report.vertices = mesh.vertex_count();
    report.layers = mesh.max_layers() as u32;
    let topology = crate::model::mesh::Topology::build(mesh);
    report.interior_vertices = (0..mesh.columns.len())
        .map(|c| {
            (1..mesh.columns[c].positions.len())
                .filter(|&k| mesh.is_interior(&topology, c, k))
                .count()
        })
        .sum();
    report.locked_interior = fitted.locked_interior;
    report.timings_s = fitted
        .timings_s
        .iter()
        .map(|(s, t)| (s.to_string(), *t))
        .collect();
    report
}
