// far_hair: seed 001's thick hairs drawn (render/src/renderer/far_hair.rs). Each thick hair
// as thick_main generated it this frame (strand_gen.wgsl: per vertex the centre with `along`
// in `positions`, two conjugate half-axes of its cross-section in `sections`, the member
// count in the first's w) is a viewer-facing ribbon as wide as its ellipse looks across the
// view (at least a strand, and at least `width.z` pixels with the coverage that leaves).
// A ribbon stands for many fibres with gaps between them: the share of the eye's rays that
// meet a fibre at `across` is 1 − exp(−hits), the hits a Poisson count over the ellipse's
// chord there (`thick_opacity`); the depth pre-pass and the shadow passes keep that share of
// each ribbon's fragments by a hashed alpha test stable per pixel (Wyman & McGuire 2017), so
// the lit pass shades each visible sample once with no sorting. Shading: the aggregated
// BCSDF (light/aggregated_bcsdf.wgsl `aggregated_cluster`) of the ellipse as seen in the
// fibre frame, with the opacity maps' fibres toward each light and the body's shadow, like
// the strands (preview_hair.wgsl). The scene, the shading and shadow modules are prepended
// by the composer (shader_composer.rs `far_hair_shader`); the lit pass is far_hair_lit.wgsl,
// the shadow passes' opacity far_hair_shadow.wgsl.

// Keep in sync with render/src/renderer/preview_hair.rs (`HairUniforms`): the same uniforms
// as the strands' ribbons, `batch` holding x: thick hairs, y: vertices per thick hair,
// z: shadow slot (shadow passes), w: unused.
struct FarView {
    view_projection: mat4x4<f32>,
    eye: vec4<f32>,
    // x: strand width at the root (m); y: world size of a pixel at unit distance (perspective)
    // or everywhere (orthographic); z: narrowest ribbon drawn, in pixels; w: unused.
    width: vec4<f32>,
    batch: vec4<u32>,
}

@group(0) @binding(0) var<uniform> far_view: FarView;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> sections: array<vec4<f32>>;

struct FarVertex {
    // Invariant: the depth pre-pass and the colour pass must compute the same depth.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) tangent: vec3<f32>,
    @location(2) along: f32,
    // −1 … 1 across the drawn ribbon.
    @location(3) across: f32,
    // Conjugate half-axes of the cross-section (m).
    @location(4) major: vec3<f32>,
    @location(5) minor: vec3<f32>,
    // x: member strands; y: share of the drawn width the ellipse covers (1 unless widened).
    @location(6) members_coverage: vec2<f32>,
    @location(7) @interpolate(flat) hair_index: u32,
}

fn far_safe_normalize(v: vec3<f32>) -> vec3<f32> {
    let length_squared = dot(v, v);
    if !(length_squared > 1e-24) {
        return vec3<f32>(0.0);
    }
    return v * inverseSqrt(length_squared);
}

fn far_toward_viewer(p: vec3<f32>) -> vec3<f32> {
    if far_view.eye.w == 0.0 {
        return far_view.eye.xyz;
    }
    return far_view.eye.xyz - p;
}

// Unit vector across the ribbon at a point with `tangent` seen from the viewer.
fn far_side(tangent: vec3<f32>, to_viewer: vec3<f32>) -> vec3<f32> {
    var side = cross(tangent, to_viewer);
    if dot(side, side) < 1e-20 {
        side = cross(tangent, vec3<f32>(0.0, 0.0, 1.0));
        if dot(side, side) < 1e-20 {
            side = cross(tangent, vec3<f32>(1.0, 0.0, 0.0));
        }
    }
    return normalize(side);
}

// Half-width (m) of the ellipse spanned by the conjugate half-axes `major`, `minor` across
// unit `side`.
fn half_width_across(major: vec3<f32>, minor: vec3<f32>, side: vec3<f32>) -> f32 {
    let a = dot(major, side);
    let b = dot(minor, side);
    return sqrt(a * a + b * b);
}

// A triangle list: two triangles per segment of every thick hair (6 vertices).
@vertex
fn vs_far(@builtin(vertex_index) vertex_index: u32) -> FarVertex {
    let n = max(far_view.batch.y, 2u);
    let segment_index = vertex_index / 6u;
    let hair_index = segment_index / (n - 1u);
    let segment = segment_index % (n - 1u);
    var ends = array<u32, 6>(0u, 1u, 0u, 0u, 1u, 1u);
    var sides = array<f32, 6>(-1.0, -1.0, 1.0, 1.0, -1.0, 1.0);
    let corner = vertex_index % 6u;
    let k = segment + ends[corner];
    let base = hair_index * n;
    let centre = positions[base + k];
    var tangent = far_safe_normalize(positions[base + min(k + 1u, n - 1u)].xyz
        - positions[base + max(k, 1u) - 1u].xyz);
    if dot(tangent, tangent) == 0.0 {
        tangent = vec3<f32>(0.0, 1.0, 0.0);
    }
    let major = sections[2u * (base + k)];
    let minor = sections[2u * (base + k) + 1u].xyz;
    let to_viewer = far_toward_viewer(centre.xyz);
    let side = far_side(tangent, to_viewer);
    // At least one strand wide, tapering as a strand does.
    let strand_half = 0.5 * far_view.width.x * (1.0 - 0.6 * centre.w);
    let half_width = max(half_width_across(major.xyz, minor, side), strand_half);
    var pixel = far_view.width.y;
    if far_view.eye.w != 0.0 {
        pixel = far_view.width.y * length(to_viewer);
    }
    let drawn = max(half_width, 0.5 * far_view.width.z * pixel);
    let world = centre.xyz + side * sides[corner] * drawn;
    var out: FarVertex;
    out.clip = far_view.view_projection * vec4<f32>(world, 1.0);
    out.world = world;
    out.tangent = tangent;
    out.along = centre.w;
    out.across = sides[corner];
    out.major = major.xyz;
    out.minor = minor;
    out.members_coverage = vec2<f32>(max(major.w, 1.0), select(1.0, half_width / drawn, drawn > 0.0));
    out.hair_index = hair_index;
    return out;
}

// The cross-section in the fibre frame (x the tangent, z toward the viewer, y = z × x) from
// conjugate half-axes: the ellipse's axes are the eigenvectors of Σ u uᵀ over the two
// projected half-axes, its semi-axes the roots of the eigenvalues. Returns (a, b, angle of
// the major axis from y toward z, area / π = a b), a and b at least `fibre_radius_m`.
fn far_section(major: vec3<f32>, minor: vec3<f32>, y: vec3<f32>, z: vec3<f32>, fibre_radius_m: f32) -> vec4<f32> {
    let u = vec2<f32>(dot(major, y), dot(major, z));
    let v = vec2<f32>(dot(minor, y), dot(minor, z));
    let syy = u.x * u.x + v.x * v.x;
    let szz = u.y * u.y + v.y * v.y;
    let syz = u.x * u.y + v.x * v.y;
    let mean = 0.5 * (syy + szz);
    let spread = sqrt(max(0.25 * (syy - szz) * (syy - szz) + syz * syz, 0.0));
    let a = max(sqrt(max(mean + spread, 0.0)), fibre_radius_m);
    let b = max(sqrt(max(mean - spread, 0.0)), fibre_radius_m);
    let angle = 0.5 * atan2(2.0 * syz, syy - szz);
    return vec4<f32>(a, b, angle, a * b);
}

// The share of the eye's rays at `across` (−1 … 1 over the ellipse's width) that meet one of
// `members` fibres of radius r spread evenly over an ellipse of half-width w across the view:
// hits along the chord are Poisson with mean 2 r N chord / (π a b), the chord 2 a b / w at the
// centre and √(1 − across²) of that elsewhere, so the mean is 4 r N √(1 − across²) / (π w).
fn thick_opacity(in: FarVertex) -> f32 {
    let r = 0.5 * far_view.width.x;
    let side = far_side(far_safe_normalize(in.tangent), far_toward_viewer(in.world));
    let w = max(half_width_across(in.major, in.minor, side), r);
    // The drawn ribbon is wider than the ellipse where widened to the narrowest width.
    let coverage = clamp(in.members_coverage.y, 0.0, 1.0);
    let t = clamp(in.across / max(coverage, 1e-6), -1.0, 1.0);
    let hits = 4.0 * r * in.members_coverage.x * sqrt(max(1.0 - t * t, 0.0)) / (3.14159265 * w);
    return select(0.0, 1.0 - exp(-hits), abs(in.across) <= coverage);
}

// A hash in [0, 1) of the pixel and the thick hair: the same threshold every frame for a
// still view (no shimmer), different for each hair (so two ribbons over one pixel do not
// cover the same subset).
fn far_alpha_threshold(pixel: vec2<f32>, hair_index: u32) -> f32 {
    var h = (u32(pixel.x) * 1973u) ^ (u32(pixel.y) * 9277u) ^ (hair_index * 26699u) ^ far_view.batch.z * 374761393u;
    h = h * 747796405u + 2891336453u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    h = (h >> 22u) ^ h;
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// The depth pre-pass: the share of the ribbon a real cluster's fibres cover.
@fragment
fn fs_far_depth(in: FarVertex) {
    if thick_opacity(in) <= far_alpha_threshold(in.clip.xy, in.hair_index) {
        discard;
    }
}

