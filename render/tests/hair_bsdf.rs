//! The lighting shaders against their CPU mirrors: `hair_bsdf` (light/hair_bsdf.wgsl ↔
//! `hairloom_core::light::hair_bsdf`), `dual_scattering` (light/dual_scattering.wgsl ↔
//! `hairloom_core::light::dual_scattering`) and far hair's `aggregated_bcsdf` and
//! `cluster_hairs_on_path` and `aggregated_cluster` (light/aggregated_bcsdf.wgsl ↔
//! `hairloom_core::light::aggregated_bcsdf`), evaluated by a compute entry point appended to
//! the hair shader, over many directions, offsets, absorptions, fibre counts and cluster
//! shapes, including the hard cases (light along the tangent, grazing angles, h = ±1, lowest
//! roughness, one-strand and flat clusters, the ribbon's edges).

use glam::{DVec3, Vec3};
use hairloom_core::light::aggregated_bcsdf::{
    AggregatedTables, ClusterShape, HairsOnPath, VISIBLE_DEPTHS, cluster_hairs_on_path,
};
use hairloom_core::light::dual_scattering::DualScatteringTables;
use hairloom_core::light::hair_bsdf::{HairBsdf, direction};
use hairloom_core::light::kajiya_kay::{KajiyaKayTable, kajiya_kay};
use hairloom_core::light::material::Fibre;
use hairloom_core::light::scene_uniforms::SceneUniforms;
use hairloom_core::model::scene::{
    HairMaterial, LightSource, Pigment, Scene, SelfShadowing, Shading,
};
use hairloom_render::device::{GpuContext, headless_for_test, read_buffer};
use hairloom_render::preview::PreviewRenderer;
use hairloom_render::renderer::preview_hair::default_hair_shader;
use hairloom_render::renderer::scene_lighting::{ActiveEffects, SceneLighting};
use hairloom_render::renderer::shader_composer::{
    RibbonInput, ShaderKey, aggregated_bcsdf_module, hair_shader,
};
use wgpu::util::DeviceExt;

/// One case: wo, wi (fibre frame), h, σ_a, n.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Case {
    wo: [f32; 4],
    wi: [f32; 4],
    sigma_a: [f32; 4],
    /// x: h, y: n.
    extra: [f32; 4],
}

/// The cases and results of the entry points below (appended to the shader before them).
const CASES: &str = r#"
struct Case {
    wo: vec4<f32>,
    wi: vec4<f32>,
    sigma_a: vec4<f32>,
    extra: vec4<f32>,
}
@group(0) @binding(10) var<storage, read> cases: array<Case>;
@group(0) @binding(11) var<storage, read_write> results: array<vec4<f32>>;
"#;

const ENTRY: &str = r#"
@compute @workgroup_size(64)
fn evaluate(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&cases) {
        return;
    }
    let c = cases[i];
    let single = hair_bsdf(c.wo.xyz, c.wi.xyz, c.extra.x, c.sigma_a.xyz);
    let dual = dual_scattering(c.wo.xyz, c.wi.xyz, single, c.extra.y);
    results[2u * i] = vec4<f32>(single, 0.0);
    results[2u * i + 1u] = vec4<f32>(dual, 0.0);
}
"#;

fn run_cases(context: &GpuContext, lighting: &SceneLighting, cases: &[Case]) -> Vec<[f32; 4]> {
    let pipeline = compute_pipeline(
        context,
        &format!("{}\n{CASES}{ENTRY}", default_hair_shader()),
        "evaluate",
    );
    let ds = lighting.dual_scattering.as_ref().expect("tables");
    run_compute(
        context,
        &pipeline,
        lighting,
        bytemuck::cast_slice(cases),
        cases.len(),
        &[
            wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::Sampler(&lighting.table_sampler),
            },
            wgpu::BindGroupEntry {
                binding: 5,
                resource: wgpu::BindingResource::TextureView(&ds.profile_view),
            },
            wgpu::BindGroupEntry {
                binding: 6,
                resource: wgpu::BindingResource::TextureView(&ds.lobes_view),
            },
        ],
    )
}

fn compute_pipeline(context: &GpuContext, source: &str, entry: &str) -> wgpu::ComputePipeline {
    let device = &context.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(entry),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: None,
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// Runs `pipeline` once per case: cases at group 0 binding 10, two `vec4` results per case at
/// binding 11, the scene at group 1, `tables` at group 2 (none: no group 2).
fn run_compute(
    context: &GpuContext,
    pipeline: &wgpu::ComputePipeline,
    lighting: &SceneLighting,
    cases: &[u8],
    count: usize,
    tables: &[wgpu::BindGroupEntry],
) -> Vec<[f32; 4]> {
    let device = &context.device;
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("cases"),
        contents: cases,
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (count * 2 * 16) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("results"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let group = |index: u32, entries: &[wgpu::BindGroupEntry]| {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(index),
            entries,
        })
    };
    let g0 = group(
        0,
        &[
            wgpu::BindGroupEntry {
                binding: 10,
                resource: input.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 11,
                resource: output.as_entire_binding(),
            },
        ],
    );
    let g1 = group(
        1,
        &[wgpu::BindGroupEntry {
            binding: 0,
            resource: lighting.uniform_buffer().as_entire_binding(),
        }],
    );
    // A shader that reads no tables has no group 2.
    let g2 = (!tables.is_empty()).then(|| group(2, tables));
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &g0, &[]);
        pass.set_bind_group(1, &g1, &[]);
        if let Some(g2) = &g2 {
            pass.set_bind_group(2, g2, &[]);
        }
        pass.dispatch_workgroups((count as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
    context.queue.submit([encoder.finish()]);
    bytemuck::cast_slice(&read_buffer(context, &readback).expect("read back")).to_vec()
}

#[test]
fn gpu_fibre_shading_matches_the_cpu_mirror() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let _ = PreviewRenderer::new(&context);
    for material in [
        HairMaterial::default(),
        HairMaterial {
            longitudinal_roughness: 0.0,
            azimuthal_roughness: 0.0,
            cuticle_tilt_deg: 0.0,
            ..HairMaterial::default()
        },
        HairMaterial {
            longitudinal_roughness: 0.8,
            azimuthal_roughness: 1.0,
            cuticle_tilt_deg: 8.0,
            ior: 1.3,
            ..HairMaterial::default()
        },
    ] {
        let scene = Scene {
            material: material.clone(),
            ..Scene::default()
        };
        let mut lighting = SceneLighting::new(&context);
        let active = ActiveEffects::new(&scene, true);
        let mean_forward = lighting.sync(&context, &active, &scene.material);
        let tables = &lighting
            .dual_scattering
            .as_ref()
            .expect("dual scattering on")
            .tables;
        lighting.write(
            &context,
            &SceneUniforms::new(&scene, &[], Some(tables), mean_forward, 0.2, 0.0005),
        );
        let fibre = Fibre::new(&material);
        let bsdf = HairBsdf::new(&fibre);
        let cpu_tables = DualScatteringTables::new(&fibre);
        let mut cases = Vec::new();
        let mut expected = Vec::new();
        let half_pi = std::f64::consts::FRAC_PI_2;
        let angles = [-half_pi, -1.2, -0.5, 0.0, 0.3, 0.9, half_pi];
        let azimuths = [0.0, 0.7, 1.6, 3.1, -2.4];
        for &theta_o in &angles {
            for &theta_i in &angles {
                for (k, &phi) in azimuths.iter().enumerate() {
                    let wo = direction(theta_o, 0.4);
                    let wi = direction(theta_i, 0.4 + phi);
                    let h = [-1.0, -0.6, 0.0, 0.35, 1.0][k];
                    let n = [0.0, 0.4, 1.0, 3.0, 12.0][(k + 2) % 5];
                    let sigma_a = fibre.sigma_a(0.2 * k as f64, 0.3);
                    let single = bsdf.hair_bsdf(wo, wi, h, sigma_a);
                    let dual = cpu_tables.dual_scattering(wo, wi, single, n);
                    let f = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
                    cases.push(Case {
                        wo: f(wo),
                        wi: f(wi),
                        sigma_a: [sigma_a[0] as f32, sigma_a[1] as f32, sigma_a[2] as f32, 0.0],
                        extra: [h as f32, n as f32, 0.0, 0.0],
                    });
                    expected.push((single, dual));
                }
            }
        }
        let results = run_cases(&context, &lighting, &cases);
        let mut worst = (0.0f64, 0.0f64);
        for (i, (single, dual)) in expected.iter().enumerate() {
            for c in 0..3 {
                let gpu_single = results[2 * i][c] as f64;
                let gpu_dual = results[2 * i + 1][c] as f64;
                assert!(gpu_single.is_finite() && gpu_dual.is_finite(), "case {i}");
                // f32 against f64, narrow lobes included: relative 1% or 1e-3 absolute for
                // the single-scattering value; the tables are f16 and bilinearly filtered
                // on the GPU, so dual scattering gets 3% or 3e-3.
                let e1 = (gpu_single - single[c]).abs() / (single[c].abs() * 0.01 + 1e-3);
                let e2 = (gpu_dual - dual[c]).abs() / (dual[c].abs() * 0.03 + 3e-3);
                worst = (worst.0.max(e1), worst.1.max(e2));
                assert!(
                    e1 <= 1.0,
                    "{material:?} case {i} channel {c}: GPU {gpu_single} CPU {}",
                    single[c]
                );
                assert!(
                    e2 <= 1.0,
                    "{material:?} case {i} channel {c}: dual GPU {gpu_dual} CPU {}",
                    dual[c]
                );
            }
        }
        eprintln!(
            "worst error / tolerance: single {:.3}, dual {:.3}",
            worst.0, worst.1
        );
    }
}

/// `sigma_a` carries the hair's colour here.
const KAJIYA_KAY_ENTRY: &str = r#"
@compute @workgroup_size(64)
fn evaluate_kajiya_kay(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&cases) {
        return;
    }
    let c = cases[i];
    results[2u * i] = vec4<f32>(kajiya_kay(c.wo.xyz, c.wi.xyz, c.sigma_a.xyz, scene.lights[0].kajiya_kay), 0.0);
    results[2u * i + 1u] = vec4<f32>(0.0);
}
"#;

/// `kajiya_kay` (light/kajiya_kay.wgsl) against `hairloom_core::light::kajiya_kay` with the
/// key light's weights the scene uniforms carry for three materials, the mirror and highlight directions
/// included (and looking straight into the light, where there is no half vector).
#[test]
fn gpu_kajiya_kay_matches_the_cpu_mirror() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let key = ShaderKey {
        shading: Shading::KajiyaKay,
        opacity_maps: SelfShadowing::None,
        body_shadows: false,
        dual_scattering: false,
    };
    let pipeline = compute_pipeline(
        &context,
        &format!(
            "{}\n{CASES}{KAJIYA_KAY_ENTRY}",
            hair_shader(&key, RibbonInput::Buffer)
        ),
        "evaluate_kajiya_kay",
    );
    for material in [
        HairMaterial::default(),
        HairMaterial {
            pigment: Pigment::Color {
                rgb: [0.9, 0.8, 0.6],
            },
            ..HairMaterial::default()
        },
        HairMaterial {
            pigment: Pigment::Melanin {
                eumelanin: 4.0,
                pheomelanin: 0.1,
            },
            longitudinal_roughness: 0.1,
            ..HairMaterial::default()
        },
    ] {
        let scene = Scene {
            material: material.clone(),
            effects: Scene::default().effects.none(),
            ..Scene::default()
        };
        let lighting = SceneLighting::new(&context);
        let mut uniforms = SceneUniforms::new(&scene, &[], None, [0.5; 3], 0.2, 0.0005);
        let (center, eye) = (Vec3::new(0.0, 1.6, 0.0), Vec3::new(0.3, 1.7, 1.0));
        let fibre = Fibre::new(&material);
        let table = KajiyaKayTable::new(&fibre);
        uniforms.match_kajiya_kay(&scene, center, eye, &table);
        lighting.write(&context, &uniforms);
        let LightSource::Directional { to_light } = scene.lights[0].source else {
            panic!("the default key light is directional");
        };
        let weights = table.at((eye - center).as_dvec3(), Vec3::from(to_light).as_dvec3());
        assert!(weights.primary > 0.0 && weights.tint.iter().all(|t| *t > 0.0));
        let half_pi = std::f64::consts::FRAC_PI_2;
        let angles = [-half_pi, -1.2, -0.5, 0.0, 0.02, 0.3, 0.9, half_pi];
        let azimuths = [0.0, 0.7, 1.6, 3.1, std::f64::consts::PI, -2.4];
        let mut cases = Vec::new();
        let mut expected = Vec::new();
        for &theta_o in &angles {
            for &theta_i in &angles {
                for (k, &phi) in azimuths.iter().enumerate() {
                    let wo = direction(theta_o, 0.4);
                    let wi = direction(theta_i, 0.4 + phi);
                    let base = fibre.color(fibre.sigma_a(0.2 * k as f64, 0.3));
                    let f = |v: [f64; 3]| [v[0] as f32, v[1] as f32, v[2] as f32, 0.0];
                    cases.push(Case {
                        wo: f(wo.to_array()),
                        wi: f(wi.to_array()),
                        sigma_a: f(base),
                        extra: [0.0; 4],
                    });
                    expected.push(kajiya_kay(wo, wi, base, &weights));
                }
            }
        }
        let results = run_compute(
            &context,
            &pipeline,
            &lighting,
            bytemuck::cast_slice(&cases),
            cases.len(),
            &[],
        );
        for (i, cpu) in expected.iter().enumerate() {
            for c in 0..3 {
                let gpu = results[2 * i][c] as f64;
                // f32 against f64 through pow(x, 80): relative 0.5 % or 1e-4.
                assert!(
                    (gpu - cpu[c]).abs() <= cpu[c].abs() * 5e-3 + 1e-4,
                    "{material:?} case {i} channel {c}: GPU {gpu} CPU {}",
                    cpu[c]
                );
            }
        }
    }
}

/// One aggregated case: wo, wi (fibre frame), the cluster (semi-axes, angle, crossings per
/// metre), and x: across, y: coverage, z: fibre radius, w: which visible depth.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ClusterCase {
    wo: [f32; 4],
    wi: [f32; 4],
    shape: [f32; 4],
    extra: [f32; 4],
}

const CLUSTER_ENTRY: &str = r#"
struct ClusterCase {
    wo: vec4<f32>,
    wi: vec4<f32>,
    shape: vec4<f32>,
    extra: vec4<f32>,
}
@group(0) @binding(10) var<storage, read> cluster_cases: array<ClusterCase>;
@group(0) @binding(11) var<storage, read_write> cluster_results: array<vec4<f32>>;

@compute @workgroup_size(64)
fn evaluate_cluster(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&cluster_cases) {
        return;
    }
    let c = cluster_cases[i];
    let path = cluster_hairs_on_path(c.shape, c.extra.z, c.wo.xyz, c.wi.xyz, c.extra.x, u32(c.extra.w));
    let f = aggregated_cluster(c.shape, c.extra.z, c.extra.y, c.wo.xyz, c.wi.xyz, c.extra.x);
    cluster_results[i] = vec4<f32>(f, path.x);
    cluster_results[arrayLength(&cluster_cases) + i] = vec4<f32>(path, 0.0, 0.0);
}
"#;

#[test]
fn gpu_aggregated_bcsdf_matches_the_cpu_mirror() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let device = &context.device;
    let pipeline = compute_pipeline(
        &context,
        &format!(
            "{}\n{}\n{CLUSTER_ENTRY}",
            default_hair_shader(),
            aggregated_bcsdf_module()
        ),
        "evaluate_cluster",
    );
    let fibre_radius_m = 40e-6;
    let shapes = [
        (30.0, 12.0, 0.3, 200u32),
        (60.0, 40.0, -1.0, 40),
        (40.0, 0.0, 0.0, 25),
        (0.0, 0.0, 0.0, 1),
        (400.0, 1.0, 1.2, 5000),
    ]
    .map(|(a, b, angle, members)| {
        ClusterShape::new(
            a * fibre_radius_m,
            b * fibre_radius_m,
            angle,
            members,
            fibre_radius_m,
        )
        .expect("valid cluster")
    });
    let mut worst = (0.0f64, 0.0f64);
    for material in [
        HairMaterial::default(),
        HairMaterial {
            longitudinal_roughness: 0.0,
            azimuthal_roughness: 0.0,
            cuticle_tilt_deg: 0.0,
            ..HairMaterial::default()
        },
        HairMaterial {
            longitudinal_roughness: 0.8,
            azimuthal_roughness: 1.0,
            cuticle_tilt_deg: 8.0,
            ior: 1.3,
            ..HairMaterial::default()
        },
    ] {
        let scene = Scene {
            material: material.clone(),
            ..Scene::default()
        };
        let lighting = SceneLighting::new(&context);
        lighting.write(
            &context,
            &SceneUniforms::new(&scene, &[], None, [0.5; 3], 0.2, 0.0005),
        );
        let tables = AggregatedTables::new(&Fibre::new(&material));
        let mut cases = Vec::new();
        let mut expected: Vec<(HairsOnPath, [f64; 3])> = Vec::new();
        let half_pi = std::f64::consts::FRAC_PI_2;
        let angles = [-half_pi, -1.0, -0.3, 0.0, 0.5, 1.2];
        let azimuths = [0.0, 0.7, 1.6, 3.1, -2.4, -0.4];
        for (s, shape) in shapes.iter().enumerate() {
            for &theta_o in &angles {
                for &theta_i in &angles {
                    for (k, &phi) in azimuths.iter().enumerate() {
                        let wo = direction(theta_o, half_pi + 0.1 * s as f64);
                        let wi = direction(theta_i, half_pi + phi);
                        let across = [-1.0, -0.6, 0.0, 0.35, 1.0, 0.9][(k + s) % 6];
                        let coverage = shape.coverage();
                        let depth = ((k + s) as u32) % VISIBLE_DEPTHS;
                        let path = cluster_hairs_on_path(shape, wo, wi, across, depth);
                        let f = tables.aggregated_cluster(shape, wo, wi, across);
                        let v = |v: DVec3| [v.x as f32, v.y as f32, v.z as f32, 0.0];
                        cases.push(ClusterCase {
                            wo: v(wo),
                            wi: v(wi),
                            shape: [
                                shape.semi_major_m as f32,
                                shape.semi_minor_m as f32,
                                shape.major_angle_rad as f32,
                                shape.crossings_per_m() as f32,
                            ],
                            extra: [
                                across as f32,
                                coverage as f32,
                                shape.fibre_radius_m as f32,
                                depth as f32,
                            ],
                        });
                        expected.push((path, f));
                    }
                }
            }
        }
        let table = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("aggregated tables"),
                contents: bytemuck::cast_slice(&tables.data),
                usage: wgpu::BufferUsages::STORAGE,
            },
        );
        let results = run_compute(
            &context,
            &pipeline,
            &lighting,
            bytemuck::cast_slice(&cases),
            cases.len(),
            &[wgpu::BindGroupEntry {
                binding: 7,
                resource: table.as_entire_binding(),
            }],
        );
        let count = cases.len();
        for (i, (path, f)) in expected.iter().enumerate() {
            let gpu_path = results[count + i];
            // Chords through flat ellipses, including ones that graze it (computed in the
            // ellipse's unit-circle coordinates so that they stay well-conditioned): f32
            // against f64, relative 1e-3 or 1e-3 hairs, plus f32's resolution of a chord as
            // long as the ellipse (1e-6 of the hairs across it: 6 thousandths of a hair in the
            // 400:1 ribbon of 5000).
            let shape = &shapes[i / (cases.len() / shapes.len())];
            let across_hairs = shape.crossings_per_m() * 2.0 * shape.semi_major_m;
            for (gpu, cpu) in [(gpu_path[0], path.before), (gpu_path[1], path.behind)] {
                let e = (gpu as f64 - cpu).abs() / (cpu.abs() * 1e-3 + 1e-3 + 1e-6 * across_hairs);
                worst.0 = worst.0.max(e);
                assert!(e <= 1.0, "{material:?} case {i}: path GPU {gpu} CPU {cpu}");
            }
            for c in 0..3 {
                let gpu = results[i][c] as f64;
                assert!(gpu.is_finite() && gpu >= 0.0, "case {i}: {gpu}");
                // f32 against f64 with narrow lobes and powers of the attenuation: relative
                // 2 % or 1e-3 absolute.
                let e = (gpu - f[c]).abs() / (f[c].abs() * 0.02 + 1e-3);
                worst.1 = worst.1.max(e);
                assert!(
                    e <= 1.0,
                    "{material:?} case {i} channel {c}: GPU {gpu} CPU {}",
                    f[c]
                );
            }
        }
    }
    eprintln!(
        "worst error / tolerance: path {:.3}, aggregated {:.3}",
        worst.0, worst.1
    );
}
