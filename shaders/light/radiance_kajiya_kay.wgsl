// Kajiya-Kay shading: the lobe (`hair_single`), attenuated by the forward transmittance of the
// `n` fibres between the point and the light (from the opacity maps; 0 without them).
fn hair_single(wo: vec3<f32>, wi: vec3<f32>, h: f32, sigma_a: vec3<f32>, light: u32) -> vec3<f32> {
    return kajiya_kay(wo, wi, hair_color(sigma_a), scene.lights[light].kajiya_kay);
}

fn hair_radiance(wo: vec3<f32>, wi: vec3<f32>, single: vec3<f32>, n: f32) -> vec3<f32> {
    return single * pow(scene.forward_transmittance.rgb, vec3<f32>(n));
}
