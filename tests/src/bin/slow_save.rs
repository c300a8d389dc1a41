//! Test helper: saves a large project to the given path through the real atomic writer,
//! pausing after every chunk and announcing it on stdout, so a test can kill it mid-write.
//!
//! Usage: `slow_save PATH PAUSE_MS`

use std::io::Write;

fn main() {
    let mut args = std::env::args().skip(1);
    let (Some(path), Some(pause)) = (args.next(), args.next()) else {
        eprintln!("usage: slow_save PATH PAUSE_MS");
        std::process::exit(2);
    };
    let pause_ms: u64 = pause.parse().unwrap_or(50);
    let mesh = hairloom_tests::grid_mesh(60, 60, 4, 0.1);
    let project = hairloom_core::Project::new(hairloom_core::Document::new("slow", mesh));
    let bytes = hairloom_core::io::project::to_bytes(&project);
    let result =
        hairloom_core::io::project::write_atomic(std::path::Path::new(&path), &bytes, |written| {
            println!("wrote {written} of {}", bytes.len());
            let _ = std::io::stdout().flush();
            std::thread::sleep(std::time::Duration::from_millis(pause_ms));
        });
    if let Err(error) = result {
        eprintln!("{error}");
        std::process::exit(1);
    }
}
