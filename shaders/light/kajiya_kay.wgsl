// Kajiya & Kay 1989: a diffuse lobe sin(T, L), a white primary highlight sin(T, H)^80 and a
// tinted secondary one sin(T, H)^20, in the fibre frame of hair_bsdf.wgsl (x is the tangent),
// with one light's `weights` (rgb: tint of the diffuse and secondary lobes; w: the primary's
// weight). CPU mirror (same name): core/src/light/kajiya_kay.rs, which chooses the weights
// per light and frame so that, over every fibre orientation, it shows the Marschner model's
// mean colour: the primary highlight as R, the tinted lobes as TT + TRT + the rest.

fn kajiya_kay(wo: vec3<f32>, wi: vec3<f32>, base: vec3<f32>, weights: vec4<f32>) -> vec3<f32> {
    let diffuse = sqrt(max(1.0 - wi.x * wi.x, 0.0));
    let sum = wi + wo;
    var primary = 0.0;
    var secondary = 0.0;
    // Looking straight into the light there is no half vector: no highlight.
    if dot(sum, sum) > 1e-12 {
        let half_vector = normalize(sum);
        let sin_th = sqrt(max(1.0 - half_vector.x * half_vector.x, 0.0));
        primary = pow(sin_th, 80.0);
        secondary = pow(sin_th, 20.0);
    }
    return base * weights.rgb * (0.35 * diffuse + 0.25 * secondary) + vec3<f32>(weights.w * primary);
}
