//! Fitting an editable hair mesh and its styling to a groom made elsewhere (strands read by
//! [`crate::io::groom_in`]): the inverse of strand generation.
//!
//! 1. **Scalp.** The artist's scalp (a glTF mesh or a project's root layer), or one built
//!    from the roots ([`scalp::scalp_from_roots`]).
//! 2. **Bundles.** Each root goes to the scalp face closest to it, at the face coordinates a
//!    generated strand would have there; faces that hold roots become bundles of `layers`
//!    layers, the rest stay bare scalp. A root farther from the scalp than
//!    `max_root_distance_relative` of the groom's size is an error that names it.
//! 3. **Columns.** Layer by layer, least squares over the strands ([`columns`]); interior
//!    vertices then go where the editor's rule puts them, so the result edits like a mesh
//!    built by hand.
//! 4. **Density and styling.** Each bundle's density follows its root count per area;
//!    length variation, curl and noise come from what the columns do not explain
//!    ([`styling`]).
//!
//! [`measure`] scores the result against the input (closest-point distances both ways,
//! root placement, strand length). Everything is deterministic: threads split the strands
//! into fixed chunks and their sums are added in chunk order.

pub mod columns;
pub mod measure;
pub mod scalp;
pub mod styling;

use std::ops::ControlFlow;
use std::time::Instant;

use glam::DVec3;

use crate::geometry::curve::FaceCoord;
use crate::io::groom_in::InputGroom;
use crate::model::document::{BodyMesh, Document};
use crate::model::mesh::{HairMesh, Topology};
use scalp::{RootHit, ScalpQuery};

/// How to fit.
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// Layers of every bundle that grows hair.
    pub layers: u32,
    /// Faces of a scalp built from the roots (when no scalp is given); 0 picks one face per
    /// `32` strands, between 64 and 4096.
    pub scalp_faces: usize,
    /// Roots farther than this share of the groom's box diagonal from the scalp are errors.
    pub max_root_distance_relative: f64,
    /// Worker threads (0: as many as the machine has).
    pub threads: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            layers: 12,
            scalp_faces: 0,
            max_root_distance_relative: 0.05,
            threads: 0,
        }
    }
}

/// Why a fit failed.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    #[error("the scalp has no faces")]
    EmptyScalp,
    #[error(
        "curve {curve}'s root is {distance:.4} from the scalp, more than {limit:.4} ({share:.1} % of the groom's size): is this the right scalp, at the right scale?"
    )]
    RootFarFromScalp {
        curve: usize,
        distance: f64,
        limit: f64,
        share: f64,
    },
    #[error("{0} layers: choose 1 to 64")]
    Layers(u32),
    #[error("{0} scalp faces: choose at most {MAX_SCALP_FACES}")]
    ScalpFaces(usize),
    #[error("fitting was cancelled")]
    Cancelled,
    #[error("the fitted hair mesh is invalid: {0}")]
    Invalid(String),
}

/// Most faces of a scalp built from the roots (a lattice of this many is built and
/// triangulated; far more than the 4096 the automatic choice goes up to).
pub const MAX_SCALP_FACES: usize = 1 << 18;

/// Where the scalp comes from.
pub enum ScalpSource {
    /// A hair mesh whose root layer is the scalp (its layers are ignored), and the body to
    /// keep with it.
    Given { scalp: HairMesh, body: BodyMesh },
    /// Built from the roots.
    FromRoots,
}

/// A fitted groom: the document, where each input root went, and the time each step took.
pub struct Fitted {
    pub document: Document,
    pub hits: Vec<RootHit>,
    pub strands_per_bundle: u32,
    /// Interior vertices locked where the strands put them (see [`keep_interior_fit`]).
    pub locked_interior: usize,
    pub timings_s: Vec<(&'static str, f64)>,
}

/// Progress of a fit: the step and its fraction; break to cancel.
pub type FitProgress<'a> = dyn FnMut(&str, f64) -> ControlFlow<()> + 'a;

/// A groom point (f32, as files hold them) in the fit's f64.
pub(crate) fn to_d(p: [f32; 3]) -> DVec3 {
    DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
}

fn thread_count(options: &FitOptions) -> usize {
    if options.threads > 0 {
        options.threads
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    }
}

/// Items per chunk of the fit's parallel loops: fixed, so that sums made per chunk and
/// added in chunk order do not depend on the thread count.
const CHUNK: usize = 2048;

/// [`crate::parallel::in_chunks`] with the fit's fixed chunk size.
fn in_chunks<T: Send>(
    count: usize,
    threads: usize,
    work: impl Fn(std::ops::Range<usize>) -> T + Sync,
) -> Vec<T> {
    crate::parallel::in_chunks(count, CHUNK, threads, work)
}

/// Strands measured to choose between a curl found only against the strands' own axes and
/// none (a tenth of `measure`'s default: enough to tell them apart).
const COMPARE_STRANDS: usize = 2000;

/// Fits a hair mesh and styling to `groom` (see the module comment).
pub fn fit(
    groom: &InputGroom,
    scalp: ScalpSource,
    name: &str,
    options: &FitOptions,
    progress: &mut FitProgress,
) -> Result<Fitted, FitError> {
    if options.layers == 0 || options.layers > 64 {
        return Err(FitError::Layers(options.layers));
    }
    if options.scalp_faces > MAX_SCALP_FACES {
        return Err(FitError::ScalpFaces(options.scalp_faces));
    }
    let threads = thread_count(options);
    let mut timings = Vec::new();
    let mut clock = Instant::now();
    let mut lap = |timings: &mut Vec<(&'static str, f64)>, step: &'static str| {
        timings.push((step, clock.elapsed().as_secs_f64()));
        clock = Instant::now();
    };
    let curves = groom.curve_count();
    let size = groom.diagonal().max(1e-12);
    let roots: Vec<DVec3> = groom.curves().map(|c| to_d(c[0])).collect();
    let (scalp_mesh, body, built) = match scalp {
        ScalpSource::Given { scalp, body } => (root_layer(&scalp), body, false),
        ScalpSource::FromRoots => {
            let faces = if options.scalp_faces > 0 {
                options.scalp_faces
            } else {
                (curves / 32).clamp(64, 4096)
            };
            let outward: DVec3 = groom
                .curves()
                .map(|c| to_d(c[c.len() - 1]) - to_d(c[0]))
                .sum();
            (
                scalp::scalp_from_roots(&roots, faces, outward),
                BodyMesh::default(),
                true,
            )
        }
    };
    lap(&mut timings, "scalp");
    if progress("scalp", 1.0).is_break() {
        return Err(FitError::Cancelled);
    }
    let query = ScalpQuery::new(&scalp_mesh).ok_or(FitError::EmptyScalp)?;
    // Roots onto faces.
    let hits: Vec<RootHit> = in_chunks(curves, threads, |range| {
        range.map(|i| query.hit(roots[i])).collect::<Vec<_>>()
    })
    .into_iter()
    .flatten()
    .collect();
    let limit = options.max_root_distance_relative * size;
    if let Some((curve, hit)) = hits.iter().enumerate().find(|(_, h)| h.distance > limit) {
        return Err(FitError::RootFarFromScalp {
            curve,
            distance: hit.distance,
            limit,
            share: 100.0 * hit.distance / size,
        });
    }
    lap(&mut timings, "roots");
    if progress("roots", 1.0).is_break() {
        return Err(FitError::Cancelled);
    }
    let mut strands_in = vec![0usize; scalp_mesh.bundles.len()];
    for hit in &hits {
        strands_in[hit.face as usize] += 1;
    }
    let mut mesh_of = |strands: &InputGroom| {
        fit_mesh(
            strands,
            &hits,
            &roots,
            &scalp_mesh,
            options.layers,
            threads,
            size,
            progress,
        )
    };
    let first = mesh_of(groom)?;
    lap(&mut timings, "columns");
    // Curly strands: the columns just fitted follow points on the helices, which leaves them
    // zigzagging (longer than the hair's axis) and soaking up part of the curl. Once the curl
    // is known, the columns are fitted again to each strand's axis (its curl averaged away)
    // and the curl is measured against those.
    let min_curl_radius = 1e-3 * size;
    let mut probe = Document::new(name.to_string(), first.mesh.clone());
    let first_curl = styling::fit_curl_styling(
        &mut probe,
        groom,
        &hits,
        &first.reference_lengths,
        min_curl_radius,
        None,
    );
    drop(probe);
    // Locks that coil together (ringlets) leave the mesh's residual nearly curl-free: look
    // for the curl in each strand against its own axis instead.
    let own_axes_curl = match first_curl {
        Some(_) => None,
        None => styling::curl_from_own_axes(groom, min_curl_radius),
    };
    let first_curl = first_curl.or(own_axes_curl);
    let (fitted_mesh, uncurled) = match first_curl {
        Some((turns_per_m, radius_m)) => {
            let axes = mesh_of(&styling::strand_axes(groom, turns_per_m, radius_m))?;
            (axes, own_axes_curl.map(|_| first))
        }
        None => (first, None),
    };
    // The curl scan, and where it found a curl, the columns again on the strands' axes.
    lap(&mut timings, "curl");
    let finish = |fitted_mesh: MeshFit, curl: Option<(f64, f64)>| {
        let MeshFit {
            mut mesh,
            lengths,
            reference_lengths,
            locked,
        } = fitted_mesh;
        // Density: root count per area, relative to the densest tenth of the bundles.
        let areas: Vec<f64> = mesh
            .bundles
            .iter()
            .map(|b| mesh.root_face_area(&b.vertices))
            .collect();
        let mut densities: Vec<f64> = strands_in
            .iter()
            .zip(&areas)
            .filter(|(n, _)| **n > 0)
            .map(|(n, a)| *n as f64 / a.max(1e-300))
            .collect();
        densities.sort_by(f64::total_cmp);
        let reference_density = densities
            .get(((densities.len() as f64) * 0.9) as usize)
            .or(densities.last())
            .copied()
            .unwrap_or(1.0);
        let mut area_sum = 0.0;
        let mut growing = 0usize;
        for ((bundle, &n), &area) in mesh.bundles.iter_mut().zip(&strands_in).zip(&areas) {
            if n > 0 {
                bundle.density = (n as f64 / area.max(1e-300) / reference_density).clamp(0.01, 1.0);
                area_sum += area;
                growing += 1;
            }
        }
        // Strands per bundle that give the input's count over the hair at full density.
        let mean_area = area_sum / growing.max(1) as f64;
        let strands_per_bundle = (reference_density * mean_area).round().clamp(1.0, 4096.0) as u32;
        let source = if built {
            format!("Fitted to {name} (scalp built from its {curves} roots)")
        } else {
            format!("Fitted to {name}")
        };
        let mut document = Document::new(name.to_string(), mesh);
        document.source = source;
        document.body = body.clone();
        styling::fit_styling(&mut document, &lengths, &reference_lengths);
        if let Some((turns_per_m, _)) = curl {
            styling::fit_curl_styling(
                &mut document,
                groom,
                &hits,
                &reference_lengths,
                min_curl_radius,
                Some(turns_per_m),
            );
        }
        document
            .validate()
            .map_err(|e| FitError::Invalid(e.to_string()))?;
        Ok::<_, FitError>(Fitted {
            document,
            hits: hits.clone(),
            strands_per_bundle,
            locked_interior: locked,
            timings_s: Vec::new(),
        })
    };
    let mut fitted = finish(fitted_mesh, first_curl)?;
    // A curl found only against the strands' own axes is right for ringlets, but a groom
    // whose strands merely wave or frizz about their clumps can show one too (Blender's hair
    // nodes: a 6 mm curl that cost 0.12 % of the size in distance and 4 % in length): keep
    // it only where it brings the fitted strands closer to the input than no curl does.
    if let Some(first) = uncurled {
        let plain = finish(first, None)?;
        let sample = measure::MeasureOptions {
            max_strands: COMPARE_STRANDS,
            threads,
            ..measure::MeasureOptions::default()
        };
        let with_curl = measure::measure(groom, &fitted, &sample).pooled.mean;
        let without = measure::measure(groom, &plain, &sample).pooled.mean;
        if without < with_curl {
            fitted = plain;
        }
    }
    lap(&mut timings, "styling");
    let _ = progress("styling", 1.0);
    fitted.timings_s = timings;
    Ok(fitted)
}

/// The hair mesh fitted to a groom's strands, with what styling needs from the fit.
struct MeshFit {
    mesh: HairMesh,
    /// Arc length per strand.
    lengths: Vec<f64>,
    /// Per strand, the length its columns were fitted for (see [`fit_mesh`]).
    reference_lengths: Vec<f64>,
    /// Interior vertices locked where the strands put them.
    locked: usize,
}

/// Steps 2 and 3 of the module comment: bundles from the root hits, then columns layer by
/// layer from the strands sampled at equal shares of their reference length.
#[allow(clippy::too_many_arguments)]
fn fit_mesh(
    groom: &InputGroom,
    hits: &[RootHit],
    roots: &[DVec3],
    scalp_mesh: &HairMesh,
    layers: u32,
    threads: usize,
    size: f64,
    progress: &mut FitProgress,
) -> Result<MeshFit, FitError> {
    let curves = groom.curve_count();
    let mut mesh = scalp_mesh.clone();
    let layers = layers as usize;
    let lengths: Vec<f64> = groom.curves().map(columns::arc_length).collect();
    let mut strands_in = vec![0usize; mesh.bundles.len()];
    for hit in hits {
        strands_in[hit.face as usize] += 1;
    }
    for (bundle, &count) in mesh.bundles.iter_mut().zip(&strands_in) {
        bundle.layers = if count > 0 { layers as u32 } else { 0 };
    }
    let weights_of = |hit: &RootHit| {
        let corners = mesh.bundles[hit.face as usize].vertices.len();
        FaceCoord { s: hit.s, t: hit.t }.weights(corners)
    };
    // Reference length per column: the 90th percentile (by weight) of the lengths of the
    // strands around it, so that length variation only shortens strands.
    let column_count = mesh.columns.len();
    let mut around: Vec<Vec<(f32, f32)>> = vec![Vec::new(); column_count];
    for (i, hit) in hits.iter().enumerate() {
        let w = weights_of(hit);
        for (a, &c) in mesh.bundles[hit.face as usize].vertices.iter().enumerate() {
            if w[a] > 1e-6 {
                around[c as usize].push((lengths[i] as f32, w[a] as f32));
            }
        }
    }
    let column_length: Vec<f64> = around
        .iter_mut()
        .map(|list| weighted_quantile(list, 0.9))
        .collect();
    drop(around);
    let reference_lengths: Vec<f64> = hits
        .iter()
        .enumerate()
        .map(|(i, hit)| {
            let w = weights_of(hit);
            mesh.bundles[hit.face as usize]
                .vertices
                .iter()
                .enumerate()
                .map(|(a, &c)| w[a] * column_length[c as usize])
                .sum::<f64>()
                .max(lengths[i] * 1e-3)
        })
        .collect();
    // One pass over the strands: every layer's normal equations, and each column's start
    // direction (the first sample's offset from the root).
    let bundle_count = mesh.bundles.len();
    // Each chunk holds every layer's normal equations for every bundle, so the chunks are
    // at most 16 (fixed, for determinism): memory stays 16 × layers × bundles × 224 bytes
    // however many curves come in.
    let chunk = curves.div_ceil(16).max(CHUNK);
    let systems_and_starts = crate::parallel::in_chunks(curves, chunk, threads, |range| {
        let mut systems: Vec<columns::LayerSystem> = (0..=layers)
            .map(|_| columns::LayerSystem::new(bundle_count))
            .collect();
        let mut start = vec![DVec3::ZERO; column_count];
        for i in range {
            let hit = &hits[i];
            let bundle = &mesh.bundles[hit.face as usize];
            let w = weights_of(hit);
            let samples =
                columns::sample_at_arc_length(groom.curve(i), reference_lengths[i], layers + 1);
            let root = samples[0].unwrap_or(roots[i]);
            for (k, sample) in samples.iter().enumerate().skip(1) {
                let Some(p) = sample else { break };
                // Fit offsets from the root, added to the scalp's own root position, so a
                // root slightly off the scalp does not drag the column sideways.
                let on_scalp = scalp_point(&mesh, hit);
                systems[k].add(
                    hit.face as usize,
                    &w,
                    bundle.vertices.len(),
                    on_scalp + (*p - root),
                );
                if k == 1 {
                    for (a, &c) in bundle.vertices.iter().enumerate() {
                        start[c as usize] += (*p - root) * w[a];
                    }
                }
            }
        }
        (systems, start)
    });
    let mut systems: Vec<columns::LayerSystem> = (0..=layers)
        .map(|_| columns::LayerSystem::new(bundle_count))
        .collect();
    let mut start = vec![DVec3::ZERO; column_count];
    for (chunk_systems, chunk_start) in &systems_and_starts {
        for (s, c) in systems.iter_mut().zip(chunk_systems) {
            s.merge(c);
        }
        for (s, c) in start.iter_mut().zip(chunk_start) {
            *s += *c;
        }
    }
    drop(systems_and_starts);
    let topology = Topology::build(&mesh);
    let grows: Vec<bool> = (0..column_count)
        .map(|c| {
            topology.bundles_of_column[c]
                .iter()
                .any(|&b| mesh.bundles[b as usize].layers > 0)
        })
        .collect();
    let corners: Vec<Vec<u32>> = mesh.bundles.iter().map(|b| b.vertices.clone()).collect();
    // Edges of the bundles that grow hair, each once.
    let mut edges: Vec<(u32, u32)> = mesh
        .bundles
        .iter()
        .filter(|b| b.layers > 0)
        .flat_map(|b| {
            let n = b.vertices.len();
            (0..n).map(move |i| {
                let (a, c) = (b.vertices[i], b.vertices[(i + 1) % n]);
                (a.min(c), a.max(c))
            })
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let roots_of_columns: Vec<DVec3> = mesh.columns.iter().map(|c| c.positions[0]).collect();
    let mut positions: Vec<Vec<DVec3>> =
        mesh.columns.iter().map(|c| vec![c.positions[0]]).collect();
    for k in 1..=layers {
        let system = &systems[k];
        // λ: 2 % of the mean data weight on a column, so data decides wherever there is any.
        let mut diag = vec![0.0f64; column_count];
        for (b, vertices) in corners.iter().enumerate() {
            for (a, &c) in vertices.iter().enumerate() {
                diag[c as usize] += system.gram[b][a][a];
            }
        }
        let supported: Vec<f64> = diag.iter().copied().filter(|d| *d > 0.0).collect();
        let mean_diag = if supported.is_empty() {
            1.0
        } else {
            supported.iter().sum::<f64>() / supported.len() as f64
        };
        let lambda = vec![0.002 * mean_diag; column_count];
        let prediction: Vec<DVec3> = (0..column_count)
            .map(|c| {
                let p = &positions[c];
                if !grows[c] {
                    // Only bare faces use this column: it stays a scalp vertex.
                    p[0]
                } else if k == 1 {
                    let step = column_length[c] / layers as f64;
                    let dir = start[c].normalize_or(DVec3::Y);
                    p[0] + dir * step
                } else {
                    let prev = p[k - 1];
                    prev + (prev - p[k - 2])
                }
            })
            .collect();
        let solved = columns::solve_layer(
            system,
            &corners,
            &lambda,
            &prediction,
            0.02 * mean_diag,
            &edges,
            &roots_of_columns,
        );
        for c in 0..column_count {
            if grows[c] {
                positions[c].push(solved[c]);
            }
        }
        if progress("columns", k as f64 / layers as f64).is_break() {
            return Err(FitError::Cancelled);
        }
    }
    for (column, p) in mesh.columns.iter_mut().zip(positions) {
        column.positions = p;
        column.w = vec![0.0; column.positions.len()];
    }
    let locked = keep_interior_fit(&mut mesh, INTERIOR_TOLERANCE_RELATIVE * size);
    mesh.update_w();
    Ok(MeshFit {
        mesh,
        lengths,
        reference_lengths,
        locked,
    })
}

/// How far the editor's interior rule may move a fitted interior vertex (as a share of the
/// groom's size) before the fit locks it where the strands put it.
pub const INTERIOR_TOLERANCE_RELATIVE: f64 = 0.01;

/// Interior vertices go where the editor's rule puts them, so the mesh edits like one built
/// by hand, except where the rule lands farther than `tolerance` from where the strands
/// say: those are locked at their fitted position (a locked interior vertex anchors the
/// rule like an exterior one, so the rule's other vertices move closer too). Repeats until
/// nothing more needs locking (at most 4 rounds). Returns the number locked.
fn keep_interior_fit(mesh: &mut HairMesh, tolerance: f64) -> usize {
    let fitted = mesh.clone();
    let topology = Topology::build(mesh);
    for _ in 0..4 {
        crate::geometry::interior::place_interior(mesh, None);
        let mut lock = Vec::new();
        for (c, (placed, fit)) in mesh.columns.iter().zip(&fitted.columns).enumerate() {
            for (k, (p, f)) in placed.positions.iter().zip(&fit.positions).enumerate() {
                if mesh.is_interior(&topology, c, k)
                    && !mesh.is_locked(c, k)
                    && (*p - *f).length() > tolerance
                {
                    lock.push(crate::model::mesh::VertexRef {
                        column: c as u32,
                        layer: k as u32,
                    });
                }
            }
        }
        if lock.is_empty() {
            break;
        }
        for v in &lock {
            mesh.columns[v.column as usize].positions[v.layer as usize] =
                fitted.columns[v.column as usize].positions[v.layer as usize];
        }
        mesh.set_locked(&lock, true);
    }
    mesh.locked.len()
}

/// The root position a generated strand would have at `hit`.
fn scalp_point(mesh: &HairMesh, hit: &RootHit) -> DVec3 {
    let bundle = &mesh.bundles[hit.face as usize];
    let w = FaceCoord { s: hit.s, t: hit.t }.weights(bundle.vertices.len());
    bundle
        .vertices
        .iter()
        .enumerate()
        .map(|(a, &c)| mesh.columns[c as usize].positions[0] * w[a])
        .sum()
}

/// A hair mesh's root layer alone: every face bare, every column one vertex.
pub fn root_layer(mesh: &HairMesh) -> HairMesh {
    let mut out = mesh.clone();
    for column in &mut out.columns {
        column.positions.truncate(1);
        column.w.truncate(1);
    }
    for bundle in &mut out.bundles {
        bundle.layers = 0;
        bundle.removed = false;
        bundle.density = 1.0;
    }
    out.locked.clear();
    out
}

/// The value below which `quantile` of the total weight lies (0 for an empty list).
fn weighted_quantile(list: &mut [(f32, f32)], quantile: f64) -> f64 {
    if list.is_empty() {
        return 0.0;
    }
    list.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = list.iter().map(|(_, w)| *w as f64).sum();
    let mut sum = 0.0;
    for (value, w) in list.iter() {
        sum += *w as f64;
        if sum >= quantile * total {
            return *value as f64;
        }
    }
    list[list.len() - 1].0 as f64
}

#[cfg(test)]
mod tests;
