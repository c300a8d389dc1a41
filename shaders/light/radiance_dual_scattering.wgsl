// Marschner shading with dual scattering (dual_scattering.wgsl): single scattering
// (`hair_single`) for the direct light, plus global and local multiple scattering.
fn hair_single(wo: vec3<f32>, wi: vec3<f32>, h: f32, sigma_a: vec3<f32>, light: u32) -> vec3<f32> {
    return hair_bsdf(wo, wi, h, sigma_a);
}

fn hair_radiance(wo: vec3<f32>, wi: vec3<f32>, single: vec3<f32>, n: f32) -> vec3<f32> {
    return dual_scattering(wo, wi, single, n);
}
