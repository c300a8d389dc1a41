// Kajiya & Kay 1989: a diffuse lobe sin(T, L) and a specular lobe sin(T, H)^p, plus a shifted,
// tinted secondary highlight, in the fibre frame of hair_bsdf.wgsl (x is the tangent). The
// colour comes from the material's absorption (hair_color), so the two shading models show
// the same hair.

fn kajiya_kay(wo: vec3<f32>, wi: vec3<f32>, base: vec3<f32>) -> vec3<f32> {
    let diffuse = sqrt(max(1.0 - wi.x * wi.x, 0.0));
    let half_vector = normalize(wi + wo);
    let sin_th = sqrt(max(1.0 - half_vector.x * half_vector.x, 0.0));
    let primary = pow(sin_th, 80.0) * 0.12;
    let secondary = pow(sin_th, 20.0) * 0.25;
    return base * diffuse * 0.35 + vec3<f32>(primary) + base * secondary;
}
