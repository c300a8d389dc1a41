// strand_gen: every vertex of every styled strand, from the five runtime textures alone
// (seed 000 §3.1-3.4). `main`: one invocation per strand, which computes what the strand's
// vertices share once (root, root uv, length, the styling ops' random phases, keys and clump
// pull: `strand_input`) and then walks its vertices, morphing each odd one from the
// neighbours it has just computed. `main_per_vertex`: one invocation per vertex, redoing the
// per-strand set-up at every vertex (and three vertices for a morphed one) — the earlier
// split, kept as a switch because a GPU may prefer its coalesced writes. Per vertex:
// - position: two filtered fetches of the hair-mesh texture and one lerp (one quadratic
//   Bézier of the column curves);
// - the styling frame û, v̂ and the styling coordinate w: one filtered fetch each between
//   layer slices;
// - styling ops (twist, curl, noise, clump, frizz, wave, length variation) seeded by the
//   root uv; an op whose amplitude is zero costs nothing.
// CPU mirror: core/src/runtime/strand_gen.rs, `StrandGen::main` (same steps; its styling
// arithmetic is f64, this is f32).
// Roots are never stored per strand: root `i` is sample `i % per_bundle` of bundle
// `i / per_bundle`, placed on the bundle's block (mirror: runtime::hair::strand_root).
// Work arrives as runs (bundle-level work: culling, strand and vertex LOD, done per frame):
// consecutive strands of one bundle at one vertex count. Output:
// `positions[run.vertex_offset + strand * run.vertex_count + k]` = (position, along), one
// bounded scratch buffer per batch of runs; odd vertices morph toward their neighbours'
// midpoint by the run's γ (eq. 11).
// The vertex itself (structs, fetches, styling ops): shared/strand_vertex.wgsl, prepended by
// render/src/ with shared/strand_run.wgsl.

@group(0) @binding(0) var<uniform> params: StrandGenParams;
@group(0) @binding(1) var<storage, read> bundles: array<BundleGpu>;
@group(0) @binding(2) var hair_mesh: texture_3d<f32>;
@group(0) @binding(3) var linear_clamp: sampler;
@group(0) @binding(4) var<storage, read_write> positions: array<vec4<f32>>;
@group(0) @binding(5) var uv_texture: texture_3d<f32>;
@group(0) @binding(6) var w_texture: texture_3d<f32>;
@group(0) @binding(7) var u_texture: texture_3d<f32>;
@group(0) @binding(8) var v_texture: texture_3d<f32>;
@group(0) @binding(9) var<storage, read> styling: array<Styling>;
// The painted maps (density, length, clump) in root-uv space; one white texel when none.
@group(0) @binding(15) var root_maps: texture_2d<f32>;
@group(0) @binding(10) var<storage, read> runs: array<StrandRun>;
// Progressive root samples: `sample_set` for quads (bundle-corner coordinates), then
// `sample_set` for triangles (barycentric).
@group(0) @binding(11) var<storage, read> samples: array<vec2<f32>>;

// One invocation per strand: the set-up once, then every vertex in order; an odd vertex is
// written once its right neighbour exists (eq. 11 morph by the run's γ).
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let strand = id.x;
    if params.run_count == 0u || strand >= params.strand_total {
        return;
    }
    let run = runs[find_run(params.first_run, params.run_count, strand, RUN_BY_STRAND)];
    let n = max(run.vertex_count, 2u);
    let local = strand - run_start(run, RUN_BY_STRAND);
    let base = run.vertex_offset + local * n;
    let input = strand_input(run.first_root + local);
    var previous = styled_vertex(input, 0u, n);
    positions[base] = vec4<f32>(previous, 0.0);
    for (var k = 1u; k < n; k += 2u) {
        let current = styled_vertex(input, k, n);
        if k + 1u < n {
            let next = styled_vertex(input, k + 1u, n);
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

// One invocation per vertex: the strand's set-up again at every vertex.
@compute @workgroup_size(64)
fn main_per_vertex(@builtin(global_invocation_id) id: vec3<u32>) {
    let vertex = id.x;
    if params.run_count == 0u || vertex >= params.vertex_total {
        return;
    }
    let run = runs[find_run(params.first_run, params.run_count, vertex, RUN_BY_VERTEX)];
    let n = max(run.vertex_count, 2u);
    let local = vertex - run.vertex_offset;
    let strand = local / n;
    let k = local % n;
    let input = strand_input(run.first_root + strand);
    let p = morphed_vertex(input, k, n, run.gamma);
    positions[vertex] = vec4<f32>(p, along_of(k, n));
}

// Far hair (seed 001, core/src/runtime/thick_hair.rs): one invocation per thick hair, which
// generates its four corner strands as `main` generates any strand and writes, per vertex,
// their centre with `along` to `positions` and the half-axes they span to `sections`
// (2 per vertex: major and the member count, minor). CPU mirror: StrandGen::thick_main.
// `ThickHairGpu` is in shared/thick_hair.wgsl. Keep the structs in sync with
// core/src/runtime/gpu_types.rs.
struct ThickGenParams {
    first: u32,
    count: u32,
    vertex_count: u32,
    output_offset: u32,
}

@group(0) @binding(12) var<storage, read> thick_hairs: array<ThickHairGpu>;
@group(0) @binding(13) var<storage, read_write> sections: array<vec4<f32>>;
@group(0) @binding(14) var<uniform> thick: ThickGenParams;

@compute @workgroup_size(64)
fn thick_main(@builtin(global_invocation_id) id: vec3<u32>) {
    let t = id.x;
    if t >= thick.count {
        return;
    }
    let hair = thick_hairs[thick.first + t];
    let n = max(thick.vertex_count, 2u);
    let base = thick.output_offset + t * n;
    let a = strand_input(hair.corners.x);
    let b = strand_input(hair.corners.y);
    let c = strand_input(hair.corners.z);
    let d = strand_input(hair.corners.w);
    for (var k = 0u; k < n; k++) {
        let pa = styled_vertex(a, k, n);
        let pb = styled_vertex(b, k, n);
        let pc = styled_vertex(c, k, n);
        let pd = styled_vertex(d, k, n);
        positions[base + k] = vec4<f32>(0.25 * (pa + pb + pc + pd), along_of(k, n));
        sections[2u * (base + k)] = vec4<f32>(0.5 * (pa - pb), f32(hair.members));
        sections[2u * (base + k) + 1u] = vec4<f32>(0.5 * (pc - pd), 0.0);
    }
}
