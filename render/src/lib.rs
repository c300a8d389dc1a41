//! Hairloom's GPU side, in re_renderer's shape: device setup (`device`), one renderer per
//! feature (`renderer/`: strand generation, hair ribbons, body — each named after its
//! shader), a view that keeps its render targets (`view`), the frame that composes them
//! (`preview`) and the measurements of the GPU path (`measure`). A runtime asset
//! (`hairloom_core::runtime::hair::RuntimeHair`) becomes GPU resources only here. Every GPU
//! stage has a CPU mirror in `hairloom_core::runtime` that tests compare against.

pub mod device;
pub mod measure;
pub mod preview;
pub mod renderer;
pub mod view;
