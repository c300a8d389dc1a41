//! Layout of the root layer on the root slice of the runtime textures (seed 000 §3.1).
//!
//! Every bundle that grows hair (not removed, at least one layer) gets a 2×2 texel *block*:
//! block corner `b` (0: (0,0), 1: (1,0), 2: (1,1), 3: (0,1) in texel offsets) holds bundle
//! corner [`BundleBlock::corner_of_block`]`[b]`. Sampling the block at texel coordinates
//! `origin + 0.5 + (s, t)` with `(s, t) ∈ [0,1]²` returns the bilinear blend of the four
//! corners with weights `(1−s)(1−t), s(1−t), st, (1−s)t` — what texture filtering does.
//!
//! Grid-like regions of quads share texels: an `m × n` patch of quads that meet four at a
//! vertex with matching corner uv takes `(m+1) × (n+1)` texels instead of `4mn`. Triangles
//! take a block whose corner 3 repeats corner 2. Regions are packed into rows (shelves).

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

/// A rectangle of bundles that share texels: `cells[j][i]` is the bundle and its rotation.
struct Region {
    cells: Vec<Vec<(u32, u8)>>,
    triangle: bool,
}

/// Builds the atlas. `max_region_side` caps region rows and columns (keeps packing easy).
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
    let corner = |r: u8, block_corner: usize| -> usize { (block_corner + r as usize) % 4 };
    let vertex = |b: u32, r: u8, block_corner: usize| {
        mesh.bundles[b as usize].vertices[corner(r, block_corner)]
    };
    let uv =
        |b: u32, r: u8, block_corner: usize| mesh.bundles[b as usize].uvs[corner(r, block_corner)];
    // Neighbour across the block edge from block corner `from` to `to`, with its rotation
    // such that the shared edge is its block edge `from' → to'`.
    let neighbour =
        |b: u32, r: u8, from: usize, to: usize, their_from: usize| -> Option<(u32, u8)> {
            let a = vertex(b, r, from);
            let c = vertex(b, r, to);
            let &(n, i) = edges.get(&(c, a))?;
            // Their corner i is `c`, which must sit at their block corner `their_from`.
            let rotation = ((i + 4 - their_from) % 4) as u8;
            // Shared texels need the same uv on both sides.
            let same_uv = uv(b, r, from).distance(uv(n, rotation, (their_from + 1) % 4)) == 0.0
                && uv(b, r, to).distance(uv(n, rotation, their_from)) == 0.0;
            same_uv.then_some((n, rotation))
        };
    let right_of = |b: u32, r: u8| neighbour(b, r, 1, 2, 3);
    let above = |b: u32, r: u8| neighbour(b, r, 2, 3, 0);

    let mut assigned = vec![false; mesh.bundles.len()];
    let mut regions: Vec<Region> = Vec::new();
    let max_side = max_region_side.max(1);
    for start in 0..mesh.bundles.len() {
        if !active[start] || assigned[start] {
            continue;
        }
        let start = start as u32;
        if mesh.bundles[start as usize].vertices.len() == 3 {
            assigned[start as usize] = true;
            regions.push(Region {
                cells: vec![vec![(start, 0)]],
                triangle: true,
            });
            continue;
        }
        assigned[start as usize] = true;
        let mut row = vec![(start, 0u8)];
        while row.len() < max_side {
            let &(b, r) = row.last().unwrap_or(&(start, 0));
            match right_of(b, r) {
                Some((n, nr)) if !assigned[n as usize] && !row.iter().any(|c| c.0 == n) => {
                    assigned[n as usize] = true;
                    row.push((n, nr));
                }
                _ => break,
            }
        }
        let mut cells = vec![row];
        'rows: while cells.len() < max_side {
            let Some(top) = cells.last() else { break };
            let mut next = Vec::with_capacity(top.len());
            for (i, &(b, r)) in top.iter().enumerate() {
                let Some((n, nr)) = above(b, r) else {
                    break 'rows;
                };
                if assigned[n as usize] || next.iter().any(|c: &(u32, u8)| c.0 == n) {
                    break 'rows;
                }
                // The new row must be a row: each cell the right neighbour of the previous.
                if i > 0 && right_of(next[i - 1].0, next[i - 1].1) != Some((n, nr)) {
                    break 'rows;
                }
                next.push((n, nr));
            }
            for &(n, _) in &next {
                assigned[n as usize] = true;
            }
            cells.push(next);
        }
        regions.push(Region {
            cells,
            triangle: false,
        });
    }

    // Skyline bottom-left packing, tallest first: each region goes where the skyline under
    // it is lowest (leftmost on ties). Width ≈ √area, so the slice stays near square.
    let size = |r: &Region| (r.cells[0].len() as u32 + 1, r.cells.len() as u32 + 1);
    let total: u32 = regions.iter().map(|r| size(r).0 * size(r).1).sum();
    let widest = regions.iter().map(|r| size(r).0).max().unwrap_or(2);
    let width = ((total as f64).sqrt() * 1.02).ceil().max(widest as f64) as u32;
    let mut order: Vec<usize> = (0..regions.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse((size(&regions[i]).1, size(&regions[i]).0)));
    let mut placements = vec![[0u32; 2]; regions.len()];
    let mut skyline = vec![0u32; width as usize];
    for &i in &order {
        let (w, h) = size(&regions[i]);
        let (mut best_x, mut best_y) = (0usize, u32::MAX);
        for x in 0..=(width - w) as usize {
            let y = skyline[x..x + w as usize]
                .iter()
                .copied()
                .max()
                .unwrap_or(0);
            if y < best_y {
                best_y = y;
                best_x = x;
            }
        }
        placements[i] = [best_x as u32, best_y];
        for column in &mut skyline[best_x..best_x + w as usize] {
            *column = best_y + h;
        }
    }
    let height = skyline.iter().copied().max().unwrap_or(1).max(1);
    let width = width.max(1);
    let mut texels: Vec<Option<TexelSource>> = vec![None; (width * height) as usize];
    let mut blocks = Vec::new();
    for (region, origin) in regions.iter().zip(&placements) {
        for (j, row) in region.cells.iter().enumerate() {
            for (i, &(b, r)) in row.iter().enumerate() {
                let block_origin = [origin[0] + i as u32, origin[1] + j as u32];
                let corner_of_block: [u8; 4] = if region.triangle {
                    [0, 1, 2, 2]
                } else {
                    [0, 1, 2, 3].map(|bc| corner(r, bc) as u8)
                };
                let bundle = &mesh.bundles[b as usize];
                for (bc, offset) in [[0u32, 0u32], [1, 0], [1, 1], [0, 1]].iter().enumerate() {
                    let c = corner_of_block[bc] as usize;
                    let index = ((block_origin[1] + offset[1]) * width
                        + block_origin[0]
                        + offset[0]) as usize;
                    texels[index] = Some(TexelSource {
                        column: bundle.vertices[c],
                        uv: bundle.uvs[c],
                    });
                }
                blocks.push(BundleBlock {
                    bundle: b,
                    origin: block_origin,
                    corner_of_block,
                    layers: bundle.layers,
                });
            }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    #[test]
    fn a_grid_shares_texels_and_every_block_sees_its_own_corners() {
        let mesh = grid(6, 4, 2, 0.5);
        let atlas = build_atlas(&mesh, 64);
        assert_eq!(atlas.blocks.len(), 24);
        // One region: 7 × 5 texels for 24 quads (instead of 96).
        assert_eq!(atlas.used_texels(), 35);
        for block in &atlas.blocks {
            let bundle = &mesh.bundles[block.bundle as usize];
            for (bc, offset) in [[0u32, 0u32], [1, 0], [1, 1], [0, 1]].iter().enumerate() {
                let index = ((block.origin[1] + offset[1]) * atlas.width
                    + block.origin[0]
                    + offset[0]) as usize;
                let texel = atlas.texels[index].expect("texel in use");
                let corner = block.corner_of_block[bc] as usize;
                assert_eq!(texel.column, bundle.vertices[corner]);
                assert_eq!(texel.uv, bundle.uvs[corner]);
            }
        }
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
