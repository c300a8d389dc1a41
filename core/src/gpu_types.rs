//! GPU-layout structs shared by the CPU mirrors (here) and the shaders (`shaders/`).
//! Fields are explicitly padded to WGSL alignment; `render`'s shader-validation test checks
//! that each size matches its WGSL struct.

use bytemuck::{Pod, Zeroable};

/// Uniform parameters of strand generation.
/// Keep in sync with `shaders/strand_gen.wgsl` (`StrandGenParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct StrandGenParams {
    /// Added to every sampled position (xyz; w unused).
    pub position_offset: [f32; 4],
    /// Hair-mesh texture width, height, depth (w unused).
    pub texture_size: [u32; 4],
    pub strand_count: u32,
    /// Vertices per strand (`2^e + 1`).
    pub vertex_count: u32,
    /// 0: exact (manual) filtering, 1: hardware filtering.
    pub filtering: u32,
    pub _padding: u32,
}

/// One strand's root on the root slice.
/// Keep in sync with `shaders/strand_gen.wgsl` (`StrandRoot`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct StrandRoot {
    /// Texel coordinates of the root: block origin + 0.5 + block coordinates.
    pub texel: [f32; 2],
    /// Layers of the strand's bundle.
    pub layers: u32,
    pub _padding: u32,
}

/// Filtering mode values of [`StrandGenParams::filtering`].
pub const FILTERING_EXACT: u32 = 0;
pub const FILTERING_HARDWARE: u32 = 1;
