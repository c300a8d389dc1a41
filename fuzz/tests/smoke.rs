//! The fuzz smoke pass of `make test`: every committed seed (the crafted hostile cases
//! among them) and a bounded number of mutations of them, per target, with no panic.
//! `make fuzz` runs the same targets for minutes.

use std::time::Duration;

use hairloom_fuzz::{Budget, Target, corpus, corpus_dir, load_seeds, run};

/// Inputs per target: seconds on this 2-core machine in the test profile.
const SMOKE_INPUTS: u64 = 1500;

#[test]
fn the_committed_corpus_holds_every_crafted_case() {
    for target in Target::ALL {
        let committed = load_seeds(&corpus_dir(target));
        for (name, bytes) in corpus::seeds(target) {
            assert!(
                committed.contains(&bytes),
                "{}/{name} is missing or stale in fuzz/corpus: run `hairloom-fuzz seed`",
                target.name()
            );
        }
    }
}

#[test]
fn every_target_survives_its_corpus_and_a_bounded_mutation_pass() {
    for target in Target::ALL {
        let seeds = load_seeds(&corpus_dir(target));
        assert!(!seeds.is_empty(), "{} has no seeds", target.name());
        let report = run(
            target,
            &seeds,
            Budget {
                max_inputs: SMOKE_INPUTS,
                max_time: Duration::from_secs(20),
            },
            0x5eed,
        );
        println!("{report}");
        assert!(
            report.inputs >= seeds.len() as u64,
            "{}: not every seed ran",
            target.name()
        );
        if let Some((message, input)) = report.panics.first() {
            panic!(
                "{}: {} panics; first: {message} (input of {} bytes)",
                target.name(),
                report.panics.len(),
                input.len()
            );
        }
    }
}

#[test]
fn crafted_cases_are_named_errors() {
    // The crafted inputs are refused with a message, not merely "not a panic".
    use hairloom_core::io::import::{ImportOptions, import_slice};
    for (name, bytes) in corpus::seeds(Target::GltfImport) {
        if !name.starts_with("crafted_") || name.contains("node_cycle") {
            continue;
        }
        let error = import_slice(&bytes, None, &name, &ImportOptions::default())
            .expect_err(&name)
            .to_string();
        assert!(error.contains(&name), "{name}: {error}");
    }
}

#[test]
fn groom_seeds_read_and_crafted_grooms_are_named_errors() {
    // The valid grooms read (so the mutations start from files the readers take in, and
    // the target's checks run), and every crafted one is refused with a message.
    use hairloom_fuzz::targets::{check_groom, read_groom_input};
    for (name, bytes) in corpus::seeds(Target::GroomIn) {
        let read = read_groom_input(&bytes).expect(&name);
        if name.starts_with("crafted_") {
            let error = read.expect_err(&name).to_string();
            assert!(error.contains("fuzz."), "{name}: {error}");
        } else {
            let groom = read.unwrap_or_else(|e| panic!("{name}: {e}"));
            check_groom(&groom, hairloom_core::io::groom_in::GroomLimits::default());
        }
    }
}
