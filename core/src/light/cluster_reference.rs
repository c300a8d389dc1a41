//! The explicit-fibre reference for far hair's aggregated BCSDF (seed 001 Fig. 2's "avg.
//! ref."): a cluster of parallel fibres placed at random in an elliptical cross-section, lit
//! by a directional light and traced particle by particle through our single-fibre BCSDF
//! ([`crate::light::hair_bsdf`]) with every bounce between fibres. What leaves toward a
//! direction, per unit of the cluster's width seen from there, is the radiance a thick hair
//! standing for the cluster should show; [`crate::light::aggregated_bcsdf`] is measured
//! against it, and so is today's far LOD (a widened strand shaded as one fibre).
//!
//! Fibres are infinite along `x`, so a path is traced in the cross-section (`y`-`z`) while
//! its direction keeps its `x` part. At a fibre the frame is the reference renderer's: `x`
//! along the fibre, `z` the incoming direction's part across it, `y = z × x`, `h` the path's
//! offset from the axis along `y` over the radius. A particle leaves a fibre where it entered
//! (the BCSDF holds the passes inside), ignoring that fibre for its next step.

use std::f64::consts::TAU;

use glam::{DVec2, DVec3};

use crate::light::hair_bsdf::HairBsdf;
use crate::strands::random::SplitMix64;

/// Paths are cut after this many fibres (their weight is then below 10⁻⁶ for any hair).
const MAX_BOUNCES: usize = 256;

/// Parallel fibres of radius `fibre_radius_m` with centres `centres` (cross-section
/// coordinates), inside the ellipse of half-axes `semi_major_m` (along `y`) and
/// `semi_minor_m` (along `z`).
#[derive(Clone, Debug)]
pub struct FibreCluster {
    pub centres: Vec<DVec2>,
    pub fibre_radius_m: f64,
    pub semi_major_m: f64,
    pub semi_minor_m: f64,
}

impl FibreCluster {
    /// `members` non-overlapping fibres placed uniformly at random inside the ellipse, or
    /// `None` when they do not fit in a thousand tries each.
    pub fn random(
        semi_major_m: f64,
        semi_minor_m: f64,
        members: usize,
        fibre_radius_m: f64,
        seed: u64,
    ) -> Option<Self> {
        let mut rng = SplitMix64::new(seed);
        let (a, b) = (semi_major_m - fibre_radius_m, semi_minor_m - fibre_radius_m);
        if !(a > 0.0 && b > 0.0) {
            return None;
        }
        let mut centres: Vec<DVec2> = Vec::with_capacity(members);
        for _ in 0..members {
            let placed = (0..1000).find_map(|_| {
                let p = DVec2::new(2.0 * rng.next_f64() - 1.0, 2.0 * rng.next_f64() - 1.0);
                let c = DVec2::new(p.x * a, p.y * b);
                let free = p.length_squared() <= 1.0
                    && centres
                        .iter()
                        .all(|o| o.distance_squared(c) >= 4.0 * fibre_radius_m.powi(2));
                free.then_some(c)
            })?;
            centres.push(placed);
        }
        Some(Self {
            centres,
            fibre_radius_m,
            semi_major_m,
            semi_minor_m,
        })
    }

    /// Width of the ellipse across the cross-section direction `d` (unit, in `y`-`z`).
    pub fn width_across(&self, d: DVec2) -> f64 {
        let side = DVec2::new(-d.y, d.x);
        2.0 * ((self.semi_major_m * side.x).powi(2) + (self.semi_minor_m * side.y).powi(2)).sqrt()
    }

    /// Radiance leaving toward each of `views` per unit irradiance from the light direction
    /// `light` (unit, toward the light), as seen on the cluster's width from that view:
    /// `W_i cos θ_i P(ω) / (W_o cos θ_o)`, `P` the density per solid angle of the light that
    /// leaves within `cone_rad` of the view. `particles` particles; `sigma_a` the fibres'
    /// absorption.
    #[expect(clippy::too_many_arguments, reason = "one measurement's settings")]
    pub fn radiance(
        &self,
        bsdf: &HairBsdf,
        sigma_a: [f64; 3],
        light: DVec3,
        views: &[DVec3],
        cone_rad: f64,
        particles: usize,
        seed: u64,
    ) -> Vec<[f64; 3]> {
        let shares = self.gather(bsdf, sigma_a, light, views, cone_rad, particles, seed);
        let Some(across_light) = DVec2::new(light.y, light.z).try_normalize() else {
            return shares;
        };
        let cone = TAU * (1.0 - cone_rad.cos());
        let width_in = self.width_across(across_light);
        let cos_in = DVec2::new(light.y, light.z).length();
        views
            .iter()
            .zip(shares)
            .map(|(view, share)| {
                let planar = DVec2::new(view.y, view.z);
                let cos_out = planar.length();
                if cos_out < 1e-6 {
                    // Seen end-on the cluster has no width: no radiance to speak of.
                    return [0.0; 3];
                }
                let width_out = self.width_across(planar / cos_out);
                share.map(|s| s / cone * width_in * cos_in / (width_out * cos_out))
            })
            .collect()
    }

    /// The share of the light falling on the cluster from `light` that leaves within
    /// `cone_rad` of each of `views` (rgb, absorption included).
    #[expect(clippy::too_many_arguments, reason = "one measurement's settings")]
    pub fn gather(
        &self,
        bsdf: &HairBsdf,
        sigma_a: [f64; 3],
        light: DVec3,
        views: &[DVec3],
        cone_rad: f64,
        particles: usize,
        seed: u64,
    ) -> Vec<[f64; 3]> {
        let mut rng = SplitMix64::new(seed);
        let mut gathered = vec![[0.0; 3]; views.len()];
        let start = -light;
        let Some(across_light) = DVec2::new(start.y, start.z).try_normalize() else {
            return gathered;
        };
        let width_in = self.width_across(across_light);
        let cos_cone = cone_rad.cos();
        // Particles start on a line across the light, well outside the ellipse.
        let side = DVec2::new(-across_light.y, across_light.x);
        let outside = across_light * 4.0 * self.semi_major_m.max(self.semi_minor_m);
        for _ in 0..particles {
            let offset = (rng.next_f64() - 0.5) * width_in;
            let mut position = side * offset - outside;
            let mut direction = start;
            let mut weight = [1.0; 3];
            let mut skip = usize::MAX;
            for _ in 0..MAX_BOUNCES {
                let Some((fibre, t)) = self.nearest_hit(position, direction, skip) else {
                    // Escaped: count it toward every view it leaves close to.
                    for (view, sum) in views.iter().zip(&mut gathered) {
                        if direction.dot(*view) >= cos_cone {
                            for c in 0..3 {
                                sum[c] += weight[c];
                            }
                        }
                    }
                    break;
                };
                let planar = DVec2::new(direction.y, direction.z);
                position += planar * t;
                let centre = self.centres[fibre];
                // The frame of a fibre hit from `−direction` (the reference renderer's).
                let x = DVec3::X;
                let z = DVec3::new(0.0, -planar.x, -planar.y).normalize();
                let y = z.cross(x);
                let offset = position - centre;
                let h = ((offset.x * y.y + offset.y * y.z) / self.fibre_radius_m).clamp(-1.0, 1.0);
                let back = -direction;
                let wo = DVec3::new(back.dot(x), back.dot(y), back.dot(z));
                let u = [
                    rng.next_f64(),
                    rng.next_f64(),
                    rng.next_f64(),
                    rng.next_f64(),
                ];
                let Some((wi, f, pdf)) = bsdf.sample(wo, h, sigma_a, u) else {
                    break;
                };
                for c in 0..3 {
                    weight[c] *= f[c] / pdf;
                }
                direction = (x * wi.x + y * wi.y + z * wi.z).normalize();
                skip = fibre;
                // Russian roulette once the path carries little.
                let most = weight.iter().cloned().fold(0.0, f64::max);
                if most < 0.05 {
                    if rng.next_f64() > most / 0.05 {
                        break;
                    }
                    weight = weight.map(|w| w * 0.05 / most);
                }
            }
        }
        gathered
            .into_iter()
            .map(|sum| sum.map(|s| s / particles.max(1) as f64))
            .collect()
    }

    /// The first fibre (other than `skip`) the path from `p` along `d` enters, and how far
    /// along `d`'s cross-section part it is.
    fn nearest_hit(&self, p: DVec2, d: DVec3, skip: usize) -> Option<(usize, f64)> {
        let e = DVec2::new(d.y, d.z);
        let ee = e.length_squared();
        if ee < 1e-18 {
            return None;
        }
        let r2 = self.fibre_radius_m.powi(2);
        let mut best: Option<(usize, f64)> = None;
        for (i, c) in self.centres.iter().enumerate() {
            if i == skip {
                continue;
            }
            let m = p - *c;
            let bb = m.dot(e);
            let cc = m.length_squared() - r2;
            let disc = bb * bb - ee * cc;
            if disc < 0.0 {
                continue;
            }
            let t = (-bb - disc.sqrt()) / ee;
            if t > 0.0 && best.is_none_or(|(_, bt)| t < bt) {
                best = Some((i, t));
            }
        }
        best
    }
}

/// The thick hair's fibre frame for an eye along `view` (the preview's: `x` along the hair,
/// `z` the view across it, `y = z × x`) and `w` in it.
pub fn in_ribbon_frame(view: DVec3, w: DVec3) -> DVec3 {
    let x = DVec3::X;
    let z = (view - x * view.x).try_normalize().unwrap_or(DVec3::Z);
    let y = z.cross(x);
    DVec3::new(w.dot(x), w.dot(y), w.dot(z))
}

/// The major-axis angle (from the ribbon frame's `y` toward its `z`) of a cluster whose major
/// axis is the cross-section's `y`, for an eye along `view`.
pub fn major_angle_in_ribbon_frame(view: DVec3) -> f64 {
    let axis = in_ribbon_frame(view, DVec3::Y);
    axis.z.atan2(axis.y)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use super::*;
    use crate::light::aggregated_bcsdf::{AggregatedTables, ClusterShape};
    use crate::light::hair_bsdf::direction;

    /// Half-angle of the cone the tests count leaving light in.
    const CONE_RAD: f64 = 0.25;
    use crate::light::material::Fibre;
    use crate::model::scene::{HairMaterial, Pigment};

    /// The aggregated model's radiance averaged over the ribbon's width, and today's far LOD
    /// (one fibre's, averaged over h), each averaged over the cone the reference counts in.
    fn predictions(
        tables: &AggregatedTables,
        bsdf: &HairBsdf,
        sigma_a: [f64; 3],
        cluster: &FibreCluster,
        light: DVec3,
        view: DVec3,
    ) -> ([f64; 3], [f64; 3]) {
        let shape = ClusterShape::new(
            cluster.semi_major_m,
            cluster.semi_minor_m,
            major_angle_in_ribbon_frame(view),
            cluster.centres.len() as u32,
            cluster.fibre_radius_m,
        )
        .expect("valid");
        let (mut aggregated, mut single) = ([0.0; 3], [0.0; 3]);
        let mut count = 0.0;
        // The cone around the view, sampled on rings.
        for ring in 0..4 {
            let tilt = CONE_RAD * (ring as f64 + 0.5) / 4.0;
            for k in 0..12 {
                let spin = TAU * k as f64 / 12.0;
                let helper = if view.x.abs() < 0.9 {
                    DVec3::X
                } else {
                    DVec3::Y
                };
                let u = view.cross(helper).normalize();
                let v = view.cross(u);
                let wo_world = (view * tilt.cos() + (u * spin.cos() + v * spin.sin()) * tilt.sin())
                    .normalize();
                let wo = in_ribbon_frame(wo_world, wo_world);
                let wi = in_ribbon_frame(wo_world, light);
                let weight = tilt.sin();
                for s in 0..8 {
                    let across = -1.0 + (s as f64 + 0.5) / 4.0;
                    let f = tables.aggregated_cluster(&shape, wo, wi, across);
                    let g = bsdf.hair_bsdf(wo, wi, across, sigma_a);
                    for c in 0..3 {
                        aggregated[c] += weight * f[c];
                        single[c] += weight * g[c];
                    }
                    count += weight;
                }
            }
        }
        (aggregated.map(|v| v / count), single.map(|v| v / count))
    }

    #[test]
    fn the_aggregated_model_is_closer_to_explicit_fibres_than_one_widened_fibre() {
        let r = 1.0;
        let mut report = Vec::new();
        for (name, pigment) in [
            (
                "brown",
                Pigment::Melanin {
                    eumelanin: 1.3,
                    pheomelanin: 0.2,
                },
            ),
            (
                "blonde",
                Pigment::Melanin {
                    eumelanin: 0.15,
                    pheomelanin: 0.2,
                },
            ),
        ] {
            let material = HairMaterial {
                pigment,
                tip_absorption_factor: 1.0,
                strand_absorption_variation: 0.0,
                ..HairMaterial::default()
            };
            let fibre = Fibre::new(&material);
            let bsdf = HairBsdf::new(&fibre);
            let tables = AggregatedTables::new(&fibre);
            let sigma_a = fibre.sigma_a_mean();
            for (density, semi_major, semi_minor, members) in
                [("dense", 14.0, 7.0, 40), ("sparse", 20.0, 12.0, 24)]
            {
                let cluster = FibreCluster::random(semi_major * r, semi_minor * r, members, r, 7)
                    .expect("fits");
                let light = direction(0.2, FRAC_PI_2 + 0.4);
                // Front-lit (the eye near the light), side-lit and back-lit views.
                let views = [
                    direction(-0.1, FRAC_PI_2 + 0.1),
                    direction(-0.2, 0.2),
                    direction(-0.3, -FRAC_PI_2 - 0.2),
                ];
                let reference =
                    cluster.radiance(&bsdf, sigma_a, light, &views, CONE_RAD, 60_000, 11);
                let (mut error_aggregated, mut error_single) = (0.0, 0.0);
                for (view, expected) in views.iter().zip(&reference) {
                    let (aggregated, single) =
                        predictions(&tables, &bsdf, sigma_a, &cluster, light, *view);
                    let luminance = |v: &[f64; 3]| (v[0] + v[1] + v[2]) / 3.0;
                    let (e, a, s) = (
                        luminance(expected),
                        luminance(&aggregated),
                        luminance(&single),
                    );
                    report.push(format!(
                        "{name} {density} view {view:.2}: explicit fibres {e:.4}, aggregated {a:.4}, one fibre {s:.4}"
                    ));
                    error_aggregated += (a - e).abs();
                    error_single += (s - e).abs();
                }
                report.push(format!(
                    "{name} {density}: summed |error| aggregated {error_aggregated:.4}, one fibre {error_single:.4}"
                ));
                assert!(error_aggregated < error_single, "{}", report.join("\n"));
            }
        }
        eprintln!("{}", report.join("\n"));
    }

    #[test]
    fn a_lone_white_fibre_scatters_everything_it_intercepts() {
        // One non-absorbing fibre in a cluster of one: every particle leaves with its weight,
        // so the light gathered over the whole sphere is the light that fell on it.
        let cluster = FibreCluster {
            centres: vec![DVec2::ZERO],
            fibre_radius_m: 1.0,
            semi_major_m: 1.0,
            semi_minor_m: 1.0,
        };
        let fibre = Fibre::new(&HairMaterial {
            pigment: Pigment::Absorption { sigma_a: [0.0; 3] },
            ..HairMaterial::default()
        });
        let bsdf = HairBsdf::new(&fibre);
        let light = direction(0.3, 1.0);
        // Cones of 90° about ±x cover every direction once.
        let shares = cluster.gather(
            &bsdf,
            [0.0; 3],
            light,
            &[DVec3::X, -DVec3::X],
            FRAC_PI_2,
            20_000,
            3,
        );
        let share = shares[0][0] + shares[1][0];
        assert!((share - 1.0).abs() < 0.03, "{share}");
    }
}
