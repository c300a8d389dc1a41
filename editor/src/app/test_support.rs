//! Helpers for the app's unit tests.

/// Replaces `path` with a FIFO (`mkfifo`): a file whose plain open blocks until a writer
/// comes, which no per-user file read may wait on.
pub fn make_fifo(path: &std::path::Path) {
    let _ = std::fs::remove_file(path);
    let made = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo");
    assert!(made.success(), "mkfifo {}", path.display());
}

/// `work()` on another thread, failing the test if it does not return within 10 s (a read
/// that blocks would otherwise hang the whole test run).
pub fn returns_promptly<T: Send + 'static>(work: impl FnOnce() -> T + Send + 'static) -> T {
    let (sender, receiver) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = sender.send(work());
    });
    receiver
        .recv_timeout(std::time::Duration::from_secs(10))
        .expect("returned instead of blocking")
}
