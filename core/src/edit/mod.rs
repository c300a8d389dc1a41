//! Edits of the hair mesh: topology tools and vertex transforms.
//!
//! Every edit is a pure function from a mesh to a new mesh (or an error that leaves the
//! input untouched). Each one keeps the invariants of [`HairMesh::validate`], re-places
//! interior vertices of the layers it affected and refreshes w. [`crate::model::history`] turns the
//! before/after pair into an undoable command.
//!
//! Column vertices are shared by every bundle around the column, so layer insertion and
//! deletion spread to every bundle that shares a column with an affected bundle at or above
//! the edited layer ([`layer_closure`]); the returned [`EditOutcome`] says which bundles were
//! affected.

pub mod pick;
pub mod select;

use std::collections::{BTreeSet, HashMap};

use glam::{DQuat, DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::geometry::curve::{cubic_point, curve_segments};
use crate::geometry::interior::place_interior;
use crate::model::mesh::{Bundle, Column, HairMesh, Topology, VertexRef, WMode};

/// Why an edit was refused. The mesh is unchanged.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EditError {
    #[error("nothing selected")]
    EmptySelection,
    #[error("bundle {index} does not exist (the mesh has {count} bundles)")]
    BundleOutOfRange { index: u32, count: usize },
    #[error("vertex (column {column}, layer {layer}) does not exist")]
    VertexOutOfRange { column: u32, layer: u32 },
    #[error(
        "vertex (column {column}, layer {layer}) is interior; interior vertices are placed automatically"
    )]
    InteriorVertex { column: u32, layer: u32 },
    #[error("layer {layer} is not an extruded layer of bundle {bundle} (it has {layers})")]
    LayerOutOfRange {
        bundle: u32,
        layer: u32,
        layers: u32,
    },
    #[error("{what} must be finite, got {value}")]
    NotFinite { what: &'static str, value: String },
    #[error("the edit would leave an invalid mesh: {0}")]
    Invalid(#[from] crate::model::mesh::InvalidMesh),
}

/// Result of a successful edit.
#[derive(Clone, Debug)]
pub struct EditOutcome {
    pub mesh: HairMesh,
    /// Bundles the edit actually changed (after spreading along shared columns).
    pub affected_bundles: Vec<u32>,
}

/// Direction of an extrusion.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ExtrudeDirection {
    /// Along the vertex normal of the current top layer (area-weighted over the extruded
    /// bundles around the vertex), by `distance` model units.
    AlongNormal { distance: f64 },
    /// The same vector for every new vertex.
    Vector { offset: [f64; 3] },
}

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

fn check_bundles(mesh: &HairMesh, bundles: &[u32]) -> Result<(), EditError> {
    if bundles.is_empty() {
        return Err(EditError::EmptySelection);
    }
    for &index in bundles {
        if index as usize >= mesh.bundles.len() {
            return Err(EditError::BundleOutOfRange {
                index,
                count: mesh.bundles.len(),
            });
        }
    }
    Ok(())
}

fn finish(
    mut mesh: HairMesh,
    affected: BTreeSet<u32>,
    layers: Option<&[usize]>,
) -> Result<EditOutcome, EditError> {
    place_interior(&mut mesh, layers);
    mesh.update_w();
    mesh.validate()?;
    Ok(EditOutcome {
        mesh,
        affected_bundles: affected.into_iter().collect(),
    })
}

/// Extrudes each bundle in `bundles` by one layer. A bundle with `n` layers gets layer
/// `n + 1`; where a taller neighbour already has that vertex it is shared, elsewhere a new
/// vertex is created from the vertex below it.
pub fn extrude(
    mesh: &HairMesh,
    bundles: &[u32],
    direction: ExtrudeDirection,
) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    let (distance, offset) = match direction {
        ExtrudeDirection::AlongNormal { distance } => (distance, DVec3::ZERO),
        ExtrudeDirection::Vector { offset } => (0.0, DVec3::from(offset)),
    };
    if !distance.is_finite() || !offset.is_finite() {
        return Err(EditError::NotFinite {
            what: "extrusion distance",
            value: format!("{distance} / {offset}"),
        });
    }
    let selected: BTreeSet<u32> = bundles.iter().copied().collect();
    let mut out = mesh.clone();
    // Normals at the current top layer of each extruded bundle, accumulated per (column, layer).
    let mut normals: HashMap<(u32, usize), DVec3> = HashMap::new();
    for &b in &selected {
        let bundle = &mesh.bundles[b as usize];
        let top = bundle.layers as usize;
        let n = bundle.vertices.len();
        for i in 0..n {
            let v = bundle.vertices[i];
            let next = mesh.columns[bundle.vertices[(i + 1) % n] as usize].positions[top];
            let prev = mesh.columns[bundle.vertices[(i + n - 1) % n] as usize].positions[top];
            let here = mesh.columns[v as usize].positions[top];
            *normals.entry((v, top)).or_default() += (next - here).cross(prev - here);
        }
    }
    // Grow in order of target layer so a vertex created for layer k is in place before k+1.
    let mut order: Vec<u32> = selected.iter().copied().collect();
    order.sort_by_key(|&b| mesh.bundles[b as usize].layers);
    for b in order {
        let top = out.bundles[b as usize].layers as usize;
        for &v in &mesh.bundles[b as usize].vertices.clone() {
            let column = &mut out.columns[v as usize];
            if column.positions.len() > top + 1 {
                continue; // shared with a taller neighbour
            }
            let base = column.positions[top];
            let step = match direction {
                ExtrudeDirection::AlongNormal { .. } => {
                    let normal = normals
                        .get(&(v, top))
                        .and_then(|n| n.try_normalize())
                        .or_else(|| {
                            (top > 0)
                                .then(|| (base - column.positions[top - 1]).try_normalize())
                                .flatten()
                        })
                        .unwrap_or(DVec3::Z);
                    normal * distance
                }
                ExtrudeDirection::Vector { .. } => offset,
            };
            column.positions.push(base + step);
            let last_w = column.w[top];
            column.w.push(last_w + step.length());
        }
        out.bundles[b as usize].layers += 1;
    }
    finish(out, selected, None)
}

/// Bundles that must change together when layer `layer` is inserted or deleted in
/// `bundles`: the closure under "shares a column and has at least `layer` layers".
pub fn layer_closure(mesh: &HairMesh, bundles: &[u32], layer: usize) -> BTreeSet<u32> {
    let topology = Topology::build(mesh);
    let mut result: BTreeSet<u32> = BTreeSet::new();
    let mut stack: Vec<u32> = bundles
        .iter()
        .copied()
        .filter(|&b| mesh.bundles[b as usize].layers as usize >= layer)
        .collect();
    while let Some(b) = stack.pop() {
        if !result.insert(b) {
            continue;
        }
        for &v in &mesh.bundles[b as usize].vertices {
            for &other in &topology.bundles_of_column[v as usize] {
                if !result.contains(&other) && mesh.bundles[other as usize].layers as usize >= layer
                {
                    stack.push(other);
                }
            }
        }
    }
    result
}

fn check_layer(mesh: &HairMesh, bundles: &[u32], layer: u32) -> Result<(), EditError> {
    for &b in bundles {
        let layers = mesh.bundles[b as usize].layers;
        if layer == 0 || layer > layers {
            return Err(EditError::LayerOutOfRange {
                bundle: b,
                layer,
                layers,
            });
        }
    }
    Ok(())
}

/// Inserts a layer between layers `layer − 1` and `layer` (1 ≤ layer ≤ n) of `bundles`
/// and every bundle sharing their columns at that height. New vertices sit at the middle of
/// their column's curve segment; w is interpolated the same way.
pub fn insert_layer(
    mesh: &HairMesh,
    bundles: &[u32],
    layer: u32,
) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    check_layer(mesh, bundles, layer)?;
    let affected = layer_closure(mesh, bundles, layer as usize);
    let k = layer as usize;
    let mut out = mesh.clone();
    let columns: BTreeSet<u32> = affected
        .iter()
        .flat_map(|&b| mesh.bundles[b as usize].vertices.iter().copied())
        .collect();
    for &c in &columns {
        let column = &mut out.columns[c as usize];
        if column.positions.len() <= k {
            continue;
        }
        let segments = curve_segments(&column.positions);
        let middle = cubic_point(&segments[k - 1], 0.5);
        let w_middle = 0.5 * (column.w[k - 1] + column.w[k]);
        column.positions.insert(k, middle);
        column.w.insert(k, w_middle);
    }
    for &b in &affected {
        out.bundles[b as usize].layers += 1;
    }
    finish(out, affected, None)
}

/// Deletes layer `layer` (1 ≤ layer ≤ n) of `bundles` and every bundle sharing their
/// columns at that height; the layers above move down by one.
pub fn delete_layer(
    mesh: &HairMesh,
    bundles: &[u32],
    layer: u32,
) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    check_layer(mesh, bundles, layer)?;
    let affected = layer_closure(mesh, bundles, layer as usize);
    let k = layer as usize;
    let mut out = mesh.clone();
    let columns: BTreeSet<u32> = affected
        .iter()
        .flat_map(|&b| mesh.bundles[b as usize].vertices.iter().copied())
        .collect();
    for &c in &columns {
        let column = &mut out.columns[c as usize];
        if column.positions.len() > k {
            column.positions.remove(k);
            column.w.remove(k);
        }
    }
    for &b in &affected {
        out.bundles[b as usize].layers -= 1;
    }
    finish(out, affected, None)
}

/// Removes (`removed = true`) or restores bundles. Geometry is kept either way.
pub fn set_removed(
    mesh: &HairMesh,
    bundles: &[u32],
    removed: bool,
) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    let mut out = mesh.clone();
    for &b in bundles {
        out.bundles[b as usize].removed = removed;
    }
    finish(out, bundles.iter().copied().collect(), None)
}

/// Splits each selected root face 1 → 4 (quads into four quads through edge midpoints and
/// the centre, triangles into four triangles through edge midpoints), through all layers.
/// Edge-midpoint columns are shared by two subdivided neighbours; next to a face that is
/// not subdivided the midpoint column is a T-junction and counts as exterior.
pub fn subdivide(mesh: &HairMesh, bundles: &[u32]) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    let selected: BTreeSet<u32> = bundles.iter().copied().collect();
    let mut out = mesh.clone();
    let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
    let mut new_bundles: Vec<u32> = Vec::new();
    // Positions per layer of a new column blending existing columns; the length follows the
    // tallest bundle that will use it.
    fn blended_column(mesh: &HairMesh, sources: &[u32], len: usize) -> Column {
        let weight = 1.0 / sources.len() as f64;
        let positions: Vec<DVec3> = (0..len)
            .map(|k| {
                sources
                    .iter()
                    .map(|&s| {
                        let column = &mesh.columns[s as usize].positions;
                        column[k.min(column.len() - 1)] * weight
                    })
                    .sum()
            })
            .collect();
        let w = (0..len)
            .map(|k| {
                sources
                    .iter()
                    .map(|&s| {
                        let w = &mesh.columns[s as usize].w;
                        w[k.min(w.len() - 1)] * weight
                    })
                    .sum()
            })
            .collect();
        Column { positions, w }
    }
    for &b in &selected {
        let bundle = mesh.bundles[b as usize].clone();
        let n = bundle.vertices.len();
        let len = bundle.layers as usize + 1;
        let mut mid = Vec::with_capacity(n);
        for i in 0..n {
            let a = bundle.vertices[i];
            let c = bundle.vertices[(i + 1) % n];
            let key = (a.min(c), a.max(c));
            let index = match midpoints.get(&key) {
                Some(&index) => {
                    let column = &mut out.columns[index as usize];
                    if column.positions.len() < len {
                        *column = blended_column(mesh, &[a, c], len);
                    }
                    index
                }
                None => {
                    let index = out.columns.len() as u32;
                    out.columns.push(blended_column(mesh, &[a, c], len));
                    midpoints.insert(key, index);
                    index
                }
            };
            mid.push(index);
        }
        let uv_mid: Vec<DVec2> = (0..n)
            .map(|i| (bundle.uvs[i] + bundle.uvs[(i + 1) % n]) * 0.5)
            .collect();
        let child = |vertices: Vec<u32>, uvs: Vec<DVec2>| Bundle {
            vertices,
            uvs,
            layers: bundle.layers,
            removed: bundle.removed,
        };
        let v = &bundle.vertices;
        let uv = &bundle.uvs;
        let children = if n == 4 {
            let center = out.columns.len() as u32;
            out.columns.push(blended_column(mesh, v, len));
            let uv_center = uv.iter().copied().sum::<DVec2>() * 0.25;
            vec![
                child(
                    vec![v[0], mid[0], center, mid[3]],
                    vec![uv[0], uv_mid[0], uv_center, uv_mid[3]],
                ),
                child(
                    vec![mid[0], v[1], mid[1], center],
                    vec![uv_mid[0], uv[1], uv_mid[1], uv_center],
                ),
                child(
                    vec![center, mid[1], v[2], mid[2]],
                    vec![uv_center, uv_mid[1], uv[2], uv_mid[2]],
                ),
                child(
                    vec![mid[3], center, mid[2], v[3]],
                    vec![uv_mid[3], uv_center, uv_mid[2], uv[3]],
                ),
            ]
        } else {
            vec![
                child(
                    vec![v[0], mid[0], mid[2]],
                    vec![uv[0], uv_mid[0], uv_mid[2]],
                ),
                child(
                    vec![mid[0], v[1], mid[1]],
                    vec![uv_mid[0], uv[1], uv_mid[1]],
                ),
                child(
                    vec![mid[2], mid[1], v[2]],
                    vec![uv_mid[2], uv_mid[1], uv[2]],
                ),
                child(
                    vec![mid[0], mid[1], mid[2]],
                    vec![uv_mid[0], uv_mid[1], uv_mid[2]],
                ),
            ]
        };
        let mut children = children.into_iter();
        if let Some(first) = children.next() {
            out.bundles[b as usize] = first;
        }
        for c in children {
            new_bundles.push(out.bundles.len() as u32);
            out.bundles.push(c);
        }
    }
    let mut affected = selected;
    affected.extend(new_bundles);
    finish(out, affected, None)
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

/// Sets w of one vertex and switches the mesh to [`WMode::Manual`]. w must stay
/// non-decreasing along the column and 0 at the root.
pub fn set_w(mesh: &HairMesh, vertex: VertexRef, w: f64) -> Result<EditOutcome, EditError> {
    if !w.is_finite() {
        return Err(EditError::NotFinite {
            what: "w",
            value: w.to_string(),
        });
    }
    if mesh.position(vertex).is_none() {
        return Err(EditError::VertexOutOfRange {
            column: vertex.column,
            layer: vertex.layer,
        });
    }
    let mut out = mesh.clone();
    out.w_mode = WMode::Manual;
    out.columns[vertex.column as usize].w[vertex.layer as usize] = w;
    out.validate()?;
    let topology = Topology::build(mesh);
    Ok(EditOutcome {
        affected_bundles: topology.bundles_of_column[vertex.column as usize].clone(),
        mesh: out,
    })
}

/// Switches how w is maintained; switching to [`WMode::FromPathLength`] recomputes it.
pub fn set_w_mode(mesh: &HairMesh, mode: WMode) -> Result<EditOutcome, EditError> {
    let mut out = mesh.clone();
    out.w_mode = mode;
    out.update_w();
    Ok(EditOutcome {
        mesh: out,
        affected_bundles: (0..mesh.bundles.len() as u32).collect(),
    })
}

/// Sets the uv of face corners: `(bundle, corner, uv)`.
pub fn set_corner_uvs(
    mesh: &HairMesh,
    changes: &[(u32, u32, DVec2)],
) -> Result<EditOutcome, EditError> {
    if changes.is_empty() {
        return Err(EditError::EmptySelection);
    }
    let mut out = mesh.clone();
    let mut affected = BTreeSet::new();
    for &(b, corner, uv) in changes {
        let count = mesh.bundles.len();
        let bundle = out
            .bundles
            .get_mut(b as usize)
            .ok_or(EditError::BundleOutOfRange { index: b, count })?;
        if !uv.is_finite() {
            return Err(EditError::NotFinite {
                what: "uv",
                value: uv.to_string(),
            });
        }
        let Some(slot) = bundle.uvs.get_mut(corner as usize) else {
            return Err(EditError::BundleOutOfRange { index: b, count });
        };
        *slot = uv;
        affected.insert(b);
    }
    out.validate()?;
    Ok(EditOutcome {
        mesh: out,
        affected_bundles: affected.into_iter().collect(),
    })
}

/// The centre of a bundle's corners at `layer`.
pub fn bundle_layer_centre(mesh: &HairMesh, bundle: &Bundle, layer: usize) -> Option<DVec3> {
    let points: Option<Vec<DVec3>> = bundle
        .vertices
        .iter()
        .map(|&c| mesh.columns.get(c as usize)?.positions.get(layer).copied())
        .collect();
    let points = points?;
    Some(points.iter().sum::<DVec3>() / points.len().max(1) as f64)
}

/// A right-handed frame at a bundle's root: first edge, its normal-perpendicular, normal.
fn root_frame(mesh: &HairMesh, bundle: &Bundle) -> Option<[DVec3; 3]> {
    let p: Vec<DVec3> = bundle
        .vertices
        .iter()
        .map(|&c| mesh.columns.get(c as usize)?.positions.first().copied())
        .collect::<Option<_>>()?;
    let n = p.len();
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        normal += p[i].cross(p[(i + 1) % n]);
    }
    let normal = normal.try_normalize()?;
    let edge = (p[1] - p[0])
        .reject_from_normalized(normal)
        .try_normalize()?;
    Some([edge, normal.cross(edge), normal])
}

/// The unit direction a bundle grows in at its top: from the centre of the layer below to
/// the top centre, or the root face's normal for a bare bundle.
pub fn growth_direction(mesh: &HairMesh, bundle: &Bundle) -> Option<DVec3> {
    match bundle.layers as usize {
        0 => root_frame(mesh, bundle).map(|[_, _, normal]| normal),
        top => (bundle_layer_centre(mesh, bundle, top)?
            - bundle_layer_centre(mesh, bundle, top - 1)?)
        .try_normalize(),
    }
}

/// The path of a bundle's centre above its root, layer by layer (`offsets[k-1]` is layer k).
fn centre_path(mesh: &HairMesh, bundle: &Bundle) -> Option<Vec<DVec3>> {
    let root = bundle_layer_centre(mesh, bundle, 0)?;
    (1..=bundle.layers as usize)
        .map(|k| Some(bundle_layer_centre(mesh, bundle, k)? - root))
        .collect()
}

/// Moves the target bundles' centre paths to `path_of(target)` (layer k's centre offset
/// from the root centre), keeping each target's own cross-section around its centre. A
/// column shared by several targets takes the mean of what they ask for.
fn set_centre_paths(
    mesh: &HairMesh,
    targets: &[u32],
    path_of: impl Fn(u32, &Bundle) -> Option<Vec<DVec3>>,
) -> Result<EditOutcome, EditError> {
    let mut sums: HashMap<(u32, usize), (DVec3, f64)> = HashMap::new();
    for &t in targets {
        let bundle = &mesh.bundles[t as usize];
        let Some(path) = path_of(t, bundle) else {
            continue;
        };
        let Some(root) = bundle_layer_centre(mesh, bundle, 0) else {
            continue;
        };
        let layers = (bundle.layers as usize).min(path.len());
        for (k, offset) in path.iter().enumerate().take(layers) {
            let layer = k + 1;
            let Some(centre) = bundle_layer_centre(mesh, bundle, layer) else {
                continue;
            };
            for &c in &bundle.vertices {
                let p = mesh.columns[c as usize].positions[layer];
                let entry = sums.entry((c, layer)).or_insert((DVec3::ZERO, 0.0));
                entry.0 += root + *offset + (p - centre);
                entry.1 += 1.0;
            }
        }
    }
    let mut out = mesh.clone();
    let mut layers = BTreeSet::new();
    for ((c, layer), (sum, count)) in sums {
        let p = sum / count;
        if !p.is_finite() {
            return Err(EditError::NotFinite {
                what: "pasted position",
                value: p.to_string(),
            });
        }
        out.columns[c as usize].positions[layer] = p;
        layers.insert(layer);
    }
    let layers: Vec<usize> = layers.into_iter().collect();
    finish(out, targets.iter().copied().collect(), Some(&layers))
}

/// Wisp copy / paste (the key-strand copy of Zhang & Wünsche's framework, on bundles):
/// gives every target the shape of `source` — its centre's path above the root, turned
/// from the source's root frame into each target's — keeping each target's own width.
/// Layers beyond the shorter of the two bundles are left alone.
pub fn paste_shape(
    mesh: &HairMesh,
    source: u32,
    targets: &[u32],
) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, &[source])?;
    check_bundles(mesh, targets)?;
    let source_bundle = &mesh.bundles[source as usize];
    let path = centre_path(mesh, source_bundle).ok_or(EditError::BundleOutOfRange {
        index: source,
        count: mesh.bundles.len(),
    })?;
    let Some([t0, b0, n0]) = root_frame(mesh, source_bundle) else {
        return Err(EditError::NotFinite {
            what: "source root frame (degenerate root face)",
            value: format!("bundle {source}"),
        });
    };
    let local: Vec<DVec3> = path
        .iter()
        .map(|d| DVec3::new(d.dot(t0), d.dot(b0), d.dot(n0)))
        .collect();
    set_centre_paths(mesh, targets, |_, bundle| {
        let [t, b, n] = root_frame(mesh, bundle)?;
        Some(local.iter().map(|l| t * l.x + b * l.y + n * l.z).collect())
    })
}

/// The bundle whose root centre is nearest to `point` (visible bundles only).
fn nearest_bundle(mesh: &HairMesh, point: DVec3) -> Option<u32> {
    mesh.bundles
        .iter()
        .enumerate()
        .filter(|(_, b)| !b.removed)
        .filter_map(|(i, b)| Some((i as u32, bundle_layer_centre(mesh, b, 0)?.distance(point))))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// Wisp mirror: each source bundle's shape, reflected across the plane `x = plane_x`,
/// onto the bundle whose root lies nearest the source root's mirror image. Returns the
/// outcome and the mirrored bundles, in source order.
pub fn mirror_shape(
    mesh: &HairMesh,
    sources: &[u32],
    plane_x: f64,
) -> Result<(EditOutcome, Vec<u32>), EditError> {
    check_bundles(mesh, sources)?;
    if !plane_x.is_finite() {
        return Err(EditError::NotFinite {
            what: "mirror plane",
            value: plane_x.to_string(),
        });
    }
    let reflect = |p: DVec3| DVec3::new(2.0 * plane_x - p.x, p.y, p.z);
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    for &s in sources {
        let bundle = &mesh.bundles[s as usize];
        let Some(root) = bundle_layer_centre(mesh, bundle, 0) else {
            continue;
        };
        if let Some(t) = nearest_bundle(mesh, reflect(root))
            && !pairs.iter().any(|&(_, existing)| existing == t)
        {
            pairs.push((s, t));
        }
    }
    let targets: Vec<u32> = pairs.iter().map(|&(_, t)| t).collect();
    if targets.is_empty() {
        return Err(EditError::EmptySelection);
    }
    let outcome = set_centre_paths(mesh, &targets, |t, _| {
        let &(s, _) = pairs.iter().find(|&&(_, target)| target == t)?;
        let path = centre_path(mesh, &mesh.bundles[s as usize])?;
        // A direction reflects without the plane's offset.
        Some(path.iter().map(|d| DVec3::new(-d.x, d.y, d.z)).collect())
    })?;
    Ok((outcome, targets))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    #[test]
    fn pasting_a_shape_copies_the_centre_path_and_keeps_the_width() {
        // Bundle 0 of a 4×1 strip bends along +x; paste it onto bundle 3.
        let mesh = grid(4, 1, 2, 0.5);
        let bent = transform_vertices(
            &mesh,
            &[
                VertexRef {
                    column: 0,
                    layer: 2,
                },
                VertexRef {
                    column: 1,
                    layer: 2,
                },
                VertexRef {
                    column: 5,
                    layer: 2,
                },
                VertexRef {
                    column: 6,
                    layer: 2,
                },
            ],
            VertexTransform::Translate {
                offset: [0.3, 0.0, 0.0],
            },
            0.0,
        )
        .expect("bend")
        .mesh;
        let out = paste_shape(&bent, 0, &[3]).expect("paste");
        let path = |m: &HairMesh, b: u32| centre_path(m, &m.bundles[b as usize]).expect("path");
        for (a, b) in path(&bent, 0).iter().zip(path(&out.mesh, 3)) {
            assert!(a.distance(b) < 1e-12, "{a} vs {b}");
        }
        // Width kept: the top corners of bundle 3 are still one unit apart.
        let bundle = &out.mesh.bundles[3];
        let top = |k: usize| out.mesh.columns[bundle.vertices[k] as usize].positions[2];
        assert!((top(0).distance(top(1)) - 1.0).abs() < 1e-12);
        assert!(out.mesh.validate().is_ok());
        assert!(matches!(
            paste_shape(&bent, 9, &[1]),
            Err(EditError::BundleOutOfRange { index: 9, .. })
        ));
        assert!(matches!(
            paste_shape(&bent, 0, &[]),
            Err(EditError::EmptySelection)
        ));
    }

    #[test]
    fn mirroring_reflects_a_shape_onto_the_other_side() {
        // A 4×1 strip spans x ∈ [0, 4]: bundle 0 mirrors onto bundle 3 across x = 2.
        let mesh = grid(4, 1, 1, 0.5);
        let leaning = transform_vertices(
            &mesh,
            &[
                VertexRef {
                    column: 0,
                    layer: 1,
                },
                VertexRef {
                    column: 5,
                    layer: 1,
                },
            ],
            VertexTransform::Translate {
                offset: [-0.2, 0.1, 0.0],
            },
            0.0,
        )
        .expect("lean")
        .mesh;
        let (out, targets) = mirror_shape(&leaning, &[0], 2.0).expect("mirror");
        assert_eq!(targets, vec![3]);
        let path = |m: &HairMesh, b: u32| centre_path(m, &m.bundles[b as usize]).expect("path");
        let source = path(&leaning, 0)[0];
        let mirrored = path(&out.mesh, 3)[0];
        assert!(mirrored.distance(DVec3::new(-source.x, source.y, source.z)) < 1e-12);
        assert!(matches!(
            mirror_shape(&leaning, &[0], f64::NAN),
            Err(EditError::NotFinite { .. })
        ));
    }

    #[test]
    fn extrude_adds_one_layer_and_shares_taller_columns() {
        let mesh = grid(3, 1, 1, 1.0);
        let out =
            extrude(&mesh, &[1], ExtrudeDirection::AlongNormal { distance: 0.5 }).expect("extrude");
        assert_eq!(out.mesh.bundles[1].layers, 2);
        assert_eq!(out.mesh.bundles[0].layers, 1);
        // Extruding the neighbour now reuses the shared column's vertex at layer 2.
        let before = out
            .mesh
            .columns
            .iter()
            .map(|c| c.positions.len())
            .sum::<usize>();
        let again = extrude(
            &out.mesh,
            &[0],
            ExtrudeDirection::Vector {
                offset: [0.0, 0.0, 0.5],
            },
        )
        .expect("extrude");
        let after = again
            .mesh
            .columns
            .iter()
            .map(|c| c.positions.len())
            .sum::<usize>();
        assert_eq!(after - before, 2, "two shared columns get no new vertex");
        assert!((again.mesh.columns[1].positions[2].z - 1.5).abs() < 1e-12);
    }

    #[test]
    fn insert_then_delete_layer_round_trips_positions() {
        let mesh = grid(3, 3, 3, 0.5);
        let inserted = insert_layer(&mesh, &[4], 2).expect("insert");
        // Shared columns spread the insertion to the whole connected block.
        assert_eq!(inserted.affected_bundles.len(), 9);
        assert!(inserted.mesh.bundles.iter().all(|b| b.layers == 4));
        let deleted = delete_layer(&inserted.mesh, &[0], 2).expect("delete");
        assert_eq!(deleted.mesh, mesh);
    }

    #[test]
    fn subdivide_quads_and_triangles() {
        let mesh = grid(2, 1, 2, 0.5);
        let out = subdivide(&mesh, &[0, 1]).expect("subdivide");
        assert_eq!(out.mesh.bundles.len(), 8);
        // 6 root vertices + 7 edge midpoints (one shared) + 2 centres.
        assert_eq!(out.mesh.columns.len(), 6 + 7 + 2);
        out.mesh.validate().expect("valid");
        // A triangle mesh: one triangle becomes four.
        let tri = HairMesh::from_scalp(
            &[DVec3::ZERO, DVec3::X, DVec3::Y],
            &[vec![0, 1, 2]],
            &[vec![DVec2::ZERO, DVec2::X, DVec2::Y]],
        );
        let out = subdivide(&tri, &[0]).expect("subdivide");
        assert_eq!(out.mesh.bundles.len(), 4);
        assert_eq!(out.mesh.columns.len(), 6);
    }

    #[test]
    fn interior_vertices_cannot_be_moved_and_bad_input_is_refused() {
        let mesh = grid(3, 3, 2, 0.5);
        let interior = VertexRef {
            column: 5,
            layer: 1,
        };
        let error = transform_vertices(
            &mesh,
            &[interior],
            VertexTransform::Translate {
                offset: [1.0, 0.0, 0.0],
            },
            0.0,
        )
        .expect_err("interior");
        assert!(matches!(error, EditError::InteriorVertex { .. }), "{error}");
        let nan = transform_vertices(
            &mesh,
            &[VertexRef {
                column: 0,
                layer: 1,
            }],
            VertexTransform::Translate {
                offset: [f64::NAN, 0.0, 0.0],
            },
            0.0,
        );
        assert!(matches!(nan, Err(EditError::NotFinite { .. })));
        assert!(matches!(
            extrude(
                &mesh,
                &[99],
                ExtrudeDirection::AlongNormal { distance: 1.0 }
            ),
            Err(EditError::BundleOutOfRange { index: 99, .. })
        ));
        assert!(matches!(
            delete_layer(&mesh, &[0], 3),
            Err(EditError::LayerOutOfRange { .. })
        ));
    }

    #[test]
    fn moving_the_rim_moves_interior_and_soft_selection_falls_off() {
        let mesh = grid(4, 4, 2, 0.5);
        let rim: Vec<VertexRef> = (0..5)
            .map(|i| VertexRef {
                column: i,
                layer: 1,
            })
            .collect();
        let out = transform_vertices(
            &mesh,
            &rim,
            VertexTransform::Translate {
                offset: [0.0, 0.0, 1.0],
            },
            2.5,
        )
        .expect("move");
        let moved = |c: usize, k: usize| {
            out.mesh.columns[c].positions[k].z - mesh.columns[c].positions[k].z
        };
        assert!((moved(0, 1) - 1.0).abs() < 1e-12);
        // Rim vertex two rows away (exterior) moves by the falloff weight.
        let expected = falloff_weight(2.0, 2.5);
        assert!((moved(10, 1) - expected).abs() < 1e-12);
        // Interior vertex of the same layer follows the exterior.
        assert!(moved(6, 1) > 0.0);
        // Root layer untouched by soft selection.
        assert!((0..mesh.columns.len()).all(|c| moved(c, 0) == 0.0));
    }
}
