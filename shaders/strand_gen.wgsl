// strand_gen: every vertex position of every strand, from the hair-mesh texture alone.
// One invocation per strand vertex: two filtered fetches and one lerp (one quadratic Bézier
// of the column curves, seed 000 §3.1).
// CPU mirror: hairloom_core::runtime::TexturePath::position (same constants, same steps).
// Structs: keep in sync with core/src/gpu_types.rs.

struct StrandGenParams {
    position_offset: vec4<f32>,
    texture_size: vec4<u32>,
    strand_count: u32,
    vertex_count: u32,
    filtering: u32,
    _padding: u32,
}

struct StrandRoot {
    texel: vec2<f32>,
    layers: u32,
    _padding: u32,
}

const SLICES_PER_SEGMENT: u32 = 4u;
const FILTERING_EXACT: u32 = 0u;

@group(0) @binding(0) var<uniform> params: StrandGenParams;
@group(0) @binding(1) var<storage, read> roots: array<StrandRoot>;
@group(0) @binding(2) var hair_mesh: texture_3d<f32>;
@group(0) @binding(3) var linear_clamp: sampler;
@group(0) @binding(4) var<storage, read_write> positions: array<vec4<f32>>;

// Trilinear filtering in f32 with textureLoad: the "exact" switch (mirror: sample_trilinear
// with Filtering::Exact). Texel centres sit at i + 0.5; clamp to the edge.
fn fetch_exact(coord: vec3<f32>) -> vec3<f32> {
    let size = vec3<i32>(params.texture_size.xyz);
    let x = clamp(coord - vec3<f32>(0.5), vec3<f32>(0.0), vec3<f32>(size - vec3<i32>(1)));
    let i0 = min(vec3<i32>(floor(x)), max(size - vec3<i32>(2), vec3<i32>(0)));
    let f = x - vec3<f32>(i0);
    let i1 = min(i0 + vec3<i32>(1), size - vec3<i32>(1));
    let c000 = textureLoad(hair_mesh, vec3<i32>(i0.x, i0.y, i0.z), 0).xyz;
    let c100 = textureLoad(hair_mesh, vec3<i32>(i1.x, i0.y, i0.z), 0).xyz;
    let c010 = textureLoad(hair_mesh, vec3<i32>(i0.x, i1.y, i0.z), 0).xyz;
    let c110 = textureLoad(hair_mesh, vec3<i32>(i1.x, i1.y, i0.z), 0).xyz;
    let c001 = textureLoad(hair_mesh, vec3<i32>(i0.x, i0.y, i1.z), 0).xyz;
    let c101 = textureLoad(hair_mesh, vec3<i32>(i1.x, i0.y, i1.z), 0).xyz;
    let c011 = textureLoad(hair_mesh, vec3<i32>(i0.x, i1.y, i1.z), 0).xyz;
    let c111 = textureLoad(hair_mesh, vec3<i32>(i1.x, i1.y, i1.z), 0).xyz;
    let bottom0 = c000 + (c100 - c000) * f.x;
    let top0 = c010 + (c110 - c010) * f.x;
    let plane0 = bottom0 + (top0 - bottom0) * f.y;
    let bottom1 = c001 + (c101 - c001) * f.x;
    let top1 = c011 + (c111 - c011) * f.x;
    let plane1 = bottom1 + (top1 - bottom1) * f.y;
    return plane0 + (plane1 - plane0) * f.z;
}

fn fetch(coord: vec3<f32>) -> vec3<f32> {
    if params.filtering == FILTERING_EXACT {
        return fetch_exact(coord);
    }
    let size = vec3<f32>(params.texture_size.xyz);
    return textureSampleLevel(hair_mesh, linear_clamp, coord / size, 0.0).xyz;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if params.vertex_count < 2u || index >= params.strand_count * params.vertex_count {
        return;
    }
    let strand = index / params.vertex_count;
    let k = index % params.vertex_count;
    let root = roots[strand];
    let layers = f32(max(root.layers, 1u));
    let tau = clamp(layers * f32(k) / f32(params.vertex_count - 1u), 0.0, layers);
    let segment = min(u32(floor(tau)), max(root.layers, 1u) - 1u);
    let local = tau - f32(segment);
    var first_slice = SLICES_PER_SEGMENT * segment;
    var q = local * 2.0;
    if local >= 0.5 {
        first_slice = first_slice + 2u;
        q = local * 2.0 - 1.0;
    }
    let a = fetch(vec3<f32>(root.texel, f32(first_slice) + q + 0.5));
    let b = fetch(vec3<f32>(root.texel, f32(first_slice) + 1.0 + q + 0.5));
    positions[index] = vec4<f32>(a + (b - a) * q + params.position_offset.xyz, 1.0);
}
