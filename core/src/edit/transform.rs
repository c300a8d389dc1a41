//! Move / rotate / scale of hair-mesh vertices with a soft-selection falloff; interior
//! vertices follow (they are placed, never moved).

use std::collections::BTreeSet;

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

use crate::edit::{EditError, EditOutcome, finish};
use crate::model::mesh::{HairMesh, Topology, VertexRef};

/// A rigid or scaling transform of selected vertices.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexTransform {
    Translate {
        offset: [f64; 3],
    },
    /// Rotation by `angle_rad` around `axis` through `pivot`.
    Rotate {
        axis: [f64; 3],
        angle_rad: f64,
        pivot: [f64; 3],
    },
    /// Per-axis scale around `pivot`.
    Scale {
        factors: [f64; 3],
        pivot: [f64; 3],
    },
}

impl VertexTransform {
    fn check_finite(&self) -> Result<(), EditError> {
        let values: Vec<f64> = match *self {
            Self::Translate { offset } => offset.to_vec(),
            Self::Rotate {
                axis,
                angle_rad,
                pivot,
            } => {
                let mut v = axis.to_vec();
                v.push(angle_rad);
                v.extend(pivot);
                v
            }
            Self::Scale { factors, pivot } => factors.iter().chain(&pivot).copied().collect(),
        };
        match values.iter().find(|v| !v.is_finite()) {
            Some(v) => Err(EditError::NotFinite {
                what: "transform parameter",
                value: v.to_string(),
            }),
            None => Ok(()),
        }
    }

    /// The transform applied with strength `weight ∈ [0, 1]` (soft selection): translation
    /// and angle scale linearly, scale factors interpolate toward 1.
    fn apply(&self, p: DVec3, weight: f64) -> DVec3 {
        match *self {
            Self::Translate { offset } => p + DVec3::from(offset) * weight,
            Self::Rotate {
                axis,
                angle_rad,
                pivot,
            } => {
                let Some(axis) = DVec3::from(axis).try_normalize() else {
                    return p;
                };
                let pivot = DVec3::from(pivot);
                pivot + DQuat::from_axis_angle(axis, angle_rad * weight) * (p - pivot)
            }
            Self::Scale { factors, pivot } => {
                let pivot = DVec3::from(pivot);
                let factors = DVec3::ONE.lerp(DVec3::from(factors), weight);
                pivot + (p - pivot) * factors
            }
        }
    }
}

/// Soft-selection weight for a vertex at `distance` from the nearest selected vertex:
/// `(1 − (d/r)²)²` inside the radius, a smooth bump that is 1 at the selection and has zero
/// slope at the radius.
pub fn falloff_weight(distance: f64, radius: f64) -> f64 {
    if radius <= 0.0 || distance >= radius {
        return 0.0;
    }
    let x = distance / radius;
    let y = 1.0 - x * x;
    y * y
}

/// Moves exterior vertices. With `falloff_radius_m > 0`, other exterior vertices within
/// that distance of the nearest selected vertex follow with weight [`falloff_weight`]
/// (root-layer vertices only when some root vertex is selected, so soft edits of hair never
/// drag the scalp). Interior vertices in the selection are an error.
pub fn transform_vertices(
    mesh: &HairMesh,
    vertices: &[VertexRef],
    transform: VertexTransform,
    falloff_radius_m: f64,
) -> Result<EditOutcome, EditError> {
    if vertices.is_empty() {
        return Err(EditError::EmptySelection);
    }
    transform.check_finite()?;
    if !falloff_radius_m.is_finite() {
        return Err(EditError::NotFinite {
            what: "falloff radius",
            value: falloff_radius_m.to_string(),
        });
    }
    let topology = Topology::build(mesh);
    for v in vertices {
        if mesh.position(*v).is_none() {
            return Err(EditError::VertexOutOfRange {
                column: v.column,
                layer: v.layer,
            });
        }
        if mesh.is_interior(&topology, v.column as usize, v.layer as usize) {
            return Err(EditError::InteriorVertex {
                column: v.column,
                layer: v.layer,
            });
        }
    }
    let selected: BTreeSet<VertexRef> = vertices.iter().copied().collect();
    let includes_root = selected.iter().any(|v| v.layer == 0);
    let selected_positions: Vec<DVec3> =
        selected.iter().filter_map(|v| mesh.position(*v)).collect();
    let mut out = mesh.clone();
    let mut layers: BTreeSet<usize> = BTreeSet::new();
    for (c, column) in mesh.columns.iter().enumerate() {
        for (k, &p) in column.positions.iter().enumerate() {
            let here = VertexRef {
                column: c as u32,
                layer: k as u32,
            };
            let weight = if selected.contains(&here) {
                1.0
            } else if falloff_radius_m > 0.0
                && (k > 0 || includes_root)
                && !mesh.is_interior(&topology, c, k)
            {
                let nearest = selected_positions
                    .iter()
                    .map(|s| s.distance(p))
                    .fold(f64::INFINITY, f64::min);
                falloff_weight(nearest, falloff_radius_m)
            } else {
                0.0
            };
            if weight > 0.0 {
                out.columns[c].positions[k] = transform.apply(p, weight);
                layers.insert(k);
            }
        }
    }
    // A moved root vertex changes the affine reference of every layer.
    let all_layers = layers.contains(&0);
    let layers: Vec<usize> = layers.into_iter().collect();
    let affected = affected_bundles_of_columns(&topology, &selected);
    finish(out, affected, if all_layers { None } else { Some(&layers) })
}

fn affected_bundles_of_columns(
    topology: &Topology,
    vertices: &BTreeSet<VertexRef>,
) -> BTreeSet<u32> {
    vertices
        .iter()
        .flat_map(|v| {
            topology.bundles_of_column[v.column as usize]
                .iter()
                .copied()
        })
        .collect()
}
