//! Wisps on bundles: a bundle's shape (its centre's path above the root) copied onto
//! others or mirrored across the body's centre, each target keeping its width.

use std::collections::{BTreeSet, HashMap};

use glam::DVec3;

use crate::edit::{EditError, EditOutcome, check_bundles, finish};
use crate::model::mesh::{Bundle, HairMesh};

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

/// Moves the target bundles' centre paths to `path_of(target)` (layer k's centre offset
/// from the root centre), keeping each target's own cross-section around its centre. A
/// column shared by several targets takes the mean of what they ask for.
fn set_centre_paths(
    mesh: &HairMesh,
    targets: &[u32],
    path_of: impl Fn(u32, &Bundle) -> Option<Vec<DVec3>>,
) -> Result<EditOutcome, EditError> {
    let mut sums: HashMap<(u32, usize), (DVec3, f64)> = HashMap::new();
    for &t in targets {
        let bundle = &mesh.bundles[t as usize];
        let Some(path) = path_of(t, bundle) else {
            continue;
        };
        let Some(root) = bundle_layer_centre(mesh, bundle, 0) else {
            continue;
        };
        let layers = (bundle.layers as usize).min(path.len());
        for (k, offset) in path.iter().enumerate().take(layers) {
            let layer = k + 1;
            let Some(centre) = bundle_layer_centre(mesh, bundle, layer) else {
                continue;
            };
            for &c in &bundle.vertices {
                let p = mesh.columns[c as usize].positions[layer];
                let entry = sums.entry((c, layer)).or_insert((DVec3::ZERO, 0.0));
                entry.0 += root + *offset + (p - centre);
                entry.1 += 1.0;
            }
        }
    }
    let mut out = mesh.clone();
    let mut layers = BTreeSet::new();
    for ((c, layer), (sum, count)) in sums {
        let p = sum / count;
        if !p.is_finite() {
            return Err(EditError::NotFinite {
                what: "pasted position",
                value: p.to_string(),
            });
        }
        out.columns[c as usize].positions[layer] = p;
        layers.insert(layer);
    }
    let layers: Vec<usize> = layers.into_iter().collect();
    finish(out, targets.iter().copied().collect(), Some(&layers))
}

/// Wisp copy / paste (the key-strand copy of Zhang & Wünsche's framework, on bundles):
/// gives every target the shape of `source` — its centre's path above the root, turned
/// from the source's root frame into each target's — keeping each target's own width.
/// Layers beyond the shorter of the two bundles are left alone.
pub fn paste_shape(
    mesh: &HairMesh,
    source: u32,
    targets: &[u32],
) -> Result<EditOutcome, EditError> {
    check_bundles(mesh, &[source])?;
    check_bundles(mesh, targets)?;
    let source_bundle = &mesh.bundles[source as usize];
    let path = centre_path(mesh, source_bundle).ok_or(EditError::BundleOutOfRange {
        index: source,
        count: mesh.bundles.len(),
    })?;
    let Some([t0, b0, n0]) = root_frame(mesh, source_bundle) else {
        return Err(EditError::NotFinite {
            what: "source root frame (degenerate root face)",
            value: format!("bundle {source}"),
        });
    };
    let local: Vec<DVec3> = path
        .iter()
        .map(|d| DVec3::new(d.dot(t0), d.dot(b0), d.dot(n0)))
        .collect();
    set_centre_paths(mesh, targets, |_, bundle| {
        let [t, b, n] = root_frame(mesh, bundle)?;
        Some(local.iter().map(|l| t * l.x + b * l.y + n * l.z).collect())
    })
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

/// Wisp mirror: each source bundle's shape, reflected across the plane `x = plane_x`,
/// onto the bundle whose root lies nearest the source root's mirror image. Returns the
/// outcome and the mirrored bundles, in source order.
pub fn mirror_shape(
    mesh: &HairMesh,
    sources: &[u32],
    plane_x: f64,
) -> Result<(EditOutcome, Vec<u32>), EditError> {
    check_bundles(mesh, sources)?;
    if !plane_x.is_finite() {
        return Err(EditError::NotFinite {
            what: "mirror plane",
            value: plane_x.to_string(),
        });
    }
    let reflect = |p: DVec3| DVec3::new(2.0 * plane_x - p.x, p.y, p.z);
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    for &s in sources {
        let bundle = &mesh.bundles[s as usize];
        let Some(root) = bundle_layer_centre(mesh, bundle, 0) else {
            continue;
        };
        if let Some(t) = nearest_bundle(mesh, reflect(root))
            && !pairs.iter().any(|&(_, existing)| existing == t)
        {
            pairs.push((s, t));
        }
    }
    let targets: Vec<u32> = pairs.iter().map(|&(_, t)| t).collect();
    if targets.is_empty() {
        return Err(EditError::EmptySelection);
    }
    let outcome = set_centre_paths(mesh, &targets, |t, _| {
        let &(s, _) = pairs.iter().find(|&&(_, target)| target == t)?;
        let path = centre_path(mesh, &mesh.bundles[s as usize])?;
        // A direction reflects without the plane's offset.
        Some(path.iter().map(|d| DVec3::new(-d.x, d.y, d.z)).collect())
    })?;
    Ok((outcome, targets))
}
