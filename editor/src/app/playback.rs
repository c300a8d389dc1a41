//! Playback of the scene's motion: the simulator stepped by the wall clock while Play is on,
//! and the posed document the viewport draws instead of the modelled one.
//!
//! View state: nothing here is saved or undone. A scene without motion never makes a
//! simulator, so nothing steps and the viewport uploads nothing per frame (tested).

use std::ops::ControlFlow;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use hairloom_core::Document;
use hairloom_core::simulate::{HairSim, SimulationEstimate, posed_document, simulator};

/// A seek that would take longer than this runs on a worker thread (with progress and
/// Cancel in the Scene panel) instead of in the UI frame.
pub const SEEK_ON_UI_THREAD_S: f64 = 0.05;

/// A seek simulating on a worker thread: the UI stays live, shows the progress and can
/// cancel it; the simulation it reaches replaces the shown one when it is done.
pub struct SeekJob {
    pub time_s: f64,
    /// The document revision the seek simulates (an edit meanwhile makes it stale).
    revision: u64,
    pub estimate: SimulationEstimate,
    steps_done: Arc<AtomicU64>,
    cancel: Arc<AtomicBool>,
    result: mpsc::Receiver<HairSim>,
}

impl SeekJob {
    fn start(mut sim: HairSim, revision: u64, time_s: f64, estimate: SimulationEstimate) -> Self {
        let steps_done = Arc::new(AtomicU64::new(0));
        let cancel = Arc::new(AtomicBool::new(false));
        let (sender, result) = mpsc::channel();
        let (done, stop) = (steps_done.clone(), cancel.clone());
        std::thread::spawn(move || {
            sim.seek_with(time_s, &mut |steps, _| {
                done.store(steps, Ordering::Relaxed);
                if stop.load(Ordering::Relaxed) {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            });
            if !stop.load(Ordering::Relaxed) {
                let _ = sender.send(sim);
            }
        });
        Self {
            time_s,
            revision,
            estimate,
            steps_done,
            cancel,
            result,
        }
    }

    /// Fraction of the steps simulated so far.
    pub fn fraction(&self) -> f32 {
        let done = self.steps_done.load(Ordering::Relaxed);
        (done as f64 / self.estimate.steps.max(1) as f64).min(1.0) as f32
    }

    /// Wall time left at the measured cost of a step.
    pub fn seconds_left(&self) -> f64 {
        let done = self.steps_done.load(Ordering::Relaxed);
        self.estimate.steps.saturating_sub(done) as f64 * self.estimate.step_s
    }

    /// Stops the worker after its current step (its result is dropped).
    fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
}

impl Drop for SeekJob {
    fn drop(&mut self) {
        self.cancel();
    }
}

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
    /// A seek simulating on a worker thread.
    pub seeking: Option<SeekJob>,
    /// Seeks estimated to take longer than this run on a worker
    /// ([`SEEK_ON_UI_THREAD_S`]; tests set 0 to send every seek there).
    pub ui_thread_budget_s: Option<f64>,
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
        self.seeking = None;
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
        if let Some(job) = &self.seeking {
            if job.revision != revision || self.playing {
                // An edit or Play since: the seek's result would be stale.
                self.seeking = None;
            } else {
                match job.result.try_recv() {
                    Ok(sim) => {
                        self.steps += job.estimate.steps;
                        self.sim = Some((revision, sim));
                        self.seeking = None;
                        self.pose(document, revision);
                        // The new pose is to be drawn.
                        return true;
                    }
                    Err(mpsc::TryRecvError::Empty) => return true,
                    Err(mpsc::TryRecvError::Disconnected) => self.seeking = None,
                }
            }
        }
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
    /// A seek that would take longer than the UI-thread budget runs on a worker thread
    /// ([`Self::seeking`]), and its estimate is returned so the editor can say what it
    /// costs before it runs; a shorter one is done at once.
    pub fn seek(
        &mut self,
        document: &Document,
        revision: u64,
        time_s: f64,
    ) -> Option<SimulationEstimate> {
        self.seeking = None;
        let budget_s = self.ui_thread_budget_s.unwrap_or(SEEK_ON_UI_THREAD_S);
        let known_step_s = self.step_ms.map(|ms| ms * 1e-3);
        let sim = self.simulator(document, revision)?;
        let steps = sim.steps_to(time_s);
        if steps == 0 {
            sim.seek(time_s);
            self.pose(document, revision);
            return None;
        }
        let estimate = match known_step_s {
            Some(step_s) => SimulationEstimate { steps, step_s },
            None => SimulationEstimate::measure(sim, time_s),
        };
        if estimate.seconds() <= budget_s {
            self.steps += sim.seek(time_s);
            self.pose(document, revision);
            return None;
        }
        self.seeking = Some(SeekJob::start(sim.clone(), revision, time_s, estimate));
        Some(estimate)
    }

    /// Stops a running seek; what is shown stays as it was.
    pub fn cancel_seek(&mut self) {
        self.seeking = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hairloom_core::model::motion::Motion;

    fn moving_document() -> Document {
        let mut document = hairloom_core::Document::new(
            "grid",
            hairloom_core::samples::straight_layers(
                hairloom_core::samples::grid_scalp(4, 4, |s, t| glam::DVec3::new(s, t, 0.0)),
                3,
                glam::DVec3::Z * 0.05,
            ),
        );
        document.scene.motion = Some(Motion::head_turn(0.3, 0.6, 70.0));
        document
    }

    /// Issue "Nothing lost, nothing blocked": a long seek ran on the UI thread (600 s at the
    /// highest accuracy froze the editor for minutes). It now runs on a worker, the UI
    /// polls its progress, and Cancel leaves the shown motion where it was.
    #[test]
    fn a_long_seek_runs_on_a_worker_and_can_be_cancelled() {
        let document = moving_document();
        let mut playback = Playback {
            ui_thread_budget_s: Some(0.0),
            ..Playback::default()
        };
        let estimate = playback
            .seek(&document, 1, 2.0)
            .expect("over the budget: a worker, with the estimate");
        assert_eq!(estimate.steps, 120, "2 s at 60 Hz");
        assert!(estimate.step_s > 0.0 && estimate.seconds() > 0.0);
        assert!(playback.seeking.is_some());
        assert_eq!(
            playback.time_s(),
            0.0,
            "nothing moves until the worker is done"
        );
        let started = Instant::now();
        while playback.seeking.is_some() {
            assert!(playback.tick(&document, 1, 0.0), "frames while it runs");
            assert!(
                started.elapsed().as_secs() < 120,
                "the worker did not finish"
            );
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert!((playback.time_s() - 2.0).abs() < 1e-9);
        assert!(playback.is_posed());
        // A cancelled seek leaves what is shown.
        playback.seek(&document, 1, 30.0).expect("a worker again");
        assert!(
            playback
                .seeking
                .as_ref()
                .is_some_and(|j| j.fraction() < 1.0)
        );
        playback.cancel_seek();
        assert!(playback.seeking.is_none());
        playback.tick(&document, 1, 0.0);
        assert!((playback.time_s() - 2.0).abs() < 1e-9);
        // An edit (a new revision) makes a running seek stale: it is dropped.
        playback.seek(&document, 1, 30.0).expect("a worker again");
        playback.tick(&document, 2, 0.0);
        assert!(playback.seeking.is_none());
    }

    #[test]
    fn a_short_seek_is_done_at_once() {
        let document = moving_document();
        let mut playback = Playback::default();
        // A step costs far less than the UI-thread budget here: two steps need no worker.
        assert!(playback.seek(&document, 1, 2.0 / 60.0).is_none());
        assert!(playback.seeking.is_none());
        assert!((playback.time_s() - 2.0 / 60.0).abs() < 1e-9);
    }
}
