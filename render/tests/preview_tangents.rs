//! The eq. 5-6 ribbon tangents of `preview_hair.wgsl` against their CPU mirror
//! (`hairloom_core::runtime::preview_hair`), on strands generated on the GPU from a bundled
//! sample. The shader's own `strand_tangent` runs in a compute entry point appended to the
//! preview shader (the vertex stage cannot write a buffer), reading the same `positions` and
//! `runs` bindings the vertex stage reads.

use glam::Vec3;
use hairloom_core::runtime::gpu_types::StrandRun;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::preview_hair::batch_tangents;
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_render::device::{headless_for_test, read_buffer};
use hairloom_render::renderer::strand_gen::{StrandGenRenderer, full_detail_plan};
use wgpu::util::DeviceExt;

/// Writes `strand_tangent` of every batch vertex to `tangents_out`.
const READBACK_ENTRY: &str = r#"
@group(0) @binding(3) var<storage, read_write> tangents_out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn tangent_readback(@builtin(global_invocation_id) id: vec3<u32>) {
    let v = id.x;
    if v >= arrayLength(&tangents_out) {
        return;
    }
    for (var r = 0u; r < arrayLength(&runs); r++) {
        let run = runs[r];
        let n = max(run.vertex_count, 2u);
        if v >= run.vertex_offset && v < run.vertex_offset + run.strand_count * n {
            let local = v - run.vertex_offset;
            let base = run.vertex_offset + (local / n) * n;
            tangents_out[v] = vec4<f32>(strand_tangent(base, local % n, n), 0.0);
            return;
        }
    }
}
"#;

#[test]
fn gpu_ribbon_tangents_match_the_cpu_mirror() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/samples/head_curly.hairloom");
    let document = hairloom_core::io::project::load(&path)
        .expect("sample")
        .document;
    let hair = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 4,
            ..RuntimeOptions::default()
        },
    );
    let generator = StrandGenRenderer::new(&context);
    let gpu_hair = generator.upload(&context, &hair).expect("upload");
    // Two runs of different vertex counts (the second with an odd count's neighbour rule
    // at 2 vertices), as vertex LOD produces them.
    let half = (gpu_hair.root_count / 2) as u32;
    let mut plan = full_detail_plan(half as usize, 17);
    let first = plan.batches[0][0];
    let second = StrandRun {
        first_root: half,
        strand_count: half,
        vertex_count: 2,
        vertex_offset: first.strand_count * 17,
        segment_offset: first.strand_count * 16,
        ..first
    };
    plan.batches[0].push(second);
    plan.strands += half as usize;
    plan.vertices += 2 * half as usize;
    let positions = generator
        .generate_positions(&context, &gpu_hair, &plan, Filtering::Exact)
        .expect("generated");
    let runs = &plan.batches[0];
    let expected = batch_tangents(
        &positions
            .iter()
            .map(|p| Vec3::from_slice(&p[..3]))
            .collect::<Vec<_>>(),
        runs,
    );

    let device = &context.device;
    let source = format!(
        "{}\n{READBACK_ENTRY}",
        hairloom_render::renderer::preview_hair::default_hair_shader()
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("preview_hair_tangent_readback"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("preview_hair_tangent_readback"),
        layout: None,
        module: &module,
        entry_point: Some("tangent_readback"),
        compilation_options: Default::default(),
        cache: None,
    });
    let storage = |label: &str, contents: &[u8]| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents,
            usage: wgpu::BufferUsages::STORAGE,
        })
    };
    let positions_buffer = storage("positions", bytemuck::cast_slice(&positions));
    let runs_buffer = storage("runs", bytemuck::cast_slice(runs));
    let bytes = (positions.len() * 16) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("tangents_out"),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("tangents_readback"),
        size: bytes,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("tangent_readback"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 1,
                resource: positions_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: runs_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: output.as_entire_binding(),
            },
        ],
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups((positions.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
    context.queue.submit([encoder.finish()]);
    let bytes = read_buffer(&context, &readback).expect("read back");
    let gpu: &[[f32; 4]] = bytemuck::cast_slice(&bytes);

    assert_eq!(gpu.len(), expected.len());
    let mut worst = 0.0f32;
    for (i, (g, e)) in gpu.iter().zip(&expected).enumerate() {
        let g = Vec3::from_slice(&g[..3]);
        assert!(g.is_finite(), "vertex {i}: {g}");
        worst = worst.max(g.distance(*e));
    }
    eprintln!(
        "tangents: {} vertices, worst |gpu − mirror| {worst:e}",
        gpu.len()
    );
    assert!(worst < 1e-5, "worst tangent difference {worst}");
    assert!(
        expected.iter().filter(|t| t.length() > 0.5).count() > expected.len() * 9 / 10,
        "most tangents are unit vectors"
    );
}
