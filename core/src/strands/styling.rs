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

/// Fraction of the bundle's length this strand keeps (length variation).
pub fn strand_length_fraction(params: &StylingParams, root_uv: DVec2) -> f64 {
    if params.length.fraction <= 0.0 {
        return 1.0;
    }
    1.0 - params.length.fraction.clamp(0.0, 1.0) * strand_random(params, root_uv, 5)
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
/// random values (phases, keys, radius jitter, whether it frizzes) and its clump pull. The
/// CPU generators compute this once per strand, not once per vertex; the values are the same
/// expressions [`styling_offset`] evaluates, so the split changes no result. Ops that are
/// off leave their fields zero.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StrandStyling {
    /// `2π ξ₁`: the curl's phase at w = 0.
    pub curl_phase_rad: f64,
    /// The curl radius with this strand's jitter, metres.
    pub curl_radius_m: f64,
    /// Where this strand reads the two noise curves (`NOISE_KEY_SPAN · ξ₃`, `· ξ₄`).
    pub noise_key_u: f64,
    pub noise_key_v: f64,
    /// The clump pull at the strand's root (clump-cell units).
    pub clump_pull: DVec2,
    /// Whether the strand frizzes (`ξ₆ < fraction`), and where it reads the frizz noise.
    pub frizz: bool,
    pub frizz_key: f64,
    /// `phase_spread · 2π · ξ₈`: the wave's phase offset.
    pub wave_phase_rad: f64,
}

impl StrandStyling {
    pub fn new(params: &StylingParams, root_uv: DVec2) -> Self {
        let mut strand = Self::default();
        let curl = &params.curl;
        if curl.radius_m != 0.0 {
            strand.curl_phase_rad = TAU * strand_random(params, root_uv, 1);
            strand.curl_radius_m = curl.radius_m
                * (1.0 + curl.radius_jitter * (2.0 * strand_random(params, root_uv, 2) - 1.0));
        }
        if params.noise.amplitude_m != 0.0 {
            strand.noise_key_u = NOISE_KEY_SPAN * strand_random(params, root_uv, 3);
            strand.noise_key_v = NOISE_KEY_SPAN * strand_random(params, root_uv, 4);
        }
        let clump = &params.clump;
        if clump.strength != 0.0 && clump.clumps_per_uv > 0.0 {
            strand.clump_pull = clump_pull(root_uv * clump.clumps_per_uv, params.seed);
        }
        let frizz = &params.frizz;
        if frizz.amplitude_m != 0.0 && strand_random(params, root_uv, 6) < frizz.fraction {
            strand.frizz = true;
            strand.frizz_key = NOISE_KEY_SPAN * strand_random(params, root_uv, 7);
        }
        let wave = &params.wave;
        if wave.amplitude_m != 0.0 {
            strand.wave_phase_rad = wave.phase_spread * TAU * strand_random(params, root_uv, 8);
        }
        strand
    }
}

/// The sum of the offsets of curl, noise, clump, frizz and wave at one vertex (object space).
/// Twist is applied by the strand generator, which knows the bundle's centre strand.
pub fn styling_offset(params: &StylingParams, input: &StylingInput) -> DVec3 {
    styling_offset_of(params, &StrandStyling::new(params, input.root_uv), input)
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
        let phase = TAU * curl.turns_per_m * w + strand.curl_phase_rad;
        offset += smoothstep(curl.ramp_in_m, w)
            * strand.curl_radius_m
            * (phase.cos() * u + phase.sin() * v);
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
    if clump.strength != 0.0 && clump.clumps_per_uv > 0.0 {
        let pull = strand.clump_pull;
        let scale = clump.strength * along.powf(clump.tightening.max(0.0)) * clump.radius_m;
        offset += scale * (pull.x * u + pull.y * v);
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
        let phase = TAU * wave.frequency_per_m * w + strand.wave_phase_rad;
        let direction = wave.direction_rad.cos() * u + wave.direction_rad.sin() * v;
        offset += smoothstep(wave.ramp_in_m, w) * wave.amplitude_m * phase.sin() * direction;
    }
    offset
}

/// Clump pull at `x` (in clump-cell units): `Σ K_i (c_i − x) / (Σ K_i + ¼)` over the jittered
/// centres `c_i` of the 3×3 neighbouring cells, `K = max(0, 1 − d²)²`. Continuous in `x`:
/// centres further than one cell have zero weight, and the `+ ¼` keeps the ratio continuous
/// where the weight sum vanishes.
pub fn clump_pull(x: DVec2, seed: u32) -> DVec2 {
    let x = if x.is_finite() { x } else { DVec2::ZERO };
    let cell = x.floor();
    let mut weighted = DVec2::ZERO;
    let mut total = 0.0;
    for dy in -1..=1 {
        for dx in -1..=1 {
            let c = cell + DVec2::new(dx as f64, dy as f64);
            let (ix, iy) = (c.x as i64 as u32, c.y as i64 as u32);
            let jitter = DVec2::new(
                hash_to_unit(hash_values(&[seed, 40, ix, iy])),
                hash_to_unit(hash_values(&[seed, 41, ix, iy])),
            );
            let centre = c + jitter;
            let d2 = (centre - x).length_squared();
            let k = (1.0 - d2).max(0.0).powi(2);
            weighted += k * (centre - x);
            total += k;
        }
    }
    weighted / (total + 0.25)
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
            + params.wave.amplitude_m;
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
