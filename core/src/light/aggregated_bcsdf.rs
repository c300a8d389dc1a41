//! Far hair's shading: seed 001's aggregated BCSDF (§4) for a thick hair that stands for a
//! cluster of fibres, built over the same Chiang R / TT / TRT fibre as near hair
//! ([`crate::light::hair_bsdf`]) so that near and far share one material. CPU mirror of
//! `shaders/light/aggregated_bcsdf.wgsl` (same names: `aggregated_bcsdf`,
//! `cluster_hairs_on_path`, `agg_profile`, `agg_lobe`), and the tables the renderer uploads.
//!
//! The model, in the measure of [`crate::light::hair_bsdf`] (`∫ f dω` is the scattered
//! fraction), with `n` the hairs the light crossed inside the cluster up to and including the
//! shaded one; what happens on the light's way is indexed by `|θ_i|` (as dual scattering's
//! tables are), the shaded fibre's own lobes by `|θ_o|` (as `hair_bsdf` evaluates them, so
//! that one fibre alone shades as near hair does):
//!
//! `f = S(φ) · [ E[a_F^k] Σ_p M̂_p(θ_h) N̂_p(θ_o, φ) + A_B̂ M_B̂(θ_h) I_B(φ)/π ]`,
//! `k` the (random) count of fibres before the shaded one, of mean `n − 1`:
//!
//! - **R̂, T̂T, TRT and the residual lobe** (the paper's R̂, T̂, D̂): the shaded fibre's lobes
//!   averaged over the incident offset `h` (a thick hair's shading point is some fibre at some
//!   offset), attenuated by the `n − 1` fibres before it (eq. 7; as the mean over a Poisson
//!   count of fibres, `exp(−(n − 1)(1 − a_F))`, not `a_F^{n−1}`, see [`expected_power`]). Each longitudinal lobe is the
//!   fibre's own `M_p` with its variance widened by `(n − 1) β_f²` (eq. 9; the paper's
//!   Gaussians in `θ_h` lose most of a rough lobe's energy off the sphere, `M_p` is
//!   normalised at every width and exact at `n = 1`). Azimuthally, the forward scatterings
//!   before the shaded fibre convolve the light's direction with their deflection; a
//!   convolution multiplies the circular Fourier coefficients, so after `n − 1` of them the
//!   lobe's first harmonic is scaled by `R_f^{n−1}`, `R_f` the mean cosine of one forward
//!   deflection (tabulated). We blend each `h`-averaged lobe toward uniform by that factor:
//!   energy is kept exactly and the first harmonic follows the convolution, where the paper
//!   replaces R̂ and D̂ by uniform lobes and T̂T by a Gaussian of accumulated variance.
//! - **B̂** (eq. 10-11): local back scattering `D_B (A₁ + A₃)` from dual scattering's tables,
//!   plus the paper's `A₁₊ = d₁₊ a_b Σ_{i=1}^{m} a_F^{2i−1}` for light that reached hairs
//!   behind the shaded one through gaps, summed in closed form so that counts need not be
//!   whole. Both come from the hairs *behind* the shaded one along the light's line, so both
//!   stop at their count `m` (dual scattering's series assume endless hair: `A₁ + A₃` is
//!   scaled by `1 − a_F^{2m}`; the paper sums `A₁₊` to the hairs in front, `n`). Without
//!   this a single strand, which has nothing behind it, would return more light than a white
//!   furnace gives it. Its variance is the attenuation-weighted mean of the paths' (`σ_b²`
//!   for `A₁ + A₃`, `σ_b² + m β_f²` for `A₁₊`), uniform over the near half circle.
//! - **S** (eq. 12-15): shadowing-masking by the cluster's own fibres. The paper defines it for
//!   `|φ| < π/2`; beyond, the light comes through the cluster, which `n` already counts, so
//!   `P_s = (1 − ρ)(1 − |cos φ|)` and `P_m = (1 − ρ) c_m min(1, 1 + cos φ)` fade to 0 at
//!   `φ = π`, continuously (holding the front's values there shadowed back light twice: the
//!   explicit-fibre reference measured it several times too dark). `P_n` is kept ≥ 0 (for
//!   sparse clusters `P_s + P_m` can pass 1).
//! - **n from the cluster's shape** (§5.2): the paper's `n = ρ l √(N / π|r_A||r_B|)` is not the
//!   mean free path of a fibre bundle; we use the exact expectation for fibres of radius `r`
//!   placed at random in the cross-section, `2 r (N − 1) / (π a b)` crossings per metre past
//!   the shaded fibre (tested against fibres placed at random), along the in-plane chord
//!   from the shaded point to where the light enters. The shaded point is not on the edge
//!   alone: the eye meets its first fibre at an exponentially distributed depth, and
//!   [`AggregatedTables::aggregated_cluster`] averages three quantiles of it
//!   ([`cluster_hairs_on_path`]); light leaving back along the eye's (empty) ray crosses
//!   nothing while within a fibre's width of it.
//!
//! `d₁₊ = 0.6`, `c_m = 0.2` as in the paper; `D_B` is dual scattering's.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::DVec3;

use crate::light::dual_scattering::{
    D_B, DualScatteringTables, H_SAMPLES, PHI_COUNT, THETA_COUNT, bilinear_lobe, ds_gaussian,
    gamma, np_integral,
};
use crate::light::hair_bsdf::{HairBsdf, P_MAX, azimuth, direction, mp, np, wrap_angle};
use crate::light::material::Fibre;
use crate::runtime::thick_hair::CrossSection;

/// Share of the `A₁₊` paths that return toward the shaded hair (seed 001, eq. 10).
pub const D_1PLUS: f64 = 0.6;
/// Probability factor of shadowing by several fibres (seed 001, eq. 13).
pub const C_M: f64 = 0.2;

/// Rows of the 1-D profile table, each `THETA_COUNT` texels over `|θ|`. Looked up at the
/// light's `|θ_i|` (what happens on the light's way through the cluster):
/// 0: `a_F` (rgb), `β_f²`; 1: `A₁ + A₃` (rgb), `Δ_b`; 2: `a_b` (rgb), `σ_b²`; 3: `R_f`.
/// Looked up at the eye's `|θ_o|` (the shaded fibre's own lobes, as near hair's
/// `hair_bsdf` evaluates them): 4: `Ā_R`; 5: `Ā_TT`; 6: `Ā_TRT`; 7: `Ā_residual` (rgb).
pub const PROFILE_ROWS: usize = 8;
/// Where the lobe table starts in the one buffer the shader reads (`vec4` entries).
pub const LOBES_OFFSET: usize = PROFILE_ROWS * THETA_COUNT;
/// Length of the buffer in `vec4<f32>`.
pub const TABLE_LEN: usize = LOBES_OFFSET + P_MAX * THETA_COUNT * PHI_COUNT;

/// Samples of each forward lobe's mean cosine (midpoints of the far half circle).
const MOMENT_STEPS: usize = 64;

/// The precomputed tables of one material, laid out as the shader's storage buffer.
#[derive(Clone, Debug, PartialEq)]
pub struct AggregatedTables {
    /// `TABLE_LEN` entries: the profile rows, then per lobe `p < P_MAX`, row `|θ_o|`, column
    /// `|φ|` (bin averages), `avg_h A_p N_p` (rgb).
    pub data: Vec<[f32; 4]>,
    /// The fibre's longitudinal lobes (variances, cuticle tilt): the shader's come from the
    /// scene uniforms, as `hair_bsdf`'s do.
    pub bsdf: HairBsdf,
}

impl AggregatedTables {
    /// Integrates the tables for `fibre` at its mean absorption (as dual scattering's).
    pub fn new(fibre: &Fibre) -> Self {
        let ds = DualScatteringTables::new(fibre);
        let bsdf = HairBsdf::new(fibre);
        let sigma_a = fibre.sigma_a_mean();
        let mut data = vec![[0.0f32; 4]; TABLE_LEN];
        let bin = PI / PHI_COUNT as f64;
        for t in 0..THETA_COUNT {
            let theta = (t as f64 + 0.5) / THETA_COUNT as f64 * FRAC_PI_2;
            let light = direction(theta, 0.0);
            let mut a_b = [0.0; 3];
            let mut mean_a = [[0.0; 3]; P_MAX + 1];
            let (mut far_energy, mut far_moment) = (0.0, 0.0);
            let mut lobe_rows = vec![[0.0f64; 3]; P_MAX * PHI_COUNT];
            for k in 0..H_SAMPLES {
                let h = -1.0 + (k as f64 + 0.5) * 2.0 / H_SAMPLES as f64;
                let inside = gamma(&bsdf, light, h);
                let transmittance = sigma_a.map(|s| (-s * inside.path).exp());
                let ap = bsdf.ap(theta.cos(), h, transmittance);
                for (p, a) in ap.iter().enumerate() {
                    let (far, moment) = if p < P_MAX {
                        let far = np_integral(
                            FRAC_PI_2,
                            1.5 * PI,
                            p,
                            bsdf.s,
                            inside.gamma_o,
                            inside.gamma_t,
                        );
                        (
                            far,
                            forward_moment(p, bsdf.s, inside.gamma_o, inside.gamma_t),
                        )
                    } else {
                        // The residual lobe is uniform: half leaves forward, with mean
                        // cosine ∫_{π/2}^{3π/2} cos(φ − π) dφ / 2π = 1/π.
                        (0.5, 1.0 / PI)
                    };
                    let weight = (a[0] + a[1] + a[2]) / 3.0 / H_SAMPLES as f64;
                    far_energy += weight * far;
                    far_moment += weight * moment;
                    for c in 0..3 {
                        mean_a[p][c] += a[c] / H_SAMPLES as f64;
                        a_b[c] += a[c] * (1.0 - far) / H_SAMPLES as f64;
                    }
                }
                for p in 0..P_MAX {
                    for j in 0..PHI_COUNT {
                        let lo = j as f64 * bin;
                        let average =
                            np_integral(lo, lo + bin, p, bsdf.s, inside.gamma_o, inside.gamma_t)
                                / bin;
                        for c in 0..3 {
                            lobe_rows[p * PHI_COUNT + j][c] +=
                                ap[p][c] * average / H_SAMPLES as f64;
                        }
                    }
                }
            }
            let r_f = if far_energy > 1e-12 {
                (far_moment / far_energy).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let spread = ds.spread[t];
            let rgb = |v: [f64; 3], w: f64| [v[0] as f32, v[1] as f32, v[2] as f32, w as f32];
            data[t] = ds.forward[t];
            data[THETA_COUNT + t] = ds.backward[t];
            data[2 * THETA_COUNT + t] = rgb(a_b, spread[0] as f64);
            data[3 * THETA_COUNT + t] = [r_f as f32, 0.0, 0.0, 0.0];
            for (p, a) in mean_a.iter().enumerate() {
                data[(4 + p) * THETA_COUNT + t] = rgb(*a, 0.0);
            }
            for p in 0..P_MAX {
                for j in 0..PHI_COUNT {
                    data[LOBES_OFFSET + (p * THETA_COUNT + t) * PHI_COUNT + j] =
                        rgb(lobe_rows[p * PHI_COUNT + j], 0.0);
                }
            }
        }
        Self { data, bsdf }
    }

    /// Profile row `row` at `|θ_i|`, linearly interpolated between texel centres.
    pub fn agg_profile(&self, row: usize, theta: f64) -> [f64; 4] {
        DualScatteringTables::profile(
            &self.data[row * THETA_COUNT..(row + 1) * THETA_COUNT],
            theta,
        )
    }

    /// `avg_h A_p N_p` of lobe `p < P_MAX` at `(|θ_o|, |φ|)`, bilinearly interpolated.
    pub fn agg_lobe(&self, p: usize, theta: f64, phi: f64) -> [f64; 3] {
        bilinear_lobe(&self.data[LOBES_OFFSET..], p, theta, phi)
    }

    /// The aggregated response `f` (see the module docs): directions in the fibre frame of the
    /// thick hair's ribbon, `hairs_on_path` from [`cluster_hairs_on_path`], `coverage` the
    /// cluster's `ρ` ([`ClusterShape::coverage`]). Non-finite inputs shade as one fibre in a
    /// dense cluster; the result is finite and ≥ 0.
    pub fn aggregated_bcsdf(
        &self,
        wo: DVec3,
        wi: DVec3,
        path: HairsOnPath,
        coverage: f64,
    ) -> [f64; 3] {
        let finite = |v: f64, lo: f64, fallback: f64| {
            if v.is_finite() {
                v.clamp(lo, 1e4)
            } else {
                fallback
            }
        };
        let n = finite(path.before, 1.0, 1.0);
        let behind = finite(path.behind, 0.0, 0.0);
        let rho = if coverage.is_finite() {
            coverage.clamp(0.0, 1.0)
        } else {
            1.0
        };
        let before = n - 1.0;
        let theta_i = wi.x.clamp(-1.0, 1.0).asin();
        let theta_o = wo.x.clamp(-1.0, 1.0).asin();
        let theta_h = 0.5 * (theta_i + theta_o);
        let cos_theta_d = (0.5 * (theta_i - theta_o)).cos().max(1e-3);
        let phi = wrap_angle(azimuth(wi) - azimuth(wo)).abs();
        let forward = self.agg_profile(0, theta_i);
        let back = self.agg_profile(1, theta_i);
        let single_back = self.agg_profile(2, theta_i);
        let r_f = self.agg_profile(3, theta_i)[0];
        let (sin_theta_i, sin_theta_o) = (theta_i.sin(), theta_o.sin());
        let (cos_theta_i, cos_theta_o) = (theta_i.cos(), theta_o.cos());
        // β_f² is a variance in θ_h; M_p's is in θ (four times).
        let widen = 4.0 * before * forward[3];
        let lobe = |x: f64, v: f64| ds_gaussian(x, v) / (2.0 * cos_theta_d);
        // First harmonic of the azimuthal lobes after n − 1 forward deflections.
        let sharpness = expected_power(r_f.clamp(0.0, 1.0), before);
        let mut out = [0.0; 3];
        let mut lobes = [0.0; 3];
        for p in 0..=P_MAX {
            // The fibre's own longitudinal lobe (exact at n = 1, normalised at every width).
            let (sin_op, cos_op) = self.bsdf.tilted(p, sin_theta_o, cos_theta_o);
            let m = mp(
                cos_theta_i,
                cos_op,
                sin_theta_i,
                sin_op,
                self.bsdf.v[p] + widen,
            );
            let mean = self.agg_profile(4 + p, theta_o);
            let shaped = if p < P_MAX {
                self.agg_lobe(p, theta_o, phi)
            } else {
                [mean[0] / TAU, mean[1] / TAU, mean[2] / TAU]
            };
            for c in 0..3 {
                lobes[c] += m * (sharpness * shaped[c] + (1.0 - sharpness) * mean[c] / TAU);
            }
        }
        let near_half = if phi < FRAC_PI_2 { 1.0 / PI } else { 0.0 };
        // Eq. 12-13 where the eye and the light share a side (|φ| < π/2); past it the light
        // comes through the cluster, which `n` already counts, so both fade to 0 at φ = π.
        let cos_phi = phi.cos();
        let p_s = (1.0 - rho) * (1.0 - cos_phi.abs());
        let p_m = (1.0 - rho) * C_M * (1.0 + cos_phi).min(1.0);
        let p_n = (1.0 - p_s - p_m).max(0.0);
        for c in 0..3 {
            let a_f = forward[c].clamp(0.0, 1.0);
            // Dual scattering's A₁ + A₃ assume hairs without end behind the shaded one; with
            // `behind` of them the series stops there (a single strand returns nothing).
            let local = D_B * back[c].max(0.0) * (1.0 - expected_power(a_f * a_f, behind));
            let gaps = D_1PLUS * single_back[c].max(0.0) * odd_power_sum(a_f, behind);
            let total_b = local + gaps;
            let variance_b = if total_b > 1e-12 {
                (local * single_back[3] + gaps * (single_back[3] + behind * forward[3])) / total_b
            } else {
                single_back[3]
            };
            let b_hat = total_b * lobe(theta_h - back[3], variance_b) * near_half;
            let s = p_s * a_f + p_n;
            out[c] = s * (expected_power(a_f, before) * lobes[c] + b_hat);
        }
        out.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 })
    }
}

/// `E[a^k]` for a Poisson count `k` of mean `mean`: `exp(−mean (1 − a))`. The hairs a ray
/// meets in a cluster are a random count, and what passes them is the mean of `a^k`, not
/// `a` to the mean count (the paper's `a_F^{n−1}`): by Jensen's inequality that is darker,
/// and the explicit-fibre reference ([`crate::light::cluster_reference`]) measured it
/// several times too dark for back light through sparse clusters.
pub fn expected_power(a: f64, mean: f64) -> f64 {
    (-mean.max(0.0) * (1.0 - a.clamp(0.0, 1.0))).exp()
}

/// `E[Σ_{i=1}^{k} a^{2i−1}] = a (1 − E[a^{2k}]) / (1 − a²)` for a Poisson count `k` of mean
/// `n` (the `A₁₊` series over the hairs behind), `a ∈ [0, 1]`.
pub fn odd_power_sum(a: f64, n: f64) -> f64 {
    let a2 = a * a;
    if 1.0 - a2 < 1e-6 {
        return a * n;
    }
    a * (1.0 - expected_power(a2, n)) / (1.0 - a2)
}

/// `∫_{π/2}^{3π/2} N_p(φ) cos(φ − π) dφ`: lobe `p`'s forward-scattered light weighted by the
/// cosine of its deflection from straight through.
fn forward_moment(p: usize, s: f64, gamma_o: f64, gamma_t: f64) -> f64 {
    let step = PI / MOMENT_STEPS as f64;
    (0..MOMENT_STEPS)
        .map(|k| {
            let phi = FRAC_PI_2 + (k as f64 + 0.5) * step;
            np(phi, p, s, gamma_o, gamma_t) * (phi - PI).cos() * step
        })
        .sum()
}

/// What is wrong with a cluster handed to the aggregated model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ClusterShapeError {
    #[error("the cluster's {what} is not a finite number")]
    NotFinite { what: &'static str },
    #[error("a cluster needs at least one member strand")]
    NoMembers,
    #[error("the fibre radius must be positive, found {0} m")]
    FibreRadius(f64),
}

/// A thick hair's cross-section as the aggregated model sees it, in the fibre frame of the
/// ribbon being shaded (`y` across, `z` toward the viewer).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterShape {
    /// Half-axes, at least one fibre radius (a cluster is at least one fibre wide: a single
    /// strand, coincident points or a flat fit give a zero axis).
    pub semi_major_m: f64,
    pub semi_minor_m: f64,
    /// Angle of the major axis in the frame's `y`-`z` plane, from `y` toward `z`.
    pub major_angle_rad: f64,
    pub members: u32,
    pub fibre_radius_m: f64,
}

impl ClusterShape {
    pub fn new(
        semi_major_m: f64,
        semi_minor_m: f64,
        major_angle_rad: f64,
        members: u32,
        fibre_radius_m: f64,
    ) -> Result<Self, ClusterShapeError> {
        for (what, value) in [
            ("major half-axis", semi_major_m),
            ("minor half-axis", semi_minor_m),
            ("major-axis angle", major_angle_rad),
            ("fibre radius", fibre_radius_m),
        ] {
            if !value.is_finite() {
                return Err(ClusterShapeError::NotFinite { what });
            }
        }
        if members == 0 {
            return Err(ClusterShapeError::NoMembers);
        }
        if fibre_radius_m <= 0.0 {
            return Err(ClusterShapeError::FibreRadius(fibre_radius_m));
        }
        Ok(Self {
            semi_major_m: semi_major_m.abs().max(fibre_radius_m),
            semi_minor_m: semi_minor_m.abs().max(fibre_radius_m),
            major_angle_rad,
            members,
            fibre_radius_m,
        })
    }

    /// The shape of a fitted section in the ribbon frame whose across axis is `across` and
    /// whose viewer axis is `toward_viewer` (both unit, orthogonal to the tangent).
    pub fn from_section(
        section: &CrossSection,
        across: DVec3,
        toward_viewer: DVec3,
        members: u32,
        fibre_radius_m: f64,
    ) -> Result<Self, ClusterShapeError> {
        if !(section.major.is_finite() && section.minor.is_finite()) {
            return Err(ClusterShapeError::NotFinite {
                what: "cross-section",
            });
        }
        let in_plane = |v: DVec3| (v.dot(across), v.dot(toward_viewer));
        let (my, mz) = in_plane(section.major);
        let (ny, nz) = in_plane(section.minor);
        let (major, minor) = ((my * my + mz * mz).sqrt(), (ny * ny + nz * nz).sqrt());
        let angle = if major >= minor {
            mz.atan2(my)
        } else {
            nz.atan2(ny)
        };
        Self::new(
            major.max(minor),
            major.min(minor),
            angle,
            members,
            fibre_radius_m,
        )
    }

    /// `ρ`: the share of the cross-section the fibres cover, `N r² / (a b)`, at most 1.
    pub fn coverage(&self) -> f64 {
        (self.members as f64 * self.fibre_radius_m.powi(2)
            / (self.semi_major_m * self.semi_minor_m))
            .min(1.0)
    }

    /// Fibres a ray crosses per metre past the shaded one: `2 r (N − 1) / (π a b)`.
    pub fn crossings_per_m(&self) -> f64 {
        2.0 * self.fibre_radius_m * (self.members as f64 - 1.0)
            / (PI * self.semi_major_m * self.semi_minor_m)
    }
}

/// The hairs on the light's line through the shaded fibre, inside its cluster.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HairsOnPath {
    /// `n`: crossed to reach the shaded fibre, itself included (≥ 1).
    pub before: f64,
    /// Past the shaded fibre, away from the light (where back scattering comes from).
    pub behind: f64,
}

impl HairsOnPath {
    /// The shaded fibre alone.
    pub const ALONE: Self = Self {
        before: 1.0,
        behind: 0.0,
    };
}

/// Depths along the eye's ray at which the shaded fibre is taken ([`cluster_hairs_on_path`]).
pub const VISIBLE_DEPTHS: u32 = 3;

/// The hairs on the light's line through the shaded fibre, which lies on the eye's ray at
/// offset `across ∈ [−1, 1]` of the ribbon's width, `depth_m` past where that ray enters the
/// ellipse (in the cross-section): toward the light along `wi` to the ellipse's edge, and away
/// from it. Fibres run along the hair, so a ray meets the ones its cross-section part crosses:
/// counts follow the in-plane chords.
pub fn cluster_hairs_at_depth(
    shape: &ClusterShape,
    wo: DVec3,
    wi: DVec3,
    across: f64,
    depth_m: f64,
) -> HairsOnPath {
    let Some(geometry) = EyeRay::new(shape, wo, across) else {
        return HairsOnPath::ALONE;
    };
    let depth = if depth_m.is_finite() {
        depth_m.clamp(0.0, geometry.chord_m)
    } else {
        0.0
    };
    geometry.hairs_from(shape, wi, depth)
}

/// The hairs on the light's line through the `k`-th of [`VISIBLE_DEPTHS`] depths at which the
/// eye's ray at `across` meets its fibre: the first fibre a ray meets lies at an exponentially
/// distributed depth (rate: crossings per metre) within the ellipse's chord, and the depths
/// are that distribution's quantiles `(k + ½) / VISIBLE_DEPTHS`. In a sparse cluster the eye
/// sees fibres deep inside, nearer a back light: taking the shaded fibre on the edge alone
/// made back light several times too dark against explicit fibres.
pub fn cluster_hairs_on_path(
    shape: &ClusterShape,
    wo: DVec3,
    wi: DVec3,
    across: f64,
    k: u32,
) -> HairsOnPath {
    let Some(geometry) = EyeRay::new(shape, wo, across) else {
        return HairsOnPath::ALONE;
    };
    let u = (k.min(VISIBLE_DEPTHS - 1) as f64 + 0.5) / VISIBLE_DEPTHS as f64;
    let rate = shape.crossings_per_m();
    let q = rate * geometry.chord_m;
    let depth = if q < 1e-4 {
        u * geometry.chord_m
    } else {
        -(1.0 - u * (1.0 - (-q).exp())).ln() / rate
    };
    geometry.hairs_from(shape, wi, depth.clamp(0.0, geometry.chord_m))
}

/// The eye's ray through a cluster, in the ellipse's unit-circle coordinates (where lines stay
/// lines and the fraction of the width a ray is at is kept, so the entry is exactly on the
/// circle and chords stay well-conditioned even through a flat ellipse).
struct EyeRay {
    /// Where the ray enters, and its direction into the cluster per metre of the
    /// cross-section, both in unit-circle coordinates.
    entry: (f64, f64),
    inward: (f64, f64),
    /// Its chord through the ellipse, in metres of the cross-section.
    chord_m: f64,
    /// Toward the eye, unit, in the cross-section (metres).
    view: (f64, f64),
    cos: f64,
    sin: f64,
}

impl EyeRay {
    fn new(shape: &ClusterShape, wo: DVec3, across: f64) -> Option<Self> {
        let (cos, sin) = (shape.major_angle_rad.cos(), shape.major_angle_rad.sin());
        let mut ray = EyeRay {
            entry: (0.0, 0.0),
            inward: (0.0, 0.0),
            chord_m: 0.0,
            view: (0.0, 1.0),
            cos,
            sin,
        };
        let view = planar(wo).map_or((0.0, 1.0), |(d, _)| d);
        ray.view = view;
        let v = ray.unit(shape, view);
        let v_length = (v.0 * v.0 + v.1 * v.1).sqrt();
        if !(v_length > 0.0 && v_length.is_finite()) {
            return None;
        }
        let v_hat = (v.0 / v_length, v.1 / v_length);
        // The ribbon's `across` runs along (view.y, −view.x)'s image, which points the same
        // way as (v.1, −v.0) in unit coordinates (the map keeps orientation).
        let side = (v_hat.1, -v_hat.0);
        let s = if across.is_finite() {
            across.clamp(-1.0, 1.0)
        } else {
            0.0
        };
        let along = (1.0 - s * s).max(0.0).sqrt();
        ray.entry = (s * side.0 + along * v_hat.0, s * side.1 + along * v_hat.1);
        ray.inward = (-v.0, -v.1);
        // From a point p of the unit circle the line p + t d meets it again at −2 p·d / |d|².
        let dd = v_length * v_length;
        ray.chord_m =
            (-2.0 * (ray.entry.0 * ray.inward.0 + ray.entry.1 * ray.inward.1) / dd).max(0.0);
        Some(ray)
    }

    /// A cross-section direction (metres) in unit-circle coordinates.
    fn unit(&self, shape: &ClusterShape, p: (f64, f64)) -> (f64, f64) {
        (
            (p.0 * self.cos + p.1 * self.sin) / shape.semi_major_m,
            (p.1 * self.cos - p.0 * self.sin) / shape.semi_minor_m,
        )
    }

    /// The hairs on the light's line through the point `depth_m` along the ray.
    fn hairs_from(&self, shape: &ClusterShape, wi: DVec3, depth_m: f64) -> HairsOnPath {
        let Some((light, _)) = planar(wi) else {
            return HairsOnPath::ALONE;
        };
        let p = (
            self.entry.0 + depth_m * self.inward.0,
            self.entry.1 + depth_m * self.inward.1,
        );
        let d = self.unit(shape, light);
        let (toward, away) = chord_ends(p, d);
        // The eye's ray is empty up to the shaded fibre: a light ray leaving back along it
        // meets nothing while the two stay within a fibre's width (the correlation seed 001's
        // shadowing-masking stands for; without it, deep fibres went dark under front light).
        let cos_a = light.0 * self.view.0 + light.1 * self.view.1;
        let free = if cos_a > 0.0 {
            let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
            let along_eye = depth_m / cos_a.max(1e-6);
            let beside_eye = 2.0 * shape.fibre_radius_m / sin_a.max(1e-6);
            toward.min(along_eye).min(beside_eye)
        } else {
            0.0
        };
        let per_m = shape.crossings_per_m();
        let path = HairsOnPath {
            before: 1.0 + per_m * (toward - free).max(0.0),
            behind: per_m * away,
        };
        if path.before.is_finite() && path.behind.is_finite() {
            path
        } else {
            HairsOnPath::ALONE
        }
    }
}

/// A direction's part across the fibres, normalised, and its length; `None` along them.
fn planar(d: DVec3) -> Option<((f64, f64), f64)> {
    let length = (d.y * d.y + d.z * d.z).sqrt();
    (length > 1e-6 && length.is_finite()).then(|| ((d.y / length, d.z / length), length))
}

/// How far the line `p + t d` runs inside the unit circle ahead (`t > 0`) and behind, for `p`
/// inside or on it: the roots of `|p + t d|² = 1` by the stable form (a point on the circle
/// gives exactly 0 on one side).
fn chord_ends(p: (f64, f64), d: (f64, f64)) -> (f64, f64) {
    let aa = d.0 * d.0 + d.1 * d.1;
    if aa < 1e-18 {
        return (0.0, 0.0);
    }
    let bb = p.0 * d.0 + p.1 * d.1;
    let cc = (p.0 * p.0 + p.1 * p.1 - 1.0).min(0.0);
    let root = (bb * bb - aa * cc).max(0.0).sqrt();
    let q = -(bb + if bb >= 0.0 { root } else { -root });
    let (t1, t2) = if q != 0.0 {
        (q / aa, cc / q)
    } else {
        (0.0, 0.0)
    };
    let (lo, hi) = (t1.min(t2), t1.max(t2));
    (hi.max(0.0), (-lo).max(0.0))
}

impl AggregatedTables {
    /// What a thick hair shows at `across` of its ribbon: [`Self::aggregated_bcsdf`] averaged
    /// over the [`VISIBLE_DEPTHS`] depths of the fibre the eye meets
    /// ([`cluster_hairs_on_path`]); the shader's `aggregated_cluster`.
    pub fn aggregated_cluster(
        &self,
        shape: &ClusterShape,
        wo: DVec3,
        wi: DVec3,
        across: f64,
    ) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for k in 0..VISIBLE_DEPTHS {
            let path = cluster_hairs_on_path(shape, wo, wi, across, k);
            let f = self.aggregated_bcsdf(wo, wi, path, shape.coverage());
            for c in 0..3 {
                sum[c] += f[c] / VISIBLE_DEPTHS as f64;
            }
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::scene::{HairMaterial, Pigment};

    const FIBRE_RADIUS_M: f64 = 40e-6;

    fn materials() -> Vec<HairMaterial> {
        let melanin = |eumelanin: f32, pheomelanin: f32| HairMaterial {
            pigment: Pigment::Melanin {
                eumelanin,
                pheomelanin,
            },
            ..HairMaterial::default()
        };
        vec![
            HairMaterial {
                pigment: Pigment::Absorption { sigma_a: [0.0; 3] },
                tip_absorption_factor: 1.0,
                ..HairMaterial::default()
            },
            melanin(0.1, 0.3),
            HairMaterial::default(),
            melanin(8.0, 0.0),
            HairMaterial {
                longitudinal_roughness: 0.0,
                azimuthal_roughness: 0.0,
                cuticle_tilt_deg: 0.0,
                ..melanin(0.3, 0.1)
            },
            HairMaterial {
                longitudinal_roughness: 1.0,
                azimuthal_roughness: 1.0,
                cuticle_tilt_deg: 10.0,
                ior: 1.3,
                ..melanin(0.3, 0.1)
            },
        ]
    }

    fn clusters() -> Vec<ClusterShape> {
        let r = FIBRE_RADIUS_M;
        [
            (30.0 * r, 12.0 * r, 0.3, 200),  // dense
            (60.0 * r, 40.0 * r, -1.0, 40),  // sparse
            (40.0 * r, 0.0, 0.0, 25),        // flat (collinear roots)
            (0.0, 0.0, 0.0, 1),              // one strand
            (0.0, 0.0, 2.0, 500),            // coincident points
            (400.0 * r, 1.0 * r, 1.2, 5000), // a ribbon of hair
        ]
        .into_iter()
        .map(|(a, b, angle, n)| ClusterShape::new(a, b, angle, n, r).expect("valid"))
        .collect()
    }

    /// `∫ f cos-weighted over the sphere of incident directions`, averaged across the ribbon:
    /// the share of uniform incident radiance the cluster sends toward `wo`.
    fn albedo(tables: &AggregatedTables, shape: &ClusterShape, wo: DVec3) -> [f64; 3] {
        let (nt, np_, nh) = (480, 64, 3);
        let mut sum = [0.0; 3];
        for k in 0..nh {
            let across = -1.0 + (k as f64 + 0.5) * 2.0 / nh as f64;
            for i in 0..nt {
                let theta = -FRAC_PI_2 + (i as f64 + 0.5) * PI / nt as f64;
                for j in 0..np_ {
                    let phi = (j as f64 + 0.5) * TAU / np_ as f64;
                    let wi = direction(theta, phi);
                    let f = tables.aggregated_cluster(shape, wo, wi, across);
                    let d_omega = theta.cos() * (PI / nt as f64) * (TAU / np_ as f64);
                    for c in 0..3 {
                        sum[c] += f[c] * d_omega / nh as f64;
                    }
                }
            }
        }
        sum
    }

    #[test]
    fn a_white_furnace_never_returns_more_than_it_receives() {
        let views = [
            direction(0.0, FRAC_PI_2),
            direction(0.6, 1.2),
            direction(-1.2, 2.0),
        ];
        let mut highest: f64 = 0.0;
        for material in materials() {
            let tables = AggregatedTables::new(&Fibre::new(&material));
            for shape in clusters() {
                for wo in views {
                    let e = albedo(&tables, &shape, wo);
                    for c in 0..3 {
                        assert!(e[c].is_finite() && e[c] >= 0.0, "{material:?} {shape:?}");
                        highest = highest.max(e[c]);
                        // The quadrature of narrow lobes costs a percent or two.
                        assert!(
                            e[c] <= 1.02,
                            "{:?} {shape:?} wo {wo}: albedo {e:?}",
                            material.pigment
                        );
                    }
                }
            }
        }
        eprintln!("highest albedo {highest:.4}");
    }

    #[test]
    fn one_fibre_in_a_dense_cluster_shades_as_the_fibre_averaged_over_its_width() {
        // One fibre with nothing before or behind it, ρ = 1: no shadowing-masking, no light
        // lost on the way, no back scattering from neighbours. What is left must carry the
        // h-averaged single fibre's energy, split front and back the same way.
        // The smoothest fibre's lobes are narrower (in θ and in φ) than any affordable grid
        // resolves for the single-fibre reference; its finiteness and furnace are tested above.
        let resolvable = materials()
            .into_iter()
            .filter(|m| m.longitudinal_roughness >= 0.1 && m.azimuthal_roughness >= 0.1);
        for material in resolvable {
            let fibre = Fibre::new(&material);
            let bsdf = HairBsdf::new(&fibre);
            let tables = AggregatedTables::new(&fibre);
            let sigma_a = fibre.sigma_a_mean();
            for wo in [direction(0.2, FRAC_PI_2), direction(-0.7, 0.5)] {
                let (nt, np_, nh) = (64, 128, 32);
                let (mut single, mut aggregated) = ([0.0; 2], [0.0; 2]);
                for i in 0..nt {
                    let theta = -FRAC_PI_2 + (i as f64 + 0.5) * PI / nt as f64;
                    for j in 0..np_ {
                        let phi = azimuth(wo) + (j as f64 + 0.5) * TAU / np_ as f64;
                        let wi = direction(theta, phi);
                        let d_omega = theta.cos() * (PI / nt as f64) * (TAU / np_ as f64);
                        let half = usize::from(wrap_angle(phi - azimuth(wo)).abs() > FRAC_PI_2);
                        let mut f_single = 0.0;
                        for k in 0..nh {
                            let h = -1.0 + (k as f64 + 0.5) * 2.0 / nh as f64;
                            let f = bsdf.hair_bsdf(wo, wi, h, sigma_a);
                            f_single += (f[0] + f[1] + f[2]) / 3.0 / nh as f64;
                        }
                        single[half] += f_single * d_omega;
                        let f = tables.aggregated_bcsdf(wo, wi, HairsOnPath::ALONE, 1.0);
                        aggregated[half] += (f[0] + f[1] + f[2]) / 3.0 * d_omega;
                    }
                }
                let total = single[0] + single[1];
                for half in 0..2 {
                    // Tables are indexed by θ_i (as dual scattering's) and their lobes are
                    // Gaussians in θ_h: at oblique views the split between the halves moves
                    // by up to about 10 % of the near half, under 1 % of the fibre's energy.
                    let error = (aggregated[half] - single[half]).abs();
                    assert!(
                        error <= 0.08 * single[half] + 0.01 * total,
                        "{:?} wo {wo} half {half}: aggregated {:.4} single {:.4}",
                        material.pigment,
                        aggregated[half],
                        single[half]
                    );
                }
            }
        }
    }

    #[test]
    fn deeper_light_arrives_dimmer_and_wider() {
        let tables = AggregatedTables::new(&Fibre::new(&HairMaterial::default()));
        // Back light through the cluster: more hairs on the path, less light.
        let (wo, wi) = (direction(0.1, FRAC_PI_2), direction(-0.2, -FRAC_PI_2 + 0.3));
        let path = |before: f64| HairsOnPath {
            before,
            behind: 2.0,
        };
        let mut previous = tables.aggregated_bcsdf(wo, wi, path(1.0), 0.5);
        for n in [2.0, 4.0, 8.0, 16.0] {
            let next = tables.aggregated_bcsdf(wo, wi, path(n), 0.5);
            assert!(next[0] < previous[0], "n {n}: {next:?} after {previous:?}");
            previous = next;
        }
        // The highlight widens (eq. 9): on black hair, where the R lobe is all there is,
        // with the loss on the light's way divided out (it depends on θ_i alone), light far
        // from the highlight grows against its peak as more fibres lie before the shaded one.
        let black = AggregatedTables::new(&Fibre::new(&HairMaterial {
            pigment: Pigment::Melanin {
                eumelanin: 8.0,
                pheomelanin: 0.0,
            },
            ..HairMaterial::default()
        }));
        let eye = direction(-0.2, FRAC_PI_2);
        let shape = |before: f64, theta_i: f64| {
            let path = HairsOnPath {
                before,
                behind: 0.0,
            };
            let f = black.aggregated_bcsdf(eye, direction(theta_i, FRAC_PI_2 + 0.3), path, 1.0);
            f[0] / expected_power(black.agg_profile(0, theta_i)[0], before - 1.0)
        };
        let spread = |before: f64| shape(before, 1.1) / shape(before, 0.25);
        assert!(
            spread(6.0) > 1.5 * spread(1.0),
            "{} vs {}",
            spread(6.0),
            spread(1.0)
        );
    }

    #[test]
    fn sparse_clusters_shadow_themselves_where_light_and_eye_part() {
        let tables = AggregatedTables::new(&Fibre::new(&HairMaterial::default()));
        let wo = direction(0.0, FRAC_PI_2);
        let side_lit = direction(0.0, FRAC_PI_2 - 1.2);
        let dense = tables.aggregated_bcsdf(wo, side_lit, HairsOnPath::ALONE, 1.0);
        let sparse = tables.aggregated_bcsdf(wo, side_lit, HairsOnPath::ALONE, 0.1);
        assert!(sparse[0] < dense[0], "{sparse:?} vs {dense:?}");
    }

    #[test]
    fn the_crossing_estimate_matches_fibres_placed_at_random() {
        use crate::strands::random::{hash_to_unit, pcg_hash};
        let r = 1.0;
        for (a, b, members) in [(30.0, 12.0, 200u32), (20.0, 20.0, 60), (50.0, 8.0, 150)] {
            let shape = ClusterShape::new(a, b, 0.0, members, r).expect("valid");
            let mut crossings = 0.0;
            let mut length = 0.0;
            for trial in 0..200u32 {
                let random = |k: u32| hash_to_unit(pcg_hash(trial * 7919 + k));
                // Fibre centres uniform in the ellipse (a Poisson bundle, overlaps allowed).
                let mut centres = Vec::new();
                let mut k = 0;
                while centres.len() < members as usize {
                    let (x, y) = (2.0 * random(k) - 1.0, 2.0 * random(k + 1) - 1.0);
                    k += 2;
                    if x * x + y * y <= 1.0 {
                        centres.push((x * a, y * b));
                    }
                }
                // A chord through the middle half of the ellipse, along x, at height y0.
                let y0 = (random(k) - 0.5) * b;
                let half = a * (1.0 - (y0 / b).powi(2)).sqrt();
                length += 2.0 * half;
                crossings += centres
                    .iter()
                    .filter(|(x, y)| (y - y0).abs() < r && x.abs() <= half)
                    .count() as f64;
            }
            // One fibre is the shaded one: the estimate is for the others.
            let measured = crossings / length * (members as f64 - 1.0) / members as f64;
            let estimated = shape.crossings_per_m();
            assert!(
                (measured - estimated).abs() <= 0.1 * estimated,
                "{a}×{b}, {members}: measured {measured} estimated {estimated}"
            );
        }
    }

    #[test]
    fn hairs_on_the_path_follow_the_geometry() {
        let r = FIBRE_RADIUS_M;
        let shape = ClusterShape::new(30.0 * r, 10.0 * r, 0.0, 300, r).expect("valid");
        let wo = direction(0.0, FRAC_PI_2);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * b.max(1.0);
        let through = shape.crossings_per_m() * 20.0 * r;
        // Light from the viewer: it meets the shaded hair first, the thickness (2b) behind.
        let at_edge = |wi: DVec3, across: f64| cluster_hairs_at_depth(&shape, wo, wi, across, 0.0);
        let front = at_edge(direction(0.0, FRAC_PI_2), 0.0);
        assert!(
            close(front.before, 1.0) && close(front.behind, through),
            "{front:?}"
        );
        // Light from behind: through the whole thickness, nothing behind.
        let back = at_edge(direction(0.0, -FRAC_PI_2), 0.0);
        assert!(
            close(back.before, 1.0 + through) && close(back.behind, 0.0),
            "{back:?}"
        );
        // Light from the side, a quarter of the width in from the far edge: the shaded point
        // is at y = −a/2, so the light crosses to y = +a/2 (a) and nothing lies behind.
        let side = at_edge(direction(0.0, 0.0), -0.5);
        let expected = 1.0 + shape.crossings_per_m() * 30.0 * r;
        assert!(
            close(side.before, expected) && close(side.behind, 0.0),
            "{side:?}"
        );
        // Tilting the light along the fibres crosses the same ones.
        let tilted = at_edge(direction(0.5, -FRAC_PI_2), 0.0);
        assert!(close(tilted.before, 1.0 + through), "{tilted:?}");
        // Deeper along the eye's ray, back light crosses fewer fibres and front light more;
        // the depths the eye sees lie inside the chord, shallowest first.
        let half = at_edge(direction(0.0, -FRAC_PI_2), 0.0);
        let deep = cluster_hairs_at_depth(&shape, wo, direction(0.0, -FRAC_PI_2), 0.0, 10.0 * r);
        assert!(
            close(deep.before, 1.0 + 0.5 * (half.before - 1.0)),
            "{deep:?}"
        );
        let depths = |wi: DVec3| -> Vec<f64> {
            (0..VISIBLE_DEPTHS)
                .map(|k| cluster_hairs_on_path(&shape, wo, wi, 0.0, k).before)
                .collect()
        };
        let oblique = depths(direction(0.0, 0.6));
        assert!(oblique.windows(2).all(|w| w[0] <= w[1]), "{oblique:?}");
        assert!(oblique[VISIBLE_DEPTHS as usize - 1] > 1.5, "{oblique:?}");
        // Light along the eye's own ray comes back through the gap the eye looked through.
        for n in depths(direction(0.0, FRAC_PI_2)) {
            assert!(close(n, 1.0), "{n}");
        }
        // A single strand has nothing else on the path.
        let one = ClusterShape::new(0.0, 0.0, 0.0, 1, r).expect("valid");
        for across in [-1.0, 0.0, 0.7, 1.0] {
            for k in 0..VISIBLE_DEPTHS {
                let n = cluster_hairs_on_path(&one, wo, direction(-0.3, -1.0), across, k);
                assert_eq!(n, HairsOnPath::ALONE);
            }
        }
    }

    #[test]
    fn degenerate_clusters_and_inputs_stay_finite_and_bad_shapes_are_named() {
        let tables = AggregatedTables::new(&Fibre::new(&HairMaterial::default()));
        let hard = [
            (DVec3::X, DVec3::X),
            (DVec3::X, -DVec3::X),
            (direction(0.0, 0.0), direction(0.0, PI)),
            (direction(1.5, 0.3), direction(-1.5, 0.3)),
        ];
        for shape in clusters() {
            for (wo, wi) in hard {
                for across in [-1.0, 1.0, f64::NAN, 3.0] {
                    for k in 0..VISIBLE_DEPTHS {
                        let n = cluster_hairs_on_path(&shape, wo, wi, across, k);
                        assert!(
                            n.before.is_finite() && n.before >= 1.0 && n.behind >= 0.0,
                            "{shape:?}: {n:?}"
                        );
                    }
                    let f = tables.aggregated_cluster(&shape, wo, wi, across);
                    assert!(f.iter().all(|v| v.is_finite() && *v >= 0.0), "{f:?}");
                }
            }
        }
        for (before, behind, rho) in [
            (f64::NAN, 1.0, 0.5),
            (1e30, f64::NAN, f64::NAN),
            (-4.0, -3.0, -1.0),
            (f64::INFINITY, f64::INFINITY, 9.0),
        ] {
            let path = HairsOnPath { before, behind };
            let f = tables.aggregated_bcsdf(direction(0.1, 1.0), direction(0.2, -1.0), path, rho);
            assert!(f.iter().all(|v| v.is_finite() && *v >= 0.0), "{f:?}");
        }
        assert_eq!(
            ClusterShape::new(f64::NAN, 1.0, 0.0, 3, 1e-5),
            Err(ClusterShapeError::NotFinite {
                what: "major half-axis"
            })
        );
        assert_eq!(
            ClusterShape::new(1.0, 1.0, f64::INFINITY, 3, 1e-5),
            Err(ClusterShapeError::NotFinite {
                what: "major-axis angle"
            })
        );
        assert_eq!(
            ClusterShape::new(1.0, 1.0, 0.0, 0, 1e-5),
            Err(ClusterShapeError::NoMembers)
        );
        assert_eq!(
            ClusterShape::new(1.0, 1.0, 0.0, 3, 0.0),
            Err(ClusterShapeError::FibreRadius(0.0))
        );
        // A fitted section with NaN axes is refused by name too.
        let section = CrossSection {
            centre: DVec3::ZERO,
            tangent: DVec3::X,
            major: DVec3::new(0.0, f64::NAN, 0.0),
            minor: DVec3::ZERO,
        };
        assert!(matches!(
            ClusterShape::from_section(&section, DVec3::Y, DVec3::Z, 4, 1e-5),
            Err(ClusterShapeError::NotFinite { .. })
        ));
    }

    #[test]
    fn tables_stay_finite_at_the_material_limits() {
        for material in materials() {
            let tables = AggregatedTables::new(&Fibre::new(&material));
            assert_eq!(tables.data.len(), TABLE_LEN);
            for entry in &tables.data {
                assert!(entry.iter().all(|v| v.is_finite()), "{entry:?}");
            }
            // The forward mean cosine is a cosine.
            for t in 0..THETA_COUNT {
                let r_f = tables.data[3 * THETA_COUNT + t][0];
                assert!((0.0..=1.0).contains(&r_f), "{r_f}");
            }
        }
    }
}
