//! Automatic placement of interior hair-mesh vertices (seed 000 §2.2).
//!
//! The user places the exterior vertices (see [`HairMesh::is_interior`]); the interior
//! vertices of each layer follow them. For layer `k` with exterior vertices `q_i` over root
//! positions `p_i`:
//!
//! 1. Fit an affine map `A(p) = L p + t` from the root positions of the exterior to their
//!    layer-`k` positions ([`fit_affine`]).
//! 2. Residuals `r_i = q_i − A(p_i)` are known at the exterior; interpolate them over the
//!    layer's mesh graph with a harmonic (uniform-weight Laplace) interpolant.
//! 3. Each interior vertex is placed at `A(p_root) + r`.
//!
//! Properties (tested below): exterior vertices never move; when the layer's exterior is an
//! affine image of the root layer's, the residuals are zero and interior vertices are the same
//! affine image; the result is a continuous function of the exterior positions; it is finite
//! and bounded for degenerate layouts (the harmonic interpolant obeys the maximum principle,
//! and the affine fit is regularised along directions the exterior does not span).
//!
//! A connected group of interior vertices that touches no exterior vertex on its layer (a
//! closed scalp such as the teapot, fully extruded) has nothing to follow on its own layer;
//! those vertices are interpolated along their column between the nearest exterior vertices
//! below and above, by layer index.

use glam::{DMat3, DVec3};

use crate::model::mesh::{HairMesh, Topology};

/// Relative strength of the regularisation of the affine fit: directions along which the
/// exterior's root positions spread less than about `sqrt(FIT_REGULARISATION)` of their
/// average spread are taken from the prior instead of from the data.
const FIT_REGULARISATION: f64 = 1e-4;
/// Iterations of the iterated-Tikhonov fit. Well-determined directions converge to the
/// exact least-squares map as `β^k` (about 1e-16 here), weak ones stay regularised.
const FIT_ITERATIONS: i32 = 4;
/// Conjugate-gradient stopping criterion, relative to the right-hand side.
const SOLVE_RELATIVE_TOLERANCE: f64 = 1e-13;

/// An affine map `p ↦ linear · p + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AffineMap {
    pub linear: DMat3,
    pub translation: DVec3,
}

impl AffineMap {
    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.linear * p + self.translation
    }
}

/// Least-squares affine map taking `from[i]` to `to[i]`, regularised so that it is finite
/// and continuous for any input (no points, coincident, collinear or coplanar points).
///
/// Along the eigen-directions of the centred covariance of `from` that the data spans well,
/// the map is the exact least-squares solution. Along a weakly spanned direction `n` (a
/// coplanar exterior, the usual case for a scalp rim) the prior for `L n` is the cross product
/// of the images of the two other directions, scaled so that rotations and uniform scalings
/// are reproduced exactly: `m = (L e1 × L e2) / sqrt(|L e1 × L e2|)`. Other directions use the
/// identity as prior. With no points, the identity map is returned.
pub(crate) fn fit_affine(from: &[DVec3], to: &[DVec3]) -> AffineMap {
    let count = from.len().min(to.len());
    if count == 0 {
        return AffineMap {
            linear: DMat3::IDENTITY,
            translation: DVec3::ZERO,
        };
    }
    let mean_from = from[..count].iter().copied().sum::<DVec3>() / count as f64;
    let mean_to = to[..count].iter().copied().sum::<DVec3>() / count as f64;
    // Work in units of each side's RMS spread so that huge (1e300) and tiny (1e-300)
    // coordinates neither overflow nor underflow in the products below.
    let rms = |points: &[DVec3], mean: DVec3| {
        let sum: f64 = points
            .iter()
            .map(|p| ((*p - mean) / (1.0 + mean.abs().max_element())).length_squared())
            .sum();
        (sum / count as f64).sqrt() * (1.0 + mean.abs().max_element())
    };
    let scale_from = rms(&from[..count], mean_from);
    let scale_to = rms(&to[..count], mean_to);
    if !(scale_from > 0.0 && scale_from.is_finite()) {
        // All source points coincide: only the translation is determined.
        return AffineMap {
            linear: DMat3::IDENTITY,
            translation: mean_to - mean_from,
        };
    }
    let scale_to = if scale_to > 0.0 && scale_to.is_finite() {
        scale_to
    } else {
        1.0
    };
    // Covariance XᵀX and cross term XᵀY of centred, normalised data (column-major DMat3).
    let mut xtx = DMat3::ZERO;
    let mut xty = DMat3::ZERO;
    for i in 0..count {
        let x = (from[i] - mean_from) / scale_from;
        let y = (to[i] - mean_to) / scale_to;
        xtx += outer(x, x);
        xty += outer(x, y);
    }
    let (eigenvalues, eigenvectors) = symmetric_eigen(xtx);
    let trace = eigenvalues.x + eigenvalues.y + eigenvalues.z;
    let tau2 = FIT_REGULARISATION * trace / 3.0;
    // Per eigen-direction: L v = g · (XᵀY)ᵀ v + f · prior(v), the closed form of
    // FIT_ITERATIONS iterated-Tikhonov steps with β = τ² / (λ + τ²).
    let factors = |lambda: f64| {
        let beta = tau2 / (lambda.max(0.0) + tau2);
        let f = beta.powi(FIT_ITERATIONS);
        let g = (0..FIT_ITERATIONS).map(|j| beta.powi(j)).sum::<f64>() / (lambda.max(0.0) + tau2);
        (g, f)
    };
    let xty_t = xty.transpose();
    // The image of eigen-direction `v` (eigenvalue `lambda`): the data's least-squares image
    // blended with `prior`.
    let image = |v: DVec3, lambda: f64, prior: DVec3| {
        let (g, f) = factors(lambda);
        xty_t * v * g + prior * f
    };
    // Eigenvalues are sorted descending, so axis 2 is the least determined direction. Its
    // vector is taken as e0 × e1 for both the data term and the prior: the solver's third
    // eigenvector may point the other way, and mixing the two orientations reflected the
    // map (interior vertices of a curved scalp landed inside the head).
    let e0 = eigenvectors.col(0);
    let e1 = eigenvectors.col(1);
    let n = e0.cross(e1);
    let a0 = image(e0, eigenvalues.x, e0);
    let a1 = image(e1, eigenvalues.y, e1);
    let c = a0.cross(a1);
    let scale2 = (a0.length_squared() + a1.length_squared()).max(f64::MIN_POSITIVE);
    let completion = c / (c.length() + 1e-24 * scale2).sqrt();
    let a2 = image(n, eigenvalues.z, completion);
    // L = Σ a_i v_iᵀ, with v_2 = n (same orientation used for the completion).
    let linear = outer(e0, a0) + outer(e1, a1) + outer(n, a2);
    let linear = linear.transpose() * (scale_to / scale_from);
    AffineMap {
        linear,
        translation: mean_to - linear * mean_from,
    }
}

/// Outer product `a bᵀ` as a column-major matrix (column j is `a · b[j]`).
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations. Returns
/// eigenvalues in descending order and the matching unit eigenvectors as columns.
#[expect(
    clippy::needless_range_loop,
    reason = "a Jacobi rotation updates rows and columns p and q in lockstep; indices mirror the textbook form"
)]
pub(crate) fn symmetric_eigen(matrix: DMat3) -> (DVec3, DMat3) {
    let mut a = matrix.to_cols_array_2d(); // a[col][row]; symmetric so a[i][j] == a[j][i]
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..32 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let diag = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= f64::EPSILON * 1e-3 * diag || off == 0.0 || !off.is_finite() {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let akp = a[k][p];
                let akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let apk = a[p][k];
                let aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in &mut v {
                let vp = row[p];
                let vq = row[q];
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    // v[row][col]: eigenvector j is (v[0][j], v[1][j], v[2][j]).
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]));
    let values = DVec3::new(
        a[order[0]][order[0]],
        a[order[1]][order[1]],
        a[order[2]][order[2]],
    );
    let column = |j: usize| DVec3::new(v[0][j], v[1][j], v[2][j]);
    let vectors = DMat3::from_cols(column(order[0]), column(order[1]), column(order[2]));
    (values, vectors)
}

/// Places the interior vertices of every layer listed in `layers` (all layers when `None`).
/// Exterior vertices are not touched.
pub fn place_interior(mesh: &mut HairMesh, layers: Option<&[usize]>) {
    let topology = Topology::build(mesh);
    let max_layer = mesh.max_layers();
    let all: Vec<usize> = (1..=max_layer).collect();
    let layers = layers.unwrap_or(&all);
    for &layer in layers {
        if layer == 0 || layer > max_layer {
            continue;
        }
        place_layer(mesh, &topology, layer);
    }
}

/// Interior placement for one layer.
fn place_layer(mesh: &mut HairMesh, topology: &Topology, layer: usize) {
    let column_count = mesh.columns.len();
    // Layer graph: columns that reach this layer, joined by edges of bundles that reach it.
    const ABSENT: u32 = u32::MAX;
    let mut slot = vec![ABSENT; column_count];
    let mut members: Vec<usize> = Vec::new();
    let mut interior_flags: Vec<bool> = Vec::new();
    let mut neighbours: Vec<Vec<u32>> = Vec::new();
    for bundle in mesh.bundles.iter().filter(|b| b.reaches(layer)) {
        let n = bundle.vertices.len();
        for i in 0..n {
            let a = bundle.vertices[i] as usize;
            let b = bundle.vertices[(i + 1) % n] as usize;
            for v in [a, b] {
                if slot[v] == ABSENT {
                    slot[v] = members.len() as u32;
                    members.push(v);
                    // A locked vertex is known, like an exterior one.
                    interior_flags
                        .push(mesh.is_interior(topology, v, layer) && !mesh.is_locked(v, layer));
                    neighbours.push(Vec::new());
                }
            }
            let (sa, sb) = (slot[a], slot[b]);
            if !neighbours[sa as usize].contains(&sb) {
                neighbours[sa as usize].push(sb);
                neighbours[sb as usize].push(sa);
            }
        }
    }
    if !interior_flags.iter().any(|&f| f) {
        return;
    }
    let exterior: Vec<usize> = (0..members.len()).filter(|&s| !interior_flags[s]).collect();
    let from: Vec<DVec3> = exterior
        .iter()
        .map(|&s| mesh.columns[members[s]].positions[0])
        .collect();
    let to: Vec<DVec3> = exterior
        .iter()
        .map(|&s| mesh.columns[members[s]].positions[layer])
        .collect();
    let affine = fit_affine(&from, &to);

    // Known residuals at exterior slots.
    let mut residual = vec![DVec3::ZERO; members.len()];
    for (i, &s) in exterior.iter().enumerate() {
        residual[s] = to[i] - affine.apply(from[i]);
    }
    // Interior slots that can reach an exterior slot through interior slots are solved
    // harmonically; the rest follow their column.
    let anchored = anchored_interior(&interior_flags, &neighbours);
    let unknown: Vec<usize> = (0..members.len())
        .filter(|&s| interior_flags[s] && anchored[s])
        .collect();
    solve_harmonic(&unknown, &interior_flags, &neighbours, &mut residual);
    for &s in &unknown {
        let column = members[s];
        let root = mesh.columns[column].positions[0];
        mesh.columns[column].positions[layer] = affine.apply(root) + residual[s];
    }
    for s in 0..members.len() {
        if interior_flags[s] && !anchored[s] {
            let column = members[s];
            let position = column_interpolation(mesh, topology, column, layer);
            mesh.columns[column].positions[layer] = position;
        }
    }
}

/// For each slot: whether it is interior and connected to an exterior slot.
fn anchored_interior(interior: &[bool], neighbours: &[Vec<u32>]) -> Vec<bool> {
    let mut anchored = vec![false; interior.len()];
    let mut stack: Vec<usize> = (0..interior.len()).filter(|&s| !interior[s]).collect();
    let mut seen: Vec<bool> = interior.iter().map(|&f| !f).collect();
    while let Some(s) = stack.pop() {
        for &t in &neighbours[s] {
            let t = t as usize;
            if interior[t] && !seen[t] {
                seen[t] = true;
                anchored[t] = true;
                stack.push(t);
            }
        }
    }
    anchored
}

/// Solves `Σ_j (r_i − r_j) = 0` for the `unknown` slots, with the other slots fixed, by
/// conjugate gradients (three right-hand sides at once, component-wise). The matrix is the
/// graph Laplacian restricted to anchored interior slots: symmetric positive definite.
fn solve_harmonic(
    unknown: &[usize],
    interior: &[bool],
    neighbours: &[Vec<u32>],
    residual: &mut [DVec3],
) {
    if unknown.is_empty() {
        return;
    }
    let mut index_of = vec![u32::MAX; residual.len()];
    for (i, &s) in unknown.iter().enumerate() {
        index_of[s] = i as u32;
    }
    let degree: Vec<f64> = unknown
        .iter()
        .map(|&s| neighbours[s].len() as f64)
        .collect();
    // b_i = Σ over fixed neighbours of their residual.
    let rhs: Vec<DVec3> = unknown
        .iter()
        .map(|&s| {
            neighbours[s]
                .iter()
                .filter(|&&t| !interior[t as usize] || index_of[t as usize] == u32::MAX)
                .map(|&t| residual[t as usize])
                .sum()
        })
        .collect();
    let apply = |x: &[DVec3], out: &mut [DVec3]| {
        for (i, &s) in unknown.iter().enumerate() {
            let mut sum = x[i] * degree[i];
            for &t in &neighbours[s] {
                let j = index_of[t as usize];
                if j != u32::MAX {
                    sum -= x[j as usize];
                }
            }
            out[i] = sum;
        }
    };
    let count = unknown.len();
    let mut x = vec![DVec3::ZERO; count];
    let mut r = rhs.clone();
    // Jacobi preconditioner.
    let mut z: Vec<DVec3> = r.iter().zip(&degree).map(|(r, d)| *r / *d).collect();
    let mut p = z.clone();
    let mut ap = vec![DVec3::ZERO; count];
    let dot = |a: &[DVec3], b: &[DVec3]| -> DVec3 { a.iter().zip(b).map(|(a, b)| *a * *b).sum() };
    let rhs_norm2 = dot(&rhs, &rhs);
    let target = rhs_norm2 * (SOLVE_RELATIVE_TOLERANCE * SOLVE_RELATIVE_TOLERANCE);
    let mut rz = dot(&r, &z);
    for _ in 0..(4 * count + 100) {
        let rr = dot(&r, &r);
        if rr.cmple(target).all() || rr.max_element() <= f64::MIN_POSITIVE {
            break;
        }
        apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        let alpha = DVec3::select(pap.cmpgt(DVec3::ZERO), rz / pap, DVec3::ZERO);
        for i in 0..count {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
            z[i] = r[i] / degree[i];
        }
        let rz_new = dot(&r, &z);
        let beta = DVec3::select(rz.cmpgt(DVec3::ZERO), rz_new / rz, DVec3::ZERO);
        rz = rz_new;
        for i in 0..count {
            p[i] = z[i] + beta * p[i];
        }
    }
    for (i, &s) in unknown.iter().enumerate() {
        residual[s] = x[i];
    }
}

/// Linear interpolation along a column between the nearest exterior vertices below and
/// above `layer`, by layer index.
fn column_interpolation(
    mesh: &HairMesh,
    topology: &Topology,
    column: usize,
    layer: usize,
) -> DVec3 {
    let positions = &mesh.columns[column].positions;
    let below = (0..layer)
        .rev()
        .find(|&k| !mesh.is_interior(topology, column, k))
        .unwrap_or(0);
    let above = (layer + 1..positions.len()).find(|&k| !mesh.is_interior(topology, column, k));
    match above {
        Some(above) => {
            let t = (layer - below) as f64 / (above - below) as f64;
            positions[below].lerp(positions[above], t)
        }
        None => positions[below],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    fn random_affine(seed: u64) -> AffineMap {
        let mut state = seed;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let linear = DMat3::from_cols(
            DVec3::new(1.0 + 0.3 * next(), 0.3 * next(), 0.3 * next()),
            DVec3::new(0.3 * next(), 1.0 + 0.3 * next(), 0.3 * next()),
            DVec3::new(0.3 * next(), 0.3 * next(), 1.0 + 0.3 * next()),
        );
        AffineMap {
            linear,
            translation: DVec3::new(next(), next(), next()) * 3.0,
        }
    }

    /// A curved (non-planar rim) scalp: the grid bent into a saddle so the rim spans 3D.
    fn saddle(nx: usize, layers: u32) -> HairMesh {
        let mut mesh = grid(nx, nx, layers, 0.4);
        for column in &mut mesh.columns {
            let r = column.positions[0];
            let bend = 0.15 * (r.x - nx as f64 / 2.0) * (r.y - nx as f64 / 2.0);
            for p in &mut column.positions {
                p.z += bend;
            }
        }
        mesh.update_w();
        mesh
    }

    #[test]
    fn affine_fit_is_exact_for_affine_data() {
        let from: Vec<DVec3> = (0..20)
            .map(|i| {
                let t = i as f64;
                DVec3::new(t.sin() * 3.0, (t * 1.7).cos() * 2.0, (t * 0.3).sin())
            })
            .collect();
        for seed in 0..10 {
            let map = random_affine(seed);
            let to: Vec<DVec3> = from.iter().map(|&p| map.apply(p)).collect();
            let fit = fit_affine(&from, &to);
            for &p in &from {
                assert!(fit.apply(p).distance(map.apply(p)) < 1e-10);
            }
            let probe = DVec3::new(5.0, -4.0, 7.0);
            assert!(fit.apply(probe).distance(map.apply(probe)) < 1e-9);
        }
    }

    /// Regression: the rim of a scalp cap on a sphere spans its thinnest direction only a
    /// little, so the fit blends data and prior there; when the eigen-solver's third vector
    /// pointed against e0 × e1 the data term was applied with the wrong sign and the map
    /// reflected (an interior vertex of a 2 cm layer landed 1.5 cm inside the head).
    #[test]
    fn affine_fit_of_a_curved_rim_keeps_its_orientation() {
        let mesh = crate::samples::sphere_cap(0.1, 0.6, 6, 1, 0.02);
        let topology = Topology::build(&mesh);
        let rim: Vec<usize> = (0..mesh.columns.len())
            .filter(|&c| topology.root_boundary[c])
            .collect();
        for scale in [1.2, 0.9, 3.0] {
            for turn in [0.0, 1.0, 2.5] {
                let map = AffineMap {
                    linear: DMat3::from_rotation_x(turn) * scale,
                    translation: DVec3::new(0.1, -0.2, 0.3),
                };
                let from: Vec<DVec3> = rim.iter().map(|&c| mesh.columns[c].positions[0]).collect();
                let to: Vec<DVec3> = from.iter().map(|&p| map.apply(p)).collect();
                let fit = fit_affine(&from, &to);
                assert!(fit.linear.determinant() > 0.0, "reflected: {fit:?}");
                let crown = DVec3::new(0.0, 0.1, 0.0);
                assert!(
                    fit.apply(crown).distance(map.apply(crown)) < 1e-9,
                    "{scale} {turn}: {} vs {}",
                    fit.apply(crown),
                    map.apply(crown)
                );
            }
        }
    }

    #[test]
    fn affine_fit_of_coplanar_points_reproduces_rotation_and_scale() {
        let from: Vec<DVec3> = (0..12)
            .map(|i| {
                let a = i as f64 * 0.5;
                DVec3::new(a.cos(), a.sin(), 0.0) * 2.0
            })
            .collect();
        let rotation = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 0.5).normalize(), 0.8);
        let map = AffineMap {
            linear: rotation * 1.7,
            translation: DVec3::new(0.3, -2.0, 5.0),
        };
        let to: Vec<DVec3> = from.iter().map(|&p| map.apply(p)).collect();
        let fit = fit_affine(&from, &to);
        // Off the plane of the data, the completion must still follow the similarity.
        let above = DVec3::new(0.2, 0.1, 1.5);
        assert!(fit.apply(above).distance(map.apply(above)) < 1e-9);
    }

    #[test]
    fn affine_fit_is_finite_for_degenerate_input() {
        let cases: Vec<Vec<DVec3>> = vec![
            vec![],
            vec![DVec3::ONE],
            vec![DVec3::ONE; 5],
            (0..5).map(|i| DVec3::X * i as f64).collect(),
            vec![DVec3::splat(1e300), DVec3::splat(-1e300)],
            vec![
                DVec3::splat(1e-300),
                DVec3::ZERO,
                DVec3::new(0.0, 1e-300, 0.0),
            ],
        ];
        for from in cases {
            let to: Vec<DVec3> = from.iter().map(|p| *p * 2.0 + DVec3::Y).collect();
            let fit = fit_affine(&from, &to);
            assert!(
                fit.linear.is_finite() && fit.translation.is_finite(),
                "{from:?}"
            );
        }
    }

    #[test]
    fn exterior_never_moves_and_affine_layers_map_interior_exactly() {
        let mut mesh = saddle(6, 3);
        let topology = Topology::build(&mesh);
        for seed in 0..5 {
            let map = random_affine(seed + 100);
            // Layer 2's exterior becomes an affine image of the root layer's exterior.
            for c in 0..mesh.columns.len() {
                if !mesh.is_interior(&topology, c, 2) {
                    let root = mesh.columns[c].positions[0];
                    mesh.columns[c].positions[2] = map.apply(root);
                } else {
                    // Scramble interior vertices: placement must not depend on them.
                    mesh.columns[c].positions[2] += DVec3::splat(seed as f64 + 0.37);
                }
            }
            let before = mesh.clone();
            place_interior(&mut mesh, Some(&[2]));
            for c in 0..mesh.columns.len() {
                let placed = mesh.columns[c].positions[2];
                if mesh.is_interior(&topology, c, 2) {
                    let expected = map.apply(mesh.columns[c].positions[0]);
                    assert!(
                        placed.distance(expected) < 1e-9,
                        "column {c}: {placed} vs {expected}"
                    );
                } else {
                    assert_eq!(placed, before.columns[c].positions[2], "exterior moved");
                }
            }
        }
    }

    #[test]
    fn placement_is_continuous_in_exterior_positions() {
        let mut mesh = saddle(6, 3);
        let topology = Topology::build(&mesh);
        let exterior: Vec<usize> = (0..mesh.columns.len())
            .filter(|&c| !mesh.is_interior(&topology, c, 1))
            .collect();
        // Push one rim vertex around; interior motion must shrink linearly with the push.
        let moved = exterior[3];
        place_interior(&mut mesh, None);
        let base = mesh.clone();
        let mut previous_change = f64::INFINITY;
        for epsilon in [1e-1, 1e-3, 1e-5, 1e-7] {
            let mut edited = base.clone();
            edited.columns[moved].positions[1] += DVec3::new(1.0, -0.5, 0.7) * epsilon;
            place_interior(&mut edited, None);
            let change = edited
                .columns
                .iter()
                .zip(&base.columns)
                .map(|(a, b)| a.positions[1].distance(b.positions[1]))
                .fold(0.0, f64::max);
            assert!(
                change <= 10.0 * epsilon,
                "change {change} for push {epsilon}"
            );
            assert!(change < previous_change);
            previous_change = change;
        }
    }

    #[test]
    fn degenerate_layers_stay_finite_and_bounded() {
        let mut mesh = saddle(5, 3);
        let topology = Topology::build(&mesh);
        let cases: [fn(DVec3, usize) -> DVec3; 4] = [
            |_, _| DVec3::new(1.0, 2.0, 3.0),       // all exterior coincident
            |r, _| DVec3::new(r.x + r.y, 0.0, 0.0), // collinear
            |r, _| DVec3::new(r.x, r.y, 0.0),       // coplanar (flattened)
            |r, c| r * if c % 2 == 0 { 1e-12 } else { 1e12 }, // wild scales
        ];
        for case in cases {
            let mut edited = mesh.clone();
            for c in 0..edited.columns.len() {
                if !edited.is_interior(&topology, c, 1) {
                    let root = edited.columns[c].positions[0];
                    edited.columns[c].positions[1] = case(root, c);
                }
            }
            place_interior(&mut edited, None);
            let bound = edited
                .columns
                .iter()
                .map(|c| c.positions[1].abs().max_element())
                .fold(0.0, f64::max);
            for column in &edited.columns {
                assert!(column.positions[1].is_finite());
                assert!(column.positions[1].abs().max_element() <= 10.0 * bound + 10.0);
            }
        }
        place_interior(&mut mesh, None);
        assert!(
            mesh.columns
                .iter()
                .all(|c| c.positions.iter().all(|p| p.is_finite()))
        );
    }

    #[test]
    fn closed_layers_follow_their_columns() {
        // Every bundle of a closed surface (a cube of 6 quads) extruded 4 times: layers 1-3
        // have no exterior vertex and fall back to column interpolation.
        let positions: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
            .collect();
        let faces: Vec<Vec<u32>> = vec![
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 5],
        ];
        let uvs = faces
            .iter()
            .map(|f| vec![glam::DVec2::ZERO; f.len()])
            .collect::<Vec<_>>();
        let mut mesh = HairMesh::from_scalp(&positions, &faces, &uvs);
        let center = DVec3::splat(0.5);
        for column in &mut mesh.columns {
            let root = column.positions[0];
            column.positions = (0..=4).map(|k| root + (root - center) * k as f64).collect();
            column.positions[2] = DVec3::splat(77.0); // garbage to be replaced
        }
        for bundle in &mut mesh.bundles {
            bundle.layers = 4;
        }
        mesh.update_w();
        mesh.validate().expect("valid cube");
        place_interior(&mut mesh, None);
        for column in &mesh.columns {
            let expected = column.positions[0].lerp(column.positions[4], 0.5);
            assert!(column.positions[2].distance(expected) < 1e-12);
        }
    }
}
