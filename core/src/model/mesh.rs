//! The hair mesh: a scalp (root layer) of quads and triangles, each face extruded into a
//! bundle of layers, each root vertex owning a column of vertices (seed 000 §2.2).
//!
//! This module holds the data and the structural invariants (`validate`). Edits live in
//! [`crate::edit`], interior-vertex placement in [`crate::geometry::interior`].
//!
//! # Vocabulary
//! - *layer* `k`: `0` is the root layer (the scalp); layer `k ≥ 1` is the k-th extrusion.
//! - *bundle*: one root face and its layers. A bundle with `layers = n` uses layers `0..=n`
//!   of each of its corner columns. `n = 0` is a bare scalp face that grows no hair.
//! - *column*: the vertices of one root vertex on successive layers. A column is exactly as
//!   long as its tallest adjacent bundle (removed bundles included, so that restoring a
//!   bundle never needs data that was thrown away).
//! - *exterior / interior*: see [`HairMesh::is_interior`].

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

/// One root face and the bundle extruded from it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bundle {
    /// Column (root vertex) indices, counter-clockwise seen from outside: 3 or 4 entries.
    pub vertices: Vec<u32>,
    /// Styling uv of each face corner (same length as `vertices`). Per corner, so that a
    /// root vertex on a uv seam can have several uv values.
    pub uvs: Vec<DVec2>,
    /// Number of extruded layers above the root.
    pub layers: u32,
    /// A removed bundle keeps its geometry (restoring it is lossless) but grows no hair
    /// and does not count as part of the hair volume.
    #[serde(default, skip_serializing_if = "is_false")]
    pub removed: bool,
    /// The fraction of the bundle's strands that grow, in `[0, 1]`: below 1 at a hairline,
    /// so hair thins out over it instead of ending at a hard edge. The runtime draws the
    /// first `⌈density · N⌉` of its `N` progressive root samples (an even, sparser cover).
    #[serde(default = "full_density", skip_serializing_if = "is_full_density")]
    pub density: f64,
}

fn is_false(value: &bool) -> bool {
    !*value
}

fn full_density() -> f64 {
    1.0
}

fn is_full_density(density: &f64) -> bool {
    *density == 1.0
}

impl Bundle {
    /// Number of corners: 3 (triangle) or 4 (quad).
    pub fn corner_count(&self) -> usize {
        self.vertices.len()
    }

    /// Whether this bundle is part of the hair volume at layer `layer`.
    pub fn reaches(&self, layer: usize) -> bool {
        !self.removed && self.layers as usize >= layer
    }
}

/// The vertices of one root vertex on successive layers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Column {
    /// Object-space position per layer; index 0 is the root (scalp) vertex.
    pub positions: Vec<DVec3>,
    /// Styling coordinate w per layer; `w[0] == 0`, non-decreasing toward the tip.
    pub w: Vec<f64>,
}

/// How the styling coordinate w is maintained.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WMode {
    /// w is the polyline length from the root along the column, in model units, recomputed
    /// after every edit, so styling frequencies mean "per model unit" (per metre for the
    /// bundled samples).
    #[default]
    FromPathLength,
    /// w was edited by the user and is kept as it is; new vertices get w interpolated or
    /// extrapolated from their column.
    Manual,
}

/// A vertex of the hair mesh: a column and a layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct VertexRef {
    pub column: u32,
    pub layer: u32,
}

/// The hair mesh document data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HairMesh {
    pub bundles: Vec<Bundle>,
    pub columns: Vec<Column>,
    #[serde(default)]
    pub w_mode: WMode,
    /// Vertices the artist placed (or a drape settled) that automatic interior placement
    /// leaves where they are: a locked interior vertex is a known value of its layer's
    /// placement, like an exterior one, and a drape holds locked vertices still. Sorted, no
    /// repeats.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub locked: Vec<VertexRef>,
}

/// A structural problem, with the path of the offending value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct InvalidMesh {
    /// JSON-style path below the hair mesh, such as `bundles[3].vertices[1]`.
    pub path: String,
    pub message: String,
}

fn invalid(path: impl Into<String>, message: impl Into<String>) -> InvalidMesh {
    InvalidMesh {
        path: path.into(),
        message: message.into(),
    }
}

/// Adjacency derived from a [`HairMesh`]; rebuilt after topology edits (it is cheap).
#[derive(Clone, Debug, Default)]
pub struct Topology {
    /// For each column, the bundles that use it (ascending).
    pub bundles_of_column: Vec<Vec<u32>>,
    /// For each column, whether its root vertex lies on the boundary of the root mesh
    /// formed by the *active* (not removed) bundles, or is used by no active bundle.
    pub root_boundary: Vec<bool>,
}

impl Topology {
    pub fn build(mesh: &HairMesh) -> Self {
        let column_count = mesh.columns.len();
        let mut bundles_of_column = vec![Vec::new(); column_count];
        // Directed edge counts tell boundary edges: an interior edge is used once in each
        // direction by two consistently oriented faces.
        let mut edge_uses: std::collections::HashMap<(u32, u32), u32> =
            std::collections::HashMap::new();
        for (bundle_index, bundle) in mesh.bundles.iter().enumerate() {
            for &v in &bundle.vertices {
                if let Some(list) = bundles_of_column.get_mut(v as usize) {
                    list.push(bundle_index as u32);
                }
            }
            if bundle.removed {
                continue;
            }
            let n = bundle.vertices.len();
            for i in 0..n {
                let a = bundle.vertices[i];
                let b = bundle.vertices[(i + 1) % n];
                *edge_uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let mut root_boundary = vec![true; column_count];
        let mut has_active = vec![false; column_count];
        for bundle in mesh.bundles.iter().filter(|b| !b.removed) {
            for &v in &bundle.vertices {
                if let Some(flag) = has_active.get_mut(v as usize) {
                    *flag = true;
                }
            }
        }
        for (column, flag) in root_boundary.iter_mut().enumerate() {
            *flag = !has_active[column];
        }
        for ((a, b), uses) in &edge_uses {
            if *uses != 2 {
                for v in [a, b] {
                    if let Some(flag) = root_boundary.get_mut(*v as usize) {
                        *flag = true;
                    }
                }
            }
        }
        Self {
            bundles_of_column,
            root_boundary,
        }
    }
}

impl HairMesh {
    /// An empty mesh: no bundles, no columns.
    pub fn empty() -> Self {
        Self {
            bundles: Vec::new(),
            columns: Vec::new(),
            w_mode: WMode::FromPathLength,
            locked: Vec::new(),
        }
    }

    /// A scalp with no extrusions: one column per root vertex, one bundle per face.
    /// Faces must have 3 or 4 corners; `uvs` is per face corner.
    pub fn from_scalp(positions: &[DVec3], faces: &[Vec<u32>], uvs: &[Vec<DVec2>]) -> Self {
        let columns = positions
            .iter()
            .map(|&p| Column {
                positions: vec![p],
                w: vec![0.0],
            })
            .collect();
        let bundles = faces
            .iter()
            .zip(uvs)
            .map(|(face, uv)| Bundle {
                vertices: face.clone(),
                uvs: uv.clone(),
                layers: 0,
                removed: false,
                density: 1.0,
            })
            .collect();
        Self {
            bundles,
            columns,
            w_mode: WMode::FromPathLength,
            locked: Vec::new(),
        }
    }

    pub fn position(&self, vertex: VertexRef) -> Option<DVec3> {
        self.columns
            .get(vertex.column as usize)?
            .positions
            .get(vertex.layer as usize)
            .copied()
    }

    /// Axis-aligned bounds `(min, max)` of every vertex; `None` for an empty mesh.
    /// The area of the root face of the bundle with corners `vertices` (its root positions;
    /// a quad as two triangles split along 0-2), model units squared; 0 where a corner's
    /// column is missing or empty.
    pub fn root_face_area(&self, vertices: &[u32]) -> f64 {
        let root = |i: usize| {
            self.columns
                .get(*vertices.get(i)? as usize)?
                .positions
                .first()
                .copied()
        };
        let triangle = |a: usize, b: usize, c: usize| -> Option<f64> {
            let (a, b, c) = (root(a)?, root(b)?, root(c)?);
            Some(0.5 * (b - a).cross(c - a).length())
        };
        let area = match vertices.len() {
            3 => triangle(0, 1, 2),
            4 => triangle(0, 1, 2).zip(triangle(0, 2, 3)).map(|(a, b)| a + b),
            _ => None,
        };
        area.filter(|a| a.is_finite()).unwrap_or(0.0)
    }

    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let mut points = self
            .columns
            .iter()
            .flat_map(|c| c.positions.iter().copied());
        let first = points.next()?;
        Some(points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// Length of the bounds' diagonal (0 for an empty mesh).
    pub fn size(&self) -> f64 {
        self.bounds()
            .map(|(lo, hi)| (hi - lo).length())
            .unwrap_or(0.0)
    }

    /// Number of vertices over all columns and layers.
    pub fn vertex_count(&self) -> usize {
        self.columns.iter().map(|c| c.positions.len()).sum()
    }

    /// Highest layer index used by any bundle.
    pub fn max_layers(&self) -> usize {
        self.bundles
            .iter()
            .map(|b| b.layers as usize)
            .max()
            .unwrap_or(0)
    }

    /// The length a column must have: one more than its tallest adjacent bundle.
    pub fn required_column_len(&self, topology: &Topology, column: usize) -> usize {
        1 + topology.bundles_of_column[column]
            .iter()
            .map(|&b| self.bundles[b as usize].layers as usize)
            .max()
            .unwrap_or(0)
    }

    /// Whether vertex (`column`, `layer`) is *interior*, i.e. hidden inside the hair volume.
    ///
    /// Definition: a vertex on layer `k ≥ 1` is interior when its root vertex is not on the
    /// boundary of the active root mesh and every bundle around the column is active and
    /// continues past layer `k` (`layers > k`). Then the vertex is surrounded on layer `k`
    /// by a closed fan of bundle cross-sections, and on layers `k − 1` and `k + 1` by the
    /// same bundles, so it lies on no side wall and no tip cap. Every other vertex is
    /// *exterior*: root-layer vertices (the scalp), vertices on the side walls of the volume
    /// (next to a removed or shorter bundle, or on the scalp's rim) and tip-cap vertices.
    /// Exterior vertices are placed by the user; interior ones by [`crate::geometry::interior`].
    pub fn is_interior(&self, topology: &Topology, column: usize, layer: usize) -> bool {
        if layer == 0 || topology.root_boundary[column] {
            return false;
        }
        topology.bundles_of_column[column].iter().all(|&b| {
            let bundle = &self.bundles[b as usize];
            !bundle.removed && bundle.layers as usize > layer
        })
    }

    /// Checks every structural invariant; returns the first violation with its path.
    pub fn validate(&self) -> Result<(), InvalidMesh> {
        let column_count = self.columns.len();
        if column_count > u32::MAX as usize {
            return Err(invalid("columns", "more columns than u32 can index"));
        }
        for (bi, bundle) in self.bundles.iter().enumerate() {
            let n = bundle.vertices.len();
            if n != 3 && n != 4 {
                return Err(invalid(
                    format!("bundles[{bi}].vertices"),
                    format!("a bundle must have 3 or 4 corners, found {n}"),
                ));
            }
            let cap = crate::runtime::textures::MAX_LAYERS_PER_BUNDLE;
            if bundle.layers > cap {
                return Err(invalid(
                    format!("bundles[{bi}].layers"),
                    format!(
                        "{} layers is above the cap of {cap} layers per bundle",
                        bundle.layers
                    ),
                ));
            }
            if !(0.0..=1.0).contains(&bundle.density) {
                return Err(invalid(
                    format!("bundles[{bi}].density"),
                    format!(
                        "density {} is outside [0, 1] (the fraction of strands that grow)",
                        bundle.density
                    ),
                ));
            }
            if bundle.uvs.len() != n {
                return Err(invalid(
                    format!("bundles[{bi}].uvs"),
                    format!("{} uv values for {n} corners", bundle.uvs.len()),
                ));
            }
            for (ci, &v) in bundle.vertices.iter().enumerate() {
                if v as usize >= column_count {
                    return Err(invalid(
                        format!("bundles[{bi}].vertices[{ci}]"),
                        format!("vertex index {v} out of range ({column_count} columns)"),
                    ));
                }
                if bundle.vertices[..ci].contains(&v) {
                    return Err(invalid(
                        format!("bundles[{bi}].vertices[{ci}]"),
                        format!("vertex {v} appears twice in one bundle"),
                    ));
                }
            }
            for (ci, uv) in bundle.uvs.iter().enumerate() {
                if !uv.is_finite() {
                    return Err(invalid(
                        format!("bundles[{bi}].uvs[{ci}]"),
                        "uv is not finite",
                    ));
                }
            }
        }
        let topology = Topology::build(self);
        for (column_index, column) in self.columns.iter().enumerate() {
            let path = format!("columns[{column_index}]");
            if topology.bundles_of_column[column_index].is_empty() {
                return Err(invalid(path, "column is used by no bundle"));
            }
            let required = self.required_column_len(&topology, column_index);
            if column.positions.len() != required {
                return Err(invalid(
                    format!("{path}.positions"),
                    format!(
                        "column has {} layers of positions but its tallest bundle needs {required}",
                        column.positions.len()
                    ),
                ));
            }
            if column.w.len() != column.positions.len() {
                return Err(invalid(
                    format!("{path}.w"),
                    format!(
                        "{} w values for {} positions",
                        column.w.len(),
                        column.positions.len()
                    ),
                ));
            }
            for (layer, p) in column.positions.iter().enumerate() {
                if !p.is_finite() {
                    return Err(invalid(
                        format!("{path}.positions[{layer}]"),
                        "position is not finite",
                    ));
                }
            }
            for (layer, w) in column.w.iter().enumerate() {
                if !w.is_finite() {
                    return Err(invalid(format!("{path}.w[{layer}]"), "w is not finite"));
                }
                if layer == 0 && *w != 0.0 {
                    return Err(invalid(
                        format!("{path}.w[0]"),
                        format!("w must be 0 at the root, found {w}"),
                    ));
                }
                if layer > 0 && *w < column.w[layer - 1] {
                    return Err(invalid(
                        format!("{path}.w[{layer}]"),
                        format!(
                            "w decreases toward the tip ({} after {})",
                            w,
                            column.w[layer - 1]
                        ),
                    ));
                }
            }
        }
        for (i, v) in self.locked.iter().enumerate() {
            let layers = self
                .columns
                .get(v.column as usize)
                .map(|c| c.positions.len());
            if layers.is_none_or(|n| v.layer as usize >= n) {
                return Err(invalid(
                    format!("locked[{i}]"),
                    format!(
                        "vertex (column {}, layer {}) is not in the mesh",
                        v.column, v.layer
                    ),
                ));
            }
            if i > 0 && self.locked[i - 1] >= *v {
                return Err(invalid(
                    format!("locked[{i}]"),
                    "locked vertices must be sorted by column and layer, without repeats",
                ));
            }
        }
        Ok(())
    }

    /// Whether automatic placement keeps this vertex where it is (see [`HairMesh::locked`]).
    pub fn is_locked(&self, column: usize, layer: usize) -> bool {
        let (Ok(column), Ok(layer)) = (u32::try_from(column), u32::try_from(layer)) else {
            return false;
        };
        self.locked
            .binary_search(&VertexRef { column, layer })
            .is_ok()
    }

    /// Locks (or unlocks) `vertices`, keeping [`HairMesh::locked`] sorted without repeats.
    /// Vertices the mesh does not have are left out.
    pub fn set_locked(&mut self, vertices: &[VertexRef], locked: bool) {
        let mut set: std::collections::BTreeSet<VertexRef> = self.locked.iter().copied().collect();
        for v in vertices.iter().filter(|v| self.position(**v).is_some()) {
            if locked {
                set.insert(*v);
            } else {
                set.remove(v);
            }
        }
        self.locked = set.into_iter().collect();
    }

    /// Recomputes w of every column from polyline length when `w_mode` asks for it.
    pub fn update_w(&mut self) {
        if self.w_mode != WMode::FromPathLength {
            return;
        }
        for column in &mut self.columns {
            column.w = path_length_w(&column.positions);
        }
    }

    /// Counts for `hairloom info`.
    pub fn stats(&self) -> MeshStats {
        let topology = Topology::build(self);
        let mut interior = 0;
        for (c, column) in self.columns.iter().enumerate() {
            for k in 0..column.positions.len() {
                if self.is_interior(&topology, c, k) {
                    interior += 1;
                }
            }
        }
        MeshStats {
            root_faces: self.bundles.len(),
            quads: self
                .bundles
                .iter()
                .filter(|b| b.vertices.len() == 4)
                .count(),
            triangles: self
                .bundles
                .iter()
                .filter(|b| b.vertices.len() == 3)
                .count(),
            removed_bundles: self.bundles.iter().filter(|b| b.removed).count(),
            hair_bundles: self
                .bundles
                .iter()
                .filter(|b| !b.removed && b.layers > 0)
                .count(),
            root_vertices: self.columns.len(),
            vertices: self.vertex_count(),
            interior_vertices: interior,
            max_layers: self.max_layers(),
            min_layers: self
                .bundles
                .iter()
                .filter(|b| !b.removed)
                .map(|b| b.layers as usize)
                .min()
                .unwrap_or(0),
        }
    }
}

/// Cumulative polyline length along a column, starting at 0.
pub(crate) fn path_length_w(positions: &[DVec3]) -> Vec<f64> {
    let mut w = Vec::with_capacity(positions.len());
    let mut total = 0.0;
    for (i, p) in positions.iter().enumerate() {
        if i > 0 {
            total += p.distance(positions[i - 1]);
        }
        w.push(total);
    }
    w
}

/// Counts describing a hair mesh.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct MeshStats {
    pub root_faces: usize,
    pub quads: usize,
    pub triangles: usize,
    pub removed_bundles: usize,
    pub hair_bundles: usize,
    pub root_vertices: usize,
    pub vertices: usize,
    pub interior_vertices: usize,
    pub min_layers: usize,
    pub max_layers: usize,
}

#[cfg(test)]
pub(crate) mod test_meshes {
    use super::*;

    /// A `nx × ny` grid of unit quads in the xy plane with uv = position / size, extruded
    /// `layers` times along +z by `step`.
    pub fn grid(nx: usize, ny: usize, layers: u32, step: f64) -> HairMesh {
        let scalp = crate::samples::grid_scalp(nx, ny, |s, t| {
            DVec3::new(s * nx as f64, t * ny as f64, 0.0)
        });
        crate::samples::straight_layers(scalp, layers, DVec3::Z * step)
    }
}

#[cfg(test)]
mod tests {
    use super::test_meshes::grid;
    use super::*;

    #[test]
    fn grid_is_valid_and_interior_is_the_inner_block() {
        let mesh = grid(4, 4, 3, 0.5);
        mesh.validate().expect("valid grid");
        let topology = Topology::build(&mesh);
        // Inner 3×3 root vertices are interior on layers 1 and 2, never on 0 or the tip (3).
        let interior: Vec<_> = (0..mesh.columns.len())
            .filter(|&c| mesh.is_interior(&topology, c, 1))
            .collect();
        assert_eq!(interior.len(), 9);
        assert!((0..mesh.columns.len()).all(|c| !mesh.is_interior(&topology, c, 3)));
        assert!((0..mesh.columns.len()).all(|c| !mesh.is_interior(&topology, c, 0)));
        assert_eq!(mesh.stats().interior_vertices, 18);
    }

    #[test]
    fn removed_bundle_exposes_its_vertices() {
        let mut mesh = grid(4, 4, 3, 0.5);
        let center = 2 * 5 + 2;
        let topology = Topology::build(&mesh);
        assert!(mesh.is_interior(&topology, center, 1));
        mesh.bundles[5].removed = true; // bundle (1,1) touches the centre vertex
        let topology = Topology::build(&mesh);
        assert!(!mesh.is_interior(&topology, center, 1));
    }

    #[test]
    fn validate_names_the_problem() {
        let mut mesh = grid(2, 2, 1, 1.0);
        mesh.bundles[1].vertices[2] = 99;
        let error = mesh.validate().expect_err("out of range");
        assert_eq!(error.path, "bundles[1].vertices[2]");
        assert!(error.message.contains("out of range"), "{error}");

        let mut mesh = grid(2, 2, 1, 1.0);
        mesh.columns[4].positions[1].y = f64::NAN;
        assert_eq!(
            mesh.validate().expect_err("nan").path,
            "columns[4].positions[1]"
        );

        for density in [1.5, -0.1, f64::NAN] {
            let mut mesh = grid(2, 2, 1, 1.0);
            mesh.bundles[3].density = density;
            let error = mesh.validate().expect_err("density out of range");
            assert_eq!(error.path, "bundles[3].density");
            assert!(error.message.contains("[0, 1]"), "{error}");
        }

        let mut mesh = grid(2, 2, 1, 1.0);
        mesh.columns[0].positions.push(DVec3::ZERO);
        mesh.columns[0].w.push(9.0);
        assert_eq!(
            mesh.validate().expect_err("too long").path,
            "columns[0].positions"
        );
    }
}
