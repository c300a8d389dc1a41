//! `hairloom-fuzz`: runs the fuzz targets on the stable toolchain.
//!
//! ```text
//! hairloom-fuzz run [TARGET|all] [--seconds N] [--inputs N] [--seed N]
//! hairloom-fuzz seed      # (re)writes the crafted and valid seeds into fuzz/corpus/
//! ```
//!
//! A panic saves its input under `fuzz/artifacts/<target>/` and makes the exit status 1.

use std::time::Duration;

use hairloom_fuzz::{Budget, Target, corpus, corpus_dir, load_seeds, run};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let code = match args.first().map(String::as_str) {
        Some("seed") => seed(),
        Some("run") => fuzz(&args[1..]),
        _ => {
            eprintln!(
                "usage: hairloom-fuzz run [TARGET|all] [--seconds N] [--inputs N] [--seed N]\n       hairloom-fuzz seed\ntargets: {}",
                Target::ALL.map(Target::name).join(", ")
            );
            2
        }
    };
    std::process::exit(code);
}

fn seed() -> i32 {
    for target in Target::ALL {
        let dir = corpus_dir(target);
        if let Err(error) = std::fs::create_dir_all(&dir) {
            eprintln!("{}: {error}", dir.display());
            return 1;
        }
        let seeds = corpus::seeds(target);
        for (name, bytes) in &seeds {
            if let Err(error) = std::fs::write(dir.join(name), bytes) {
                eprintln!("{}: {error}", dir.join(name).display());
                return 1;
            }
        }
        println!(
            "{}: {} seeds in {}",
            target.name(),
            seeds.len(),
            dir.display()
        );
    }
    0
}

fn fuzz(args: &[String]) -> i32 {
    let mut targets = Target::ALL.to_vec();
    let mut budget = Budget {
        max_inputs: u64::MAX,
        max_time: Duration::from_secs(60),
    };
    let mut rng_seed = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(1, |d| d.as_nanos() as u64);
    let mut rest = args.iter();
    while let Some(arg) = rest.next() {
        let mut number = || rest.next().and_then(|v| v.parse::<u64>().ok());
        match arg.as_str() {
            "all" => targets = Target::ALL.to_vec(),
            "--seconds" => match number() {
                Some(n) => budget.max_time = Duration::from_secs(n),
                None => return usage("--seconds needs a number"),
            },
            "--inputs" => match number() {
                Some(n) => budget.max_inputs = n,
                None => return usage("--inputs needs a number"),
            },
            "--seed" => match number() {
                Some(n) => rng_seed = n,
                None => return usage("--seed needs a number"),
            },
            name => match Target::from_name(name) {
                Some(target) => targets = vec![target],
                None => return usage(&format!("no target named {name}")),
            },
        }
    }
    println!("mutation seed {rng_seed}");
    let mut failed = false;
    for target in targets {
        let seeds = load_seeds(&corpus_dir(target));
        let report = run(target, &seeds, budget, rng_seed);
        println!("{report}");
        for (i, (message, input)) in report.panics.iter().enumerate().take(10) {
            failed = true;
            let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("artifacts")
                .join(target.name());
            let path = dir.join(format!("panic-{rng_seed}-{i}"));
            let saved = std::fs::create_dir_all(&dir).and_then(|()| std::fs::write(&path, input));
            match saved {
                Ok(()) => println!("  panic: {message}\n  input: {}", path.display()),
                Err(error) => println!("  panic: {message}\n  (could not save the input: {error})"),
            }
        }
    }
    i32::from(failed)
}

fn usage(message: &str) -> i32 {
    eprintln!("hairloom-fuzz: {message}");
    2
}
