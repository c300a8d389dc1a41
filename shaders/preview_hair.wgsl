// preview_hair: camera-facing ribbons from strand vertex positions, Kajiya-Kay shading with a
// root-to-tip colour and three lights. Strand vertices are strand-major in `positions`
// (`vertex_count` per strand); each segment is two triangles (6 vertices).
// Structs: keep in sync with render/src/preview.rs (`HairUniforms`).

struct HairUniforms {
    view_projection: mat4x4<f32>,
    camera_position: vec4<f32>,
    root_color: vec4<f32>,
    tip_color: vec4<f32>,
    // Ribbon width in model units (x), strand count (y, as f32), vertex count (z).
    width_counts: vec4<f32>,
}

@group(0) @binding(0) var<uniform> hair: HairUniforms;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;

struct VertexOutput {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) tangent: vec3<f32>,
    @location(2) along: f32,
}

fn strand_point(strand: u32, k: u32, vertex_count: u32) -> vec3<f32> {
    return positions[strand * vertex_count + k].xyz;
}

@vertex
fn vs_main(@builtin(vertex_index) vertex_index: u32) -> VertexOutput {
    let vertex_count = u32(hair.width_counts.z);
    let segments = vertex_count - 1u;
    let strand = vertex_index / (segments * 6u);
    let in_strand = vertex_index % (segments * 6u);
    let segment = in_strand / 6u;
    // Two triangles: (0,0) (1,0) (0,1) / (0,1) (1,0) (1,1) as (end, side).
    var ends = array<u32, 6>(0u, 1u, 0u, 0u, 1u, 1u);
    var sides = array<f32, 6>(-1.0, -1.0, 1.0, 1.0, -1.0, 1.0);
    let corner = in_strand % 6u;
    let k = segment + ends[corner];
    let p = strand_point(strand, k, vertex_count);
    let previous = strand_point(strand, max(k, 1u) - 1u, vertex_count);
    let next = strand_point(strand, min(k + 1u, vertex_count - 1u), vertex_count);
    var tangent = next - previous;
    if dot(tangent, tangent) < 1e-20 {
        tangent = vec3<f32>(0.0, 1.0, 0.0);
    }
    tangent = normalize(tangent);
    let to_camera = hair.camera_position.xyz - p;
    var side = cross(tangent, to_camera);
    if dot(side, side) < 1e-20 {
        side = cross(tangent, vec3<f32>(0.0, 0.0, 1.0));
    }
    let along = f32(k) / f32(vertex_count - 1u);
    // Taper toward the tip.
    let half_width = 0.5 * hair.width_counts.x * (1.0 - 0.6 * along);
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
