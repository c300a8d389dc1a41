//! The wind field: a mean flow whose gusts travel with it, plus a little crosswind, both
//! smooth value noise over time so nothing jumps between steps.

use glam::DVec3;

use crate::model::motion::Wind;
use crate::strands::random::{hash_to_unit, hash_values};

/// Smooth 1-D value noise in `[-1, 1]`: hashed values at integers, eased between them.
fn value_noise(x: f64, channel: u32) -> f64 {
    if !x.is_finite() {
        return 0.0;
    }
    let cell = x.floor();
    let t = x - cell;
    let ease = t * t * (3.0 - 2.0 * t);
    // Cells wrap at 2³¹: a wind blowing for 68 years at 1 Hz repeats.
    let at = |i: f64| {
        let wrapped = i.rem_euclid(2_147_483_648.0) as u32;
        2.0 * hash_to_unit(hash_values(&[wrapped, channel])) - 1.0
    };
    at(cell) + (at(cell + 1.0) - at(cell)) * ease
}

/// The air's velocity at `p` and `time_s`.
pub(crate) fn wind_velocity(wind: &Wind, p: DVec3, time_s: f64) -> DVec3 {
    let speed = wind.speed_m_per_s;
    let direction = DVec3::from(wind.direction).normalize_or_zero();
    if speed.is_nan() || speed <= 0.0 || direction == DVec3::ZERO {
        return DVec3::ZERO;
    }
    // Gusts move downwind at the mean speed: points along the wind see the same gust later.
    let phase = wind.gust_frequency_hz * (time_s - p.dot(direction) / speed);
    let gust = 1.0 + wind.gust_strength * value_noise(phase, 0);
    let side = direction.any_orthonormal_vector();
    let up = direction.cross(side);
    let cross = (side * value_noise(phase * 1.7, 1) + up * value_noise(phase * 1.3, 2))
        * (0.25 * wind.gust_strength);
    (direction * gust + cross) * speed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wind_is_smooth_bounded_and_still_without_speed() {
        let wind = Wind {
            speed_m_per_s: 5.0,
            ..Wind::default()
        };
        let mut previous = wind_velocity(&wind, DVec3::ZERO, 0.0);
        for i in 1..2000 {
            let v = wind_velocity(&wind, DVec3::ZERO, i as f64 * 0.005);
            assert!(v.length() <= 5.0 * (1.0 + 0.5 + 0.25 * 2f64.sqrt() * 0.5) + 1e-9);
            // Smooth: a 5 ms step changes the velocity by a small fraction of it.
            assert!((v - previous).length() < 0.1, "{v} after {previous}");
            previous = v;
        }
        let still = Wind::default();
        assert_eq!(wind_velocity(&still, DVec3::ONE, 3.0), DVec3::ZERO);
        assert!(wind_velocity(&wind, DVec3::NAN, f64::INFINITY).is_finite());
    }
}
