//! CPU mirror of the per-vertex work of `shaders/preview_hair.wgsl`: the eq. 5-6 ribbon
//! tangents, in f32 as the vertex shader computes them from a batch of generated strand
//! vertices (`render/tests/preview_tangents.rs` compares them with a GPU read-back). The f64
//! definition is [`crate::strands::lod::tangents`]; the renderer is `render/src/preview.rs`.

use glam::Vec3;

use crate::runtime::gpu_types::StrandRun;

/// Mirror of `safe_normalize`: the unit vector, or zero when `v` has (almost) no length.
pub(crate) fn safe_normalize(v: Vec3) -> Vec3 {
    let length_squared = v.dot(v);
    // As the shader's `!(x > 1e-24)`: NaN lengths give zero too.
    if length_squared.is_nan() || length_squared <= 1e-24 {
        return Vec3::ZERO;
    }
    v / length_squared.sqrt()
}

/// Mirror of `strand_tangent`: the tangent at vertex `k` of the `n`-vertex strand starting
/// at `positions[base]`. Inner vertices use `p[k+1] − p[k−1]`; an end reflects its
/// neighbour's tangent about the end segment.
pub fn strand_tangent(positions: &[Vec3], base: usize, k: usize, n: usize) -> Vec3 {
    let p = |i: usize| positions[base + i];
    if n == 2 {
        return safe_normalize(p(1) - p(0));
    }
    if k > 0 && k + 1 < n {
        return safe_normalize(p(k + 1) - p(k - 1));
    }
    let (inner, end_segment) = if k > 0 {
        (n - 2, p(n - 1) - p(n - 2))
    } else {
        (1, p(1) - p(0))
    };
    let t = safe_normalize(p(inner + 1) - p(inner - 1));
    let q = safe_normalize(end_segment);
    if q.dot(q) == 0.0 {
        return t;
    }
    if t.dot(t) == 0.0 {
        return q;
    }
    safe_normalize(2.0 * q * t.dot(q) - t)
}

/// The tangent of every vertex of a batch, in the batch's order
/// (`run.vertex_offset + strand · run.vertex_count + k`).
pub fn batch_tangents(positions: &[Vec3], runs: &[StrandRun]) -> Vec<Vec3> {
    let mut out = vec![Vec3::ZERO; positions.len()];
    for run in runs {
        let n = run.vertex_count.max(2) as usize;
        for strand in 0..run.strand_count as usize {
            let base = run.vertex_offset as usize + strand * n;
            for k in 0..n {
                if let Some(slot) = out.get_mut(base + k) {
                    *slot = strand_tangent(positions, base, k, n);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::strands::lod::tangents;

    #[test]
    fn the_f32_mirror_follows_the_f64_definition() {
        for n in [2usize, 3, 5, 17, 33] {
            let points: Vec<DVec3> = (0..n)
                .map(|k| {
                    let t = k as f64 / (n - 1) as f64;
                    DVec3::new((5.0 * t).sin(), 2.0 * t, 0.3 * t * t)
                })
                .collect();
            let f32_points: Vec<Vec3> = points.iter().map(|p| p.as_vec3()).collect();
            let expected = tangents(&points);
            for (k, e) in expected.iter().enumerate() {
                let got = strand_tangent(&f32_points, 0, k, n).as_dvec3();
                assert!(got.distance(*e) < 1e-5, "n {n} k {k}: {got} vs {e}");
            }
        }
    }

    #[test]
    fn degenerate_strands_give_zero_or_finite_unit_tangents() {
        let same = vec![Vec3::ONE; 4];
        for k in 0..4 {
            assert_eq!(strand_tangent(&same, 0, k, 4), Vec3::ZERO);
        }
        // Coincident end vertices: the end borrows its neighbour's tangent.
        let end = [Vec3::ZERO, Vec3::ZERO, Vec3::X, Vec3::new(2.0, 1.0, 0.0)];
        let t = strand_tangent(&end, 0, 0, 4);
        assert!((t.length() - 1.0).abs() < 1e-6, "{t}");
        let runs = [StrandRun {
            strand_count: 1,
            vertex_count: 4,
            ..StrandRun::default()
        }];
        let all = batch_tangents(&end, &runs);
        assert_eq!(all.len(), 4);
        assert!(all.iter().all(|t| t.is_finite()));
    }
}
