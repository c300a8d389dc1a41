//! The saved document: the hair mesh, the body it grows on, its styling and its scene.
//!
//! View state (camera, selection, GPU handles) never lives here: undo never moves the
//! camera and project files hold only what the artist made.

use serde::{Deserialize, Serialize};

use crate::model::mesh::{HairMesh, InvalidMesh};
use crate::model::root_maps::RootMaps;
use crate::model::scene::Scene;
use crate::model::styling::StylingSet;

/// A triangle mesh drawn under the hair (the head, the teapot) and used for depth testing.
/// Positions are `f32` because the body is display-only; the hair mesh is `f64`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyMesh {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

impl BodyMesh {
    /// Axis-aligned bounds `(min, max)` of its finite vertices; `None` without one.
    pub fn bounds(&self) -> Option<(glam::Vec3, glam::Vec3)> {
        let mut points = self
            .positions
            .iter()
            .map(|p| glam::Vec3::from_array(*p))
            .filter(|p| p.is_finite());
        let first = points.next()?;
        Some(points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    pub fn validate(&self) -> Result<(), InvalidMesh> {
        for (i, p) in self.positions.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(InvalidMesh {
                    path: format!("positions[{i}]"),
                    message: "position is not finite".into(),
                });
            }
        }
        let count = self.positions.len();
        for (t, triangle) in self.triangles.iter().enumerate() {
            for (c, &v) in triangle.iter().enumerate() {
                if v as usize >= count {
                    return Err(InvalidMesh {
                        path: format!("triangles[{t}][{c}]"),
                        message: format!("vertex index {v} out of range ({count} positions)"),
                    });
                }
            }
        }
        Ok(())
    }

    /// A unit shading normal per vertex: the mean of the normals of the triangles around it,
    /// each weighted by its angle at the vertex (so a fan of thin triangles does not outvote
    /// one wide one; Thürmer & Wüthrich 1998). Vertices at the same position share one
    /// normal, so a scan split at its uv seams shades without a seam. A vertex with no
    /// triangle of any area gets `[0, 0, 0]`: the shaders then fall back to the face's own
    /// normal. Orientation follows the winding; a renderer turns a normal to face the viewer.
    /// Indices out of range are skipped (`validate` names them).
    pub fn vertex_normals(&self) -> Vec<[f32; 3]> {
        use std::collections::HashMap;
        let count = self.positions.len();
        // One slot per distinct position (exact bits: welding nearby points would join the
        // lips of a mouth).
        let mut slot_of_position: HashMap<[u32; 3], u32> = HashMap::with_capacity(count);
        let slots: Vec<u32> = self
            .positions
            .iter()
            .map(|p| {
                let next = slot_of_position.len() as u32;
                *slot_of_position
                    .entry(p.map(|c| if c == 0.0 { 0 } else { c.to_bits() }))
                    .or_insert(next)
            })
            .collect();
        let mut sums = vec![glam::DVec3::ZERO; slot_of_position.len()];
        let point = |i: u32| glam::DVec3::from(self.positions[i as usize].map(f64::from));
        for triangle in &self.triangles {
            if triangle.iter().any(|&v| v as usize >= count) {
                continue;
            }
            let corners = triangle.map(point);
            let cross = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            let longest_squared = (0..3)
                .map(|c| corners[c].distance_squared(corners[(c + 1) % 3]))
                .fold(0.0, f64::max);
            // A sliver whose plane is set by rounding (two corners a float's step apart)
            // has a normal that points anywhere: it adds nothing.
            let area_measure = cross.length();
            if area_measure.is_nan() || area_measure <= 1e-6 * longest_squared {
                continue;
            }
            let normal = cross.normalize();
            for c in 0..3 {
                let a = corners[(c + 1) % 3] - corners[c];
                let b = corners[(c + 2) % 3] - corners[c];
                let angle = a.angle_between(b);
                if angle.is_finite() {
                    sums[slots[triangle[c] as usize] as usize] += normal * angle;
                }
            }
        }
        slots
            .iter()
            .map(|&slot| {
                sums[slot as usize]
                    .try_normalize()
                    .map_or([0.0; 3], |n| n.as_vec3().to_array())
            })
            .collect()
    }
}

/// Everything an artist makes, saved in a project file and edited through commands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Document {
    /// A human-readable name (the sample's or imported file's name).
    pub name: String,
    /// Where the scalp and body came from, with attribution when a licence asks for it.
    #[serde(default)]
    pub source: String,
    pub hair_mesh: HairMesh,
    #[serde(default)]
    pub body: BodyMesh,
    /// Styling parameters: global values with per-bundle-group overrides.
    #[serde(default)]
    pub styling: StylingSet,
    /// Lights, cameras, the hair material and the effects the renderer runs. Files from
    /// before scenes existed (format version 1) get the default scene.
    #[serde(default)]
    pub scene: Scene,
    /// Density, length and clump painted over the scalp in root-uv space (none: 1
    /// everywhere). Files from before painted maps have none.
    #[serde(default, skip_serializing_if = "RootMaps::is_empty")]
    pub root_maps: RootMaps,
}

/// A validation problem anywhere in a document, with the JSON path of the value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct InvalidDocument {
    pub path: String,
    pub message: String,
}

impl Document {
    /// The head's plane of symmetry, `x = plane_x`: the middle of the body's x extent (a
    /// head is symmetric; its hair need not be yet), or of the hair mesh's without a body.
    /// Wisp mirroring and the brushes' X-mirror reflect across it.
    pub fn mirror_plane_x(&self) -> f64 {
        let body_x = self.body.positions.iter().map(|p| p[0] as f64);
        match (body_x.clone().reduce(f64::min), body_x.reduce(f64::max)) {
            (Some(lo), Some(hi)) if lo.is_finite() && hi.is_finite() => 0.5 * (lo + hi),
            _ => self
                .hair_mesh
                .bounds()
                .map_or(0.0, |(lo, hi)| 0.5 * (lo.x + hi.x)),
        }
    }

    /// Vertices per strand (2^N + 1, as N) that draw this project's styling as curves
    /// ([`crate::strands::styling::strand_vertices_log2`] over its longest column's w).
    pub fn strand_vertices_log2(&self) -> u32 {
        let longest_w = self
            .hair_mesh
            .columns
            .iter()
            .filter_map(|c| c.w.last().copied())
            .fold(0.0, f64::max);
        crate::strands::styling::strand_vertices_log2(&self.styling, longest_w)
    }

    pub fn new(name: impl Into<String>, hair_mesh: HairMesh) -> Self {
        Self {
            name: name.into(),
            source: String::new(),
            hair_mesh,
            body: BodyMesh::default(),
            styling: StylingSet::default(),
            scene: Scene::default(),
            root_maps: RootMaps::default(),
        }
    }

    /// Validates the whole document; paths are relative to the document.
    pub fn validate(&self) -> Result<(), InvalidDocument> {
        self.hair_mesh.validate().map_err(|e| InvalidDocument {
            path: format!("hair_mesh.{}", e.path),
            message: e.message,
        })?;
        self.body.validate().map_err(|e| InvalidDocument {
            path: format!("body.{}", e.path),
            message: e.message,
        })?;
        self.styling.validate().map_err(|message| {
            let (path, message) = message.split_once(": ").unwrap_or(("", &message));
            InvalidDocument {
                path: format!("styling.{path}"),
                message: message.to_string(),
            }
        })?;
        self.scene.validate().map_err(|e| InvalidDocument {
            path: format!("scene.{}", e.path),
            message: e.message,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A latitude-longitude sphere of radius `radius`, its longitude seam split (the first
    /// and last columns are separate vertices at the same positions, as a uv seam leaves
    /// them).
    fn split_seam_sphere(radius: f32, rings: u32, columns: u32) -> BodyMesh {
        let mut positions = Vec::new();
        for r in 0..=rings {
            let theta = std::f32::consts::PI * r as f32 / rings as f32;
            // Exactly zero at the poles, so each pole is one point.
            let ring_radius = if r == 0 || r == rings {
                0.0
            } else {
                radius * theta.sin()
            };
            for c in 0..=columns {
                let phi = std::f32::consts::TAU * (c % columns) as f32 / columns as f32;
                positions.push([
                    ring_radius * phi.cos(),
                    radius * theta.cos(),
                    ring_radius * phi.sin(),
                ]);
            }
        }
        let at = |r: u32, c: u32| r * (columns + 1) + c;
        let mut triangles = Vec::new();
        for r in 0..rings {
            for c in 0..columns {
                triangles.push([at(r, c), at(r, c + 1), at(r + 1, c)]);
                triangles.push([at(r, c + 1), at(r + 1, c + 1), at(r + 1, c)]);
            }
        }
        BodyMesh {
            positions,
            triangles,
        }
    }

    #[test]
    fn sphere_normals_point_along_the_radius_and_the_seam_does_not_show() {
        let sphere = split_seam_sphere(0.1, 24, 48);
        let normals = sphere.vertex_normals();
        assert_eq!(normals.len(), sphere.positions.len());
        // The sphere's winding faces inward or outward; either way every normal lies along
        // the radius, all with the same sign.
        let mut signs = std::collections::BTreeSet::new();
        for (p, n) in sphere.positions.iter().zip(&normals) {
            let radial = glam::Vec3::from(*p).normalize();
            let n = glam::Vec3::from(*n);
            assert!((n.length() - 1.0).abs() < 1e-5, "not unit: {n}");
            let cosine = n.dot(radial);
            assert!(cosine.abs() > 0.998, "{n} at {radial}: cos {cosine}");
            signs.insert(cosine > 0.0);
        }
        assert_eq!(signs.len(), 1, "normals flip across the sphere");
        // The two copies of each seam vertex share their normal exactly.
        for r in 0..=24u32 {
            let first = normals[(r * 49) as usize];
            let last = normals[(r * 49 + 48) as usize];
            assert_eq!(first, last, "ring {r}");
        }
    }

    #[test]
    fn a_thin_fan_does_not_outvote_a_wide_triangle() {
        // Vertex 0 at a fold between one wide triangle in the plane z = 0 and five slivers
        // in the plane x = 0: weighted by angle (90° each side) the normal bisects the fold;
        // weighted by count it would lean toward the slivers.
        let mut positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mut triangles = vec![[0, 1, 2]];
        for k in 0..=5u32 {
            let angle = std::f32::consts::FRAC_PI_2 * k as f32 / 5.0;
            positions.push([0.0, angle.cos(), angle.sin()]);
        }
        for k in 0..5u32 {
            triangles.push([0, 3 + k, 4 + k]);
        }
        let mesh = BodyMesh {
            positions,
            triangles,
        };
        let n = glam::Vec3::from(mesh.vertex_normals()[0]);
        let expected = glam::Vec3::new(1.0, 0.0, 1.0).normalize();
        assert!(n.dot(expected) > 0.999, "{n}");
    }

    #[test]
    fn degenerate_and_bad_triangles_leave_no_nan() {
        let mesh = BodyMesh {
            positions: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [5.0, 5.0, 5.0],
            ],
            // Collinear, repeated corners and an index out of range; vertex 3 is in none.
            triangles: vec![[0, 1, 2], [1, 1, 1], [0, 1, 99]],
        };
        assert_eq!(mesh.vertex_normals(), vec![[0.0; 3]; 4]);
        assert!(BodyMesh::default().vertex_normals().is_empty());
    }
}
