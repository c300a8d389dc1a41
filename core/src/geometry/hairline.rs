//! The border of the hair and how far each root lies from it: what the hairline styling op
//! ([`crate::model::styling::Hairline`]) thins and shortens strands by.
//!
//! The border is every root edge that exactly one hair-growing bundle uses: the hairline
//! over the forehead, the nape, around the ears, the rim of a bald patch. A root's distance
//! is the straight-line distance from its scalp vertex to the nearest border edge; over a
//! face the generators blend the corners' distances as they blend positions (bilinear for
//! quads, barycentric for triangles), so thinning is continuous across bundles.
//!
//! Distances are rounded to binary16, so the f64 reference, f32 runtime textures and f16
//! ones start from the same number: whether a root near the threshold grows does not depend
//! on the texture precision.
//!
//! Straight-line rather than geodesic: the falloff spans a centimetre or two, over which a
//! scalp is nearly flat. Brute force over border edges (columns × border edges) rather
//! than a spatial index: the border is a small share of the edges (a head: 450 columns, a
//! hundred border edges, well under a millisecond). It runs whenever runtime textures are
//! built (an upload, a reshape: a drag, a drape, a simulated step); a whole body of 9,000
//! columns with a thousand border edges costs about 10⁷ point-segment distances there.

use std::collections::HashMap;

use glam::DVec3;

use crate::model::mesh::{Bundle, HairMesh};

/// The distance written where no border exists (hair over a whole closed surface): the
/// largest binary16 value, so f16 and f32 runtime textures hold the same number.
pub const NO_BORDER_DISTANCE: f64 = 65504.0;

/// Whether a bundle grows hair (and so is inside the border).
fn grows(bundle: &Bundle) -> bool {
    !bundle.removed && bundle.layers > 0 && bundle.density > 0.0
}

/// The root edges (column pairs, lower index first) that exactly one hair-growing bundle
/// uses, sorted.
pub fn border_edges(mesh: &HairMesh) -> Vec<[u32; 2]> {
    let mut uses: HashMap<[u32; 2], u32> = HashMap::new();
    for bundle in mesh.bundles.iter().filter(|b| grows(b)) {
        let n = bundle.vertices.len();
        for i in 0..n {
            let (a, b) = (bundle.vertices[i], bundle.vertices[(i + 1) % n]);
            if a != b {
                *uses.entry([a.min(b), a.max(b)]).or_default() += 1;
            }
        }
    }
    let mut edges: Vec<[u32; 2]> = uses
        .into_iter()
        .filter(|&(_, count)| count == 1)
        .map(|(edge, _)| edge)
        .collect();
    edges.sort_unstable();
    edges
}

/// Distance from `p` to the segment `a`–`b` (a point where `a == b`).
fn distance_to_segment(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let length_squared = ab.length_squared();
    let t = if length_squared > 0.0 {
        ((p - a).dot(ab) / length_squared).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

/// Each column's root distance to the border of the hair (object units, rounded to
/// binary16), at most [`NO_BORDER_DISTANCE`]; 0 for a column on the border and for columns
/// no growing bundle uses. Non-finite positions give 0 (a validated mesh has none).
pub fn column_distances(mesh: &HairMesh) -> Vec<f64> {
    let edges: Vec<(DVec3, DVec3)> = border_edges(mesh)
        .into_iter()
        .filter_map(|[a, b]| {
            let root = |c: u32| mesh.columns.get(c as usize)?.positions.first().copied();
            Some((root(a)?, root(b)?))
        })
        .collect();
    let mut inside = vec![false; mesh.columns.len()];
    for bundle in mesh.bundles.iter().filter(|b| grows(b)) {
        for &c in &bundle.vertices {
            if let Some(flag) = inside.get_mut(c as usize) {
                *flag = true;
            }
        }
    }
    mesh.columns
        .iter()
        .zip(&inside)
        .map(|(column, &inside)| {
            let Some(&p) = column.positions.first().filter(|p| p.is_finite()) else {
                return 0.0;
            };
            if !inside {
                return 0.0;
            }
            let nearest = edges
                .iter()
                .map(|&(a, b)| distance_to_segment(p, a, b))
                .fold(f64::INFINITY, f64::min);
            let distance = if nearest.is_finite() {
                nearest.min(NO_BORDER_DISTANCE)
            } else {
                NO_BORDER_DISTANCE
            };
            crate::runtime::half::round_to_f16(distance as f32) as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    #[test]
    fn the_border_is_the_rim_of_the_growing_faces() {
        // 4 × 3 quads, 1 unit apart: 5 × 4 columns, 14 rim edges.
        let mesh = grid(4, 3, 2, 1.0);
        assert_eq!(border_edges(&mesh).len(), 2 * (4 + 3));
        let distances = column_distances(&mesh);
        // Rim columns are on the border; the interior ones one unit in.
        let on_rim = distances.iter().filter(|&&d| d == 0.0).count();
        assert_eq!(on_rim, 14);
        assert!(
            distances
                .iter()
                .all(|&d| d == 0.0 || (d - 1.0).abs() < 1e-12),
            "{distances:?}"
        );
        // Binary16 values: f16 textures hold them as they are.
        let scaled: Vec<f64> = {
            let mut mesh = mesh.clone();
            for column in &mut mesh.columns {
                column.positions[0] *= 0.0137;
            }
            column_distances(&mesh)
        };
        assert!(scaled.iter().any(|&d| d > 0.0));
        assert!(
            scaled
                .iter()
                .all(|&d| crate::runtime::half::round_to_f16(d as f32) as f64 == d)
        );
        // A bald face inside (removed) opens a border around it: on a 3 × 3 grid with its
        // centre bald, every column is on one.
        let mut mesh = grid(3, 3, 2, 1.0);
        let centre = 4;
        mesh.bundles[centre].removed = true;
        assert_eq!(border_edges(&mesh).len(), 12 + 4);
        assert!(column_distances(&mesh).iter().all(|&d| d == 0.0));
        // A bundle that grows nothing (density 0) is bald too.
        mesh.bundles[centre].removed = false;
        mesh.bundles[centre].density = 0.0;
        assert_eq!(border_edges(&mesh).len(), 12 + 4);
    }

    #[test]
    fn degenerate_meshes_give_finite_distances() {
        // No growing bundle: no border, and no column inside.
        let mut mesh = grid(2, 2, 1, 1.0);
        for bundle in &mut mesh.bundles {
            bundle.layers = 0;
        }
        assert!(border_edges(&mesh).is_empty());
        assert!(column_distances(&mesh).iter().all(|&d| d == 0.0));
        // Every root at one point (zero-length border edges): distance 0, finite.
        let mut mesh = grid(2, 2, 1, 1.0);
        for column in &mut mesh.columns {
            column.positions[0] = DVec3::ONE;
        }
        assert!(column_distances(&mesh).iter().all(|&d| d == 0.0));
        // A NaN root does not spread: its own distance is 0, the others stay finite.
        let mut mesh = grid(3, 3, 1, 1.0);
        mesh.columns[5].positions[0] = DVec3::NAN;
        let distances = column_distances(&mesh);
        assert!(distances.iter().all(|d| d.is_finite() && *d >= 0.0));
        assert_eq!(distances[5], 0.0);
    }

    #[test]
    fn a_closed_surface_has_no_border() {
        // Two triangles glued along all three edges: a closed (degenerate) shell.
        let mut mesh = grid(1, 1, 1, 1.0);
        let quad = mesh.bundles[0].clone();
        let mut a = quad.clone();
        a.vertices = vec![quad.vertices[0], quad.vertices[1], quad.vertices[2]];
        a.uvs.truncate(3);
        let mut b = a.clone();
        b.vertices.reverse();
        mesh.bundles = vec![a, b];
        assert!(border_edges(&mesh).is_empty());
        let distances = column_distances(&mesh);
        assert_eq!(distances[quad.vertices[0] as usize], NO_BORDER_DISTANCE);
        // The fourth corner belongs to no bundle now.
        assert_eq!(distances[quad.vertices[3] as usize], 0.0);
    }
}
