//! The opacity-map and body-shadow lookups of the lit shaders (light/opacity_maps.wgsl,
//! light/body_shadows.wgsl) against the CPU mirror (`hairloom_core::light::opacity_maps`), on
//! synthetic maps: at texel centres they give exactly the mirror's count of fibres in front,
//! and points outside the light's view (beside it, behind the light, beyond its far plane,
//! NaN) see no fibre and full light — never NaN.

use glam::{Vec3, Vec4};
use hairloom_core::light::opacity_maps::{ShadowView, hairs_in_front};
use hairloom_core::light::scene_uniforms::SceneUniforms;
use hairloom_core::model::scene::{Scene, SelfShadowing};
use hairloom_render::device::{headless_for_test, read_buffer};
use hairloom_render::renderer::preview_hair::default_hair_shader;
use hairloom_render::renderer::scene_lighting::{ActiveEffects, SceneLighting};
use wgpu::util::DeviceExt;

const ENTRY: &str = r#"
@group(0) @binding(10) var<storage, read> points: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read_write> looked_up: array<vec4<f32>>;

@compute @workgroup_size(64)
fn lookup(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&points) {
        return;
    }
    let world = points[i].xyz;
    looked_up[i] = vec4<f32>(hairs_in_front(world, 0), body_visibility(world, 0), 0.0, 0.0);
}
"#;

const SIZE: u32 = 8;
const Z0: f32 = 0.25;

#[test]
fn opacity_lookups_match_the_mirror_and_are_finite_outside_the_light() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let device = &context.device;
    let scene = Scene::default();
    let (center, radius) = (Vec3::new(0.0, 1.6, 0.0), 0.2);
    let view = ShadowView::fit(&scene.lights[0].source, center, radius, SIZE);
    let mut lighting = SceneLighting::new(&context);
    let mean_forward = lighting.sync(&context, &ActiveEffects::new(&scene, true), &scene.material);
    let uniforms = SceneUniforms::new(
        &scene,
        &[view],
        lighting.dual_scattering.as_ref().map(|d| &d.tables),
        mean_forward,
        radius,
        0.0,
    );
    lighting.write(&context, &uniforms);
    // Opacity layers: texel (x, y) holds (1, 2, 3, 4) × (x + 1) fibres at its layer ends.
    let values = |x: u32| [1.0f32, 2.0, 3.0, 4.0].map(|v| v * (x + 1) as f32);
    let texels: Vec<u8> = (0..SIZE * SIZE)
        .flat_map(|i| values(i % SIZE))
        .flat_map(|v| half::f16::from_f32(v).to_le_bytes())
        .collect();
    let opacity = device.create_texture_with_data(
        &context.queue,
        &wgpu::TextureDescriptor {
            label: Some("test_opacity_layers"),
            size: wgpu::Extent3d {
                width: SIZE,
                height: SIZE,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba16Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &texels,
    );
    // Depth maps cleared to a constant: the first hair at Z0 everywhere, the body at 0.5.
    let depth = |label, value: f32| {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: SIZE,
                height: SIZE,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &texture.create_view(&Default::default()),
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(value),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        context.queue.submit([encoder.finish()]);
        texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        })
    };
    let first_hair = depth("test_first_hair", Z0);
    let body = depth("test_body_depth", 0.5);
    // Points: texel centres at several depths, then points outside the view.
    let inverse = view.view_projection.inverse();
    let at = |x: u32, y: u32, z: f32| {
        let ndc = Vec4::new(
            (x as f32 + 0.5) / SIZE as f32 * 2.0 - 1.0,
            1.0 - (y as f32 + 0.5) / SIZE as f32 * 2.0,
            z,
            1.0,
        );
        let world = inverse * ndc;
        world.truncate() / world.w
    };
    let mut points = Vec::new();
    let mut expected = Vec::new();
    let start = view.light_distance(Z0);
    let layer_depth = uniforms.shadows[0].layers[0];
    for (x, y) in [(0, 0), (3, 5), (7, 2)] {
        for z in [0.1, 0.26, 0.3, 0.4, 0.45, 0.6, 0.9] {
            points.push(at(x, y, z).extend(1.0));
            let n = hairs_in_front(
                SelfShadowing::DeepOpacityMaps,
                view.light_distance(z),
                start,
                layer_depth,
                &values(x),
            );
            expected.push(Some((n, if z > 0.5 { 0.0 } else { 1.0 })));
        }
    }
    let toward_light = view.eye;
    for outside in [
        center + Vec3::new(5.0, 0.0, 0.0).cross(toward_light).normalize() * 10.0,
        center + toward_light * 100.0,
        center - toward_light * 100.0,
        Vec3::splat(f32::NAN),
        Vec3::splat(f32::INFINITY),
    ] {
        points.push(outside.extend(1.0));
        expected.push(None);
    }
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("opacity_lookup"),
        source: wgpu::ShaderSource::Wgsl(format!("{}\n{ENTRY}", default_hair_shader()).into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("opacity_lookup"),
        layout: None,
        module: &module,
        entry_point: Some("lookup"),
        compilation_options: Default::default(),
        cache: None,
    });
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("points"),
        contents: bytemuck::cast_slice(&points.iter().map(|p| p.to_array()).collect::<Vec<_>>()),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (points.len() * 16) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("looked_up"),
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
    let opacity_view = opacity.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let group = |index: u32, entries: &[wgpu::BindGroupEntry]| {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(index),
            entries,
        })
    };
    fn buffer(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        }
    }
    fn texture(binding: u32, view: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        }
    }
    let g0 = group(0, &[buffer(10, &input), buffer(11, &output)]);
    let g1 = group(1, &[buffer(0, lighting.uniform_buffer())]);
    let g2 = group(
        2,
        &[
            texture(0, &opacity_view),
            texture(1, &first_hair),
            texture(2, &body),
            wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::Sampler(&lighting.depth_sampler),
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
        pass.dispatch_workgroups((points.len() as u32).div_ceil(64), 1, 1);
    }
    encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
    context.queue.submit([encoder.finish()]);
    let results: Vec<[f32; 4]> =
        bytemuck::cast_slice(&read_buffer(&context, &readback).expect("read back")).to_vec();
    for (i, (result, expected)) in results.iter().zip(&expected).enumerate() {
        let [n, visible, ..] = *result;
        assert!(
            n.is_finite() && visible.is_finite(),
            "point {i}: {result:?}"
        );
        match expected {
            Some((expected_n, expected_visible)) => {
                assert!(
                    (n - expected_n).abs() <= 2e-3 * expected_n.max(1.0),
                    "point {i} at {:?}: GPU {n} fibres, mirror {expected_n}",
                    points[i]
                );
                assert_eq!(visible, *expected_visible, "point {i}: body shadow");
            }
            None => {
                assert_eq!(n, 0.0, "point {i} outside the view sees no fibre");
                assert_eq!(visible, 1.0, "point {i} outside the view is lit");
            }
        }
    }
}
