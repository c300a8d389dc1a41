//! Hairloom's GPU side: device setup now; strand generation and preview rendering build on
//! it. Every GPU stage here has a CPU mirror in `hairloom-core` that tests compare against.

pub mod device;
pub mod preview;
pub mod strand_gen;
