//! Topology tools: extrude, insert / delete a layer (spread over shared columns by
//! [`layer_closure`]), remove / restore bundles and 1 → 4 subdivision.

use std::collections::{BTreeSet, HashMap};

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::edit::{EditError, EditOutcome, check_bundles, finish};
use crate::geometry::curve::{cubic_point, curve_segments};
use crate::model::mesh::{Bundle, Column, HairMesh, Topology, VertexRef};

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
    let cap = crate::runtime::textures::MAX_LAYERS_PER_BUNDLE;
    if let Some(&bundle) = selected
        .iter()
        .find(|&&b| mesh.bundles[b as usize].layers >= cap)
    {
        return Err(EditError::LayerCap { bundle, cap });
    }
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
    edit_layer(mesh, bundles, layer, 1, |column, k| {
        if column.positions.len() > k {
            let segments = curve_segments(&column.positions);
            let middle = cubic_point(&segments[k - 1], 0.5);
            let w_middle = 0.5 * (column.w[k - 1] + column.w[k]);
            column.positions.insert(k, middle);
            column.w.insert(k, w_middle);
        }
    })
}

/// Deletes layer `layer` (1 ≤ layer ≤ n) of `bundles` and every bundle sharing their
/// columns at that height; the layers above move down by one.
pub fn delete_layer(
    mesh: &HairMesh,
    bundles: &[u32],
    layer: u32,
) -> Result<EditOutcome, EditError> {
    edit_layer(mesh, bundles, layer, -1, |column, k| {
        if column.positions.len() > k {
            column.positions.remove(k);
            column.w.remove(k);
        }
    })
}

/// What inserting and deleting a layer share: the checks, the spread over shared columns
/// ([`layer_closure`]), `edit_column` on each of their columns at layer `k`, and the layer
/// counts changed by `layer_change`.
fn edit_layer(
    mesh: &HairMesh,
    bundles: &[u32],
    layer: u32,
    layer_change: i32,
    edit_column: impl Fn(&mut Column, usize),
) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    check_layer(mesh, bundles, layer)?;
    let affected = layer_closure(mesh, bundles, layer as usize);
    let mut out = mesh.clone();
    let columns: BTreeSet<u32> = affected
        .iter()
        .flat_map(|&b| mesh.bundles[b as usize].vertices.iter().copied())
        .collect();
    for &c in &columns {
        edit_column(&mut out.columns[c as usize], layer as usize);
    }
    // Locked vertices move with their layer: up one above an inserted layer, down one above
    // a deleted one, and a deleted vertex's lock goes with it.
    let edited = |c: u32| {
        columns.contains(&c)
            && out.columns[c as usize].positions.len() != mesh.columns[c as usize].positions.len()
    };
    let locked: Vec<VertexRef> = mesh
        .locked
        .iter()
        .filter_map(|&v| {
            if !edited(v.column) || v.layer < layer {
                Some(v)
            } else if layer_change > 0 {
                Some(VertexRef {
                    layer: v.layer + 1,
                    ..v
                })
            } else if v.layer == layer {
                None
            } else {
                Some(VertexRef {
                    layer: v.layer - 1,
                    ..v
                })
            }
        })
        .collect();
    // Shifting a column's locks above one layer keeps the list sorted.
    out.locked = locked;
    for &b in &affected {
        let bundle = &mut out.bundles[b as usize];
        bundle.layers = bundle.layers.saturating_add_signed(layer_change);
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

/// Deletes bundles for good (unlike [`set_removed`], nothing is kept to restore): their
/// root faces leave the scalp — the body keeps them — columns no remaining bundle uses go,
/// and every column shortens to its tallest remaining bundle. What is left is renumbered in
/// order; `affected_bundles` lists the survivors' new indices. Deleting every bundle is
/// refused (a scalp with no face has nothing to grow on).
pub fn delete_bundles(mesh: &HairMesh, bundles: &[u32]) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    let gone: BTreeSet<u32> = bundles.iter().copied().collect();
    if gone.len() == mesh.bundles.len() {
        return Err(EditError::NothingLeft);
    }
    let mut remap = vec![u32::MAX; mesh.columns.len()];
    let mut out = HairMesh {
        bundles: Vec::with_capacity(mesh.bundles.len() - gone.len()),
        columns: Vec::new(),
        w_mode: mesh.w_mode,
        locked: Vec::new(),
    };
    for (index, bundle) in mesh.bundles.iter().enumerate() {
        if gone.contains(&(index as u32)) {
            continue;
        }
        let mut kept = bundle.clone();
        for v in &mut kept.vertices {
            let column = &mut remap[*v as usize];
            if *column == u32::MAX {
                *column = out.columns.len() as u32;
                out.columns.push(mesh.columns[*v as usize].clone());
            }
            *v = *column;
        }
        out.bundles.push(kept);
    }
    let topology = Topology::build(&out);
    for (c, column) in out.columns.iter_mut().enumerate() {
        let length = 1 + topology.bundles_of_column[c]
            .iter()
            .map(|&b| out.bundles[b as usize].layers as usize)
            .max()
            .unwrap_or(0);
        column.positions.truncate(length);
        column.w.truncate(length);
    }
    out.locked = mesh
        .locked
        .iter()
        .filter_map(|v| {
            let column = remap[v.column as usize];
            (column != u32::MAX).then_some(VertexRef {
                column,
                layer: v.layer,
            })
        })
        .collect();
    out.locked.sort();
    let survivors = (0..out.bundles.len() as u32).collect();
    finish(out, survivors, None)
}

/// The new index of each of `count` bundles after [`delete_bundles`] deleted `gone`
/// (`None` for a deleted one): survivors keep their order.
pub fn bundle_renumbering(count: usize, gone: &[u32]) -> Vec<Option<u32>> {
    let gone: BTreeSet<u32> = gone.iter().copied().collect();
    let mut next = 0;
    (0..count as u32)
        .map(|b| {
            (!gone.contains(&b)).then(|| {
                next += 1;
                next - 1
            })
        })
        .collect()
}

/// Sets the fraction of strands the selected bundles grow (`Bundle::density`, `[0, 1]`;
/// anything else is refused with the bundle's field named). Geometry is untouched.
pub fn set_density(
    mesh: &HairMesh,
    bundles: &[u32],
    density: f64,
) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    let mut out = mesh.clone();
    for &b in bundles {
        out.bundles[b as usize].density = density;
    }
    finish(out, bundles.iter().copied().collect(), Some(&[]))
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
            density: bundle.density,
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
