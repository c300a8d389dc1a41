//! Procedural styling (seed 000 §3.4): deterministic per-strand perturbations whose
//! directions live in the uvw styling frame and whose amplitudes are object-space lengths
//! (metres), so they do not stretch when a bundle stretches.
//!
//! Conventions for every op:
//! - `w` is the styling coordinate at the vertex (model units from the root along the
//!   strand), `τ̂ ∈ [0, 1]` the vertex's fraction of the strand from root to tip, `(û, v̂, ŵ)`
//!   the interpolated frame and `x` the strand's root uv.
//! - Per-strand random values are smooth functions of `x` ([`strand_random`]): value noise
//!   over uv with [`StylingParams::variation_per_uv`] cells per uv unit. Strands whose roots
//!   are close therefore get close shapes — across bundle borders too, so styling shows no
//!   seams — while strands more than a cell apart are independent.
//! - Nothing is applied at the root vertex (`w = 0` and `τ̂ = 0` make every op vanish) and an
//!   op whose amplitude is zero is skipped entirely ("compute only what is asked").
//!
//! Twist is the one op that is deliberately per bundle: it turns each bundle into a lock
//! rotating about its own centre strand, so strands on two sides of a bundle border belong to
//! different locks.

use glam::{DVec2, DVec3};

use crate::model::styling::StylingParams;
use crate::strands::random::{hash_to_unit, hash_values};

const TAU: f64 = std::f64::consts::TAU;
/// How far along the noise domain a strand's key can sit: enough that strands one
/// variation cell apart read unrelated noise, small enough to keep nearby strands alike.
const NOISE_KEY_SPAN: f64 = 16.0;
/// Quintic fade: C² continuous interpolation weight.
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Smooth 2D value noise in `[0, 1)` at `p` (lattice values from [`hash_values`]).
pub(crate) fn value_noise_2d(p: DVec2, seed: u32, channel: u32) -> f64 {
    let p = if p.is_finite() { p } else { DVec2::ZERO };
    let cell = p.floor();
    let f = p - cell;
    let (ix, iy) = (cell.x as i64 as u32, cell.y as i64 as u32);
    let lattice = |dx: u32, dy: u32| {
        hash_to_unit(hash_values(&[
            seed,
            channel,
            ix.wrapping_add(dx),
            iy.wrapping_add(dy),
        ]))
    };
    let (fx, fy) = (fade(f.x), fade(f.y));
    let bottom = lattice(0, 0) + (lattice(1, 0) - lattice(0, 0)) * fx;
    let top = lattice(0, 1) + (lattice(1, 1) - lattice(0, 1)) * fx;
    bottom + (top - bottom) * fy
}

/// Smooth 1D value noise in `[−1, 1]`.
pub fn value_noise_1d(x: f64, seed: u32, channel: u32) -> f64 {
    let x = if x.is_finite() { x } else { 0.0 };
    let cell = x.floor();
    let f = fade(x - cell);
    let i = cell as i64 as u32;
    let lattice =
        |d: u32| hash_to_unit(hash_values(&[seed, channel, i.wrapping_add(d)])) * 2.0 - 1.0;
    lattice(0) + (lattice(1) - lattice(0)) * f
}

/// The per-strand random field ξ_channel at root uv `root_uv`, in `[0, 1)`.
pub fn strand_random(params: &StylingParams, root_uv: DVec2, channel: u32) -> f64 {
    value_noise_2d(root_uv * params.variation_per_uv, params.seed, channel)
}

/// Fraction of the bundle's length this strand keeps: length variation
/// (`1 − fraction · ξ₅`) times, for a stray, `length_min + (1 − length_min) c₁₀` (`c` the
/// cell-constant [`strand_cell_random`]).
pub fn strand_length_fraction(params: &StylingParams, root_uv: DVec2) -> f64 {
    let mut fraction = 1.0;
    if params.length.fraction > 0.0 {
        fraction -= params.length.fraction.clamp(0.0, 1.0) * strand_random(params, root_uv, 5);
    }
    let stray = &params.stray;
    if stray.fraction > 0.0 && strand_cell_random(params, root_uv, 9) < stray.fraction {
        let shortest = stray.length_min.clamp(0.0, 1.0);
        fraction *= shortest + (1.0 - shortest) * strand_cell_random(params, root_uv, 10);
    }
    fraction
}

/// The hairline op's share of its length a strand keeps (0: it does not grow at all), for a
/// root `distance` (object units) from the border of the hair and `rank = (j + ½) / N`, its
/// sample's place in its bundle's progressive set ([`crate::model::styling::Hairline`]).
/// Written `1 − (1 − edge)(1 − s)` so that a root `width_m` or more inside keeps exactly 1.
/// A NaN distance counts as 0 (on the border); runtime bundles refuse non-finite texels.
pub fn hairline_length_scale(params: &StylingParams, distance: f64, rank: f64) -> f64 {
    let hairline = &params.hairline;
    // Off unless a positive width (NaN too).
    if hairline.width_m.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return 1.0;
    }
    let s = smoothstep(hairline.width_m, distance.max(0.0));
    let density = 1.0 - (1.0 - hairline.edge_density.clamp(0.0, 1.0)) * (1.0 - s);
    // Grows only below the density (a NaN rank or density grows nothing).
    if rank.partial_cmp(&density) != Some(std::cmp::Ordering::Less) {
        return 0.0;
    }
    1.0 - (1.0 - hairline.edge_length.clamp(0.0, 1.0)) * (1.0 - s)
}

fn smoothstep(edge: f64, x: f64) -> f64 {
    if edge <= 0.0 {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    let t = (x / edge).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Everything an op needs at one strand vertex.
#[derive(Clone, Copy, Debug)]
pub struct StylingInput {
    /// Unit styling directions (û, v̂ may be skewed; ŵ ⟂ both).
    pub u: DVec3,
    pub v: DVec3,
    pub w_axis: DVec3,
    pub root_uv: DVec2,
    /// Styling coordinate w at the vertex (≥ 0).
    pub w: f64,
    /// Fraction of the strand from root (0) to tip (1).
    pub along: f64,
}

/// What the styling ops need of a strand that is the same at every one of its vertices: its
/// random values (phases, keys, radius jitter, whether it frizzes or strays) and its clump
/// pulls. The CPU generators compute this once per strand, not once per vertex; the values
/// are the same expressions [`styling_offset`] evaluates, so the split changes no result.
/// Ops that are off leave their fields zero.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StrandStyling {
    /// The curl's phase at w = 0 as a vector: `(cos 2πξ₁, sin 2πξ₁)` blended toward the
    /// strand's lock phase by `curl.clump_coherence` ([`blend_phase`]).
    pub curl_phase: DVec2,
    /// The curl radius with this strand's jitter, metres.
    pub curl_radius_m: f64,
    /// Where this strand reads the two noise curves (`NOISE_KEY_SPAN · ξ₃`, `· ξ₄`).
    pub noise_key_u: f64,
    pub noise_key_v: f64,
    /// The clump and sub-clump pulls at the strand's root (cell units); zero for a stray.
    pub clump_pull: DVec2,
    pub sub_clump_pull: DVec2,
    /// Whether the strand frizzes (`ξ₆ < fraction`, or a stray), and where it reads the
    /// frizz noise.
    pub frizz: bool,
    pub frizz_key: f64,
    /// The wave's phase as a vector: angle `phase_spread · 2π ξ₈`, blended toward the lock
    /// phase by `wave.clump_coherence`.
    pub wave_phase: DVec2,
    /// Whether the strand strays, the direction it drifts in (unit, in (û, v̂)) and where it
    /// reads its drift noise.
    pub stray: bool,
    pub stray_direction: DVec2,
    pub stray_key: f64,
}

impl StrandStyling {
    /// This strand feeling `share` of its clump and sub-clump pulls (the painted clump map
    /// at its root, [`crate::model::root_maps`]).
    pub fn with_clump_share(mut self, share: f64) -> Self {
        self.clump_pull *= share;
        self.sub_clump_pull *= share;
        self
    }

    pub fn new(params: &StylingParams, root_uv: DVec2) -> Self {
        let mut strand = Self::default();
        let xi = |channel| strand_random(params, root_uv, channel);
        let lock_uv = root_uv * params.clump.clumps_per_uv.max(1.0);
        let stray = &params.stray;
        strand.stray =
            stray.fraction > 0.0 && strand_cell_random(params, root_uv, 9) < stray.fraction;
        let curl = &params.curl;
        if curl.radius_m != 0.0 {
            let own = unit_phase(TAU * xi(1));
            strand.curl_phase = blend_phase(own, curl.clump_coherence, || {
                lock_phase(lock_uv, params.seed, 44, 1.0)
            });
            strand.curl_radius_m = curl.radius_m * (1.0 + curl.radius_jitter * (2.0 * xi(2) - 1.0));
        }
        if params.noise.amplitude_m != 0.0 {
            strand.noise_key_u = NOISE_KEY_SPAN * xi(3);
            strand.noise_key_v = NOISE_KEY_SPAN * xi(4);
        }
        let clump = &params.clump;
        if !strand.stray && clump.strength != 0.0 && clump.clumps_per_uv > 0.0 {
            strand.clump_pull = clump_pull(lock_uv, params.seed);
        }
        if !strand.stray && clump.sub_strength != 0.0 && clump.sub_clumps_per_uv > 0.0 {
            strand.sub_clump_pull = clump_pull_on(
                root_uv * clump.sub_clumps_per_uv,
                params.seed,
                SUB_CLUMP_CHANNEL,
            );
        }
        let frizz = &params.frizz;
        if frizz.amplitude_m != 0.0 && (strand.stray || xi(6) < frizz.fraction) {
            strand.frizz = true;
            strand.frizz_key = NOISE_KEY_SPAN * xi(7);
        }
        let wave = &params.wave;
        if wave.amplitude_m != 0.0 {
            let own = unit_phase(wave.phase_spread * TAU * xi(8));
            strand.wave_phase = blend_phase(own, wave.clump_coherence, || {
                lock_phase(lock_uv, params.seed, 45, wave.lock_phase_spread)
            });
        }
        // A stray cell's strands drift as one wisp: direction and key are constant over
        // the cell, so f32 and f64 agree on them (no amplified rounding) except for a root
        // within one f32 step of a cell border, where the cell itself (and whether the
        // strand strays at all) may differ: a step by design, like frizz's selection.
        if strand.stray && stray.amplitude_m != 0.0 {
            strand.stray_direction = unit_phase(TAU * strand_cell_random(params, root_uv, 11));
            strand.stray_key = NOISE_KEY_SPAN * strand_cell_random(params, root_uv, 12);
        }
        strand
    }
}

/// `(cos a, sin a)`.
fn unit_phase(angle_rad: f64) -> DVec2 {
    let (sin, cos) = angle_rad.sin_cos();
    DVec2::new(cos, sin)
}

/// A strand's own phase `own` (a unit vector) blended toward its lock's by `coherence`:
/// `e = (1 − c) own + c lock`, then `e / max(|e|, ½)` — unit length wherever the two do not
/// nearly cancel, and continuous (shrinking toward 0) where they do. At `c = 0` it is `own`
/// and the lock is never evaluated.
pub fn blend_phase(own: DVec2, coherence: f64, lock: impl FnOnce() -> DVec2) -> DVec2 {
    if coherence <= 0.0 {
        return own;
    }
    let c = coherence.min(1.0);
    let e = own * (1.0 - c) + lock() * c;
    e / e.length().max(0.5)
}

/// The hash channel of the sub-clump centres' jitter (x; y is the next one). The main
/// clump's centres use [`CLUMP_CHANNEL`].
pub const SUB_CLUMP_CHANNEL: u32 = 42;
/// The hash channel of the clump centres' jitter (x; y is the next one).
pub const CLUMP_CHANNEL: u32 = 40;

/// A random value that is constant over each cell of the random-value lattice (the cell
/// holding `root_uv · variation_per_uv`) and uniform in `[0, 1)`: for selections by share
/// (strays), where the smooth [`strand_random`] would bunch around ½ and select fewer
/// strands than asked.
pub fn strand_cell_random(params: &StylingParams, root_uv: DVec2, channel: u32) -> f64 {
    let p = root_uv * params.variation_per_uv;
    let p = if p.is_finite() { p } else { DVec2::ZERO };
    let cell = p.floor();
    hash_to_unit(hash_values(&[
        params.seed,
        channel,
        cell.x as i64 as u32,
        cell.y as i64 as u32,
    ]))
}

/// The sum of the offsets of curl, noise, clump, frizz, wave and strays at one vertex (object
/// space). Twist is applied by the strand generator, which knows the bundle's centre strand.
pub fn styling_offset(params: &StylingParams, input: &StylingInput) -> DVec3 {
    styling_offset_of(params, &StrandStyling::new(params, input.root_uv), input)
}

/// `Im`-and-`Re` rotation of the phase vector `e` by `angle_rad`: `e · exp(i angle)`.
fn rotate(e: DVec2, angle_rad: f64) -> DVec2 {
    let (sin, cos) = angle_rad.sin_cos();
    DVec2::new(e.x * cos - e.y * sin, e.x * sin + e.y * cos)
}

/// [`styling_offset`] with the strand's constant part computed already (once per strand).
pub(crate) fn styling_offset_of(
    params: &StylingParams,
    strand: &StrandStyling,
    input: &StylingInput,
) -> DVec3 {
    let StylingInput { u, v, w, along, .. } = *input;
    if along <= 0.0 || w <= 0.0 {
        return DVec3::ZERO;
    }
    let mut offset = DVec3::ZERO;
    let curl = &params.curl;
    if curl.radius_m != 0.0 {
        let rate = 1.0 + (curl.rate_tip_scale - 1.0) * along * 0.5;
        let turned = rotate(strand.curl_phase, TAU * curl.turns_per_m * w * rate);
        let radius = strand.curl_radius_m * (1.0 + (curl.radius_tip_scale - 1.0) * along);
        offset += smoothstep(curl.ramp_in_m, w) * radius * (turned.x * u + turned.y * v);
    }
    let noise = &params.noise;
    if noise.amplitude_m != 0.0 {
        let (key_u, key_v) = (strand.noise_key_u, strand.noise_key_v);
        let (mut nu, mut nv, mut gain, mut frequency) = (0.0, 0.0, 1.0, noise.frequency_per_m);
        for octave in 0..noise.octaves.max(1) {
            nu += gain * value_noise_1d(frequency * w + key_u, params.seed, 10 + octave);
            nv += gain * value_noise_1d(frequency * w + key_v, params.seed, 20 + octave);
            gain *= 0.5;
            frequency *= 2.0;
        }
        offset += noise.amplitude_m * along * (nu * u + nv * v);
    }
    let clump = &params.clump;
    if (clump.strength != 0.0 || clump.sub_strength != 0.0) && !strand.stray {
        let profile = along.powf(clump.tightening.max(0.0));
        let pull = strand.clump_pull * (clump.strength * clump.radius_m)
            + strand.sub_clump_pull * (clump.sub_strength * clump.sub_radius_m);
        offset += profile * (pull.x * u + pull.y * v);
    }
    let frizz = &params.frizz;
    if frizz.amplitude_m != 0.0 && strand.frizz {
        let key = strand.frizz_key;
        let a = value_noise_1d(frizz.frequency_per_m * w + key, params.seed, 30);
        let b = value_noise_1d(frizz.frequency_per_m * w + key + 500.0, params.seed, 31);
        offset += frizz.amplitude_m * along * along * (a * u + b * v);
    }
    let wave = &params.wave;
    if wave.amplitude_m != 0.0 {
        let turned = rotate(strand.wave_phase, TAU * wave.frequency_per_m * w);
        let direction = wave.direction_rad.cos() * u + wave.direction_rad.sin() * v;
        offset += smoothstep(wave.ramp_in_m, w) * wave.amplitude_m * turned.y * direction;
    }
    let stray = &params.stray;
    if stray.amplitude_m != 0.0 && strand.stray {
        let key = strand.stray_key;
        let a = value_noise_1d(stray.frequency_per_m * w + key, params.seed, 50);
        let b = value_noise_1d(stray.frequency_per_m * w + key + 500.0, params.seed, 51);
        let drift = strand.stray_direction + 0.5 * DVec2::new(a, b);
        offset += stray.amplitude_m * along * along * (drift.x * u + drift.y * v);
    }
    offset
}

/// Clump pull at `x` (in clump-cell units): `Σ K_i (c_i − x) / (Σ K_i + ¼)` over the jittered
/// centres `c_i` of the 3×3 neighbouring cells, `K = max(0, 1 − d²)²`. Continuous in `x`:
/// centres further than one cell have zero weight, and the `+ ¼` keeps the ratio continuous
/// where the weight sum vanishes.
pub fn clump_pull(x: DVec2, seed: u32) -> DVec2 {
    clump_pull_on(x, seed, CLUMP_CHANNEL)
}

/// [`clump_pull`] with the centres' jitter hashed on `channel` (x) and `channel + 1` (y):
/// one lattice per clump level.
pub fn clump_pull_on(x: DVec2, seed: u32, channel: u32) -> DVec2 {
    let mut weighted = DVec2::ZERO;
    let mut total = 0.0;
    for_each_centre(x, seed, channel, |_, d, k| {
        weighted += k * d;
        total += k;
    });
    weighted / (total + 0.25)
}

/// A lock's phase at `x` (clump-cell units of the main clump lattice): every clump centre
/// draws an angle `spread · 2π unit(hash(seed, channel, cx, cy))` and the strand reads their
/// kernel-weighted average `Σ K_i (cos, sin)_i / (Σ K_i + ¼)`, with the clump pull's weights
/// — continuous, and near a centre close to that centre's own angle. Channels: 44 curl
/// (spread 1: every ringlet its own), 45 wave (`wave.lock_phase_spread`).
pub fn lock_phase(x: DVec2, seed: u32, channel: u32, spread: f64) -> DVec2 {
    let mut weighted = DVec2::ZERO;
    let mut total = 0.0;
    for_each_centre(x, seed, CLUMP_CHANNEL, |(ix, iy), _, k| {
        let unit = hash_to_unit(hash_values(&[seed, channel, ix, iy]));
        weighted += k * unit_phase(spread * TAU * unit);
        total += k;
    });
    weighted / (total + 0.25)
}

/// Calls `f((cx, cy), c − x, K)` for the jittered centre `c` of each of the 3×3 cells around
/// `x` (dy outer, dx inner: the order the shader sums in), `K = max(0, 1 − |c − x|²)²`.
fn for_each_centre(x: DVec2, seed: u32, channel: u32, mut f: impl FnMut((u32, u32), DVec2, f64)) {
    let x = if x.is_finite() { x } else { DVec2::ZERO };
    let cell = x.floor();
    for dy in -1..=1 {
        for dx in -1..=1 {
            let c = cell + DVec2::new(dx as f64, dy as f64);
            let (ix, iy) = (c.x as i64 as u32, c.y as i64 as u32);
            let jitter = DVec2::new(
                hash_to_unit(hash_values(&[seed, channel, ix, iy])),
                hash_to_unit(hash_values(&[seed, channel + 1, ix, iy])),
            );
            let d = c + jitter - x;
            let k = (1.0 - d.length_squared()).max(0.0).powi(2);
            f((ix, iy), d, k);
        }
    }
}

/// Segments a strand needs per curl turn or wave cycle to draw it as a curve, not a zigzag.
pub const SEGMENTS_PER_TURN: f64 = 8.0;
/// The fewest and most vertices per strand [`strand_vertices_log2`] chooses: 2^4 + 1 = 17
/// (plain hair) to 2^7 + 1 = 129 (tight ringlets on long hair).
pub const STRAND_VERTICES_LOG2_RANGE: (u32, u32) = (4, 7);

/// The vertices per strand (2^N + 1, as N) that draw the styling's finest shape along the
/// strand: [`SEGMENTS_PER_TURN`] segments per curl turn (at the rate the tip reaches) or wave
/// cycle over `longest_w` (the longest strand's w), within [`STRAND_VERTICES_LOG2_RANGE`].
/// Seventeen vertices drew a 6-turn ringlet as 16 straight pieces: straw-like frizz.
pub fn strand_vertices_log2(set: &crate::model::styling::StylingSet, longest_w: f64) -> u32 {
    let (fewest, most) = STRAND_VERTICES_LOG2_RANGE;
    let longest_w = if longest_w.is_finite() {
        longest_w.max(0.0)
    } else {
        0.0
    };
    let cycles_per_m = std::iter::once(&set.global)
        .chain(set.groups.iter().map(|g| &g.params))
        .map(|p| {
            let curl = if p.curl.radius_m != 0.0 {
                p.curl.turns_per_m.abs() * p.curl.rate_tip_scale.max(1.0)
            } else {
                0.0
            };
            let wave = if p.wave.amplitude_m != 0.0 {
                p.wave.frequency_per_m.abs()
            } else {
                0.0
            };
            curl.max(wave)
        })
        .fold(0.0, f64::max);
    let segments = SEGMENTS_PER_TURN * cycles_per_m * longest_w;
    // NaN-safe: anything not above one segment (NaN included) takes the fewest.
    if segments.is_nan() || segments <= 1.0 {
        return fewest;
    }
    (segments.log2().ceil() as u32).clamp(fewest, most)
}

/// Twist: rotates `position` about the bundle centre strand point `centre` by
/// `2π · turns_per_m · w` around `axis` (Rodrigues).
pub fn twist(params: &StylingParams, position: DVec3, centre: DVec3, axis: DVec3, w: f64) -> DVec3 {
    if params.twist.turns_per_m == 0.0 || w <= 0.0 {
        return position;
    }
    let Some(k) = axis.try_normalize() else {
        return position;
    };
    let angle = TAU * params.twist.turns_per_m * w;
    let o = position - centre;
    let (sin, cos) = angle.sin_cos();
    centre + o * cos + k.cross(o) * sin + k * k.dot(o) * (1.0 - cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(root_uv: DVec2, w: f64, along: f64) -> StylingInput {
        StylingInput {
            u: DVec3::X,
            v: DVec3::Y,
            w_axis: DVec3::Z,
            root_uv,
            w,
            along,
        }
    }

    #[test]
    fn nothing_at_the_root_and_nothing_when_disabled() {
        let params = StylingParams::every_op();
        assert_eq!(
            styling_offset(&params, &input(DVec2::splat(0.3), 0.0, 0.0)),
            DVec3::ZERO
        );
        let off = StylingParams::default();
        assert_eq!(
            styling_offset(&off, &input(DVec2::splat(0.3), 0.2, 0.5)),
            DVec3::ZERO
        );
        assert_eq!(strand_length_fraction(&off, DVec2::splat(0.3)), 1.0);
        assert!(styling_offset(&params, &input(DVec2::splat(0.3), 0.2, 0.5)).length() > 1e-4);
    }

    #[test]
    fn offsets_are_bounded_by_the_amplitudes() {
        let params = StylingParams::every_op();
        let bound = params.curl.radius_m * 1.3
            + params.noise.amplitude_m * 2.0
            + params.clump.strength * params.clump.radius_m * 1.5
            + params.frizz.amplitude_m
            + params.wave.amplitude_m
            + params.stray.amplitude_m * (1.0 + 0.5 * 2f64.sqrt());
        for i in 0..2000 {
            let t = i as f64 / 2000.0;
            let uv = DVec2::new((t * 37.0).fract(), (t * 91.0).fract());
            let offset = styling_offset(&params, &input(uv, t * 0.3, t));
            assert!(offset.is_finite() && offset.length() <= bound, "{offset}");
        }
    }

    #[test]
    fn close_roots_get_close_offsets() {
        // O(ε): the offset difference shrinks linearly with the root distance.
        let params = StylingParams::every_op();
        let root = DVec2::new(0.4123, 0.7789);
        for w in [0.05, 0.13, 0.29] {
            let base = styling_offset(&params, &input(root, w, w / 0.3));
            for epsilon in [1e-4, 1e-5, 1e-6, 1e-7] {
                let moved = styling_offset(
                    &params,
                    &input(root + DVec2::new(epsilon, -epsilon), w, w / 0.3),
                );
                let change = moved.distance(base);
                // Lipschitz bound: amplitudes (≤ 2 cm) × variation cells per uv (200) × key span.
                assert!(change < 100.0 * epsilon, "w {w}, ε {epsilon}: {change}");
            }
        }
    }

    #[test]
    fn clump_pull_is_continuous_and_points_to_centres() {
        let mut last = clump_pull(DVec2::new(3.0, 5.0), 1);
        for i in 1..=4000 {
            let x = DVec2::new(3.0 + i as f64 * 0.001, 5.0 + i as f64 * 0.0007);
            let pull = clump_pull(x, 1);
            assert!(pull.distance(last) < 0.01, "jump at {x}");
            assert!(pull.length() < 1.0);
            last = pull;
        }
    }

    /// Roots on a line across uv, `step` apart, as a deterministic spread of strands.
    fn roots(count: usize, step: f64) -> impl Iterator<Item = DVec2> {
        (0..count).map(move |i| DVec2::new(0.1 + i as f64 * step, 0.3 + i as f64 * step * 0.37))
    }

    #[test]
    fn ringlets_share_their_locks_helix_and_waves_their_locks_phase() {
        // Pairs of roots a tenth of a clump cell apart but 10 random-value cells apart: their
        // own phases are unrelated, their lock is (almost always) the same.
        let mut params = StylingParams::default();
        params.curl.radius_m = 0.005;
        params.wave.amplitude_m = 0.005;
        params.wave.phase_spread = 1.0;
        params.clump.clumps_per_uv = 10.0;
        params.variation_per_uv = 1000.0;
        let spread = |params: &StylingParams| {
            let (mut curl, mut wave) = (0.0, 0.0);
            let n = 2000;
            for root in roots(n, 0.000_37) {
                let a = StrandStyling::new(params, root);
                let b = StrandStyling::new(params, root + DVec2::new(0.01, 0.0));
                curl += a.curl_phase.distance(b.curl_phase) / n as f64;
                wave += a.wave_phase.distance(b.wave_phase) / n as f64;
            }
            (curl, wave)
        };
        let (curl_free, wave_free) = spread(&params);
        params.curl.clump_coherence = 1.0;
        params.wave.clump_coherence = 1.0;
        let (curl_locked, wave_locked) = spread(&params);
        // Independent unit vectors are 4/π ≈ 1.27 apart on average.
        assert!(
            curl_free > 1.0 && wave_free > 1.0,
            "{curl_free} {wave_free}"
        );
        assert!(
            curl_locked < 0.35 * curl_free,
            "{curl_locked} vs {curl_free}"
        );
        assert!(
            wave_locked < 0.35 * wave_free,
            "{wave_locked} vs {wave_free}"
        );
        // Locked phases still differ between locks.
        let far: f64 = roots(500, 0.0037)
            .map(|root| {
                let a = StrandStyling::new(&params, root);
                let b = StrandStyling::new(&params, root + DVec2::new(0.3, 0.2));
                a.curl_phase.distance(b.curl_phase)
            })
            .sum::<f64>()
            / 500.0;
        assert!(far > 0.8, "locks apart share a phase: {far}");
    }

    /// `wave.lock_phase_spread` decides how far apart locks wave: at 0 every lock is in step
    /// (crests run as bands across the head), at 1 each lock has any phase; a document that
    /// predates the field reads 1, the phases it had.
    #[test]
    fn wave_lock_phase_spread_keeps_locks_in_step() {
        let mut params = StylingParams::default();
        params.wave.amplitude_m = 0.005;
        params.wave.phase_spread = 0.0;
        params.wave.clump_coherence = 1.0;
        params.clump.clumps_per_uv = 10.0;
        let apart = |spread: f64| {
            let mut params = params.clone();
            params.wave.lock_phase_spread = spread;
            roots(500, 0.0037)
                .map(|root| {
                    let a = StrandStyling::new(&params, root);
                    let b = StrandStyling::new(&params, root + DVec2::new(0.3, 0.2));
                    // Directions: the blend shrinks where the lock kernel is weak.
                    let (a, b) = (a.wave_phase.normalize(), b.wave_phase.normalize());
                    a.distance(b)
                })
                .sum::<f64>()
                / 500.0
        };
        let (step, near, free) = (apart(0.0), apart(0.2), apart(1.0));
        assert!(step < 1e-9, "in step: {step}");
        // Angles within a fifth of a cycle: chords under 2 sin(π/5) ≈ 1.18, mostly far less.
        assert!(near > 0.05 && near < 0.5, "a fifth of a cycle: {near}");
        assert!(free > 0.8, "any phase: {free}");
        let old: crate::model::styling::Wave =
            serde_json::from_str(r#"{"amplitude_m": 0.01, "clump_coherence": 0.9}"#)
                .expect("a wave without the field parses");
        assert_eq!(old.lock_phase_spread, 1.0);
    }

    #[test]
    fn lock_phase_is_continuous_and_blends_to_unit_length() {
        let mut last = lock_phase(DVec2::new(3.0, 5.0), 1, 44, 1.0);
        for i in 1..=4000 {
            let x = DVec2::new(3.0 + i as f64 * 0.001, 5.0 + i as f64 * 0.0007);
            let phase = lock_phase(x, 1, 44, 1.0);
            assert!(phase.distance(last) < 0.02, "jump at {x}");
            assert!(phase.length() < 1.0);
            last = phase;
        }
        // The blend is continuous too, shrinking only where own and lock phases cancel.
        let blend = |x: DVec2| blend_phase(DVec2::X, 0.7, || lock_phase(x, 1, 44, 1.0));
        let mut last = blend(DVec2::new(3.0, 5.0));
        for i in 1..=4000 {
            let x = DVec2::new(3.0 + i as f64 * 0.001, 5.0 + i as f64 * 0.0007);
            let blended = blend(x);
            assert!(blended.distance(last) < 0.05, "jump at {x}");
            last = blended;
        }
        assert_eq!(blend_phase(DVec2::Y, 0.0, || unreachable!()), DVec2::Y);
    }

    #[test]
    fn curl_radius_and_rate_follow_the_strand_and_default_to_the_plain_helix() {
        let mut params = StylingParams {
            curl: crate::model::styling::Curl {
                radius_m: 0.01,
                turns_per_m: 30.0,
                ramp_in_m: 0.0,
                radius_jitter: 0.0,
                ..Default::default()
            },
            ..StylingParams::default()
        };
        let root = DVec2::new(0.31, 0.62);
        let at = |params: &StylingParams, w: f64, along: f64| {
            styling_offset(params, &input(root, w, along))
        };
        // The plain helix: ramp · r · (cos(ψ + φ), sin(ψ + φ)).
        let phase = TAU * strand_random(&params, root, 1);
        for (w, along) in [(0.01, 0.1), (0.07, 0.5), (0.2, 1.0)] {
            let psi = TAU * 30.0 * w + phase;
            let expected = 0.01 * DVec3::new(psi.cos(), psi.sin(), 0.0);
            assert!(at(&params, w, along).distance(expected) < 1e-15);
        }
        params.curl.radius_tip_scale = 0.5;
        params.curl.rate_tip_scale = 2.0;
        assert!((at(&params, 0.2, 1.0).length() - 0.005).abs() < 1e-12);
        assert!((at(&params, 0.1, 0.5).length() - 0.0075).abs() < 1e-12);
        // The rate moves linearly along the strand: the phase at the tip has turned
        // (1 + (2 − 1) / 2) = 1.5 × as far as the plain helix's.
        let tip = at(&params, 0.2, 1.0);
        let psi = TAU * 30.0 * 0.2 * 1.5 + phase;
        assert!(tip.distance(0.005 * DVec3::new(psi.cos(), psi.sin(), 0.0)) < 1e-12);
    }

    #[test]
    fn strays_are_the_asked_share_leave_their_clump_and_end_shorter() {
        let mut params = StylingParams::every_op();
        params.stray.fraction = 0.1;
        params.length.fraction = 0.0;
        // One root in each of 20,164 distinct random-value cells (a 142 × 142 grid over uv,
        // 200 cells per uv): the share's standard deviation is 0.002.
        let side = 142;
        let n = side * side;
        let mut strays = 0;
        let grid = (0..n)
            .map(|i| DVec2::new((i % side) as f64 + 0.5, (i / side) as f64 + 0.5) / side as f64);
        for root in grid {
            let strand = StrandStyling::new(&params, root);
            let length = strand_length_fraction(&params, root);
            if strand.stray {
                strays += 1;
                assert_eq!(strand.clump_pull, DVec2::ZERO);
                assert_eq!(strand.sub_clump_pull, DVec2::ZERO);
                assert!(strand.frizz, "a stray frizzes");
                assert!((strand.stray_direction.length() - 1.0).abs() < 1e-12);
                assert!(
                    (params.stray.length_min..=1.0).contains(&length),
                    "{length}"
                );
            } else {
                let lattice = root * params.clump.clumps_per_uv;
                assert_eq!(strand.clump_pull, clump_pull(lattice, params.seed));
                assert_eq!(length, 1.0);
            }
        }
        let share = strays as f64 / n as f64;
        assert!((share - 0.1).abs() < 0.01, "{share}");
        // Off: nobody strays, lengths untouched.
        params.stray.fraction = 0.0;
        assert!(
            roots(2000, 0.0004).all(|r| !StrandStyling::new(&params, r).stray
                && strand_length_fraction(&params, r) == 1.0)
        );
    }

    #[test]
    fn the_hairline_thins_evenly_and_shortens_toward_the_border() {
        use crate::model::styling::Hairline;
        let mut params = StylingParams::default();
        let n = 64;
        let ranks: Vec<f64> = (0..n).map(|j| (j as f64 + 0.5) / n as f64).collect();
        // Off: every strand, full length, wherever it is.
        assert!(
            ranks
                .iter()
                .all(|&r| hairline_length_scale(&params, 0.0, r) == 1.0)
        );
        params.hairline = Hairline {
            width_m: 0.01,
            edge_density: 0.25,
            edge_length: 0.4,
        };
        let grown_with = |params: &StylingParams, distance: f64| {
            ranks
                .iter()
                .filter(|&&r| hairline_length_scale(params, distance, r) > 0.0)
                .count()
        };
        let grown = |distance: f64| grown_with(&params, distance);
        // At the border: the asked share grows (the first samples: an even cover), at the
        // edge length.
        assert_eq!(grown(0.0), 16);
        assert!(
            ranks[..16]
                .iter()
                .all(|&r| (hairline_length_scale(&params, 0.0, r) - 0.4).abs() < 1e-15)
        );
        // A width or more inside: exactly as without the op.
        for distance in [0.01, 0.0100001, 0.5, 65504.0] {
            assert!(
                ranks
                    .iter()
                    .all(|&r| hairline_length_scale(&params, distance, r) == 1.0)
            );
        }
        // In between: more strands and longer ones the further in, never fewer.
        let mut last = (0, 0.0);
        for i in 0..=100 {
            let distance = 0.01 * i as f64 / 100.0;
            let length = hairline_length_scale(&params, distance, ranks[0]);
            assert!(grown(distance) >= last.0 && length >= last.1, "{distance}");
            last = (grown(distance), length);
        }
        assert_eq!(grown(0.005), 40, "half way: (0.25 + 0.75 · ½) of 64");
        // Negative and NaN distances count as on the border; an edge density of 0 grows
        // nothing there.
        assert_eq!(grown(-1.0), 16);
        assert_eq!(grown(f64::NAN), 16);
        let mut bare_edge = params.clone();
        bare_edge.hairline.edge_density = 0.0;
        assert_eq!(grown_with(&bare_edge, 0.0), 0);
    }

    #[test]
    fn sub_clumps_gather_strands_on_a_finer_lattice() {
        // Sign changes of the pull's x along a line: one per clump crossed.
        let crossings = |channel: u32, per_uv: f64| {
            let pulls: Vec<f64> = roots(4000, 0.0002)
                .map(|r| clump_pull_on(r * per_uv, 3, channel).x)
                .collect();
            pulls.windows(2).filter(|p| p[0] * p[1] < 0.0).count()
        };
        let main = crossings(CLUMP_CHANNEL, 40.0);
        let sub = crossings(SUB_CLUMP_CHANNEL, 160.0);
        assert!(sub as f64 > 2.5 * main as f64, "main {main}, sub {sub}");
        // Its own centres: the sub lattice at the main density is not the main lattice.
        let x = DVec2::new(2.37, 4.81);
        assert_ne!(
            clump_pull_on(x, 3, CLUMP_CHANNEL),
            clump_pull_on(x, 3, SUB_CLUMP_CHANNEL)
        );
    }

    #[test]
    fn curly_styles_get_the_vertices_their_turns_need() {
        use crate::model::styling::StylingSet;
        let mut set = StylingSet::default();
        assert_eq!(
            strand_vertices_log2(&set, 0.3),
            4,
            "plain hair: 17 vertices"
        );
        set.global.curl.radius_m = 0.007;
        set.global.curl.turns_per_m = 40.0;
        // 40 turns/m × 0.15 m × 8 = 48 segments: 64.
        assert_eq!(strand_vertices_log2(&set, 0.15), 6);
        set.global.curl.rate_tip_scale = 1.5;
        // 72 segments: 128.
        assert_eq!(strand_vertices_log2(&set, 0.15), 7);
        assert_eq!(strand_vertices_log2(&set, 100.0), 7, "at most 129");
        for w in [f64::NAN, f64::INFINITY, -1.0, 0.0] {
            assert_eq!(strand_vertices_log2(&set, w), 4, "{w}");
        }
        // A group's waves count too.
        let mut set = StylingSet::default();
        set.new_group("waves", &[0]);
        set.groups[0].params.wave.amplitude_m = 0.01;
        set.groups[0].params.wave.frequency_per_m = 20.0;
        assert_eq!(strand_vertices_log2(&set, 0.4), 6);
    }

    #[test]
    fn twist_keeps_distance_from_the_centre_and_leaves_the_centre_alone() {
        let params = StylingParams::every_op();
        let centre = DVec3::new(0.1, 0.2, 0.3);
        let p = centre + DVec3::new(0.01, 0.0, 0.002);
        let twisted = twist(&params, p, centre, DVec3::Z, 0.1);
        assert!((twisted.distance(centre) - p.distance(centre)).abs() < 1e-15);
        assert!(twisted.distance(p) > 1e-3);
        assert_eq!(twist(&params, centre, centre, DVec3::Z, 0.1), centre);
        assert_eq!(twist(&params, p, centre, DVec3::ZERO, 0.1), p);
    }

    #[test]
    fn extreme_inputs_stay_finite() {
        let mut params = StylingParams::every_op();
        params.curl.turns_per_m = 1e9; // far above any vertex count
        params.noise.frequency_per_m = 1e9;
        for uv in [
            DVec2::splat(1e9),
            DVec2::splat(-1e9),
            DVec2::NAN,
            DVec2::ZERO,
        ] {
            for w in [1e-12, 1.0, 1e6] {
                assert!(styling_offset(&params, &input(uv, w, 1.0)).is_finite());
            }
        }
    }
}
