//! The hair mesh's columns fitted to a groom's strands, layer by layer.
//!
//! A generated strand at corner weights `w` passes through `Σ_c w_c X_c(k)` at layer `k`
//! (the column-blend curve interpolates its layer points). So at each layer the column
//! positions `X(k)` are the least-squares solution of `Σ_c w_ic X_c(k) = P_i(k)` over the
//! strands `i`, where `P_i(k)` is strand `i` sampled at arc length `k/L` of its reference
//! length (the long strands of its neighbourhood: shorter strands stop early, as length
//! variation makes them). A small pull toward each column's straight continuation of the
//! layers below keeps columns that few strands constrain (or none, past the shorter
//! strands' tips) in line. The normal equations are assembled per bundle (a 4 × 4 block
//! per layer, from one pass over the strands) and solved by conjugate gradients, matrix
//! free: the blocks are the sparse matrix.
//! (No sparse solver crate: the matrix is a sum of tiny dense blocks that CG applies in a
//! few lines, and a factorisation per layer would cost more than the solve.)

use glam::DVec3;

/// Strand `i` sampled at `count` points `k/(count−1)` of `reference_length` along its arc
/// length; `None` past its own end (by more than 2 % of the reference).
pub fn sample_at_arc_length(
    points: &[[f32; 3]],
    reference_length: f64,
    count: usize,
) -> Vec<Option<DVec3>> {
    let to = super::to_d;
    let mut out = Vec::with_capacity(count);
    let mut segment = 0usize;
    let mut segment_start = 0.0f64;
    let last = points.len() - 1;
    let total = arc_length(points);
    for k in 0..count {
        let s = reference_length * k as f64 / (count - 1).max(1) as f64;
        if s > total + 0.02 * reference_length {
            out.push(None);
            continue;
        }
        // Walk forward to the segment holding s (samples rise, so the walk is linear).
        loop {
            if segment >= last {
                break;
            }
            let a = to(points[segment]);
            let b = to(points[segment + 1]);
            let len = (b - a).length();
            if segment_start + len >= s || segment + 1 == last {
                break;
            }
            segment_start += len;
            segment += 1;
        }
        if segment >= last {
            out.push(Some(to(points[last])));
            continue;
        }
        let a = to(points[segment]);
        let b = to(points[segment + 1]);
        let len = (b - a).length();
        let f = if len > 0.0 {
            ((s - segment_start) / len).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(Some(a.lerp(b, f)));
    }
    out
}

/// Arc length of a polyline.
pub fn arc_length(points: &[[f32; 3]]) -> f64 {
    points
        .windows(2)
        .map(|w| (super::to_d(w[1]) - super::to_d(w[0])).length())
        .sum()
}

/// The normal equations of one layer: per bundle, `G = Σ w wᵀ` and `R = Σ w Pᵀ`.
#[derive(Clone, Debug)]
pub struct LayerSystem {
    pub gram: Vec<[[f64; 4]; 4]>,
    pub rhs: Vec<[DVec3; 4]>,
}

impl LayerSystem {
    pub fn new(bundles: usize) -> Self {
        Self {
            gram: vec![[[0.0; 4]; 4]; bundles],
            rhs: vec![[DVec3::ZERO; 4]; bundles],
        }
    }

    pub fn add(&mut self, bundle: usize, weights: &[f64; 4], corners: usize, target: DVec3) {
        for a in 0..corners {
            for b in 0..corners {
                self.gram[bundle][a][b] += weights[a] * weights[b];
            }
            self.rhs[bundle][a] += target * weights[a];
        }
    }

    pub fn merge(&mut self, other: &LayerSystem) {
        for (g, o) in self.gram.iter_mut().zip(&other.gram) {
            for a in 0..4 {
                for b in 0..4 {
                    g[a][b] += o[a][b];
                }
            }
        }
        for (r, o) in self.rhs.iter_mut().zip(&other.rhs) {
            for a in 0..4 {
                r[a] += o[a];
            }
        }
    }
}

/// Solves `(Σ_b G_b + λ I + μ L) X = Σ_b R_b + λ · prediction + μ L · roots` for the
/// columns' positions: the data, a pull toward each column's `prediction`, and `L`, the
/// graph Laplacian over `edges`, asking neighbouring columns to move alike (their offsets
/// from their `roots` to match), which holds columns that few strands constrain.
/// `corners[b]` lists bundle `b`'s columns; `lambda` per column.
pub fn solve_layer(
    system: &LayerSystem,
    corners: &[Vec<u32>],
    lambda: &[f64],
    prediction: &[DVec3],
    smoothness: f64,
    edges: &[(u32, u32)],
    roots: &[DVec3],
) -> Vec<DVec3> {
    let n = prediction.len();
    let laplacian = |x: &[DVec3], out: &mut [DVec3], scale: f64| {
        for &(a, b) in edges {
            let d = (x[a as usize] - x[b as usize]) * scale;
            out[a as usize] += d;
            out[b as usize] -= d;
        }
    };
    let apply = |x: &[DVec3], out: &mut Vec<DVec3>| {
        out.clear();
        out.extend(x.iter().zip(lambda).map(|(x, l)| *x * *l));
        laplacian(x, out, smoothness);
        for (b, vertices) in corners.iter().enumerate() {
            let g = &system.gram[b];
            for (a, &ca) in vertices.iter().enumerate() {
                let mut sum = DVec3::ZERO;
                for (c, &cc) in vertices.iter().enumerate() {
                    sum += x[cc as usize] * g[a][c];
                }
                out[ca as usize] += sum;
            }
        }
    };
    let mut rhs: Vec<DVec3> = prediction
        .iter()
        .zip(lambda)
        .map(|(p, l)| *p * *l)
        .collect();
    laplacian(roots, &mut rhs, smoothness);
    for (b, vertices) in corners.iter().enumerate() {
        for (a, &ca) in vertices.iter().enumerate() {
            rhs[ca as usize] += system.rhs[b][a];
        }
    }
    // Conjugate gradients, the three coordinates at once (the matrix is the same).
    let mut x = prediction.to_vec();
    let mut ax = Vec::with_capacity(n);
    apply(&x, &mut ax);
    let mut r: Vec<DVec3> = rhs.iter().zip(&ax).map(|(b, a)| *b - *a).collect();
    let mut p = r.clone();
    let dot = |a: &[DVec3], b: &[DVec3]| -> DVec3 { a.iter().zip(b).map(|(a, b)| *a * *b).sum() };
    let mut rr = dot(&r, &r);
    let target = dot(&rhs, &rhs) * 1e-20;
    let mut ap = Vec::with_capacity(n);
    for _ in 0..(4 * n).max(64) {
        if rr.cmple(target).all() {
            break;
        }
        apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        let alpha = DVec3::select(pap.cmpgt(DVec3::ZERO), rr / pap, DVec3::ZERO);
        for i in 0..n {
            x[i] += p[i] * alpha;
            r[i] -= ap[i] * alpha;
        }
        let rr_new = dot(&r, &r);
        let beta = DVec3::select(rr.cmpgt(DVec3::ZERO), rr_new / rr, DVec3::ZERO);
        for i in 0..n {
            p[i] = r[i] + p[i] * beta;
        }
        rr = rr_new;
    }
    x
}
