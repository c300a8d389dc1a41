// strand_mesh: generation by task and mesh shaders, where the adapter has them (seed 000 §4,
// Fig. 8-10; wgpu's EXPERIMENTAL_MESH_SHADER). Appended to a pass's generating ribbon shader
// (the generated ribbon input, shared/ribbon.wgsl, the pass's own file, which defines
// `PassVertex` and `pass_vertex`), so every pass that draws the hair — depth pre-pass, lit,
// width OIT, opacity maps — can run it in place of its vertex shader; render/src/ prepends
// `enable wgpu_mesh_shader;`.
// - Task shader, one workgroup per bundle: culls the bundle's bounding sphere against this
//   pass's view (the camera, or a light in the shadow passes), computes its level of detail
//   from the frame's camera (eq. 7-12: strands, vertices per strand, morph factor, thickness;
//   shared/strand_lod.wgsl, mirror frame_plan::bundle_lod — the same strands every other
//   path draws) and launches one mesh workgroup per strand group. No CPU frame plan.
// - Mesh shader, one workgroup per strand group: one invocation per strand vertex. The
//   strand's set-up (root, root uv, the styling ops' random values) is computed once per
//   strand and shared through workgroup memory, every vertex once, odd vertices morphed from
//   their neighbours (eq. 11), tangents (eq. 5-6) from the neighbours in workgroup memory;
//   each invocation writes its two ribbon vertices and the two triangles to the next vertex.
//   No scratch buffer, and nothing evaluated twice (the vertex-shader path evaluates 3-7
//   styled vertices per ribbon vertex).
// Work distribution: a run of n vertices per strand puts ⌊96 / n⌋ whole strands (at most 16)
// in a group when n ≤ 96; longer strands are cut into chunks of 95 vertices that overlap by
// one (chunk starts are even, so every odd vertex's neighbours are in its chunk), one chunk
// per group.
// The same triangles as the vertex-shader path's strips, so the same picture
// (render/tests/strand_mesh.rs); CPU mirror of the points and tangents: StrandGen::main
// followed by runtime::preview_hair, as for the other paths.

// The work distribution's sizes — MESH_STRAND_VERTICES (invocations per mesh workgroup; ribbon
// vertices are twice this), MESH_CHUNK_SEGMENTS (segments per chunk of a longer strand; even,
// so chunks start on even vertices) and MESH_MAX_STRANDS (whole strands per group, each with
// its set-up in workgroup memory) — are written ahead of this file by render/src/ from
// render/src/renderer/strand_gen.rs, whose `mesh_groups` is the CPU mirror. They are sized so
// a group fits NVIDIA's mesh-shader limits (28 KiB of workgroup memory, which naga's SPIR-V
// also keeps the outputs in; 32 KiB of outputs); render/tests/shader_validation.rs adds both
// up.

// Each bundle's bounds and sizes, in the hair's model space (`RuntimeTextures::bundle_bounds`,
// as the frame plan culls and plans with), and the frame's LOD camera and settings.
@group(0) @binding(32) var<storage, read> bundle_lods: array<BundleLodGpu>;
@group(0) @binding(33) var<uniform> lod: LodParams;
// Far hair's level per bundle: 1 or more draws its thick hairs (far_hair.wgsl), not strands.
@group(0) @binding(34) var<storage, read> far_levels: array<u32>;

struct MeshTask {
    // The bundle's strands at its level of detail.
    run: StrandRun,
}

var<task_payload> task: MeshTask;

// How a run of `n`-vertex strands is cut into groups.
struct MeshWork {
    // Whole strands per group (1 when strands are cut into chunks).
    strands_per_group: u32,
    // Groups per strand (1 when whole strands fit).
    chunks_per_strand: u32,
    // Strand vertices per chunk (n for whole strands).
    chunk_vertices: u32,
}

fn mesh_work(n: u32) -> MeshWork {
    var work: MeshWork;
    if n <= MESH_STRAND_VERTICES {
        work.strands_per_group = min(MESH_STRAND_VERTICES / n, MESH_MAX_STRANDS);
        work.chunks_per_strand = 1u;
        work.chunk_vertices = n;
    } else {
        work.strands_per_group = 1u;
        work.chunks_per_strand = (n - 1u + MESH_CHUNK_SEGMENTS - 1u) / MESH_CHUNK_SEGMENTS;
        work.chunk_vertices = MESH_CHUNK_SEGMENTS + 1u;
    }
    return work;
}

// Whether a sphere is at least partly inside the view frustum of `m` (mirror:
// core/src/runtime/frame_plan.rs `sphere_in_view`).
fn sphere_in_view(m: mat4x4<f32>, centre: vec3<f32>, radius: f32) -> bool {
    let r0 = vec4<f32>(m[0].x, m[1].x, m[2].x, m[3].x);
    let r1 = vec4<f32>(m[0].y, m[1].y, m[2].y, m[3].y);
    let r2 = vec4<f32>(m[0].z, m[1].z, m[2].z, m[3].z);
    let r3 = vec4<f32>(m[0].w, m[1].w, m[2].w, m[3].w);
    let planes = array<vec4<f32>, 6>(r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2);
    let point = vec4<f32>(centre, 1.0);
    for (var i = 0u; i < 6u; i++) {
        let length = length(planes[i].xyz);
        // A degenerate plane culls nothing, as on the CPU.
        if length > 0.0 && dot(planes[i], point) / length < -radius {
            return false;
        }
    }
    return true;
}

@task
@payload(task)
@workgroup_size(1)
fn ts_main(@builtin(workgroup_id) group: vec3<u32>) -> @builtin(mesh_task_size) vec3<u32> {
    let index = group.y * lod.counts.w + group.x;
    if index >= lod.counts.z {
        return vec3<u32>(0u, 1u, 1u);
    }
    if index < arrayLength(&far_levels) && far_levels[index] > 0u {
        return vec3<u32>(0u, 1u, 1u);
    }
    let bundle = bundle_lods[index];
    if lod.switches.z != 0.0 && !sphere_in_view(hair.view_projection, bundle.centre, bundle.radius_m) {
        return vec3<u32>(0u, 1u, 1u);
    }
    let run = bundle_lod(index, bundle, lod);
    task.run = run;
    if run.strand_count == 0u {
        return vec3<u32>(0u, 1u, 1u);
    }
    let work = mesh_work(max(run.vertex_count, 2u));
    let groups = (run.strand_count + work.strands_per_group - 1u) / work.strands_per_group;
    return vec3<u32>(groups * work.chunks_per_strand, 1u, 1u);
}

struct RibbonTriangle {
    @builtin(triangle_indices) indices: vec3<u32>,
}

struct MeshOutput {
    @builtin(vertices) vertices: array<PassVertex, 2u * MESH_STRAND_VERTICES>,
    @builtin(primitives) primitives: array<RibbonTriangle, 2u * MESH_STRAND_VERTICES>,
    @builtin(vertex_count) vertex_count: u32,
    @builtin(primitive_count) primitive_count: u32,
}

var<workgroup> mesh_out: MeshOutput;
// Each strand's set-up, computed by its first invocation.
var<workgroup> mesh_inputs: array<StrandInput, MESH_MAX_STRANDS>;
// The styled vertices, then the morphed ones: odd vertices are morphed in place, reading only
// their even neighbours, which never change.
var<workgroup> mesh_points: array<vec3<f32>, MESH_STRAND_VERTICES>;

// Morphed strand vertex q of the slot whose vertex k0 is mesh_points[base]: from workgroup
// memory inside the chunk, evaluated here beyond it (a chunk's two ends, when strands are
// cut into chunks).
fn mesh_point(base: u32, k0: u32, chunk: u32, q: u32, input: StrandInput, n: u32, gamma: f32) -> vec3<f32> {
    if q >= k0 && q < k0 + chunk {
        return mesh_points[base + q - k0];
    }
    return morphed_vertex(input, q, n, gamma);
}

@mesh(mesh_out)
@payload(task)
@workgroup_size(MESH_STRAND_VERTICES)
fn ms_main(
    @builtin(local_invocation_index) t: u32,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let run = task.run;
    let n = max(run.vertex_count, 2u);
    let work = mesh_work(n);
    let first_strand = (group.x / work.chunks_per_strand) * work.strands_per_group;
    let k0 = (group.x % work.chunks_per_strand) * MESH_CHUNK_SEGMENTS;
    // This group's strands and the vertices of each it covers.
    let strands = min(work.strands_per_group, run.strand_count - first_strand);
    let chunk = min(work.chunk_vertices, n - k0);
    let slot = t / work.chunk_vertices;
    let j = t % work.chunk_vertices;
    let k = k0 + j;
    let strand = first_strand + slot;
    let in_group = slot < strands && j < chunk;

    if t == 0u {
        mesh_out.vertex_count = 2u * strands * chunk;
        mesh_out.primitive_count = 2u * strands * (chunk - 1u);
    }
    if in_group && j == 0u {
        mesh_inputs[slot] = strand_input(run.first_root + strand);
    }
    workgroupBarrier();
    if in_group {
        mesh_points[t] = styled_vertex(mesh_inputs[slot], k, n);
    }
    workgroupBarrier();
    if in_group && run.gamma > 0.0 && k % 2u == 1u && k + 1u < n {
        // Eq. 11, as strand_gen.wgsl `main`: an odd vertex toward its neighbours' midpoint.
        let middle = 0.5 * (mesh_points[t - 1u] + mesh_points[t + 1u]);
        mesh_points[t] = mix(mesh_points[t], middle, run.gamma);
    }
    workgroupBarrier();
    if !in_group {
        return;
    }
    let input = mesh_inputs[slot];
    // The slot's strand vertex k0 is at mesh_points[t - j].
    let base = t - j;
    var centre: RibbonCentre;
    centre.p = mesh_points[t];
    if n == 2u {
        centre.tangent = safe_normalize(mesh_points[base + 1u] - mesh_points[base]);
    } else {
        // Eq. 5-6 from the morphed points i − 1, i, i + 1, i = clamp(k, 1, n − 2).
        let i = clamp(k, 1u, n - 2u);
        let a = mesh_point(base, k0, chunk, i - 1u, input, n, run.gamma);
        let b = mesh_point(base, k0, chunk, i, input, n, run.gamma);
        let c = mesh_point(base, k0, chunk, i + 1u, input, n, run.gamma);
        centre.tangent = end_reflected_tangent(a, b, c, k, n);
    }
    centre.along = along_of(k, n);
    centre.run = run;
    centre.strand = strand;
    // Ribbon vertices 2v (side −1) and 2v + 1 (side +1) of strand vertex v, as a strip has them.
    let v = slot * chunk + j;
    centre.side = -1.0;
    mesh_out.vertices[2u * v] = pass_vertex(ribbon_vertex_at(centre));
    centre.side = 1.0;
    mesh_out.vertices[2u * v + 1u] = pass_vertex(ribbon_vertex_at(centre));
    if j + 1u < chunk {
        // The strip's two triangles to the next vertex; earlier strands in the group each
        // have one segment fewer than vertices.
        let triangle = 2u * (v - slot);
        mesh_out.primitives[triangle].indices = vec3<u32>(2u * v, 2u * v + 1u, 2u * v + 2u);
        mesh_out.primitives[triangle + 1u].indices = vec3<u32>(2u * v + 2u, 2u * v + 1u, 2u * v + 3u);
    }
}
