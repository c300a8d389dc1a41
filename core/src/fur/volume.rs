//! The fur volume patch (seed 002 §2.2, after Lengyel 2000): a small box of real strands,
//! toroidal along the two skin axes so that its textures tile, grown by a particle
//! simulation. Every shell and fin texture is sampled from it.
//!
//! Coordinates are metres in the patch's own frame: `x, y` along the skin in
//! `[0, tile_width_m)` (wrapping), `z` up from the skin in `[0, length_m]`.

use glam::DVec3;

use crate::strands::random::SplitMix64;

/// The looks seed 002 shows (its Fig. 5): straight, curly, sparse and dense fur.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FurPreset {
    Straight,
    Curly,
    Sparse,
    Dense,
}

impl FurPreset {
    pub const ALL: [FurPreset; 4] = [Self::Straight, Self::Curly, Self::Sparse, Self::Dense];

    pub fn name(self) -> &'static str {
        match self {
            Self::Straight => "straight",
            Self::Curly => "curly",
            Self::Sparse => "sparse",
            Self::Dense => "dense",
        }
    }

    /// The particle system's parameters for this look, for a 1 cm tile of 1 cm fur.
    pub fn params(self) -> FurVolumeParams {
        let base = FurVolumeParams {
            tile_width_m: 0.01,
            length_m: 0.01,
            strand_count: 1600,
            strand_radius_m: 40e-6,
            steps: 24,
            slant: 0.15,
            wander: 0.08,
            curl_radius_m: 0.0,
            curl_turns: 0.0,
            length_variation: 0.35,
            tint_variation: 0.25,
            seed: 2002,
        };
        match self {
            Self::Straight => base,
            Self::Curly => FurVolumeParams {
                curl_radius_m: 0.0009,
                curl_turns: 2.5,
                strand_count: 1000,
                wander: 0.12,
                steps: 48,
                ..base
            },
            Self::Sparse => FurVolumeParams {
                strand_count: 500,
                strand_radius_m: 55e-6,
                ..base
            },
            Self::Dense => FurVolumeParams {
                strand_count: 4000,
                strand_radius_m: 32e-6,
                ..base
            },
        }
    }
}

/// The particle system that grows a fur volume patch.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FurVolumeParams {
    /// The patch's width along both skin axes; its textures repeat at this spacing.
    pub tile_width_m: f64,
    /// The longest strand's height above the skin (the volume's height).
    pub length_m: f64,
    pub strand_count: u32,
    pub strand_radius_m: f64,
    /// Particle steps per strand (its polyline has `steps + 1` points).
    pub steps: u32,
    /// How far strands lean along +x (the direction field's way) per unit of height.
    pub slant: f64,
    /// Random turning of the particle's velocity, as a share of its speed per step.
    pub wander: f64,
    /// Helix radius of curly fur (0: no curl).
    pub curl_radius_m: f64,
    /// Helix turns over the full length.
    pub curl_turns: f64,
    /// Strand lengths vary down to `1 − length_variation` of `length_m`.
    pub length_variation: f64,
    /// Strand brightness varies down to `1 − tint_variation`.
    pub tint_variation: f64,
    pub seed: u64,
}

/// Why a volume cannot be grown from these parameters.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FurVolumeError {
    #[error("fur volume: {name} is {value}, it must be finite and in {range}")]
    OutOfRange {
        name: &'static str,
        value: f64,
        range: &'static str,
    },
}

/// The most strands one tile may hold: a 1 cm tile of the densest animal fur has a few
/// thousand; this bound keeps the sampler's time and memory bounded for hostile input.
pub const MAX_VOLUME_STRANDS: u32 = 200_000;
/// The most particle steps per strand.
pub const MAX_VOLUME_STEPS: u32 = 1024;

impl FurVolumeParams {
    pub fn validate(&self) -> Result<(), FurVolumeError> {
        let check = |name, value: f64, lo: f64, hi: f64, range| {
            if value.is_finite() && value >= lo && value <= hi {
                Ok(())
            } else {
                Err(FurVolumeError::OutOfRange { name, value, range })
            }
        };
        check("tile_width_m", self.tile_width_m, 1e-5, 1.0, "[1e-5, 1] m")?;
        check("length_m", self.length_m, 1e-5, 1.0, "[1e-5, 1] m")?;
        check(
            "strand_count",
            self.strand_count as f64,
            1.0,
            MAX_VOLUME_STRANDS as f64,
            "[1, 200000]",
        )?;
        check(
            "strand_radius_m",
            self.strand_radius_m,
            1e-7,
            self.tile_width_m * 0.1,
            "(0, tile_width_m / 10]",
        )?;
        check(
            "steps",
            self.steps as f64,
            1.0,
            MAX_VOLUME_STEPS as f64,
            "[1, 1024]",
        )?;
        check("slant", self.slant, 0.0, 1.0, "[0, 1] (0° to 45°)")?;
        check("wander", self.wander, 0.0, 2.0, "[0, 2]")?;
        check(
            "curl_radius_m",
            self.curl_radius_m,
            0.0,
            self.tile_width_m * 0.5,
            "[0, tile_width_m / 2]",
        )?;
        check("curl_turns", self.curl_turns, 0.0, 64.0, "[0, 64]")?;
        check(
            "length_variation",
            self.length_variation,
            0.0,
            0.95,
            "[0, 0.95]",
        )?;
        check("tint_variation", self.tint_variation, 0.0, 1.0, "[0, 1]")?;
        Ok(())
    }
}

/// One grown strand: its points from root (on the skin, `z = 0`) to tip, unwrapped (a strand
/// may leave the tile; samplers wrap its points), and its brightness.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeStrand {
    pub points: Vec<DVec3>,
    pub tint: f32,
}

/// A grown fur volume patch.
#[derive(Clone, Debug, PartialEq)]
pub struct FurVolume {
    pub params: FurVolumeParams,
    pub strands: Vec<VolumeStrand>,
}

impl FurVolume {
    /// Grows the patch: each strand is a particle launched from a random root with a speed
    /// that takes it to its length in `steps` steps; each step its velocity turns by a random
    /// wander and is pulled back toward the growth direction (up, leaning by `slant`), so
    /// strands stay above the skin; curly fur adds a helix about the growth direction.
    pub fn grow(params: &FurVolumeParams) -> Result<Self, FurVolumeError> {
        params.validate()?;
        let mut random = SplitMix64::new(params.seed);
        let growth = DVec3::new(params.slant, 0.0, 1.0).normalize();
        // A frame about the growth direction for the helix.
        let side = DVec3::Y;
        let across = growth.cross(side).normalize();
        let steps = params.steps as usize;
        let strands = (0..params.strand_count)
            .map(|_| {
                let root = DVec3::new(
                    random.next_f64() * params.tile_width_m,
                    random.next_f64() * params.tile_width_m,
                    0.0,
                );
                let length = params.length_m * (1.0 - params.length_variation * random.next_f64());
                let tint = (1.0 - params.tint_variation * random.next_f64()) as f32;
                let phase = random.next_f64() * std::f64::consts::TAU;
                // Arc length per step along the growth direction (the helix adds to it).
                let step = length / params.steps as f64 / growth.z;
                let mut direction = growth;
                let mut axis_point = root;
                let mut points = Vec::with_capacity(steps + 1);
                points.push(root);
                for k in 1..=steps {
                    let turn = DVec3::new(
                        random.next_f64() - 0.5,
                        random.next_f64() - 0.5,
                        random.next_f64() - 0.5,
                    ) * (2.0 * params.wander);
                    // Wander, then a spring back toward the growth direction keeps the
                    // velocity within about 45° of it, so strands never dive into the skin.
                    direction = (direction + turn + (growth - direction) * 0.5).normalize();
                    if direction.z < 0.3 {
                        direction = (direction + DVec3::Z * (0.3 - direction.z)).normalize();
                    }
                    axis_point += direction * step;
                    let t = k as f64 / params.steps as f64;
                    // The helix grows in from the root over the first tenth so roots stay put.
                    let angle = phase + std::f64::consts::TAU * params.curl_turns * t;
                    let ramp = (t * 10.0).min(1.0);
                    let helix =
                        (across * angle.cos() + side * angle.sin()) * (params.curl_radius_m * ramp);
                    let helix_at_root =
                        (across * phase.cos() + side * phase.sin()) * (params.curl_radius_m * ramp);
                    let mut point = axis_point + helix - helix_at_root;
                    point.z = point.z.clamp(0.0, params.length_m);
                    points.push(point);
                }
                VolumeStrand { points, tint }
            })
            .collect();
        Ok(Self {
            params: *params,
            strands,
        })
    }
}

/// `value` wrapped into `[0, period)`.
pub fn wrap(value: f64, period: f64) -> f64 {
    let wrapped = value.rem_euclid(period);
    // rem_euclid can round up to `period` for tiny negative values.
    if wrapped >= period { 0.0 } else { wrapped }
}
