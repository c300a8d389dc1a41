//! A progress bar on a terminal's standard error, redrawn in place (logs and pipes get
//! nothing), shared by the command line's long jobs: strand generation and simulation.

use std::io::{IsTerminal, Write};

pub struct TerminalProgress {
    label: &'static str,
    shown: bool,
    last_percent: Option<usize>,
}

impl TerminalProgress {
    /// A bar labelled `label`, drawn only when standard error is a terminal.
    pub fn new(label: &'static str) -> Self {
        Self {
            label,
            shown: std::io::stderr().is_terminal(),
            last_percent: None,
        }
    }

    /// Redraws the bar at `fraction` (0 to 1) when its whole percentage changed.
    pub fn update(&mut self, fraction: f64) {
        let percent = (fraction.clamp(0.0, 1.0) * 100.0) as usize;
        if !self.shown || self.last_percent == Some(percent) {
            return;
        }
        let filled = percent / 5;
        let _ = write!(
            std::io::stderr(),
            "\r{} [{}{}] {percent:>3}%",
            self.label,
            "#".repeat(filled),
            " ".repeat(20 - filled)
        );
        self.last_percent = Some(percent);
    }

    /// Ends the bar's line (when one was drawn).
    pub fn finish(self) {
        if self.shown && self.last_percent.is_some() {
            let _ = writeln!(std::io::stderr());
        }
    }
}

/// Simulates `sim` to `time_s`, first saying on standard error what it will cost when that
/// is more than a second (measured on a copy: see `SimulationEstimate`), with a progress bar
/// on a terminal. Returns the steps run.
pub fn seek_with_progress(sim: &mut hairloom_core::simulate::HairSim, time_s: f64) -> u64 {
    use hairloom_core::simulate::SimulationEstimate;
    let estimate = SimulationEstimate::measure(sim, time_s);
    if estimate.seconds() > 1.0 {
        eprintln!("{}", estimate.describe(time_s));
    }
    let mut bar = TerminalProgress::new("simulating");
    let ran = sim.seek_with(time_s, &mut |done, total| {
        bar.update(done as f64 / total.max(1) as f64);
        std::ops::ControlFlow::Continue(())
    });
    bar.finish();
    ran
}
