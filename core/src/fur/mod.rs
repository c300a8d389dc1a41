//! Fur as shells and fins (seed 002, "Real-Time Fur over Arbitrary Surfaces", after Lengyel
//! 2000): the CPU side of the `fur` effect.
//!
//! | file | stage |
//! |---|---|
//! | [`volume`] | a toroidal patch of real strands grown by a particle system (presets: straight, curly, sparse, dense) |
//! | [`textures`] | the patch sampled into shell layers (tall Gaussian), a fin texture, and the shell levels of detail |
//! | [`lapped`] | the surface covered by non-overlapping lapped-texture patches aligned to a direction field, and its fin edges |
//! | [`base`] | the surface fur grows on from a hair mesh (root faces, columns as offset vectors) and the arrays `fur.wgsl` reads |
//! | [`lighting`] | the seed's Kajiya-Kay lookup table |

pub mod base;
pub mod lapped;
pub mod lighting;
pub mod textures;
pub mod volume;

#[cfg(test)]
mod tests;
