// strand_vertex: one styled strand vertex from the five runtime textures (seed 000
// §3.1-3.4), shared by the compute generation (strand_gen.wgsl) and generation in the ribbon
// vertex shader (shared/ribbon_generated.wgsl). WGSL has no #include: render/src/ prepends
// this file; the including shader declares the globals it reads — `params`, `bundles`,
// `samples`, `styling`, `hair_mesh`, `uv_texture`, `u_texture`, `v_texture`, `w_texture`,
// `root_maps`, `linear_clamp` — at its own bindings.
// CPU mirror: core/src/runtime/strand_gen.rs (`fetch`, `StrandGen::strand_position`,
// `strand_root`, `StrandGen::strand_input`, `StrandGen::styled_vertex`).
// Structs: keep in sync with core/src/runtime/gpu_types.rs.

struct StrandGenParams {
    position_offset: vec4<f32>,
    vertex_total: u32,
    run_count: u32,
    filtering: u32,
    first_run: u32,
    per_bundle: u32,
    sample_set: u32,
    strand_total: u32,
    _padding: u32,
}

struct BundleGpu {
    origin_texel: vec2<f32>,
    layers: u32,
    styling: u32,
    rotation: u32,
    triangle: u32,
    _padding: vec2<u32>,
}

// struct StrandRun: shaders/shared/strand_run.wgsl, prepended by render/src/.

struct StrandRoot {
    texel: vec2<f32>,
    centre_texel: vec2<f32>,
    layers: u32,
    styling: u32,
    // (j + ½) / N: the root's place in its bundle's progressive sample set (the hairline
    // op thins by it).
    rank: f32,
    _padding: u32,
}

struct Styling {
    curl_radius_m: f32,
    curl_turns_per_m: f32,
    curl_ramp_in_m: f32,
    curl_radius_jitter: f32,
    twist_turns_per_m: f32,
    noise_amplitude_m: f32,
    noise_frequency_per_m: f32,
    noise_octaves: u32,
    clump_strength: f32,
    clump_clumps_per_uv: f32,
    clump_radius_m: f32,
    clump_tightening: f32,
    frizz_amplitude_m: f32,
    frizz_frequency_per_m: f32,
    frizz_fraction: f32,
    length_fraction: f32,
    wave_amplitude_m: f32,
    wave_frequency_per_m: f32,
    wave_direction_rad: f32,
    wave_phase_spread: f32,
    wave_ramp_in_m: f32,
    variation_per_uv: f32,
    seed: u32,
    curl_clump_coherence: f32,
    curl_radius_tip_scale: f32,
    curl_rate_tip_scale: f32,
    clump_sub_strength: f32,
    clump_sub_clumps_per_uv: f32,
    clump_sub_radius_m: f32,
    wave_clump_coherence: f32,
    stray_fraction: f32,
    stray_amplitude_m: f32,
    stray_frequency_per_m: f32,
    stray_length_min: f32,
    hairline_width_m: f32,
    hairline_edge_density: f32,
    hairline_edge_length: f32,
    wave_lock_phase_spread: f32,
    _padding0: u32,
    _padding1: u32,
}

// Mirror: SLICES_PER_SEGMENT in core/src/runtime/textures.rs (p_k, q0, q1 per segment).
const SLICES_PER_SEGMENT: u32 = 3u;
const FILTERING_EXACT: u32 = 0u;
// One turn in radians (2π; light/hair_bsdf.wgsl has its own TAU).
const TURN_RAD: f32 = 6.283185307179586;
// Mirror: NOISE_KEY_SPAN in core/src/strands/styling.rs.
const NOISE_KEY_SPAN: f32 = 16.0;
// Mirror: CLUMP_CHANNEL and SUB_CLUMP_CHANNEL in core/src/strands/styling.rs.
const CLUMP_CHANNEL: u32 = 40u;
const SUB_CLUMP_CHANNEL: u32 = 42u;

// Trilinear filtering in f32 with textureLoad: the "exact" switch (mirror: sample_trilinear
// with Filtering::Exact). Texel centres sit at i + 0.5; clamp to the edge.
fn fetch_exact(texture: texture_3d<f32>, coord: vec3<f32>) -> vec4<f32> {
    let size = vec3<i32>(textureDimensions(texture));
    let x = clamp(coord - vec3<f32>(0.5), vec3<f32>(0.0), vec3<f32>(size - vec3<i32>(1)));
    let i0 = min(vec3<i32>(floor(x)), max(size - vec3<i32>(2), vec3<i32>(0)));
    let f = x - vec3<f32>(i0);
    let i1 = min(i0 + vec3<i32>(1), size - vec3<i32>(1));
    let c000 = textureLoad(texture, vec3<i32>(i0.x, i0.y, i0.z), 0);
    let c100 = textureLoad(texture, vec3<i32>(i1.x, i0.y, i0.z), 0);
    let c010 = textureLoad(texture, vec3<i32>(i0.x, i1.y, i0.z), 0);
    let c110 = textureLoad(texture, vec3<i32>(i1.x, i1.y, i0.z), 0);
    let c001 = textureLoad(texture, vec3<i32>(i0.x, i0.y, i1.z), 0);
    let c101 = textureLoad(texture, vec3<i32>(i1.x, i0.y, i1.z), 0);
    let c011 = textureLoad(texture, vec3<i32>(i0.x, i1.y, i1.z), 0);
    let c111 = textureLoad(texture, vec3<i32>(i1.x, i1.y, i1.z), 0);
    let bottom0 = c000 + (c100 - c000) * f.x;
    let top0 = c010 + (c110 - c010) * f.x;
    let plane0 = bottom0 + (top0 - bottom0) * f.y;
    let bottom1 = c001 + (c101 - c001) * f.x;
    let top1 = c011 + (c111 - c011) * f.x;
    let plane1 = bottom1 + (top1 - bottom1) * f.y;
    return plane0 + (plane1 - plane0) * f.z;
}

// The painted maps at root uv `uv`: (density, length, clump, _) shares, bilinear between
// texel centres, clamped at the edges (mirror: RootMaps::sample). With nothing painted the
// texture is one white texel: 1 everywhere.
fn root_map_values(uv: vec2<f32>) -> vec4<f32> {
    let size = vec2<i32>(textureDimensions(root_maps));
    var x = clamp(uv * vec2<f32>(size) - vec2<f32>(0.5), vec2<f32>(0.0), vec2<f32>(size - vec2<i32>(1)));
    // A NaN uv reads texel (0, 0), as the mirror does.
    x = select(x, vec2<f32>(0.0), x != x);
    let i0 = min(vec2<i32>(floor(x)), size - vec2<i32>(1));
    let f = x - vec2<f32>(i0);
    let i1 = min(i0 + vec2<i32>(1), size - vec2<i32>(1));
    let c00 = textureLoad(root_maps, vec2<i32>(i0.x, i0.y), 0);
    let c10 = textureLoad(root_maps, vec2<i32>(i1.x, i0.y), 0);
    let c01 = textureLoad(root_maps, vec2<i32>(i0.x, i1.y), 0);
    let c11 = textureLoad(root_maps, vec2<i32>(i1.x, i1.y), 0);
    let bottom = c00 + (c10 - c00) * f.x;
    let top = c01 + (c11 - c01) * f.x;
    return bottom + (top - bottom) * f.y;
}

// The share of its length a strand of rank `rank` keeps under the maps: 0 where the density
// map does not grow it (mirror: RootMapValues::length_scale).
fn root_map_length_scale(maps: vec4<f32>, rank: f32) -> f32 {
    return select(0.0, maps.y, rank < maps.x);
}

// The filtering switch: exact (manual, f32 weights) or the texture unit's (8-bit weights).
fn fetch(texture: texture_3d<f32>, coord: vec3<f32>) -> vec4<f32> {
    if params.filtering == FILTERING_EXACT {
        return fetch_exact(texture, coord);
    }
    let size = vec3<f32>(textureDimensions(texture));
    return textureSampleLevel(texture, linear_clamp, coord / size, 0.0);
}

// Where the two hair-mesh fetches of curve parameter tau sit: (z_a, z_b, q), the point being
// mix(fetch(z_a), fetch(z_b), q). The quadratics' joint m = (q0 + q1) / 2 is not stored: it is
// the fetch half-way between slices 3k+1 (q0) and 3k+2 (q1). Mirror: curve_fetch_slices in
// core/src/runtime/textures.rs.
fn curve_fetch_slices(layers: u32, tau_in: f32) -> vec3<f32> {
    let layer_count = max(layers, 1u);
    let tau = clamp(tau_in, 0.0, f32(layer_count));
    let segment = min(u32(floor(tau)), layer_count - 1u);
    let local = tau - f32(segment);
    let base = f32(SLICES_PER_SEGMENT * segment);
    if local < 0.5 {
        let q = local * 2.0;
        return vec3<f32>(base + q, base + 1.0 + 0.5 * q, q);
    }
    let q = local * 2.0 - 1.0;
    return vec3<f32>(base + 1.5 + 0.5 * q, base + 2.0 + q, q);
}

// Mirror: StrandGen::strand_position.
fn strand_position(texel: vec2<f32>, layers: u32, tau: f32) -> vec3<f32> {
    let slices = curve_fetch_slices(layers, tau);
    let a = fetch(hair_mesh, vec3<f32>(texel, slices.x + 0.5)).xyz;
    let b = fetch(hair_mesh, vec3<f32>(texel, slices.y + 0.5)).xyz;
    return a + (b - a) * slices.z + params.position_offset.xyz;
}

// --- Deterministic randomness (mirror: core/src/strands/random.rs, core/src/strands/styling.rs) ---

fn pcg_hash(value: u32) -> u32 {
    let state = value * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

fn hash3(a: u32, b: u32, c: u32) -> u32 {
    return pcg_hash(pcg_hash(pcg_hash(0x6A09E667u ^ a) ^ b) ^ c);
}

fn hash4(a: u32, b: u32, c: u32, d: u32) -> u32 {
    return pcg_hash(hash3(a, b, c) ^ d);
}

fn hash_to_unit(hash: u32) -> f32 {
    return f32(hash >> 8u) * (1.0 / 16777216.0);
}

fn fade(t: f32) -> f32 {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

// Float cell index to the u32 the CPU gets from `as i64 as u32`.
fn cell_index(cell: f32) -> u32 {
    return bitcast<u32>(i32(cell));
}

fn value_noise_2d(p: vec2<f32>, seed: u32, channel: u32) -> f32 {
    let cell = floor(p);
    let f = p - cell;
    let ix = cell_index(cell.x);
    let iy = cell_index(cell.y);
    let l00 = hash_to_unit(hash4(seed, channel, ix, iy));
    let l10 = hash_to_unit(hash4(seed, channel, ix + 1u, iy));
    let l01 = hash_to_unit(hash4(seed, channel, ix, iy + 1u));
    let l11 = hash_to_unit(hash4(seed, channel, ix + 1u, iy + 1u));
    let fx = fade(f.x);
    let fy = fade(f.y);
    let bottom = l00 + (l10 - l00) * fx;
    let top = l01 + (l11 - l01) * fx;
    return bottom + (top - bottom) * fy;
}

fn value_noise_1d(x: f32, seed: u32, channel: u32) -> f32 {
    let cell = floor(x);
    let f = fade(x - cell);
    let i = cell_index(cell);
    let l0 = hash_to_unit(hash3(seed, channel, i)) * 2.0 - 1.0;
    let l1 = hash_to_unit(hash3(seed, channel, i + 1u)) * 2.0 - 1.0;
    return l0 + (l1 - l0) * f;
}

fn strand_random(s: Styling, root_uv: vec2<f32>, channel: u32) -> f32 {
    return value_noise_2d(root_uv * s.variation_per_uv, s.seed, channel);
}

fn ramp(edge: f32, x: f32) -> f32 {
    if edge <= 0.0 {
        return select(0.0, 1.0, x > 0.0);
    }
    let t = clamp(x / edge, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// Mirror: styling::strand_cell_random (uniform, constant over a random-value cell).
fn strand_cell_random(s: Styling, root_uv: vec2<f32>, channel: u32) -> f32 {
    let p = root_uv * s.variation_per_uv;
    return hash_to_unit(hash4(s.seed, channel, cell_index(floor(p.x)), cell_index(floor(p.y))));
}

fn unit_phase(angle_rad: f32) -> vec2<f32> {
    return vec2<f32>(cos(angle_rad), sin(angle_rad));
}

// The jittered centre of lattice cell c (mirror: styling::for_each_centre).
fn clump_centre(c: vec2<f32>, seed: u32, channel: u32) -> vec2<f32> {
    let ix = cell_index(c.x);
    let iy = cell_index(c.y);
    return c + vec2<f32>(
        hash_to_unit(hash4(seed, channel, ix, iy)),
        hash_to_unit(hash4(seed, channel + 1u, ix, iy)),
    );
}

// Mirror: styling::clump_pull_on.
fn clump_pull(x: vec2<f32>, seed: u32, channel: u32) -> vec2<f32> {
    let cell = floor(x);
    var weighted = vec2<f32>(0.0);
    var total = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let c = cell + vec2<f32>(f32(dx), f32(dy));
            let d = clump_centre(c, seed, channel) - x;
            let k = max(1.0 - dot(d, d), 0.0);
            weighted += k * k * d;
            total += k * k;
        }
    }
    return weighted / (total + 0.25);
}

// Mirror: styling::lock_phase (the main clump lattice's centres).
fn lock_phase(x: vec2<f32>, seed: u32, channel: u32, spread: f32) -> vec2<f32> {
    let cell = floor(x);
    var weighted = vec2<f32>(0.0);
    var total = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let c = cell + vec2<f32>(f32(dx), f32(dy));
            let d = clump_centre(c, seed, CLUMP_CHANNEL) - x;
            let k = max(1.0 - dot(d, d), 0.0);
            let angle = hash_to_unit(hash4(seed, channel, cell_index(c.x), cell_index(c.y)));
            weighted += k * k * unit_phase(spread * TURN_RAD * angle);
            total += k * k;
        }
    }
    return weighted / (total + 0.25);
}

// Mirror: styling::blend_phase.
fn blend_phase(own: vec2<f32>, coherence: f32, lock: vec2<f32>) -> vec2<f32> {
    let c = min(coherence, 1.0);
    let e = own * (1.0 - c) + lock * c;
    return e / max(length(e), 0.5);
}

// e · exp(i angle) (mirror: styling::rotate).
fn rotate_phase(e: vec2<f32>, angle_rad: f32) -> vec2<f32> {
    let c = cos(angle_rad);
    let s = sin(angle_rad);
    return vec2<f32>(e.x * c - e.y * s, e.x * s + e.y * c);
}

// What the styling ops need of a strand that does not change along it (mirror:
// styling::StrandStyling): random phases, keys and the clump pulls, seeded by the root uv.
struct StrandConstants {
    curl_phase: vec2<f32>,
    curl_radius_m: f32,
    noise_key_u: f32,
    noise_key_v: f32,
    clump_pull: vec2<f32>,
    sub_clump_pull: vec2<f32>,
    frizz: bool,
    frizz_key: f32,
    wave_phase: vec2<f32>,
    stray: bool,
    stray_direction: vec2<f32>,
    stray_key: f32,
}

// Mirror: StrandStyling::new.
fn strand_constants(s: Styling, root_uv: vec2<f32>) -> StrandConstants {
    var c: StrandConstants;
    let lock_uv = root_uv * max(s.clump_clumps_per_uv, 1.0);
    c.stray = s.stray_fraction > 0.0 && strand_cell_random(s, root_uv, 9u) < s.stray_fraction;
    if s.curl_radius_m != 0.0 {
        c.curl_phase = unit_phase(TURN_RAD * strand_random(s, root_uv, 1u));
        if s.curl_clump_coherence > 0.0 {
            c.curl_phase = blend_phase(
                c.curl_phase,
                s.curl_clump_coherence,
                lock_phase(lock_uv, s.seed, 44u, 1.0),
            );
        }
        c.curl_radius_m = s.curl_radius_m
            * (1.0 + s.curl_radius_jitter * (2.0 * strand_random(s, root_uv, 2u) - 1.0));
    }
    if s.noise_amplitude_m != 0.0 {
        c.noise_key_u = NOISE_KEY_SPAN * strand_random(s, root_uv, 3u);
        c.noise_key_v = NOISE_KEY_SPAN * strand_random(s, root_uv, 4u);
    }
    if !c.stray && s.clump_strength != 0.0 && s.clump_clumps_per_uv > 0.0 {
        c.clump_pull = clump_pull(lock_uv, s.seed, CLUMP_CHANNEL);
    }
    if !c.stray && s.clump_sub_strength != 0.0 && s.clump_sub_clumps_per_uv > 0.0 {
        c.sub_clump_pull =
            clump_pull(root_uv * s.clump_sub_clumps_per_uv, s.seed, SUB_CLUMP_CHANNEL);
    }
    if s.frizz_amplitude_m != 0.0
        && (c.stray || strand_random(s, root_uv, 6u) < s.frizz_fraction) {
        c.frizz = true;
        c.frizz_key = NOISE_KEY_SPAN * strand_random(s, root_uv, 7u);
    }
    if s.wave_amplitude_m != 0.0 {
        c.wave_phase = unit_phase(s.wave_phase_spread * TURN_RAD * strand_random(s, root_uv, 8u));
        if s.wave_clump_coherence > 0.0 {
            c.wave_phase = blend_phase(
                c.wave_phase,
                s.wave_clump_coherence,
                lock_phase(lock_uv, s.seed, 45u, s.wave_lock_phase_spread),
            );
        }
    }
    if c.stray && s.stray_amplitude_m != 0.0 {
        c.stray_direction = unit_phase(TURN_RAD * strand_cell_random(s, root_uv, 11u));
        c.stray_key = NOISE_KEY_SPAN * strand_cell_random(s, root_uv, 12u);
    }
    return c;
}

// Mirror: styling::strand_length_fraction.
fn strand_length_fraction(s: Styling, root_uv: vec2<f32>) -> f32 {
    var fraction = 1.0;
    if s.length_fraction > 0.0 {
        fraction -= s.length_fraction * strand_random(s, root_uv, 5u);
    }
    if s.stray_fraction > 0.0 && strand_cell_random(s, root_uv, 9u) < s.stray_fraction {
        fraction *= s.stray_length_min
            + (1.0 - s.stray_length_min) * strand_cell_random(s, root_uv, 10u);
    }
    return fraction;
}

// Mirror: styling::hairline_length_scale (0: the strand does not grow).
fn hairline_length_scale(s: Styling, distance: f32, rank: f32) -> f32 {
    if !(s.hairline_width_m > 0.0) {
        return 1.0;
    }
    let x = ramp(s.hairline_width_m, max(distance, 0.0));
    let density = 1.0 - (1.0 - s.hairline_edge_density) * (1.0 - x);
    if !(rank < density) {
        return 0.0;
    }
    return 1.0 - (1.0 - s.hairline_edge_length) * (1.0 - x);
}

// Mirror: styling::styling_offset_of (without twist).
fn styling_offset(
    s: Styling,
    c: StrandConstants,
    u: vec3<f32>,
    v: vec3<f32>,
    w: f32,
    along: f32,
) -> vec3<f32> {
    if along <= 0.0 || w <= 0.0 {
        return vec3<f32>(0.0);
    }
    var offset = vec3<f32>(0.0);
    if s.curl_radius_m != 0.0 {
        let rate = 1.0 + (s.curl_rate_tip_scale - 1.0) * along * 0.5;
        let turned = rotate_phase(c.curl_phase, TURN_RAD * s.curl_turns_per_m * w * rate);
        let radius = c.curl_radius_m * (1.0 + (s.curl_radius_tip_scale - 1.0) * along);
        offset += ramp(s.curl_ramp_in_m, w) * radius * (turned.x * u + turned.y * v);
    }
    if s.noise_amplitude_m != 0.0 {
        var nu = 0.0;
        var nv = 0.0;
        var gain = 1.0;
        var frequency = s.noise_frequency_per_m;
        for (var octave = 0u; octave < max(s.noise_octaves, 1u); octave++) {
            nu += gain * value_noise_1d(frequency * w + c.noise_key_u, s.seed, 10u + octave);
            nv += gain * value_noise_1d(frequency * w + c.noise_key_v, s.seed, 20u + octave);
            gain *= 0.5;
            frequency *= 2.0;
        }
        offset += s.noise_amplitude_m * along * (nu * u + nv * v);
    }
    if (s.clump_strength != 0.0 || s.clump_sub_strength != 0.0) && !c.stray {
        let profile = pow(along, s.clump_tightening);
        let pull = c.clump_pull * (s.clump_strength * s.clump_radius_m)
            + c.sub_clump_pull * (s.clump_sub_strength * s.clump_sub_radius_m);
        offset += profile * (pull.x * u + pull.y * v);
    }
    if s.frizz_amplitude_m != 0.0 && c.frizz {
        let a = value_noise_1d(s.frizz_frequency_per_m * w + c.frizz_key, s.seed, 30u);
        let b = value_noise_1d(s.frizz_frequency_per_m * w + c.frizz_key + 500.0, s.seed, 31u);
        offset += s.frizz_amplitude_m * along * along * (a * u + b * v);
    }
    if s.wave_amplitude_m != 0.0 {
        let turned = rotate_phase(c.wave_phase, TURN_RAD * s.wave_frequency_per_m * w);
        let direction = cos(s.wave_direction_rad) * u + sin(s.wave_direction_rad) * v;
        offset += ramp(s.wave_ramp_in_m, w) * s.wave_amplitude_m * turned.y * direction;
    }
    if s.stray_amplitude_m != 0.0 && c.stray {
        let a = value_noise_1d(s.stray_frequency_per_m * w + c.stray_key, s.seed, 50u);
        let b = value_noise_1d(s.stray_frequency_per_m * w + c.stray_key + 500.0, s.seed, 51u);
        let drift = c.stray_direction + 0.5 * vec2<f32>(a, b);
        offset += s.stray_amplitude_m * along * along * (drift.x * u + drift.y * v);
    }
    return offset;
}

// Mirror: frames::fallback_frame(n).v (a unit vector perpendicular to n).
fn perpendicular(n: vec3<f32>) -> vec3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(b, sign + n.y * n.y * a, -n.y);
}

fn normalize_or(x: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let length_squared = dot(x, x);
    if !(length_squared > 1e-30) {
        return fallback;
    }
    return x * inverseSqrt(length_squared);
}

// Mirror: styling::apply_twist (Rodrigues about the bundle's centre strand).
fn twist(s: Styling, p: vec3<f32>, centre: vec3<f32>, axis: vec3<f32>, w: f32) -> vec3<f32> {
    if s.twist_turns_per_m == 0.0 || w <= 0.0 {
        return p;
    }
    let angle = TURN_RAD * s.twist_turns_per_m * w;
    let o = p - centre;
    let c = cos(angle);
    let sn = sin(angle);
    return centre + o * c + cross(axis, o) * sn + axis * dot(axis, o) * (1.0 - c);
}

// Mirror: runtime::strand_root (Atlas::sample_block_coords).
fn strand_root(root_index: u32) -> StrandRoot {
    let bundle = bundles[root_index / params.per_bundle];
    let sample_index = root_index % params.per_bundle;
    var coords: vec2<f32>;
    var centre: vec2<f32>;
    if bundle.triangle != 0u {
        // Barycentric (s, t) to block coordinates (s / (1 − t), t).
        let sample = samples[params.sample_set + sample_index];
        let denominator = 1.0 - sample.y;
        var s = 0.0;
        if denominator > 0.0 {
            s = clamp(sample.x / denominator, 0.0, 1.0);
        }
        coords = vec2<f32>(s, sample.y);
        centre = vec2<f32>(0.5, 1.0 / 3.0);
    } else {
        // `rotation` quarter turns (s, t) ↦ (t, 1 − s).
        coords = samples[sample_index];
        for (var turn = 0u; turn < bundle.rotation; turn++) {
            coords = vec2<f32>(coords.y, 1.0 - coords.x);
        }
        centre = vec2<f32>(0.5, 0.5);
    }
    var root: StrandRoot;
    root.texel = bundle.origin_texel + coords;
    root.centre_texel = bundle.origin_texel + centre;
    root.layers = bundle.layers;
    root.styling = bundle.styling;
    root.rank = (f32(sample_index) + 0.5) / f32(params.per_bundle);
    return root;
}

struct StrandInput {
    root: StrandRoot,
    style: Styling,
    root_uv: vec2<f32>,
    length_fraction: f32,
    constants: StrandConstants,
    // The painted length map's share (1 without maps): a cut strand's styling reads
    // along · cut, the first part of the strand it would be.
    cut: f32,
}

// What every vertex of root `root_index`'s strand shares (mirror: StrandGen::strand_input).
fn strand_input(root_index: u32) -> StrandInput {
    let root = strand_root(root_index);
    var style_index = root.styling;
    if style_index >= arrayLength(&styling) {
        style_index = 0u;
    }
    var input: StrandInput;
    input.root = root;
    input.style = styling[style_index];
    // Root uv: always exact (it seeds every per-strand random value).
    input.root_uv = fetch_exact(uv_texture, vec3<f32>(root.texel, 0.5)).xy;
    // The root slice's fourth channel: the root's distance to the border of the hair
    // (always exact: it decides whether the strand grows).
    let hairline_distance = fetch_exact(hair_mesh, vec3<f32>(root.texel, 0.5)).w;
    // The painted maps at the root (exact too: density decides whether it grows).
    let maps = root_map_values(input.root_uv);
    input.length_fraction = strand_length_fraction(input.style, input.root_uv)
        * hairline_length_scale(input.style, hairline_distance, root.rank)
        * root_map_length_scale(maps, root.rank);
    input.constants = strand_constants(input.style, input.root_uv);
    input.constants.clump_pull *= maps.z;
    input.constants.sub_clump_pull *= maps.z;
    input.cut = maps.y;
    return input;
}

// Vertex k of n of a styled strand (mirror: StrandGen::styled_vertex).
fn styled_vertex(input: StrandInput, k: u32, n: u32) -> vec3<f32> {
    let root = input.root;
    let s = input.style;
    let along = f32(k) / f32(n - 1u);
    let tau = f32(root.layers) * input.length_fraction * along;
    var p = strand_position(root.texel, root.layers, tau);
    // A strand that does not grow (hairline) lies at its root: nothing is drawn.
    if k == 0u || input.length_fraction <= 0.0 {
        return p;
    }
    let layer_coord = vec3<f32>(root.texel, tau + 0.5);
    let u = normalize_or(fetch(u_texture, layer_coord).xyz, vec3<f32>(1.0, 0.0, 0.0));
    let v = normalize_or(fetch(v_texture, layer_coord).xyz, vec3<f32>(0.0, 1.0, 0.0));
    let w_axis = normalize_or(cross(u, v), perpendicular(u));
    let w = fetch(w_texture, layer_coord).x;
    if s.twist_turns_per_m != 0.0 {
        let centre = strand_position(root.centre_texel, root.layers, tau);
        p = twist(s, p, centre, w_axis, w);
    }
    return p + styling_offset(s, input.constants, u, v, w, along * input.cut);
}

fn along_of(k: u32, n: u32) -> f32 {
    return f32(k) / f32(n - 1u);
}

// Vertex k with the run's vertex LOD: an odd vertex slides toward its (unmorphed)
// neighbours' midpoint by γ (eq. 11; mirror: strands::lod::morph_odd_vertices).
fn morphed_vertex(input: StrandInput, k: u32, n: u32, gamma: f32) -> vec3<f32> {
    let p = styled_vertex(input, k, n);
    if gamma > 0.0 && k % 2u == 1u && k + 1u < n {
        let middle = 0.5 * (styled_vertex(input, k - 1u, n) + styled_vertex(input, k + 1u, n));
        return mix(p, middle, gamma);
    }
    return p;
}
