//! Hair that falls and moves: the hair mesh simulated on the CPU (seed 000 §3.4; Wu & Yuksel
//! 2016), only when the scene has motion.
//!
//! | file | what |
//! |---|---|
//! | [`body_sdf`] | the body's signed distance field, built once, for collision |
//! | [`wind`] | the wind field (mean flow, travelling gusts) |
//! | [`xpbd`] | [`HairSim`]: fixed-rate XPBD on the hair-mesh vertices |
//!
//! and [`drape`], the modelling tool that lets bundles fall onto the body as one edit.
//!
//! The strands follow the simulated mesh the way they follow any edit: the runtime textures
//! are rebuilt from [`HairSim::posed_mesh`], so the styling frames ride along (§3.4).

pub mod body_sdf;
pub mod wind;
pub mod xpbd;

pub use body_sdf::BodySdf;
pub use xpbd::HairSim;

use std::collections::BTreeSet;

use crate::edit::select::bundle_vertices_above_root;
use crate::edit::{EditError, EditOutcome, check_bundles};
use crate::model::document::{BodyMesh, Document};
use crate::model::mesh::{HairMesh, Topology, VertexRef};
use crate::model::motion::{HairPhysics, Motion, SimQuality};

/// Wall time a simulation for a seek, a render or an export may take before the user is
/// told, with the estimate, that it will be longer (`docs/resource-policy.md`): the work
/// then runs on with a progress bar and can be cancelled.
pub const SIMULATION_BUDGET_S: f64 = 10.0;

/// What simulating to a time will cost, measured on this machine before the work starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimulationEstimate {
    pub steps: u64,
    /// Wall time of one fixed step, measured on a copy of the simulation.
    pub step_s: f64,
}

impl SimulationEstimate {
    /// Times one fixed step of a copy of `sim` (the copy is dropped: `sim` does not move)
    /// and counts the steps a seek to `time_s` runs.
    pub fn measure(sim: &HairSim, time_s: f64) -> Self {
        let steps = sim.steps_to(time_s);
        let mut probe = sim.clone();
        let started = std::time::Instant::now();
        probe.step();
        Self {
            steps,
            step_s: started.elapsed().as_secs_f64(),
        }
    }

    pub fn seconds(&self) -> f64 {
        self.steps as f64 * self.step_s
    }

    pub fn over_budget(&self) -> bool {
        self.seconds() > SIMULATION_BUDGET_S
    }

    /// One line: the steps, the time they will take and, when that is over
    /// [`SIMULATION_BUDGET_S`], that it is.
    pub fn describe(&self, time_s: f64) -> String {
        let line = format!(
            "simulating to {time_s:.2} s: {} steps at {:.1} ms a step, about {}",
            self.steps,
            self.step_s * 1e3,
            duration_text(self.seconds())
        );
        if self.over_budget() {
            format!("{line} — over the {SIMULATION_BUDGET_S:.0} s budget (it can be cancelled)")
        } else {
            line
        }
    }
}

/// `3 h 5 min`, `4 min 10 s`, `12.3 s`.
pub fn duration_text(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "forever".into();
    }
    let whole = seconds.round() as u64;
    if whole >= 3600 {
        format!("{} h {} min", whole / 3600, (whole % 3600) / 60)
    } else if whole >= 60 {
        format!("{} min {} s", whole / 60, whole % 60)
    } else {
        format!("{seconds:.1} s")
    }
}

/// The longest simulated time a drape may take before it stops settling.
pub const DRAPE_MAX_S: f64 = 12.0;
/// The hair is at rest when no vertex moves faster than this for [`DRAPE_REST_STEPS`] steps.
pub const DRAPE_REST_SPEED_M_PER_S: f64 = 0.01;
pub const DRAPE_REST_STEPS: u32 = 15;
/// A drape is an edit, not a frame: it can afford the accuracy that keeps long columns from
/// stretching under their own weight (at the playback default of 2 × 2, a 60 cm column hangs
/// about 30% longer than modelled; `hairloom bench sim` measures the error by quality).
pub const DRAPE_QUALITY: SimQuality = SimQuality {
    rate_hz: 60.0,
    substeps: 4,
    iterations: 8,
};

/// How a drape went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrapeReport {
    pub simulated_s: f64,
    /// Whether the hair came to rest before [`DRAPE_MAX_S`].
    pub settled: bool,
    pub deepest_penetration_m: f64,
}

/// Lets `bundles` (every active bundle when empty) fall under gravity onto `body` and
/// settle, keeping `locked` vertices, the mesh's own locked vertices and every vertex of the
/// other bundles where they are; w is refreshed, so the result is one ordinary undo step.
///
/// Interior vertices keep their simulated places, and the drape locks the ones it moved:
/// the simulation held them at their modelled distances from their neighbours, while
/// re-placing them from each layer's rim would not (on a whole-scalp patch of long hair the
/// rim is the hairline, which hangs far from the crown's inner layers: re-placed crown
/// columns came out 1.5× their length). Unlocking them returns them to automatic
/// placement.
pub fn drape(
    mesh: &HairMesh,
    body: &BodyMesh,
    bundles: &[u32],
    locked: &[VertexRef],
) -> Result<(EditOutcome, DrapeReport), EditError> {
    let selected: BTreeSet<u32> = if bundles.is_empty() {
        (0..mesh.bundles.len() as u32)
            .filter(|&b| !mesh.bundles[b as usize].removed)
            .collect()
    } else {
        check_bundles(mesh, bundles)?;
        bundles.iter().copied().collect()
    };
    if selected.is_empty() {
        return Err(EditError::EmptySelection);
    }
    // Everything a bundle outside the selection uses stays put.
    let mut pinned: BTreeSet<VertexRef> = locked.iter().chain(&mesh.locked).copied().collect();
    for (b, bundle) in mesh.bundles.iter().enumerate() {
        if selected.contains(&(b as u32)) || bundle.removed {
            continue;
        }
        for &column in &bundle.vertices {
            for layer in 0..=bundle.layers {
                pinned.insert(VertexRef { column, layer });
            }
        }
    }
    let motion = Motion {
        physics: HairPhysics::drape(),
        quality: DRAPE_QUALITY,
        ..Motion::default()
    };
    let pinned: Vec<VertexRef> = pinned.into_iter().collect();
    let mut sim = HairSim::with_body(mesh, body, &motion, &pinned);
    let max_steps = (DRAPE_MAX_S / sim.step_s()).ceil() as u32;
    let mut still = 0;
    let mut settled = false;
    for _ in 0..max_steps {
        sim.step();
        still = if sim.max_speed_m_per_s() < DRAPE_REST_SPEED_M_PER_S {
            still + 1
        } else {
            0
        };
        if still >= DRAPE_REST_STEPS {
            settled = true;
            break;
        }
    }
    let report = DrapeReport {
        simulated_s: sim.time_s(),
        settled,
        deepest_penetration_m: sim.deepest_penetration_m(),
    };
    let mut draped = sim.posed_mesh();
    let topology = Topology::build(&draped);
    let settled_interior: Vec<VertexRef> = bundle_vertices_above_root(&draped, &selected)
        .into_iter()
        .filter(|v| {
            pinned.binary_search(v).is_err()
                && draped.is_interior(&topology, v.column as usize, v.layer as usize)
        })
        .collect();
    draped.set_locked(&settled_interior, true);
    draped.update_w();
    draped.validate()?;
    Ok((
        EditOutcome {
            mesh: draped,
            affected_bundles: selected.into_iter().collect(),
        },
        report,
    ))
}

/// A simulator for `document` moved by `motion` (the scene's, or one chosen for a command).
pub fn simulator(document: &Document, motion: &Motion) -> HairSim {
    HairSim::with_body(&document.hair_mesh, &document.body, motion, &[])
}

/// `document` as the simulation has it now: the posed hair mesh on the posed body. The
/// strands follow the way they follow any edit: the runtime asset is rebuilt from it.
pub fn posed_document(document: &Document, sim: &HairSim) -> Document {
    Document {
        hair_mesh: sim.posed_mesh(),
        body: sim.posed_body(&document.body),
        ..document.clone()
    }
}

#[cfg(test)]
mod tests;
