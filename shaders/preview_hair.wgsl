// preview_hair: camera-facing ribbons from strand vertices, Kajiya-Kay shading with a
// root-to-tip colour and three lights. Vertices sit in `positions` as the batch's runs lay
// them out (`run.vertex_offset + strand * run.vertex_count + k`, w = fraction along the
// strand); each segment is two triangles (6 vertices). Tangents follow eq. 5-6 (ends mirror
// their neighbour about the end segment), so shading holds when vertex LOD changes counts;
// ribbon width grows by the run's thickness factor (eq. 8 compensation).
// Structs: keep in sync with render/src/preview.rs (`HairUniforms`); `StrandRun` is in
// shaders/shared/strand_run.wgsl.

struct HairUniforms {
    view_projection: mat4x4<f32>,
    camera_position: vec4<f32>,
    root_color: vec4<f32>,
    tip_color: vec4<f32>,
    // Ribbon width in model units (x); y, z, w unused.
    width: vec4<f32>,
    // The batch's runs: runs[first_run .. first_run + run_count] (x, y); z, w unused.
    batch: vec4<u32>,
}

// struct StrandRun: shaders/shared/strand_run.wgsl, prepended by render/src/.

@group(0) @binding(0) var<uniform> hair: HairUniforms;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> runs: array<StrandRun>;

struct VertexOutput {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) tangent: vec3<f32>,
    @location(2) along: f32,
}

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

// Eq. 5-6 (mirror: core/src/runtime/preview_hair.rs; f64 definition: strands::lod::tangents): inner vertices use p[k+1] − p[k−1]; an end
// reflects its neighbour's tangent about the end segment.
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

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> VertexOutput {
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
    let to_camera = hair.camera_position.xyz - p;
    var side = cross(tangent, to_camera);
    if dot(side, side) < 1e-20 {
        side = cross(tangent, vec3<f32>(0.0, 0.0, 1.0));
    }
    let along = vertex.w;
    // Taper toward the tip; thicker where strand LOD dropped strands.
    let half_width = 0.5 * hair.width.x * run.thickness * (1.0 - 0.6 * along);
    let world = p + normalize(side) * sides[corner] * half_width;
    var out: VertexOutput;
    out.clip = hair.view_projection * vec4<f32>(world, 1.0);
    out.world = world;
    out.tangent = tangent;
    out.along = along;
    return out;
}

// Kajiya-Kay: diffuse sin(T, L), specular sin(T, H)^p (Kajiya & Kay 1989), plus a second,
// shifted and tinted lobe for the colour-carrying secondary highlight.
fn kajiya_kay(t: vec3<f32>, l: vec3<f32>, v: vec3<f32>, base: vec3<f32>) -> vec3<f32> {
    let tl = dot(t, l);
    let diffuse = sqrt(max(1.0 - tl * tl, 0.0));
    let h = normalize(l + v);
    let th = dot(t, h);
    let sin_th = sqrt(max(1.0 - th * th, 0.0));
    let primary = pow(sin_th, 80.0) * 0.35;
    let secondary = pow(sin_th, 20.0) * 0.25;
    return base * diffuse * 0.8 + vec3<f32>(primary) + base * secondary;
}

@fragment
fn fs_main(in: VertexOutput) -> @location(0) vec4<f32> {
    let base = mix(hair.root_color.rgb, hair.tip_color.rgb, in.along);
    let v = normalize(hair.camera_position.xyz - in.world);
    let t = normalize(in.tangent);
    // Three-point lighting: key (front right, above), fill (left), rim (behind).
    var color = kajiya_kay(t, normalize(vec3<f32>(0.6, 0.8, 0.9)), v, base) * 1.0;
    color += kajiya_kay(t, normalize(vec3<f32>(-0.8, 0.3, 0.5)), v, base) * 0.35;
    color += kajiya_kay(t, normalize(vec3<f32>(0.0, 0.5, -1.0)), v, base) * 0.5;
    // Darker toward the root: a cheap stand-in for self-shadowing.
    color *= 0.55 + 0.45 * in.along;
    return vec4<f32>(color + base * 0.08, 1.0);
}
