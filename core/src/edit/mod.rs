//! Edits of the hair mesh, one file per kind: topology tools ([`topology`]), vertex
//! transforms ([`transform`]), styling coordinates ([`coordinates`]: w and uv) and wisp
//! shape copy / mirror ([`wisps`]); selection ([`select`]) and picking ([`pick`]).
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

pub mod brush;
pub mod coordinates;
pub mod paint_maps;
pub mod pick;
pub mod select;
pub mod split_merge;
pub mod styling_direction;
pub mod topology;
pub mod transform;
pub mod wisps;

use std::collections::BTreeSet;

use crate::geometry::interior::place_interior;
use crate::model::mesh::{HairMesh, VertexRef};

// The edit API in one place: callers write `edit::extrude`, whichever file it lives in.
pub use brush::{BrushDab, BrushKind, apply_brush, turned_layers};
pub use coordinates::{set_corner_uvs, set_w, set_w_mode};
pub use split_merge::{merge_bundles, split_bundles};
pub use topology::{
    ExtrudeDirection, bundle_renumbering, delete_bundles, delete_layer, extrude, insert_layer,
    layer_closure, set_density, set_removed, subdivide,
};
pub use transform::{VertexTransform, falloff_weight, transform_vertices};
pub use wisps::{bundle_layer_centre, growth_direction, mirror_shape, mirror_styling, paste_shape};

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
    #[error("bundle {bundle} already has {cap} layers, the most a bundle may have")]
    LayerCap { bundle: u32, cap: u32 },
    #[error("{what} must be finite, got {value}")]
    NotFinite { what: &'static str, value: String },
    #[error("the selected bundles share no vertex with other bundles: nothing to split")]
    NothingToSplit,
    #[error(
        "no vertex of the selected bundles has a twin at the same root (what a split leaves): nothing to merge"
    )]
    NothingToMerge,
    #[error("that would delete every bundle: a scalp needs at least one face to grow hair on")]
    NothingLeft,
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

pub(crate) fn check_bundles(mesh: &HairMesh, bundles: &[u32]) -> Result<(), EditError> {
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

/// Locks (or unlocks) `vertices`: automatic interior placement keeps a locked vertex where
/// it is (a known value of its layer, like an exterior vertex) and a drape holds it still.
/// The layers involved are placed again, so an unlocked interior vertex returns to its
/// automatic place.
pub fn set_locked(
    mesh: &HairMesh,
    vertices: &[VertexRef],
    locked: bool,
) -> Result<EditOutcome, EditError> {
    if vertices.is_empty() {
        return Err(EditError::EmptySelection);
    }
    for v in vertices {
        if mesh.position(*v).is_none() {
            return Err(EditError::VertexOutOfRange {
                column: v.column,
                layer: v.layer,
            });
        }
    }
    let mut out = mesh.clone();
    out.set_locked(vertices, locked);
    let layers: BTreeSet<usize> = vertices.iter().map(|v| v.layer as usize).collect();
    let layers: Vec<usize> = layers.into_iter().collect();
    let affected: BTreeSet<u32> = mesh
        .bundles
        .iter()
        .enumerate()
        .filter(|(_, b)| vertices.iter().any(|v| b.vertices.contains(&v.column)))
        .map(|(i, _)| i as u32)
        .collect();
    finish(out, affected, Some(&layers))
}

/// Trims each column to what its tallest bundle needs (a split or a shorter
/// pasted shape can leave a column with only shorter bundles).
pub(crate) fn fit_column_lengths(mesh: &mut HairMesh) {
    let topology = crate::Topology::build(mesh);
    for c in 0..mesh.columns.len() {
        let required = mesh.required_column_len(&topology, c);
        let column = &mut mesh.columns[c];
        column.positions.truncate(required.max(1));
        column.w.truncate(required.max(1));
    }
}

pub(crate) fn finish(
    mut mesh: HairMesh,
    affected: BTreeSet<u32>,
    layers: Option<&[usize]>,
) -> Result<EditOutcome, EditError> {
    // A lock on a vertex an edit took away (a shorter column) goes with it.
    let columns = &mesh.columns;
    mesh.locked.retain(|v| {
        columns
            .get(v.column as usize)
            .is_some_and(|c| (v.layer as usize) < c.positions.len())
    });
    place_interior(&mut mesh, layers);
    mesh.update_w();
    mesh.validate()?;
    Ok(EditOutcome {
        mesh,
        affected_bundles: affected.into_iter().collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::VertexRef;
    use crate::model::mesh::test_meshes::grid;
    use glam::{DVec2, DVec3};
    use wisps::centre_path;

    fn at(column: u32, layer: u32) -> VertexRef {
        VertexRef { column, layer }
    }

    #[test]
    fn set_density_changes_only_the_selected_bundles_and_refuses_out_of_range() {
        let mesh = grid(3, 2, 2, 0.5);
        let outcome = set_density(&mesh, &[0, 4], 0.3).expect("set");
        for (b, bundle) in outcome.mesh.bundles.iter().enumerate() {
            let expected = if b == 0 || b == 4 { 0.3 } else { 1.0 };
            assert_eq!(bundle.density, expected, "bundle {b}");
        }
        assert_eq!(outcome.mesh.columns, mesh.columns, "geometry untouched");
        for bad in [1.5, -0.2, f64::NAN] {
            match set_density(&mesh, &[1], bad) {
                Err(EditError::Invalid(e)) => assert_eq!(e.path, "bundles[1].density"),
                other => panic!("density {bad}: {other:?}"),
            }
        }
        assert!(matches!(
            set_density(&mesh, &[], 0.5),
            Err(EditError::EmptySelection)
        ));
        assert!(matches!(
            set_density(&mesh, &[99], 0.5),
            Err(EditError::BundleOutOfRange { .. })
        ));
    }

    #[test]
    fn a_locked_interior_vertex_keeps_its_place_and_steers_its_neighbours() {
        // 3×3 quads, two layers: columns 5, 6, 9, 10 are interior at layer 1.
        let mesh = grid(3, 3, 2, 0.5);
        assert!(mesh.is_interior(&crate::model::mesh::Topology::build(&mesh), 5, 1));
        let placed = mesh.position(at(6, 1)).expect("vertex");
        // An artist pulls column 5's middle vertex up and locks it there.
        let mut moved = mesh.clone();
        moved.columns[5].positions[1] += DVec3::new(0.0, 0.0, 0.3);
        let locked = set_locked(&moved, &[at(5, 1)], true).expect("lock");
        assert_eq!(locked.mesh.locked, vec![at(5, 1)]);
        assert_eq!(
            locked.mesh.columns[5].positions[1], moved.columns[5].positions[1],
            "placement kept the locked vertex"
        );
        assert!(
            locked.mesh.position(at(6, 1)).expect("vertex").z > placed.z + 1e-6,
            "its interior neighbour follows it"
        );
        // An edit elsewhere re-places layer 1 and still keeps it.
        let extruded = transform_vertices(
            &locked.mesh,
            &[at(0, 1)],
            VertexTransform::Translate {
                offset: [0.01, 0.0, 0.0],
            },
            0.0,
        )
        .expect("move");
        assert_eq!(
            extruded.mesh.columns[5].positions[1],
            moved.columns[5].positions[1]
        );
        // Unlocking returns it to its automatic place.
        let unlocked = set_locked(&locked.mesh, &[at(5, 1)], false).expect("unlock");
        assert!(unlocked.mesh.locked.is_empty());
        let automatic = mesh.position(at(5, 1)).expect("vertex");
        assert!((unlocked.mesh.position(at(5, 1)).expect("vertex") - automatic).length() < 1e-9);
        // A vertex the mesh does not have is refused by name.
        assert!(matches!(
            set_locked(&mesh, &[at(5, 9)], true),
            Err(EditError::VertexOutOfRange {
                column: 5,
                layer: 9
            })
        ));
    }

    #[test]
    fn locks_follow_inserted_and_deleted_layers() {
        let mesh = grid(2, 1, 3, 0.5);
        let all: Vec<u32> = (0..mesh.bundles.len() as u32).collect();
        let locked = set_locked(&mesh, &[at(0, 1), at(0, 3)], true).expect("lock");
        let inserted = insert_layer(&locked.mesh, &all, 2).expect("insert");
        assert_eq!(inserted.mesh.locked, vec![at(0, 1), at(0, 4)]);
        let deleted = delete_layer(&inserted.mesh, &all, 1).expect("delete");
        assert_eq!(deleted.mesh.locked, vec![at(0, 3)], "the deleted lock went");
        deleted.mesh.validate().expect("valid");
    }

    #[test]
    fn a_lock_the_mesh_does_not_have_is_named() {
        let mut mesh = grid(2, 1, 1, 0.5);
        mesh.locked = vec![at(0, 7)];
        let error = mesh.validate().expect_err("out of range");
        assert_eq!(error.path, "locked[0]");
        mesh.locked = vec![at(1, 1), at(0, 1)];
        let error = mesh.validate().expect_err("unsorted");
        assert_eq!(error.path, "locked[1]");
    }

    #[test]
    fn pasting_a_shape_copies_the_centre_path_and_keeps_the_width_of_a_moved_top() {
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
    fn pasting_copies_every_corner_and_the_layer_count() {
        // Bundle 0 of a 4×1 strip (columns 0, 1, 6, 5) grows a third layer, then its top
        // tapers: each top corner moves a quarter of the way to the top's centre.
        let mesh = grid(4, 1, 2, 0.5);
        let grown = extrude(&mesh, &[0], ExtrudeDirection::AlongNormal { distance: 0.5 })
            .expect("extrude")
            .mesh;
        let mut tapered = grown.clone();
        let centre = bundle_layer_centre(&grown, &grown.bundles[0], 3).expect("centre");
        for c in [0usize, 1, 5, 6] {
            let p = &mut tapered.columns[c].positions[3];
            *p += (centre - *p) * 0.25;
        }
        let tapered = finish(tapered, [0].into(), None).expect("valid").mesh;
        let out = paste_shape(&tapered, 0, &[3, 0]).expect("paste");
        out.mesh.validate().expect("valid after paste");
        let bundle = &out.mesh.bundles[3];
        assert_eq!(bundle.layers, 3, "the source's layer count");
        // Every corner moved from its own root exactly as the source's matching corner did
        // (both frames are the same here: the strip is flat and the bundles alike).
        for (&s, &t) in tapered.bundles[0].vertices.iter().zip(&bundle.vertices) {
            let source = &tapered.columns[s as usize].positions;
            let target = &out.mesh.columns[t as usize].positions;
            for k in 1..=3 {
                let (a, b) = (source[k] - source[0], target[k] - target[0]);
                assert!(a.distance(b) < 1e-9, "column {t} layer {k}: {a} vs {b}");
            }
        }
        // The taper came along: the top is three quarters as wide as the root.
        let top = |k: usize| out.mesh.columns[bundle.vertices[k] as usize].positions[3];
        assert!((top(0).distance(top(1)) - 0.75).abs() < 1e-9);
        // The source itself is not a target, and its neighbours keep their layer counts.
        assert_eq!(out.mesh.bundles[0], tapered.bundles[0]);
        assert_eq!(out.mesh.bundles[2].layers, 2);

        // A shorter shape shrinks the target; only its own columns lose their tops. Bundles
        // 0 and 1 grow a third layer; bundle 3's two-layer shape goes onto bundle 0.
        let tall = extrude(
            &mesh,
            &[0, 1],
            ExtrudeDirection::AlongNormal { distance: 0.5 },
        )
        .expect("extrude")
        .mesh;
        let out = paste_shape(&tall, 3, &[0]).expect("paste short");
        out.mesh.validate().expect("valid after a shorter paste");
        assert_eq!(out.mesh.bundles[0].layers, 2);
        assert_eq!(
            out.mesh.columns[0].positions.len(),
            3,
            "bundle 0's own column"
        );
        assert_eq!(
            out.mesh.columns[1].positions.len(),
            4,
            "shared with bundle 1"
        );

        // Pasting a bundle onto itself alone is nothing to do.
        assert!(matches!(
            paste_shape(&tapered, 0, &[0]),
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
        let (out, pairs) = mirror_shape(&leaning, &[0], 2.0).expect("mirror");
        assert_eq!(pairs, vec![(0, 3)]);
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
    fn mirroring_copies_every_corner_and_the_layer_count() {
        // Bundle 0 of a 4×1 strip grows a third layer whose top leans and tapers toward
        // one corner; its mirror image across x = 2 is bundle 3.
        let mesh = grid(4, 1, 2, 0.5);
        let mut shaped = extrude(&mesh, &[0], ExtrudeDirection::AlongNormal { distance: 0.5 })
            .expect("extrude")
            .mesh;
        shaped.columns[0].positions[3] += DVec3::new(0.3, 0.2, 0.0);
        shaped.columns[1].positions[3] += DVec3::new(-0.1, 0.0, 0.1);
        let shaped = finish(shaped, [0].into(), None).expect("valid").mesh;
        let (out, pairs) = mirror_shape(&shaped, &[0], 2.0).expect("mirror");
        assert_eq!(pairs, vec![(0, 3)]);
        out.mesh.validate().expect("valid after mirror");
        assert_eq!(out.mesh.bundles[3].layers, 3);
        // Each source column's path, reflected, is the path of the column at its root's
        // mirror image (column c at x = i mirrors to x = 4 - i, same row).
        for (s, t) in [(0usize, 4usize), (1, 3), (5, 9), (6, 8)] {
            let (source, target) = (&shaped.columns[s].positions, &out.mesh.columns[t].positions);
            for k in 1..=3 {
                let d = source[k] - source[0];
                let reflected = DVec3::new(-d.x, d.y, d.z);
                let got = target[k] - target[0];
                assert!(
                    got.distance(reflected) < 1e-9,
                    "column {t} layer {k}: {got} vs {reflected}"
                );
            }
        }
    }

    #[test]
    fn mirroring_turns_curl_twist_and_wave_the_other_way() {
        use crate::model::styling::StylingSet;
        let mesh = grid(4, 1, 2, 0.5);
        let mut styling = StylingSet::default();
        let left = styling.new_group("left", &[0]);
        let params = &mut styling.groups[left].params;
        params.curl.radius_m = 0.004;
        params.curl.turns_per_m = 30.0;
        params.twist.turns_per_m = 5.0;
        params.wave.amplitude_m = 0.01;
        params.wave.direction_rad = 0.3;
        let source = styling.groups[left].params.clone();
        // The strip's u runs along +x on both sides: the reflection reverses handedness.
        let mirrored = mirror_styling(&styling, &mesh, &[(0, 3)]);
        mirrored.validate().expect("valid styling");
        let group = mirrored.group_of(3).expect("a group for the mirror image");
        assert_eq!(mirrored.groups[group].name, "left (mirrored)");
        let got = mirrored.params_for(3);
        assert_eq!(got.curl.turns_per_m, -30.0);
        assert_eq!(got.twist.turns_per_m, -5.0);
        assert!((got.wave.direction_rad - (std::f64::consts::PI - 0.3)).abs() < 1e-9);
        assert_eq!(got.curl.radius_m, source.curl.radius_m);
        assert_eq!(mirrored.params_for(0), &source, "the source keeps its own");
        // Mirroring again reuses the mirrored group.
        let again = mirror_styling(&mirrored, &mesh, &[(0, 3)]);
        assert_eq!(again.groups.len(), mirrored.groups.len());
        assert_eq!(again.params_for(3), got);

        // A uv layout mirrored on the right side (u runs along -x there): the reflected
        // frame matches the target's, and the parameters copy as they are.
        let mut flipped = mesh.clone();
        for bundle in &mut flipped.bundles[2..] {
            for uv in &mut bundle.uvs {
                uv.x = 1.0 - uv.x;
            }
        }
        let same = mirror_styling(&styling, &flipped, &[(0, 3)]);
        assert_eq!(same.params_for(3), &source);
        let copied = same.group_of(3).expect("grouped");
        assert_eq!(copied, left, "nothing turned: the source's own group");
        // A source on the global parameters sends its target back to them.
        let mut grouped_target = StylingSet::default();
        grouped_target.new_group("right", &[3]);
        let plain = mirror_styling(&grouped_target, &mesh, &[(1, 3)]);
        assert_eq!(plain.group_of(3), None);
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

    #[test]
    fn deleting_bundles_renumbers_what_is_left_and_shortens_columns() {
        use crate::model::styling::{StylingGroup, StylingSet};
        // 3 × 2 grid, 3 layers; the middle column of bundles 1 and 4 is extruded two more.
        let mut mesh = grid(3, 2, 3, 0.1);
        for _ in 0..2 {
            mesh = extrude(
                &mesh,
                &[1, 4],
                ExtrudeDirection::AlongNormal { distance: 0.1 },
            )
            .expect("extrude")
            .mesh;
        }
        mesh.set_locked(&[at(0, 1), at(5, 2)], true);
        let tallest_before = mesh.columns.iter().map(|c| c.positions.len()).max();
        assert_eq!(tallest_before, Some(6));

        let out = delete_bundles(&mesh, &[1, 4]).expect("delete");
        out.mesh.validate().expect("valid");
        assert_eq!(out.mesh.bundles.len(), 4);
        assert_eq!(out.affected_bundles, vec![0, 1, 2, 3]);
        // Every column is exactly as tall as its tallest bundle now (no tall bundle left).
        assert!(out.mesh.columns.iter().all(|c| c.positions.len() == 4));
        // Columns no bundle uses are gone: the grid's 12 root vertices all remain used.
        assert_eq!(out.mesh.columns.len(), 12);
        // Survivors keep their order and geometry (bundle 2 became bundle 1).
        let root = |m: &HairMesh, b: usize| {
            m.bundles[b]
                .vertices
                .iter()
                .map(|&v| m.columns[v as usize].positions[0])
                .collect::<Vec<_>>()
        };
        assert_eq!(root(&out.mesh, 1), root(&mesh, 2));
        assert!(
            out.mesh
                .locked
                .iter()
                .all(|v| out.mesh.position(*v).is_some())
        );
        assert_eq!(out.mesh.locked.len(), 2);

        // Deleting a corner bundle drops the column only it used.
        let corner = delete_bundles(&mesh, &[0]).expect("delete");
        assert_eq!(corner.mesh.columns.len(), 11);
        corner.mesh.validate().expect("valid");

        // Styling groups follow; deleting everything is refused; bad indices are named.
        let mut styling = StylingSet {
            groups: vec![StylingGroup {
                name: "left".into(),
                bundles: vec![0, 1, 2, 4, 5, 99],
                params: Default::default(),
            }],
            ..Default::default()
        };
        styling.renumber_bundles(&bundle_renumbering(6, &[1, 4]));
        assert_eq!(styling.groups[0].bundles, vec![0, 1, 3]);
        assert!(matches!(
            delete_bundles(&mesh, &[0, 1, 2, 3, 4, 5]),
            Err(EditError::NothingLeft)
        ));
        assert!(matches!(
            delete_bundles(&mesh, &[6]),
            Err(EditError::BundleOutOfRange { index: 6, .. })
        ));
        assert!(matches!(
            delete_bundles(&mesh, &[]),
            Err(EditError::EmptySelection)
        ));
    }
}
