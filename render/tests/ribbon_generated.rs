//! Ribbons that generate their own strand vertices in the vertex shader
//! (`shaders/shared/ribbon_generated.wgsl`) against the compute path and the CPU mirror, on
//! a sample's LOD plan (several vertex counts, morphed odd vertices, and a 2-vertex run). The
//! shader's own `ribbon_centre` runs in a compute entry point appended to the preview shader
//! (the vertex stage cannot write a buffer), with the bindings the vertex stage reads.

mod common;

use glam::Vec3;
use hairloom_core::runtime::frame_plan::{LodSettings, plan_frame};
use hairloom_core::runtime::gpu_types::StrandRun;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::preview_hair::batch_tangents;
use hairloom_core::runtime::strand_gen::{Filtering, StrandGen};
use hairloom_core::runtime::textures::Precision;
use hairloom_render::device::{headless_for_test, read_buffer};
use hairloom_render::renderer::preview_hair::{HairUniforms, RibbonInput};
use hairloom_render::renderer::shader_composer::{ShaderKey, hair_shader};
use hairloom_render::renderer::strand_gen::{
    GENERATED_BINDING_OFFSET, GenerationPath, StrandGenRenderer,
};
use wgpu::util::DeviceExt;

/// Writes, for every batch vertex, `ribbon_centre`'s point (w: along) and tangent (w: side)
/// of the ribbon vertex on its +1 side.
const READBACK_ENTRY: &str = r#"
@group(0) @binding(30) var<storage, read_write> ribbon_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn ribbon_readback(@builtin(global_invocation_id) id: vec3<u32>) {
    let v = id.x;
    if 2u * v >= arrayLength(&ribbon_out) {
        return;
    }
    for (var r = 0u; r < hair.batch.y; r++) {
        let run = runs[r];
        let n = max(run.vertex_count, 2u);
        if v >= run.vertex_offset && v < run.vertex_offset + run.strand_count * n {
            let local = v - run.vertex_offset;
            let centre = ribbon_centre(2u * (local % n) + 1u, run_start(run, RUN_BY_STRAND) + local / n);
            ribbon_out[2u * v] = vec4<f32>(centre.p, centre.along);
            ribbon_out[2u * v + 1u] = vec4<f32>(centre.tangent, centre.side);
            return;
        }
    }
}
"#;

#[test]
fn vertex_shader_generation_matches_compute_and_the_cpu_mirror() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let document = common::sample("head_long_wavy");
    let runtime = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            precision: Precision::F16,
            strands_per_bundle: 16,
            ..RuntimeOptions::default()
        },
    );
    let roots = runtime.strand_roots();
    let generator = StrandGenRenderer::with_path(&context, GenerationPath::VertexShader);
    let hair = generator.upload(&context, &runtime).expect("upload");
    // A camera far enough for partial strand counts, several vertex levels and morphing;
    // one batch.
    let (lo, hi) = runtime.textures.hair_bounds().expect("hair");
    let (camera, lod) = common::morphing_lod(lo, hi);
    let mut plan = plan_frame(&hair.bundles, 16, 5, &camera, &lod, usize::MAX / 2, &[]);
    assert_eq!(plan.batches.len(), 1);
    // And a run of 2-vertex strands (the tangent's other rule) at the end.
    let last = *plan.batches[0].last().expect("runs");
    let extra = StrandRun {
        first_root: 0,
        strand_count: 3,
        vertex_count: 2,
        vertex_offset: last.vertex_offset + last.strand_count * last.vertex_count,
        segment_offset: last.segment_offset + last.strand_count * (last.vertex_count - 1),
        gamma: 0.0,
        thickness: 1.0,
        _padding: 0,
    };
    plan.batches[0].push(extra);
    plan.strands += 3;
    plan.vertices += 6;
    let runs = plan.batches[0].clone();
    assert!(runs.iter().any(|r| r.gamma > 0.0), "no run morphs");
    assert!(
        runs.iter().any(|r| r.vertex_count != runs[0].vertex_count),
        "one vertex count only"
    );

    // The compute path's vertices (per strand), and the CPU mirror's.
    let computed = generator
        .generate_positions(&context, &hair, &plan, Filtering::Exact)
        .expect("compute");
    let computed: Vec<Vec3> = computed.iter().map(|p| Vec3::from_slice(&p[..3])).collect();
    let mirror = StrandGen {
        textures: &runtime.textures,
        filtering: Filtering::Exact,
    };
    let expected = mirror.main(&roots, &runs, &[&document.styling.global]);
    let tangents = batch_tangents(&computed, &runs);

    // The vertex shader's points and tangents.
    let device = &context.device;
    let key = ShaderKey::all()[0];
    let source = format!(
        "{}\n{READBACK_ENTRY}",
        hair_shader(&key, RibbonInput::Generated)
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("ribbon_readback"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("ribbon_readback"),
        layout: None,
        module: &module,
        entry_point: Some("ribbon_readback"),
        compilation_options: Default::default(),
        cache: None,
    });
    let uniforms = HairUniforms {
        view_projection: glam::Mat4::IDENTITY.to_cols_array_2d(),
        eye: [0.0, 0.0, 1.0, 1.0],
        width: [0.0; 4],
        batch: [0, runs.len() as u32, 0, 0],
    };
    let uniform_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("hair"),
        contents: bytemuck::bytes_of(&uniforms),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let runs_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("runs"),
        contents: bytemuck::cast_slice(&runs),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let bytes = (plan.vertices * 32) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("ribbon_out"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("ribbon_readback"),
        size: bytes,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let params = generator.params_buffer(&context, &hair, Filtering::Exact, 0, &[]);
    let mut entries = vec![
        wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform_buffer.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 2,
            resource: runs_buffer.as_entire_binding(),
        },
        wgpu::BindGroupEntry {
            binding: 30,
            resource: output.as_entire_binding(),
        },
    ];
    entries.extend(generator.source_entries(GENERATED_BINDING_OFFSET, &hair, &params));
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ribbon_readback"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((plan.vertices as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
    context.queue.submit([encoder.finish()]);
    let bytes = read_buffer(&context, &readback).expect("read back");
    let gpu: &[[f32; 4]] = bytemuck::cast_slice(&bytes);

    let size = document.hair_mesh.size() as f32;
    let (mut vs_compute, mut vs_mirror, mut tangent) = (0.0f32, 0.0f32, 0.0f32);
    let mut v = 0;
    for run in &runs {
        let n = run.vertex_count.max(2) as usize;
        for _ in 0..run.strand_count {
            for k in 0..n {
                let point = Vec3::from_slice(&gpu[2 * v][..3]);
                let along = gpu[2 * v][3];
                let t = Vec3::from_slice(&gpu[2 * v + 1][..3]);
                assert!(point.is_finite() && t.is_finite(), "vertex {v}");
                assert_eq!(gpu[2 * v + 1][3], 1.0, "vertex {v}: side");
                assert!(
                    (along - k as f32 / (n - 1) as f32).abs() < 1e-6,
                    "vertex {v}"
                );
                vs_compute = vs_compute.max(point.distance(computed[v]));
                vs_mirror = vs_mirror.max(point.distance(expected[v]));
                tangent = tangent.max(t.distance(tangents[v]));
                v += 1;
            }
        }
    }
    assert_eq!(v, plan.vertices);
    eprintln!(
        "{} vertices in {} runs: |vs − compute| {vs_compute:.2e}, |vs − CPU mirror| {vs_mirror:.2e} (size {size:.3}), tangents |vs − compute| {tangent:.2e}",
        plan.vertices,
        runs.len()
    );
    // Today's bound for exact filtering against the mirror (render/tests/strand_gen.rs).
    assert!(vs_mirror <= 1e-5 * size, "{vs_mirror}");
    assert!(vs_compute <= 1e-5 * size, "{vs_compute}");
    // Unit tangents from points a few µm apart at most.
    assert!(tangent <= 1e-3, "{tangent}");
}

/// The whole frame — opacity-map and body shadow passes, the depth pre-pass, the lit pass
/// and width-based coverage, LOD on — drawn with ribbons that generate their own vertices
/// and with the compute path: the same picture.
#[test]
fn vertex_shader_frames_match_compute_frames() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let (pictures, plan) = common::frames(
        &context,
        "head_curly",
        12,
        33,
        LodSettings::default(),
        Vec3::new(0.6, 0.2, 1.0),
        &[
            GenerationPath::ComputePerStrand,
            GenerationPath::VertexShader,
        ],
    );
    assert!(plan.strands > 0);
    let pixels = pictures[0].len() / 4;
    let (differing, drawn) = common::compare(&pictures[0], &pictures[1]);
    eprintln!("{differing} of {pixels} pixels differ by more than 2/255 ({drawn} drawn)");
    assert!(drawn > pixels / 10, "the head is in the picture");
    assert!(
        differing * 1000 <= pixels,
        "{differing} of {pixels} pixels differ"
    );
}
