// linear_hair_skinning: the LHS baseline (seed 000 §5) — every strand stored, bound to its
// three nearest guides with weights and per-vertex offsets in the guides' frames; each frame
// the guides' frames are rebuilt from their pose (`guide_frames`, one invocation per guide)
// and every strand vertex of the frame plan's runs is skinned into the same scratch layout
// strand_gen writes (`skin_main`, one invocation per strand, odd vertices morphed by the
// run's γ as strand_gen does), so the frame draws both methods through the same passes.
// CPU mirror: core/src/runtime/linear_hair_skinning.rs (same names). render/src/ prepends
// shared/strand_run.wgsl.
// Keep the structs in sync with core/src/runtime/linear_hair_skinning.rs.

struct SkinParams {
    first_run: u32,
    run_count: u32,
    strand_total: u32,
    vertex_count: u32,
    guide_count: u32,
    _padding0: u32,
    _padding1: u32,
    _padding2: u32,
}

struct SkinBinding {
    guides: array<u32, 3>,
    _padding: u32,
    weights: array<f32, 3>,
    _padding2: f32,
}

@group(0) @binding(0) var<uniform> params: SkinParams;
// Guide-major pose: guide g's vertex s at g · vertex_count + s (xyz; w unused).
@group(0) @binding(1) var<storage, read> guide_points: array<vec4<f32>>;
// Per guide vertex: tangent, then normal (2 entries each).
@group(0) @binding(2) var<storage, read_write> frames: array<vec4<f32>>;
// `guide_frames` only: each guide's root reference direction.
@group(0) @binding(3) var<storage, read> references: array<vec4<f32>>;
// `skin_main` only.
@group(0) @binding(4) var<storage, read> runs: array<StrandRun>;
@group(0) @binding(5) var<storage, read> bindings: array<SkinBinding>;
// Slot g's offset of every stored strand vertex, 3 floats each (normal, binormal, tangent
// components): one buffer per slot keeps each under the storage binding limit.
@group(0) @binding(6) var<storage, read> offsets0: array<f32>;
@group(0) @binding(7) var<storage, read> offsets1: array<f32>;
@group(0) @binding(8) var<storage, read> offsets2: array<f32>;
@group(0) @binding(9) var<storage, read_write> positions: array<vec4<f32>>;

// A unit vector ⟂ unit `n` (Duff et al. 2017).
fn duff_perpendicular(n: vec3<f32>) -> vec3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
}

fn try_normalize(v: vec3<f32>) -> vec4<f32> {
    let length_squared = dot(v, v);
    if length_squared > 1e-30 {
        return vec4<f32>(v * inverseSqrt(length_squared), 1.0);
    }
    return vec4<f32>(0.0);
}

// One invocation per guide: tangents by central differences (one-sided at the ends, the
// previous one where the difference has no length), normals parallel-transported from the
// reference made ⟂ the root tangent.
@compute @workgroup_size(64)
fn guide_frames(@builtin(global_invocation_id) id: vec3<u32>) {
    let g = id.x;
    if g >= params.guide_count {
        return;
    }
    let v = max(params.vertex_count, 2u);
    let base = g * v;
    let reference = references[g].xyz;
    var tangent = vec3<f32>(0.0);
    var normal = vec3<f32>(0.0);
    for (var s = 0u; s < v; s++) {
        let d = guide_points[base + min(s + 1u, v - 1u)].xyz - guide_points[base + max(s, 1u) - 1u].xyz;
        let t = try_normalize(d);
        var new_tangent = tangent;
        if t.w > 0.0 {
            new_tangent = t.xyz;
        } else if s == 0u {
            let r = try_normalize(reference);
            new_tangent = select(vec3<f32>(0.0, 0.0, 1.0), r.xyz, r.w > 0.0);
        }
        var carried = reference;
        if s > 0u {
            carried = normal;
        }
        var n = try_normalize(carried - new_tangent * dot(new_tangent, carried));
        if n.w == 0.0 && s > 0u {
            let b = cross(tangent, normal);
            n = try_normalize(b - new_tangent * dot(new_tangent, b));
        }
        if n.w == 0.0 {
            n = vec4<f32>(duff_perpendicular(new_tangent), 1.0);
        }
        tangent = new_tangent;
        normal = n.xyz;
        frames[2u * (base + s)] = vec4<f32>(tangent, 0.0);
        frames[2u * (base + s) + 1u] = vec4<f32>(normal, 0.0);
    }
}

fn slot_offset(slot: u32, i: u32) -> vec3<f32> {
    if slot == 0u {
        return vec3<f32>(offsets0[3u * i], offsets0[3u * i + 1u], offsets0[3u * i + 2u]);
    }
    if slot == 1u {
        return vec3<f32>(offsets1[3u * i], offsets1[3u * i + 1u], offsets1[3u * i + 2u]);
    }
    return vec3<f32>(offsets2[3u * i], offsets2[3u * i + 1u], offsets2[3u * i + 2u]);
}

// Stored vertex `s` of `strand`, skinned to the pose.
fn skin_vertex(strand: u32, s: u32) -> vec3<f32> {
    let v = max(params.vertex_count, 2u);
    let binding = bindings[strand];
    var p = vec3<f32>(0.0);
    for (var slot = 0u; slot < 3u; slot++) {
        let w = binding.weights[slot];
        if w == 0.0 {
            continue;
        }
        let gv = binding.guides[slot] * v + s;
        let tangent = frames[2u * gv].xyz;
        let normal = frames[2u * gv + 1u].xyz;
        let o = slot_offset(slot, strand * v + s);
        p += w * (guide_points[gv].xyz + o.x * normal + o.y * cross(tangent, normal) + o.z * tangent);
    }
    return p;
}

fn along_of(k: u32, n: u32) -> f32 {
    return f32(k) / f32(n - 1u);
}

// One invocation per strand of the batch: its run's vertices from every (V − 1)/(n − 1)-th
// stored vertex, odd ones morphed by γ.
@compute @workgroup_size(64)
fn skin_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if params.run_count == 0u || index >= params.strand_total {
        return;
    }
    let run = runs[find_run(params.first_run, params.run_count, index, RUN_BY_STRAND)];
    let n = max(run.vertex_count, 2u);
    let v = max(params.vertex_count, 2u);
    let step = max((v - 1u) / (n - 1u), 1u);
    let local = index - run_start(run, RUN_BY_STRAND);
    let strand = run.first_root + local;
    if strand >= arrayLength(&bindings) {
        return;
    }
    let base = run.vertex_offset + local * n;
    var previous = skin_vertex(strand, 0u);
    positions[base] = vec4<f32>(previous, 0.0);
    for (var k = 1u; k < n; k += 2u) {
        let current = skin_vertex(strand, min(k * step, v - 1u));
        if k + 1u < n {
            let next = skin_vertex(strand, min((k + 1u) * step, v - 1u));
            var p = current;
            if run.gamma > 0.0 {
                p = mix(current, 0.5 * (previous + next), run.gamma);
            }
            positions[base + k] = vec4<f32>(p, along_of(k, n));
            positions[base + k + 1u] = vec4<f32>(next, along_of(k + 1u, n));
            previous = next;
        } else {
            positions[base + k] = vec4<f32>(current, along_of(k, n));
        }
    }
}
