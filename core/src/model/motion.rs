//! The scene's motion: what moves the hair and how the simulator is set up.
//!
//! A scene without motion (`Scene::motion == None`, the default) never builds a simulator:
//! no step runs and no texture is re-uploaded per frame. With motion, the hair mesh is
//! simulated at a fixed rate ([`crate::simulate`]) and the strands follow it.
//!
//! Units are in the names; the head animation moves the body rigidly in model space (Y up).

use glam::{DQuat, DVec3, EulerRot};
use serde::{Deserialize, Serialize};

use crate::model::scene::InvalidScene;

/// One key of the head animation: where the body is at `time_s`, as a rigid motion of its
/// modelled pose (rotation about the model origin, then translation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeadKey {
    pub time_s: f64,
    pub translation_m: [f64; 3],
    /// Turn about the up axis (Y), positive to the head's left.
    pub yaw_deg: f64,
    /// Nod about the X axis, positive looks down.
    pub pitch_deg: f64,
    /// Tilt about the Z axis.
    pub roll_deg: f64,
}

impl HeadKey {
    pub fn at(time_s: f64) -> Self {
        Self {
            time_s,
            translation_m: [0.0; 3],
            yaw_deg: 0.0,
            pitch_deg: 0.0,
            roll_deg: 0.0,
        }
    }

    pub fn rotation(&self) -> DQuat {
        DQuat::from_euler(
            EulerRot::YXZ,
            self.yaw_deg.to_radians(),
            self.pitch_deg.to_radians(),
            self.roll_deg.to_radians(),
        )
    }
}

/// A rigid motion: `p ↦ rotation · p + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidMotion {
    pub rotation: DQuat,
    pub translation: DVec3,
}

impl RigidMotion {
    pub const IDENTITY: Self = Self {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    pub fn apply(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    pub fn inverse_apply(&self, p: DVec3) -> DVec3 {
        self.rotation.inverse() * (p - self.translation)
    }
}

/// Wind: a mean flow plus gusts, a smooth noise field over space and time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Wind {
    /// Mean speed; 0 is no wind.
    pub speed_m_per_s: f64,
    /// Where the wind blows toward (any length but 0).
    pub direction: [f64; 3],
    /// Gusts: the speed varies by up to this fraction of the mean, `[0, 1]`.
    pub gust_strength: f64,
    /// How often gusts come.
    pub gust_frequency_hz: f64,
}

impl Default for Wind {
    fn default() -> Self {
        Self {
            speed_m_per_s: 0.0,
            direction: [1.0, 0.0, 0.0],
            gust_strength: 0.5,
            gust_frequency_hz: 0.7,
        }
    }
}

/// How the hair mesh responds. Stiffnesses are in `[0, 1]` and map to XPBD compliances
/// (see [`crate::simulate::xpbd`]), so they mean the same whatever the step and iteration
/// counts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HairPhysics {
    /// Resistance to bending along the columns.
    pub bend_stiffness: f64,
    /// Resistance of each bundle layer's cross-section to shearing and squashing.
    pub shape_stiffness: f64,
    /// Pull back toward the modelled shape (carried with the head) at the root and at the
    /// tip: the modelled style is what the hair returns to when nothing moves it.
    pub retention_root: f64,
    pub retention_tip: f64,
    /// Velocity damping, per second.
    pub damping_per_s: f64,
    /// Air drag toward the wind's velocity, per second.
    pub drag_per_s: f64,
    /// Coulomb friction against the body, `[0, 2]`.
    pub friction: f64,
    /// The distance every hair-mesh vertex keeps from the body.
    pub collision_margin_m: f64,
    /// The hair's own volume: each layer above the scalp keeps this much more distance from
    /// the body than the one below, so hair lying on the head still covers it.
    #[serde(default = "default_volume")]
    pub volume_m_per_layer: f64,
}

fn default_volume() -> f64 {
    HairPhysics::default().volume_m_per_layer
}

impl Default for HairPhysics {
    fn default() -> Self {
        Self {
            bend_stiffness: 0.5,
            shape_stiffness: 0.4,
            retention_root: 0.9,
            retention_tip: 0.15,
            damping_per_s: 1.5,
            drag_per_s: 2.0,
            friction: 0.3,
            collision_margin_m: 0.002,
            volume_m_per_layer: 0.003,
        }
    }
}

impl HairPhysics {
    /// Draping: the hair falls freely onto the body (no pull toward the modelled shape).
    pub fn drape() -> Self {
        Self {
            bend_stiffness: 0.1,
            shape_stiffness: 0.2,
            retention_root: 0.0,
            retention_tip: 0.0,
            damping_per_s: 6.0,
            friction: 0.6,
            ..Self::default()
        }
    }
}

/// Sub-steps and iterations: the simulator's accuracy switch, measured in
/// `hairloom bench sim`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimQuality {
    /// Fixed steps per simulated second, whatever the frame rate.
    pub rate_hz: f64,
    pub substeps: u32,
    pub iterations: u32,
}

impl Default for SimQuality {
    /// 2 × 2: the quality that fits the 2 ms-per-frame budget on one core of the CI machine
    /// for the long sample (1.6 ms, 5.6 mm RMS from the converged reference in a fast head
    /// turn in wind; 4 × 2 halves the error for twice the time: BENCHMARKS.md).
    fn default() -> Self {
        Self {
            rate_hz: 60.0,
            substeps: 2,
            iterations: 2,
        }
    }
}

/// What moves the hair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Motion {
    /// Keys of the body's rigid motion, by time; none is a still head.
    pub head_animation: Vec<HeadKey>,
    /// Downward acceleration (along −Y).
    pub gravity_m_per_s2: f64,
    pub wind: Wind,
    pub physics: HairPhysics,
    pub quality: SimQuality,
}

impl Default for Motion {
    fn default() -> Self {
        Self {
            head_animation: Vec::new(),
            gravity_m_per_s2: 9.81,
            wind: Wind::default(),
            physics: HairPhysics::default(),
            quality: SimQuality::default(),
        }
    }
}

/// Most keys a head animation may hold; more is not an animation an artist typed.
pub const MAX_HEAD_KEYS: usize = 10_000;
/// Limits on the simulator's step counts: bounded time per simulated second.
pub const MAX_RATE_HZ: f64 = 1000.0;
pub const MAX_SUBSTEPS: u32 = 64;
pub const MAX_ITERATIONS: u32 = 64;
/// The most constraint sweeps (rate × sub-steps × iterations) per simulated second: 60 Hz ×
/// 16 × 16, about 80 ms of work per frame on the long sample; more is a typing mistake.
pub const MAX_SWEEPS_PER_S: f64 = 60.0 * 16.0 * 16.0;
/// The latest time a head-animation key may have (ten minutes): bounded work to reach it.
pub const MAX_KEY_TIME_S: f64 = 600.0;

fn invalid(path: String, message: String) -> InvalidScene {
    InvalidScene { path, message }
}

fn check(path: &str, value: f64, lo: f64, hi: f64) -> Result<(), InvalidScene> {
    if !value.is_finite() {
        return Err(invalid(
            path.into(),
            format!("{value} is not a finite number"),
        ));
    }
    if !(lo..=hi).contains(&value) {
        return Err(invalid(
            path.into(),
            format!("{value} is outside the valid range [{lo}, {hi}]"),
        ));
    }
    Ok(())
}

impl Motion {
    /// A head turn: still, a turn of `yaw_deg` over `turn_s` starting at `start_s`, a hold,
    /// and back. The editor's and CLI's default animation.
    pub fn head_turn(start_s: f64, turn_s: f64, yaw_deg: f64) -> Self {
        let key = |time_s: f64, yaw_deg: f64| HeadKey {
            yaw_deg,
            ..HeadKey::at(time_s)
        };
        Self {
            head_animation: vec![
                key(0.0, 0.0),
                key(start_s, 0.0),
                key(start_s + turn_s, yaw_deg),
                key(start_s + 2.0 * turn_s + 0.5, yaw_deg),
                key(start_s + 3.0 * turn_s + 0.5, 0.0),
            ],
            ..Self::default()
        }
    }

    /// The body's pose at `time_s`: keys interpolated linearly (translation and each of yaw,
    /// pitch and roll, so a 270° turn between two keys turns 270°, not the short way), held
    /// before the first and after the last.
    pub fn head_pose(&self, time_s: f64) -> RigidMotion {
        let keys = &self.head_animation;
        let pose = |key: &HeadKey| RigidMotion {
            rotation: key.rotation(),
            translation: DVec3::from(key.translation_m),
        };
        let Some(first) = keys.first() else {
            return RigidMotion::IDENTITY;
        };
        if time_s.partial_cmp(&first.time_s) != Some(std::cmp::Ordering::Greater) {
            return pose(first);
        }
        // The first key at or after `time_s` (keys are in time order).
        let next = keys.partition_point(|k| k.time_s < time_s);
        let (Some(a), Some(b)) = (keys.get(next.wrapping_sub(1)), keys.get(next)) else {
            return pose(keys.last().unwrap_or(first));
        };
        let span = b.time_s - a.time_s;
        let t = if span > 0.0 {
            ((time_s - a.time_s) / span).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let lerp = |x: f64, y: f64| x + (y - x) * t;
        let between = HeadKey {
            time_s,
            translation_m: DVec3::from(a.translation_m)
                .lerp(DVec3::from(b.translation_m), t)
                .to_array(),
            yaw_deg: lerp(a.yaw_deg, b.yaw_deg),
            pitch_deg: lerp(a.pitch_deg, b.pitch_deg),
            roll_deg: lerp(a.roll_deg, b.roll_deg),
        };
        pose(&between)
    }

    /// The animation's length: the last key's time (0 for a still head).
    pub fn duration_s(&self) -> f64 {
        self.head_animation.last().map_or(0.0, |k| k.time_s)
    }

    pub fn validate(&self) -> Result<(), InvalidScene> {
        if self.head_animation.len() > MAX_HEAD_KEYS {
            return Err(invalid(
                "motion.head_animation".into(),
                format!(
                    "{} keys are more than the {MAX_HEAD_KEYS} an animation may hold",
                    self.head_animation.len()
                ),
            ));
        }
        let mut previous = f64::NEG_INFINITY;
        for (i, key) in self.head_animation.iter().enumerate() {
            let at = |field: &str| format!("motion.head_animation[{i}].{field}");
            check(&at("time_s"), key.time_s, 0.0, MAX_KEY_TIME_S)?;
            if key.time_s < previous {
                return Err(invalid(
                    at("time_s"),
                    format!(
                        "{} is before the previous key's {previous}: keys go in time order",
                        key.time_s
                    ),
                ));
            }
            previous = key.time_s;
            for (axis, value) in ["x", "y", "z"].iter().zip(key.translation_m) {
                check(&at(&format!("translation_m.{axis}")), value, -1e4, 1e4)?;
            }
            check(&at("yaw_deg"), key.yaw_deg, -1e5, 1e5)?;
            check(&at("pitch_deg"), key.pitch_deg, -1e5, 1e5)?;
            check(&at("roll_deg"), key.roll_deg, -1e5, 1e5)?;
        }
        check(
            "motion.gravity_m_per_s2",
            self.gravity_m_per_s2,
            -100.0,
            100.0,
        )?;
        let wind = &self.wind;
        check("motion.wind.speed_m_per_s", wind.speed_m_per_s, 0.0, 500.0)?;
        for (axis, value) in ["x", "y", "z"].iter().zip(wind.direction) {
            check(&format!("motion.wind.direction.{axis}"), value, -1e6, 1e6)?;
        }
        if DVec3::from(wind.direction).length_squared() < 1e-24 {
            return Err(invalid(
                "motion.wind.direction".into(),
                "a direction cannot have zero length".into(),
            ));
        }
        check("motion.wind.gust_strength", wind.gust_strength, 0.0, 1.0)?;
        check(
            "motion.wind.gust_frequency_hz",
            wind.gust_frequency_hz,
            0.0,
            100.0,
        )?;
        let p = &self.physics;
        check("motion.physics.bend_stiffness", p.bend_stiffness, 0.0, 1.0)?;
        check(
            "motion.physics.shape_stiffness",
            p.shape_stiffness,
            0.0,
            1.0,
        )?;
        check("motion.physics.retention_root", p.retention_root, 0.0, 1.0)?;
        check("motion.physics.retention_tip", p.retention_tip, 0.0, 1.0)?;
        check("motion.physics.damping_per_s", p.damping_per_s, 0.0, 1000.0)?;
        check("motion.physics.drag_per_s", p.drag_per_s, 0.0, 1000.0)?;
        check("motion.physics.friction", p.friction, 0.0, 2.0)?;
        check(
            "motion.physics.collision_margin_m",
            p.collision_margin_m,
            0.0,
            0.1,
        )?;
        check(
            "motion.physics.volume_m_per_layer",
            p.volume_m_per_layer,
            0.0,
            0.1,
        )?;
        let q = &self.quality;
        check("motion.quality.rate_hz", q.rate_hz, 1.0, MAX_RATE_HZ)?;
        if !(1..=MAX_SUBSTEPS).contains(&q.substeps) {
            return Err(invalid(
                "motion.quality.substeps".into(),
                format!(
                    "{} is outside the valid range [1, {MAX_SUBSTEPS}]",
                    q.substeps
                ),
            ));
        }
        if !(1..=MAX_ITERATIONS).contains(&q.iterations) {
            return Err(invalid(
                "motion.quality.iterations".into(),
                format!(
                    "{} is outside the valid range [1, {MAX_ITERATIONS}]",
                    q.iterations
                ),
            ));
        }
        let sweeps = q.rate_hz * q.substeps as f64 * q.iterations as f64;
        if sweeps > MAX_SWEEPS_PER_S {
            return Err(invalid(
                "motion.quality".into(),
                format!(
                    "{} Hz × {} sub-steps × {} iterations is {sweeps} constraint sweeps per simulated second, more than the {MAX_SWEEPS_PER_S} allowed",
                    q.rate_hz, q.substeps, q.iterations
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_pose_interpolates_and_holds_outside_the_keys() {
        let motion = Motion::head_turn(0.5, 1.0, 90.0);
        let before = motion.head_pose(-1.0);
        assert_eq!(before, RigidMotion::IDENTITY);
        let half = motion.head_pose(1.0);
        let (axis, angle) = half.rotation.to_axis_angle();
        assert!((angle.to_degrees() - 45.0).abs() < 1e-9, "{angle}");
        assert!((axis - DVec3::Y).length() < 1e-9);
        let x = motion.head_pose(1.5).apply(DVec3::X);
        assert!((x - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-9, "{x}");
        assert_eq!(motion.head_pose(1e9), RigidMotion::IDENTITY);
        // Angles interpolate as angles: halfway through a 270° turn is 135°, not −45°.
        let wide = Motion {
            head_animation: vec![
                HeadKey::at(0.0),
                HeadKey {
                    yaw_deg: 270.0,
                    ..HeadKey::at(1.0)
                },
            ],
            ..Motion::default()
        };
        let (_, angle) = wide.head_pose(0.5).rotation.to_axis_angle();
        assert!(
            (angle.to_degrees() - 135.0).abs() < 1e-9,
            "{}",
            angle.to_degrees()
        );
        let nan = motion.head_pose(f64::NAN);
        assert!(nan.rotation.is_finite() && nan.translation.is_finite());
    }

    #[test]
    fn invalid_motion_is_refused_with_the_field_named() {
        let mut motion = Motion::head_turn(0.0, 1.0, 30.0);
        assert!(motion.validate().is_ok());
        motion.head_animation[2].time_s = 0.1;
        motion.head_animation[3].time_s = 0.05;
        let error = motion.validate().expect_err("invalid");
        assert_eq!(error.path, "motion.head_animation[3].time_s");
        let mut motion = Motion::default();
        motion.wind.direction = [0.0; 3];
        assert_eq!(
            motion.validate().expect_err("invalid").path,
            "motion.wind.direction"
        );
        let mut motion = Motion::default();
        motion.physics.friction = f64::NAN;
        assert_eq!(
            motion.validate().expect_err("invalid").path,
            "motion.physics.friction"
        );
        let mut motion = Motion::default();
        motion.quality.substeps = 0;
        assert_eq!(
            motion.validate().expect_err("invalid").path,
            "motion.quality.substeps"
        );
        let mut motion = Motion::default();
        motion.quality.rate_hz = 1000.0;
        motion.quality.substeps = 64;
        motion.quality.iterations = 64;
        assert_eq!(
            motion.validate().expect_err("invalid").path,
            "motion.quality"
        );
        let mut motion = Motion::head_turn(0.0, 1.0, 30.0);
        motion.head_animation[4].time_s = 1e6;
        assert_eq!(
            motion.validate().expect_err("invalid").path,
            "motion.head_animation[4].time_s"
        );
    }
}
