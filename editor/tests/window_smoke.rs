//! Smoke test of the real binary with a real window: start Xvfb, run `hairloom` (no
//! arguments: the embedded sample) on it for a few seconds, take a screenshot with `xwd` and
//! check it is not blank (panels, text and the rendered viewport give many colours).
//!
//! Needs `Xvfb` and `xwd` (Debian: xvfb, x11-apps), which `make test` installs; without them
//! the test is skipped unless HAIRLOOM_REQUIRE_DISPLAY=1 (set by `make test`).

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

struct KillOnDrop(Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn have(program: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {program}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// An X window dump (XWD, ZPixmap, 24/32-bit TrueColor) as RGB pixels.
fn parse_xwd(bytes: &[u8]) -> Result<(u32, u32, Vec<[u8; 3]>), String> {
    let field = |i: usize| -> Result<u32, String> {
        bytes
            .get(4 * i..4 * i + 4)
            .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| "truncated XWD header".to_string())
    };
    let header_size = field(0)? as usize;
    let (format, width, height) = (field(2)?, field(4)?, field(5)?);
    let byte_order = field(7)?;
    let bits_per_pixel = field(11)?;
    let bytes_per_line = field(12)? as usize;
    let masks = [field(14)?, field(15)?, field(16)?];
    let colors = field(19)? as usize;
    if format != 2 || bits_per_pixel != 32 {
        return Err(format!(
            "XWD format {format} at {bits_per_pixel} bits per pixel (expected ZPixmap, 32)"
        ));
    }
    let data = header_size + 12 * colors;
    let mut pixels = Vec::with_capacity((width * height) as usize);
    for y in 0..height as usize {
        for x in 0..width as usize {
            let at = data + y * bytes_per_line + 4 * x;
            let b = bytes.get(at..at + 4).ok_or("truncated XWD pixels")?;
            let value = if byte_order == 0 {
                u32::from_le_bytes([b[0], b[1], b[2], b[3]])
            } else {
                u32::from_be_bytes([b[0], b[1], b[2], b[3]])
            };
            let channel = |mask: u32| ((value & mask) >> mask.trailing_zeros()) as u8;
            pixels.push([channel(masks[0]), channel(masks[1]), channel(masks[2])]);
        }
    }
    Ok((width, height, pixels))
}

#[test]
fn the_editor_window_opens_and_draws() {
    let required = std::env::var("HAIRLOOM_REQUIRE_DISPLAY").as_deref() == Ok("1");
    if !have("Xvfb") || !have("xwd") {
        assert!(
            !required,
            "Xvfb and xwd are required (apt-get install xvfb x11-apps)"
        );
        eprintln!("skipped: Xvfb or xwd missing (run `make test`)");
        return;
    }
    let display = format!(":{}", 90 + std::process::id() % 100);
    let _xvfb = KillOnDrop(
        Command::new("Xvfb")
            .args([
                display.as_str(),
                "-screen",
                "0",
                "1280x800x24",
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
    // Its own recovery folder: no offer from (or autosave into) the user's.
    let recovery_dir = tempfile::tempdir().expect("temp dir");
    let mut editor = KillOnDrop(
        Command::new(env!("CARGO_BIN_EXE_hairloom"))
            .env("DISPLAY", &display)
            .env_remove("WAYLAND_DISPLAY")
            .env("XDG_RUNTIME_DIR", &runtime_dir)
            .env("HAIRLOOM_RECOVERY_DIR", recovery_dir.path())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start hairloom"),
    );
    // Screenshots until the window shows enough (software rendering starts slowly).
    let start = Instant::now();
    let mut last = String::new();
    while start.elapsed() < Duration::from_secs(90) {
        std::thread::sleep(Duration::from_secs(3));
        if let Ok(Some(status)) = editor.0.try_wait() {
            let mut stderr = String::new();
            if let Some(mut pipe) = editor.0.stderr.take() {
                let _ = std::io::Read::read_to_string(&mut pipe, &mut stderr);
            }
            panic!("hairloom exited with {status}: {stderr}");
        }
        let dump = Command::new("xwd")
            .args(["-root", "-silent", "-display", display.as_str()])
            .output()
            .expect("run xwd");
        let (width, height, pixels) = parse_xwd(&dump.stdout).expect("an XWD screenshot");
        let background = pixels[0];
        let drawn = pixels.iter().filter(|p| **p != background).count();
        let mut colours: Vec<[u8; 3]> = pixels.clone();
        colours.sort_unstable();
        colours.dedup();
        last = format!(
            "{width}x{height}: {drawn} pixels differ from the corner, {} colours",
            colours.len()
        );
        // The window covers most of the screen; text, panels and hair give many colours.
        if drawn > pixels.len() / 2 && colours.len() > 200 {
            let out = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/editor-smoke.png");
            let rgb: Vec<u8> = pixels.iter().flatten().copied().collect();
            if let Some(image) = image::RgbImage::from_raw(width, height, rgb) {
                let _ = image.save(&out);
            }
            eprintln!("{last} (screenshot: {})", out.display());
            return;
        }
    }
    panic!("the editor window did not draw within 90 s: {last}");
}
