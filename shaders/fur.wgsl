// fur: seed 002's shells and fins over the hair mesh's root faces (after the scene, shading
// and shadow modules). Shells are the root faces offset along each vertex's column (the
// seed's c_v, from the hair mesh) to height h, textured from the strand volume's shell layers
// through the lapped patches' coordinates; fins stand on the root edges along the columns,
// textured from the volume seen through a slab, faded in near the silhouette. Both are lit by
// the scene's hair shading with the strands' stored tangents.
// Structs: keep in sync with render/src/renderer/fur.rs (`FurUniforms`) and
// core/src/fur/base.rs (`FurColumnGpu`, `FurCornerGpu`, `FurFinGpu`). CPU mirrors of
// `shell_point` and `fin_fade`: core/src/fur/base.rs.

struct FurUniforms {
    view_projection: mat4x4<f32>,
    // xyz: the camera's position.
    eye: vec4<f32>,
    // x: shells drawn at this level, y: the level m, z: layers L at level 0, w: 1 when the next
    // coarser level exists.
    shells: vec4<u32>,
    // x: the share of the next coarser level blended in, y: how much fur shows against the
    // strands (1: shells only), z: the alpha test, w: fibres a ray crosses straight out
    // through the whole fur (self-shadowing).
    blend: vec4<f32>,
    // x: the tile's width in metres; y, z, w: unused.
    shape: vec4<f32>,
}

struct FurColumn {
    points: array<vec4<f32>, 4>,
    normal: vec4<f32>,
}

struct FurCorner {
    tangent: vec3<f32>,
    vertex: u32,
    uv: vec2<f32>,
    pad: vec2<f32>,
}

struct FurFin {
    vertices: vec2<u32>,
    u_start: f32,
    u_length: f32,
}

@group(0) @binding(0) var<uniform> fur: FurUniforms;
@group(0) @binding(1) var<storage, read> fur_columns: array<FurColumn>;
@group(0) @binding(2) var<storage, read> fur_corners: array<FurCorner>;
@group(0) @binding(3) var<storage, read> fur_fins: array<FurFin>;
@group(0) @binding(4) var shell_colour: texture_2d_array<f32>;
@group(0) @binding(5) var shell_direction: texture_2d_array<f32>;
@group(0) @binding(6) var fin_texture: texture_2d<f32>;
@group(0) @binding(7) var fur_sampler: sampler;
// The fin texture repeats along the edge but not from skin to tips.
@group(0) @binding(8) var fin_sampler: sampler;

struct FurVertex {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) uv: vec2<f32>,
    // The texture's u axis, across-axis and the fur's growth direction, in the world.
    @location(2) tangent: vec3<f32>,
    @location(3) growth: vec3<f32>,
    // x: height along the fur (0 skin, 1 tips), y: fade (fins).
    @location(4) height_fade: vec2<f32>,
    @location(5) @interpolate(flat) shell: u32,
    // The surface normal under the fur.
    @location(6) normal: vec3<f32>,
    // How far, in tiles, the shell above this one is shifted along the surface (combing).
    @location(7) shear_uv: vec2<f32>,
}

// The point at height h of a column, piecewise linear through its four points
// (mirror: base.rs `shell_point`).
fn shell_point(column: FurColumn, h: f32) -> vec3<f32> {
    let x = clamp(h, 0.0, 1.0) * 3.0;
    let i = min(u32(floor(x)), 2u);
    return mix(column.points[i].xyz, column.points[i + 1u].xyz, x - f32(i));
}

fn column_growth(column: FurColumn) -> vec3<f32> {
    let d = column.points[3].xyz - column.points[0].xyz;
    if dot(d, d) > 1e-20 {
        return normalize(d);
    }
    return column.normal.xyz;
}

// Seed 002 §2.3: max(0, 2|p| − 1), p the cosine between the fin's normal and the eye
// direction (mirror: base.rs `fin_fade`).
fn fin_fade(fin_normal: vec3<f32>, to_eye: vec3<f32>) -> f32 {
    let n = fin_normal * inverseSqrt(max(dot(fin_normal, fin_normal), 1e-30));
    let e = to_eye * inverseSqrt(max(dot(to_eye, to_eye), 1e-30));
    return max(0.0, 2.0 * abs(dot(n, e)) - 1.0);
}

// The first array layer of level m's shells: level j holds L >> j layers.
fn level_first(m: u32) -> u32 {
    let l = fur.shells.z;
    return 2u * l - 2u * (l >> m);
}

// Shell `instance` of the level drawn, at its height along every column (the innermost one
// lifted a little off the surface it lies on, so it does not fight the body's depth).
@vertex
fn vs_shell(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> FurVertex {
    let corner = fur_corners[vertex];
    let column = fur_columns[corner.vertex];
    let layers = f32(max(fur.shells.z, 2u) - 1u);
    let h = max(f32(instance << fur.shells.y), 0.1) / layers;
    let world = shell_point(column, h);
    var out: FurVertex;
    out.clip = fur.view_projection * vec4<f32>(world, 1.0);
    out.world = world;
    out.uv = corner.uv;
    out.tangent = corner.tangent;
    out.growth = column_growth(column);
    out.height_fade = vec2<f32>(h, 1.0);
    out.shell = instance;
    out.normal = column.normal.xyz;
    // The column's reach along the surface's texture axes over one shell spacing.
    let reach = (column.points[3].xyz - column.points[0].xyz) * (f32(1u << fur.shells.y) / layers);
    let x = corner.tangent;
    let y = cross(column.normal.xyz, x);
    out.shear_uv = vec2<f32>(dot(reach, x), dot(reach, y)) / max(fur.shape.x, 1e-9);
    return out;
}

// A fin: two triangles on base edge `instance`, from the roots to the tips of both columns;
// collapsed when it is faded out (seed 002 draws only the fins with non-zero alpha).
@vertex
fn vs_fin(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> FurVertex {
    let fin = fur_fins[instance];
    let a = fur_columns[fin.vertices.x];
    let b = fur_columns[fin.vertices.y];
    // Corners: (side, height) for two triangles.
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
    );
    let c = corners[vertex % 6u];
    let root_a = a.points[0].xyz;
    let root_b = b.points[0].xyz;
    let edge = root_b - root_a;
    let growth = normalize(column_growth(a) + column_growth(b) + vec3<f32>(0.0, 0.0, 1e-9));
    let middle = 0.5 * (root_a + root_b);
    let fade = fin_fade(cross(edge, growth), fur.eye.xyz - middle);
    var world = mix(shell_point(a, c.y), shell_point(b, c.y), c.x);
    var out: FurVertex;
    out.clip = fur.view_projection * vec4<f32>(world, 1.0);
    if fade <= 0.0 {
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
    }
    out.world = world;
    out.uv = vec2<f32>(fin.u_start + c.x * fin.u_length, c.y);
    out.tangent = normalize(edge + vec3<f32>(1e-9, 0.0, 0.0));
    out.growth = growth;
    out.height_fade = vec2<f32>(c.y, fade);
    out.shell = 0u;
    out.normal = normalize(a.normal.xyz + b.normal.xyz + vec3<f32>(0.0, 0.0, 1e-9));
    out.shear_uv = vec2<f32>(0.0);
    return out;
}

// Lit fur: the stored strand tangent (in the volume: x along the texture's u, y across it on
// the skin, z up) turned into the world as the shells place the volume — x and y along the
// surface, z sheared along the fur's growth (seed 002's combing) — and shaded by the scene's
// hair model, with the opacity maps' and the body's shadows and Banks' darkening toward the
// skin.
fn shade_fur(in: FurVertex, local_tangent: vec3<f32>, tint: f32) -> vec4<f32> {
    let n = in.normal * inverseSqrt(max(dot(in.normal, in.normal), 1e-20));
    var x = in.tangent - n * dot(in.tangent, n);
    x = x * inverseSqrt(max(dot(x, x), 1e-20));
    let y = cross(n, x);
    let z = in.growth * inverseSqrt(max(dot(in.growth, in.growth), 1e-20));
    let tangent = local_tangent.x * x + local_tangent.y * y + local_tangent.z * z;
    let wo = normalize(fur.eye.xyz - in.world);
    let frame = fibre_frame(tangent, wo);
    let wo_local = vec3<f32>(dot(wo, frame[0]), dot(wo, frame[1]), dot(wo, frame[2]));
    let sigma_a = strand_sigma_a(in.height_fade.x, 0.5);
    // Banks' self-shadowing with the material's own attenuation: the fibres between this
    // depth and the fur's top along a light at angle θ to the surface are
    // `(1 − h) · fibres_through / cos θ` (`fibres_through`: the fibres a ray crosses going
    // straight out through the whole fur, from the strands' density, width and length), each
    // passing the material's forward transmittance, as the opacity maps count them for strands.
    let above = (1.0 - clamp(in.height_fade.x, 0.0, 1.0)) * fur.blend.w;
    var radiance = scene.ambient.rgb * hair_color(sigma_a)
        * pow(scene.forward_transmittance.rgb, vec3<f32>(above));
    for (var i = 0u; i < scene.counts.x; i++) {
        let wi = light_direction(i, in.world);
        let slot = light_shadow_slot(i);
        let through_fur = above / max(dot(wi, n), 0.15);
        let crossed = hairs_in_front(in.world, slot) + through_fur;
        let visible = body_visibility(in.world, slot);
        let wi_local = vec3<f32>(dot(wi, frame[0]), dot(wi, frame[1]), dot(wi, frame[2]));
        let single = hair_single(wo_local, wi_local, 0.0, sigma_a, i);
        radiance += hair_radiance(wo_local, wi_local, single, crossed) * light_irradiance(i, in.world) * visible;
    }
    return vec4<f32>(tonemap(radiance * tint), 1.0);
}

// Shell `shell` of level `m` blended toward level `m + 1` by `t` (seed 002 §2.4: the
// coarser level's even shells take both of a pair, its odd ones are empty; blending toward it
// as the fur recedes, then dropping the odd shells, never pops), sampled with gradients `g`.
fn shell_texel(uv: vec2<f32>, shell: u32, g: vec4<f32>) -> vec4<f32> {
    let m = fur.shells.y;
    let fine = textureSampleGrad(shell_colour, fur_sampler, uv, level_first(m) + shell, g.xy, g.zw);
    let coarse_layer = level_first(min(m + 1u, 6u)) + shell / 2u;
    var coarse = textureSampleGrad(shell_colour, fur_sampler, uv, coarse_layer, g.xy, g.zw);
    if shell % 2u == 1u || fur.shells.w == 0u {
        coarse = vec4<f32>(0.0);
    }
    let t = select(0.0, fur.blend.x, fur.shells.w == 1u);
    let premultiplied = mix(fine.rgb * fine.a, coarse.rgb * coarse.a, t);
    let alpha = mix(fine.a, coarse.a, t);
    return vec4<f32>(premultiplied / max(alpha, 1e-6), alpha);
}

// Taps along a shell's shear: combed fur leans, so a strand climbing from this shell to the
// next crosses the surface by `shear_uv`; seen from outside it is a dash that long, not the dot
// the tall filter leaves on each shell (which only reads as a strand when shells stack
// straight up). The dash is the union of the strand's pieces within half a spacing.
const SHEAR_TAPS: u32 = 6u;

@fragment
fn fs_shell(in: FurVertex) -> @location(0) vec4<f32> {
    let g = vec4<f32>(dpdx(in.uv), dpdy(in.uv));
    var texel = vec4<f32>(0.0);
    for (var k = 0u; k < SHEAR_TAPS; k++) {
        let offset = (f32(k) + 0.5) / f32(SHEAR_TAPS) - 0.5;
        let tap = shell_texel(in.uv - offset * in.shear_uv, in.shell, g);
        if tap.a > texel.a {
            texel = tap;
        }
    }
    let stored = textureSampleGrad(shell_direction, fur_sampler, in.uv, in.shell << fur.shells.y, g.xy, g.zw).xyz * 2.0 - 1.0;
    let alpha = texel.a * fur.blend.y;
    if alpha < fur.blend.z {
        discard;
    }
    let lit = shade_fur(in, stored, texel.r);
    return vec4<f32>(lit.rgb, alpha);
}

@fragment
fn fs_fin(in: FurVertex) -> @location(0) vec4<f32> {
    // Row 0 of the fin texture is the skin, as v = 0 is here.
    let texel = textureSample(fin_texture, fin_sampler, in.uv);
    let alpha = texel.a * in.height_fade.y * fur.blend.y;
    if alpha < fur.blend.z {
        discard;
    }
    // Fin strands run up the fin: along the growth, leaning along the edge.
    let lit = shade_fur(in, vec3<f32>(0.2, 0.0, 1.0), texel.r);
    return vec4<f32>(lit.rgb, alpha);
}
