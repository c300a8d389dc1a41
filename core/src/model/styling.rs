//! Styling parameters (seed 000 §3.4): what an artist sets for curl, twist, noise, clump,
//! frizz, wave and length variation, globally or per group of bundles. The ops these
//! parameters drive, and their conventions, are in [`crate::strands::styling`].

use serde::{Deserialize, Serialize};

/// Curl: a helix around the strand. Offset
/// `ramp(w) · r(τ̂) · rotate(e, ψ)` in (û, v̂): `e` is the strand's phase as a unit vector
/// `(cos 2πξ₁, sin 2πξ₁)`, blended toward its lock's phase by `clump_coherence` (ringlets:
/// the strands of a clump coil together), `ψ = 2π · turns_per_m · w · (1 + (rate_tip_scale
/// − 1) τ̂ / 2)` (the rate moves linearly from root to tip), `r(τ̂) = radius_m · (1 +
/// radius_jitter · (2ξ₂ − 1)) · (1 + (radius_tip_scale − 1) τ̂)`,
/// `ramp(w) = smoothstep(0, ramp_in_m, w)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Curl {
    pub radius_m: f64,
    /// Turns per metre along w; negative turns the other way (a left-handed helix).
    pub turns_per_m: f64,
    /// Length over which the curl grows from nothing at the root to full radius.
    pub ramp_in_m: f64,
    /// Relative spread of radii between strands, in `[0, 1]`.
    pub radius_jitter: f64,
    /// 0: every strand its own phase (a frizzy mass of helices); 1: the strands of a clump
    /// share their lock's helix (ringlets).
    pub clump_coherence: f64,
    /// The radius at the tip as a multiple of the radius at the root.
    pub radius_tip_scale: f64,
    /// The turns per metre at the tip as a multiple of those at the root.
    pub rate_tip_scale: f64,
}

impl Default for Curl {
    fn default() -> Self {
        Self {
            radius_m: 0.0,
            turns_per_m: 20.0,
            ramp_in_m: 0.02,
            radius_jitter: 0.3,
            clump_coherence: 0.0,
            radius_tip_scale: 1.0,
            rate_tip_scale: 1.0,
        }
    }
}

/// Twist: every strand of a bundle turns about the bundle's centre strand by
/// `θ = 2π · turns_per_m · w` around ŵ (its distance from the centre is kept).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Twist {
    pub turns_per_m: f64,
}

/// Noise: smooth coherent noise along the strand. Offset
/// `amplitude_m · τ̂ · Σ_o 0.5^o (n(f 2^o w + k_u), n(f 2^o w + k_v))` in (û, v̂), with `n` a
/// smooth 1D value noise in `[−1, 1]`, `f` = `frequency_per_m` and strand keys `k` from ξ.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Noise {
    pub amplitude_m: f64,
    pub frequency_per_m: f64,
    pub octaves: u32,
}

impl Default for Noise {
    fn default() -> Self {
        Self {
            amplitude_m: 0.0,
            frequency_per_m: 10.0,
            octaves: 2,
        }
    }
}

/// Clump: strands gather toward clump centres scattered over uv (a jittered grid of
/// `clumps_per_uv` cells per uv unit). The pull is a compact-kernel average toward nearby
/// centres, continuous everywhere:
/// `Δ = Σ K_i (c_i − x) / (Σ K_i + ¼)`, `K_i = max(0, 1 − |c_i − x|² / h²)²`, `h` one cell;
/// offset `strength · τ̂^tightening · radius_m · (Δ.x û + Δ.y v̂)`.
///
/// A second level of sub-clumps (locks within the lock) gathers strands the same way on its
/// own, finer lattice (`sub_clumps_per_uv`, centres hashed on their own channels) with its
/// own strength and reach, and the same profile along the strand.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Clump {
    /// 0 (no clumping) to 1 (tips meet at the clump centre).
    pub strength: f64,
    pub clumps_per_uv: f64,
    /// Object-space size of one clump cell.
    pub radius_m: f64,
    /// Profile exponent along the strand: larger keeps roots spread and tightens only tips.
    pub tightening: f64,
    /// Sub-clumps: 0 (none) to 1.
    pub sub_strength: f64,
    pub sub_clumps_per_uv: f64,
    /// Object-space size of one sub-clump cell.
    pub sub_radius_m: f64,
}

impl Default for Clump {
    fn default() -> Self {
        Self {
            strength: 0.0,
            clumps_per_uv: 40.0,
            radius_m: 0.01,
            tightening: 1.5,
            sub_strength: 0.0,
            sub_clumps_per_uv: 160.0,
            sub_radius_m: 0.003,
        }
    }
}

/// Frizz: a fraction of strands (those with ξ₆ < `fraction`) get high-frequency noise that
/// grows toward the tip: `amplitude_m · τ̂² · (n(f w + k), n(f w + k'))` in (û, v̂).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Frizz {
    pub amplitude_m: f64,
    pub frequency_per_m: f64,
    pub fraction: f64,
}

impl Default for Frizz {
    fn default() -> Self {
        Self {
            amplitude_m: 0.0,
            frequency_per_m: 120.0,
            fraction: 0.2,
        }
    }
}

/// Wave: a planar wave across the strand. Offset
/// `ramp(w) · amplitude_m · Im(e · exp(i 2π · frequency_per_m · w)) · d`, with
/// `d = cos α û + sin α v̂` (`α` = `direction_rad`) and the phase `e` the unit vector of
/// angle `phase_spread · 2π ξ₈`, blended toward its lock's phase by `clump_coherence` (the
/// strands of a lock wave together: waves that read from the front). The locks' own phases
/// lie within `lock_phase_spread` of a cycle: at 1 every lock waves on its own (a patchwork
/// of crests whose highlights break up into blotches), small values keep neighbouring locks
/// nearly in step so the crests, and their highlights, run as bands across the head.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Wave {
    pub amplitude_m: f64,
    pub frequency_per_m: f64,
    pub direction_rad: f64,
    /// 0: neighbouring strands wave together; 1: fully random phases.
    pub phase_spread: f64,
    pub ramp_in_m: f64,
    /// 0: the phase above; 1: every strand of a lock takes its lock's phase.
    pub clump_coherence: f64,
    /// How far apart the locks' phases lie, as a share of a cycle: 0 all locks in step, 1
    /// any phase (the default, which documents made before this field keep).
    pub lock_phase_spread: f64,
}

impl Default for Wave {
    fn default() -> Self {
        Self {
            amplitude_m: 0.0,
            frequency_per_m: 8.0,
            direction_rad: 0.0,
            phase_spread: 0.15,
            ramp_in_m: 0.03,
            clump_coherence: 0.0,
            lock_phase_spread: 1.0,
        }
    }
}

/// Strays and flyaways: the strands of a `fraction` of the random-value cells leave their
/// clump (no clump or sub-clump pull), always frizz (with the frizz parameters), drift off
/// the mass by `amplitude_m · τ̂² · (cos α + n_a / 2, sin α + n_b / 2)` in (û, v̂) — a
/// direction `α` of their own wandering with slow noise `n` of `frequency_per_m` — and keep
/// `length_min … 1` of their length. A stray cell's strands share direction, noise and
/// length: they leave as one small wisp.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Stray {
    /// Share of strands that stray, 0 (off) to 1.
    pub fraction: f64,
    pub amplitude_m: f64,
    pub frequency_per_m: f64,
    /// The shortest a stray gets, as a share of the length it would have.
    pub length_min: f64,
}

impl Default for Stray {
    fn default() -> Self {
        Self {
            fraction: 0.0,
            amplitude_m: 0.01,
            frequency_per_m: 6.0,
            length_min: 0.4,
        }
    }
}

/// Hairlines: hair thins out, and grows shorter, over the last `width_m` before the border
/// of the hair (where bundles end: the hairline, the nape, around the ears, a bald patch).
/// With `d` a root's distance to that border (object units, straight-line, bilinear over
/// its face from the root corners') and `s = smoothstep(0, width_m, d)`, the strand grows
/// when its place in its bundle's progressive sample set, `(j + ½) / N`, is below
/// `edge_density + (1 − edge_density) s` — an even, sparser cover toward the border — and
/// keeps `edge_length + (1 − edge_length) s` of its length: short, fine-looking vellus at
/// the edge instead of a comb line of full-length roots.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Hairline {
    /// How far in from the border the falloff reaches; 0 turns the op off.
    pub width_m: f64,
    /// The share of strands that grow right at the border.
    pub edge_density: f64,
    /// The share of their length strands keep right at the border.
    pub edge_length: f64,
}

impl Default for Hairline {
    fn default() -> Self {
        Self {
            width_m: 0.0,
            edge_density: 0.1,
            edge_length: 0.3,
        }
    }
}

/// Strand density over the scalp. Off at 0: every bundle grows its N strands (times its own
/// `density`) whatever the size of its root face, so large faces look sparse and small ones
/// dense. With `strands_per_cm2 > 0` a bundle grows `strands_per_cm2 · area` strands (its
/// root face's area in cm², model units taken as metres), at most its N, times its own
/// `density` ([`crate::strands::lod::grown_share`]): the same cover over the whole scalp.
/// Its progressive samples keep the cover even, and the painted density map thins it further.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Density {
    pub strands_per_cm2: f64,
}

/// Length variation: a strand ends at `1 − fraction · ξ₅` of its bundle's length.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LengthVariation {
    pub fraction: f64,
}

/// All styling parameters of one set of bundles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct StylingParams {
    pub curl: Curl,
    pub twist: Twist,
    pub noise: Noise,
    pub clump: Clump,
    pub frizz: Frizz,
    pub wave: Wave,
    pub length: LengthVariation,
    pub stray: Stray,
    pub hairline: Hairline,
    pub density: Density,
    /// Cells per uv unit of the per-strand random fields ξ.
    pub variation_per_uv: f64,
    pub seed: u32,
}

impl Default for StylingParams {
    fn default() -> Self {
        Self {
            curl: Curl::default(),
            twist: Twist::default(),
            noise: Noise::default(),
            clump: Clump::default(),
            frizz: Frizz::default(),
            wave: Wave::default(),
            length: LengthVariation::default(),
            stray: Stray::default(),
            hairline: Hairline::default(),
            density: Density::default(),
            variation_per_uv: 200.0,
            seed: 1,
        }
    }
}

/// Global parameters with per-group overrides; a bundle uses the last group that lists it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StylingSet {
    pub global: StylingParams,
    pub groups: Vec<StylingGroup>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StylingGroup {
    pub name: String,
    pub bundles: Vec<u32>,
    pub params: StylingParams,
}

impl StylingSet {
    /// Follows a renumbering of the bundles (`renumber[old]` is the new index, `None` for a
    /// deleted bundle): groups keep their members under their new numbers and lose deleted
    /// ones (a group left empty stays, with its parameters, for the artist to refill).
    /// Indices past `renumber` (which `validate` would name) are dropped too.
    pub fn renumber_bundles(&mut self, renumber: &[Option<u32>]) {
        for group in &mut self.groups {
            group.bundles = group
                .bundles
                .iter()
                .filter_map(|&b| renumber.get(b as usize).copied().flatten())
                .collect();
        }
    }

    pub fn params_for(&self, bundle: u32) -> &StylingParams {
        self.group_of(bundle)
            .map(|g| &self.groups[g].params)
            .unwrap_or(&self.global)
    }

    /// Index of the group whose parameters `bundle` uses (the last that lists it), `None`
    /// for the global parameters.
    pub fn group_of(&self, bundle: u32) -> Option<usize> {
        self.groups
            .iter()
            .rposition(|g| g.bundles.contains(&bundle))
    }

    /// Moves `bundles` into group `group` (`None`: back to the global parameters), out of
    /// every other group, so each bundle is listed at most once.
    pub fn assign(&mut self, bundles: &[u32], group: Option<usize>) -> Result<(), String> {
        if let Some(g) = group
            && g >= self.groups.len()
        {
            return Err(format!(
                "group {g} does not exist ({} groups)",
                self.groups.len()
            ));
        }
        for existing in &mut self.groups {
            existing.bundles.retain(|b| !bundles.contains(b));
        }
        if let Some(g) = group {
            let target = &mut self.groups[g].bundles;
            target.extend_from_slice(bundles);
            target.sort_unstable();
            target.dedup();
        }
        Ok(())
    }

    /// A new group holding `bundles` (taken out of other groups), starting from the
    /// parameters they use now; returns its index.
    pub fn new_group(&mut self, name: impl Into<String>, bundles: &[u32]) -> usize {
        let params = bundles
            .first()
            .map_or(&self.global, |&b| self.params_for(b))
            .clone();
        self.groups.push(StylingGroup {
            name: name.into(),
            bundles: Vec::new(),
            params,
        });
        let index = self.groups.len() - 1;
        let _ = self.assign(bundles, Some(index));
        index
    }

    /// Every number must be finite and every range respected; names the offending field.
    pub fn validate(&self) -> Result<(), String> {
        let check = |p: &StylingParams, at: &str| -> Result<(), String> {
            let values = [
                ("curl.radius_m", p.curl.radius_m),
                ("curl.turns_per_m", p.curl.turns_per_m),
                ("curl.ramp_in_m", p.curl.ramp_in_m),
                ("curl.radius_jitter", p.curl.radius_jitter),
                ("curl.clump_coherence", p.curl.clump_coherence),
                ("curl.radius_tip_scale", p.curl.radius_tip_scale),
                ("curl.rate_tip_scale", p.curl.rate_tip_scale),
                ("twist.turns_per_m", p.twist.turns_per_m),
                ("noise.amplitude_m", p.noise.amplitude_m),
                ("noise.frequency_per_m", p.noise.frequency_per_m),
                ("clump.strength", p.clump.strength),
                ("clump.clumps_per_uv", p.clump.clumps_per_uv),
                ("clump.radius_m", p.clump.radius_m),
                ("clump.tightening", p.clump.tightening),
                ("clump.sub_strength", p.clump.sub_strength),
                ("clump.sub_clumps_per_uv", p.clump.sub_clumps_per_uv),
                ("clump.sub_radius_m", p.clump.sub_radius_m),
                ("frizz.amplitude_m", p.frizz.amplitude_m),
                ("frizz.frequency_per_m", p.frizz.frequency_per_m),
                ("frizz.fraction", p.frizz.fraction),
                ("wave.amplitude_m", p.wave.amplitude_m),
                ("wave.frequency_per_m", p.wave.frequency_per_m),
                ("wave.direction_rad", p.wave.direction_rad),
                ("wave.phase_spread", p.wave.phase_spread),
                ("wave.ramp_in_m", p.wave.ramp_in_m),
                ("wave.clump_coherence", p.wave.clump_coherence),
                ("wave.lock_phase_spread", p.wave.lock_phase_spread),
                ("length.fraction", p.length.fraction),
                ("stray.fraction", p.stray.fraction),
                ("stray.amplitude_m", p.stray.amplitude_m),
                ("stray.frequency_per_m", p.stray.frequency_per_m),
                ("stray.length_min", p.stray.length_min),
                ("hairline.width_m", p.hairline.width_m),
                ("hairline.edge_density", p.hairline.edge_density),
                ("hairline.edge_length", p.hairline.edge_length),
                ("density.strands_per_cm2", p.density.strands_per_cm2),
                ("variation_per_uv", p.variation_per_uv),
            ];
            for (name, value) in values {
                if !value.is_finite() {
                    return Err(format!("{at}.{name}: not a finite number"));
                }
                if let Some(&(_, lo, hi)) = HARD_RANGES.iter().find(|(n, ..)| *n == name)
                    && !(lo..=hi).contains(&value)
                {
                    return Err(format!(
                        "{at}.{name}: {value} is outside the valid range [{lo}, {hi}]"
                    ));
                }
            }
            if p.noise.octaves > 8 {
                return Err(format!(
                    "{at}.noise.octaves: {} is more than 8",
                    p.noise.octaves
                ));
            }
            Ok(())
        };
        check(&self.global, "global")?;
        for (i, group) in self.groups.iter().enumerate() {
            check(&group.params, &format!("groups[{i}].params"))?;
        }
        Ok(())
    }
}

/// The valid range of every styling parameter: what a file, a paste or a typed value may
/// hold (refused by name outside it). The editor's sliders span a narrower, comfortable
/// range; a typed value beyond the slider but inside this range is allowed. The limits are
/// generous physical bounds (a 0.5 m curl radius is already a hoop, not hair) chosen so that
/// no parameter can throw strands metres away or divide by zero: clumps per uv and
/// variation cells per uv start at 1, fractions stay in [0, 1].
pub const HARD_RANGES: &[(&str, f64, f64)] = &[
    ("curl.radius_m", 0.0, 0.5),
    // Negative turns: a left-handed helix (what a mirrored bundle needs).
    ("curl.turns_per_m", -1000.0, 1000.0),
    ("curl.ramp_in_m", 0.0, 10.0),
    ("curl.radius_jitter", 0.0, 1.0),
    ("curl.clump_coherence", 0.0, 1.0),
    // A helix may shrink to nothing or grow 4× toward the tip, never turn inside out.
    ("curl.radius_tip_scale", 0.0, 4.0),
    ("curl.rate_tip_scale", 0.0, 4.0),
    ("twist.turns_per_m", -1000.0, 1000.0),
    ("noise.amplitude_m", 0.0, 0.5),
    ("noise.frequency_per_m", 0.0, 10_000.0),
    ("clump.strength", 0.0, 1.0),
    ("clump.clumps_per_uv", 1.0, 10_000.0),
    ("clump.radius_m", 0.0, 1.0),
    ("clump.tightening", 0.0, 100.0),
    ("clump.sub_strength", 0.0, 1.0),
    ("clump.sub_clumps_per_uv", 1.0, 10_000.0),
    ("clump.sub_radius_m", 0.0, 1.0),
    ("frizz.amplitude_m", 0.0, 0.5),
    ("frizz.frequency_per_m", 0.0, 10_000.0),
    ("frizz.fraction", 0.0, 1.0),
    ("wave.amplitude_m", 0.0, 0.5),
    ("wave.frequency_per_m", 0.0, 1000.0),
    (
        "wave.direction_rad",
        -std::f64::consts::TAU,
        std::f64::consts::TAU,
    ),
    ("wave.phase_spread", 0.0, 1.0),
    ("wave.ramp_in_m", 0.0, 10.0),
    ("wave.clump_coherence", 0.0, 1.0),
    ("wave.lock_phase_spread", 0.0, 1.0),
    ("length.fraction", 0.0, 1.0),
    ("stray.fraction", 0.0, 1.0),
    ("stray.amplitude_m", 0.0, 0.5),
    ("stray.frequency_per_m", 0.0, 1000.0),
    ("stray.length_min", 0.0, 1.0),
    // A metre of falloff is already a whole head of thinning hair.
    ("hairline.width_m", 0.0, 1.0),
    ("hairline.edge_density", 0.0, 1.0),
    ("hairline.edge_length", 0.0, 1.0),
    // Real scalps grow about 150-300 a cm²; ten times that is already fur.
    ("density.strands_per_cm2", 0.0, 10_000.0),
    ("variation_per_uv", 1.0, 10_000.0),
];

impl StylingParams {
    /// Every op on at moderate, hair-sized amplitudes: the set tests and benchmarks use when
    /// they want all of styling exercised at once.
    pub fn every_op() -> Self {
        StylingParams {
            curl: Curl {
                radius_m: 0.004,
                clump_coherence: 0.5,
                radius_tip_scale: 0.7,
                rate_tip_scale: 1.3,
                ..Curl::default()
            },
            noise: Noise {
                amplitude_m: 0.003,
                ..Noise::default()
            },
            clump: Clump {
                strength: 0.7,
                sub_strength: 0.5,
                ..Clump::default()
            },
            frizz: Frizz {
                amplitude_m: 0.002,
                fraction: 1.0,
                ..Frizz::default()
            },
            wave: Wave {
                amplitude_m: 0.01,
                clump_coherence: 0.5,
                ..Wave::default()
            },
            length: LengthVariation { fraction: 0.3 },
            stray: Stray {
                fraction: 0.2,
                ..Stray::default()
            },
            hairline: Hairline {
                width_m: 0.008,
                ..Hairline::default()
            },
            twist: Twist { turns_per_m: 3.0 },
            ..StylingParams::default()
        }
    }
    /// Each op alone at [`Self::every_op`]'s setting, named (the rows of `bench switches`):
    /// what each costs on its own against no styling. The second levels (sub-clumps,
    /// ringlets, lock waves, strays) are their own rows, on top of the op they refine.
    pub fn each_op() -> Vec<(&'static str, StylingParams)> {
        let all = Self::every_op();
        let none = Self::default();
        let curl = StylingParams {
            curl: Curl {
                clump_coherence: 0.0,
                radius_tip_scale: 1.0,
                rate_tip_scale: 1.0,
                ..all.curl.clone()
            },
            ..none.clone()
        };
        let clump = StylingParams {
            clump: Clump {
                sub_strength: 0.0,
                ..all.clump.clone()
            },
            ..none.clone()
        };
        let wave = StylingParams {
            wave: Wave {
                clump_coherence: 0.0,
                ..all.wave.clone()
            },
            ..none.clone()
        };
        vec![
            ("curl", curl),
            (
                "curl: ringlets + tip scales",
                StylingParams {
                    curl: all.curl.clone(),
                    ..none.clone()
                },
            ),
            (
                "twist",
                StylingParams {
                    twist: all.twist.clone(),
                    ..none.clone()
                },
            ),
            (
                "noise",
                StylingParams {
                    noise: all.noise.clone(),
                    ..none.clone()
                },
            ),
            ("clump", clump),
            (
                "clump + sub-clumps",
                StylingParams {
                    clump: all.clump.clone(),
                    ..none.clone()
                },
            ),
            (
                "frizz",
                StylingParams {
                    frizz: all.frizz.clone(),
                    ..none.clone()
                },
            ),
            ("wave", wave),
            (
                "wave: shared by locks",
                StylingParams {
                    wave: all.wave.clone(),
                    ..none.clone()
                },
            ),
            (
                "length variation",
                StylingParams {
                    length: all.length.clone(),
                    ..none.clone()
                },
            ),
            (
                "strays",
                StylingParams {
                    stray: all.stray.clone(),
                    ..none.clone()
                },
            ),
            (
                "hairline",
                StylingParams {
                    hairline: all.hairline.clone(),
                    ..none.clone()
                },
            ),
            ("every op", all),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue "The editor as artists use it", bug 7: a 5 m or negative curl radius, 0 clumps
    /// per uv and a 1e30 wave amplitude were accepted.
    #[test]
    fn values_outside_the_hard_ranges_are_refused_by_name() {
        let refused = |edit: fn(&mut StylingParams), field: &str| {
            let mut set = StylingSet::default();
            edit(&mut set.global);
            let error = set.validate().expect_err(field);
            assert!(
                error.starts_with(&format!("global.{field}:")) && error.contains("valid range"),
                "{field}: {error}"
            );
        };
        refused(|p| p.curl.radius_m = 5.0, "curl.radius_m");
        refused(|p| p.curl.radius_m = -1.0, "curl.radius_m");
        refused(|p| p.clump.clumps_per_uv = 0.0, "clump.clumps_per_uv");
        refused(|p| p.wave.amplitude_m = 1e30, "wave.amplitude_m");
        // Beyond the editor's slider (0.03 m) but inside the valid range: allowed.
        let mut set = StylingSet::default();
        set.global.curl.radius_m = 0.1;
        set.validate()
            .expect("a typed value past the slider is fine");
        // Every default and the every-op set sit inside the ranges.
        set.global = StylingParams::every_op();
        set.validate().expect("every_op is valid");
        for (name, lo, hi) in HARD_RANGES {
            assert!(lo < hi, "{name}");
        }
    }

    #[test]
    fn assigning_moves_bundles_between_groups_and_back_to_global() {
        let mut set = StylingSet::default();
        set.global.curl.radius_m = 0.002;
        let a = set.new_group("fringe", &[3, 1, 2]);
        assert_eq!(set.groups[a].bundles, vec![1, 2, 3]);
        assert_eq!(
            set.params_for(1).curl.radius_m,
            0.002,
            "starts from what it used"
        );
        set.groups[a].params.curl.radius_m = 0.004;
        let b = set.new_group("crown", &[2, 7]);
        assert_eq!(
            set.groups[b].params.curl.radius_m, 0.004,
            "2 came from the fringe"
        );
        assert_eq!(
            set.groups[a].bundles,
            vec![1, 3],
            "a bundle is in one group"
        );
        set.assign(&[3, 7], None).expect("to global");
        assert_eq!(set.group_of(3), None);
        assert_eq!(set.group_of(7), None);
        assert_eq!(set.group_of(2), Some(b));
        let error = set.assign(&[1], Some(5)).expect_err("no group 5");
        assert!(error.contains("group 5"), "{error}");
        assert_eq!(
            set.group_of(1),
            Some(a),
            "a refused assignment changes nothing"
        );
    }

    #[test]
    fn groups_override_and_validation_names_fields() {
        let mut set = StylingSet::default();
        set.groups.push(StylingGroup {
            name: "fringe".into(),
            bundles: vec![3, 4],
            params: StylingParams::every_op(),
        });
        assert_eq!(set.params_for(3), &StylingParams::every_op());
        assert_eq!(set.params_for(5), &StylingParams::default());
        assert!(set.validate().is_ok());
        set.groups[0].params.wave.amplitude_m = f64::NAN;
        assert_eq!(
            set.validate().expect_err("nan"),
            "groups[0].params.wave.amplitude_m: not a finite number"
        );
        set.groups[0].params.wave.amplitude_m = 0.0;
        set.global.length.fraction = 1.5;
        assert!(
            set.validate()
                .expect_err("range")
                .starts_with("global.length.fraction")
        );
    }
}
