// The scene every lit shader receives (group 1): lights, shadow views, the fibre model's
// constants, dual-scattering constants, the body's colour. WGSL has no #include:
// render/src/renderer/scene_lighting.rs prepends this file to each lit shader.
// Keep in sync with core/src/light/scene_uniforms.rs (`SceneUniforms`, `GpuLight`,
// `GpuShadowView`); CPU mirror of tonemap: core/src/light/mod.rs.

struct SceneLight {
    // xyz: unit direction toward the light (w = 0) or its position in metres (w = 1).
    vector: vec4<f32>,
    // rgb: colour × intensity; w: the light's shadow slot, or −1 when it casts none.
    radiance: vec4<f32>,
    // Kajiya-Kay's weights for this light (light/kajiya_kay.wgsl; 0 under Marschner): rgb
    // the tint of its diffuse and secondary lobes, w its primary highlight's weight.
    kajiya_kay: vec4<f32>,
}

struct ShadowView {
    view_projection: mat4x4<f32>,
    // x: near, y: far (distances from the light), z: 1 for a perspective view, w: texel size.
    params: vec4<f32>,
    // x: the depth the opacity layers span, y: the lookup bias (metres), z, w: unused.
    layers: vec4<f32>,
}

struct SceneUniforms {
    lights: array<SceneLight, 8>,
    shadows: array<ShadowView, 2>,
    // x: light count, y: opacity layers, z: self-shadowing (0 none, 1 OSM, 2 DOM), w: coverage.
    counts: vec4<u32>,
    // rgb: ambient radiance; w: exposure.
    ambient: vec4<f32>,
    background: vec4<f32>,
    // rgb: absorption at the root; w: tip factor.
    sigma_a: vec4<f32>,
    // x: per-strand variation, y: η, z: azimuthal logistic scale s, w: β_n.
    fibre: vec4<f32>,
    lobe_variance: vec4<f32>,
    tilt_sin: vec4<f32>,
    tilt_cos: vec4<f32>,
    forward_transmittance: vec4<f32>,
    ds_lobe_shift: vec4<f32>,
    ds_lobe_variance: vec4<f32>,
    body_color: vec4<f32>,
    // x: Gauss-Legendre offsets averaged across thin fibres (1 to 3).
    quality: vec4<u32>,
    // The ombré: rgb the tip colour (linear), w 1 when the material has one.
    ombre_tip: vec4<f32>,
    // x: where the ombré starts, y: where it ends (fractions along the strand).
    ombre_span: vec4<f32>,
}

@group(1) @binding(0) var<uniform> scene: SceneUniforms;

// Unit direction from `world` toward light `i`.
fn light_direction(i: u32, world: vec3<f32>) -> vec3<f32> {
    let light = scene.lights[i];
    if light.vector.w == 0.0 {
        return light.vector.xyz;
    }
    let offset = light.vector.xyz - world;
    let length_squared = dot(offset, offset);
    if !(length_squared > 1e-18) {
        return vec3<f32>(0.0, 1.0, 0.0);
    }
    return offset * inverseSqrt(length_squared);
}

// Irradiance of light `i` at `world` (point lights fall off with the squared distance).
fn light_irradiance(i: u32, world: vec3<f32>) -> vec3<f32> {
    let light = scene.lights[i];
    if light.vector.w == 0.0 {
        return light.radiance.rgb;
    }
    let offset = light.vector.xyz - world;
    return light.radiance.rgb / max(dot(offset, offset), 1e-12);
}

fn light_shadow_slot(i: u32) -> i32 {
    return i32(scene.lights[i].radiance.w);
}

// The ACES filmic fit (Narkowicz 2015) of radiance × exposure.
fn tonemap(radiance: vec3<f32>) -> vec3<f32> {
    let x = max(radiance * scene.ambient.w, vec3<f32>(0.0));
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

// The colour a thick mass of hair with absorption `sigma_a` shows (Chiang et al. 2016,
// inverse of eq. 9; mirror: core/src/light/material.rs `color_from_sigma_a`).
fn hair_color(sigma_a: vec3<f32>) -> vec3<f32> {
    return exp(-sqrt(max(sigma_a, vec3<f32>(0.0))) * color_polynomial());
}

// Chiang et al. 2016 eq. 9's polynomial in the azimuthal roughness β_n.
fn color_polynomial() -> f32 {
    let b = scene.fibre.w;
    return 5.969 - 0.215 * b + 2.532 * b * b - 10.73 * b * b * b + 5.574 * b * b * b * b
        + 0.245 * b * b * b * b * b;
}

// Absorption at fraction `along` of a strand with random value `xi`
// (mirror: core/src/light/material.rs `Fibre::sigma_a`).
fn strand_sigma_a(along: f32, xi: f32) -> vec3<f32> {
    return painted_strand_sigma_a(along, xi, vec4<f32>(0.0));
}

// The colour `share` of the way from `own` toward `toward`, kept in the colour fit's range
// except that hair darker than 1e-4 keeps its own floor (no jump in absorption where a blend
// starts; never below 1e-30, so the logarithm stays finite). Mirror: material.rs
// `blend_toward`; its absorption is `sigma_a_of_blend`.
fn blend_toward(own: vec3<f32>, toward: vec3<f32>, share: f32) -> vec3<f32> {
    let lowest = max(min(own, vec3<f32>(1e-4)), vec3<f32>(1e-30));
    return clamp(mix(own, toward, share), lowest, vec3<f32>(0.9999));
}

// The absorption that shows a blended colour `rgb` (Chiang et al. 2016 eq. 9).
fn sigma_a_of_blend(rgb: vec3<f32>) -> vec3<f32> {
    let l = log(rgb) / color_polynomial();
    return l * l;
}

// How far the ombré has turned the colour toward the tip's at fraction `t` of the strand: 0
// up to its start, 1 from its end, a smoothstep between (a step when the span is empty).
// Mirror: `FibreOmbre::share`.
fn ombre_share(t: f32) -> f32 {
    let start = scene.ombre_span.x;
    let span = scene.ombre_span.y - start;
    if span <= 1e-6 {
        return select(0.0, 1.0, t >= start);
    }
    let x = clamp((t - start) / span, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

// As `strand_sigma_a`, on a strand under the colour map's `paint` (linear rgb, weight): the
// root's colour blended toward the painted one by its weight, then along the strand toward
// the ombré's tip colour, and the absorption that shows it (mirror: `Fibre::painted`, then
// `Fibre::sigma_a`).
fn painted_strand_sigma_a(along: f32, xi: f32, paint: vec4<f32>) -> vec3<f32> {
    var root = scene.sigma_a.rgb;
    let t = clamp(along, 0.0, 1.0);
    let weight = clamp(paint.a, 0.0, 1.0);
    var share = 0.0;
    if scene.ombre_tip.w > 0.0 {
        share = ombre_share(t);
    }
    if weight > 0.0 || share > 0.0 {
        var rgb = hair_color(root);
        if weight > 0.0 {
            rgb = blend_toward(rgb, paint.rgb, weight);
            root = sigma_a_of_blend(rgb);
        }
        if share > 0.0 {
            root = sigma_a_of_blend(blend_toward(rgb, scene.ombre_tip.rgb, share));
        }
    }
    let scale = (1.0 + (scene.sigma_a.w - 1.0) * t) * (1.0 + scene.fibre.x * (2.0 * xi - 1.0));
    return root * max(scale, 0.0);
}

// The fibre frame shading works in, for a strand with `tangent` seen along the unit `wo`
// (toward the viewer), as columns: x along the fibre, z toward the viewer across it,
// y = z × x. A zero tangent falls back to +y; a view along the fibre to z = x × +z.
// (preview_hair.wgsl and far_hair_lit.wgsl.)
fn fibre_frame(tangent: vec3<f32>, wo: vec3<f32>) -> mat3x3<f32> {
    var x = vec3<f32>(0.0, 1.0, 0.0);
    if dot(tangent, tangent) > 1e-24 {
        x = tangent * inverseSqrt(dot(tangent, tangent));
    }
    var z = wo - x * dot(wo, x);
    if !(dot(z, z) > 1e-24) {
        z = cross(x, vec3<f32>(0.0, 0.0, 1.0));
    }
    if dot(z, z) > 1e-24 {
        z = z * inverseSqrt(dot(z, z));
    } else {
        z = vec3<f32>(0.0);
    }
    return mat3x3<f32>(x, cross(z, x), z);
}
