//! A signed distance field of the body, built once, for hair-body collision.
//!
//! Sampled on a regular grid around the body: exact point-triangle distances in a band of
//! cells around each triangle, then the closest triangle carried to every other grid point
//! by fast sweeping (Bridson's `makelevelset3` scheme). The sign comes from the angle-weighted
//! pseudo-normal of the closest feature (Bærentzen & Aanæs 2005) rather than from ray
//! parity, so a body with holes (a scan open at the neck) still has an inside: each point
//! takes the side of the surface nearest to it.
//!
//! Why not the `mesh_to_sdf` crate: it brings nalgebra, simba and rand (about a hundred
//! crates) for a 200-line job, works in f32 only, and its parity sign needs a watertight
//! mesh, which scans are not.

use std::collections::HashMap;

use glam::DVec3;

use crate::model::document::BodyMesh;

/// Grid points along the body's longest side by default: about 4 mm cells on a head.
pub const DEFAULT_RESOLUTION: usize = 72;
/// The largest resolution accepted: bounds the build's memory (about 163³ points × 16 B =
/// 69 MB while building, a quarter of it kept).
pub const MAX_RESOLUTION: usize = 160;

/// Which part of a triangle is closest to a point: decides the pseudo-normal for the sign.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Feature {
    Face,
    Edge(u8),
    Vertex(u8),
}

/// The closest point to `p` on triangle `abc` (groom fitting puts roots on a scalp with it).
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    closest_on_triangle(p, a, b, c).0
}

/// The closest point to `p` on triangle `abc` and the feature it lies on (Ericson 2004,
/// "Real-Time Collision Detection" §5.1.5, by Voronoi regions).
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, Feature) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + ab * v, Feature::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, Feature::Edge(1));
    }
    let denominator = va + vb + vc;
    if denominator == 0.0 || !denominator.is_finite() {
        // A degenerate (zero-area) triangle: its vertices are as good as any point on it.
        return (a, Feature::Vertex(0));
    }
    let v = vb / denominator;
    let w = vc / denominator;
    (a + ab * v + ac * w, Feature::Face)
}

/// The body's signed distance field: negative inside, positive outside, in model units.
#[derive(Clone, Debug)]
pub struct BodySdf {
    origin: DVec3,
    cell_m: f64,
    dims: [usize; 3],
    /// Signed distance at each grid point, x fastest.
    distance_m: Vec<f32>,
}

impl BodySdf {
    /// A field with no body: everything is outside, infinitely far.
    pub fn empty() -> Self {
        Self {
            origin: DVec3::ZERO,
            cell_m: 1.0,
            dims: [0; 3],
            distance_m: Vec::new(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.distance_m.is_empty()
    }

    /// Bytes held by the field.
    pub fn memory_bytes(&self) -> usize {
        self.distance_m.len() * std::mem::size_of::<f32>()
    }

    /// Builds the field with `resolution` grid points along the body's longest side (clamped
    /// to `[8, MAX_RESOLUTION]`), with `padding_m` of room around the body's bounds.
    /// Degenerate triangles are skipped; a body with no usable triangle gives
    /// [`Self::empty`]. Positions must be finite (`BodyMesh::validate`); non-finite ones
    /// are skipped with their triangles.
    pub fn build(body: &BodyMesh, resolution: usize, padding_m: f64) -> Self {
        let positions: Vec<DVec3> = body
            .positions
            .iter()
            .map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect();
        let usable = |t: &[u32; 3]| {
            t.iter()
                .all(|&v| positions.get(v as usize).is_some_and(|p| p.is_finite()))
        };
        let triangles: Vec<[u32; 3]> = body
            .triangles
            .iter()
            .filter(|t| usable(t))
            .filter(|t| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                (b - a).cross(c - a).length_squared() > 0.0
            })
            .copied()
            .collect();
        if triangles.is_empty() {
            return Self::empty();
        }
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for t in &triangles {
            for &v in t {
                lo = lo.min(positions[v as usize]);
                hi = hi.max(positions[v as usize]);
            }
        }
        let padding_m = if padding_m.is_finite() {
            padding_m.max(0.0)
        } else {
            0.0
        };
        let resolution = resolution.clamp(8, MAX_RESOLUTION);
        let extent = (hi - lo).max_element().max(1e-9) + 2.0 * padding_m;
        let cell_m = extent / (resolution - 1) as f64;
        // One extra cell of room on each side so the surface never touches the grid's edge.
        let origin = lo - DVec3::splat(padding_m + cell_m);
        let dims = ((hi + DVec3::splat(padding_m + cell_m) - origin) / cell_m)
            .ceil()
            .as_uvec3()
            .to_array()
            .map(|n| (n as usize + 1).clamp(2, MAX_RESOLUTION + 3));
        let count = dims[0] * dims[1] * dims[2];
        let index = |i: usize, j: usize, k: usize| i + dims[0] * (j + dims[1] * k);
        let point = |i: usize, j: usize, k: usize| {
            origin + DVec3::new(i as f64, j as f64, k as f64) * cell_m
        };

        let corners = |t: usize| triangles[t].map(|v| positions[v as usize]);
        let distance_to = |p: DVec3, t: usize| {
            let [a, b, c] = corners(t);
            (p - closest_on_triangle(p, a, b, c).0).length()
        };

        // Exact distances in a band of cells around each triangle.
        const BAND_CELLS: f64 = 1.0;
        let mut best = vec![f64::INFINITY; count];
        let mut closest = vec![u32::MAX; count];
        for t in 0..triangles.len() {
            let [a, b, c] = corners(t);
            let grid_lo = ((a.min(b).min(c) - origin) / cell_m - BAND_CELLS).floor();
            let grid_hi = ((a.max(b).max(c) - origin) / cell_m + BAND_CELLS).ceil();
            let range = |axis: usize| {
                let from = grid_lo[axis].max(0.0) as usize;
                let to = (grid_hi[axis].max(0.0) as usize).min(dims[axis] - 1);
                from..=to
            };
            for k in range(2) {
                for j in range(1) {
                    for i in range(0) {
                        let at = index(i, j, k);
                        let d = distance_to(point(i, j, k), t);
                        if d < best[at] {
                            best[at] = d;
                            closest[at] = t as u32;
                        }
                    }
                }
            }
        }

        // Carry the closest triangle to the rest of the grid: sweeps in the eight diagonal
        // orders, each point trying the closest triangles of its neighbours behind it.
        for _ in 0..2 {
            for order in 0..8usize {
                let step = [order & 1, (order >> 1) & 1, (order >> 2) & 1];
                let along = |axis: usize| -> Vec<usize> {
                    if step[axis] == 0 {
                        (0..dims[axis]).collect()
                    } else {
                        (0..dims[axis]).rev().collect()
                    }
                };
                let (is, js, ks) = (along(0), along(1), along(2));
                for &k in &ks {
                    for &j in &js {
                        for &i in &is {
                            let at = index(i, j, k);
                            let behind = [
                                (step[0] == 0 && i > 0 || step[0] == 1 && i + 1 < dims[0])
                                    .then(|| index(if step[0] == 0 { i - 1 } else { i + 1 }, j, k)),
                                (step[1] == 0 && j > 0 || step[1] == 1 && j + 1 < dims[1])
                                    .then(|| index(i, if step[1] == 0 { j - 1 } else { j + 1 }, k)),
                                (step[2] == 0 && k > 0 || step[2] == 1 && k + 1 < dims[2])
                                    .then(|| index(i, j, if step[2] == 0 { k - 1 } else { k + 1 })),
                            ];
                            for neighbour in behind.into_iter().flatten() {
                                let t = closest[neighbour];
                                if t == u32::MAX || t == closest[at] {
                                    continue;
                                }
                                let d = distance_to(point(i, j, k), t as usize);
                                if d < best[at] {
                                    best[at] = d;
                                    closest[at] = t;
                                }
                            }
                        }
                    }
                }
            }
        }

        // Pseudo-normals: faces, edges (sum of the adjacent faces) and vertices (weighted by
        // the corner angles).
        let face_normals: Vec<DVec3> = (0..triangles.len())
            .map(|t| {
                let [a, b, c] = corners(t);
                (b - a).cross(c - a).normalize_or_zero()
            })
            .collect();
        let mut vertex_normals = vec![DVec3::ZERO; positions.len()];
        let mut edge_normals: HashMap<(u32, u32), DVec3> = HashMap::new();
        for (t, triangle) in triangles.iter().enumerate() {
            let p = corners(t);
            for corner in 0..3 {
                let (u, v) = (
                    p[(corner + 1) % 3] - p[corner],
                    p[(corner + 2) % 3] - p[corner],
                );
                let angle = u.angle_between(v);
                if angle.is_finite() {
                    vertex_normals[triangle[corner] as usize] += face_normals[t] * angle;
                }
                let (a, b) = (triangle[corner], triangle[(corner + 1) % 3]);
                *edge_normals.entry((a.min(b), a.max(b))).or_default() += face_normals[t];
            }
        }
        let mut distance_m = vec![f32::INFINITY; count];
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let at = index(i, j, k);
                    let t = closest[at];
                    if t == u32::MAX {
                        continue;
                    }
                    let p = point(i, j, k);
                    let [a, b, c] = corners(t as usize);
                    let (on, feature) = closest_on_triangle(p, a, b, c);
                    let triangle = triangles[t as usize];
                    let normal = match feature {
                        Feature::Face => face_normals[t as usize],
                        Feature::Edge(e) => {
                            let (a, b) = (triangle[e as usize], triangle[(e as usize + 1) % 3]);
                            edge_normals[&(a.min(b), a.max(b))]
                        }
                        Feature::Vertex(v) => vertex_normals[triangle[v as usize] as usize],
                    };
                    let sign = if (p - on).dot(normal) < 0.0 {
                        -1.0
                    } else {
                        1.0
                    };
                    distance_m[at] = (sign * best[at]) as f32;
                }
            }
        }
        Self {
            origin,
            cell_m,
            dims,
            distance_m,
        }
    }

    /// The field the simulator uses for `mesh` on `body`: the default resolution, with room
    /// around the body of 5% of the hair's size (hair reaching past the body stays inside it).
    pub fn for_hair(body: &BodyMesh, mesh: &crate::model::mesh::HairMesh) -> Self {
        Self::build(body, DEFAULT_RESOLUTION, 0.05 * mesh.size().max(1e-3))
    }

    fn value(&self, i: usize, j: usize, k: usize) -> f64 {
        self.distance_m[i + self.dims[0] * (j + self.dims[1] * k)] as f64
    }

    /// Signed distance at `p` (trilinear between grid points). Outside the grid, the
    /// distance to the grid plus the value at its nearest point: outside, and never less
    /// than the true distance's lower bound. Non-finite `p` is infinitely far outside.
    pub fn distance_m(&self, p: DVec3) -> f64 {
        if self.is_empty() || !p.is_finite() {
            return f64::INFINITY;
        }
        let max = DVec3::new(
            (self.dims[0] - 1) as f64,
            (self.dims[1] - 1) as f64,
            (self.dims[2] - 1) as f64,
        );
        let g = (p - self.origin) / self.cell_m;
        let clamped = g.clamp(DVec3::ZERO, max);
        let outside_m = (g - clamped).length() * self.cell_m;
        let base = clamped.floor().min(max - DVec3::ONE).max(DVec3::ZERO);
        let f = clamped - base;
        let (i, j, k) = (base.x as usize, base.y as usize, base.z as usize);
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let x00 = lerp(self.value(i, j, k), self.value(i + 1, j, k), f.x);
        let x10 = lerp(self.value(i, j + 1, k), self.value(i + 1, j + 1, k), f.x);
        let x01 = lerp(self.value(i, j, k + 1), self.value(i + 1, j, k + 1), f.x);
        let x11 = lerp(
            self.value(i, j + 1, k + 1),
            self.value(i + 1, j + 1, k + 1),
            f.x,
        );
        let inside = lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z);
        if outside_m > 0.0 {
            inside.max(0.0) + outside_m
        } else {
            inside
        }
    }

    /// The direction of increasing distance at `p` (unit length; +Y where the field is
    /// flat), by central differences over half a cell.
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        let h = 0.5 * self.cell_m;
        let d = |offset: DVec3| self.distance_m(p + offset);
        let g = DVec3::new(
            d(DVec3::X * h) - d(-DVec3::X * h),
            d(DVec3::Y * h) - d(-DVec3::Y * h),
            d(DVec3::Z * h) - d(-DVec3::Z * h),
        );
        g.try_normalize().unwrap_or(DVec3::Y)
    }

    /// [`Self::distance_m`] and the unit direction of increasing distance together: inside
    /// the grid from the same eight grid values (the trilinear field's own gradient, one
    /// lookup instead of seven), outside it by [`Self::gradient`]. The collision hot path.
    pub fn distance_and_gradient(&self, p: DVec3) -> (f64, DVec3) {
        if self.is_empty() || !p.is_finite() {
            return (f64::INFINITY, DVec3::Y);
        }
        let g = (p - self.origin) / self.cell_m;
        let max = DVec3::new(
            (self.dims[0] - 1) as f64,
            (self.dims[1] - 1) as f64,
            (self.dims[2] - 1) as f64,
        );
        if g.cmplt(DVec3::ZERO).any() || g.cmpgt(max).any() {
            return (self.distance_m(p), self.gradient(p));
        }
        let base = g.floor().min(max - DVec3::ONE).max(DVec3::ZERO);
        let f = g - base;
        let (i, j, k) = (base.x as usize, base.y as usize, base.z as usize);
        let v = |di: usize, dj: usize, dk: usize| self.value(i + di, j + dj, k + dk);
        let (v000, v100, v010, v110) = (v(0, 0, 0), v(1, 0, 0), v(0, 1, 0), v(1, 1, 0));
        let (v001, v101, v011, v111) = (v(0, 0, 1), v(1, 0, 1), v(0, 1, 1), v(1, 1, 1));
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let (x00, x10) = (lerp(v000, v100, f.x), lerp(v010, v110, f.x));
        let (x01, x11) = (lerp(v001, v101, f.x), lerp(v011, v111, f.x));
        let (y0, y1) = (lerp(x00, x10, f.y), lerp(x01, x11, f.y));
        let distance = lerp(y0, y1, f.z);
        let dx = lerp(
            lerp(v100 - v000, v110 - v010, f.y),
            lerp(v101 - v001, v111 - v011, f.y),
            f.z,
        );
        let dy = lerp(x10 - x00, x11 - x01, f.z);
        let dz = y1 - y0;
        let gradient = DVec3::new(dx, dy, dz).try_normalize().unwrap_or(DVec3::Y);
        (distance, gradient)
    }

    /// How far along the ray from `origin` (in `direction`'s units made metres: the
    /// direction is normalised) the body's surface lies, by sphere tracing the field (each
    /// step as long as the distance to the body, which the field never overstates); `None`
    /// when the ray passes the body or goes further than `max_m`. The brushes use it so a
    /// stroke over the face does not reach the hair behind the head.
    pub fn ray_hit_m(&self, origin: DVec3, direction: DVec3, max_m: f64) -> Option<f64> {
        let direction = direction.try_normalize()?;
        if self.is_empty() || !origin.is_finite() || !max_m.is_finite() {
            return None;
        }
        // Half a cell: closer than the field resolves counts as on the surface.
        let surface_m = 0.5 * self.cell_m;
        let mut t = 0.0;
        for _ in 0..512 {
            let distance = self.distance_m(origin + direction * t);
            if distance < surface_m {
                return Some(t);
            }
            t += distance;
            if t > max_m {
                return None;
            }
        }
        None
    }

    pub fn cell_m(&self) -> f64 {
        self.cell_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::samples::sphere_body as sphere;

    #[test]
    fn a_sphere_field_is_the_distance_to_the_sphere() {
        let body = sphere(0.1, 24, 48);
        let sdf = BodySdf::build(&body, 48, 0.05);
        // Faceting of a 48-segment sphere is about 0.2 mm; near the surface the grid's
        // trilinear error is under half a cell, at the centre (the field's cone tip) under one.
        let centre = sdf.distance_m(DVec3::ZERO);
        assert!((centre + 0.1).abs() < sdf.cell_m(), "{centre}");
        for p in [
            DVec3::new(0.05, 0.0, 0.0),
            DVec3::new(0.0, 0.12, 0.0),
            DVec3::new(0.08, -0.08, 0.05),
            DVec3::new(0.0, 0.0, -0.14),
            DVec3::new(0.3, 0.0, 0.0),
        ] {
            let exact = p.length() - 0.1;
            let got = sdf.distance_m(p);
            assert!(
                (got - exact).abs() < 0.5 * sdf.cell_m(),
                "at {p}: {got} vs {exact}"
            );
        }
        let g = sdf.gradient(DVec3::new(0.0, 0.0, 0.105));
        assert!(g.dot(DVec3::Z) > 0.95, "{g}");
        // The fast path agrees with the slow one.
        for p in [
            DVec3::new(0.0, 0.0, 0.105),
            DVec3::new(0.06, 0.07, -0.02),
            DVec3::X * 0.5,
        ] {
            let (d, n) = sdf.distance_and_gradient(p);
            assert!((d - sdf.distance_m(p)).abs() < 1e-9, "{p}");
            assert!(
                n.dot(sdf.gradient(p)) > 0.98,
                "{p}: {n} vs {}",
                sdf.gradient(p)
            );
        }
        assert!(sdf.distance_m(DVec3::NAN) == f64::INFINITY);
    }

    /// A ray at the sphere meets it one radius short of its centre; one past it, or
    /// pointing away, meets nothing; a degenerate ray is refused.
    #[test]
    fn a_ray_meets_the_sphere_where_it_is() {
        let sdf = BodySdf::build(&sphere(0.1, 24, 48), 48, 0.05);
        let origin = DVec3::new(0.0, 0.0, 0.5);
        let hit = sdf
            .ray_hit_m(origin, DVec3::new(0.0, 0.0, -2.0), 1.0)
            .expect("a hit");
        assert!((hit - 0.4).abs() < 1.5 * sdf.cell_m(), "{hit}");
        assert_eq!(sdf.ray_hit_m(origin, DVec3::Z, 10.0), None);
        assert_eq!(
            sdf.ray_hit_m(origin + DVec3::X * 0.2, -DVec3::Z, 10.0),
            None
        );
        assert_eq!(
            sdf.ray_hit_m(origin, -DVec3::Z, 0.3),
            None,
            "beyond the range"
        );
        assert_eq!(sdf.ray_hit_m(origin, DVec3::ZERO, 1.0), None);
        assert_eq!(BodySdf::empty().ray_hit_m(origin, -DVec3::Z, 1.0), None);
    }

    #[test]
    fn a_sphere_with_a_hole_still_has_an_inside() {
        let mut body = sphere(0.1, 24, 48);
        // Cut the bottom cap open (a scan open at the neck).
        body.triangles.truncate(body.triangles.len() - 3 * 2 * 48);
        let sdf = BodySdf::build(&body, 48, 0.05);
        assert!(sdf.distance_m(DVec3::ZERO) < -0.05);
        assert!(sdf.distance_m(DVec3::new(0.0, 0.05, 0.0)) < -0.03);
        assert!(sdf.distance_m(DVec3::new(0.0, 0.13, 0.0)) > 0.02);
    }

    #[test]
    fn degenerate_bodies_give_an_empty_field_or_skip_bad_triangles() {
        assert!(BodySdf::build(&BodyMesh::default(), 64, 0.1).is_empty());
        let flat = BodyMesh {
            positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
            triangles: vec![[0, 1, 2], [0, 1, 7]],
        };
        let sdf = BodySdf::build(&flat, 64, 0.1);
        assert!(sdf.is_empty());
        assert_eq!(sdf.distance_m(DVec3::ZERO), f64::INFINITY);
        // Absurd resolutions are clamped: memory stays bounded.
        let big = BodySdf::build(&sphere(0.1, 8, 16), usize::MAX, f64::NAN);
        assert!(big.memory_bytes() <= (MAX_RESOLUTION + 3).pow(3) * 4);
    }
}
