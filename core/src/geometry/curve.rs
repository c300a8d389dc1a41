//! Curves through hair-mesh columns and the f64 reference strand evaluator.
//!
//! Each column is a centripetal Catmull-Rom curve (α = ½) through its layer positions.
//! A segment between layers `k` and `k + 1` is converted to a cubic Bézier (`b0 = p_k`,
//! `b3 = p_{k+1}`) and, for the GPU path, to two quadratics joined C¹ at the curve's half
//! (Truong et al. 2020):
//! `q0 = b0 + ¾ (b1 − b0)`, `q1 = b3 + ¾ (b2 − b3)`, `m = (q0 + q1) / 2`;
//! the first quadratic is `(b0, q0, m)` over `t ∈ [0, ½]`, the second `(m, q1, b3)`.
//!
//! Two strand definitions exist (DESIGN.md stage 4):
//! - [`CurveDefinition::ColumnBlend`]: the bilinear (quad) or barycentric (triangle) blend of
//!   the face's column curves. This is what texture filtering of per-vertex control points
//!   computes, so it is the definition the runtime uses.
//! - [`CurveDefinition::PerStrandCentripetal`]: the 2009 definition, a centripetal curve
//!   through the strand's own blended layer points. It differs from the blend because the
//!   centripetal knot spacing is nonlinear in the points.
//!
//! End conditions: the missing neighbour before the root and after the tip is the
//! reflection `2 p_0 − p_1` (and `2 p_n − p_{n−1}`), which makes the end tangents follow
//! the first and last segment. A column's curve spans the whole column, so a shorter bundle
//! uses a prefix of the same curve as its taller neighbour (no seam between them).
//!
//! Coincident control points never divide by zero: a zero-length knot interval makes the
//! adjacent Bézier handle collapse onto its end point, which is also the limit of the
//! formula as the interval goes to zero (so the result is continuous).

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::model::mesh::HairMesh;

/// Which curve a strand follows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveDefinition {
    #[default]
    ColumnBlend,
    PerStrandCentripetal,
}

/// How each curve segment is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SegmentForm {
    #[default]
    ExactCubic,
    TwoQuadratics,
}

/// Knot intervals shorter than this (in units of |Δp|^½) count as zero.
const MIN_KNOT_INTERVAL: f64 = 1e-150;

/// Cubic Bézier control points `[b0, b1, b2, b3]` of the centripetal Catmull-Rom segment
/// from `p1` to `p2` with neighbours `p0` and `p3` (Yuksel et al. 2011, α = ½):
/// `d_i = |p_i − p_{i−1}|^½`,
/// `b1 = p1 + (d1² (p2 − p1) + d2² (p1 − p0)) / (3 d1 (d1 + d2))`,
/// `b2 = p2 + (d3² (p1 − p2) + d2² (p2 − p3)) / (3 d3 (d3 + d2))` — written with the
/// symmetric form below.
pub(crate) fn centripetal_bezier(p0: DVec3, p1: DVec3, p2: DVec3, p3: DVec3) -> [DVec3; 4] {
    let d1 = p1.distance(p0).sqrt();
    let d2 = p2.distance(p1).sqrt();
    let d3 = p3.distance(p2).sqrt();
    let handle = |from: DVec3, toward: DVec3, away: DVec3, d_out: f64, d_mid: f64| {
        // Handle at `from` of the segment toward `toward`, with `away` the point before.
        if d_out <= MIN_KNOT_INTERVAL || d_out + d_mid <= MIN_KNOT_INTERVAL {
            return from;
        }
        from + ((toward - from) * (d_out * d_out) + (from - away) * (d_mid * d_mid))
            / (3.0 * d_out * (d_out + d_mid))
    };
    let b1 = handle(p1, p2, p0, d1, d2);
    let b2 = handle(p2, p1, p3, d3, d2);
    [p1, b1, b2, p2]
}

/// Evaluates a cubic Bézier at `t ∈ [0, 1]`.
pub(crate) fn cubic_point(b: &[DVec3; 4], t: f64) -> DVec3 {
    let s = 1.0 - t;
    b[0] * (s * s * s) + b[1] * (3.0 * s * s * t) + b[2] * (3.0 * s * t * t) + b[3] * (t * t * t)
}

/// The two C¹ quadratics approximating a cubic (Truong et al. 2020, split at ½):
/// `[[b0, q0, m], [m, q1, b3]]`.
pub fn cubic_to_quadratics(b: &[DVec3; 4]) -> [[DVec3; 3]; 2] {
    let q0 = b[0] + (b[1] - b[0]) * 0.75;
    let q1 = b[3] + (b[2] - b[3]) * 0.75;
    let m = (q0 + q1) * 0.5;
    [[b[0], q0, m], [m, q1, b[3]]]
}

/// Evaluates a quadratic Bézier at `t ∈ [0, 1]`.
pub(crate) fn quadratic_point(q: &[DVec3; 3], t: f64) -> DVec3 {
    let s = 1.0 - t;
    q[0] * (s * s) + q[1] * (2.0 * s * t) + q[2] * (t * t)
}

/// Evaluates a segment's cubic (exact, or as two quadratics) at `t ∈ [0, 1]`.
pub(crate) fn segment_point(b: &[DVec3; 4], t: f64, form: SegmentForm) -> DVec3 {
    match form {
        SegmentForm::ExactCubic => cubic_point(b, t),
        SegmentForm::TwoQuadratics => {
            let halves = cubic_to_quadratics(b);
            if t < 0.5 {
                quadratic_point(&halves[0], 2.0 * t)
            } else {
                quadratic_point(&halves[1], 2.0 * t - 1.0)
            }
        }
    }
}

/// Bézier segments of the centripetal curve through `points` (one per consecutive pair),
/// with reflected end neighbours. Fewer than two points give no segment.
pub fn curve_segments(points: &[DVec3]) -> Vec<[DVec3; 4]> {
    let n = points.len();
    if n < 2 {
        return Vec::new();
    }
    (0..n - 1)
        .map(|k| {
            let p1 = points[k];
            let p2 = points[k + 1];
            let p0 = if k == 0 { 2.0 * p1 - p2 } else { points[k - 1] };
            let p3 = if k + 2 < n {
                points[k + 2]
            } else {
                2.0 * p2 - p1
            };
            centripetal_bezier(p0, p1, p2, p3)
        })
        .collect()
}

/// Evaluates a curve given by segments at `t ∈ [0, segments.len()]` (layer units), clamped.
pub(crate) fn curve_point(segments: &[[DVec3; 4]], t: f64, form: SegmentForm) -> DVec3 {
    let Some(last) = segments.len().checked_sub(1) else {
        return DVec3::ZERO;
    };
    let t = if t.is_nan() {
        0.0
    } else {
        t.clamp(0.0, segments.len() as f64)
    };
    let k = (t.floor() as usize).min(last);
    segment_point(&segments[k], t - k as f64, form)
}

/// Where a strand sits on its root face.
///
/// Quads use bilinear coordinates `(s, t) ∈ [0,1]²` over corners `(c0, c1, c2, c3)`:
/// weights `(1−s)(1−t), s(1−t), st, (1−s)t`. Triangles use barycentric `(s, t)` with
/// `s + t ≤ 1`: weights `1−s−t, s, t` for corners `(c0, c1, c2)`.
///
/// (Seed 000 §3.3 lays a triangle onto a 2×2 texel block by duplicating a corner and maps
/// barycentric `(ξs, ξt)` to block coordinates `(ξs / (1 − ξt), ξt)`; the paper prints
/// `ξs (1 − ξt)`, but only the quotient makes bilinear filtering equal the barycentric blend
/// it describes. The runtime-texture code uses the quotient.)
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FaceCoord {
    pub s: f64,
    pub t: f64,
}

impl FaceCoord {
    /// Corner weights for a face with `corners` corners (3 or 4).
    pub fn weights(self, corners: usize) -> [f64; 4] {
        let (s, t) = (self.s, self.t);
        if corners == 3 {
            [1.0 - s - t, s, t, 0.0]
        } else {
            [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t]
        }
    }
}

/// Reference (f64) evaluation of the strand of `bundle` at `coord`, at `t ∈ [0, layers]`.
pub struct ReferenceStrand {
    /// Bézier segments per corner column (column-blend definition).
    column_segments: Vec<Vec<[DVec3; 4]>>,
    /// Segments of the per-strand centripetal curve.
    strand_segments: Vec<[DVec3; 4]>,
    weights: [f64; 4],
    /// Blended root uv of the strand.
    pub root_uv: DVec2,
    /// Number of layers of the bundle (the strand spans `t ∈ [0, layers]`).
    pub layers: usize,
}

impl ReferenceStrand {
    /// Prepares a strand. Returns `None` for an out-of-range bundle index.
    pub fn new(mesh: &HairMesh, bundle_index: usize, coord: FaceCoord) -> Option<Self> {
        let corners = mesh.bundles.get(bundle_index)?.vertices.len();
        Self::with_weights(mesh, bundle_index, coord.weights(corners))
    }

    /// Prepares the strand whose bundle-corner weights are `weights` (summing to 1; entries
    /// past the bundle's corner count are ignored).
    pub fn with_weights(mesh: &HairMesh, bundle_index: usize, weights: [f64; 4]) -> Option<Self> {
        let bundle = mesh.bundles.get(bundle_index)?;
        let layers = bundle.layers as usize;
        let column_segments: Vec<Vec<[DVec3; 4]>> = bundle
            .vertices
            .iter()
            .map(|&v| curve_segments(&mesh.columns[v as usize].positions))
            .collect();
        let blended: Vec<DVec3> = (0..=layers)
            .map(|k| {
                bundle
                    .vertices
                    .iter()
                    .enumerate()
                    .map(|(i, &v)| mesh.columns[v as usize].positions[k] * weights[i])
                    .sum()
            })
            .collect();
        let root_uv = bundle
            .uvs
            .iter()
            .enumerate()
            .map(|(i, uv)| *uv * weights[i])
            .sum();
        Some(Self {
            column_segments,
            strand_segments: curve_segments(&blended),
            weights,
            root_uv,
            layers,
        })
    }

    /// Position at `t ∈ [0, layers]` (clamped).
    pub fn point(&self, t: f64, definition: CurveDefinition, form: SegmentForm) -> DVec3 {
        let t = if t.is_nan() {
            0.0
        } else {
            t.clamp(0.0, self.layers as f64)
        };
        match definition {
            CurveDefinition::ColumnBlend => self
                .column_segments
                .iter()
                .enumerate()
                .map(|(i, segments)| curve_point(segments, t, form) * self.weights[i])
                .sum(),
            CurveDefinition::PerStrandCentripetal => curve_point(&self.strand_segments, t, form),
        }
    }

    /// `count ≥ 2` points evenly spaced in `t` from root to tip.
    pub fn polyline(
        &self,
        count: usize,
        definition: CurveDefinition,
        form: SegmentForm,
    ) -> Vec<DVec3> {
        let count = count.max(2);
        (0..count)
            .map(|i| {
                let t = self.layers as f64 * i as f64 / (count - 1) as f64;
                self.point(t, definition, form)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    #[test]
    fn curve_interpolates_its_points() {
        let points = [
            DVec3::ZERO,
            DVec3::new(1.0, 0.2, 0.0),
            DVec3::new(1.5, 1.0, 0.3),
            DVec3::new(1.2, 2.5, 0.1),
        ];
        let segments = curve_segments(&points);
        for (k, p) in points.iter().enumerate() {
            for form in [SegmentForm::ExactCubic, SegmentForm::TwoQuadratics] {
                assert!(curve_point(&segments, k as f64, form).distance(*p) < 1e-14);
            }
        }
    }

    #[test]
    fn collinear_evenly_spaced_points_give_a_straight_uniform_line() {
        let points: Vec<DVec3> = (0..5).map(|k| DVec3::new(k as f64, 0.0, 0.0)).collect();
        let segments = curve_segments(&points);
        for i in 0..=40 {
            let t = i as f64 / 10.0;
            let p = curve_point(&segments, t, SegmentForm::ExactCubic);
            assert!(p.distance(DVec3::new(t, 0.0, 0.0)) < 1e-12, "{t}: {p}");
        }
    }

    #[test]
    fn quadratics_are_c1_and_close_to_the_cubic() {
        let b = [
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(2.0, 1.0, 0.5),
            DVec3::new(3.0, 0.0, 0.0),
        ];
        let [first, second] = cubic_to_quadratics(&b);
        // C¹ at the junction: equal derivatives 2(m − q0) and 2(q1 − m) scaled by 2.
        assert!((first[2] - first[1]).distance(second[1] - second[0]) < 1e-15);
        // End tangents match the cubic's direction.
        assert!(
            (first[1] - first[0])
                .normalize()
                .distance((b[1] - b[0]).normalize())
                < 1e-15
        );
        let worst = (0..=100)
            .map(|i| {
                let t = i as f64 / 100.0;
                cubic_point(&b, t).distance(segment_point(&b, t, SegmentForm::TwoQuadratics))
            })
            .fold(0.0, f64::max);
        assert!(worst > 0.0 && worst < 0.1, "{worst}");
    }

    #[test]
    fn coincident_points_stay_finite_and_continuous() {
        let a = DVec3::new(1.0, 2.0, 3.0);
        let b = DVec3::new(2.0, 2.0, 3.0);
        let exact = centripetal_bezier(a, a, b, b);
        assert!(exact.iter().all(|p| p.is_finite()));
        assert_eq!(exact[1], a);
        assert_eq!(exact[2], b);
        // Approaching coincidence converges to the collapsed handles.
        let near = centripetal_bezier(a - DVec3::X * 1e-12, a, b, b + DVec3::X * 1e-12);
        assert!(near[1].distance(exact[1]) < 1e-5 && near[2].distance(exact[2]) < 1e-5);
        let all_same = curve_segments(&[a, a, a, a]);
        for t in [0.0, 0.3, 1.5, 3.0] {
            assert!(curve_point(&all_same, t, SegmentForm::ExactCubic).distance(a) < 1e-14);
        }
    }

    #[test]
    fn definitions_agree_on_parallel_columns_and_differ_on_uneven_ones() {
        let mut mesh = grid(1, 1, 3, 1.0);
        let strand = ReferenceStrand::new(&mesh, 0, FaceCoord { s: 0.3, t: 0.6 }).expect("bundle");
        for i in 0..=30 {
            let t = i as f64 / 10.0;
            let a = strand.point(t, CurveDefinition::ColumnBlend, SegmentForm::ExactCubic);
            let b = strand.point(
                t,
                CurveDefinition::PerStrandCentripetal,
                SegmentForm::ExactCubic,
            );
            assert!(a.distance(b) < 1e-12);
            assert!(a.distance(DVec3::new(0.3, 0.6, t)) < 1e-12);
        }
        // Columns with very different spacing: the two definitions separate.
        mesh.columns[0].positions[1].z = 0.1;
        mesh.columns[3].positions[2] += DVec3::new(1.5, 0.0, 0.0);
        let strand = ReferenceStrand::new(&mesh, 0, FaceCoord { s: 0.5, t: 0.5 }).expect("bundle");
        let gap = (0..=30)
            .map(|i| {
                let t = i as f64 / 10.0;
                strand
                    .point(t, CurveDefinition::ColumnBlend, SegmentForm::ExactCubic)
                    .distance(strand.point(
                        t,
                        CurveDefinition::PerStrandCentripetal,
                        SegmentForm::ExactCubic,
                    ))
            })
            .fold(0.0, f64::max);
        assert!(gap > 1e-4, "{gap}");
        // Both still pass through the blended layer points.
        for k in 0..=3 {
            let a = strand.point(
                k as f64,
                CurveDefinition::ColumnBlend,
                SegmentForm::ExactCubic,
            );
            let b = strand.point(
                k as f64,
                CurveDefinition::PerStrandCentripetal,
                SegmentForm::ExactCubic,
            );
            assert!(a.distance(b) < 1e-12);
        }
    }

    #[test]
    fn triangle_weights_are_barycentric() {
        let w = FaceCoord { s: 0.2, t: 0.3 }.weights(3);
        assert_eq!(w, [0.5, 0.2, 0.3, 0.0]);
        let w = FaceCoord { s: 0.2, t: 0.3 }.weights(4);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }
}
