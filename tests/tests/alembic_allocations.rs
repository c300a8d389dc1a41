//! Hostile Alembic files must not make the reader allocate what a size field claims: an
//! object or property name whose size says 4 GiB is an error read from the bytes the blob
//! holds, not a 4 GiB buffer (on a machine with less memory free, that allocation aborts
//! the editor — `catch_unwind` cannot catch it). This binary counts the largest single
//! allocation made while reading, through its own global allocator.

#![allow(
    unsafe_code,
    reason = "a global allocator that forwards to the system one and remembers the largest request: the only way to see what a reader allocates"
)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::ops::ControlFlow;
use std::sync::atomic::{AtomicUsize, Ordering};

use hairloom_core::Document;
use hairloom_core::io::alembic::groom::Groom;
use hairloom_core::io::alembic::{AlembicTarget, groom_file};
use hairloom_core::io::groom_in::{GroomLimits, read_groom};
use hairloom_core::samples::{grid_scalp, straight_layers};
use hairloom_core::strands::reference::{StrandOptions, generate};

/// The system allocator, remembering the largest request since the last reset.
struct Largest;

static LARGEST: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Largest = Largest;

/// Offsets of every length-prefixed name `name` in `bytes` (a u32 size, then the name).
fn prefixed(bytes: &[u8], name: &str) -> Vec<usize> {
    let mut needle = (name.len() as u32).to_le_bytes().to_vec();
    needle.extend_from_slice(name.as_bytes());
    bytes
        .windows(needle.len())
        .enumerate()
        .filter(|(_, w)| *w == needle.as_slice())
        .map(|(at, _)| at)
        .collect()
}

#[test]
fn name_sizes_that_claim_gigabytes_are_errors_not_allocations() {
    let scalp = grid_scalp(2, 2, |s, t| glam::DVec3::new(0.1 * s, 0.0, 0.08 * t));
    let document = Document::new("grid", straight_layers(scalp, 3, glam::DVec3::Y * 0.03));
    let strands = generate(
        &document,
        &StrandOptions {
            strands_per_bundle: 4,
            vertices_log2: 2,
            ..StrandOptions::default()
        },
    );
    let bytes = groom_file(
        &Groom::new(&document, &strands, 8e-5),
        AlembicTarget::Blender,
    )
    .expect("abc");
    let dir = tempfile::tempdir().expect("temp dir");
    let read = |bytes: &[u8]| {
        let path = dir.path().join("groom.abc");
        std::fs::write(&path, bytes).expect("write");
        LARGEST.store(0, Ordering::Relaxed);
        let result = read_groom(&path, GroomLimits::default(), &mut |_| {
            ControlFlow::Continue(())
        });
        (result, LARGEST.load(Ordering::Relaxed))
    };
    let (valid, valid_largest) = read(&bytes);
    valid.expect("our own groom reads");
    // An object's name ("guides", a child of the top object) and two property names (the
    // curves schema's compound and its points), each claiming 4 GiB.
    let names = ["guides", ".geom", "P"];
    for name in names {
        let at = *prefixed(&bytes, name)
            .first()
            .unwrap_or_else(|| panic!("{name:?} is named in the file"));
        let mut hostile = bytes.clone();
        hostile[at..at + 4].copy_from_slice(&0xFFFF_FF00u32.to_le_bytes());
        let (result, largest) = read(&hostile);
        assert!(
            result.is_err(),
            "{name}: a 4 GiB name cannot fit in the file"
        );
        assert!(
            largest < (64 << 20).max(4 * valid_largest),
            "{name}: reading allocated {largest} bytes at once (a valid read: {valid_largest})"
        );
    }
}
