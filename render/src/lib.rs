//! Hairloom's GPU side: device setup (`device`), strand generation (`strand_gen`, running
//! `shaders/strand_gen.wgsl`) and the preview renderer (`preview`: ribbons and the body).
//! A runtime asset (`hairloom_core::runtime::hair::RuntimeHair`) becomes GPU resources only
//! here. Every GPU stage has a CPU mirror in `hairloom_core::runtime` that tests compare
//! against.

pub mod device;
pub mod measure;
pub mod preview;
pub mod strand_gen;
