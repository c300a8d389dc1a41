//! Styling fitted from what the hair mesh does not explain.
//!
//! **Length variation.** The columns follow the long strands of each neighbourhood (their
//! reference length); a generated strand ends at `1 − f·ξ` of it, `ξ` uniform, so the mean
//! ratio of a strand's length to its reference is `1 − f/2`: `f = 2 (1 − mean ratio)`.
//!
//! **Curl.** Each strand's offset from the unstyled strand the hair mesh grows at its root
//! (its residual), in the styling directions `û`, `v̂` there, is a complex signal `z(w)`; a curl
//! of `n` turns per metre is `r e^{i(2π n w + φ)}`, so its rotating spectrum peaks at `n`
//! with magnitude `r` whatever each strand's phase. The spectra's power is summed over the
//! strands and the peak taken; a peak that does not stand out (or has a mirror peak at
//! `−n`, as a planar wave would) is not called a curl.

use glam::{DVec2, DVec3};

use super::scalp::RootHit;
use crate::geometry::curve::{CurveDefinition, FaceCoord, ReferenceStrand, SegmentForm};
use crate::geometry::frames::Frame;
use crate::io::groom_in::InputGroom;
use crate::model::document::Document;
use crate::model::mesh::HairMesh;

/// Sets the document's global styling from the strands' lengths and reference lengths.
pub fn fit_styling(document: &mut Document, lengths: &[f64], reference_lengths: &[f64]) {
    let ratios: Vec<f64> = lengths
        .iter()
        .zip(reference_lengths)
        .filter(|(_, r)| **r > 0.0)
        .map(|(l, r)| (l / r).min(1.0))
        .collect();
    if ratios.is_empty() {
        return;
    }
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    let fraction = (2.0 * (1.0 - mean)).clamp(0.0, 0.95);
    // Below 2 % the variation is noise of the sampling, not a style.
    document.styling.global.length.fraction = if fraction < 0.02 { 0.0 } else { fraction };
}

/// Most strands whose residuals are analysed (an even stride over the groom).
const CURL_STRANDS: usize = 4000;
/// Frequencies scanned, in turns per metre along w: log-spaced, both signs.
const CURL_FREQUENCIES: usize = 160;
const CURL_MIN_TURNS_PER_M: f64 = 2.0;
const CURL_MAX_TURNS_PER_M: f64 = 400.0;

/// One strand's residual from the hair mesh: per sample, w along the unstyled strand and
/// the offset's coordinates in the styling directions `û`, `v̂`.
struct Residual {
    w: Vec<f64>,
    z: Vec<DVec2>,
}

fn residual(
    mesh: &HairMesh,
    frames: &[Vec<Option<Frame>>],
    points: &[[f32; 3]],
    hit: &RootHit,
    reference_length: f64,
    samples: usize,
) -> Option<Residual> {
    let reference =
        ReferenceStrand::new(mesh, hit.face as usize, FaceCoord { s: hit.s, t: hit.t })?;
    let layers = reference.layers as f64;
    if layers == 0.0 {
        return None;
    }
    let length = super::columns::arc_length(points);
    // Bounded: a coil whose axis is far shorter than its arc would ask for any number.
    let count = ((length / reference_length.max(1e-12)) * samples as f64)
        .ceil()
        .clamp(8.0, 16.0 * samples as f64) as usize;
    let along = super::columns::sample_at_arc_length(points, length, count);
    let root = along[0]?;
    // The unstyled strand finely sampled, with its length so far (w). Each input sample is
    // matched to its nearest point there, searching forward from the last match: a curly
    // strand's arc length runs ahead of its axis, so arc length cannot give the match.
    const GRID: usize = 1024;
    let grid: Vec<DVec3> = (0..=GRID)
        .map(|j| {
            reference.point(
                layers * j as f64 / GRID as f64,
                CurveDefinition::ColumnBlend,
                SegmentForm::ExactCubic,
            )
        })
        .collect();
    let mut grid_w = Vec::with_capacity(grid.len());
    let mut total = 0.0;
    for j in 0..grid.len() {
        if j > 0 {
            total += (grid[j] - grid[j - 1]).length();
        }
        grid_w.push(total);
    }
    let offset = grid[0] - root;
    let bundle = &mesh.bundles[hit.face as usize];
    let weights = FaceCoord { s: hit.s, t: hit.t }.weights(bundle.vertices.len());
    // The styling directions û, v̂ at τ, blended over the corners as the generator does.
    let styling_frame = |tau: f64| -> Option<(DVec3, DVec3)> {
        let k = (tau.floor().max(0.0) as usize).min(bundle.layers.saturating_sub(1) as usize);
        let f = (tau - k as f64).clamp(0.0, 1.0);
        let (mut u, mut v) = (DVec3::ZERO, DVec3::ZERO);
        for (i, &c) in bundle.vertices.iter().enumerate() {
            let a = frames.get(k)?.get(c as usize).copied().flatten()?;
            let b = frames.get(k + 1)?.get(c as usize).copied().flatten()?;
            u += weights[i] * a.u.lerp(b.u, f);
            v += weights[i] * a.v.lerp(b.v, f);
        }
        Some((u.try_normalize()?, v.try_normalize()?))
    };
    let mut w = Vec::with_capacity(count);
    let mut z = Vec::with_capacity(count);
    let mut at = 0usize;
    let window = GRID / 8;
    for p in along.iter() {
        let Some(p) = p else { break };
        let p = *p + offset;
        // The match is where p lies in the styling plane (û, v̂) of the unstyled strand,
        // as the generator put it: the first crossing of (p − G_j)·ŵ_j ahead of the last
        // match; the nearest point when there is none.
        let (mut best, mut best_d) = (at, f64::INFINITY);
        let mut crossing = None;
        let mut previous_side: Option<f64> = None;
        let end = (at + window).min(GRID + 1);
        for (j, &g) in grid.iter().enumerate().take(end).skip(at) {
            let d = (g - p).length_squared();
            if d < best_d {
                best = j;
                best_d = d;
            }
            if let Some((su, sv)) = styling_frame(layers * j as f64 / GRID as f64) {
                let side = (p - g).dot(su.cross(sv));
                if previous_side.is_some_and(|s| s >= 0.0 && side < 0.0) && crossing.is_none() {
                    crossing = Some(j);
                }
                previous_side = Some(side);
            }
        }
        if let Some(j) = crossing {
            best = j;
        }
        at = best;
        if at == GRID && w.len() > 8 {
            break; // past the unstyled strand's tip
        }
        // The offset in the styling directions (they may be skewed): d = a û + b v̂ in the
        // least-squares sense, so a curl of the generator is a pure rotation of (a, b).
        let (su, sv) = styling_frame(layers * at as f64 / GRID as f64)?;
        let d = p - grid[at];
        let (uu, uv, vv) = (su.dot(su), su.dot(sv), sv.dot(sv));
        let det = uu * vv - uv * uv;
        if det < 1e-6 {
            return None;
        }
        let (du, dv) = (d.dot(su), d.dot(sv));
        w.push(grid_w[at]);
        z.push(DVec2::new(
            (vv * du - uv * dv) / det,
            (uu * dv - uv * du) / det,
        ));
    }
    (w.len() >= 8).then_some(Residual { w, z })
}

/// Fits a curl (a helix around the strand) to the residuals: the frequency whose rotating
/// component is strongest over the strands (its radius is [`curl_radius`]'s). The residual's mean is
/// removed per strand first (a bundle-scale offset is not a curl). `None` when no rotating
/// component stands out of the rest of the spectrum.
fn fit_curl(residuals: &[Residual], near: Option<f64>, mirror_ratio: f64) -> Option<f64> {
    let ratio =
        (CURL_MAX_TURNS_PER_M / CURL_MIN_TURNS_PER_M).powf(1.0 / (CURL_FREQUENCIES - 1) as f64);
    let frequencies: Vec<f64> = (0..CURL_FREQUENCIES)
        .flat_map(|k| {
            let f = CURL_MIN_TURNS_PER_M * ratio.powi(k as i32);
            [f, -f]
        })
        // A known rate (from a first pass) is refined within −30 % … +40 % of itself.
        .filter(|&f| near.is_none_or(|n| f * n > 0.0 && (0.7..=1.4).contains(&(f / n))))
        .collect();
    let mut power = vec![0.0f64; frequencies.len()];
    for r in residuals {
        let n = r.z.len();
        let mean = r.z.iter().copied().sum::<DVec2>() / n as f64;
        let span = r.w[n - 1] - r.w[0];
        if span <= 0.0 {
            continue;
        }
        let spacing = span / (n - 1) as f64;
        for (k, &f) in frequencies.iter().enumerate() {
            // Above a quarter of the sampling rate the estimate aliases: skip it.
            if f.abs() * spacing > 0.25 || f.abs() * span < 1.5 {
                continue;
            }
            let mut sum = DVec2::ZERO;
            for j in 0..n {
                let phase = -std::f64::consts::TAU * f * r.w[j];
                let (sin, cos) = phase.sin_cos();
                let d = r.z[j] - mean;
                // (d.x + i d.y) · e^{iφ}
                sum += DVec2::new(d.x * cos - d.y * sin, d.x * sin + d.y * cos);
            }
            power[k] += (sum / n as f64).length_squared();
        }
    }
    let (best, &peak) = power.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))?;
    if near.is_some() {
        // The first pass already found the peak over the whole spectrum.
        return (peak > 0.0).then_some(frequencies[best]);
    }
    let mut sorted = power.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let mirror = power[best ^ 1];
    // A curl turns one way: its peak stands well above the spectrum and above its mirror
    // frequency (a planar wave has both).
    // Power ratios: the peak's amplitude at least 3× the median's, and its power
    // `mirror_ratio` × its mirror's.
    if peak <= 0.0 || peak < 9.0 * median || peak < mirror_ratio * mirror {
        return None;
    }
    Some(frequencies[best])
}

/// The curl's radius once its rate is known: the median distance of the residual from the
/// strand's axis. With `about_axis`, the hair mesh was fitted to the strands' axes
/// ([`strand_axes`]) and the residual itself is that distance. Otherwise the mesh follows
/// points on the helices and the residual is taken about its own one-turn mean, a rough
/// estimate (low by about a quarter on the curly sample) that is only good enough to size
/// the axes' smoothing. The spectral peak's magnitude would do neither: each sample's w comes
/// from a nearest-point search and the phase error it leaves cancels part of the coherent sum.
fn curl_radius(residuals: &[Residual], turns_per_m: f64, about_axis: bool) -> Option<f64> {
    let half_turn = 0.5 / turns_per_m.abs().max(1e-9);
    let mut distances = Vec::new();
    for r in residuals {
        let n = r.z.len();
        let (first, last) = (r.w[0], r.w[n - 1]);
        let (mut lo, mut hi) = (0usize, 0usize);
        let mut sum = DVec2::ZERO;
        for j in 0..n {
            // The window [w_j − half turn, w_j + half turn]; w increases along the strand.
            while hi < n && r.w[hi] <= r.w[j] + half_turn {
                sum += r.z[hi];
                hi += 1;
            }
            while r.w[lo] < r.w[j] - half_turn {
                sum -= r.z[lo];
                lo += 1;
            }
            if r.w[j] - half_turn < first || r.w[j] + half_turn > last || hi - lo < 4 {
                continue; // the window is not a whole turn
            }
            let centre = if about_axis {
                DVec2::ZERO
            } else {
                sum / (hi - lo) as f64
            };
            distances.push((r.z[j] - centre).length());
        }
    }
    if distances.is_empty() {
        return None;
    }
    let middle = distances.len() / 2;
    let (_, median, _) = distances.select_nth_unstable_by(middle, f64::total_cmp);
    Some(*median)
}

/// Curl fitted from the strands' residuals (see [`fit_curl`]); sets the global curl when
/// one stands out and is larger than `min_radius`. With `near`, a rate found before is
/// refined near itself and the mesh is taken to follow the strands' axes.
pub fn fit_curl_styling(
    document: &mut Document,
    groom: &InputGroom,
    hits: &[RootHit],
    reference_lengths: &[f64],
    min_radius: f64,
    near: Option<f64>,
) -> Option<(f64, f64)> {
    let mesh = &document.hair_mesh;
    let frames: Vec<Vec<Option<Frame>>> = (0..=mesh.max_layers())
        .map(|k| crate::geometry::frames::layer_frames(mesh, k))
        .collect();
    let stride = groom.curve_count().div_ceil(CURL_STRANDS).max(1);
    let residuals: Vec<Residual> = (0..groom.curve_count())
        .step_by(stride)
        .filter_map(|i| {
            residual(
                mesh,
                &frames,
                groom.curve(i),
                &hits[i],
                reference_lengths[i],
                128,
            )
        })
        .collect();
    // In the styling frame a helix is a circle: its mirror is weak (power 4× below).
    let turns_per_m = fit_curl(&residuals, near, 4.0)?;
    let radius = curl_radius(&residuals, turns_per_m, near.is_some())?;
    // A "curl" wider than a styling parameter may be (a groom in centimetres or
    // millimetres: the fit works in file units) is left out rather than failing the fit.
    let max_radius = crate::model::styling::HARD_RANGES
        .iter()
        .find(|(name, ..)| *name == "curl.radius_m")
        .map_or(f64::INFINITY, |&(_, _, hi)| hi);
    if radius < min_radius || radius > max_radius {
        return None;
    }
    let curl = &mut document.styling.global.curl;
    curl.turns_per_m = turns_per_m;
    curl.radius_m = radius;
    Some((turns_per_m, radius))
}

/// Curl found from the strands alone, with no hair mesh: each strand's residual from its own
/// axis (three moving means a third of its length long), in a frame parallel-transported
/// along that axis (û ⟂ the axis, v̂ = axis × û: the styling frame's handedness), scanned as
/// [`fit_curl`] scans the mesh's residuals. For locks that coil together (ringlets: the
/// strands of a clump share their helix), the hair mesh fitted to the strands coils with them
/// and the residual from it keeps little of the curl, so the mesh's first pass finds none.
/// Returns the rate and the rough radius (about the one-turn mean) that size
/// [`strand_axes`]' smoothing; `None` when no curl stands out or it is under `min_radius`.
pub fn curl_from_own_axes(groom: &InputGroom, min_radius: f64) -> Option<(f64, f64)> {
    const SAMPLES: usize = 128;
    let stride = groom.curve_count().div_ceil(CURL_STRANDS).max(1);
    let residuals: Vec<Residual> = (0..groom.curve_count())
        .step_by(stride)
        .filter_map(|i| {
            let points = groom.curve(i);
            let length = super::columns::arc_length(points);
            if length.is_nan() || length <= 0.0 {
                return None;
            }
            let samples: Vec<DVec3> = super::columns::sample_at_arc_length(points, length, SAMPLES)
                .into_iter()
                .map_while(|p| p)
                .collect();
            if samples.len() < 16 {
                return None;
            }
            let mut axis = samples.clone();
            for _ in 0..3 {
                axis = moving_mean(&axis, samples.len() / 6);
            }
            let mut w = Vec::with_capacity(samples.len());
            let mut z = Vec::with_capacity(samples.len());
            let mut along = 0.0;
            let mut u: Option<DVec3> = None;
            for j in 0..samples.len() {
                let tangent = if j + 1 < axis.len() {
                    axis[j + 1] - axis[j]
                } else {
                    axis[j] - axis[j - 1]
                };
                let t = tangent.try_normalize()?;
                if j > 0 {
                    along += (axis[j] - axis[j - 1]).length();
                }
                // Parallel transport: the previous û with its component along t removed.
                let next = match u {
                    Some(previous) => previous - t * previous.dot(t),
                    None => t.any_orthogonal_vector(),
                };
                let unit_u = next.try_normalize()?;
                u = Some(unit_u);
                let unit_v = t.cross(unit_u);
                let d = samples[j] - axis[j];
                w.push(along);
                z.push(DVec2::new(d.dot(unit_u), d.dot(unit_v)));
            }
            Some(Residual { w, z })
        })
        .collect();
    // The styling directions û, v̂ are not orthonormal, so in this orthonormal frame a
    // helix is an ellipse and its mirror frequency carries power too (0.58 × the peak's on
    // the curly sample's ringlets); a planar wave still has both alike.
    let turns_per_m = fit_curl(&residuals, None, 1.5)?;
    let radius = curl_radius(&residuals, turns_per_m, false)?;
    (radius >= min_radius).then_some((turns_per_m, radius))
}

/// Each strand with its curl averaged away: its axis. Three passes of a moving mean one turn
/// of the helix long (in arc length): one pass cancels a helix of exactly that turn length,
/// and three make the cancellation forgiving (a sinc³ response: a turn length off by 20 %
/// leaves about 1 % of the radius). Near the ends the axis is extrapolated (see
/// [`moving_mean`]); the root stays where it was.
pub fn strand_axes(groom: &InputGroom, turns_per_m: f64, radius_m: f64) -> InputGroom {
    let turn_arc_m =
        ((std::f64::consts::TAU * radius_m).powi(2) + (1.0 / turns_per_m).powi(2)).sqrt();
    let mut axes = InputGroom {
        starts: Vec::with_capacity(groom.starts.len()),
        points: Vec::with_capacity(groom.points.len()),
        ..InputGroom::default()
    };
    axes.starts.push(0);
    for i in 0..groom.curve_count() {
        let points = groom.curve(i);
        let length = super::columns::arc_length(points);
        // 16 samples a turn, bounded by the input's own size (a few times its points).
        let count = ((length / (turn_arc_m / 16.0)).ceil() as usize + 1)
            .min((4 * points.len()).clamp(64, 4096))
            .max(2);
        let mut samples: Vec<DVec3> = super::columns::sample_at_arc_length(points, length, count)
            .into_iter()
            .map_while(|p| p)
            .collect();
        let spacing = length / (count - 1) as f64;
        // At most the strand's own samples (a zero-length strand would ask for usize::MAX).
        let half = ((0.5 * turn_arc_m / spacing.max(1e-300)).round() as usize).min(samples.len());
        let root = samples.first().copied();
        for _ in 0..3 {
            samples = moving_mean(&samples, half);
        }
        // The root stays where the file put it (its scalp hit is already known).
        if let (Some(first), Some(root)) = (samples.first_mut(), root) {
            *first = root;
        }
        axes.points
            .extend(samples.iter().map(|p| p.as_vec3().to_array()));
        axes.starts.push(axes.points.len() as u32);
    }
    axes
}

/// Mean of each point's neighbourhood of `half` points either side. Within `half` of an
/// end, where a whole window does not fit, the curve is continued by point reflection
/// through the last whole-window mean (`2 m(h) − m(2h − j)`): a shrinking window would keep
/// the helix there, and a clamped one would pile the points up. Strands shorter than two
/// windows get the shrinking window.
fn moving_mean(points: &[DVec3], half: usize) -> Vec<DVec3> {
    let mut prefix = Vec::with_capacity(points.len() + 1);
    prefix.push(DVec3::ZERO);
    for p in points {
        prefix.push(prefix[prefix.len() - 1] + *p);
    }
    let n = points.len();
    let mean = |j: usize, m: usize| (prefix[j + m + 1] - prefix[j - m]) / (2 * m + 1) as f64;
    if n < 4 * half + 1 {
        return (0..n)
            .map(|j| mean(j, half.min(j).min(n - 1 - j)))
            .collect();
    }
    let (first, last) = (half, n - 1 - half);
    (0..n)
        .map(|j| {
            if j < first {
                2.0 * mean(first, half) - mean(2 * first - j, half)
            } else if j > last {
                2.0 * mean(last, half) - mean(2 * last - j, half)
            } else {
                mean(j, half)
            }
        })
        .collect()
}
