//! Geometry derived from the hair mesh (f64, the reference every faster path is measured
//! against): interior-vertex placement, styling frames, column curves and generated uv.

pub mod curve;
pub mod frames;
pub mod hairline;
pub mod interior;
pub mod uv;
