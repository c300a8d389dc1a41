// viewport_blit: draws a rendered view into an egui paint callback's rectangle (the editor's
// viewport). egui sets the render pass viewport to the callback's rectangle, so one triangle
// over clip space fills it; the view's picture is stretched with linear filtering when it was
// drawn smaller (interactive frames).

@group(0) @binding(0) var picture: texture_2d<f32>;
@group(0) @binding(1) var linear_clamp: sampler;

struct Varyings {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> Varyings {
    // One triangle over the whole viewport; uv (0, 0) at its top-left.
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: Varyings;
    out.position = vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
    out.uv = vec2<f32>(corner.x, 1.0 - corner.y);
    return out;
}

@fragment
fn fs_main(in: Varyings) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSampleLevel(picture, linear_clamp, in.uv, 0.0).rgb, 1.0);
}
