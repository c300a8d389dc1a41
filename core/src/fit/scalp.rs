//! The scalp a groom grows from: where each root lies on it, and, when the artist gives
//! none, a scalp built from the roots.
//!
//! # A scalp from roots
//! Roots of a groom lie on a surface we do not have. We fit a sphere to them (algebraic
//! least squares; a plane when they are nearly flat), unroll it around the roots' mean
//! direction with the azimuthal equidistant projection (distances along the sphere kept
//! from the centre, so a whole head cap unrolls without folding), lay a hexagonal lattice
//! over the unrolled roots with an edge sized for the wanted number of faces, keep the
//! lattice points near roots and triangulate them with `spade` (Delaunay; on a hexagonal
//! lattice that is the lattice's own equilateral triangles). Lattice triangles that hold a
//! root become faces; each vertex is lifted back to 3D at the mean radius of the roots
//! around it, so the surface passes through the roots rather than the fitted sphere.
//! Styling uv is the unrolled position scaled to the unit square.

use glam::{DVec2, DVec3};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use spade::{DelaunayTriangulation, Point2, Triangulation};

use crate::model::mesh::HairMesh;

/// Where a root lies on the scalp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootHit {
    pub face: u32,
    /// Bilinear (quad) or barycentric (triangle) coordinates, as strands use them.
    pub s: f64,
    pub t: f64,
    /// Distance from the root to the scalp.
    pub distance: f64,
}

/// Closest-face queries on a hair mesh's root layer.
pub struct ScalpQuery<'a> {
    mesh: &'a HairMesh,
    tree: ImmutableKdTree<f64, 3>,
    faces: Vec<u32>,
}

/// How many nearest face centres are tested exactly per root.
const CANDIDATE_FACES: usize = 24;

impl<'a> ScalpQuery<'a> {
    /// `None` for a mesh with no faces.
    pub fn new(mesh: &'a HairMesh) -> Option<Self> {
        let mut centres = Vec::new();
        let mut faces = Vec::new();
        for (i, bundle) in mesh.bundles.iter().enumerate() {
            let c: DVec3 = bundle
                .vertices
                .iter()
                .map(|&v| mesh.columns[v as usize].positions[0])
                .sum::<DVec3>()
                / bundle.vertices.len() as f64;
            centres.push(c.to_array());
            faces.push(i as u32);
        }
        if centres.is_empty() {
            return None;
        }
        let tree = ImmutableKdTree::new_from_slice(&centres).ok()?;
        Some(Self { mesh, tree, faces })
    }

    /// The closest point of the scalp to `p`, among the faces whose centres are nearest.
    pub fn hit(&self, p: DVec3) -> RootHit {
        let count = std::num::NonZeroUsize::new(CANDIDATE_FACES.min(self.faces.len()))
            .unwrap_or(std::num::NonZeroUsize::MIN);
        let candidates = self
            .tree
            .query(&p.to_array())
            .nearest_n::<SquaredEuclidean<f64>>(count)
            .execute();
        let mut best = RootHit {
            face: 0,
            s: 0.0,
            t: 0.0,
            distance: f64::INFINITY,
        };
        for candidate in candidates {
            let face = self.faces[candidate.item as usize];
            let corners: Vec<DVec3> = self.mesh.bundles[face as usize]
                .vertices
                .iter()
                .map(|&v| self.mesh.columns[v as usize].positions[0])
                .collect();
            let (s, t, q) = closest_on_face(&corners, p);
            let distance = (q - p).length();
            if distance < best.distance {
                best = RootHit {
                    face,
                    s,
                    t,
                    distance,
                };
            }
        }
        best
    }
}

/// Closest point on a triangle or quad: its face coordinates and position.
pub fn closest_on_face(corners: &[DVec3], p: DVec3) -> (f64, f64, DVec3) {
    use crate::simulate::body_sdf::closest_point_on_triangle as closest;
    if corners.len() == 3 {
        let q = closest(p, corners[0], corners[1], corners[2]);
        let (s, t) = barycentric(q, corners[0], corners[1], corners[2]);
        return (s, t, q);
    }
    // A quad: the closest point of its two triangles starts Gauss-Newton on the bilinear
    // patch, which is what strands interpolate over.
    let q1 = closest(p, corners[0], corners[1], corners[2]);
    let q2 = closest(p, corners[0], corners[2], corners[3]);
    let (mut s, mut t) = if (q1 - p).length_squared() <= (q2 - p).length_squared() {
        let (b1, b2) = barycentric(q1, corners[0], corners[1], corners[2]);
        // (1−b1−b2)·c0 + b1·c1 + b2·c2 ≈ bilinear s = b1 + b2, t = b2 / (b1 + b2)…
        (b1 + b2, if b1 + b2 > 0.0 { b2 / (b1 + b2) } else { 0.0 })
    } else {
        let (b1, b2) = barycentric(q2, corners[0], corners[2], corners[3]);
        (if b1 + b2 > 0.0 { b1 / (b1 + b2) } else { 0.0 }, b1 + b2)
    };
    let [c0, c1, c2, c3] = [corners[0], corners[1], corners[2], corners[3]];
    let at = |s: f64, t: f64| {
        c0 * ((1.0 - s) * (1.0 - t)) + c1 * (s * (1.0 - t)) + c2 * (s * t) + c3 * ((1.0 - s) * t)
    };
    for _ in 0..12 {
        let r = at(s, t) - p;
        let ds = (c1 - c0) * (1.0 - t) + (c2 - c3) * t;
        let dt = (c3 - c0) * (1.0 - s) + (c2 - c1) * s;
        let (a, b, c) = (ds.dot(ds), ds.dot(dt), dt.dot(dt));
        let det = a * c - b * b;
        if det.abs() < 1e-30 {
            break;
        }
        let (gs, gt) = (ds.dot(r), dt.dot(r));
        let step_s = (c * gs - b * gt) / det;
        let step_t = (a * gt - b * gs) / det;
        s = (s - step_s).clamp(0.0, 1.0);
        t = (t - step_t).clamp(0.0, 1.0);
        if step_s.abs() + step_t.abs() < 1e-12 {
            break;
        }
    }
    (s, t, at(s, t))
}

/// Barycentric `(s, t)` of `q` in triangle `abc` (weights `1−s−t, s, t`), clamped inside.
fn barycentric(q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (f64, f64) {
    let (e1, e2, d) = (b - a, c - a, q - a);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det.abs() < 1e-300 {
        return (0.0, 0.0);
    }
    let (p1, p2) = (d.dot(e1), d.dot(e2));
    let s = ((d22 * p1 - d12 * p2) / det).clamp(0.0, 1.0);
    let t = ((d11 * p2 - d12 * p1) / det).clamp(0.0, 1.0 - s);
    (s, t)
}

/// How the roots are unrolled into the plane.
#[derive(Clone, Copy, Debug)]
enum Unroll {
    /// Azimuthal equidistant about `axis` on a sphere of `radius` around `centre`.
    Sphere {
        centre: DVec3,
        radius: f64,
        axis: DVec3,
        e1: DVec3,
        e2: DVec3,
    },
    /// Orthographic onto the plane through `origin` spanned by `e1`, `e2` (normal `n`).
    Plane {
        origin: DVec3,
        e1: DVec3,
        e2: DVec3,
        n: DVec3,
    },
}

impl Unroll {
    fn fit(roots: &[DVec3], outward_hint: DVec3) -> Self {
        let n = roots.len() as f64;
        let mean = roots.iter().copied().sum::<DVec3>() / n;
        let extent = roots
            .iter()
            .map(|r| (*r - mean).length())
            .fold(0.0, f64::max);
        if let Some((centre, radius)) = fit_sphere(roots, mean)
            && radius.is_finite()
            && radius < 20.0 * extent.max(1e-12)
        {
            let axis = roots
                .iter()
                .map(|r| (*r - centre).normalize_or_zero())
                .sum::<DVec3>()
                .normalize_or(outward_hint.normalize_or(DVec3::Y));
            let e1 = axis.any_orthonormal_vector();
            let e2 = axis.cross(e1);
            return Unroll::Sphere {
                centre,
                radius,
                axis,
                e1,
                e2,
            };
        }
        let (_, vectors) = crate::geometry::interior::symmetric_eigen(covariance(roots, mean));
        let mut normal = vectors.z_axis;
        if normal.dot(outward_hint) < 0.0 {
            normal = -normal;
        }
        let e1 = normal.any_orthonormal_vector();
        let e2 = normal.cross(e1);
        Unroll::Plane {
            origin: mean,
            e1,
            e2,
            n: normal,
        }
    }

    fn flat(&self, p: DVec3) -> DVec2 {
        match *self {
            Unroll::Sphere {
                centre,
                radius,
                axis,
                e1,
                e2,
            } => {
                let d = (p - centre).normalize_or(axis);
                let theta = d.dot(axis).clamp(-1.0, 1.0).acos();
                let phi = d.dot(e2).atan2(d.dot(e1));
                DVec2::new(phi.cos(), phi.sin()) * (radius * theta)
            }
            Unroll::Plane { origin, e1, e2, .. } => {
                DVec2::new((p - origin).dot(e1), (p - origin).dot(e2))
            }
        }
    }

    /// The 3D point at `q` in the plane, at `height` (radius from the centre, or offset
    /// along the plane's normal).
    fn lift(&self, q: DVec2, height: f64) -> DVec3 {
        match *self {
            Unroll::Sphere {
                centre,
                radius,
                axis,
                e1,
                e2,
            } => {
                let theta = q.length() / radius;
                let dir = q.normalize_or(DVec2::X);
                let d = axis * theta.cos() + (e1 * dir.x + e2 * dir.y) * theta.sin();
                centre + d * height
            }
            Unroll::Plane { origin, e1, e2, n } => origin + e1 * q.x + e2 * q.y + n * height,
        }
    }

    fn height(&self, p: DVec3) -> f64 {
        match *self {
            Unroll::Sphere { centre, .. } => (p - centre).length(),
            Unroll::Plane { origin, n, .. } => (p - origin).dot(n),
        }
    }
}

fn covariance(points: &[DVec3], mean: DVec3) -> glam::DMat3 {
    let mut m = glam::DMat3::ZERO;
    for p in points {
        let d = *p - mean;
        m += glam::DMat3::from_cols(d * d.x, d * d.y, d * d.z);
    }
    m * (1.0 / points.len().max(1) as f64)
}

/// Least-squares sphere through `points` (`|p|² = 2 c·p + k`, solved about `mean` for
/// conditioning); `None` when the points are (nearly) coplanar.
fn fit_sphere(points: &[DVec3], mean: DVec3) -> Option<(DVec3, f64)> {
    let mut a = [[0.0f64; 4]; 4];
    let mut b = [0.0f64; 4];
    for p in points {
        let d = *p - mean;
        let row = [2.0 * d.x, 2.0 * d.y, 2.0 * d.z, 1.0];
        let rhs = d.length_squared();
        for i in 0..4 {
            for j in 0..4 {
                a[i][j] += row[i] * row[j];
            }
            b[i] += row[i] * rhs;
        }
    }
    let x = solve4(a, b)?;
    let c = DVec3::new(x[0], x[1], x[2]);
    let r2 = x[3] + c.length_squared();
    (r2 > 0.0).then(|| (mean + c, r2.sqrt()))
}

/// Gaussian elimination with partial pivoting; `None` for a (nearly) singular system.
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> Option<[f64; 4]> {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    for col in 0..4 {
        let pivot = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() <= 1e-12 * scale {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..4 {
            let f = a[row][col] / a[col][col];
            let pivot_row = a[col];
            for (value, pivot_value) in a[row].iter_mut().zip(pivot_row).skip(col) {
                *value -= f * pivot_value;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 4];
    for row in (0..4).rev() {
        let s: f64 = (row + 1..4).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

/// A scalp of about `target_faces` triangles over `roots` (see the module comment).
/// `outward_hint` is the side the hair grows to (the mean root-to-tip direction).
pub fn scalp_from_roots(roots: &[DVec3], target_faces: usize, outward_hint: DVec3) -> HairMesh {
    if roots.len() < 3 {
        return HairMesh::empty();
    }
    let unroll = Unroll::fit(roots, outward_hint);
    let flat: Vec<DVec2> = roots.iter().map(|&r| unroll.flat(r)).collect();
    let (lo, hi) = flat
        .iter()
        .fold((flat[0], flat[0]), |(lo, hi), &q| (lo.min(q), hi.max(q)));
    let span = (hi - lo).max(DVec2::splat(1e-9));
    // Area covered by roots, from an occupancy grid of 128 cells along the longer side.
    let cell = span.max_element() / 128.0;
    let mut occupied = std::collections::HashSet::new();
    for q in &flat {
        let key = (((q.x - lo.x) / cell) as i64, ((q.y - lo.y) / cell) as i64);
        occupied.insert(key);
    }
    let area = occupied.len() as f64 * cell * cell;
    let edge = (4.0 * area / (3f64.sqrt() * target_faces.max(1) as f64))
        .sqrt()
        .max(1e-9);
    let flat_points: Vec<[f64; 2]> = flat.iter().map(|q| q.to_array()).collect();
    let Ok(tree) = ImmutableKdTree::<f64, 2>::new_from_slice(&flat_points) else {
        return HairMesh::empty();
    };
    let nearest = |q: DVec2, n: usize| {
        tree.query(&q.to_array())
            .nearest_n::<SquaredEuclidean<f64>>(
                std::num::NonZeroUsize::new(n).unwrap_or(std::num::NonZeroUsize::MIN),
            )
            .execute()
    };
    // Hexagonal lattice points within one edge of a root: every lattice triangle that holds
    // a root has all three corners among them.
    let row_step = edge * 3f64.sqrt() / 2.0;
    let rows = ((span.y + 2.0 * edge) / row_step).ceil() as i64 + 1;
    let cols = ((span.x + 2.0 * edge) / edge).ceil() as i64 + 2;
    let mut sites: Vec<DVec2> = Vec::new();
    for j in 0..rows {
        for i in 0..cols {
            let x = lo.x - edge + i as f64 * edge + if j % 2 == 1 { edge / 2.0 } else { 0.0 };
            let y = lo.y - edge + j as f64 * row_step;
            let q = DVec2::new(x, y);
            if nearest(q, 1)
                .first()
                .is_some_and(|n| n.distance <= edge * edge)
            {
                sites.push(q);
            }
        }
    }
    let mut triangulation: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::new();
    let mut handles = Vec::with_capacity(sites.len());
    for q in &sites {
        match triangulation.insert(Point2::new(q.x, q.y)) {
            Ok(h) => handles.push(h.index()),
            Err(_) => return HairMesh::empty(),
        }
    }
    // Vertex index per triangulation vertex (insertion order is kept by spade for distinct
    // points, but map through the handles to be sure).
    let mut vertex_of = vec![u32::MAX; triangulation.num_vertices()];
    for (site, &handle) in handles.iter().enumerate() {
        vertex_of[handle] = site as u32;
    }
    // Which lattice triangles hold a root: count roots per face by locating each root.
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut face_of_triangle = std::collections::HashMap::new();
    for q in &flat {
        use spade::PositionInTriangulation as P;
        let face = match triangulation.locate(Point2::new(q.x, q.y)) {
            P::OnFace(f) => Some(f),
            P::OnEdge(e) => triangulation
                .directed_edge(e)
                .face()
                .as_inner()
                .map(|f| f.fix()),
            P::OnVertex(v) => triangulation
                .vertex(v)
                .out_edges()
                .find_map(|e| e.face().as_inner().map(|f| f.fix())),
            _ => None,
        };
        let Some(face) = face else { continue };
        let face = triangulation.face(face);
        let vertices = face.vertices().map(|v| vertex_of[v.fix().index()]);
        // Lattice triangles only: a Delaunay triangle across a gap has a longer edge.
        let longest = face
            .adjacent_edges()
            .iter()
            .map(|e| e.length_2())
            .fold(0.0, f64::max);
        if longest > (edge * 1.01).powi(2) || vertices.contains(&u32::MAX) {
            continue;
        }
        face_of_triangle.entry(face.fix()).or_insert_with(|| {
            faces.push(vertices);
            faces.len() - 1
        });
    }
    // Keep only vertices that faces use, lifted to the roots' height around them.
    let mut used = vec![u32::MAX; sites.len()];
    let mut positions = Vec::new();
    let mut uvs_of_vertex = Vec::new();
    for face in &mut faces {
        for v in face.iter_mut() {
            let site = *v as usize;
            if used[site] == u32::MAX {
                used[site] = positions.len() as u32;
                let q = sites[site];
                let neighbours = nearest(q, 8);
                let (mut sum, mut weights) = (0.0, 0.0);
                for n in &neighbours {
                    let w = 1.0 / (n.distance.sqrt() + 0.25 * edge);
                    sum += w * unroll.height(roots[n.item as usize]);
                    weights += w;
                }
                positions.push(unroll.lift(q, sum / weights.max(1e-300)));
                uvs_of_vertex.push((q - lo) / span.max_element());
            }
            *v = used[site];
        }
    }
    let face_lists: Vec<Vec<u32>> = faces.iter().map(|f| f.to_vec()).collect();
    let uvs: Vec<Vec<DVec2>> = faces
        .iter()
        .map(|f| f.iter().map(|&v| uvs_of_vertex[v as usize]).collect())
        .collect();
    HairMesh::from_scalp(&positions, &face_lists, &uvs)
}
