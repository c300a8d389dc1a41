//! Selection on the hair mesh: which bundles or exterior vertices fall in a screen region
//! (box, lasso, paint stroke), growing and shrinking a selection, whole layers, and the
//! vertices a move / rotate / scale of selected bundles acts on.
//!
//! Screen positions come from a `project` closure (the editor's camera), so everything here
//! is pure and testable. Interior vertices are never selectable: they place themselves.

use std::collections::BTreeSet;

use glam::DVec3;

use crate::model::mesh::{HairMesh, Topology, VertexRef};

/// A region on the screen, in pixels.
#[derive(Clone, Debug, PartialEq)]
pub enum Region {
    /// An axis-aligned box between two corners (any order).
    Box { a: [f64; 2], b: [f64; 2] },
    /// A closed polygon (even-odd rule).
    Lasso(Vec<[f64; 2]>),
    /// Every point within `radius_px` of a stroke's sample points.
    Paint {
        points: Vec<[f64; 2]>,
        radius_px: f64,
    },
}

impl Region {
    pub fn contains(&self, p: [f64; 2]) -> bool {
        match self {
            Self::Box { a, b } => {
                (a[0].min(b[0])..=a[0].max(b[0])).contains(&p[0])
                    && (a[1].min(b[1])..=a[1].max(b[1])).contains(&p[1])
            }
            Self::Lasso(polygon) => point_in_polygon(p, polygon),
            Self::Paint { points, radius_px } => points.iter().any(|q| {
                let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
                dx * dx + dy * dy <= radius_px * radius_px
            }),
        }
    }
}

/// Even-odd point-in-polygon; fewer than three points contain nothing.
pub fn point_in_polygon(p: [f64; 2], polygon: &[[f64; 2]]) -> bool {
    if polygon.len() < 3 {
        return false;
    }
    let mut inside = false;
    let mut j = polygon.len() - 1;
    for i in 0..polygon.len() {
        let (a, b) = (polygon[i], polygon[j]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// The visible runs of a polyline through `points` (closed: back to the first point), each
/// edge cut into `pieces` and a piece kept when `seen` says its middle is visible: what a
/// depth-tested outline draws. Consecutive visible pieces join into one run.
pub fn visible_runs(
    points: &[DVec3],
    closed: bool,
    pieces: usize,
    seen: impl Fn(DVec3) -> bool,
) -> Vec<Vec<DVec3>> {
    let pieces = pieces.max(1);
    let edges = if closed && points.len() > 2 {
        points.len()
    } else {
        points.len().saturating_sub(1)
    };
    let mut runs: Vec<Vec<DVec3>> = Vec::new();
    let mut open = false;
    for i in 0..edges {
        let (a, b) = (points[i], points[(i + 1) % points.len()]);
        for k in 0..pieces {
            let (t0, t1) = (k as f64 / pieces as f64, (k + 1) as f64 / pieces as f64);
            if seen(a.lerp(b, 0.5 * (t0 + t1))) {
                if !open {
                    runs.push(vec![a.lerp(b, t0)]);
                    open = true;
                }
                if let Some(run) = runs.last_mut() {
                    run.push(a.lerp(b, t1));
                }
            } else {
                open = false;
            }
        }
    }
    runs
}

/// What occludes picking and the viewport's outlines: a coarse screen-space depth buffer of
/// the body, so a click or a region selects (and an outline shows) only what the artist
/// sees (no selecting through the head), unless X-ray is on. Built on the CPU per selection gesture: the head scan's 35K triangles rasterise
/// into a 2-pixel grid in milliseconds, far cheaper than a ray test per vertex.
#[derive(Clone, Debug)]
pub struct DepthMap {
    columns: usize,
    rows: usize,
    cell_px: f64,
    /// Nearest view depth per cell (`INFINITY` where nothing is).
    depth: Vec<f64>,
}

impl DepthMap {
    /// Rasterises `triangles` (model space). `project` maps a point to screen pixels and
    /// view depth (`[x, y, w]`, `None` behind the camera); the screen is `size_px`.
    pub fn rasterize(
        positions: &[[f32; 3]],
        triangles: &[[u32; 3]],
        project: impl Fn(DVec3) -> Option<[f64; 3]>,
        size_px: [f64; 2],
        cell_px: f64,
    ) -> Self {
        let cell_px = cell_px.max(0.5);
        let columns = (size_px[0] / cell_px).ceil().clamp(1.0, 8192.0) as usize;
        let rows = (size_px[1] / cell_px).ceil().clamp(1.0, 8192.0) as usize;
        let mut depth = vec![f64::INFINITY; columns * rows];
        let projected: Vec<Option<[f64; 3]>> = positions
            .iter()
            .map(|p| project(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)))
            .collect();
        for triangle in triangles {
            let corners = triangle.map(|i| projected.get(i as usize).copied().flatten());
            let [Some(a), Some(b), Some(c)] = corners else {
                continue;
            };
            let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            if area.abs() < 1e-12 || [a, b, c].iter().any(|p| p.iter().any(|v| !v.is_finite())) {
                continue;
            }
            let lo_x = (a[0].min(b[0]).min(c[0]) / cell_px).floor().max(0.0) as usize;
            let hi_x = ((a[0].max(b[0]).max(c[0]) / cell_px).ceil() as usize).min(columns);
            let lo_y = (a[1].min(b[1]).min(c[1]) / cell_px).floor().max(0.0) as usize;
            let hi_y = ((a[1].max(b[1]).max(c[1]) / cell_px).ceil() as usize).min(rows);
            for row in lo_y..hi_y {
                for column in lo_x..hi_x {
                    let x = (column as f64 + 0.5) * cell_px;
                    let y = (row as f64 + 0.5) * cell_px;
                    let wa = ((b[0] - x) * (c[1] - y) - (b[1] - y) * (c[0] - x)) / area;
                    let wb = ((c[0] - x) * (a[1] - y) - (c[1] - y) * (a[0] - x)) / area;
                    let wc = 1.0 - wa - wb;
                    if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                        continue;
                    }
                    // 1/w is affine in screen space under perspective.
                    let inverse = wa / a[2] + wb / b[2] + wc / c[2];
                    let w = 1.0 / inverse;
                    let cell = &mut depth[row * columns + column];
                    if w < *cell {
                        *cell = w;
                    }
                }
            }
        }
        Self {
            columns,
            rows,
            cell_px,
            depth,
        }
    }

    /// Whether a point at screen `[x, y]` and view depth `w` is in front of the occluders
    /// (within a tolerance: 1 % of its depth plus 3 mm, so roots on the scalp stay
    /// pickable).
    pub fn visible(&self, [x, y, w]: [f64; 3]) -> bool {
        if x < 0.0 || y < 0.0 {
            return true;
        }
        let (column, row) = ((x / self.cell_px) as usize, (y / self.cell_px) as usize);
        if column >= self.columns || row >= self.rows {
            return true;
        }
        w <= self.depth[row * self.columns + column] * 1.01 + 0.003
    }
}

/// The mean of a bundle's vertices over all its layers (where a click or region "sees" it).
pub fn bundle_centre(mesh: &HairMesh, bundle: u32) -> Option<DVec3> {
    let bundle = mesh.bundles.get(bundle as usize)?;
    let mut sum = DVec3::ZERO;
    let mut count = 0.0;
    for &c in &bundle.vertices {
        let column = mesh.columns.get(c as usize)?;
        for p in column.positions.iter().take(bundle.layers as usize + 1) {
            sum += *p;
            count += 1.0;
        }
    }
    (count > 0.0).then(|| sum / count)
}

/// Visible bundles whose centre projects into `region`.
pub fn bundles_in_region(
    mesh: &HairMesh,
    project: impl Fn(DVec3) -> Option<[f64; 2]>,
    region: &Region,
) -> Vec<u32> {
    (0..mesh.bundles.len() as u32)
        .filter(|&b| !mesh.bundles[b as usize].removed)
        .filter(|&b| {
            bundle_centre(mesh, b)
                .and_then(&project)
                .is_some_and(|p| region.contains(p))
        })
        .collect()
}

/// Every exterior (artist-shaped) vertex of the mesh.
pub fn exterior_vertices(mesh: &HairMesh, topology: &Topology) -> Vec<VertexRef> {
    let mut out = Vec::new();
    for (c, column) in mesh.columns.iter().enumerate() {
        if topology.bundles_of_column[c]
            .iter()
            .all(|&b| mesh.bundles[b as usize].removed)
        {
            continue;
        }
        for layer in 0..column.positions.len() {
            if !mesh.is_interior(topology, c, layer) {
                out.push(VertexRef {
                    column: c as u32,
                    layer: layer as u32,
                });
            }
        }
    }
    out
}

/// Exterior vertices that project into `region`.
pub fn vertices_in_region(
    mesh: &HairMesh,
    topology: &Topology,
    project: impl Fn(DVec3) -> Option<[f64; 2]>,
    region: &Region,
) -> Vec<VertexRef> {
    exterior_vertices(mesh, topology)
        .into_iter()
        .filter(|v| {
            mesh.position(*v)
                .and_then(&project)
                .is_some_and(|p| region.contains(p))
        })
        .collect()
}

/// The exterior vertex projecting nearest to `point`, within `max_px`.
pub fn nearest_vertex(
    mesh: &HairMesh,
    topology: &Topology,
    project: impl Fn(DVec3) -> Option<[f64; 2]>,
    point: [f64; 2],
    max_px: f64,
) -> Option<VertexRef> {
    exterior_vertices(mesh, topology)
        .into_iter()
        .filter_map(|v| {
            let p = project(mesh.position(v)?)?;
            let d = ((p[0] - point[0]).powi(2) + (p[1] - point[1]).powi(2)).sqrt();
            (d <= max_px).then_some((v, d))
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(v, _)| v)
}

/// Bundles sharing a column with a selected bundle, added (visible ones only).
pub fn grow_bundles(
    mesh: &HairMesh,
    topology: &Topology,
    selected: &BTreeSet<u32>,
) -> BTreeSet<u32> {
    let mut out = selected.clone();
    for &b in selected {
        let Some(bundle) = mesh.bundles.get(b as usize) else {
            continue;
        };
        for &c in &bundle.vertices {
            out.extend(
                topology.bundles_of_column[c as usize]
                    .iter()
                    .filter(|&&n| !mesh.bundles[n as usize].removed),
            );
        }
    }
    out
}

/// Selected bundles whose neighbours (bundles sharing a column) are all selected.
pub fn shrink_bundles(
    mesh: &HairMesh,
    topology: &Topology,
    selected: &BTreeSet<u32>,
) -> BTreeSet<u32> {
    selected
        .iter()
        .copied()
        .filter(|&b| {
            mesh.bundles.get(b as usize).is_some_and(|bundle| {
                bundle.vertices.iter().all(|&c| {
                    topology.bundles_of_column[c as usize]
                        .iter()
                        .all(|n| mesh.bundles[*n as usize].removed || selected.contains(n))
                })
            })
        })
        .collect()
}

/// Vertices joined to `v` by an edge: along its column and along its layer's face edges.
pub(crate) fn vertex_neighbours(
    mesh: &HairMesh,
    topology: &Topology,
    v: VertexRef,
) -> Vec<VertexRef> {
    let mut out = Vec::new();
    if v.layer > 0 {
        out.push(VertexRef {
            layer: v.layer - 1,
            ..v
        });
    }
    out.push(VertexRef {
        layer: v.layer + 1,
        ..v
    });
    for &b in &topology.bundles_of_column[v.column as usize] {
        let bundle = &mesh.bundles[b as usize];
        if bundle.removed || bundle.layers < v.layer {
            continue;
        }
        let n = bundle.vertices.len();
        if let Some(i) = bundle.vertices.iter().position(|&c| c == v.column) {
            for j in [(i + 1) % n, (i + n - 1) % n] {
                out.push(VertexRef {
                    column: bundle.vertices[j],
                    layer: v.layer,
                });
            }
        }
    }
    out.retain(|n| mesh.position(*n).is_some());
    out
}

/// Exterior neighbours of the selection, added.
pub fn grow_vertices(
    mesh: &HairMesh,
    topology: &Topology,
    selected: &BTreeSet<VertexRef>,
) -> BTreeSet<VertexRef> {
    let mut out = selected.clone();
    for &v in selected {
        out.extend(
            vertex_neighbours(mesh, topology, v)
                .into_iter()
                .filter(|n| !mesh.is_interior(topology, n.column as usize, n.layer as usize)),
        );
    }
    out
}

/// Selected vertices whose exterior neighbours are all selected.
pub fn shrink_vertices(
    mesh: &HairMesh,
    topology: &Topology,
    selected: &BTreeSet<VertexRef>,
) -> BTreeSet<VertexRef> {
    selected
        .iter()
        .copied()
        .filter(|&v| {
            vertex_neighbours(mesh, topology, v)
                .into_iter()
                .filter(|n| !mesh.is_interior(topology, n.column as usize, n.layer as usize))
                .all(|n| selected.contains(&n))
        })
        .collect()
}

/// The exterior vertices at `layer` of the given bundles (all visible bundles when `None`).
pub fn layer_vertices(
    mesh: &HairMesh,
    topology: &Topology,
    bundles: Option<&BTreeSet<u32>>,
    layer: u32,
) -> BTreeSet<VertexRef> {
    mesh.bundles
        .iter()
        .enumerate()
        .filter(|(b, bundle)| {
            !bundle.removed
                && bundle.layers >= layer
                && bundles.is_none_or(|set| set.contains(&(*b as u32)))
        })
        .flat_map(|(_, bundle)| bundle.vertices.iter().copied())
        .map(|column| VertexRef { column, layer })
        .filter(|v| {
            mesh.position(*v).is_some()
                && !mesh.is_interior(topology, v.column as usize, v.layer as usize)
        })
        .collect()
}

/// Every vertex above the root of `bundles` (layers 1 to each bundle's top), sorted: what
/// Lock, Drape and moving a bundle act on (the scalp stays where the head is).
pub fn bundle_vertices_above_root<'a>(
    mesh: &HairMesh,
    bundles: impl IntoIterator<Item = &'a u32>,
) -> BTreeSet<VertexRef> {
    let mut out = BTreeSet::new();
    for &b in bundles {
        let Some(bundle) = mesh.bundles.get(b as usize) else {
            continue;
        };
        for &column in &bundle.vertices {
            for layer in 1..=bundle.layers {
                let v = VertexRef { column, layer };
                if mesh.position(v).is_some() {
                    out.insert(v);
                }
            }
        }
    }
    out
}

/// What moving the selected bundles moves: their exterior vertices above the root.
pub fn bundle_transform_vertices(
    mesh: &HairMesh,
    topology: &Topology,
    bundles: &BTreeSet<u32>,
) -> Vec<VertexRef> {
    bundle_vertices_above_root(mesh, bundles)
        .into_iter()
        .filter(|v| !mesh.is_interior(topology, v.column as usize, v.layer as usize))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::DepthMap;

    /// An orthographic-like projection for tests: screen = 100·(x, y), depth = z.
    fn project(p: glam::DVec3) -> Option<[f64; 3]> {
        (p.z > 0.0).then_some([100.0 * p.x, 100.0 * p.y, p.z])
    }

    #[test]
    fn the_depth_map_hides_what_is_behind_the_body_only() {
        // A wall at depth 2 covering x, y in [0, 1] (screen [0, 100]).
        let positions = [
            [0.0, 0.0, 2.0],
            [1.0, 0.0, 2.0],
            [1.0, 1.0, 2.0],
            [0.0, 1.0, 2.0],
        ];
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let map = DepthMap::rasterize(&positions, &triangles, project, [200.0, 200.0], 2.0);
        assert!(!map.visible([50.0, 50.0, 3.0]), "behind the wall");
        assert!(map.visible([50.0, 50.0, 1.5]), "in front of it");
        assert!(
            map.visible([50.0, 50.0, 2.01]),
            "on it, within the tolerance"
        );
        assert!(map.visible([150.0, 50.0, 3.0]), "beside it");
        assert!(map.visible([-5.0, 500.0, 3.0]), "off screen");
        // A triangle behind the camera or degenerate is skipped, not a panic.
        let broken = [[0.0, 0.0, -1.0], [1.0, 0.0, 2.0], [f32::NAN, 1.0, 2.0]];
        let map = DepthMap::rasterize(&broken, &[[0, 1, 2], [0, 1, 9]], project, [10.0, 10.0], 2.0);
        assert!(map.visible([5.0, 5.0, 100.0]));
    }

    use super::*;

    #[test]
    fn visible_runs_keep_only_what_is_seen_and_join_across_edges() {
        let square = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        // Everything seen: one run round the whole closed square (4 edges × 2 pieces).
        let all = visible_runs(&square, true, 2, |_| true);
        assert_eq!(all.len(), 1);
        assert_eq!(all[0].len(), 9);
        assert_eq!(all[0][0], all[0][8]);
        // Nothing seen: nothing drawn.
        assert!(visible_runs(&square, true, 4, |_| false).is_empty());
        // An occluder over x > 0.6 hides the right edge and the ends of the two edges
        // touching it: the open polyline splits into two runs.
        let runs = visible_runs(&square, false, 4, |p| p.x < 0.6);
        assert_eq!(runs.len(), 2);
        assert!(runs.iter().flatten().all(|p| p.x <= 0.75 + 1e-12));
        assert_eq!(runs[0][0], square[0]);
        assert_eq!(runs[1].last(), Some(&square[3]));
        // One point or none: no edge.
        assert!(visible_runs(&square[..1], true, 4, |_| true).is_empty());
        assert!(visible_runs(&[], false, 4, |_| true).is_empty());
    }
    use crate::model::mesh::test_meshes::grid;

    /// Looks down the z axis: x, y in model units become pixels ×100.
    fn top_view(p: DVec3) -> Option<[f64; 2]> {
        Some([p.x * 100.0, p.y * 100.0])
    }

    #[test]
    fn regions_contain_what_they_enclose() {
        let square = Region::Lasso(vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]);
        assert!(square.contains([5.0, 5.0]));
        assert!(!square.contains([15.0, 5.0]));
        assert!(!Region::Lasso(vec![[0.0, 0.0], [1.0, 1.0]]).contains([0.5, 0.5]));
        let boxed = Region::Box {
            a: [10.0, 10.0],
            b: [0.0, 0.0],
        };
        assert!(boxed.contains([0.0, 10.0]) && !boxed.contains([-0.1, 5.0]));
        let paint = Region::Paint {
            points: vec![[0.0, 0.0], [20.0, 0.0]],
            radius_px: 3.0,
        };
        assert!(paint.contains([20.0, 2.9]) && !paint.contains([10.0, 3.1]));
        // NaN never lands inside anything.
        assert!(!square.contains([f64::NAN, 5.0]) && !boxed.contains([f64::NAN, 1.0]));
    }

    #[test]
    fn a_box_selects_the_bundles_and_exterior_vertices_it_covers() {
        // 3×3 bundles of 0.5 m with 2 layers; the centre column's layer 1 is interior.
        let mesh = grid(3, 3, 2, 0.5);
        let topology = Topology::build(&mesh);
        let left_column = Region::Box {
            a: [-1.0, -1.0],
            b: [60.0, 400.0],
        };
        let bundles = bundles_in_region(&mesh, top_view, &left_column);
        assert_eq!(bundles, vec![0, 3, 6]);
        let all = Region::Box {
            a: [-1.0, -1.0],
            b: [400.0, 400.0],
        };
        let vertices = vertices_in_region(&mesh, &topology, top_view, &all);
        assert_eq!(vertices.len(), exterior_vertices(&mesh, &topology).len());
        assert!(vertices.iter().all(|v| !mesh.is_interior(
            &topology,
            v.column as usize,
            v.layer as usize
        )));
        assert!(
            vertices.len() < mesh.vertex_count(),
            "interior ones are left out"
        );
    }

    #[test]
    fn grow_then_shrink_returns_to_the_selection() {
        let mesh = grid(5, 5, 1, 0.5);
        let topology = Topology::build(&mesh);
        let centre: BTreeSet<u32> = [12].into();
        let grown = grow_bundles(&mesh, &topology, &centre);
        assert_eq!(grown.len(), 9, "the centre and its 8 neighbours");
        assert_eq!(shrink_bundles(&mesh, &topology, &grown), centre);
        assert!(shrink_bundles(&mesh, &topology, &centre).is_empty());

        let corner = VertexRef {
            column: 0,
            layer: 1,
        };
        let v: BTreeSet<VertexRef> = [corner].into();
        let grown = grow_vertices(&mesh, &topology, &v);
        assert!(grown.len() > 1 && grown.contains(&corner));
        assert!(shrink_vertices(&mesh, &topology, &grown).is_subset(&grown));
    }

    #[test]
    fn a_layer_and_bundle_moves_leave_the_scalp_and_interior_alone() {
        let mesh = grid(3, 3, 3, 0.5);
        let topology = Topology::build(&mesh);
        let layer = layer_vertices(&mesh, &topology, None, 3);
        assert_eq!(layer.len(), 16, "the whole top layer is exterior");
        let middle = layer_vertices(&mesh, &topology, None, 2);
        assert_eq!(
            middle.len(),
            12,
            "the 4 inner columns are interior below the top"
        );
        let moved = bundle_transform_vertices(&mesh, &topology, &[4].into());
        assert!(moved.iter().all(|v| v.layer >= 1));
        assert!(moved.iter().all(|v| !mesh.is_interior(
            &topology,
            v.column as usize,
            v.layer as usize
        )));
        assert_eq!(moved.len(), 4, "the centre bundle's top-layer corners");
        let nearest = nearest_vertex(&mesh, &topology, top_view, [0.0, 0.0], 5.0);
        assert_eq!(nearest.map(|v| v.column), Some(0));
        assert!(nearest_vertex(&mesh, &topology, top_view, [-50.0, 0.0], 5.0).is_none());
    }
}
