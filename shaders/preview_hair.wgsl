// preview_hair: the hair's colour pass. Ribbons from shared/ribbon.wgsl, lit by the scene's
// lights (shared/scene.wgsl) through `hair_radiance` — Kajiya-Kay, Marschner, or Marschner
// with dual scattering (light/radiance_*.wgsl) — with the fibres in front of each point
// from the opacity maps (`hairs_in_front`) and the body's shadow (`body_visibility`); the
// renderer prepends the modules the scene's effects name and stubs for the rest.
// `fs_main` draws opaque ribbons where the depth pre-pass (`fs_depth`) left them nearest;
// with width-based coverage, strands narrower than a pixel stay out of the pre-pass (so the
// lit pass never sees them) and go to `fs_oit` instead, which accumulates weighted blended
// transparency (McGuire & Bavoil 2013; composited by oit_composite.wgsl).

struct VertexOutput {
    // Invariant: the depth pre-pass and the colour pass must compute the same depth.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) tangent: vec3<f32>,
    @location(2) along: f32,
    // The incident offset across the fibre: −1 … 1 from one edge to the other.
    @location(3) h: f32,
    @location(4) coverage: f32,
    @location(5) @interpolate(flat) root: u32,
    @location(6) width_px: f32,
    // The colour map at the strand's root: linear rgb, and its weight (0: the material's).
    @location(7) @interpolate(flat) paint: vec4<f32>,
}

// The colour map at each root, packed as render/src/renderer/strand_gen/upload.rs uploads it
// (mirror: PaintedColour::pack — sRGB-encoded rgb bytes, the weight in byte 3); one 0 (no
// colour) when none is painted, or where the strands have no runtime asset.
@group(0) @binding(3) var<storage, read> root_paint: array<u32>;

// The sRGB transfer function's inverse (mirror: root_maps::srgb_to_linear).
fn srgb_to_linear(encoded: vec3<f32>) -> vec3<f32> {
    let low = encoded / 12.92;
    let high = pow((encoded + vec3<f32>(0.055)) / 1.055, vec3<f32>(2.4));
    return select(high, low, encoded <= vec3<f32>(0.04045));
}

// Root `root`'s painted colour (mirror: PaintedColour::unpack).
fn root_paint_of(root: u32) -> vec4<f32> {
    if root >= arrayLength(&root_paint) {
        return vec4<f32>(0.0);
    }
    let packed = unpack4x8unorm(root_paint[root]);
    return vec4<f32>(srgb_to_linear(packed.rgb), packed.a);
}

@vertex
fn vs_main(
    @builtin(vertex_index) vertex_index: u32,
    @builtin(instance_index) instance_index: u32,
) -> VertexOutput {
    return pass_vertex(ribbon_vertex(vertex_index, instance_index));
}

// What this pass's rasteriser takes from a ribbon vertex (the vertex shader above, and the
// mesh shader of shaders/strand_mesh.wgsl, through `PassVertex`).
alias PassVertex = VertexOutput;

fn pass_vertex(ribbon: RibbonVertex) -> VertexOutput {
    var out: VertexOutput;
    out.clip = ribbon.clip;
    out.world = ribbon.world;
    out.tangent = ribbon.tangent;
    out.along = ribbon.along;
    // The ribbon's side vector is cross(tangent, toward viewer) = −y of the fibre frame.
    out.h = -ribbon.side;
    out.coverage = ribbon.coverage;
    out.root = ribbon.root;
    out.width_px = ribbon.width_px;
    out.paint = root_paint_of(ribbon.root);
    return out;
}

// Single scattering of a fibre: a fibre a few pixels wide or more is shaded at the pixel's
// own offset h; a thinner one covers every offset within its pixel, so it takes the average
// over h by Gauss-Legendre with the scene's number of points (`effects.fibre_offsets`: each
// point is one more evaluation per light; `hairloom bench shading` measures what each buys),
// which is what a path tracer's pixel averages to. Blended between 2 and 4 pixels so nothing
// pops as a strand's width changes. (Multiple scattering does not depend on h:
// `hair_radiance` adds it once.)
fn fibre_single(wo: vec3<f32>, wi: vec3<f32>, h: f32, width_px: f32, sigma_a: vec3<f32>, light: u32) -> vec3<f32> {
    let averaged = clamp(2.0 - 0.5 * width_px, 0.0, 1.0);
    var result = vec3<f32>(0.0);
    if averaged < 1.0 {
        result += (1.0 - averaged) * hair_single(wo, wi, clamp(h, -1.0, 1.0), sigma_a, light);
    }
    if averaged > 0.0 {
        // Gauss-Legendre over h ∈ [−1, 1], weights summing to 1, written out per count (a
        // loop over constant arrays indexed at run time costs twice as much on a CPU adapter).
        var average: vec3<f32>;
        let points = scene.quality.x;
        if points <= 1u {
            average = hair_single(wo, wi, 0.0, sigma_a, light);
        } else if points == 2u {
            average = 0.5 * (hair_single(wo, wi, -0.5773503, sigma_a, light)
                + hair_single(wo, wi, 0.5773503, sigma_a, light));
        } else {
            average = 0.2777778 * (hair_single(wo, wi, -0.7745967, sigma_a, light)
                + hair_single(wo, wi, 0.7745967, sigma_a, light))
                + 0.4444444 * hair_single(wo, wi, 0.0, sigma_a, light);
        }
        result += averaged * average;
    }
    return result;
}

// Radiance leaving the fibre toward the viewer, tone-mapped.
fn shade_hair(in: VertexOutput) -> vec3<f32> {
    let wo = safe_normalize(toward_viewer(in.world));
    let frame = fibre_frame(in.tangent, wo);
    let x = frame[0];
    let y = frame[1];
    let z = frame[2];
    let sigma_a = painted_strand_sigma_a(in.along, strand_shading_random(in.root), in.paint);
    let wo_local = vec3<f32>(dot(wo, x), dot(wo, y), dot(wo, z));
    var radiance = scene.ambient.rgb * hair_color(sigma_a);
    for (var i = 0u; i < scene.counts.x; i++) {
        let wi = light_direction(i, in.world);
        let slot = light_shadow_slot(i);
        let n = hairs_in_front(in.world, slot);
        let visible = body_visibility(in.world, slot);
        let wi_local = vec3<f32>(dot(wi, x), dot(wi, y), dot(wi, z));
        let single = fibre_single(wo_local, wi_local, in.h, in.width_px, sigma_a, i);
        radiance += hair_radiance(wo_local, wi_local, single, n) * light_irradiance(i, in.world) * visible;
    }
    return tonemap(radiance);
}

// The depth pre-pass: only the nearest ribbon of each sample is then shaded (the colour pass
// tests for equal depth), so the lighting runs once per visible fragment, not once per layer
// of hair. With width-based coverage, thin strands stay out of it (they are blended later).
@fragment
fn fs_depth(in: VertexOutput) {
    if scene.counts.w == 1u && in.coverage < 0.999 {
        discard;
    }
}

// The lit pass. No `discard` here: a shader that may discard loses the early depth test, and
// the early test against the pre-pass is what keeps shading to one fragment per sample.
@fragment
fn fs_main(in: VertexOutput) -> @location(0) vec4<f32> {
    return vec4<f32>(shade_hair(in), 1.0);
}

struct OitOutput {
    @location(0) accumulation: vec4<f32>,
    @location(1) revealage: vec4<f32>,
}

@fragment
fn fs_oit(in: VertexOutput) -> OitOutput {
    if in.coverage >= 0.999 {
        discard;
    }
    let alpha = clamp(in.coverage, 0.0, 1.0);
    let color = shade_hair(in);
    // McGuire & Bavoil 2013 eq. 9: nearer fragments weigh more.
    let depth = clamp(in.clip.z, 0.0, 1.0);
    let weight = alpha * max(1e-2, 3e3 * pow(1.0 - depth, 3.0));
    var out: OitOutput;
    out.accumulation = vec4<f32>(color * weight, weight);
    out.revealage = vec4<f32>(alpha);
    return out;
}
