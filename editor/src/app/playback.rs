//! Playback of the scene's motion: the simulator stepped by the wall clock while Play is on,
//! and the posed document the viewport draws instead of the modelled one.
//!
//! View state: nothing here is saved or undone. A scene without motion never makes a
//! simulator, so nothing steps and the viewport uploads nothing per frame (tested).

use std::time::Instant;

use hairloom_core::Document;
use hairloom_core::simulate::{HairSim, posed_document, simulator};

#[derive(Default)]
pub struct Playback {
    pub playing: bool,
    /// The simulator and the document revision it was made from.
    sim: Option<(u64, HairSim)>,
    /// The posed document, and the document revision it was posed from.
    posed: Option<(u64, Document)>,
    /// A fresh number whenever the posed document changes: the viewport re-uploads then,
    /// and only then.
    pub pose_revision: u64,
    /// Fixed steps taken since the editor opened.
    pub steps: u64,
    /// Wall-clock time of the previous tick while playing.
    last_tick_s: Option<f64>,
    /// CPU time per fixed step, smoothed.
    pub step_ms: Option<f64>,
}

impl Playback {
    /// What the viewport draws: the posed document while one exists for `revision`.
    pub fn shown<'a>(&'a self, document: &'a Document, revision: u64) -> &'a Document {
        match &self.posed {
            Some((posed_from, posed)) if *posed_from == revision => posed,
            _ => document,
        }
    }

    /// A number that changes whenever [`Self::shown`] does.
    pub fn shown_revision(&self, revision: u64) -> u64 {
        match &self.posed {
            Some((posed_from, _)) if *posed_from == revision => self.pose_revision,
            _ => revision,
        }
    }

    /// Simulated time of what is shown.
    pub fn time_s(&self) -> f64 {
        self.sim.as_ref().map_or(0.0, |(_, sim)| sim.time_s())
    }

    pub fn is_posed(&self) -> bool {
        self.posed.is_some()
    }

    /// Back to the modelled shape at time 0.
    pub fn reset(&mut self) {
        self.playing = false;
        self.sim = None;
        if self.posed.take().is_some() {
            self.pose_revision = super::state::next_revision();
        }
        self.last_tick_s = None;
    }

    /// The simulator for `document` at `revision`, made when missing or stale (an edit
    /// starts the motion again from the new shape).
    fn simulator(&mut self, document: &Document, revision: u64) -> Option<&mut HairSim> {
        let motion = document.scene.motion.as_ref()?;
        if self
            .sim
            .as_ref()
            .is_none_or(|(made_at, _)| *made_at != revision)
        {
            self.sim = Some((revision, simulator(document, motion)));
        }
        self.sim.as_mut().map(|(_, sim)| sim)
    }

    fn pose(&mut self, document: &Document, revision: u64) {
        if let Some((_, sim)) = &self.sim {
            self.posed = Some((revision, posed_document(document, sim)));
            self.pose_revision = super::state::next_revision();
        }
    }

    /// Called once per UI frame: while playing, simulates the wall-clock time since the last
    /// frame. Returns whether another frame is wanted.
    pub fn tick(&mut self, document: &Document, revision: u64, now_s: f64) -> bool {
        if document.scene.motion.is_none() {
            if self.sim.is_some() || self.posed.is_some() {
                self.reset();
            }
            return false;
        }
        if !self.playing {
            self.last_tick_s = None;
            return false;
        }
        let frame_s = self.last_tick_s.map_or(0.0, |last| now_s - last);
        self.last_tick_s = Some(now_s);
        let Some(sim) = self.simulator(document, revision) else {
            return false;
        };
        let started = Instant::now();
        let taken = sim.advance(frame_s);
        if taken > 0 {
            let ms = started.elapsed().as_secs_f64() * 1e3 / taken as f64;
            self.step_ms = Some(self.step_ms.map_or(ms, |old| 0.8 * old + 0.2 * ms));
            self.steps += taken as u64;
            self.pose(document, revision);
        }
        true
    }

    /// Shows the motion at `time_s` (simulating from the start when it lies in the past).
    pub fn seek(&mut self, document: &Document, revision: u64, time_s: f64) {
        let Some(sim) = self.simulator(document, revision) else {
            return;
        };
        self.steps += sim.seek(time_s);
        self.pose(document, revision);
    }
}
