//! Wisps on bundles: a bundle's shape (its centre's path above the root) copied onto
//! others or mirrored across the body's centre, each target keeping its width.

use std::collections::HashMap;

use glam::DVec3;

use crate::edit::{EditError, EditOutcome, check_bundles, finish};
use crate::geometry::frames::layer_frames;
use crate::model::mesh::{Bundle, HairMesh};
use crate::model::styling::{StylingGroup, StylingSet};

/// The centre of a bundle's corners at `layer`.
pub fn bundle_layer_centre(mesh: &HairMesh, bundle: &Bundle, layer: usize) -> Option<DVec3> {
    let points: Option<Vec<DVec3>> = bundle
        .vertices
        .iter()
        .map(|&c| mesh.columns.get(c as usize)?.positions.get(layer).copied())
        .collect();
    let points = points?;
    Some(points.iter().sum::<DVec3>() / points.len().max(1) as f64)
}

/// A right-handed frame at a bundle's root: first edge, its normal-perpendicular, normal.
fn root_frame(mesh: &HairMesh, bundle: &Bundle) -> Option<[DVec3; 3]> {
    let p: Vec<DVec3> = bundle
        .vertices
        .iter()
        .map(|&c| mesh.columns.get(c as usize)?.positions.first().copied())
        .collect::<Option<_>>()?;
    let n = p.len();
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        normal += p[i].cross(p[(i + 1) % n]);
    }
    let normal = normal.try_normalize()?;
    let edge = (p[1] - p[0])
        .reject_from_normalized(normal)
        .try_normalize()?;
    Some([edge, normal.cross(edge), normal])
}

/// The unit direction a bundle grows in at its top: from the centre of the layer below to
/// the top centre, or the root face's normal for a bare bundle.
pub fn growth_direction(mesh: &HairMesh, bundle: &Bundle) -> Option<DVec3> {
    match bundle.layers as usize {
        0 => root_frame(mesh, bundle).map(|[_, _, normal]| normal),
        top => (bundle_layer_centre(mesh, bundle, top)?
            - bundle_layer_centre(mesh, bundle, top - 1)?)
        .try_normalize(),
    }
}

/// The path of a bundle's centre above its root, layer by layer (`offsets[k-1]` is layer k).
pub(crate) fn centre_path(mesh: &HairMesh, bundle: &Bundle) -> Option<Vec<DVec3>> {
    let root = bundle_layer_centre(mesh, bundle, 0)?;
    (1..=bundle.layers as usize)
        .map(|k| Some(bundle_layer_centre(mesh, bundle, k)? - root))
        .collect()
}

/// `d`'s coordinates in `frame` (tangent, bitangent, normal).
fn to_frame([t, b, n]: [DVec3; 3], d: DVec3) -> DVec3 {
    DVec3::new(d.dot(t), d.dot(b), d.dot(n))
}

/// A direction reflected across a plane `x = const` (no offset: directions have none).
fn reflect_direction(d: DVec3) -> DVec3 {
    DVec3::new(-d.x, d.y, d.z)
}

/// How each corner of a bundle moves away from its own root, layer by layer
/// (`[corner][k - 1]` is layer k), in the bundle's root frame.
fn corner_paths_local(
    mesh: &HairMesh,
    bundle: &Bundle,
    frame: [DVec3; 3],
) -> Option<Vec<Vec<DVec3>>> {
    bundle
        .vertices
        .iter()
        .map(|&c| {
            let positions = &mesh.columns.get(c as usize)?.positions;
            let root = *positions.first()?;
            (1..=bundle.layers as usize)
                .map(|k| Some(to_frame(frame, *positions.get(k)? - root)))
                .collect()
        })
        .collect()
}

/// Wisp copy / paste (the key-strand copy of Zhang & Wünsche's framework, on bundles):
/// gives every target the whole shape of `source` — its layer count, and each corner's path
/// away from its root (so the source's spread, taper and twist come along), turned from the
/// source's root frame into each target's and started from each target's own roots. When a
/// target has another corner count (a triangle onto a quad), its corners follow the source
/// centre's path instead. A column shared by several targets takes the mean of what they
/// ask for; columns grow or shrink with the layer counts.
pub fn paste_shape(
    mesh: &HairMesh,
    source: u32,
    targets: &[u32],
) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, &[source])?;
    check_bundles(mesh, targets)?;
    let source_bundle = &mesh.bundles[source as usize];
    let Some(source_frame) = root_frame(mesh, source_bundle) else {
        return Err(EditError::NotFinite {
            what: "source root frame (degenerate root face)",
            value: format!("bundle {source}"),
        });
    };
    let out_of_range = EditError::BundleOutOfRange {
        index: source,
        count: mesh.bundles.len(),
    };
    let centre_local: Vec<DVec3> = centre_path(mesh, source_bundle)
        .ok_or(out_of_range.clone())?
        .iter()
        .map(|&d| to_frame(source_frame, d))
        .collect();
    let corners_local =
        corner_paths_local(mesh, source_bundle, source_frame).ok_or(out_of_range)?;
    let layers = source_bundle.layers as usize;
    let mut targets: Vec<u32> = targets.iter().copied().filter(|&t| t != source).collect();
    targets.sort_unstable();
    targets.dedup();
    if targets.is_empty() {
        return Err(EditError::EmptySelection);
    }
    // Each target's corner paths in object space (`None`: a degenerate root face, left alone).
    let wanted: Vec<(u32, usize, Vec<Vec<DVec3>>)> = targets
        .iter()
        .filter_map(|&t| {
            let bundle = &mesh.bundles[t as usize];
            let [t1, b1, n1] = root_frame(mesh, bundle)?;
            let to_object = |l: &DVec3| t1 * l.x + b1 * l.y + n1 * l.z;
            let same_corners = bundle.vertices.len() == source_bundle.vertices.len();
            let paths = (0..bundle.vertices.len())
                .map(|i| {
                    let local = if same_corners {
                        &corners_local[i]
                    } else {
                        &centre_local
                    };
                    local.iter().map(to_object).collect()
                })
                .collect();
            Some((t, layers, paths))
        })
        .collect();
    set_shapes(mesh, &wanted)
}

/// Gives each `(target, layers, paths)` of `wanted` `layers` layers and puts its corner `i`
/// at layer `k` at its own root plus `paths[i][k - 1]` (object space). A column shared by
/// several targets takes the mean of what they ask for; columns grow or shrink with the
/// layer counts.
fn set_shapes(
    mesh: &HairMesh,
    wanted: &[(u32, usize, Vec<Vec<DVec3>>)],
) -> Result<EditOutcome, EditError> {
    let mut out = mesh.clone();
    for (t, layers, _) in wanted {
        out.bundles[*t as usize].layers = *layers as u32;
    }
    // Columns long enough for the new layer counts (trimmed back below where they shrank).
    let topology = crate::Topology::build(&out);
    let old_lengths: Vec<usize> = out.columns.iter().map(|c| c.positions.len()).collect();
    for (t, _, _) in wanted {
        for &c in &out.bundles[*t as usize].vertices.clone() {
            let required = out.required_column_len(&topology, c as usize);
            let column = &mut out.columns[c as usize];
            while column.positions.len() < required {
                let (last, last_w) = (
                    *column.positions.last().unwrap_or(&DVec3::ZERO),
                    *column.w.last().unwrap_or(&0.0),
                );
                column.positions.push(last);
                column.w.push(last_w);
            }
        }
    }
    let mut sums: HashMap<(u32, usize), (DVec3, f64)> = HashMap::new();
    for (t, _, paths) in wanted {
        for (&c, path) in mesh.bundles[*t as usize].vertices.iter().zip(paths) {
            let root = mesh.columns[c as usize].positions[0];
            for (k, offset) in path.iter().enumerate() {
                let entry = sums.entry((c, k + 1)).or_insert((DVec3::ZERO, 0.0));
                entry.0 += root + *offset;
                entry.1 += 1.0;
            }
        }
    }
    for ((c, layer), (sum, count)) in sums {
        let p = sum / count;
        if !p.is_finite() {
            return Err(EditError::NotFinite {
                what: "pasted position",
                value: p.to_string(),
            });
        }
        out.columns[c as usize].positions[layer] = p;
    }
    // New vertices' w continues their column by path length (kept as is in manual w mode
    // afterwards, recomputed otherwise).
    for (column, &old) in out.columns.iter_mut().zip(&old_lengths) {
        for k in old.max(1)..column.positions.len() {
            column.w[k] = column.w[k - 1] + column.positions[k].distance(column.positions[k - 1]);
        }
    }
    crate::edit::fit_column_lengths(&mut out);
    finish(out, wanted.iter().map(|(t, _, _)| *t).collect(), None)
}

/// The bundle whose root centre is nearest to `point` (visible bundles only).
fn nearest_bundle(mesh: &HairMesh, point: DVec3) -> Option<u32> {
    mesh.bundles
        .iter()
        .enumerate()
        .filter(|(_, b)| !b.removed)
        .filter_map(|(i, b)| Some((i as u32, bundle_layer_centre(mesh, b, 0)?.distance(point))))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// Wisp mirror: each source bundle's whole shape (layer count and every corner's path),
/// reflected across the plane `x = plane_x`, onto the bundle whose root lies nearest the
/// source root's mirror image; each target corner follows the source corner whose reflected
/// root is nearest (the centre's path when the corners do not pair up). Returns the outcome
/// and the `(source, target)` pairs, in source order.
pub fn mirror_shape(
    mesh: &HairMesh,
    sources: &[u32],
    plane_x: f64,
) -> Result<(EditOutcome, Vec<(u32, u32)>), EditError> {
    check_bundles(mesh, sources)?;
    if !plane_x.is_finite() {
        return Err(EditError::NotFinite {
            what: "mirror plane",
            value: plane_x.to_string(),
        });
    }
    let reflect = |p: DVec3| DVec3::new(2.0 * plane_x - p.x, p.y, p.z);
    let root_of = |c: u32| mesh.columns[c as usize].positions[0];
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    let mut wanted: Vec<(u32, usize, Vec<Vec<DVec3>>)> = Vec::new();
    for &s in sources {
        let bundle = &mesh.bundles[s as usize];
        let Some(root) = bundle_layer_centre(mesh, bundle, 0) else {
            continue;
        };
        let Some(t) = nearest_bundle(mesh, reflect(root)) else {
            continue;
        };
        if pairs.iter().any(|&(_, existing)| existing == t) {
            continue;
        }
        let target = &mesh.bundles[t as usize];
        let Some(centre) = centre_path(mesh, bundle) else {
            continue;
        };
        // Target corner j ← the source corner whose reflected root is nearest.
        let partner: Vec<usize> = target
            .vertices
            .iter()
            .map(|&tc| {
                (0..bundle.vertices.len())
                    .min_by(|&a, &b| {
                        let distance =
                            |i: usize| reflect(root_of(bundle.vertices[i])).distance(root_of(tc));
                        distance(a).total_cmp(&distance(b))
                    })
                    .unwrap_or(0)
            })
            .collect();
        let paired = target.vertices.len() == bundle.vertices.len()
            && (0..partner.len()).all(|j| !partner[..j].contains(&partner[j]));
        let paths = partner
            .iter()
            .map(|&i| {
                let column = &mesh.columns[bundle.vertices[i] as usize].positions;
                (1..=bundle.layers as usize)
                    .map(|k| {
                        let d = if paired {
                            column[k] - column[0]
                        } else {
                            centre[k - 1]
                        };
                        reflect_direction(d)
                    })
                    .collect()
            })
            .collect();
        pairs.push((s, t));
        wanted.push((t, bundle.layers as usize, paths));
    }
    if wanted.is_empty() {
        return Err(EditError::EmptySelection);
    }
    Ok((set_shapes(mesh, &wanted)?, pairs))
}

/// Mirror copies group styling too: each target takes its source's styling group, turned
/// so the mirrored bundle is the mirror image of its source, not only in shape. A source on
/// the global parameters sends its target back to them (the artist grouped nothing). A
/// grouped source's parameters are turned through how the target's styling frame (û, v̂ at
/// the root) sits against the reflected source frame: the 2×2 map `M` from the source's
/// (û, v̂) coordinates to the target's decides. When `det M < 0` the reflection reverses
/// handedness, so a curl and a twist that are on turn the other way; an active wave's
/// direction is mapped through `M`. Noise, frizz and clump are random or isotropic in
/// (û, v̂) and copy as they are. The target joins a group `"<source group> (mirrored)"`
/// holding exactly those parameters (reused when one exists: mirroring twice makes no new
/// group), or the source's own group when nothing turned.
pub fn mirror_styling(styling: &StylingSet, mesh: &HairMesh, pairs: &[(u32, u32)]) -> StylingSet {
    let frames = layer_frames(mesh, 0);
    // A bundle's root frame: its corners' û and v̂ averaged.
    let root_axes = |b: u32| -> Option<(DVec3, DVec3)> {
        let bundle = mesh.bundles.get(b as usize)?;
        let (mut u, mut v) = (DVec3::ZERO, DVec3::ZERO);
        for &c in &bundle.vertices {
            let frame = frames.get(c as usize).copied().flatten()?;
            u += frame.u;
            v += frame.v;
        }
        Some((u.try_normalize()?, v.try_normalize()?))
    };
    let mut out = styling.clone();
    for &(s, t) in pairs {
        if s == t {
            continue;
        }
        let Some(source_group) = styling.group_of(s) else {
            let _ = out.assign(&[t], None);
            continue;
        };
        let (Some((su, sv)), Some((tu, tv))) = (root_axes(s), root_axes(t)) else {
            continue;
        };
        let (su, sv) = (reflect_direction(su), reflect_direction(sv));
        // The target's (û, v̂) coordinates of the reflected source axes. û and v̂ need not be
        // orthogonal: solve for them through the target's dual basis.
        let (uu, uv, vv) = (tu.dot(tu), tu.dot(tv), tv.dot(tv));
        let det_t = uu * vv - uv * uv;
        if det_t.abs() < 1e-12 {
            continue;
        }
        let coords = |d: DVec3| {
            let (du, dv) = (d.dot(tu), d.dot(tv));
            ((vv * du - uv * dv) / det_t, (uu * dv - uv * du) / det_t)
        };
        let (m00, m10) = coords(su);
        let (m01, m11) = coords(sv);
        let flips = m00 * m11 - m01 * m10 < 0.0;
        let source = &styling.groups[source_group];
        let mut params = source.params.clone();
        if flips && params.curl.radius_m > 0.0 {
            params.curl.turns_per_m = -params.curl.turns_per_m;
        }
        if flips && params.twist.turns_per_m != 0.0 {
            params.twist.turns_per_m = -params.twist.turns_per_m;
        }
        let alpha = params.wave.direction_rad;
        let mapped = (
            m00 * alpha.cos() + m01 * alpha.sin(),
            m10 * alpha.cos() + m11 * alpha.sin(),
        );
        if params.wave.amplitude_m > 0.0 && mapped.0.hypot(mapped.1) > 1e-9 {
            // Rounded so that mirroring back gives the same group, not a new near-twin.
            params.wave.direction_rad = (mapped.1.atan2(mapped.0) * 1e9).round() / 1e9;
        }
        let group = if params == source.params {
            source_group
        } else {
            let name = format!("{} (mirrored)", source.name);
            out.groups
                .iter()
                .position(|g| g.name == name && g.params == params)
                .unwrap_or_else(|| {
                    out.groups.push(StylingGroup {
                        name,
                        bundles: Vec::new(),
                        params,
                    });
                    out.groups.len() - 1
                })
        };
        let group = Some(group);
        // The group exists (just found or made): assigning cannot fail.
        let _ = out.assign(&[t], group);
    }
    out
}
