//! The lighting shaders against their CPU mirrors: `hair_bsdf` (light/hair_bsdf.wgsl ↔
//! `hairloom_core::light::hair_bsdf`) and `dual_scattering` (light/dual_scattering.wgsl ↔
//! `hairloom_core::light::dual_scattering`), evaluated by a compute entry point appended to the
//! hair shader, over many directions, offsets, absorptions and fibre counts, including the hard
//! cases (light along the tangent, grazing angles, h = ±1, lowest roughness).

use glam::DVec3;
use hairloom_core::light::dual_scattering::DualScatteringTables;
use hairloom_core::light::hair_bsdf::{HairBsdf, direction};
use hairloom_core::light::material::Fibre;
use hairloom_core::light::scene_uniforms::SceneUniforms;
use hairloom_core::model::scene::{HairMaterial, Scene};
use hairloom_render::device::{GpuContext, headless_for_test, read_buffer};
use hairloom_render::preview::PreviewRenderer;
use hairloom_render::renderer::preview_hair::default_hair_shader;
use hairloom_render::renderer::scene_lighting::{ActiveEffects, SceneLighting};
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

const ENTRY: &str = r#"
struct Case {
    wo: vec4<f32>,
    wi: vec4<f32>,
    sigma_a: vec4<f32>,
    extra: vec4<f32>,
}
@group(0) @binding(10) var<storage, read> cases: array<Case>;
@group(0) @binding(11) var<storage, read_write> results: array<vec4<f32>>;

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
    let device = &context.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("hair_bsdf_mirror"),
        source: wgpu::ShaderSource::Wgsl(format!("{}\n{ENTRY}", default_hair_shader()).into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("hair_bsdf_mirror"),
        layout: None,
        module: &module,
        entry_point: Some("evaluate"),
        compilation_options: Default::default(),
        cache: None,
    });
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("cases"),
        contents: bytemuck::cast_slice(cases),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (cases.len() * 2 * 16) as u64;
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
    let ds = lighting.dual_scattering.as_ref().expect("tables");
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
    let g2 = group(
        2,
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
    );
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &g0, &[]);
        pass.set_bind_group(1, &g1, &[]);
        pass.set_bind_group(2, &g2, &[]);
        pass.dispatch_workgroups((cases.len() as u32).div_ceil(64), 1, 1);
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
