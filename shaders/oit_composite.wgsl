// oit_composite: resolves weighted blended transparency (McGuire & Bavoil 2013) over the
// opaque picture, per sample: colour = Σ c·w / Σ w, opacity 1 − Π(1 − α), blended with
// (src α, 1 − src α). Reads the multisampled accumulation and revealage of preview_hair's
// `fs_oit`.

@group(0) @binding(0) var accumulation: texture_multisampled_2d<f32>;
@group(0) @binding(1) var revealage: texture_multisampled_2d<f32>;

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    // One triangle over the whole target.
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) position: vec4<f32>, @builtin(sample_index) sample: u32) -> @location(0) vec4<f32> {
    let texel = vec2<i32>(position.xy);
    let reveal = textureLoad(revealage, texel, i32(sample)).r;
    let accumulated = textureLoad(accumulation, texel, i32(sample));
    if reveal >= 0.9999 {
        discard;
    }
    let color = accumulated.rgb / max(accumulated.a, 1e-5);
    return vec4<f32>(color, 1.0 - reveal);
}
