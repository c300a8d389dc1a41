//! Split and merge (the hair-mesh operations of Yuksel et al. 2009): a group of bundles
//! splits off its neighbours so it can be shaped as its own lock, and merges back so its
//! tops join theirs again. Roots never move: a split duplicates the shared columns (root
//! included) for the group; a merge welds columns whose roots coincide.

use std::collections::{BTreeMap, BTreeSet};

use crate::edit::{EditError, EditOutcome, check_bundles, finish, fit_column_lengths};
use crate::model::mesh::{Column, HairMesh, Topology, VertexRef};

/// Splits `bundles` off the bundles around them: every column the group shares with a
/// bundle outside it is duplicated for the group (positions, w and locks), so moving the
/// group's vertices no longer moves its neighbours'. Refused when the group shares no
/// column with another bundle.
pub fn split_bundles(mesh: &HairMesh, bundles: &[u32]) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    let group: BTreeSet<u32> = bundles.iter().copied().collect();
    let topology = Topology::build(mesh);
    let mut out = mesh.clone();
    // Shared column → its copy for the group.
    let mut copies: BTreeMap<u32, u32> = BTreeMap::new();
    let mut neighbours: BTreeSet<u32> = BTreeSet::new();
    for &b in &group {
        for &c in &mesh.bundles[b as usize].vertices {
            let outside: Vec<u32> = topology.bundles_of_column[c as usize]
                .iter()
                .copied()
                .filter(|o| !group.contains(o))
                .collect();
            if outside.is_empty() || copies.contains_key(&c) {
                continue;
            }
            neighbours.extend(outside);
            copies.insert(c, out.columns.len() as u32);
            out.columns.push(mesh.columns[c as usize].clone());
        }
    }
    if copies.is_empty() {
        return Err(EditError::NothingToSplit);
    }
    for &b in &group {
        for v in &mut out.bundles[b as usize].vertices {
            if let Some(&copy) = copies.get(v) {
                *v = copy;
            }
        }
    }
    // A locked vertex stays locked on both sides.
    let copied_locks: Vec<VertexRef> = mesh
        .locked
        .iter()
        .filter_map(|v| {
            copies.get(&v.column).map(|&column| VertexRef {
                column,
                layer: v.layer,
            })
        })
        .collect();
    out.locked.extend(copied_locks);
    out.locked.sort();
    out.locked.dedup();
    fit_column_lengths(&mut out);
    let mut affected = group;
    affected.extend(neighbours);
    finish(out, affected, None)
}

/// Merges `bundles` with the bundles they were split from: each column of the group whose
/// root coincides exactly with another column's (what a split leaves) is welded with it —
/// layer by layer the mean of the welded columns, locks kept — and the spare column goes.
/// Refused when no column of the group has a twin.
pub fn merge_bundles(mesh: &HairMesh, bundles: &[u32]) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, bundles)?;
    let group: BTreeSet<u32> = bundles.iter().copied().collect();
    let group_columns: BTreeSet<u32> = group
        .iter()
        .flat_map(|&b| mesh.bundles[b as usize].vertices.iter().copied())
        .collect();
    // Columns by exact root position; a weld keeps the lowest index.
    let mut by_root: BTreeMap<[u64; 3], Vec<u32>> = BTreeMap::new();
    for (c, column) in mesh.columns.iter().enumerate() {
        if let Some(root) = column.positions.first() {
            by_root
                .entry(root.to_array().map(f64::to_bits))
                .or_default()
                .push(c as u32);
        }
    }
    let mut out = mesh.clone();
    let mut welded_into: BTreeMap<u32, u32> = BTreeMap::new();
    for twins in by_root.values().filter(|t| t.len() > 1) {
        if !twins.iter().any(|c| group_columns.contains(c)) {
            continue;
        }
        let keep = twins[0];
        let members: Vec<&Column> = twins.iter().map(|&c| &mesh.columns[c as usize]).collect();
        let len = members.iter().map(|c| c.positions.len()).max().unwrap_or(1);
        let mut positions = Vec::with_capacity(len);
        let mut w: Vec<f64> = Vec::with_capacity(len);
        for layer in 0..len {
            let present: Vec<&Column> = members
                .iter()
                .copied()
                .filter(|c| layer < c.positions.len())
                .collect();
            let share = 1.0 / present.len() as f64;
            positions.push(present.iter().map(|c| c.positions[layer] * share).sum());
            let mean: f64 = present.iter().map(|c| c.w[layer] * share).sum();
            // w stays non-decreasing toward the tip (a shorter twin's mean may dip).
            w.push(w.last().map_or(mean, |&below: &f64| mean.max(below)));
        }
        out.columns[keep as usize] = Column { positions, w };
        for &c in &twins[1..] {
            welded_into.insert(c, keep);
        }
    }
    if welded_into.is_empty() {
        return Err(EditError::NothingToMerge);
    }
    let mut affected: BTreeSet<u32> = BTreeSet::new();
    for (b, bundle) in out.bundles.iter_mut().enumerate() {
        for v in &mut bundle.vertices {
            if let Some(&keep) = welded_into.get(v) {
                *v = keep;
                affected.insert(b as u32);
            }
        }
    }
    for v in &mut out.locked {
        if let Some(&keep) = welded_into.get(&v.column) {
            v.column = keep;
        }
    }
    out.locked.sort();
    out.locked.dedup();
    remove_unused_columns(&mut out);
    affected.extend(group);
    finish(out, affected, None)
}

/// Drops the columns no bundle uses and renumbers the rest (bundles and locks follow).
fn remove_unused_columns(mesh: &mut HairMesh) {
    let topology = Topology::build(mesh);
    let mut renumbered: Vec<Option<u32>> = Vec::with_capacity(mesh.columns.len());
    let mut next = 0u32;
    for users in &topology.bundles_of_column {
        if users.is_empty() {
            renumbered.push(None);
        } else {
            renumbered.push(Some(next));
            next += 1;
        }
    }
    let mut index = 0;
    mesh.columns.retain(|_| {
        index += 1;
        renumbered[index - 1].is_some()
    });
    for bundle in &mut mesh.bundles {
        for v in &mut bundle.vertices {
            *v = renumbered[*v as usize].unwrap_or(*v);
        }
    }
    mesh.locked = mesh
        .locked
        .iter()
        .filter_map(|v| {
            renumbered[v.column as usize].map(|column| VertexRef {
                column,
                layer: v.layer,
            })
        })
        .collect();
    mesh.locked.sort();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::interior::place_interior;
    use crate::model::mesh::test_meshes::grid;

    /// A 3 × 2 grid of quads, 2 layers, interior placed; bundles 0 and 3 are its left column.
    fn mesh() -> HairMesh {
        let mut mesh = grid(3, 2, 2, 0.5);
        place_interior(&mut mesh, None);
        mesh.update_w();
        mesh
    }

    #[test]
    fn a_split_group_moves_alone_and_merging_it_back_restores_the_mesh() {
        let original = mesh();
        let group = [0u32, 3];
        let split = split_bundles(&original, &group).expect("split");
        split.mesh.validate().expect("valid after split");
        // The group shared the three columns of the line x = 1 with bundles 1 and 4.
        assert_eq!(split.mesh.columns.len(), original.columns.len() + 3);
        assert_eq!(split.affected_bundles, vec![0, 1, 3, 4]);
        let shared = |mesh: &HairMesh, a: u32, b: u32| {
            let (a, b) = (&mesh.bundles[a as usize], &mesh.bundles[b as usize]);
            a.vertices.iter().filter(|v| b.vertices.contains(v)).count()
        };
        assert_eq!(shared(&original, 0, 1), 2);
        assert_eq!(shared(&split.mesh, 0, 1), 0);
        assert_eq!(
            shared(&split.mesh, 0, 3),
            2,
            "inside the group nothing splits"
        );
        // Moving the group's top corner on x = 1 leaves bundle 1 where it was.
        let corner = split.mesh.bundles[0].vertices[1];
        let mut moved = split.mesh.clone();
        moved.columns[corner as usize].positions[2].z += 0.25;
        let theirs = original.bundles[1].vertices[0];
        assert_eq!(
            moved.columns[theirs as usize].positions,
            original.columns[theirs as usize].positions
        );
        // Roots stay put.
        assert_eq!(
            moved.columns[corner as usize].positions[0],
            moved.columns[theirs as usize].positions[0]
        );

        // Merging the unmoved split gives the original mesh back, exactly.
        let merged = merge_bundles(&split.mesh, &group).expect("merge");
        assert_eq!(merged.mesh, original);
        // Merging the moved one joins the tops half-way.
        let merged = merge_bundles(&moved, &group).expect("merge moved");
        merged.mesh.validate().expect("valid after merge");
        assert_eq!(merged.mesh.columns.len(), original.columns.len());
        let joined = merged.mesh.bundles[1].vertices[0];
        assert_eq!(merged.mesh.bundles[0].vertices[1], joined);
        let expected = original.columns[theirs as usize].positions[2].z + 0.125;
        assert!((merged.mesh.columns[joined as usize].positions[2].z - expected).abs() < 1e-12);
    }

    #[test]
    fn split_keeps_locks_and_trims_columns_merge_keeps_them() {
        let mut original = mesh();
        // Bundle 1 is one layer taller: the shared column x = 1, y = 0 then needs 4 entries
        // only for bundle 1's side.
        let extruded = crate::edit::extrude(
            &original,
            &[1],
            crate::edit::ExtrudeDirection::Vector {
                offset: [0.0, 0.0, 0.5],
            },
        )
        .expect("extrude");
        original = extruded.mesh;
        let corner = original.bundles[0].vertices[1];
        original.locked = vec![VertexRef {
            column: corner,
            layer: 2,
        }];
        original.validate().expect("valid");
        let split = split_bundles(&original, &[0]).expect("split");
        let copy = split.mesh.bundles[0].vertices[1];
        assert_eq!(split.mesh.columns[copy as usize].positions.len(), 3);
        assert_eq!(split.mesh.columns[corner as usize].positions.len(), 4);
        assert!(split.mesh.locked.contains(&VertexRef {
            column: copy,
            layer: 2
        }));
        assert!(split.mesh.locked.contains(&VertexRef {
            column: corner,
            layer: 2
        }));
        let merged = merge_bundles(&split.mesh, &[0]).expect("merge");
        assert_eq!(merged.mesh, original);
    }

    #[test]
    fn split_and_merge_say_when_there_is_nothing_to_do() {
        let original = mesh();
        let all: Vec<u32> = (0..original.bundles.len() as u32).collect();
        assert!(matches!(
            split_bundles(&original, &all),
            Err(EditError::NothingToSplit)
        ));
        assert!(matches!(
            merge_bundles(&original, &[0]),
            Err(EditError::NothingToMerge)
        ));
        assert!(matches!(
            split_bundles(&original, &[]),
            Err(EditError::EmptySelection)
        ));
        assert!(matches!(
            merge_bundles(&original, &[99]),
            Err(EditError::BundleOutOfRange { .. })
        ));
    }
}
