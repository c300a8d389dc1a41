//! Per-vertex styling frames û, v̂, ŵ (seed 000 §3.4, eq. 1-4).
//!
//! û at a vertex is the texture-space-area-weighted average of the object-space images of
//! the uv axes over the same-layer triangles around the vertex; v̂ likewise; ŵ = û × v̂.
//! Frames belong to vertices, so neighbouring bundles share them and styling has no seams
//! (Figure 4).
//!
//! "Triangles around a vertex" are, for every bundle using the vertex, the triangle made of
//! the vertex and its two bundle edges: (corner, next, previous). uv comes from the bundle's
//! own face corners, so a vertex on a uv seam still gets one frame.
//!
//! Degenerate input never produces NaN: triangles whose uv area is below
//! [`MIN_UV_AREA_FRACTION`] of the largest uv area around the vertex (or exactly zero) are
//! skipped; when nothing is left, or û and v̂ come out (nearly) parallel or zero, the frame
//! falls back to [`fallback_frame`] built from the vertex normal.

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::model::mesh::HairMesh;

/// uv triangles smaller than this fraction of the largest one around a vertex are skipped.
pub const MIN_UV_AREA_FRACTION: f64 = 1e-10;
/// |û × v̂| below this means "parallel": the fallback is used.
pub const MIN_FRAME_SINE: f64 = 1e-6;

/// Object-space styling directions at a vertex. û and v̂ are unit length but not
/// necessarily orthogonal (the frame may be skewed, as in the paper); ŵ is unit and
/// orthogonal to both.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    pub u: DVec3,
    pub v: DVec3,
    pub w: DVec3,
    /// True when the frame came from [`fallback_frame`] rather than from eq. 1-4.
    pub fallback: bool,
}

/// Frames of every vertex on `layer`; `None` for columns that do not reach it.
pub fn layer_frames(mesh: &HairMesh, layer: usize) -> Vec<Option<Frame>> {
    let count = mesh.columns.len();
    let mut u_sum = vec![DVec3::ZERO; count];
    let mut v_sum = vec![DVec3::ZERO; count];
    let mut area_sum = vec![0.0f64; count];
    let mut max_area = vec![0.0f64; count];
    let mut normal_sum = vec![DVec3::ZERO; count];
    struct Contribution {
        vertex: usize,
        area: f64,
        u: DVec3,
        v: DVec3,
    }
    let mut contributions = Vec::new();
    for bundle in mesh.bundles.iter().filter(|b| b.reaches(layer)) {
        let n = bundle.vertices.len();
        for corner in 0..n {
            let next = (corner + 1) % n;
            let prev = (corner + n - 1) % n;
            let index = [corner, next, prev].map(|i| bundle.vertices[i] as usize);
            let p = index.map(|i| mesh.columns[i].positions[layer]);
            let uv = [corner, next, prev].map(|i| bundle.uvs[i]);
            let e1 = p[1] - p[0];
            let e2 = p[2] - p[0];
            normal_sum[index[0]] += e1.cross(e2);
            let Some((u, v, area)) = triangle_uv_axes(e1, e2, uv) else {
                continue;
            };
            max_area[index[0]] = max_area[index[0]].max(area);
            contributions.push(Contribution {
                vertex: index[0],
                area,
                u,
                v,
            });
        }
    }
    for c in contributions {
        if c.area <= MIN_UV_AREA_FRACTION * max_area[c.vertex] {
            continue;
        }
        // Eq. 1: area-weighted average (normalisation by Σ A_i does not change the direction).
        u_sum[c.vertex] += c.u * c.area;
        v_sum[c.vertex] += c.v * c.area;
        area_sum[c.vertex] += c.area;
    }
    (0..count)
        .map(|i| {
            if mesh.columns[i].positions.len() <= layer {
                return None;
            }
            Some(frame_from_sums(u_sum[i], v_sum[i], normal_sum[i]))
        })
        .collect()
}

/// Eq. 2-3 for one triangle: the object-space images of the uv axes, and the uv area.
/// `None` when the uv triangle has zero area or the result is not finite.
pub(crate) fn triangle_uv_axes(
    e1: DVec3,
    e2: DVec3,
    uv: [DVec2; 3],
) -> Option<(DVec3, DVec3, f64)> {
    let du1 = uv[1] - uv[0];
    let du2 = uv[2] - uv[0];
    // T = [[du1.x, du2.x], [du1.y, du2.y]]; [u v] = [e1 e2] T⁻¹.
    let det = du1.x * du2.y - du2.x * du1.y;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let u = (e1 * du2.y - e2 * du1.y) * inv;
    let v = (e2 * du1.x - e1 * du2.x) * inv;
    let area = 0.5 * det.abs();
    (u.is_finite() && v.is_finite()).then_some((u, v, area))
}

/// Eq. 1 and 4 from accumulated sums, with the documented fallbacks.
fn frame_from_sums(u_sum: DVec3, v_sum: DVec3, normal_sum: DVec3) -> Frame {
    let normal = normal_sum.try_normalize().unwrap_or(DVec3::Z);
    let u = u_sum.try_normalize();
    let v = v_sum.try_normalize();
    match (u, v) {
        (Some(u), Some(v)) => {
            let cross = u.cross(v);
            if cross.length() > MIN_FRAME_SINE {
                return Frame {
                    u,
                    v,
                    w: cross.normalize(),
                    fallback: false,
                };
            }
            // û ∥ v̂: keep û, rebuild v̂ in the tangent plane of the normal.
            complete_from_u(u, normal)
        }
        (Some(u), None) => complete_from_u(u, normal),
        (None, Some(v)) => {
            let frame = complete_from_u(v, normal);
            Frame {
                u: -frame.v,
                v,
                w: frame.w,
                fallback: true,
            }
        }
        (None, None) => fallback_frame(normal),
    }
}

fn complete_from_u(u: DVec3, normal: DVec3) -> Frame {
    let tangent = (u - normal * u.dot(normal)).try_normalize();
    match tangent {
        Some(u) => Frame {
            u,
            v: normal.cross(u),
            w: normal,
            fallback: true,
        },
        None => fallback_frame(normal),
    }
}

/// An orthonormal frame with ŵ = `normal`, û and v̂ from the branchless basis of Duff et al.
/// 2017 ("Building an Orthonormal Basis, Revisited"), continuous except at normal = −z.
pub(crate) fn fallback_frame(normal: DVec3) -> Frame {
    let n = normal.try_normalize().unwrap_or(DVec3::Z);
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let u = DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let v = DVec3::new(b, sign + n.y * n.y * a, -n.y);
    Frame {
        u,
        v,
        w: n,
        fallback: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    fn assert_unit_frame(frame: &Frame) {
        for axis in [frame.u, frame.v, frame.w] {
            assert!(axis.is_finite());
            assert!((axis.length() - 1.0).abs() < 1e-9, "{frame:?}");
        }
        assert!(frame.w.dot(frame.u).abs() < 1e-9 && frame.w.dot(frame.v).abs() < 1e-9);
    }

    #[test]
    fn flat_grid_frames_follow_uv_axes() {
        let mesh = grid(3, 3, 1, 1.0);
        for frame in layer_frames(&mesh, 0).into_iter().flatten() {
            assert!(frame.u.distance(DVec3::X) < 1e-12);
            assert!(frame.v.distance(DVec3::Y) < 1e-12);
            assert!(frame.w.distance(DVec3::Z) < 1e-12);
            assert!(!frame.fallback);
        }
    }

    #[test]
    fn frames_are_shared_across_bundle_borders() {
        // Bend the grid so each bundle has a different orientation. The frame of a vertex on
        // a border is one value for all bundles around it; evaluating "per bundle" finite
        // differences would give different ones (Figure 4a).
        let mut mesh = grid(4, 1, 1, 1.0);
        for column in &mut mesh.columns {
            let x = column.positions[0].x;
            for p in &mut column.positions {
                p.z += 0.3 * x * x;
            }
        }
        let frames = layer_frames(&mesh, 0);
        let border_vertex = 2; // between bundles 1 and 2, on row 0
        let frame = frames[border_vertex].expect("frame");
        // Per-bundle axes on each side differ, the shared frame lies between them.
        let side = |b: usize| {
            let bundle = &mesh.bundles[b];
            let p: Vec<DVec3> = bundle
                .vertices
                .iter()
                .map(|&v| mesh.columns[v as usize].positions[0])
                .collect();
            (p[1] - p[0]).normalize()
        };
        let (left, right) = (side(1), side(2));
        assert!(left.distance(right) > 0.1);
        assert!(frame.u.dot(left) > 0.9 && frame.u.dot(right) > 0.9);
        assert!((frame.u - left).length() < (right - left).length());
        // Continuity of the per-vertex field: frames of neighbouring vertices vary smoothly.
        for pair in frames.windows(2).take(4) {
            let (a, b) = (pair[0].expect("frame"), pair[1].expect("frame"));
            assert!(a.u.dot(b.u) > 0.8);
        }
    }

    #[test]
    fn degenerate_uv_never_gives_nan() {
        let mut mesh = grid(2, 2, 1, 1.0);
        // Zero-area uv on one bundle, all-coincident uv on another, parallel axes on a third.
        mesh.bundles[0].uvs = vec![DVec2::ZERO; 4];
        mesh.bundles[1].uvs = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(3.0, 3.0),
        ];
        mesh.bundles[2].uvs = vec![DVec2::splat(f64::MAX); 4];
        for layer in 0..=1 {
            for frame in layer_frames(&mesh, layer).into_iter().flatten() {
                assert_unit_frame(&frame);
            }
        }
        // Every uv of the mesh collapsed: all frames fall back, still orthonormal.
        for bundle in &mut mesh.bundles {
            bundle.uvs = vec![DVec2::ONE; 4];
        }
        for frame in layer_frames(&mesh, 1).into_iter().flatten() {
            assert!(frame.fallback);
            assert_unit_frame(&frame);
        }
    }

    #[test]
    fn fallback_frame_is_orthonormal_everywhere() {
        for i in 0..200 {
            let t = i as f64 * 0.173;
            let n = DVec3::new(t.sin() * t.cos(), (2.0 * t).cos(), (0.7 * t).sin() - 0.999);
            assert_unit_frame(&fallback_frame(n));
        }
        assert_unit_frame(&fallback_frame(-DVec3::Z));
        assert_unit_frame(&fallback_frame(DVec3::ZERO));
        assert_unit_frame(&fallback_frame(DVec3::NAN));
    }
}
