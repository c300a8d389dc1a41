//! Strand root positions: progressive blue-noise sample sets by weighted sample elimination
//! (Yuksel 2015, "Sample Elimination for Generating Poisson Disk Sample Sets"), as in seed
//! 000 §3.3.
//!
//! A set is *progressive*: every prefix of it is itself well spread, so a bundle that draws
//! `k` strands uses samples `0..k` and LOD can drop strands from the end without clumping.
//!
//! - [`SampleDomain::Square`]: samples in `[0,1)²` for quad bundles, with toroidal distances so
//!   that the same set in neighbouring bundles stays blue across their shared edges.
//! - [`SampleDomain::Triangle`]: samples in the half `s + t < 1` for triangle bundles. Their
//!   barycentric coordinates are `(1−s−t, s, t)`; [`triangle_to_block`] maps them onto the
//!   2×2 texel block of a triangle (whose third corner is duplicated) as
//!   `(s / (1 − t), t)`, which makes bilinear filtering equal the barycentric blend. (Seed 000
//!   prints `s (1 − t)`; only the quotient has that property, see `curve::FaceCoord`.)

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::strands::random::SplitMix64;

/// Where samples live.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SampleDomain {
    Square,
    Triangle,
}

impl SampleDomain {
    fn area(self) -> f64 {
        match self {
            Self::Square => 1.0,
            Self::Triangle => 0.5,
        }
    }
}

/// Candidates per output sample (Yuksel 2015 uses 5).
const CANDIDATE_RATIO: usize = 5;
/// Weight exponent α of `w(d) = (1 − d / 2r_max)^α`.
const WEIGHT_EXPONENT: i32 = 8;
/// Weight-limiting parameters β and γ: distances below
/// `r_min = r_max β (1 − (N/M)^γ)` weigh as much as `r_min`.
const LIMIT_BETA: f64 = 0.65;
const LIMIT_GAMMA: f64 = 1.5;

/// The maximum Poisson-disk radius for `count` samples in `area`: hexagonal packing.
pub(crate) fn max_radius(count: usize, area: f64) -> f64 {
    (area / (2.0 * 3f64.sqrt() * count.max(1) as f64)).sqrt()
}

/// `count` progressive blue-noise samples in `domain`, deterministic from `seed`.
pub fn progressive_samples(count: usize, domain: SampleDomain, seed: u64) -> Vec<DVec2> {
    if count == 0 {
        return Vec::new();
    }
    let mut rng = SplitMix64::new(seed);
    let candidates: Vec<DVec2> = (0..count * CANDIDATE_RATIO)
        .map(|_| {
            let p = DVec2::new(rng.next_f64(), rng.next_f64());
            match domain {
                SampleDomain::Square => p,
                // Fold the upper triangle onto the lower one: uniform in s + t < 1.
                SampleDomain::Triangle if p.x + p.y >= 1.0 => DVec2::ONE - p,
                SampleDomain::Triangle => p,
            }
        })
        .collect();
    let (mut current, _) = eliminate(&candidates, count, domain);
    // Progressive order: repeatedly halve; the samples eliminated at each halving go, best
    // (last eliminated) first, right after the survivors.
    let mut ordered = vec![DVec2::ZERO; count];
    let mut end = count;
    while end > 1 {
        let half = end / 2;
        let (survivors, eliminated) = eliminate(&current, half, domain);
        for (i, p) in eliminated.iter().rev().enumerate() {
            ordered[half + i] = *p;
        }
        current = survivors;
        end = half;
    }
    ordered[0] = current[0];
    ordered
}

/// Eliminates samples from `points` until `target` remain. Returns (survivors in input
/// order, eliminated in elimination order).
fn eliminate(points: &[DVec2], target: usize, domain: SampleDomain) -> (Vec<DVec2>, Vec<DVec2>) {
    let n = points.len();
    if target >= n {
        return (points.to_vec(), Vec::new());
    }
    let r_max = max_radius(target, domain.area());
    let r_min = r_max * LIMIT_BETA * (1.0 - (target as f64 / n as f64).powf(LIMIT_GAMMA));
    let reach = 2.0 * r_max;
    let toroidal = domain == SampleDomain::Square;
    let distance = |a: DVec2, b: DVec2| {
        let mut d = (a - b).abs();
        if toroidal {
            d = d.min(DVec2::ONE - d);
        }
        d.length()
    };
    let weight = |d: f64| {
        let d = d.max(r_min);
        (1.0 - d / reach).max(0.0).powi(WEIGHT_EXPONENT)
    };
    // Uniform grid of cells at least `reach` wide.
    let cells = ((1.0 / reach).floor() as usize).clamp(1, 1024);
    let cell_of = |p: DVec2| {
        let c = (p * cells as f64).floor();
        ((c.x as usize).min(cells - 1), (c.y as usize).min(cells - 1))
    };
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); cells * cells];
    for (i, p) in points.iter().enumerate() {
        let (cx, cy) = cell_of(*p);
        grid[cy * cells + cx].push(i as u32);
    }
    let neighbours = |i: usize, visit: &mut dyn FnMut(usize, f64)| {
        let (cx, cy) = cell_of(points[i]);
        let span: isize = if cells < 3 { 0 } else { 1 };
        let mut seen_cells: Vec<usize> = Vec::with_capacity(9);
        for dy in -span..=span {
            for dx in -span..=span {
                let wrap = |c: usize, d: isize| -> Option<usize> {
                    let v = c as isize + d;
                    if toroidal {
                        Some(v.rem_euclid(cells as isize) as usize)
                    } else if v < 0 || v >= cells as isize {
                        None
                    } else {
                        Some(v as usize)
                    }
                };
                let (Some(x), Some(y)) = (wrap(cx, dx), wrap(cy, dy)) else {
                    continue;
                };
                let cell = y * cells + x;
                if seen_cells.contains(&cell) {
                    continue;
                }
                seen_cells.push(cell);
                for &j in &grid[cell] {
                    let j = j as usize;
                    if j != i {
                        let d = distance(points[i], points[j]);
                        if d < reach {
                            visit(j, d);
                        }
                    }
                }
            }
        }
    };
    let mut weights = vec![0.0f64; n];
    for (i, w) in weights.iter_mut().enumerate() {
        neighbours(i, &mut |_, d| *w += weight(d));
    }
    // Max-heap with lazy invalidation: an entry is current when its weight matches.
    let mut heap: std::collections::BinaryHeap<(OrderedWeight, u32)> = weights
        .iter()
        .enumerate()
        .map(|(i, &w)| (OrderedWeight(w), i as u32))
        .collect();
    let mut removed = vec![false; n];
    let mut eliminated = Vec::with_capacity(n - target);
    while eliminated.len() < n - target {
        let Some((OrderedWeight(w), i)) = heap.pop() else {
            break;
        };
        let i = i as usize;
        if removed[i] || w != weights[i] {
            continue;
        }
        removed[i] = true;
        eliminated.push(points[i]);
        let mut updates = Vec::new();
        neighbours(i, &mut |j, d| {
            if !removed[j] {
                updates.push((j, weight(d)));
            }
        });
        for (j, dw) in updates {
            weights[j] -= dw;
            heap.push((OrderedWeight(weights[j]), j as u32));
        }
    }
    let survivors = (0..n).filter(|&i| !removed[i]).map(|i| points[i]).collect();
    (survivors, eliminated)
}

/// f64 with a total order for the heap (weights are always finite).
#[derive(Clone, Copy, PartialEq)]
struct OrderedWeight(f64);

impl Eq for OrderedWeight {}

impl PartialOrd for OrderedWeight {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for OrderedWeight {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// Maps a triangle sample `(s, t)` (barycentric `1−s−t, s, t`) to the 2×2 texel block of a
/// triangle bundle: `(s / (1 − t), t)`. At the duplicated corner (`t = 1`) any first
/// coordinate gives the same point; 0 is returned.
pub(crate) fn triangle_to_block(sample: DVec2) -> DVec2 {
    let denominator = 1.0 - sample.y;
    let s = if denominator > 0.0 {
        (sample.x / denominator).clamp(0.0, 1.0)
    } else {
        0.0
    };
    DVec2::new(s, sample.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn min_spacing(points: &[DVec2], toroidal: bool) -> f64 {
        let mut best = f64::INFINITY;
        for i in 0..points.len() {
            for j in i + 1..points.len() {
                let mut d = (points[i] - points[j]).abs();
                if toroidal {
                    d = d.min(DVec2::ONE - d);
                }
                best = best.min(d.length());
            }
        }
        best
    }

    #[test]
    fn every_prefix_keeps_a_minimum_spacing() {
        let samples = progressive_samples(1024, SampleDomain::Square, 1);
        assert_eq!(samples.len(), 1024);
        assert!(
            samples
                .iter()
                .all(|p| (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y))
        );
        // Relative radius d_min / r_max: white noise falls toward 0 as N grows; sample
        // elimination keeps it bounded below at every prefix, not only at powers of two.
        let mut worst: f64 = f64::INFINITY;
        for k in (2..=1024).step_by(7).chain([16, 64, 256, 1024]) {
            let relative = min_spacing(&samples[..k], true) / max_radius(k, 1.0);
            worst = worst.min(relative);
        }
        assert!(worst > 0.3, "worst relative spacing {worst}");
        let full = min_spacing(&samples, true) / max_radius(1024, 1.0);
        assert!(full > 0.6, "full set relative spacing {full}");
        // White noise of the same size for contrast.
        let mut rng = SplitMix64::new(1);
        let white: Vec<DVec2> = (0..1024)
            .map(|_| DVec2::new(rng.next_f64(), rng.next_f64()))
            .collect();
        assert!(min_spacing(&white, true) / max_radius(1024, 1.0) < 0.1);
    }

    #[test]
    fn sets_are_deterministic_per_seed() {
        let a = progressive_samples(200, SampleDomain::Triangle, 9);
        assert_eq!(a, progressive_samples(200, SampleDomain::Triangle, 9));
        assert_ne!(a, progressive_samples(200, SampleDomain::Triangle, 10));
        assert!(
            a.iter()
                .all(|p| p.x >= 0.0 && p.y >= 0.0 && p.x + p.y <= 1.0)
        );
    }

    /// Counts of points (as barycentric positions) in the four midpoint sub-triangles.
    fn sub_triangle_counts(points: impl Iterator<Item = DVec2>) -> [usize; 4] {
        let mut counts = [0; 4];
        for p in points {
            let (s, t) = (p.x, p.y);
            let index = if s + t < 0.5 {
                0
            } else if s >= 0.5 {
                1
            } else if t >= 0.5 {
                2
            } else {
                3
            };
            counts[index] += 1;
        }
        counts
    }

    #[test]
    fn triangle_set_mapped_through_the_block_is_area_uniform() {
        // Sample on the block, evaluate the bilinear blend of (a, b, c, c) at the mapped
        // coordinates and read back barycentric (s, t): each quarter of the triangle must
        // hold a quarter of the samples (±6% with this fixed seed).
        let samples = progressive_samples(2048, SampleDomain::Triangle, 3);
        let blended = samples.iter().map(|&p| {
            let q = triangle_to_block(p);
            // Bilinear weights of corners a, b, c, c(duplicate): (1−x)(1−y), x(1−y), y (x + 1 − x).
            DVec2::new(q.x * (1.0 - q.y), q.y)
        });
        let counts = sub_triangle_counts(blended);
        for c in counts {
            assert!((c as f64 - 512.0).abs() < 0.06 * 512.0, "{counts:?}");
        }
        // Using the quad set on a triangle instead is biased toward the duplicated corner.
        let quad = progressive_samples(2048, SampleDomain::Square, 3);
        let biased = sub_triangle_counts(quad.iter().map(|q| DVec2::new(q.x * (1.0 - q.y), q.y)));
        assert!(biased[2] as f64 > 1.5 * 512.0, "{biased:?}");
    }

    #[test]
    fn degenerate_inputs() {
        assert!(progressive_samples(0, SampleDomain::Square, 0).is_empty());
        assert_eq!(progressive_samples(1, SampleDomain::Square, 0).len(), 1);
        assert_eq!(
            triangle_to_block(DVec2::new(0.0, 1.0)),
            DVec2::new(0.0, 1.0)
        );
        assert!(triangle_to_block(DVec2::new(0.3, 1.0 - 1e-300)).is_finite());
    }
}
