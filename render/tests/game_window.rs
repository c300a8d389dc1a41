//! `cargo run --example game` in a real window: the example (a plain winit + wgpu program
//! using only `hairloom_render::game`) opens on Xvfb, draws a few frames of the bundled
//! sample and exits cleanly, saying what it drew. (`tests/game.rs` checks the picture.)
//!
//! Needs Xvfb (Debian: xvfb), which `make test` installs, and the example built as a program
//! (`cargo build -p hairloom-render --example game`, which `make test` runs first: `cargo test
//! --all-targets` builds examples only as test harnesses); without either the test is skipped
//! unless HAIRLOOM_REQUIRE_DISPLAY=1 (set by `make test`).

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

struct KillOnDrop(Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn example_binary() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target"));
    // This test binary lives in <target>/<profile>/deps; the example in <target>/<profile>/examples.
    let profile = std::env::current_exe()
        .ok()
        .and_then(|exe| {
            exe.parent()?
                .parent()?
                .file_name()
                .map(|p| p.to_string_lossy().into_owned())
        })
        .unwrap_or_else(|| "debug".into());
    target.join(profile).join("examples/game")
}

#[test]
fn the_game_example_draws_in_a_window() {
    let required = std::env::var("HAIRLOOM_REQUIRE_DISPLAY").as_deref() == Ok("1");
    let binary = example_binary();
    let have_xvfb = Command::new("sh")
        .args(["-c", "command -v Xvfb"])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !have_xvfb || !binary.exists() {
        assert!(
            !required,
            "needs Xvfb (apt-get install xvfb) and the example built at {} (cargo build -p hairloom-render --example game)",
            binary.display()
        );
        eprintln!("skipped: Xvfb or {} missing", binary.display());
        return;
    }
    let display = format!(":{}", 190 + std::process::id() % 100);
    let _xvfb = KillOnDrop(
        Command::new("Xvfb")
            .args([
                display.as_str(),
                "-screen",
                "0",
                "800x600x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("start Xvfb"),
    );
    std::thread::sleep(Duration::from_millis(800));
    let runtime_dir = std::env::temp_dir().join("hairloom-runtime");
    let _ = std::fs::create_dir_all(&runtime_dir);
    let output = Command::new(&binary)
        .args(["--frames", "3"])
        .env("DISPLAY", &display)
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_RUNTIME_DIR", &runtime_dir)
        .output()
        .expect("run the example");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success()
        && stderr.contains("no GPU adapter")
        && hairloom_render::device::skip_test_without_gpu("game example", &stderr)
    {
        return;
    }
    assert!(output.status.success(), "{stdout}{stderr}");
    eprintln!("{stdout}");
    // "3 frames in …; last frame: N strands, M vertices, …" with N > 0.
    let strands: usize = stdout
        .split("last frame: ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!(stdout.contains("3 frames in") && strands > 1000, "{stdout}");
}
