// Ribbon input: strand vertices generated in the vertex shader from the five runtime
// textures (shared/strand_vertex.wgsl), with no scratch buffer — the portable analogue of the
// paper's mesh shader (seed 000 §4). A triangle strip per strand, one instance per strand:
// ribbon vertex i is strand vertex i / 2, side i % 2, and each evaluates the (morphed)
// points k − 1, k, k + 1 its eq. 5-6 tangent needs; every strand's set-up (root, root uv,
// styling randoms) is redone per ribbon vertex, as a vertex shader cannot share it. One draw
// per run (`first_instance` = the run's first strand in the batch). Prepended to
// shared/ribbon.wgsl, which calls `ribbon_centre`. CPU mirror: StrandGen::main followed by
// runtime::preview_hair (the same points and tangents as the compute path).
// Bindings: the ribbons' own (0, 2) and strand_gen's, at strand_gen's numbers + 16
// (render/src/renderer/strand_gen.rs `GENERATED_BINDING_OFFSET`).

@group(0) @binding(16) var<uniform> params: StrandGenParams;
@group(0) @binding(17) var<storage, read> bundles: array<BundleGpu>;
@group(0) @binding(18) var hair_mesh: texture_3d<f32>;
@group(0) @binding(19) var linear_clamp: sampler;
@group(0) @binding(21) var uv_texture: texture_3d<f32>;
@group(0) @binding(22) var w_texture: texture_3d<f32>;
@group(0) @binding(23) var u_texture: texture_3d<f32>;
@group(0) @binding(24) var v_texture: texture_3d<f32>;
@group(0) @binding(25) var<storage, read> styling: array<Styling>;
@group(0) @binding(31) var root_maps: texture_2d<f32>;
@group(0) @binding(27) var<storage, read> samples: array<vec2<f32>>;

fn ribbon_centre(vertex_index: u32, instance_index: u32) -> RibbonCentre {
    let run = runs[find_run(hair.batch.x, hair.batch.y, instance_index, RUN_BY_STRAND)];
    let n = max(run.vertex_count, 2u);
    let strand = instance_index - run_start(run, RUN_BY_STRAND);
    let k = min(vertex_index / 2u, n - 1u);
    let input = strand_input(run.first_root + strand);
    var out: RibbonCentre;
    if n == 2u {
        let a = styled_vertex(input, 0u, n);
        let b = styled_vertex(input, 1u, n);
        out.p = select(a, b, k == 1u);
        out.tangent = safe_normalize(b - a);
    } else {
        let i = clamp(k, 1u, n - 2u);
        let a = morphed_vertex(input, i - 1u, n, run.gamma);
        let b = morphed_vertex(input, i, n, run.gamma);
        let c = morphed_vertex(input, i + 1u, n, run.gamma);
        out.p = b;
        if k < i {
            out.p = a;
        } else if k > i {
            out.p = c;
        }
        out.tangent = end_reflected_tangent(a, b, c, k, n);
    }
    out.along = along_of(k, n);
    out.side = select(-1.0, 1.0, vertex_index % 2u == 1u);
    out.run = run;
    out.strand = strand;
    return out;
}
