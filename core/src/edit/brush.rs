//! Grooming brushes: comb, length, puff, smooth, clump and part dabs on the hair mesh's exterior
//! vertices, as a groom artist strokes them over the head. Interior vertices follow by the
//! existing rule ([`crate::geometry::interior`], through [`finish`]).
//!
//! Exterior vertices and locked interior ones (known values of their layers, as a drape
//! leaves them) are brushed; the other interior vertices are placed.
//!
//! A stroke is a run of dabs; the editor applies each to the mesh the stroke has made so far
//! and records the stroke as one undo step. Every dab keeps the mesh valid:
//! - the brushed columns keep their segment lengths (comb, puff, smooth and clump turn
//!   segments, never stretch them; the length brush scales them, down to a floor); interior
//!   vertices are then placed by the rule, so a segment next to one can change, and no
//!   segment anywhere is left shorter than the floor (a layer collapsing onto the one below);
//! - no bundle layer flips against the layer below (see [`turned_layers`]);
//! - hair stays outside the body: a vertex the dab moves into it is pushed back out along
//!   the body's distance field.
//!
//! A dab that would break one of these anyway (the push out of the head, or interior
//! placement, can) is applied at a half, a quarter, an eighth of its strength, or not at
//! all. Each is judged against the mesh before the dab and against what placing its
//! interior afresh alone gives (as any edit does), so a sample placed otherwise is not
//! frozen by a layer the brush did not turn.
//!
//! With `mirror_x` the dab also acts at its mirror image across the head's plane `x = c`:
//! each vertex takes the stronger centre's weight and the weighted mean of their motions
//! (a dab on the plane does not act twice, and sideways combing cancels there instead of
//! parting the hair).

use std::collections::BTreeSet;

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::edit::select::vertex_neighbours;
use crate::edit::{EditError, EditOutcome, falloff_weight, finish};
use crate::model::mesh::{HairMesh, Topology, VertexRef};
use crate::simulate::BodySdf;

/// What a dab does to the vertices under it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BrushKind {
    /// Drag hair along the pointer's motion; segments turn, lengths stay.
    #[default]
    Comb,
    /// Grow the hair under the brush (inverted: cut it), scaling its segments from the root.
    Length,
    /// Lift hair away from the scalp (inverted: flatten it onto the scalp).
    Puff,
    /// Relax kinks: each vertex toward the mean of its neighbours along and across the hair.
    Smooth,
    /// Gather the hair under the brush toward its centre, layer by layer (inverted: spread).
    Clump,
    /// Part the hair along the stroke: each strand falls away from the stroke's line to the
    /// side its root lies on (a middle part is a stroke along the head's centre).
    Part,
}

impl BrushKind {
    pub const ALL: [BrushKind; 6] = [
        BrushKind::Comb,
        BrushKind::Length,
        BrushKind::Puff,
        BrushKind::Smooth,
        BrushKind::Clump,
        BrushKind::Part,
    ];

    pub fn label(self) -> &'static str {
        match self {
            BrushKind::Comb => "Comb",
            BrushKind::Length => "Grow / cut",
            BrushKind::Puff => "Puff",
            BrushKind::Smooth => "Smooth",
            BrushKind::Clump => "Clump",
            BrushKind::Part => "Part",
        }
    }
}

/// One dab of a brush stroke, in model units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BrushDab {
    pub kind: BrushKind,
    /// Where the brush touches the hair.
    pub centre_m: [f64; 3],
    pub radius_m: f64,
    /// 0 … 1; a tablet's pressure multiplies into it.
    pub strength: f64,
    /// Ctrl: the brush's opposite (cut, flatten, spread).
    pub invert: bool,
    /// The pointer's motion over the hair since the last dab (the comb's direction).
    pub motion_m: [f64; 3],
    /// The view direction (camera toward the scene): hair whose scalp faces away from the
    /// viewer is left alone, so a stroke never reaches through the head. `None`: all hair.
    pub view_direction: Option<[f64; 3]>,
    /// Also act at the mirror image across `x = mirror_plane_x`.
    pub mirror_x: bool,
    pub mirror_plane_x: f64,
}

/// How far one dab at full strength moves hair, as a share of the brush radius (puff,
/// smooth, clump) or of the segment length (length): small steps, so a stroke of many dabs
/// builds a shape the artist can follow.
const STEP_SHARE: f64 = 0.25;
/// The share by which one dab at full strength grows or cuts the hair under the brush.
const LENGTH_STEP: f64 = 0.1;
/// No brush leaves a segment shorter than this (unless it already was): the length brush
/// cuts to it, and a dab that would crowd vertices closer is held back.
const MIN_SEGMENT_M: f64 = 1e-4;
/// Hair pushed out of the body lands this far outside it.
const BODY_MARGIN_M: f64 = 1e-3;
/// How deep inside the body's (sampled) distance field a hair vertex may sit before a dab
/// that put it there is held back.
const INSIDE_TOLERANCE_M: f64 = 2.5e-4;
/// A scalp normal this far toward the view direction counts as facing away.
const FACING_AWAY: f64 = 0.2;

impl BrushDab {
    fn check(&self) -> Result<(), EditError> {
        let mut values: Vec<(&'static str, f64)> = vec![
            ("brush radius", self.radius_m),
            ("brush strength", self.strength),
            ("mirror plane", self.mirror_plane_x),
        ];
        values.extend(self.centre_m.map(|v| ("brush centre", v)));
        values.extend(self.motion_m.map(|v| ("brush motion", v)));
        if let Some(view) = self.view_direction {
            values.extend(view.map(|v| ("view direction", v)));
        }
        if let Some((what, value)) = values.iter().find(|(_, v)| !v.is_finite()) {
            return Err(EditError::NotFinite {
                what,
                value: value.to_string(),
            });
        }
        Ok(())
    }

    /// The brush's centres with their motion and view direction (the mirror image second).
    fn centres(&self) -> Vec<(DVec3, DVec3, Option<DVec3>)> {
        let view = self.view_direction.map(DVec3::from);
        let mut centres = vec![(DVec3::from(self.centre_m), DVec3::from(self.motion_m), view)];
        if self.mirror_x {
            let mirror = |v: DVec3| DVec3::new(-v.x, v.y, v.z);
            let c = DVec3::from(self.centre_m);
            centres.push((
                DVec3::new(2.0 * self.mirror_plane_x - c.x, c.y, c.z),
                mirror(DVec3::from(self.motion_m)),
                view.map(mirror),
            ));
        }
        centres
    }
}

/// The unit normal of each column's root vertex: the mean of the root faces around it
/// (Newell's normal, so quads need not be planar). Zero for a column with no active root
/// face (removed bundles do not count).
pub fn root_normals(mesh: &HairMesh) -> Vec<DVec3> {
    let mut sums = vec![DVec3::ZERO; mesh.columns.len()];
    for bundle in mesh.bundles.iter().filter(|b| !b.removed) {
        let corners: Vec<DVec3> = bundle
            .vertices
            .iter()
            .filter_map(|&c| mesh.columns.get(c as usize)?.positions.first().copied())
            .collect();
        if corners.len() != bundle.vertices.len() {
            continue;
        }
        let normal = newell(&corners);
        for &c in &bundle.vertices {
            sums[c as usize] += normal;
        }
    }
    sums.iter()
        .map(|n| n.try_normalize().unwrap_or(DVec3::ZERO))
        .collect()
}

/// Newell's polygon normal, its length twice the area.
fn newell(corners: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for (i, a) in corners.iter().enumerate() {
        let b = corners[(i + 1) % corners.len()];
        n += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    n
}

/// A layer of a bundle that turned over or collapsed: its corners wind against the layer
/// below's (or span no area), which no brush, transform or drape should leave behind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TurnedLayer {
    pub bundle: u32,
    pub layer: u32,
}

/// Every layer of every active bundle that turned over or collapsed: its corners wind
/// against the layer below's (their normals point opposite ways: the cross-section flipped
/// between two layers), or its area falls below a millionth of the root face's. Hair may
/// bend and shear any way (a long bundle hanging down the back, a layer sheared along the
/// strand); only a flip from one layer to the next counts. A dab never adds one (a mesh
/// that came in with one keeps it).
pub fn turned_layers(mesh: &HairMesh) -> Vec<TurnedLayer> {
    let mut turned = Vec::new();
    for (b, bundle) in mesh.bundles.iter().enumerate() {
        if bundle.removed {
            continue;
        }
        let layer_normal = |k: usize| {
            let corners: Option<Vec<DVec3>> = bundle
                .vertices
                .iter()
                .map(|&c| mesh.columns.get(c as usize)?.positions.get(k).copied())
                .collect();
            corners.map(|corners| newell(&corners))
        };
        let Some(root) = layer_normal(0) else {
            continue;
        };
        let root_area = root.length();
        if root_area <= 0.0 {
            continue;
        }
        let mut below = root;
        for k in 1..=bundle.layers as usize {
            let Some(normal) = layer_normal(k) else {
                continue;
            };
            let collapsed = normal.length() <= 1e-6 * root_area;
            if collapsed || normal.dot(below) < 0.0 {
                turned.push(TurnedLayer {
                    bundle: b as u32,
                    layer: k as u32,
                });
            }
            if !collapsed {
                below = normal;
            }
        }
    }
    turned
}

/// One dab on `mesh` (see the module documentation). `body` keeps hair outside the head;
/// [`BodySdf::empty`] when there is none. The outcome's `affected_bundles` is empty when the
/// dab touched nothing (or could not act without turning a layer over).
pub fn apply_brush(
    mesh: &HairMesh,
    body: &BodySdf,
    dab: &BrushDab,
) -> Result<EditOutcome, EditError> {
    dab.check()?;
    let unchanged = || EditOutcome {
        mesh: mesh.clone(),
        affected_bundles: Vec::new(),
    };
    let strength = dab.strength.clamp(0.0, 1.0);
    if dab.radius_m <= 0.0 || strength == 0.0 {
        return Ok(unchanged());
    }
    let topology = Topology::build(mesh);
    let normals = root_normals(mesh);
    let centres = dab.centres();
    // Each brushed hair vertex under the brush: its weight, the centre that acts on it and
    // the comb's motion there.
    let mut weights: Vec<Vec<Weight>> = mesh
        .columns
        .iter()
        .map(|c| vec![Weight::default(); c.positions.len()])
        .collect();
    let mut touched_columns: BTreeSet<usize> = BTreeSet::new();
    for (c, column) in mesh.columns.iter().enumerate() {
        // Hair of removed bundles is hidden and left alone.
        let active = topology.bundles_of_column[c]
            .iter()
            .any(|&b| !mesh.bundles[b as usize].removed);
        if !active {
            continue;
        }
        for (k, &p) in column.positions.iter().enumerate().skip(1) {
            // A locked interior vertex is a known value of its layer (placed by the artist
            // or a drape), so the brush moves it like an exterior one.
            if mesh.is_interior(&topology, c, k) && !mesh.is_locked(c, k) {
                continue;
            }
            // Where the brush and its mirror image overlap (a dab on the head's plane) the
            // vertex takes the stronger's weight and the weighted mean of their motions, so
            // sideways combing cancels on the plane instead of parting the hair there.
            let mut total = 0.0;
            let mut motion = DVec3::ZERO;
            for (i, (centre, centre_motion, view)) in centres.iter().enumerate() {
                if view.is_some_and(|view| normals[c].dot(view) > FACING_AWAY) {
                    continue;
                }
                let w = falloff_weight(p.distance(*centre), dab.radius_m) * strength;
                total += w;
                motion += *centre_motion * w;
                if w > weights[c][k].weight {
                    weights[c][k].weight = w;
                    weights[c][k].centre = i;
                    touched_columns.insert(c);
                }
            }
            if total > 0.0 {
                weights[c][k].motion = motion / total;
            }
        }
    }
    if touched_columns.is_empty() {
        return Ok(unchanged());
    }
    let moved = stroke_positions(mesh, &topology, &normals, dab, &centres, &weights);
    // The strongest share of the dab (1, ½, ¼, ⅛) that turns no layer over, crowds none and
    // puts no hair in the head. Interior placement fits whole layers, so every bundle is
    // checked, not only those under the brush.
    let affected: BTreeSet<u32> = touched_columns
        .iter()
        .flat_map(|&c| topology.bundles_of_column[c].iter().copied())
        .collect();
    // What is wrong before the dab, and what placing the interior afresh alone does (any
    // edit places it; a mesh placed by an older rule, or with locks, may change where no
    // brush touched): a dab is held back only for what it adds to both.
    let placed = finish(mesh.clone(), BTreeSet::new(), None)?.mesh;
    let mut turned_before = turned_layers(mesh);
    turned_before.extend(turned_layers(&placed));
    let mut inside_before = inside_body(mesh, body);
    inside_before.extend(inside_body(&placed, body));
    let mut short_before = short_segments(mesh);
    short_before.extend(short_segments(&placed));
    for share in [1.0, 0.5, 0.25, 0.125] {
        let mut out = mesh.clone();
        for &c in &touched_columns {
            blend_column(
                &mesh.columns[c].positions,
                &moved[c],
                share,
                &mut out.columns[c].positions,
            );
        }
        keep_outside(&mut out, body, &touched_columns);
        let outcome = finish(out, affected.clone(), None)?;
        let turned = turned_layers(&outcome.mesh);
        // Interior vertices are placed after the push out of the body, so they are checked.
        let inside = inside_body(&outcome.mesh, body);
        let held = turned.iter().all(|t| turned_before.contains(t))
            && inside.is_subset(&inside_before)
            && short_segments(&outcome.mesh).is_subset(&short_before);
        if held {
            return Ok(outcome);
        }
    }
    Ok(unchanged())
}

/// Where the dab at full strength puts each vertex of the touched columns (the others keep
/// theirs): the brush's displacement, then every column walked from the root so each
/// segment keeps its length (or, for the length brush, its scaled length).
fn stroke_positions(
    mesh: &HairMesh,
    topology: &Topology,
    normals: &[DVec3],
    dab: &BrushDab,
    centres: &[(DVec3, DVec3, Option<DVec3>)],
    weights: &[Vec<Weight>],
) -> Vec<Vec<DVec3>> {
    let sign = if dab.invert { -1.0 } else { 1.0 };
    let step = STEP_SHARE * dab.radius_m;
    let mut target: Vec<Vec<DVec3>> = mesh.columns.iter().map(|c| c.positions.clone()).collect();
    // Clump: the weighted centre of the hair under each centre, layer by layer.
    let longest = mesh.columns.iter().map(|c| c.positions.len()).max();
    let mut clump_centres: Vec<Vec<(DVec3, f64)>> =
        vec![vec![(DVec3::ZERO, 0.0); longest.unwrap_or(0)]; centres.len()];
    if dab.kind == BrushKind::Clump {
        for (c, column) in mesh.columns.iter().enumerate() {
            for (k, &p) in column.positions.iter().enumerate() {
                let Weight {
                    weight: w,
                    centre: i,
                    ..
                } = weights[c][k];
                if w > 0.0 {
                    let slot = &mut clump_centres[i][k];
                    slot.0 += p * w;
                    slot.1 += w;
                }
            }
        }
    }
    for (c, column) in mesh.columns.iter().enumerate() {
        for (k, &p) in column.positions.iter().enumerate().skip(1) {
            let Weight {
                weight: w,
                centre: i,
                motion,
            } = weights[c][k];
            if w <= 0.0 {
                continue;
            }
            let root = column.positions[0];
            target[c][k] = match dab.kind {
                BrushKind::Comb => p + motion * w,
                // Toward (or onto) the scalp's normal, by a share of the vertex's height.
                BrushKind::Puff => p + normals[c] * (sign * w * STEP_SHARE * p.distance(root)),
                BrushKind::Smooth => {
                    // Along the column and across its layer's face edges, each once.
                    let here = VertexRef {
                        column: c as u32,
                        layer: k as u32,
                    };
                    let neighbours: BTreeSet<VertexRef> = vertex_neighbours(mesh, topology, here)
                        .into_iter()
                        .collect();
                    let sum: DVec3 = neighbours.iter().filter_map(|&n| mesh.position(n)).sum();
                    p.lerp(sum / neighbours.len().max(1) as f64, 0.5 * w)
                }
                BrushKind::Clump => {
                    let (sum, total) = clump_centres[i][k];
                    let toward = sum / total - p;
                    let pull = (sign * w * 0.5).max(-step / toward.length().max(1e-12));
                    p + toward * pull
                }
                // Away from the stroke's line, across it and along the scalp: the side is
                // the root's, so a whole strand goes one way.
                BrushKind::Part => {
                    let across = motion
                        .cross(normals[c])
                        .try_normalize()
                        .unwrap_or(DVec3::ZERO);
                    // A root on the line itself stays (f64::signum would send it right).
                    let offset = (root - centres[i].0).dot(across);
                    let side = if offset.abs() <= 1e-9 {
                        0.0
                    } else {
                        offset.signum()
                    };
                    p + across * (side * w * step)
                }
                BrushKind::Length => p,
            };
        }
    }
    // Walk each touched column from the root, segment lengths kept (or scaled).
    for (c, column) in mesh.columns.iter().enumerate() {
        let column_weight = weights[c].iter().map(|w| w.weight).fold(0.0, f64::max);
        if column_weight <= 0.0 {
            continue;
        }
        let scale = match dab.kind {
            BrushKind::Length => 1.0 + sign * column_weight * LENGTH_STEP,
            _ => 1.0,
        };
        for k in 1..column.positions.len() {
            let before = column.positions[k] - column.positions[k - 1];
            let length = (before.length() * scale).max(MIN_SEGMENT_M.min(before.length()));
            let direction = (target[c][k] - target[c][k - 1])
                .try_normalize()
                .or_else(|| before.try_normalize())
                .unwrap_or(DVec3::Y);
            target[c][k] = target[c][k - 1] + direction * length;
        }
    }
    target
}

/// How a dab acts on one vertex.
#[derive(Clone, Copy, Debug, Default)]
struct Weight {
    /// Falloff × strength of the stronger centre (0: untouched).
    weight: f64,
    /// That centre (0: the brush, 1: its mirror image).
    centre: usize,
    /// The comb's motion here: the centres' motions weighted by their falloff.
    motion: DVec3,
}

/// `share` of the way from a column's `old` positions to its `target` ones, walked from the
/// root so each segment takes its length in between (a straight blend of the points would
/// shorten every segment that turns).
fn blend_column(old: &[DVec3], target: &[DVec3], share: f64, out: &mut [DVec3]) {
    for k in 1..out.len().min(old.len()).min(target.len()) {
        let old_segment = old[k] - old[k - 1];
        let length = old_segment.length()
            + share * ((target[k] - target[k - 1]).length() - old_segment.length());
        let direction = (old[k].lerp(target[k], share) - out[k - 1])
            .try_normalize()
            .or_else(|| old_segment.try_normalize())
            .unwrap_or(DVec3::Y);
        out[k] = out[k - 1] + direction * length;
    }
}

/// The segments `(column, upper layer)` shorter than [`MIN_SEGMENT_M`]: a layer collapsing
/// onto the one below (hair cut to nothing, or vertices crowded against the body).
fn short_segments(mesh: &HairMesh) -> BTreeSet<(usize, usize)> {
    let mut short = BTreeSet::new();
    for (c, column) in mesh.columns.iter().enumerate() {
        for (k, s) in column.positions.windows(2).enumerate() {
            // A hair's breadth of tolerance: a cut to exactly the floor may round under it.
            if s[0].distance(s[1]) < MIN_SEGMENT_M * 0.999 {
                short.insert((c, k + 1));
            }
        }
    }
    short
}

/// The hair vertices (layer ≥ 1) deeper inside the body than [`INSIDE_TOLERANCE_M`].
fn inside_body(mesh: &HairMesh, body: &BodySdf) -> BTreeSet<(usize, usize)> {
    if body.is_empty() {
        return BTreeSet::new();
    }
    let mut inside = BTreeSet::new();
    for (c, column) in mesh.columns.iter().enumerate() {
        for (k, &p) in column.positions.iter().enumerate().skip(1) {
            if body.distance_m(p) < -INSIDE_TOLERANCE_M {
                inside.insert((c, k));
            }
        }
    }
    inside
}

/// Pushes each non-root vertex of `columns` that lies inside the body (or within the
/// margin of its surface) back out along the distance field's gradient.
fn keep_outside(mesh: &mut HairMesh, body: &BodySdf, columns: &BTreeSet<usize>) {
    if body.is_empty() {
        return;
    }
    for &c in columns {
        for p in mesh.columns[c].positions.iter_mut().skip(1) {
            let (distance, gradient) = body.distance_and_gradient(*p);
            if distance < BODY_MARGIN_M
                && let Some(out) = gradient.try_normalize()
            {
                *p += out * (BODY_MARGIN_M - distance);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::samples::{grid_scalp, sphere_body, sphere_cap, straight_layers};
    use crate::strands::random::SplitMix64;

    const RADIUS_M: f64 = 0.1;

    /// A cap of hair on a sphere head, symmetric across x = 0, and the head's field.
    fn head() -> (HairMesh, BodySdf) {
        let body = sphere_body(RADIUS_M, 24, 48);
        let mesh = sphere_cap(RADIUS_M, 0.9, 6, 4, 0.02);
        let sdf = BodySdf::for_hair(&body, &mesh);
        (mesh, sdf)
    }

    fn dab(kind: BrushKind, centre: DVec3, radius_m: f64) -> BrushDab {
        BrushDab {
            kind,
            centre_m: centre.to_array(),
            radius_m,
            strength: 1.0,
            invert: false,
            motion_m: [0.0; 3],
            view_direction: None,
            mirror_x: false,
            mirror_plane_x: 0.0,
        }
    }

    fn column_length(mesh: &HairMesh, c: usize) -> f64 {
        let p = &mesh.columns[c].positions;
        p.windows(2).map(|s| s[0].distance(s[1])).sum()
    }

    /// Random strokes of every brush, mirrored or not, strong and weak, from any side: the
    /// mesh stays valid, no layer turns over or collapses, and no hair vertex goes inside
    /// the head.
    #[test]
    fn random_strokes_keep_the_mesh_valid_unturned_and_outside_the_body() {
        let (mut mesh, sdf) = head();
        let mut random = SplitMix64::new(7);
        let mut acted = 0;
        for step in 0..300 {
            let kind = BrushKind::ALL[(random.next_u64() as usize) % BrushKind::ALL.len()];
            let c = (random.next_u64() as usize) % mesh.columns.len();
            let column = &mesh.columns[c].positions;
            let on = column[(random.next_u64() as usize) % column.len()];
            let mut unit = || 2.0 * random.next_f64() - 1.0;
            let d = BrushDab {
                kind,
                centre_m: (on + DVec3::new(unit(), unit(), unit()) * 0.01).to_array(),
                radius_m: 0.01 + 0.05 * unit().abs(),
                strength: unit().abs(),
                invert: unit() < 0.0,
                motion_m: (DVec3::new(unit(), unit(), unit()) * 0.03).to_array(),
                view_direction: (unit() < 0.0)
                    .then(|| DVec3::new(unit(), unit(), unit()).normalize().to_array()),
                mirror_x: unit() < 0.0,
                mirror_plane_x: 0.0,
            };
            let outcome = apply_brush(&mesh, &sdf, &d).unwrap_or_else(|e| panic!("{step}: {e}"));
            if !outcome.affected_bundles.is_empty() {
                acted += 1;
            }
            mesh = outcome.mesh;
            mesh.validate().expect("valid");
            assert_eq!(turned_layers(&mesh), Vec::new(), "dab {step} ({kind:?})");
            assert_eq!(
                short_segments(&mesh),
                BTreeSet::new(),
                "dab {step} ({kind:?})"
            );
            for (c, column) in mesh.columns.iter().enumerate() {
                for (k, &p) in column.positions.iter().enumerate().skip(1) {
                    let distance = sdf.distance_m(p);
                    assert!(
                        distance > -INSIDE_TOLERANCE_M,
                        "dab {step} ({kind:?}): column {c} layer {k} is {distance} m inside the head"
                    );
                }
            }
        }
        assert!(acted > 150, "only {acted} of 300 dabs acted");
    }

    /// Combing turns hair without stretching it: every strand keeps its length.
    #[test]
    fn comb_keeps_every_strand_length_and_follows_the_motion() {
        let (mesh, _) = head();
        let before: Vec<f64> = (0..mesh.columns.len())
            .map(|c| column_length(&mesh, c))
            .collect();
        let top = mesh.columns[(mesh.columns.len() - 1) / 2].positions[4];
        let mut d = dab(BrushKind::Comb, top, 0.05);
        d.motion_m = [0.02, 0.0, 0.0];
        let outcome = apply_brush(&mesh, &BodySdf::empty(), &d).expect("comb");
        assert!(!outcome.affected_bundles.is_empty());
        let mut moved_x = 0.0;
        for (c, column) in outcome.mesh.columns.iter().enumerate() {
            let length = column_length(&outcome.mesh, c);
            assert!(
                (length - before[c]).abs() < 1e-9 * before[c].max(1.0),
                "column {c}: {length} after {}",
                before[c]
            );
            moved_x += column.positions[4].x - mesh.columns[c].positions[4].x;
        }
        assert!(moved_x > 0.01, "the tips moved along the comb: {moved_x}");
    }

    /// With X-mirror, a dab on one side of the head acts the same on the other.
    #[test]
    fn a_mirrored_dab_acts_the_same_on_both_sides() {
        let (mesh, sdf) = head();
        for kind in BrushKind::ALL {
            let tip = mesh.columns[1].positions[4];
            let mut d = dab(kind, tip, 0.04);
            d.motion_m = [0.01, -0.005, 0.004];
            d.mirror_x = true;
            d.strength = 0.7;
            let out = apply_brush(&mesh, &sdf, &d).expect("dab").mesh;
            assert_ne!(out, mesh, "{kind:?} acted");
            assert_mirror_symmetric(&out, &format!("{kind:?}"));
            // A dab on the plane itself, combing sideways: the two sides' motions cancel
            // there (no parting, nothing crossing) and the result stays symmetric.
            let mut on_plane = d;
            on_plane.centre_m[0] = 0.0;
            let out = apply_brush(&mesh, &sdf, &on_plane).expect("dab").mesh;
            assert_ne!(out, mesh, "{kind:?} on the plane acted");
            assert_mirror_symmetric(&out, &format!("{kind:?} on the plane"));
        }
    }

    /// Each column's positions mirror those of the column whose root is nearest its root's
    /// mirror image across x = 0.
    fn assert_mirror_symmetric(mesh: &HairMesh, what: &str) {
        for (c, column) in mesh.columns.iter().enumerate() {
            let root = column.positions[0];
            let m = DVec3::new(-root.x, root.y, root.z);
            let image = (0..mesh.columns.len())
                .min_by(|&a, &b| {
                    let da = mesh.columns[a].positions[0].distance(m);
                    da.total_cmp(&mesh.columns[b].positions[0].distance(m))
                })
                .expect("a column");
            for (k, p) in column.positions.iter().enumerate() {
                let q = mesh.columns[image].positions[k];
                let mirrored = DVec3::new(-q.x, q.y, q.z);
                assert!(
                    p.distance(mirrored) < 1e-6,
                    "{what}: column {c} layer {k} at {p} and its image at {q}"
                );
            }
        }
    }

    /// A part stroke along the head's centre line sends each side's hair away from it: the
    /// tips on the right move right, those on the left move left, as mirror images.
    #[test]
    fn a_part_along_the_centre_sends_each_side_away_from_it() {
        let (mesh, sdf) = head();
        let mut out = mesh.clone();
        for i in 0..8 {
            let z = -0.04 + 0.01 * i as f64;
            let top = DVec3::new(0.0, (RADIUS_M * RADIUS_M - z * z).sqrt() + 0.08, z);
            let mut d = dab(BrushKind::Part, top, 0.06);
            d.motion_m = [0.0, 0.0, 0.01];
            d.mirror_x = true;
            out = apply_brush(&out, &sdf, &d).expect("part").mesh;
        }
        let (mut right, mut left) = (0, 0);
        for (c, column) in out.columns.iter().enumerate() {
            let root_x = column.positions[0].x;
            let moved = column.positions[4].x - mesh.columns[c].positions[4].x;
            if root_x > 0.01 && moved > 1e-4 {
                right += 1;
            }
            if root_x < -0.01 && moved < -1e-4 {
                left += 1;
            }
            if root_x > 0.01 {
                assert!(
                    moved > -1e-9,
                    "column {c} on the right moved left by {moved}"
                );
            }
        }
        assert!(right >= 3 && right == left, "{right} right, {left} left");
        assert_mirror_symmetric(&out, "part");
    }

    /// Hair of a removed bundle is hidden: a brush over it leaves it where it was.
    #[test]
    fn a_removed_bundle_is_not_brushed() {
        let (mut mesh, sdf) = head();
        // The cap's corner bundle: its corner column is its own.
        let b = 0;
        mesh.bundles[b].removed = true;
        let topology = Topology::build(&mesh);
        let only_removed: Vec<usize> = mesh.bundles[b]
            .vertices
            .iter()
            .map(|&c| c as usize)
            .filter(|&c| {
                topology.bundles_of_column[c]
                    .iter()
                    .all(|&o| mesh.bundles[o as usize].removed)
            })
            .collect();
        let mut d = dab(
            BrushKind::Comb,
            mesh.columns[only_removed[0]].positions[4],
            0.2,
        );
        d.motion_m = [0.02, 0.0, 0.0];
        let out = apply_brush(&mesh, &sdf, &d).expect("comb");
        assert!(!out.affected_bundles.is_empty(), "the hair around it moved");
        for c in only_removed {
            assert_eq!(out.mesh.columns[c], mesh.columns[c], "column {c}");
        }
    }

    /// Seen from the front, a brush as large as the head leaves the hair whose scalp faces
    /// away alone (it never reaches through the head).
    #[test]
    fn a_front_facing_dab_leaves_the_far_side_alone() {
        let (mesh, sdf) = head();
        let mut d = dab(BrushKind::Comb, DVec3::new(0.0, 0.1, 0.0), 1.0);
        d.motion_m = [0.0, 0.0, 0.02];
        // Looking along −z: the front is +z.
        d.view_direction = Some([0.0, 0.0, -1.0]);
        let out = apply_brush(&mesh, &sdf, &d).expect("comb").mesh;
        let normals = root_normals(&mesh);
        let (mut front, mut back) = (0, 0);
        let topology = Topology::build(&mesh);
        for (c, column) in out.columns.iter().enumerate() {
            // Interior vertices are placed from the whole layer, so only the exterior count.
            let moved = (1..column.positions.len()).any(|k| {
                !mesh.is_interior(&topology, c, k)
                    && column.positions[k] != mesh.columns[c].positions[k]
            });
            if normals[c].z < -FACING_AWAY {
                assert!(!moved, "column {c} faces away but moved");
                back += 1;
            } else if moved {
                front += 1;
            }
        }
        assert!(
            front > 0 && back > 0,
            "{front} moved in front, {back} held behind"
        );
    }

    /// The length brush grows hair by a share per dab and cuts it down to a floor, never to
    /// nothing; puff lifts the tips away from the scalp and flattening brings them back.
    #[test]
    fn length_grows_and_cuts_within_bounds_and_puff_lifts() {
        let (mesh, sdf) = head();
        let c = mesh.columns.len() / 2;
        let tip = mesh.columns[c].positions[4];
        let before = column_length(&mesh, c);
        let grown = apply_brush(&mesh, &sdf, &dab(BrushKind::Length, tip, 0.01)).expect("grow");
        let grown_length = column_length(&grown.mesh, c);
        assert!(grown_length > before * 1.02, "{before} → {grown_length}");
        let mut cut = mesh.clone();
        let mut d = dab(BrushKind::Length, tip, 0.5);
        d.invert = true;
        for _ in 0..200 {
            cut = apply_brush(&cut, &sdf, &d).expect("cut").mesh;
        }
        // The columns on the cap's rim are exterior all the way up: their segments.
        let topology = Topology::build(&cut);
        for (c, column) in cut.columns.iter().enumerate() {
            if !topology.root_boundary[c] {
                continue;
            }
            for s in column.positions.windows(2) {
                assert!(
                    s[0].distance(s[1]) >= MIN_SEGMENT_M * 0.999,
                    "column {c}: {} {} {}",
                    s[0].distance(s[1]),
                    s[0],
                    s[1]
                );
            }
            assert!(
                column_length(&cut, c) < 0.5 * column_length(&mesh, c),
                "column {c} cut: {} of {}",
                column_length(&cut, c),
                column_length(&mesh, c)
            );
        }
        // The cap's hair stands straight out: flattening lays it toward the scalp, and
        // puffing lifts it back up.
        let height = |m: &HairMesh| m.columns[c].positions[4].length();
        let mut flat = dab(BrushKind::Puff, tip, 0.05);
        flat.invert = true;
        let flattened = apply_brush(&mesh, &sdf, &flat).expect("flatten").mesh;
        assert!(height(&flattened) < height(&mesh) - 1e-4);
        let lift = dab(BrushKind::Puff, flattened.columns[c].positions[4], 0.05);
        let puffed = apply_brush(&flattened, &sdf, &lift).expect("puff").mesh;
        assert!(
            height(&puffed) > height(&flattened) + 1e-4,
            "{} → {}",
            height(&flattened),
            height(&puffed)
        );
    }

    /// A comb that would drag one corner of a bundle's tip across the bundle (turning the
    /// tip face over) acts only as far as the face stays the right way up.
    #[test]
    fn a_dab_that_would_turn_a_layer_over_is_held_back() {
        let scalp = grid_scalp(1, 1, |s, t| DVec3::new(0.1 * s, 0.1 * t, 0.0));
        let mesh = straight_layers(scalp, 1, DVec3::Z * 0.3);
        let root = mesh.columns[0].positions[0];
        let corner = mesh.columns[0].positions[1];
        let mut d = dab(BrushKind::Comb, corner, 0.02);
        d.motion_m = [1.0, 1.0, 0.0];
        // The whole dab would turn the tip face over: the segment turned toward the
        // motion, its length kept, lands past the opposite corner.
        let mut whole = mesh.clone();
        whole.columns[0].positions[1] =
            root + (corner + DVec3::new(1.0, 1.0, 0.0) - root).normalize() * 0.3;
        assert_ne!(turned_layers(&whole), Vec::new());
        let outcome = apply_brush(&mesh, &BodySdf::empty(), &d).expect("comb");
        assert_eq!(turned_layers(&outcome.mesh), Vec::new());
        // Held back to a share that keeps the face the right way up: the corner moved.
        let moved = outcome.mesh.columns[0].positions[1];
        assert!(moved.distance(corner) > 1e-3, "the corner moved: {moved}");
        assert!(
            (moved.distance(root) - 0.3).abs() < 1e-9,
            "its segment kept its length"
        );
    }

    /// On every head sample (draped, curled, hanging down the back: layers that bend and
    /// shear), a comb dab on the crown acts — the turn-over check flags flips, not bends —
    /// and leaves no new turned layer.
    #[test]
    fn a_comb_acts_on_every_head_sample() {
        let samples = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/samples");
        let mut checked = 0;
        for entry in std::fs::read_dir(&samples).expect("the samples folder") {
            let path = entry.expect("an entry").path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if !name.starts_with("head_") {
                continue;
            }
            let mesh = crate::io::project::load(&path)
                .unwrap_or_else(|e| panic!("{name}: {e}"))
                .document
                .hair_mesh;
            let (lo, hi) = mesh.bounds().expect("hair");
            let centre = DVec3::new(0.3 * lo.x + 0.7 * hi.x, hi.y, 0.5 * (lo.z + hi.z));
            let mut d = dab(BrushKind::Comb, centre, 0.05);
            d.motion_m = [0.0, 0.0, -0.01];
            d.strength = 0.5;
            // Placing the interior afresh alone (as any edit does) may turn a layer of a
            // sample placed otherwise; the dab adds nothing to that.
            let placed = finish(mesh.clone(), BTreeSet::new(), None)
                .expect("placed")
                .mesh;
            let mut before = turned_layers(&mesh);
            before.extend(turned_layers(&placed));
            let outcome = apply_brush(&mesh, &BodySdf::empty(), &d).expect("comb");
            assert!(
                !outcome.affected_bundles.is_empty(),
                "{name}: the comb acted"
            );
            let after = turned_layers(&outcome.mesh);
            assert!(after.iter().all(|t| before.contains(t)), "{name}");
            // Draped samples fold here and there (a few percent of their layers); a check
            // that flagged bends would flag a third of them.
            let layers: usize = mesh.bundles.iter().map(|b| b.layers as usize).sum();
            assert!(
                before.len() * 10 < layers,
                "{name}: {} of its layers count as turned: the check flags bends",
                before.len()
            );
            checked += 1;
        }
        assert!(checked >= 4, "{checked} head samples");
    }

    #[test]
    fn a_dab_with_a_non_finite_value_is_a_named_error() {
        let (mesh, sdf) = head();
        let mut d = dab(BrushKind::Smooth, DVec3::ZERO, 0.1);
        d.motion_m[1] = f64::NAN;
        let error = apply_brush(&mesh, &sdf, &d).expect_err("NaN");
        assert!(error.to_string().contains("brush motion"), "{error}");
        let mut d = dab(BrushKind::Smooth, DVec3::ZERO, f64::INFINITY);
        d.strength = 0.5;
        assert!(apply_brush(&mesh, &sdf, &d).is_err());
    }
}
