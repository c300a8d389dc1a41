// Ribbons from strand vertices (group 0), shared by the hair's colour pass
// (preview_hair.wgsl) and its shadow passes (hair_shadow.wgsl). Vertices sit in `positions`
// as the batch's runs lay them out (`run.vertex_offset + strand * run.vertex_count + k`,
// w = fraction along the strand); each segment is two triangles (6 vertices) facing the
// viewer. Tangents follow eq. 5-6 (ends mirror their neighbour about the end segment), so
// shading holds when vertex LOD changes counts; width grows by the run's thickness factor
// (eq. 8 compensation) and tapers toward the tip. A ribbon narrower than `width.z` pixels is
// drawn that wide with its true coverage (width-based coverage and the shadow passes).
// Structs: keep in sync with render/src/renderer/preview_hair.rs (`HairUniforms`);
// `StrandRun` is in shaders/shared/strand_run.wgsl.

struct HairUniforms {
    view_projection: mat4x4<f32>,
    // xyz: the viewer's position (w = 1), or the unit direction toward an orthographic
    // viewer (w = 0: a directional light's shadow view).
    eye: vec4<f32>,
    // x: ribbon width at the root (m); y: world size of a pixel at unit distance
    // (perspective) or everywhere (orthographic); z: narrowest ribbon drawn, in pixels
    // (0: as wide as the strand); w: unused.
    width: vec4<f32>,
    // x, y: the batch's runs, runs[x .. x + y]; z: shadow slot (shadow passes); w: unused.
    batch: vec4<u32>,
}

@group(0) @binding(0) var<uniform> hair: HairUniforms;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> runs: array<StrandRun>;

// The run holding batch segment `segment` (binary search).
fn find_run(segment: u32) -> u32 {
    var low = hair.batch.x;
    var high = hair.batch.x + max(hair.batch.y, 1u) - 1u;
    while low < high {
        let middle = (low + high + 1u) / 2u;
        if runs[middle].segment_offset <= segment {
            low = middle;
        } else {
            high = middle - 1u;
        }
    }
    return low;
}

fn safe_normalize(v: vec3<f32>) -> vec3<f32> {
    let length_squared = dot(v, v);
    if !(length_squared > 1e-24) {
        return vec3<f32>(0.0);
    }
    return v * inverseSqrt(length_squared);
}

// Eq. 5-6 (mirror: core/src/runtime/preview_hair.rs; f64 definition: strands::lod::tangents):
// inner vertices use p[k+1] − p[k−1]; an end reflects its neighbour's tangent about the end
// segment.
fn strand_tangent(base: u32, k: u32, n: u32) -> vec3<f32> {
    if n == 2u {
        return safe_normalize(positions[base + 1u].xyz - positions[base].xyz);
    }
    if k > 0u && k + 1u < n {
        return safe_normalize(positions[base + k + 1u].xyz - positions[base + k - 1u].xyz);
    }
    var inner = 1u;
    var end_segment = positions[base + 1u].xyz - positions[base].xyz;
    if k > 0u {
        inner = n - 2u;
        end_segment = positions[base + n - 1u].xyz - positions[base + n - 2u].xyz;
    }
    let t = safe_normalize(positions[base + inner + 1u].xyz - positions[base + inner - 1u].xyz);
    let q = safe_normalize(end_segment);
    if dot(q, q) == 0.0 {
        return t;
    }
    if dot(t, t) == 0.0 {
        return q;
    }
    return safe_normalize(2.0 * q * dot(t, q) - t);
}

// The strand's random value for absorption variation, from its root index
// (mirror: core/src/light/material.rs `strand_shading_random`).
fn strand_shading_random(root: u32) -> f32 {
    let state = (0x5A3D1E77u ^ root) * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return f32(((word >> 22u) ^ word) >> 8u) * (1.0 / 16777216.0);
}

// Direction toward the viewer from `p`.
fn toward_viewer(p: vec3<f32>) -> vec3<f32> {
    if hair.eye.w == 0.0 {
        return hair.eye.xyz;
    }
    return hair.eye.xyz - p;
}

struct RibbonVertex {
    clip: vec4<f32>,
    world: vec3<f32>,
    tangent: vec3<f32>,
    along: f32,
    // −1 or +1: which edge of the ribbon.
    side: f32,
    // Fraction of the drawn width the strand covers (1 unless widened).
    coverage: f32,
    // Drawn width in pixels (texels in a shadow view).
    width_px: f32,
    root: u32,
}

fn ribbon_vertex(vertex_index: u32) -> RibbonVertex {
    let segment_index = vertex_index / 6u;
    let run = runs[find_run(segment_index)];
    let n = max(run.vertex_count, 2u);
    let local = segment_index - run.segment_offset;
    let strand = local / (n - 1u);
    let segment = local % (n - 1u);
    // Two triangles: (0,0) (1,0) (0,1) / (0,1) (1,0) (1,1) as (end, side).
    var ends = array<u32, 6>(0u, 1u, 0u, 0u, 1u, 1u);
    var sides = array<f32, 6>(-1.0, -1.0, 1.0, 1.0, -1.0, 1.0);
    let corner = vertex_index % 6u;
    let k = segment + ends[corner];
    let base = run.vertex_offset + strand * n;
    let vertex = positions[base + k];
    let p = vertex.xyz;
    var tangent = strand_tangent(base, k, n);
    if dot(tangent, tangent) == 0.0 {
        tangent = vec3<f32>(0.0, 1.0, 0.0);
    }
    let to_viewer = toward_viewer(p);
    var side = cross(tangent, to_viewer);
    if dot(side, side) < 1e-20 {
        side = cross(tangent, vec3<f32>(0.0, 0.0, 1.0));
        if dot(side, side) < 1e-20 {
            side = cross(tangent, vec3<f32>(1.0, 0.0, 0.0));
        }
    }
    let along = vertex.w;
    // Taper toward the tip; thicker where strand LOD dropped strands.
    let half_width = 0.5 * hair.width.x * run.thickness * (1.0 - 0.6 * along);
    var pixel = hair.width.y;
    if hair.eye.w != 0.0 {
        pixel = hair.width.y * length(to_viewer);
    }
    let drawn = max(half_width, 0.5 * hair.width.z * pixel);
    let world = p + normalize(side) * sides[corner] * drawn;
    var out: RibbonVertex;
    out.clip = hair.view_projection * vec4<f32>(world, 1.0);
    out.world = world;
    out.tangent = tangent;
    out.along = along;
    out.side = sides[corner];
    out.coverage = select(1.0, half_width / drawn, drawn > 0.0);
    out.width_px = select(0.0, 2.0 * drawn / pixel, pixel > 0.0);
    out.root = run.first_root + strand;
    return out;
}
