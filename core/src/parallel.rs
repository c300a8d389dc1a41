//! Deterministic data parallelism over std's scoped threads: results come back in item
//! order whatever the thread count or scheduling, so a parallel run equals a serial one.
//! (A worker pool crate such as rayon would give the same with more machinery; the few
//! loops here need only chunked ranges.)

/// Runs `work` over `count` items in chunks of `chunk` items on `threads` threads and
/// returns the chunks' results in order. A worker's panic is re-raised here (it is a bug),
/// never turned into fewer results.
pub fn in_chunks<T: Send>(
    count: usize,
    chunk: usize,
    threads: usize,
    work: impl Fn(std::ops::Range<usize>) -> T + Sync,
) -> Vec<T> {
    let chunk = chunk.max(1);
    let chunks = count.div_ceil(chunk).max(1);
    let range = |c: usize| c * chunk..((c + 1) * chunk).min(count);
    let threads = threads.clamp(1, chunks);
    if threads == 1 {
        return (0..chunks).map(|c| work(range(c))).collect();
    }
    let work = &work;
    let mut results: Vec<(usize, T)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                scope.spawn(move || {
                    (t..chunks)
                        .step_by(threads)
                        .map(|c| (c, work(range(c))))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| {
                h.join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .collect()
    });
    results.sort_by_key(|(c, _)| *c);
    results.into_iter().map(|(_, r)| r).collect()
}
