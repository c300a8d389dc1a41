//! Strands on the CPU: root sample sets, the random numbers the GPU reproduces, the styling
//! ops, level-of-detail formulas and the f64 reference strand generator.

pub mod accuracy;
pub mod lod;
pub mod random;
pub mod reference;
pub mod roots;
pub mod styling;
