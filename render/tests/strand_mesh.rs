//! Generation by task and mesh shaders (`shaders/strand_mesh.wgsl`) against the vertex-shader
//! path, whose strips it must reproduce triangle for triangle: whole frames with every pass
//! that draws the hair (opacity-map and body shadows, depth pre-pass, lit pass, width-based
//! coverage), with LOD (several vertex counts, morphing, several strands per mesh group) and
//! with strands long enough to be cut into chunks (257 vertices).
//!
//! Mesh shaders are an optional adapter feature: where the device lacks it these tests say
//! they skipped, unless `HAIRLOOM_REQUIRE_MESH_SHADERS=1` (then they fail). `make test` runs
//! them once more on Mesa 25's lavapipe, which has `VK_EXT_mesh_shader` (see the Makefile's
//! `mesh-shader-test`).

mod common;

use glam::Vec3;
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_render::device::{GpuContext, headless_for_test};
use hairloom_render::preview::{Camera, HairSource, PreviewError, PreviewRenderer, default_scene};
use hairloom_render::renderer::preview_body::GpuBody;
use hairloom_render::renderer::strand_gen::{
    GenerationPath, StrandGenError, StrandGenRenderer, mesh_shaders_available,
};

/// A device with mesh shaders, or `None` after saying why the test skipped.
fn mesh_context(test: &str) -> Option<GpuContext> {
    let context = headless_for_test(test)?;
    common::has_mesh_shaders(&context, test).then_some(context)
}

#[test]
fn mesh_shader_frames_match_vertex_shader_frames() {
    let Some(context) = mesh_context(module_path!()) else {
        return;
    };
    // LOD on with a wide morph window (λ = 1): partial strand counts, several vertex levels,
    // morphed odd vertices; up to 33 vertices per strand, so 2-16 strands per mesh group.
    let (_, lod) = common::morphing_lod(Vec3::ZERO, Vec3::ONE);
    let (pictures, plan) = common::frames(
        &context,
        "head_curly",
        12,
        33,
        lod,
        Vec3::new(0.6, 0.2, 1.0),
        &[GenerationPath::VertexShader, GenerationPath::MeshShader],
    );
    let runs: Vec<_> = plan.batches.iter().flatten().collect();
    let mut vertex_counts: Vec<u32> = runs.iter().map(|r| r.vertex_count).collect();
    vertex_counts.sort_unstable();
    vertex_counts.dedup();
    eprintln!("vertex counts {vertex_counts:?} in {} runs", runs.len());
    assert!(vertex_counts.len() >= 2, "{vertex_counts:?}");
    assert!(runs.iter().any(|r| r.gamma > 0.0), "some runs morph");
    let pixels = pictures[0].len() / 4;
    let (differing, drawn) = common::compare(&pictures[0], &pictures[1]);
    eprintln!("LOD on: {differing} of {pixels} pixels differ by more than 2/255 ({drawn} drawn)");
    assert!(drawn > pixels / 10, "the head is in the picture");
    // The same triangles from the same arithmetic, compiled for another stage: at most a
    // stray pixel (a seam or a wrong tangent at chunk ends would show on every strand).
    assert!(
        differing * 10_000 <= pixels,
        "{differing} of {pixels} differ"
    );
}

#[test]
fn strands_longer_than_a_mesh_group_are_drawn_in_chunks() {
    let Some(context) = mesh_context(module_path!()) else {
        return;
    };
    // 257 vertices per strand: three chunks of at most 95 vertices each, whose end vertices
    // evaluate their neighbour beyond the chunk for the tangent.
    let lod = LodSettings {
        enabled: false,
        ..LodSettings::default()
    };
    let (pictures, plan) = common::frames(
        &context,
        "head_long_wavy",
        4,
        257,
        lod,
        Vec3::new(-0.3, 0.1, -1.0),
        &[GenerationPath::VertexShader, GenerationPath::MeshShader],
    );
    assert!(plan.batches.iter().flatten().all(|r| r.vertex_count == 257));
    let pixels = pictures[0].len() / 4;
    let (differing, drawn) = common::compare(&pictures[0], &pictures[1]);
    eprintln!(
        "257 vertices: {differing} of {pixels} pixels differ by more than 2/255 ({drawn} drawn)"
    );
    assert!(drawn > pixels / 10, "the head is in the picture");
    // The same triangles from the same arithmetic, compiled for another stage: at most a
    // stray pixel (a seam or a wrong tangent at chunk ends would show on every strand).
    assert!(
        differing * 10_000 <= pixels,
        "{differing} of {pixels} differ"
    );
}

/// Where the device lacks mesh shaders the path is refused by name, never half-built; this
/// part runs on every adapter.
#[test]
fn mesh_shaders_are_refused_by_name_where_the_device_lacks_them() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let has = mesh_shaders_available(&context.device);
    assert_eq!(GenerationPath::MeshShader.available(&context.device), has);
    assert_eq!(
        GenerationPath::preferred(&context.device) == GenerationPath::MeshShader,
        has
    );
    match StrandGenRenderer::check_path(&context, GenerationPath::MeshShader) {
        Ok(()) => assert!(has),
        Err(error) => {
            assert!(!has);
            assert!(matches!(error, StrandGenError::NoMeshShaders { .. }));
            let message = error.to_string();
            assert!(
                message.contains(&context.adapter_info.name) && message.contains("mesh shaders"),
                "{message}"
            );
        }
    }
    for path in [
        GenerationPath::ComputePerStrand,
        GenerationPath::ComputePerVertex,
        GenerationPath::VertexShader,
    ] {
        assert!(StrandGenRenderer::check_path(&context, path).is_ok());
    }
    if has {
        return;
    }
    // A preview asked for mesh shaders on such a device answers with the error, never a
    // wgpu validation panic.
    let document = common::sample("head_short_straight");
    let runtime = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 2,
            ..RuntimeOptions::default()
        },
    );
    let body = GpuBody::upload(&context, &document.body);
    let (lo, hi) = runtime.textures.hair_bounds().expect("hair");
    let generator = StrandGenRenderer::with_path(&context, GenerationPath::MeshShader);
    let hair = generator.upload(&context, &runtime).expect("upload");
    let frame = default_scene(
        &body,
        HairSource::Generated {
            generator: &generator,
            hair: &hair,
            filtering: Filtering::Exact,
            lod: LodSettings::default(),
            far: None,
            fur: None,
        },
        9,
        (lo, hi),
        Camera::framing(lo, hi, Vec3::Z),
        &document.scene,
    );
    let preview = PreviewRenderer::new(&context);
    let plan = preview.plan(&frame, 32, 32);
    match preview.render(&context, &frame, &plan, 32, 32) {
        Err(PreviewError::Generation(StrandGenError::NoMeshShaders { .. })) => {}
        other => panic!(
            "expected the mesh-shader refusal, got {:?}",
            other.map(|p| p.len())
        ),
    }
}

/// Reads `bundle_lod` (`shaders/shared/strand_lod.wgsl`, what the task shaders plan with)
/// back through a compute entry point, so it runs on every adapter.
const LOD_READBACK: &str = r#"
@group(1) @binding(0) var<storage, read> test_bundles: array<BundleLodGpu>;
@group(1) @binding(1) var<uniform> test_lod: LodParams;
@group(1) @binding(2) var<storage, read_write> test_runs: array<StrandRun>;

@compute @workgroup_size(64)
fn lod_readback(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < test_lod.counts.z {
        test_runs[id.x] = bundle_lod(id.x, test_bundles[id.x], test_lod);
    }
}
"#;

/// The task shaders' level of detail (eq. 7-12 in f32 on the GPU) against the frame plan's
/// (`frame_plan::bundle_lod`, f64), bundle by bundle: near, middle, far and very far, LOD
/// off, a wide morph window, thinned bundles (density < 1), and strand
/// counts that are not powers of two.
#[test]
fn task_shader_lod_matches_the_frame_plan() {
    use hairloom_core::runtime::frame_plan::bundle_lod;
    use hairloom_core::runtime::gpu_types::{BundleLodGpu, LodParams, StrandRun};
    use hairloom_render::device::read_buffer;
    use hairloom_render::renderer::shader_composer::STRAND_LOD;
    use hairloom_render::renderer::strand_gen::SHADER_SOURCE;
    use wgpu::util::DeviceExt;
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let device = &context.device;
    // Thinned bundles (density < 1: Tools ▸ Set density), as an artist thins them.
    let mut document = common::sample("head_long_wavy");
    for bundle in document.hair_mesh.bundles.iter_mut().step_by(5) {
        bundle.density = 0.35;
    }
    let runtime = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 64,
            ..RuntimeOptions::default()
        },
    );
    let bounds = runtime.bundle_bounds();
    assert!(bounds.iter().any(|b| b.density < 1.0), "thinned bundles");
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("lod_readback"),
        source: wgpu::ShaderSource::Wgsl([SHADER_SOURCE, STRAND_LOD, LOD_READBACK].concat().into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("lod_readback"),
        layout: None,
        module: &module,
        entry_point: Some("lod_readback"),
        compilation_options: Default::default(),
        cache: None,
    });
    let (lo, hi) = runtime.textures.hair_bounds().expect("hair");
    let centre = (lo + hi) * 0.5;
    let max_log2 = 5;
    let (mut compared, mut levels, mut morphing, mut partial) = (0, Vec::new(), 0, 0);
    // Strand counts that are not powers of two too: density · N rounds differently in f32.
    for (per_bundle, distance) in [64u32, 10, 37]
        .into_iter()
        .flat_map(|n| [0.6f32, 3.0, 12.0, 60.0].map(|d| (n, d)))
    {
        let gpu_bundles: Vec<BundleLodGpu> = bounds
            .iter()
            .map(|b| BundleLodGpu::new(b, per_bundle))
            .collect();
        let bundle_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(&gpu_bundles),
            usage: wgpu::BufferUsages::STORAGE,
        });
        for settings in [
            LodSettings::default(),
            common::morphing_lod(lo, hi).1,
            LodSettings {
                enabled: false,
                ..LodSettings::default()
            },
        ] {
            let eye = centre + Vec3::new(0.3, 0.1, 1.0).normalize() * distance;
            let camera = common::lod_camera(eye, centre);
            let params = LodParams::new(
                &camera,
                &settings,
                per_bundle,
                max_log2,
                bounds.len() as u32,
                1,
            );
            let lod_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let size = (bounds.len() * size_of::<StrandRun>()) as u64;
            let output = device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipeline.get_bind_group_layout(1),
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: bundle_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: lod_buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: output.as_entire_binding(),
                    },
                ],
            });
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(1, &group, &[]);
                pass.dispatch_workgroups((bounds.len() as u32).div_ceil(64), 1, 1);
            }
            encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
            context.queue.submit([encoder.finish()]);
            let bytes = read_buffer(&context, &readback).expect("readback");
            let gpu: &[StrandRun] = bytemuck::cast_slice(&bytes);
            for (index, (bounds, gpu)) in bounds.iter().zip(gpu).enumerate() {
                let cpu = bundle_lod(
                    index as u32,
                    bounds,
                    per_bundle,
                    max_log2,
                    &camera,
                    &settings,
                );
                let what =
                    format!("bundle {index} of {per_bundle} strands at {distance} m, {settings:?}");
                assert_eq!(gpu.first_root, index as u32 * per_bundle, "{what}");
                assert_eq!(gpu.strand_count, cpu.strands, "{what}");
                assert_eq!(gpu.vertex_count, cpu.vertex_count, "{what}");
                assert!(
                    (gpu.gamma - cpu.gamma).abs() <= 1e-4,
                    "{what}: {gpu:?} {cpu:?}"
                );
                assert!(
                    (gpu.thickness - cpu.thickness).abs() <= 1e-5 * cpu.thickness,
                    "{what}: {gpu:?} {cpu:?}"
                );
                compared += 1;
                levels.push(cpu.vertex_count);
                morphing += usize::from(cpu.gamma > 0.0);
                partial += usize::from(cpu.strands > 0 && cpu.strands < per_bundle);
            }
        }
    }
    levels.sort_unstable();
    levels.dedup();
    eprintln!(
        "{compared} bundle plans agree: vertex counts {levels:?}, {morphing} morphing, {partial} with some strands dropped"
    );
    assert!(levels.len() >= 3 && morphing > 0 && partial > 0);
}

/// Far hair on the mesh-shader path: the task shaders leave the bundles that draw thick hairs
/// out (their levels bound beside the LOD parameters), so the picture is the vertex-shader
/// path's.
#[test]
fn far_hair_draws_on_the_mesh_path_as_on_compute() {
    use hairloom_core::model::scene::{Effects, FarHair, Scene};
    use hairloom_core::runtime::thick_hair::FarHair as FarTable;
    use hairloom_render::renderer::strand_gen::GpuFarHair;
    let Some(context) = mesh_context(module_path!()) else {
        return;
    };
    let document = common::sample("head_short_straight");
    let hair = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 8,
            ..RuntimeOptions::default()
        },
    );
    let body = GpuBody::upload(&context, &hair.body);
    let (lo, hi) = hair.textures.hair_bounds().expect("hair");
    let mut camera = Camera::framing(lo, hi, Vec3::new(0.3, 0.2, 1.0));
    camera.eye = camera.target + (camera.eye - camera.target) * 3.0;
    let lighting = Scene {
        effects: Effects {
            far_hair: FarHair::Aggregated,
            shadow_resolution: 128,
            ..Effects::default()
        },
        ..document.scene.clone()
    };
    let table = FarTable::build(&hair, 9).expect("hierarchy");
    let mut pictures = Vec::new();
    for path in [GenerationPath::VertexShader, GenerationPath::MeshShader] {
        let generator = StrandGenRenderer::with_path(&context, path);
        let gpu_hair = generator.upload(&context, &hair).expect("upload");
        let far = GpuFarHair::upload(&context, table.clone());
        let renderer = PreviewRenderer::new(&context);
        let scene = default_scene(
            &body,
            HairSource::Generated {
                generator: &generator,
                hair: &gpu_hair,
                filtering: Filtering::Exact,
                lod: LodSettings::default(),
                far: Some(&far),
                fur: None,
            },
            9,
            (lo, hi),
            camera,
            &lighting,
        );
        renderer
            .settle_far_levels(&context, &scene, 96, 96)
            .expect("settles");
        let plan = renderer.plan(&scene, 96, 96);
        assert!(plan.far_bundles > 0, "{path:?}: no far bundle");
        let pixels = renderer
            .render(&context, &scene, &plan, 96, 96)
            .unwrap_or_else(|e| panic!("{path:?}: {e}"));
        pictures.push((plan.far_levels, pixels));
    }
    assert_eq!(pictures[0].0, pictures[1].0, "both paths settle alike");
    let pixels = pictures[0].1.len() / 4;
    let (differing, drawn) = common::compare(&pictures[0].1, &pictures[1].1);
    eprintln!("far hair: {differing} of {pixels} pixels differ ({drawn} drawn)");
    assert!(drawn > pixels / 50, "the head is in the picture");
    assert!(differing * 100 <= pixels, "{differing} of {pixels} differ");
}
