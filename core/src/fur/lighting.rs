//! Seed 002's hair lighting (§2.4, from Lengyel 2000): a modified Banks / Kajiya-Kay model
//! stored in a 32 × 32 lookup table indexed by `u = T·L` and `v = T·H`,
//!
//! `HairLighting(u, v) = K_a + K_d (1 − u²)^{P_d/2} + K_s (1 − v²)^{P_s/2}`,
//!
//! and the Banks self-shadowing term that darkens shells near the skin.

/// The seed's table side.
pub const LIGHTING_TABLE_SIZE: usize = 32;

/// Colours and powers of the seed's lighting model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KajiyaKayLighting {
    pub ambient: [f32; 3],
    pub diffuse: [f32; 3],
    pub specular: [f32; 3],
    pub diffuse_power: f32,
    pub specular_power: f32,
}

impl KajiyaKayLighting {
    /// `HairLighting(u, v)` for `u = T·L`, `v = T·H` (clamped to `[−1, 1]`; NaN reads as 0,
    /// the brightest, so a bad tangent shows rather than vanishes).
    pub fn evaluate(&self, u: f32, v: f32) -> [f32; 3] {
        let clean = |x: f32| if x.is_nan() { 0.0 } else { x.clamp(-1.0, 1.0) };
        let (u, v) = (clean(u), clean(v));
        let d = (1.0 - u * u)
            .max(0.0)
            .powf(0.5 * self.diffuse_power.max(0.0));
        let s = (1.0 - v * v)
            .max(0.0)
            .powf(0.5 * self.specular_power.max(0.0));
        std::array::from_fn(|c| self.ambient[c] + self.diffuse[c] * d + self.specular[c] * s)
    }

    /// The table the GPU samples: row `j` is `v`, column `i` is `u`, both at texel centres
    /// over `[−1, 1]`, RGB per texel (bilinear filtering reproduces [`Self::evaluate`] to
    /// within the table's resolution).
    pub fn table(&self) -> Vec<[f32; 3]> {
        let n = LIGHTING_TABLE_SIZE;
        let at = |i: usize| -1.0 + 2.0 * (i as f32 + 0.5) / n as f32;
        (0..n * n)
            .map(|k| self.evaluate(at(k % n), at(k / n)))
            .collect()
    }
}

/// Banks' self-shadowing: the light reaching shell `height` (0 skin … 1 tips) through fur of
/// mean shell coverage `density`, as `(1 − density)^{(1 − height)·layers}` floored at the
/// ambient share the skin still gets.
pub fn banks_self_shadow(height: f32, density: f32, layers: u32, floor: f32) -> f32 {
    let depth = (1.0 - height.clamp(0.0, 1.0)) * layers as f32;
    let through = (1.0 - density.clamp(0.0, 1.0)).powf(depth);
    through.max(floor.clamp(0.0, 1.0))
}
