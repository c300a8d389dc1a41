// The Marschner R / TT / TRT fibre model in Chiang et al. 2016's energy-conserving form.
// CPU mirror (same names, f64): core/src/light/hair_bsdf.rs, which states the conventions:
// directions in the fibre frame (x along the tangent, y across, z toward the viewer),
// θ = asin(x), φ = atan2(z, y), h the incident offset in [−1, 1]; the result f_s gives a
// directional light's reflected radiance as f_s · E. Constants (variances, logistic scale,
// cuticle tilt rotations, η) come precomputed in `scene` (shaders/shared/scene.wgsl).

const PI: f32 = 3.14159265;
const TAU: f32 = 6.28318531;

fn safe_sqrt(x: f32) -> f32 {
    return sqrt(max(x, 0.0));
}

fn i0(x: f32) -> f32 {
    var value = 0.0;
    var x2i = 1.0;
    var factorial = 1.0;
    var four_i = 1.0;
    for (var i = 0; i < 10; i++) {
        if i > 1 {
            factorial *= f32(i);
        }
        value += x2i / (four_i * factorial * factorial);
        x2i *= x * x;
        four_i *= 4.0;
    }
    return value;
}

fn log_i0(x: f32) -> f32 {
    if x > 12.0 {
        return x + 0.5 * (-log(TAU) + log(1.0 / x) + 1.0 / (8.0 * x));
    }
    return log(i0(x));
}

fn mp(cos_theta_i: f32, cos_theta_o: f32, sin_theta_i: f32, sin_theta_o: f32, v: f32) -> f32 {
    let a = cos_theta_i * cos_theta_o / v;
    let b = sin_theta_i * sin_theta_o / v;
    var m: f32;
    if v <= 0.1 {
        m = exp(log_i0(a) - b - 1.0 / v + 0.6931472 + log(1.0 / (2.0 * v)));
    } else {
        let e = exp(1.0 / v);
        // sinh(1/v) = (e − 1/e) / 2
        m = exp(-b) * i0(a) / ((e - 1.0 / e) * v);
    }
    if !(m < 3.0e38) || !(m >= 0.0) {
        return 0.0;
    }
    return m;
}

fn fr_dielectric(cos_theta_i: f32, eta_in: f32) -> f32 {
    var cos_i = clamp(cos_theta_i, -1.0, 1.0);
    var eta = eta_in;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = safe_sqrt(1.0 - sin2_t);
    let parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return (parallel * parallel + perpendicular * perpendicular) * 0.5;
}

fn lobe_phi(p: f32, gamma_o: f32, gamma_t: f32) -> f32 {
    return 2.0 * p * gamma_t - 2.0 * gamma_o + p * PI;
}

fn logistic(x: f32, s: f32) -> f32 {
    let e = exp(-abs(x) / s);
    return e / (s * (1.0 + e) * (1.0 + e));
}

fn logistic_cdf(x: f32, s: f32) -> f32 {
    return 1.0 / (1.0 + exp(-x / s));
}

fn wrap_angle(x: f32) -> f32 {
    var y = x - TAU * floor(x / TAU);
    if y > PI {
        y -= TAU;
    }
    return y;
}

fn np(phi: f32, p: f32, s: f32, gamma_o: f32, gamma_t: f32) -> f32 {
    let dphi = wrap_angle(phi - lobe_phi(p, gamma_o, gamma_t));
    return logistic(dphi, s) / (logistic_cdf(PI, s) - logistic_cdf(-PI, s));
}

// Lobe p's (sin θ, |cos θ|) of the outgoing direction, turned by the cuticle tilt.
fn tilted(p: u32, sin_theta: f32, cos_theta: f32) -> vec2<f32> {
    let s = scene.tilt_sin;
    let c = scene.tilt_cos;
    var r = vec2<f32>(sin_theta, cos_theta);
    if p == 0u {
        r = vec2<f32>(sin_theta * c.y - cos_theta * s.y, cos_theta * c.y + sin_theta * s.y);
    } else if p == 1u {
        r = vec2<f32>(sin_theta * c.x + cos_theta * s.x, cos_theta * c.x - sin_theta * s.x);
    } else if p == 2u {
        r = vec2<f32>(sin_theta * c.z + cos_theta * s.z, cos_theta * c.z - sin_theta * s.z);
    }
    return vec2<f32>(r.x, abs(r.y));
}

fn hair_bsdf(wo: vec3<f32>, wi: vec3<f32>, h_in: f32, sigma_a: vec3<f32>) -> vec3<f32> {
    let eta = scene.fibre.y;
    let s = scene.fibre.z;
    let h = clamp(h_in, -1.0, 1.0);
    let sin_theta_o = clamp(wo.x, -1.0, 1.0);
    let cos_theta_o = safe_sqrt(1.0 - sin_theta_o * sin_theta_o);
    let sin_theta_t = sin_theta_o / eta;
    let cos_theta_t = safe_sqrt(1.0 - sin_theta_t * sin_theta_t);
    let etap = safe_sqrt(eta * eta - sin_theta_o * sin_theta_o) / max(cos_theta_o, 1e-12);
    let sin_gamma_t = clamp(h / etap, -1.0, 1.0);
    let cos_gamma_t = safe_sqrt(1.0 - sin_gamma_t * sin_gamma_t);
    let gamma_o = asin(h);
    let gamma_t = asin(sin_gamma_t);
    let transmittance = exp(-max(sigma_a, vec3<f32>(0.0)) * (2.0 * cos_gamma_t / max(cos_theta_t, 1e-12)));
    let sin_theta_i = clamp(wi.x, -1.0, 1.0);
    let cos_theta_i = safe_sqrt(1.0 - sin_theta_i * sin_theta_i);
    let phi = atan2(wi.z, wi.y) - atan2(wo.z, wo.y);
    // A_p: Fresnel at the first interface, the passes inside, and the tail of longer paths.
    let f = fr_dielectric(cos_theta_o * safe_sqrt(1.0 - h * h), eta);
    var a = array<vec3<f32>, 4>();
    a[0] = vec3<f32>(f);
    a[1] = (1.0 - f) * (1.0 - f) * transmittance;
    a[2] = a[1] * transmittance * f;
    a[3] = a[2] * transmittance * f / max(vec3<f32>(1.0) - transmittance * f, vec3<f32>(1e-12));
    var sum = vec3<f32>(0.0);
    for (var p = 0u; p < 3u; p++) {
        let o = tilted(p, sin_theta_o, cos_theta_o);
        sum += mp(cos_theta_i, o.y, sin_theta_i, o.x, scene.lobe_variance[p]) * a[p]
            * np(phi, f32(p), s, gamma_o, gamma_t);
    }
    sum += mp(cos_theta_i, cos_theta_o, sin_theta_i, sin_theta_o, scene.lobe_variance.w) * a[3] / TAU;
    return select(vec3<f32>(0.0), sum, (sum < vec3<f32>(3.0e38)) & (sum >= vec3<f32>(0.0)));
}
