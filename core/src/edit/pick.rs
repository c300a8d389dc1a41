//! Picking: which bundle a ray from the camera hits first. A bundle is hit through any of
//! its layer faces (root to tip) — the surfaces an artist sees and clicks.

use glam::DVec3;

use crate::model::mesh::HairMesh;

/// Möller–Trumbore: distance along `direction` (unit or not) to the triangle, if hit in front.
fn ray_triangle(origin: DVec3, direction: DVec3, [a, b, c]: [DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-18 {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = direction.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0 && t.is_finite()).then_some(t)
}

/// The visible (not removed) bundle whose layer faces the ray meets first, and the distance.
pub fn pick_bundle(mesh: &HairMesh, origin: DVec3, direction: DVec3) -> Option<(u32, f64)> {
    if !origin.is_finite() || !direction.is_finite() || direction.length_squared() == 0.0 {
        return None;
    }
    let mut best: Option<(u32, f64)> = None;
    for (index, bundle) in mesh.bundles.iter().enumerate() {
        if bundle.removed {
            continue;
        }
        for layer in 0..=bundle.layers as usize {
            let corners: Option<Vec<DVec3>> = bundle
                .vertices
                .iter()
                .map(|&c| mesh.columns.get(c as usize)?.positions.get(layer).copied())
                .collect();
            let Some(corners) = corners else { continue };
            let triangles: &[[usize; 3]] = if corners.len() == 4 {
                &[[0, 1, 2], [0, 2, 3]]
            } else {
                &[[0, 1, 2]]
            };
            for t in triangles {
                let hit = ray_triangle(origin, direction, t.map(|i| corners[i]));
                if let Some(distance) = hit
                    && best.is_none_or(|(_, d)| distance < d)
                {
                    best = Some((index as u32, distance));
                }
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    #[test]
    fn the_nearest_face_along_the_ray_wins() {
        let mesh = grid(3, 3, 2, 0.5);
        let (lo, hi) = mesh.bounds().expect("bounds");
        let centre = (lo + hi) * 0.5;
        // Straight down the layers' stacking direction through the middle bundle.
        let axis = (mesh.columns[0].positions[1] - mesh.columns[0].positions[0]).normalize();
        let origin = centre + axis * 10.0;
        let (bundle, distance) = pick_bundle(&mesh, origin, -axis).expect("hit");
        assert_eq!(bundle, 4, "3×3 grid: the middle bundle");
        assert!(distance > 0.0 && distance < 10.0);
        // Pointing away, or a degenerate ray: nothing.
        assert!(pick_bundle(&mesh, origin, axis).is_none());
        assert!(pick_bundle(&mesh, origin, DVec3::ZERO).is_none());
        assert!(pick_bundle(&mesh, DVec3::NAN, -axis).is_none());
        // A removed bundle is not pickable.
        let mut removed = mesh.clone();
        removed.bundles[4].removed = true;
        assert_ne!(pick_bundle(&removed, origin, -axis).map(|p| p.0), Some(4));
    }
}
