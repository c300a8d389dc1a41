//! Fuzzing Hairloom's inputs on the stable toolchain.
//!
//! Each [`Target`] feeds bytes to one reader: project files, glTF import, runtime bundles
//! and KTX2 textures. [`run`] replays a seed corpus through a target, then mutates it
//! ([`mutate`]: byte- and JSON-aware mutations, splicing between seeds) for a budget of
//! inputs or seconds, catching panics and recording the slowest input. `make fuzz` runs
//! each target for a set time (the `hairloom-fuzz` binary); `make test` runs a bounded
//! smoke pass over the committed corpus (`fuzz/corpus/`, written by `hairloom-fuzz seed`),
//! which holds every crafted hostile case the issue found.
//!
//! Why not libFuzzer: cargo-fuzz needs a nightly toolchain, and `make test` must run on a
//! fresh machine with stable Rust only. The targets are plain `fn(&[u8])`, so a
//! coverage-guided engine can drive the same functions where nightly exists.

pub mod corpus;
pub mod mutate;
pub mod targets;

use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use targets::Target;

/// How long one fuzzing run may go on.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    pub max_inputs: u64,
    pub max_time: Duration,
}

/// What a run did.
#[derive(Debug)]
pub struct Report {
    pub target: Target,
    /// Inputs run, seeds included.
    pub inputs: u64,
    pub seeds: usize,
    pub elapsed: Duration,
    /// Panics found: (message, input).
    pub panics: Vec<(String, Vec<u8>)>,
    /// The slowest input and its time.
    pub slowest: Duration,
}

impl std::fmt::Display for Report {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let seconds = self.elapsed.as_secs_f64();
        write!(
            f,
            "{:<16} {:>9} inputs ({} seeds) in {:>6.1} s ({:>7.0}/s), {} panics, slowest input {:.1} ms",
            self.target.name(),
            self.inputs,
            self.seeds,
            seconds,
            self.inputs as f64 / seconds.max(1e-9),
            self.panics.len(),
            self.slowest.as_secs_f64() * 1e3
        )
    }
}

/// The committed seed corpus folder of `target`.
pub fn corpus_dir(target: Target) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("corpus")
        .join(target.name())
}

/// The seeds in `dir`, sorted by name (empty when the folder is missing).
pub fn load_seeds(dir: &Path) -> Vec<Vec<u8>> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|entries| entries.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    paths.sort();
    paths.iter().filter_map(|p| std::fs::read(p).ok()).collect()
}

/// Runs every seed through `target`, then mutated seeds until `budget` is spent. Panics
/// are caught and reported (the panic message is captured, not printed).
pub fn run(target: Target, seeds: &[Vec<u8>], budget: Budget, rng_seed: u64) -> Report {
    let mut rng = fastrand::Rng::with_seed(rng_seed);
    let started = Instant::now();
    let mut report = Report {
        target,
        inputs: 0,
        seeds: seeds.len(),
        elapsed: Duration::ZERO,
        panics: Vec::new(),
        slowest: Duration::ZERO,
    };
    let message = std::sync::Arc::new(std::sync::Mutex::new(String::new()));
    let previous_hook = std::panic::take_hook();
    {
        let message = message.clone();
        std::panic::set_hook(Box::new(move |info| {
            if let Ok(mut slot) = message.lock() {
                *slot = format!("{info}");
            }
        }));
    }
    // An abort (stack overflow, out of memory) cannot be caught: with this set, each input
    // is written there before it runs, so the one that killed the process is left behind.
    let current = std::env::var_os("HAIRLOOM_FUZZ_CURRENT").map(PathBuf::from);
    let one = |input: &[u8], report: &mut Report| {
        if let Some(path) = &current {
            let _ = std::fs::write(path, input);
        }
        let start = Instant::now();
        let result = std::panic::catch_unwind(AssertUnwindSafe(|| target.run(input)));
        report.slowest = report.slowest.max(start.elapsed());
        report.inputs += 1;
        if result.is_err() {
            let text = message.lock().map(|m| m.clone()).unwrap_or_default();
            report.panics.push((text, input.to_vec()));
        }
    };
    for seed in seeds {
        one(seed, &mut report);
    }
    if !seeds.is_empty() {
        while report.inputs < budget.max_inputs && started.elapsed() < budget.max_time {
            let input = mutate::mutate(&mut rng, seeds);
            one(&input, &mut report);
        }
    }
    std::panic::set_hook(previous_hook);
    report.elapsed = started.elapsed();
    report
}
