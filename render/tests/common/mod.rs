//! What several GPU tests share: the bundled samples and a camera that makes the frame plan
//! use every part of LOD.

use glam::{Mat4, Vec3};
use hairloom_core::runtime::frame_plan::{LodCamera, LodSettings};

/// A bundled sample project's document.
pub fn sample(name: &str) -> hairloom_core::model::document::Document {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../assets/samples/{name}.hairloom"));
    hairloom_core::io::project::load(&path)
        .expect("sample")
        .document
}

/// A camera far enough from hair in the box `(lo, hi)` for partial strand counts and several
/// vertex levels, with a wide morph window (λ = 1) so that many bundles sit between two
/// levels (morphing).
pub fn morphing_lod(lo: Vec3, hi: Vec3) -> (LodCamera, LodSettings) {
    let centre = (lo + hi) * 0.5;
    let eye = centre + Vec3::new(0.0, 0.0, 6.0);
    let fov_y_rad = 30f32.to_radians();
    let camera = LodCamera {
        eye,
        view_projection: Mat4::perspective_rh(fov_y_rad, 1.0, 0.01, 100.0)
            * Mat4::look_at_rh(eye, centre, Vec3::Y),
        fov_y_rad,
        resolution_px: 1080.0,
    };
    let lod = LodSettings {
        alpha_strands: 0.02,
        alpha_vertices: 0.005,
        lambda: 1.0,
        ..LodSettings::default()
    };
    (camera, lod)
}
