//! Light: everything the lighting effects compute on the CPU, each file the mirror of the
//! shader it is named after (`shaders/light/X.wgsl` ↔ `light/X.rs`), plus the reference
//! renderer every GPU configuration is measured against.
//!
//! | file | what |
//! |---|---|
//! | [`material`] | absorption from melanin or colour (Chiang et al. 2016), root-to-tip and per-strand variation |
//! | [`kajiya_kay`] | Kajiya & Kay 1989's cheap fibre shading, weighted per material to show the Marschner model's mean colour |
//! | [`hair_bsdf`] | the Marschner R / TT / TRT fibre model in Chiang's energy-conserving form |
//! | [`dual_scattering`] | Zinke et al. 2008's multiple-scattering tables and response |
//! | [`aggregated_bcsdf`] | far hair: seed 001's aggregated BCSDF for a thick hair standing for a cluster of fibres |
//! | [`cluster_reference`] | the explicit-fibre reference the aggregated BCSDF is measured against |
//! | [`opacity_maps`] | shadow views, opacity-map layers and lookups (Kim & Neumann 2001; Yuksel & Keyser 2008) |
//! | [`scene_uniforms`] | the scene as the shaders receive it (`shaders/shared/scene.wgsl`) |
//! | [`reference_render`] | the CPU path tracer: f64 reference strands as fibres, exact shadows, many bounces |

pub mod aggregated_bcsdf;
pub mod cluster_reference;
pub mod dual_scattering;
pub mod hair_bsdf;
pub mod kajiya_kay;
pub mod material;
pub mod opacity_maps;
pub mod reference_render;
pub mod scene_uniforms;

/// The ACES filmic curve fitted by Narkowicz 2015, applied to linear radiance × exposure:
/// what every Hairloom picture maps to display values (the shaders' `tonemap`).
pub(crate) fn tonemap(x: f32) -> f32 {
    let x = if x.is_finite() { x.max(0.0) } else { 0.0 };
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

/// sRGB encoding of a display value in `[0, 1]` (what an sRGB render target does on write).
pub(crate) fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tonemapping_is_monotone_bounded_and_safe() {
        let mut last = -1.0;
        for i in 0..1000 {
            let x = i as f32 * 0.02;
            let y = tonemap(x);
            assert!((0.0..=1.0).contains(&y) && y >= last);
            last = y;
        }
        assert_eq!(tonemap(f32::NAN), 0.0);
        assert_eq!(tonemap(-3.0), 0.0);
        assert_eq!(tonemap(f32::INFINITY), 0.0);
        assert!(linear_to_srgb(0.5) > 0.7 && linear_to_srgb(0.5) < 0.74);
    }
}
