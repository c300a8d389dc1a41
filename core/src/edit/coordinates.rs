//! Styling coordinates: w per vertex (or from path length) and root-face uv.

use std::collections::BTreeSet;

use glam::DVec2;

use crate::edit::{EditError, EditOutcome};
use crate::model::mesh::{HairMesh, Topology, VertexRef, WMode};

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
