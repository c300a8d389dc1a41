//! Generated styling uv for scalps that have none (or an unsuitable one).
//!
//! [`azimuthal_uv`] is an azimuthal-equidistant projection around an axis: a point's
//! direction from `center` is written as the angle θ from `axis` and the azimuth φ around
//! it, and uv = ½ + θ/(2π) (cos φ, sin φ). It has no seam and no singularity on any region
//! that stays within 180° of the axis, which covers a scalp seen from its crown, and it is
//! smooth, so frames (eq. 1-3) vary smoothly across bundles.

use glam::{DVec2, DVec3};

use crate::model::mesh::HairMesh;

/// uv of `point` by the azimuthal-equidistant projection described in the module docs.
/// `reference` fixes φ = 0 (any vector not parallel to `axis`).
pub(crate) fn azimuthal_uv(point: DVec3, center: DVec3, axis: DVec3, reference: DVec3) -> DVec2 {
    let axis = axis.try_normalize().unwrap_or(DVec3::Y);
    let e1 = (reference - axis * reference.dot(axis))
        .try_normalize()
        .unwrap_or_else(|| axis.any_orthonormal_vector());
    let e2 = axis.cross(e1);
    let Some(d) = (point - center).try_normalize() else {
        return DVec2::splat(0.5);
    };
    let theta = d.dot(axis).clamp(-1.0, 1.0).acos();
    let planar = DVec2::new(d.dot(e1), d.dot(e2));
    let direction = planar.try_normalize().unwrap_or(DVec2::X);
    DVec2::splat(0.5) + direction * (theta / (2.0 * std::f64::consts::PI))
}

/// Replaces every face-corner uv of `mesh` with [`azimuthal_uv`] of its root position. With
/// no axis given, the axis is the area-weighted mean normal of the root layer and the centre
/// lies one bounding radius below the centroid along it, which projects a cap like a dome
/// and a nearly flat patch almost orthographically.
pub fn generate_uv(mesh: &mut HairMesh, frame: Option<(DVec3, DVec3, DVec3)>) {
    let (center, axis, reference) = frame.unwrap_or_else(|| default_projection(mesh));
    for bundle in &mut mesh.bundles {
        for (corner, &v) in bundle.vertices.iter().enumerate() {
            let p = mesh.columns[v as usize].positions[0];
            bundle.uvs[corner] = azimuthal_uv(p, center, axis, reference);
        }
    }
}

fn default_projection(mesh: &HairMesh) -> (DVec3, DVec3, DVec3) {
    let mut normal = DVec3::ZERO;
    for bundle in &mesh.bundles {
        let p: Vec<DVec3> = bundle
            .vertices
            .iter()
            .map(|&v| mesh.columns[v as usize].positions[0])
            .collect();
        for k in 1..p.len() - 1 {
            normal += (p[k] - p[0]).cross(p[k + 1] - p[0]);
        }
    }
    let axis = normal.try_normalize().unwrap_or(DVec3::Y);
    let count = mesh.columns.len().max(1) as f64;
    let centroid = mesh.columns.iter().map(|c| c.positions[0]).sum::<DVec3>() / count;
    let radius = mesh
        .columns
        .iter()
        .map(|c| c.positions[0].distance(centroid))
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    (
        centroid - axis * radius,
        axis,
        axis.any_orthonormal_vector(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pole_maps_to_centre_and_angle_to_radius() {
        let uv = azimuthal_uv(DVec3::Y * 2.0, DVec3::ZERO, DVec3::Y, DVec3::X);
        assert!(uv.distance(DVec2::splat(0.5)) < 1e-15);
        let uv = azimuthal_uv(DVec3::X, DVec3::ZERO, DVec3::Y, DVec3::X);
        assert!(uv.distance(DVec2::new(0.75, 0.5)) < 1e-15);
        assert!(azimuthal_uv(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO).is_finite());
    }
}
