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
use std::ops::ControlFlow;

use glam::DVec3;

use crate::model::document::BodyMesh;
use crate::model::mesh::{HairMesh, VertexRef};
use crate::model::motion::{Motion, RigidMotion};
use crate::simulate::body_sdf::BodySdf;
use crate::simulate::wind::wind_velocity;

/// Frame time above which the simulator drops time instead of catching up (a stalled
/// frame must not trigger a burst of steps).
pub const MAX_FRAME_S: f64 = 0.25;
/// The most fixed steps one frame may take; time beyond them is dropped (a slow machine
/// plays slower instead of falling further behind with every frame).
pub const MAX_STEPS_PER_FRAME: u32 = 16;
/// Layers above which the hair's volume stops adding clearance from the body: volume is how
/// thick hair lies on the head, which a long strand's tip does not add to.
pub const VOLUME_LAYERS: usize = 4;
/// The head moving faster than this between two sub-steps is a cut (teleport), not motion:
/// the hair is carried with it rigidly instead of being yanked.
pub const TELEPORT_SPEED_M_PER_S: f64 = 10.0;
pub const TELEPORT_TURN_RAD_PER_S: f64 = 4.0 * std::f64::consts::PI;
/// A safety net, far above anything hair does: no particle moves faster.
pub const MAX_SPEED_M_PER_S: f64 = 500.0;

/// XPBD compliance of a stiffness in `[0, 1]`.
pub(crate) fn compliance(stiffness: f64) -> f64 {
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

/// Orders constraints by a greedy colouring: within a colour no two share a particle, so
/// consecutive projections do not wait on each other's results and the CPU overlaps their
/// square roots and divisions (the Gauss-Seidel loop is latency-bound otherwise). The order
/// is fixed by the input's, so results stay deterministic.
fn by_colour(constraints: Vec<Distance>, particles: usize) -> Vec<Distance> {
    let mut used = vec![0u64; particles];
    let mut colours: Vec<Vec<Distance>> = Vec::new();
    let mut overflow = Vec::new();
    for constraint in constraints {
        let (a, b) = (constraint.a as usize, constraint.b as usize);
        let free = !(used[a] | used[b]);
        if free == 0 {
            overflow.push(constraint); // more than 64 colours: a pathological vertex
            continue;
        }
        let colour = free.trailing_zeros() as usize;
        used[a] |= 1 << colour;
        used[b] |= 1 << colour;
        if colours.len() <= colour {
            colours.resize_with(colour + 1, Vec::new);
        }
        colours[colour].push(constraint);
    }
    colours.into_iter().flatten().chain(overflow).collect()
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
    /// Distance each particle keeps from the body: the margin plus its layer's volume.
    clearance_m: Vec<f64>,
    constraints: Vec<Distance>,
    pose: RigidMotion,
    /// Buffers reused by every sub-step (no allocation per step).
    lambda_scratch: Vec<f64>,
    retention_lambda_scratch: Vec<f64>,
    target_scratch: Vec<DVec3>,
    /// The air's velocity at each particle for the current step (empty without wind).
    wind_scratch: Vec<DVec3>,
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
        let mut clearance_m = Vec::new();
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
                clearance_m.push(
                    physics.collision_margin_m
                        + physics.volume_m_per_layer * k.min(VOLUME_LAYERS) as f64,
                );
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
        let constraints: Vec<Distance> = edges
            .into_iter()
            .map(|((a, b), kind)| Distance {
                a,
                b,
                rest_m: rest_position[a as usize].distance(rest_position[b as usize]),
                kind,
            })
            .filter(|d| d.rest_m.is_finite())
            .collect();
        let constraints = by_colour(constraints, rest_position.len());
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
            clearance_m,
            constraints,
            pose,
            lambda_scratch: Vec::new(),
            retention_lambda_scratch: Vec::new(),
            target_scratch: Vec::new(),
            wind_scratch: Vec::new(),
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
        Self::new(mesh, BodySdf::for_hair(body, mesh), motion, pinned)
    }

    pub fn particle_count(&self) -> usize {
        self.position.len()
    }

    pub fn constraint_count(&self) -> usize {
        self.constraints.len()
    }

    /// Bytes the simulator holds (particles, constraints, the modelled mesh; the body's
    /// field counted apart, see [`BodySdf::memory_bytes`]).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        let particles = self.position.len()
            * (4 * size_of::<DVec3>() + size_of::<f64>() + size_of::<Option<f64>>());
        let constraints = self.constraints.len() * size_of::<Distance>();
        let mesh: usize = self
            .rest
            .columns
            .iter()
            .map(|c| c.positions.len() * (size_of::<DVec3>() + size_of::<f64>()))
            .sum();
        particles + constraints + mesh
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
    /// Pinned vertices (the roots on the scalp) are left out: they sit on the surface by
    /// construction.
    pub fn deepest_penetration_m(&self) -> f64 {
        self.position
            .iter()
            .zip(&self.inverse_mass)
            .filter(|(_, w)| **w > 0.0)
            .map(|(&p, _)| -self.sdf.distance_m(self.pose.inverse_apply(p)))
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
            if taken == MAX_STEPS_PER_FRAME {
                self.accumulator_s = 0.0;
                break;
            }
            self.step();
            self.accumulator_s -= step_s;
            taken += 1;
        }
        self.accumulator_s = self.accumulator_s.max(0.0);
        taken
    }

    /// Runs (from the start if `time_s` is in the past) until the simulated time reaches
    /// `time_s`, rounded to whole steps. For scrubbing and `render --time`. Returns the
    /// steps it ran.
    pub fn seek(&mut self, time_s: f64) -> u64 {
        self.seek_with(time_s, &mut |_, _| ControlFlow::Continue(()))
    }

    /// The fixed steps [`Self::seek`] to `time_s` would run from here (from the start when
    /// `time_s` is in the past).
    pub fn steps_to(&self, time_s: f64) -> u64 {
        let target = self.target_step(time_s);
        if target < self.steps {
            target
        } else {
            target - self.steps
        }
    }

    fn target_step(&self, time_s: f64) -> u64 {
        if time_s.is_finite() {
            (time_s.max(0.0) / self.step_s()).round() as u64
        } else {
            0
        }
    }

    /// [`Self::seek`], telling `progress(steps_run, steps_to_run)` after every fixed step;
    /// `ControlFlow::Break` stops it there (the simulation is then at the step reached, a
    /// valid state that a later seek continues from). Returns the steps it ran.
    pub fn seek_with(
        &mut self,
        time_s: f64,
        progress: &mut dyn FnMut(u64, u64) -> ControlFlow<()>,
    ) -> u64 {
        let target = self.target_step(time_s);
        let total = self.steps_to(time_s);
        if target < self.steps {
            *self = Self::new(&self.rest, self.sdf.clone(), &self.motion, &self.pinned);
        }
        let mut ran = 0;
        while self.steps < target {
            self.step();
            ran += 1;
            if progress(ran, total).is_break() {
                break;
            }
        }
        self.accumulator_s = 0.0;
        ran
    }

    /// One fixed step: `substeps` predictions, each followed by `iterations` projections.
    pub fn step(&mut self) {
        let quality = self.motion.quality.clone();
        let substeps = quality.substeps.max(1);
        let dt = self.step_s() / substeps as f64;
        // The air at the middle of the step, once per step: gusts change over tenths of a
        // second, sub-steps over milliseconds.
        let mut wind = std::mem::take(&mut self.wind_scratch);
        wind.clear();
        if self.motion.wind.speed_m_per_s > 0.0 {
            let time_s = self.time_s() + 0.5 * self.step_s();
            wind.extend(
                self.position
                    .iter()
                    .map(|&p| wind_velocity(&self.motion.wind, p, time_s)),
            );
        }
        self.wind_scratch = wind;
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
        let cut = moved > TELEPORT_SPEED_M_PER_S * dt || turn > TELEPORT_TURN_RAD_PER_S * dt;
        if cut {
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
            let air = self.wind_scratch.get(i).copied().unwrap_or(DVec3::ZERO);
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
        // 1 / (w_a + w_b + α̃) by kind and by how many ends move (particles have unit or zero
        // inverse mass): no division in the constraint loop but the one for the direction.
        let inverse_denominator = stiffness.map(|alpha| [1.0 / (1.0 + alpha), 1.0 / (2.0 + alpha)]);
        let mut lambda = std::mem::take(&mut self.lambda_scratch);
        lambda.clear();
        lambda.resize(self.constraints.len(), 0.0);
        let mut targets = std::mem::take(&mut self.target_scratch);
        targets.clear();
        targets.extend(self.rest_position.iter().map(|&p| new_pose.apply(p)));
        let mut retention_lambda = std::mem::take(&mut self.retention_lambda_scratch);
        retention_lambda.clear();
        retention_lambda.resize(self.position.len(), 0.0);
        for iteration in 0..iterations {
            for (constraint, lambda) in self.constraints.iter().zip(lambda.iter_mut()) {
                let (a, b) = (constraint.a as usize, constraint.b as usize);
                let (wa, wb) = (self.inverse_mass[a], self.inverse_mass[b]);
                let w = wa + wb;
                if w == 0.0 {
                    continue;
                }
                let delta = self.position[a] - self.position[b];
                let length_squared = delta.length_squared();
                if length_squared.is_nan() || length_squared <= 1e-24 {
                    continue; // coincident: no direction to push along
                }
                let length = length_squared.sqrt();
                let kind = constraint.kind as usize;
                let alpha = stiffness[kind];
                let inverse = if w == 1.0 {
                    inverse_denominator[kind][0]
                } else if w == 2.0 {
                    inverse_denominator[kind][1]
                } else {
                    1.0 / (w + alpha)
                };
                let change = (constraint.rest_m - length - alpha * *lambda) * inverse;
                *lambda += change;
                // The unit direction folded into one scale: one division per constraint.
                let scale = change / length;
                self.position[a] += delta * (wa * scale);
                self.position[b] -= delta * (wb * scale);
            }
            for (i, lambda) in retention_lambda.iter_mut().enumerate() {
                let (Some(alpha), w) = (self.retention[i], self.inverse_mass[i]) else {
                    continue;
                };
                if w == 0.0 {
                    continue;
                }
                let delta = self.position[i] - targets[i];
                let length_squared = delta.length_squared();
                if length_squared.is_nan() || length_squared <= 1e-24 {
                    continue;
                }
                let length = length_squared.sqrt();
                let alpha = alpha / dt2;
                let change = (-length - alpha * *lambda) / (w + alpha);
                *lambda += change;
                self.position[i] += delta * (w * change / length);
            }
            // Collisions are projected last, once per sub-step: nothing moves a particle
            // after them, and each costs a field lookup.
            if iteration + 1 == iterations {
                // After a cut the previous positions were carried too: they are in the new
                // pose's frame.
                self.collide(if cut { new_pose } else { old_pose }, new_pose);
            }
        }
        self.lambda_scratch = lambda;
        self.target_scratch = targets;
        self.retention_lambda_scratch = retention_lambda;

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
        for i in 0..self.position.len() {
            if self.inverse_mass[i] == 0.0 {
                continue;
            }
            let margin = self.clearance_m[i];
            let local = new_pose.inverse_apply(self.position[i]);
            let (distance, normal) = self.sdf.distance_and_gradient(local);
            if distance.is_nan() || distance >= margin {
                continue;
            }
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
