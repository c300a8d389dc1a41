//! Hairloom's GPU side, in re_renderer's shape: device setup (`device`), one renderer per
//! feature (`renderer/`: strand generation, hair ribbons, body, and the effects a scene asks
//! for — shadow maps, body shadows, dual-scattering tables, order-independent coverage — each
//! named after its shader; the lit shaders composed in `renderer::shader_composer`), a view
//! that keeps its render targets (`view`), the one frame builder that records the passes a
//! scene names in order (`frame`), the one hair asset that owns a document's runtime data and
//! its GPU side and takes every change by its kind (`hair_asset`), the preview that renders a
//! picture with them (`preview`), the registry of every labelled GPU resource (`resources`)
//! and the measurements of the GPU path (`measure`); and `game`, the drop-in runtime a wgpu
//! game uses to draw a runtime bundle into its own render pass (`cargo run --example game`),
//! on the same frame builder and hair asset. A runtime asset
//! (`hairloom_core::runtime::hair::RuntimeHair`) becomes GPU resources only here. Every GPU
//! stage has a CPU mirror in `hairloom_core::runtime` that tests compare against.

pub mod device;
pub mod frame;
pub mod game;
pub mod hair_asset;
pub mod measure;
pub mod preview;
pub mod renderer;
pub mod resources;
pub mod view;
