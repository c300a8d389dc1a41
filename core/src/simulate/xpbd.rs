//! Hair-mesh dynamics by XPBD (Macklin et al. 2016) with small steps (Macklin et al. 2019):
//! each fixed step is split into sub-steps, each sub-step predicts positions from
//! velocities and projects the constraints a few times.
//!
//! The particles are the hair-mesh vertices (a few thousand, against 100K strands: the
//! method's advantage, Wu & Yuksel 2016). Constraints, all distances kept at their modelled
//! lengths:
//! - **stretch** along each column, layer `k` to `k + 1` (inextensible: zero compliance);
//! - **bend** along each column, `k` to `k + 2`;
//! - **shape** of each bundle layer's cross-section: its sides and, for quads, diagonals;
//! - **shear** between a layer's corners and the next layer's neighbours: how a whole bundle
//!   bends, so it is as soft as bending;
//! - **retention** toward the modelled shape carried with the head, strongest at the root:
//!   the style is what the hair returns to;
//! - **collision** with the body's signed distance field, with Coulomb friction;
//! - roots (and locked vertices) are pinned to the moving body.
//!
//! Interior vertices are simulated with the rest: they are tied to their neighbours by the
//! same constraints, so they follow the exterior without the per-step Laplace solve that
//! re-placing them would cost (`hairloom bench sim` measures both).
//!
//! Stiffnesses in `[0, 1]` map to compliances `10^(−1 − 8 s)` m/N for unit-mass particles,
//! so a stiffness means the same whatever the step and iteration counts (the XPBD
//! property; `bench sim` measures what remains).
//!
//! Everything runs in a fixed order on one thread: the same inputs give the same bytes.

use std::collections::BTreeMap;

use glam::DVec3;

use crate::model::document::BodyMesh;
use crate::model::mesh::{HairMesh, VertexRef};
use crate::model::motion::{Motion, RigidMotion};
use crate::simulate::body_sdf::BodySdf;
use crate::simulate::wind::wind_velocity;

/// Frame time above which the simulator drops time instead of catching up (a stalled
/// frame must not trigger a burst of steps).
pub const MAX_FRAME_S: f64 = 0.25;
/// The head moving faster than this between two sub-steps is a cut (teleport), not motion:
/// the hair is carried with it rigidly instead of being yanked.
pub const TELEPORT_SPEED_M_PER_S: f64 = 10.0;
pub const TELEPORT_TURN_RAD_PER_S: f64 = 4.0 * std::f64::consts::PI;
/// A safety net, far above anything hair does: no particle moves faster.
pub const MAX_SPEED_M_PER_S: f64 = 500.0;

/// XPBD compliance of a stiffness in `[0, 1]`.
pub fn compliance(stiffness: f64) -> f64 {
    10f64.powf(-1.0 - 8.0 * stiffness.clamp(0.0, 1.0))
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Kind {
    Stretch,
    Shape,
    Bend,
}

#[derive(Clone, Copy, Debug)]
struct Distance {
    a: u32,
    b: u32,
    rest_m: f64,
    kind: Kind,
}

/// What a step counted, for tests and the status bar.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    pub steps: u64,
    pub collisions: u64,
}

/// A hair mesh being simulated.
#[derive(Clone, Debug)]
pub struct HairSim {
    motion: Motion,
    rest: HairMesh,
    pinned: Vec<VertexRef>,
    sdf: BodySdf,
    /// First particle of each column and how many of its layers are simulated.
    column_start: Vec<usize>,
    column_len: Vec<usize>,
    /// Modelled position of each particle (body space).
    rest_position: Vec<DVec3>,
    position: Vec<DVec3>,
    previous: Vec<DVec3>,
    velocity: Vec<DVec3>,
    inverse_mass: Vec<f64>,
    /// Compliance of each particle's pull toward its modelled position (`None`: no pull).
    retention: Vec<Option<f64>>,
    constraints: Vec<Distance>,
    pose: RigidMotion,
    steps: u64,
    accumulator_s: f64,
    stats: StepStats,
}

impl HairSim {
    /// Sets up the simulation of `mesh` (the modelled shape) on `body`. `sdf` must be the
    /// body's field (see [`BodySdf::build`]); `pinned` vertices keep their place on the body
    /// (an artist's locked vertices), as the roots do.
    pub fn new(mesh: &HairMesh, sdf: BodySdf, motion: &Motion, pinned: &[VertexRef]) -> Self {
        let column_count = mesh.columns.len();
        let mut column_len = vec![0usize; column_count];
        for bundle in mesh.bundles.iter().filter(|b| !b.removed) {
            for &c in &bundle.vertices {
                let len =
                    (bundle.layers as usize + 1).min(mesh.columns[c as usize].positions.len());
                column_len[c as usize] = column_len[c as usize].max(len);
            }
        }
        let mut column_start = Vec::with_capacity(column_count);
        let mut rest_position = Vec::new();
        let mut retention = Vec::new();
        let mut inverse_mass = Vec::new();
        let physics = &motion.physics;
        for (c, column) in mesh.columns.iter().enumerate() {
            column_start.push(rest_position.len());
            let len = column_len[c];
            for k in 0..len {
                rest_position.push(column.positions[k]);
                let fraction = k as f64 / (len - 1).max(1) as f64;
                let stiffness = physics.retention_root
                    + (physics.retention_tip - physics.retention_root) * fraction;
                retention.push((stiffness > 0.0).then(|| compliance(stiffness)));
                inverse_mass.push(if k == 0 { 0.0 } else { 1.0 });
            }
        }
        for vertex in pinned {
            let (c, k) = (vertex.column as usize, vertex.layer as usize);
            if c < column_count && k < column_len[c] {
                inverse_mass[column_start[c] + k] = 0.0;
            }
        }
        let particle = |c: u32, k: usize| -> Option<u32> {
            let c = c as usize;
            (k < column_len[c]).then(|| (column_start[c] + k) as u32)
        };
        // Deduplicated in a map so shared edges appear once and the order is fixed.
        let mut edges: BTreeMap<(u32, u32), Kind> = BTreeMap::new();
        let mut add = |a: Option<u32>, b: Option<u32>, kind: Kind| {
            if let (Some(a), Some(b)) = (a, b)
                && a != b
            {
                let key = (a.min(b), a.max(b));
                let entry = edges.entry(key).or_insert(kind);
                *entry = (*entry).min(kind);
            }
        };
        for (c, &len) in column_len.iter().enumerate() {
            for k in 0..len {
                add(
                    particle(c as u32, k),
                    particle(c as u32, k + 1),
                    Kind::Stretch,
                );
                add(particle(c as u32, k), particle(c as u32, k + 2), Kind::Bend);
            }
        }
        for bundle in mesh.bundles.iter().filter(|b| !b.removed) {
            let n = bundle.vertices.len();
            let layers = bundle.layers as usize;
            for k in 0..=layers {
                for i in 0..n {
                    let (a, b) = (bundle.vertices[i], bundle.vertices[(i + 1) % n]);
                    if k > 0 {
                        add(particle(a, k), particle(b, k), Kind::Shape);
                    }
                    if k < layers {
                        // Shear between layers is how a bundle bends: as soft as bending.
                        add(particle(a, k), particle(b, k + 1), Kind::Bend);
                        add(particle(b, k), particle(a, k + 1), Kind::Bend);
                    }
                }
                if n == 4 && k > 0 {
                    let v = &bundle.vertices;
                    add(particle(v[0], k), particle(v[2], k), Kind::Shape);
                    add(particle(v[1], k), particle(v[3], k), Kind::Shape);
                }
            }
        }
        let constraints = edges
            .into_iter()
            .map(|((a, b), kind)| Distance {
                a,
                b,
                rest_m: rest_position[a as usize].distance(rest_position[b as usize]),
                kind,
            })
            .filter(|d| d.rest_m.is_finite())
            .collect();
        let pose = motion.head_pose(0.0);
        let position: Vec<DVec3> = rest_position.iter().map(|&p| pose.apply(p)).collect();
        Self {
            motion: motion.clone(),
            rest: mesh.clone(),
            pinned: pinned.to_vec(),
            sdf,
            column_start,
            column_len,
            velocity: vec![DVec3::ZERO; position.len()],
            previous: position.clone(),
            position,
            rest_position,
            inverse_mass,
            retention,
            constraints,
            pose,
            steps: 0,
            accumulator_s: 0.0,
            stats: StepStats::default(),
        }
    }

    /// Builds the body's field at the default resolution, then [`Self::new`].
    pub fn with_body(
        mesh: &HairMesh,
        body: &BodyMesh,
        motion: &Motion,
        pinned: &[VertexRef],
    ) -> Self {
        let padding_m = 0.05 * mesh.size().max(1e-3);
        let sdf = BodySdf::build(body, super::body_sdf::DEFAULT_RESOLUTION, padding_m);
        Self::new(mesh, sdf, motion, pinned)
    }

    pub fn particle_count(&self) -> usize {
        self.position.len()
    }

    pub fn constraint_count(&self) -> usize {
        self.constraints.len()
    }

    /// Fixed steps taken since the start.
    pub fn stats(&self) -> StepStats {
        self.stats
    }

    pub fn step_s(&self) -> f64 {
        1.0 / self.motion.quality.rate_hz
    }

    /// Simulated time: the fixed steps taken times the step.
    pub fn time_s(&self) -> f64 {
        self.steps as f64 * self.step_s()
    }

    pub fn positions(&self) -> &[DVec3] {
        &self.position
    }

    pub fn velocities(&self) -> &[DVec3] {
        &self.velocity
    }

    pub fn sdf(&self) -> &BodySdf {
        &self.sdf
    }

    /// The body's pose at the current time.
    pub fn pose(&self) -> RigidMotion {
        self.pose
    }

    /// Kinetic plus gravitational energy per unit particle mass (J/kg summed over
    /// particles), heights measured from the model origin.
    pub fn energy(&self) -> f64 {
        let g = self.motion.gravity_m_per_s2;
        self.position
            .iter()
            .zip(&self.velocity)
            .zip(&self.inverse_mass)
            .filter(|(_, w)| **w > 0.0)
            .map(|((p, v), _)| 0.5 * v.length_squared() + g * p.y)
            .sum()
    }

    /// Signed distance of the deepest particle below the body's surface (positive: inside).
    pub fn deepest_penetration_m(&self) -> f64 {
        self.position
            .iter()
            .map(|&p| -self.sdf.distance_m(self.pose.inverse_apply(p)))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Moves simulated time on by a frame's `frame_s`, in fixed steps: the frame rate never
    /// changes what is computed, only when it is looked at. Returns the steps taken.
    pub fn advance(&mut self, frame_s: f64) -> u32 {
        let frame_s = if frame_s.is_finite() {
            frame_s.clamp(0.0, MAX_FRAME_S)
        } else {
            0.0
        };
        self.accumulator_s += frame_s;
        let step_s = self.step_s();
        let mut taken = 0;
        // A tolerance of a millionth of a step absorbs the rounding of frame times.
        while self.accumulator_s >= step_s * (1.0 - 1e-6) {
            self.step();
            self.accumulator_s -= step_s;
            taken += 1;
        }
        self.accumulator_s = self.accumulator_s.max(0.0);
        taken
    }

    /// Runs (from the start if `time_s` is in the past) until the simulated time reaches
    /// `time_s`, rounded to whole steps. For scrubbing and `render --time`.
    pub fn seek(&mut self, time_s: f64) {
        let target = if time_s.is_finite() {
            (time_s.max(0.0) / self.step_s()).round() as u64
        } else {
            0
        };
        if target < self.steps {
            *self = Self::new(&self.rest, self.sdf.clone(), &self.motion, &self.pinned);
        }
        while self.steps < target {
            self.step();
        }
        self.accumulator_s = 0.0;
    }

    /// One fixed step: `substeps` predictions, each followed by `iterations` projections.
    pub fn step(&mut self) {
        let quality = self.motion.quality.clone();
        let substeps = quality.substeps.max(1);
        let dt = self.step_s() / substeps as f64;
        for substep in 0..substeps {
            let time_s = self.time_s() + (substep + 1) as f64 * dt;
            self.substep(time_s, dt, quality.iterations.max(1));
        }
        self.steps += 1;
        self.stats.steps += 1;
    }

    fn substep(&mut self, time_s: f64, dt: f64, iterations: u32) {
        let motion = &self.motion;
        let physics = &motion.physics;
        let old_pose = self.pose;
        let new_pose = motion.head_pose(time_s);
        let turn = (new_pose.rotation * old_pose.rotation.inverse())
            .to_axis_angle()
            .1;
        let turn = turn.min(std::f64::consts::TAU - turn).abs();
        let moved = (new_pose.translation - old_pose.translation).length();
        if moved > TELEPORT_SPEED_M_PER_S * dt || turn > TELEPORT_TURN_RAD_PER_S * dt {
            // A cut: carry everything with the head, keeping its shape and body-relative
            // velocity.
            let delta = new_pose.rotation * old_pose.rotation.inverse();
            for i in 0..self.position.len() {
                self.position[i] = new_pose.apply(old_pose.inverse_apply(self.position[i]));
                self.velocity[i] = delta * self.velocity[i];
            }
        }
        self.pose = new_pose;

        let gravity = DVec3::new(0.0, -motion.gravity_m_per_s2, 0.0);
        let damping = (-physics.damping_per_s * dt).exp();
        let drag = (-physics.drag_per_s * dt).exp();
        for i in 0..self.position.len() {
            self.previous[i] = self.position[i];
            if self.inverse_mass[i] == 0.0 {
                // Pinned: carried by the body.
                self.position[i] = new_pose.apply(self.rest_position[i]);
                self.velocity[i] = DVec3::ZERO;
                continue;
            }
            let air = wind_velocity(&motion.wind, self.position[i], time_s);
            let mut v = self.velocity[i] * damping + gravity * dt;
            v = air + (v - air) * drag;
            self.velocity[i] = v;
            self.position[i] += v * dt;
        }

        let dt2 = dt * dt;
        let compliance_of = |kind: Kind| match kind {
            Kind::Stretch => 0.0,
            Kind::Shape => compliance(physics.shape_stiffness),
            Kind::Bend => compliance(physics.bend_stiffness),
        } / dt2;
        let stiffness = [
            compliance_of(Kind::Stretch),
            compliance_of(Kind::Shape),
            compliance_of(Kind::Bend),
        ];
        let mut lambda = vec![0.0; self.constraints.len()];
        let mut retention_lambda = vec![0.0; self.position.len()];
        for _ in 0..iterations {
            for (c, constraint) in self.constraints.iter().enumerate() {
                let (a, b) = (constraint.a as usize, constraint.b as usize);
                let (wa, wb) = (self.inverse_mass[a], self.inverse_mass[b]);
                let w = wa + wb;
                if w == 0.0 {
                    continue;
                }
                let delta = self.position[a] - self.position[b];
                let length = delta.length();
                if length.is_nan() || length <= 1e-12 {
                    continue; // coincident: no direction to push along
                }
                let normal = delta / length;
                let alpha = stiffness[constraint.kind as usize];
                let violation = length - constraint.rest_m;
                let change = (-violation - alpha * lambda[c]) / (w + alpha);
                lambda[c] += change;
                self.position[a] += normal * (wa * change);
                self.position[b] -= normal * (wb * change);
            }
            for (i, lambda) in retention_lambda.iter_mut().enumerate() {
                let (Some(alpha), w) = (self.retention[i], self.inverse_mass[i]) else {
                    continue;
                };
                if w == 0.0 {
                    continue;
                }
                let target = new_pose.apply(self.rest_position[i]);
                let delta = self.position[i] - target;
                let length = delta.length();
                if length.is_nan() || length <= 1e-12 {
                    continue;
                }
                let alpha = alpha / dt2;
                let change = (-length - alpha * *lambda) / (w + alpha);
                *lambda += change;
                self.position[i] += delta / length * (w * change);
            }
            self.collide(old_pose, new_pose);
        }

        for i in 0..self.position.len() {
            let v = (self.position[i] - self.previous[i]) / dt;
            self.velocity[i] = if v.is_finite() {
                v.clamp_length_max(MAX_SPEED_M_PER_S)
            } else {
                DVec3::ZERO
            };
            if !self.position[i].is_finite() {
                // Never reached in the tests; a last guard so one bad value cannot spread.
                self.position[i] = self.previous[i];
            }
        }
    }

    /// Pushes particles out of the body along the field's gradient, with Coulomb friction on
    /// the body-relative motion of this sub-step.
    fn collide(&mut self, old_pose: RigidMotion, new_pose: RigidMotion) {
        if self.sdf.is_empty() {
            return;
        }
        let physics = &self.motion.physics;
        let margin = physics.collision_margin_m;
        for i in 0..self.position.len() {
            if self.inverse_mass[i] == 0.0 {
                continue;
            }
            let local = new_pose.inverse_apply(self.position[i]);
            let distance = self.sdf.distance_m(local);
            if distance.is_nan() || distance >= margin {
                continue;
            }
            let normal = self.sdf.gradient(local);
            let depth = margin - distance;
            let mut pushed = local + normal * depth;
            let before = old_pose.inverse_apply(self.previous[i]);
            let moved = pushed - before;
            let tangential = moved - normal * moved.dot(normal);
            let slide = tangential.length();
            if slide > 0.0 {
                let keep = (1.0 - physics.friction * depth / slide).max(0.0);
                pushed -= tangential * (1.0 - keep);
            }
            self.position[i] = new_pose.apply(pushed);
            self.stats.collisions += 1;
        }
    }

    /// The hair mesh as it is now: the modelled mesh with each simulated vertex moved, the
    /// rest (vertices of removed bundles) carried with the body. w keeps its modelled
    /// values, so the styling does not slide along a strand that bends.
    pub fn posed_mesh(&self) -> HairMesh {
        let mut mesh = self.rest.clone();
        for (c, column) in mesh.columns.iter_mut().enumerate() {
            let (start, len) = (self.column_start[c], self.column_len[c]);
            for (k, p) in column.positions.iter_mut().enumerate() {
                *p = if k < len {
                    self.position[start + k]
                } else {
                    self.pose.apply(*p)
                };
            }
        }
        mesh
    }

    /// The body in its current pose.
    pub fn posed_body(&self, body: &BodyMesh) -> BodyMesh {
        BodyMesh {
            positions: body
                .positions
                .iter()
                .map(|p| {
                    let q = self
                        .pose
                        .apply(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
                    q.as_vec3().to_array()
                })
                .collect(),
            triangles: body.triangles.clone(),
        }
    }

    /// Largest particle speed now.
    pub fn max_speed_m_per_s(&self) -> f64 {
        self.velocity.iter().map(|v| v.length()).fold(0.0, f64::max)
    }
}
