//! Test helper: writes the runtime bundle of [`hairloom_tests::bundle_variant`] `VARIANT`
//! into `DIR` through the real folder writer, pausing after every file and announcing it on
//! stdout, so a test can kill it at each point of an export over an existing bundle.
//!
//! Usage: `slow_bundle DIR VARIANT PAUSE_MS`

use std::io::Write;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [dir, variant, pause] = args.as_slice() else {
        eprintln!("usage: slow_bundle DIR VARIANT PAUSE_MS");
        std::process::exit(2);
    };
    let variant: u32 = variant.parse().unwrap_or(0);
    let pause_ms: u64 = pause.parse().unwrap_or(50);
    let files = hairloom_tests::bundle_variant_files(variant);
    let result = hairloom_core::io::runtime_bundle::write_bundle_folder(
        std::path::Path::new(dir),
        &files,
        |name| {
            println!("wrote {name}");
            let _ = std::io::stdout().flush();
            std::thread::sleep(std::time::Duration::from_millis(pause_ms));
        },
    );
    if let Err(error) = result {
        eprintln!("{error}");
        std::process::exit(1);
    }
}
