//! Layout of the root layer on the root slice of the runtime textures (seed 000 §3.1).
//!
//! Every bundle that grows hair (not removed, at least one layer) gets a 2×2 texel *block*:
//! block corner `b` (0: (0,0), 1: (1,0), 2: (1,1), 3: (0,1) in texel offsets) holds bundle
//! corner [`BundleBlock::corner_of_block`]`[b]`. Sampling the block at texel coordinates
//! `origin + 0.5 + (s, t)` with `(s, t) ∈ [0,1]²` returns the bilinear blend of the four
//! corners with weights `(1−s)(1−t), s(1−t), st, (1−s)t` — what texture filtering does.
//!
//! Charts of quads share texels: neighbouring blocks share the two texels of their common
//! edge when both sides hold the same column with the same corner uv, so an `m × n` patch of
//! quads that meet four at a vertex takes `(m+1) × (n+1)` texels instead of `4mn`, and a
//! chart may have any shape (it follows the scalp's quads round irregular vertices until a
//! texel would need two contents). Triangles take a block whose corner 3 repeats corner 2.
//! Charts are packed bottom-left on a texel bitmap (see [`build_atlas`]).

use std::collections::HashMap;

use glam::DVec2;
use serde::{Deserialize, Serialize};

use crate::model::mesh::HairMesh;

/// Where one bundle sits on the root slice.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BundleBlock {
    pub bundle: u32,
    /// Texel of block corner 0.
    pub origin: [u32; 2],
    /// Bundle corner index held by each block corner (for a triangle, corners 2 and 3 hold
    /// the same bundle corner).
    pub corner_of_block: [u8; 4],
    pub layers: u32,
}

/// What a texel of the root slice holds: a column and the uv of the face corner there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelSource {
    pub column: u32,
    pub uv: DVec2,
}

/// The root-slice layout of a hair mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Atlas {
    pub width: u32,
    pub height: u32,
    pub blocks: Vec<BundleBlock>,
    /// Row-major `width × height`; `None` for unused texels.
    pub texels: Vec<Option<TexelSource>>,
}

impl Atlas {
    /// Number of texels in use (≈ hair-mesh vertices on the root layer, plus duplicates
    /// where regions meet or triangles sit).
    pub fn used_texels(&self) -> usize {
        self.texels.iter().filter(|t| t.is_some()).count()
    }

    pub fn block_of(&self, bundle: u32) -> Option<&BundleBlock> {
        self.blocks.iter().find(|b| b.bundle == bundle)
    }

    /// Block coordinates of the point at bundle-corner coordinates `(s, t)` (the coordinates
    /// root samples are given in): the block's rotation `r = corner_of_block[0]` applied as
    /// `r` quarter turns `(s, t) ↦ (t, 1 − s)`. Triangles are never rotated.
    pub fn block_coords(block: &BundleBlock, s: f64, t: f64) -> (f64, f64) {
        let (mut s, mut t) = (s, t);
        if block.corner_of_block[3] != block.corner_of_block[2] {
            for _ in 0..block.corner_of_block[0] {
                (s, t) = (t, 1.0 - s);
            }
        }
        (s, t)
    }

    /// Whether the block holds a triangle (its corners 2 and 3 are the same face corner).
    pub fn is_triangle(block: &BundleBlock) -> bool {
        block.corner_of_block[2] == block.corner_of_block[3]
    }

    /// Block coordinates of a root sample as the manifest's sample sets give it: bundle-corner
    /// coordinates for quads ([`Atlas::block_coords`]), barycentric for triangles
    /// ([`crate::strands::roots::triangle_to_block`]).
    pub fn sample_block_coords(block: &BundleBlock, sample: DVec2) -> (f64, f64) {
        if Self::is_triangle(block) {
            let q = crate::strands::roots::triangle_to_block(sample);
            (q.x, q.y)
        } else {
            Self::block_coords(block, sample.x, sample.y)
        }
    }

    /// Bundle-corner weights for block coordinates `(s, t)`: the contract between the
    /// texture path and the reference evaluator.
    pub fn corner_weights(block: &BundleBlock, s: f64, t: f64) -> [f64; 4] {
        let block_weights = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
        let mut weights = [0.0; 4];
        for b in 0..4 {
            weights[block.corner_of_block[b] as usize] += block_weights[b];
        }
        weights
    }
}

/// A connected set of bundles laid out on the texel grid. Neighbouring cells share the
/// texels of their common edge, so a chart of `n` quads that meet four at a vertex takes
/// about `n` texels instead of `4n`.
#[derive(Clone)]
struct Chart {
    /// Cell (block origin relative to the chart's corner), bundle and rotation.
    cells: Vec<([u32; 2], u32, u8)>,
    triangle: bool,
    /// Texels the chart's blocks use, relative to the chart's corner, with what they hold.
    texels: Vec<([u32; 2], TexelSource)>,
    /// Texel extent of the chart.
    size: [u32; 2],
}

/// Texel offsets of block corners 0-3.
pub const BLOCK_CORNER_OFFSETS: [[i32; 2]; 4] = [[0, 0], [1, 0], [1, 1], [0, 1]];

impl BundleBlock {
    /// The texel `(x, y)` of each block corner (origin + [`BLOCK_CORNER_OFFSETS`]).
    pub fn corner_texels(&self) -> [(u32, u32); 4] {
        BLOCK_CORNER_OFFSETS
            .map(|[dx, dy]| (self.origin[0] + dx as u32, self.origin[1] + dy as u32))
    }
}
/// Cell step across block edge `e` (from block corner `e` to `e + 1`).
const ACROSS_BLOCK_EDGE: [[i32; 2]; 4] = [[0, -1], [1, 0], [0, 1], [-1, 0]];

fn same_source(a: &TexelSource, b: &TexelSource) -> bool {
    a.column == b.column && a.uv == b.uv
}

/// Builds the atlas. `max_region_side` caps a chart's rows and columns of blocks.
///
/// Charts grow breadth-first from the first bundle not yet placed: a neighbour across a
/// block edge joins when its cell is free and each of its four texels is free or already
/// holds the same column with the same uv (so uv seams and irregular vertices start new
/// charts). Charts are then packed bottom-left on a texel bitmap, biggest first; a texel two
/// charts both need with the same content is shared. The width that gives the smallest slice
/// among a few near-square candidates wins.
pub fn build_atlas(mesh: &HairMesh, max_region_side: usize) -> Atlas {
    let active: Vec<bool> = mesh
        .bundles
        .iter()
        .map(|b| !b.removed && b.layers > 0)
        .collect();
    // Directed edge → (bundle, corner index of the edge start).
    let mut edges: HashMap<(u32, u32), (u32, usize)> = HashMap::new();
    for (b, bundle) in mesh.bundles.iter().enumerate() {
        if !active[b] || bundle.vertices.len() != 4 {
            continue;
        }
        for i in 0..4 {
            edges.insert(
                (bundle.vertices[i], bundle.vertices[(i + 1) % 4]),
                (b as u32, i),
            );
        }
    }
    let best = [4usize, 6, 8, 12, 16, 24, 32, 48, 64]
        .into_iter()
        .filter(|&side| side < max_region_side.max(1))
        .chain([max_region_side.max(1)])
        .map(|side| {
            let mut charts = grow_charts(mesh, &active, &edges, side as i32);
            let packed = pack_atlas(&mut charts);
            (charts, packed)
        })
        .min_by_key(|(_, (_, width, height))| {
            (*width as u64 * *height as u64, (*width).max(*height))
        });
    let Some((_, (placed, width, height))) = best else {
        unreachable!("at least one chart side is tried")
    };
    let corner = |r: u8, block_corner: usize| -> usize { (block_corner + r as usize) % 4 };
    let mut texels: Vec<Option<TexelSource>> = vec![None; (width * height) as usize];
    let mut blocks = Vec::new();
    for (chart, origin) in &placed {
        for (p, s) in &chart.texels {
            texels[((origin[1] + p[1]) * width + origin[0] + p[0]) as usize] = Some(*s);
        }
        for &(cell, b, r) in &chart.cells {
            blocks.push(BundleBlock {
                bundle: b,
                origin: [origin[0] + cell[0], origin[1] + cell[1]],
                corner_of_block: if chart.triangle {
                    [0, 1, 2, 2]
                } else {
                    [0, 1, 2, 3].map(|bc| corner(r, bc) as u8)
                },
                layers: mesh.bundles[b as usize].layers,
            });
        }
    }
    blocks.sort_by_key(|b| b.bundle);
    Atlas {
        width,
        height,
        blocks,
        texels,
    }
}

fn grow_charts(
    mesh: &HairMesh,
    active: &[bool],
    edges: &HashMap<(u32, u32), (u32, usize)>,
    max_side: i32,
) -> Vec<Chart> {
    let corner = |r: u8, block_corner: usize| -> usize { (block_corner + r as usize) % 4 };
    let source = |b: u32, r: u8, block_corner: usize| {
        let bundle = &mesh.bundles[b as usize];
        let c = corner(r, block_corner);
        TexelSource {
            column: bundle.vertices[c],
            uv: bundle.uvs[c],
        }
    };
    // The quad across block edge `e` of `(b, r)` and the rotation that puts the shared edge
    // on its opposite block edge.
    let across = |b: u32, r: u8, e: usize| -> Option<(u32, u8)> {
        let from = mesh.bundles[b as usize].vertices[corner(r, e)];
        let to = mesh.bundles[b as usize].vertices[corner(r, (e + 1) % 4)];
        let &(n, i) = edges.get(&(to, from))?;
        // Their corner i is `to`, which sits at their block corner e + 2.
        Some((n, ((i + 4 - (e + 2) % 4) % 4) as u8))
    };
    let mut assigned = vec![false; mesh.bundles.len()];
    let mut charts: Vec<Chart> = Vec::new();
    for start in 0..mesh.bundles.len() {
        if !active[start] || assigned[start] {
            continue;
        }
        assigned[start] = true;
        let start = start as u32;
        if mesh.bundles[start as usize].vertices.len() == 3 {
            let corners = [0usize, 1, 2, 2];
            charts.push(Chart {
                cells: vec![([0, 0], start, 0)],
                triangle: true,
                texels: BLOCK_CORNER_OFFSETS
                    .iter()
                    .zip(corners)
                    .map(|(o, c)| ([o[0] as u32, o[1] as u32], source(start, 0, c)))
                    .collect(),
                size: [2, 2],
            });
            continue;
        }
        let mut cells: HashMap<[i32; 2], (u32, u8)> = HashMap::new();
        let mut texels: HashMap<[i32; 2], TexelSource> = HashMap::new();
        let mut order: Vec<[i32; 2]> = Vec::new();
        let (mut lo, mut hi) = ([0i32; 2], [0i32; 2]);
        let place = |cell: [i32; 2],
                     b: u32,
                     r: u8,
                     cells: &mut HashMap<[i32; 2], (u32, u8)>,
                     texels: &mut HashMap<[i32; 2], TexelSource>,
                     order: &mut Vec<[i32; 2]>| {
            cells.insert(cell, (b, r));
            order.push(cell);
            for (bc, o) in BLOCK_CORNER_OFFSETS.iter().enumerate() {
                texels.insert([cell[0] + o[0], cell[1] + o[1]], source(b, r, bc));
            }
        };
        place([0, 0], start, 0, &mut cells, &mut texels, &mut order);
        // Frontier by Chebyshev distance from the seed, so a chart grows in square rings
        // (squares pack; breadth-first diamonds and long arms leave holes).
        let mut frontier = std::collections::BinaryHeap::new();
        let mut pushed = 0u64;
        let mut push_neighbours =
            |cell: [i32; 2], b: u32, r: u8, frontier: &mut std::collections::BinaryHeap<_>| {
                for (e, step) in ACROSS_BLOCK_EDGE.iter().enumerate() {
                    if let Some((n, nr)) = across(b, r, e) {
                        let target = [cell[0] + step[0], cell[1] + step[1]];
                        let ring = target[0].abs().max(target[1].abs());
                        pushed += 1;
                        frontier.push(std::cmp::Reverse((ring, pushed, target, n, nr)));
                    }
                }
            };
        push_neighbours([0, 0], start, 0, &mut frontier);
        while let Some(std::cmp::Reverse((_, _, target, n, nr))) = frontier.pop() {
            let new_lo = [lo[0].min(target[0]), lo[1].min(target[1])];
            let new_hi = [hi[0].max(target[0]), hi[1].max(target[1])];
            let fits = (0..2).all(|a| new_hi[a] - new_lo[a] < max_side);
            let consistent = || {
                BLOCK_CORNER_OFFSETS.iter().enumerate().all(|(bc, o)| {
                    texels
                        .get(&[target[0] + o[0], target[1] + o[1]])
                        .is_none_or(|held| same_source(held, &source(n, nr, bc)))
                })
            };
            if assigned[n as usize] || cells.contains_key(&target) || !fits || !consistent() {
                continue;
            }
            assigned[n as usize] = true;
            (lo, hi) = (new_lo, new_hi);
            place(target, n, nr, &mut cells, &mut texels, &mut order);
            push_neighbours(target, n, nr, &mut frontier);
        }
        let shift = |p: [i32; 2]| [(p[0] - lo[0]) as u32, (p[1] - lo[1]) as u32];
        let mut chart_texels: Vec<([u32; 2], TexelSource)> =
            texels.iter().map(|(p, s)| (shift(*p), *s)).collect();
        chart_texels.sort_by_key(|(p, _)| (p[1], p[0]));
        charts.push(Chart {
            cells: order
                .iter()
                .map(|cell| {
                    let (b, r) = cells[cell];
                    (shift(*cell), b, r)
                })
                .collect(),
            triangle: false,
            texels: chart_texels,
            size: [(hi[0] - lo[0] + 2) as u32, (hi[1] - lo[1] + 2) as u32],
        });
    }

    charts
}

/// Packs charts (biggest first) at a few near-square widths; the smallest slice wins.
/// Sorts `charts` into packing order and returns their origins, width and height.
fn pack_atlas(charts: &mut [Chart]) -> (Vec<(Chart, [u32; 2])>, u32, u32) {
    charts.sort_by_key(|c| std::cmp::Reverse((c.texels.len(), c.size[1], c.size[0])));
    let used: usize = charts.iter().map(|c| c.texels.len()).sum();
    let widest = charts.iter().map(|c| c.size[0]).max().unwrap_or(2);
    let square = ((used as f64).sqrt().ceil() as u32).max(widest).max(1);
    (0..5)
        .map(|k| (square + square * k / 16).max(widest))
        .map(|width| {
            let (placements, height) = pack_charts(charts, width);
            (placements, width, height)
        })
        .min_by_key(|&(_, width, height)| (width as u64 * height as u64, width.max(height)))
        .unwrap_or((Vec::new(), 1, 1))
}

/// Bottom-left packing of `charts` (in order) on a texel bitmap `width` wide: each chart,
/// in whichever quarter turn sits lowest, goes to the lowest, then leftmost, origin where
/// every texel it uses is free or already holds the same content. Returns the placed charts
/// with their origins, and the height used.
fn pack_charts(charts: &[Chart], width: u32) -> (Vec<(Chart, [u32; 2])>, u32) {
    let width = width as usize;
    let mut grid: Vec<Option<TexelSource>> = Vec::new();
    let mut height = 0usize;
    // Rows below this are full: a search starts here.
    let mut first_open_row = 0usize;
    // Holes deeper than this under the top are not searched: keeps packing linear in the
    // number of charts on big meshes, while the holes a chart leaves are still filled by
    // the smaller charts that come soon after it.
    let window = 2 * charts
        .iter()
        .map(|c| c.size[0].max(c.size[1]) as usize)
        .max()
        .unwrap_or(2);
    let mut placed = Vec::with_capacity(charts.len());
    for chart in charts {
        // The texel that failed last is tried first at the next origin: neighbouring origins
        // usually fail on the same texel, so a big chart is not walked texel by texel.
        let last_failed = std::cell::Cell::new(0usize);
        let fits = |chart: &Chart, grid: &[Option<TexelSource>], x: usize, y: usize| {
            let texel_fits = |(p, s): &([u32; 2], TexelSource)| {
                let i = (y + p[1] as usize) * width + x + p[0] as usize;
                grid.get(i)
                    .copied()
                    .flatten()
                    .is_none_or(|held| same_source(&held, s))
            };
            let first = last_failed.get().min(chart.texels.len().saturating_sub(1));
            if chart.texels.get(first).is_some_and(|t| !texel_fits(t)) {
                return false;
            }
            match chart.texels.iter().position(|t| !texel_fits(t)) {
                Some(failed) => {
                    last_failed.set(failed);
                    false
                }
                None => true,
            }
        };
        let lowest = |chart: &Chart| {
            let w = chart.size[0] as usize;
            if w > width {
                return None;
            }
            let mut y = first_open_row.max(height.saturating_sub(window));
            loop {
                if let Some(x) = (0..=(width - w)).find(|&x| fits(chart, &grid, x, y)) {
                    return Some([x, y]);
                }
                y += 1;
            }
        };
        let turns = if chart.triangle { 1 } else { 4 };
        let (chart, origin) =
            std::iter::successors(Some(chart.clone()), |c| Some(c.quarter_turn()))
                .take(turns)
                .filter_map(|c| lowest(&c).map(|origin| (c, origin)))
                .min_by_key(|(c, o)| (o[1] + c.size[1] as usize, o[1], o[0]))
                .unwrap_or_else(|| unreachable!("the unturned chart fits: width ≥ its width"));
        let h = chart.size[1] as usize;
        if grid.len() < (origin[1] + h) * width {
            grid.resize((origin[1] + h) * width, None);
        }
        for (p, s) in &chart.texels {
            grid[(origin[1] + p[1] as usize) * width + origin[0] + p[0] as usize] = Some(*s);
        }
        height = height.max(origin[1] + h);
        while first_open_row < height
            && grid[first_open_row * width..(first_open_row + 1) * width]
                .iter()
                .all(Option::is_some)
        {
            first_open_row += 1;
        }
        placed.push((chart, [origin[0] as u32, origin[1] as u32]));
    }
    (placed, height.max(1) as u32)
}

impl Chart {
    /// The chart turned a quarter turn counter-clockwise: texel `(x, y)` goes to
    /// `(h − 1 − y, x)`; a block's new corner 0 is its old corner 3, so its rotation grows
    /// by 3 (mod 4).
    fn quarter_turn(&self) -> Chart {
        let [w, h] = self.size;
        Chart {
            cells: self
                .cells
                .iter()
                .map(|&(c, b, r)| ([h - 2 - c[1], c[0]], b, (r + 3) % 4))
                .collect(),
            triangle: self.triangle,
            texels: self
                .texels
                .iter()
                .map(|&(p, s)| ([h - 1 - p[1], p[0]], s))
                .collect(),
            size: [h, w],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    /// Every block's four texels hold its bundle's corners (column and uv), so a texel shared
    /// by several blocks holds what each of them needs; every active bundle has one block.
    fn assert_blocks_see_their_own_corners(mesh: &HairMesh, atlas: &Atlas) {
        let active = mesh
            .bundles
            .iter()
            .filter(|b| !b.removed && b.layers > 0)
            .count();
        assert_eq!(atlas.blocks.len(), active);
        for block in &atlas.blocks {
            let bundle = &mesh.bundles[block.bundle as usize];
            assert_eq!(block.layers, bundle.layers);
            for (bc, offset) in [[0u32, 0u32], [1, 0], [1, 1], [0, 1]].iter().enumerate() {
                let (x, y) = (block.origin[0] + offset[0], block.origin[1] + offset[1]);
                assert!(
                    x < atlas.width && y < atlas.height,
                    "block {block:?} outside"
                );
                let texel = atlas.texels[(y * atlas.width + x) as usize].expect("texel in use");
                let corner = block.corner_of_block[bc] as usize;
                assert_eq!(texel.column, bundle.vertices[corner], "block {block:?}");
                assert_eq!(texel.uv, bundle.uvs[corner], "block {block:?}");
            }
            // Quads are a pure rotation of the bundle's corners (what `block_coords` undoes).
            if !Atlas::is_triangle(block) {
                let r = block.corner_of_block[0];
                assert_eq!(block.corner_of_block, [0, 1, 2, 3].map(|b| (b + r) % 4));
            }
        }
    }

    #[test]
    fn a_grid_shares_texels_and_every_block_sees_its_own_corners() {
        let mesh = grid(6, 4, 2, 0.5);
        let atlas = build_atlas(&mesh, 64);
        // One chart: 7 × 5 texels for 24 quads (instead of 96).
        assert_eq!(atlas.used_texels(), 35);
        assert_eq!(atlas.width * atlas.height, 35);
        assert_blocks_see_their_own_corners(&mesh, &atlas);
        // Charts capped at 2 × 2 blocks still cover the grid, each block seeing its corners
        // (packing lets them share the texels they agree on again).
        let capped = build_atlas(&mesh, 2);
        assert_blocks_see_their_own_corners(&mesh, &capped);
    }

    #[test]
    fn charts_follow_the_scalp_round_irregular_vertices_and_pack_densely() {
        // The head samples' scalp: quads round valence-3 and -5 vertices, uv seams.
        let path = crate::samples::default_sample_path();
        let project = crate::io::project::load(&path).expect("sample loads");
        let mesh = &project.document.hair_mesh;
        let atlas = build_atlas(mesh, 64);
        assert_blocks_see_their_own_corners(mesh, &atlas);
        let root_vertices: std::collections::HashSet<u32> = mesh
            .bundles
            .iter()
            .filter(|b| !b.removed && b.layers > 0)
            .flat_map(|b| b.vertices.iter().copied())
            .collect();
        let used = atlas.used_texels();
        let slice = (atlas.width * atlas.height) as usize;
        // Few duplicates (the earlier rectangle regions used 782 texels for 452 root
        // vertices) and few holes (they filled 79% of a 29×34 slice).
        assert!(
            used * 10 <= root_vertices.len() * 14,
            "{used} texels for {} vertices",
            root_vertices.len()
        );
        assert!(used * 100 >= slice * 85, "{used} of {slice} texels used");
    }

    #[test]
    fn a_quarter_turned_chart_keeps_each_block_on_its_corners() {
        // Turning must move texels and blocks together, whatever the rotation.
        let mesh = grid(3, 2, 1, 0.5);
        let atlas = build_atlas(&mesh, 64);
        let blocks: Vec<_> = atlas
            .blocks
            .iter()
            .map(|b| {
                let r = b.corner_of_block[0];
                (b.origin, b.bundle, r)
            })
            .collect();
        let chart = Chart {
            cells: blocks,
            triangle: false,
            texels: (0..atlas.height)
                .flat_map(|y| (0..atlas.width).map(move |x| [x, y]))
                .filter_map(|[x, y]| {
                    atlas.texels[(y * atlas.width + x) as usize].map(|s| ([x, y], s))
                })
                .collect(),
            size: [atlas.width, atlas.height],
        };
        let mut turned = chart.clone();
        for _ in 0..4 {
            let before = turned.size;
            turned = turned.quarter_turn();
            assert_eq!(turned.size, [before[1], before[0]]);
            let [w, h] = turned.size;
            let mut texels = vec![None; (w * h) as usize];
            for (p, s) in &turned.texels {
                texels[(p[1] * w + p[0]) as usize] = Some(*s);
            }
            let turned_atlas = Atlas {
                width: w,
                height: h,
                blocks: turned
                    .cells
                    .iter()
                    .map(|&(cell, b, r)| BundleBlock {
                        bundle: b,
                        origin: cell,
                        corner_of_block: [0, 1, 2, 3].map(|bc| (bc + r) % 4),
                        layers: 1,
                    })
                    .collect(),
                texels,
            };
            assert_blocks_see_their_own_corners(&mesh, &turned_atlas);
        }
        assert_eq!(turned.size, chart.size);
    }

    #[test]
    fn uv_seams_removed_bundles_and_triangles_get_their_own_blocks() {
        let mut mesh = grid(4, 1, 1, 0.5);
        // A uv seam between bundles 1 and 2.
        for uv in &mut mesh.bundles[2].uvs {
            uv.x += 10.0;
        }
        mesh.bundles[3].removed = true;
        let atlas = build_atlas(&mesh, 64);
        assert_eq!(atlas.blocks.len(), 3);
        assert!(atlas.block_of(3).is_none());
        // Bundles 0-1 share (3 × 2 texels); bundle 2 is alone (2 × 2).
        assert_eq!(atlas.used_texels(), 6 + 4);
        let triangle = HairMesh::from_scalp(
            &[glam::DVec3::ZERO, glam::DVec3::X, glam::DVec3::Y],
            &[vec![0, 1, 2]],
            &[vec![DVec2::ZERO, DVec2::X, DVec2::Y]],
        );
        let mut triangle = triangle;
        triangle.columns.iter_mut().for_each(|c| {
            c.positions.push(c.positions[0] + glam::DVec3::Z);
            c.w.push(1.0);
        });
        triangle.bundles[0].layers = 1;
        let atlas = build_atlas(&triangle, 64);
        assert_eq!(atlas.blocks[0].corner_of_block, [0, 1, 2, 2]);
        let w = Atlas::corner_weights(&atlas.blocks[0], 0.5, 0.5);
        assert_eq!(w, [0.25, 0.25, 0.5, 0.0]);
    }

    #[test]
    fn block_coords_put_the_weight_on_the_same_bundle_corners() {
        for r in 0..4u8 {
            let block = BundleBlock {
                bundle: 0,
                origin: [0, 0],
                corner_of_block: [0, 1, 2, 3].map(|b| (b + r) % 4),
                layers: 1,
            };
            for (s, t) in [(0.2, 0.7), (0.0, 1.0), (0.9, 0.1)] {
                let (bs, bt) = Atlas::block_coords(&block, s, t);
                let weights = Atlas::corner_weights(&block, bs, bt);
                let expected = crate::geometry::curve::FaceCoord { s, t }.weights(4);
                for k in 0..4 {
                    assert!(
                        (weights[k] - expected[k]).abs() < 1e-15,
                        "r {r}: {weights:?} vs {expected:?}"
                    );
                }
            }
        }
    }
}
