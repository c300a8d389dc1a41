//! Strands on the CPU: root sample sets, the random numbers the GPU reproduces, the styling
//! ops, level-of-detail formulas and the f64 reference strand generator.

pub mod accuracy;
pub mod lod;
pub mod random;
pub mod reference;
pub mod roots;
pub mod styling;

/// A strand's width at its tip as a fraction of its root width: every renderer tapers the
/// fibre linearly from root to tip (`shaders/shared/ribbon.wgsl`, the far-hair shader, the
/// path tracer) and every strand export writes the same taper.
pub const TIP_WIDTH_FRACTION: f64 = 0.4;

/// The width of a strand whose root is `root_width_m` wide at fraction `along` of its
/// vertices (0 root, 1 tip; clamped).
pub fn strand_width_m(root_width_m: f64, along: f64) -> f64 {
    root_width_m * (1.0 - (1.0 - TIP_WIDTH_FRACTION) * along.clamp(0.0, 1.0))
}
