//! One renderer per feature (re_renderer's shape): each owns the pipelines and bind-group
//! layouts of its shader, and records its work into a frame that [`crate::preview`] composes
//! from the scene's effects. Each is named after its shader: `shaders/X.wgsl` ↔
//! `renderer/X.rs` ↔ `hairloom_core::runtime::X` or `hairloom_core::light::X` (the CPU mirror
//! tests compare against).
//!
//! | renderer | shader | when |
//! |---|---|---|
//! | [`strand_gen`] | `strand_gen.wgsl` | every frame with generated hair |
//! | [`preview_hair`] | `preview_hair.wgsl` + `light/*` | always (the lit ribbons; OIT entry with width-based coverage) |
//! | [`preview_hair`], [`hair_shadow`] | + `strand_mesh.wgsl` | the mesh-shader generation path (task and mesh stages in place of the vertex shader) |
//! | [`preview_body`] | `preview_body.wgsl` + `light/*` | always |
//! | [`hair_shadow`] | `hair_shadow.wgsl` | opacity shadow maps or deep opacity maps |
//! | [`body_shadow`] | `preview_body.wgsl` (`vs_shadow`) | body shadows |
//! | [`oit_composite`] | `oit_composite.wgsl` | width-based coverage |
//! | [`scene_lighting`] | `shared/scene.wgsl`, `light/dual_scattering.wgsl` | always (tables: dual scattering) |
//! | [`viewport_blit`] | `viewport_blit.wgsl` | the editor's viewport (an egui paint callback) |
//! | [`far_hair`], [`far_lod`], [`strand_gen`] (`ThickGenRenderer`) | `far_hair*.wgsl` + `light/aggregated_bcsdf.wgsl`, `far_lod.wgsl`, `strand_gen.wgsl` (`thick_main`) | far hair (`far: aggregated`) |
//! | [`fur`] | `fur.wgsl` + `light/*` | fur (`fur: shells_fins`, seed 002) |
//! | [`linear_hair_skinning`] | `linear_hair_skinning.wgsl` | the LHS baseline (`bench gpu`), in place of generation |

pub mod body_shadow;
pub mod far_hair;
pub mod far_lod;
pub mod fur;
pub mod hair_shadow;
pub mod linear_hair_skinning;
pub mod oit_composite;
pub mod preview_body;
pub mod preview_hair;
pub mod scene_lighting;
pub mod shader_composer;
pub mod strand_gen;
pub mod viewport_blit;

use crate::device::GpuContext;
use crate::resources::Tracked;
use crate::view::{COLOR_FORMAT, DEPTH_FORMAT};

/// What differs between the renderers' pipelines; the rest (no culling) is shared.
pub(crate) struct PipelineSpec<'a> {
    pub label: &'a str,
    pub source: &'a str,
    pub groups: &'a [&'a wgpu::BindGroupLayout],
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    pub vertex_entry: &'a str,
    /// Triangle lists, or a strip per instance (ribbons generated in the vertex shader).
    pub topology: wgpu::PrimitiveTopology,
    /// `None`: a depth-only pipeline.
    pub fragment_entry: Option<&'a str>,
    pub targets: &'a [Option<wgpu::ColorTargetState>],
    pub depth: Option<wgpu::DepthStencilState>,
    pub sample_count: u32,
}

/// The shader module and pipeline layout of `spec`.
fn module_and_layout(
    context: &GpuContext,
    spec: &PipelineSpec,
) -> (wgpu::ShaderModule, wgpu::PipelineLayout) {
    let device = &context.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(spec.label),
        source: wgpu::ShaderSource::Wgsl(spec.source.into()),
    });
    let groups: Vec<Option<&wgpu::BindGroupLayout>> =
        spec.groups.iter().map(|g| Some(*g)).collect();
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(spec.label),
        bind_group_layouts: &groups,
        immediate_size: 0,
    });
    (module, layout)
}

/// `topology` with no culling: ribbons face the viewer from either winding.
fn primitive_state(topology: wgpu::PrimitiveTopology) -> wgpu::PrimitiveState {
    wgpu::PrimitiveState {
        topology,
        cull_mode: None,
        ..Default::default()
    }
}

fn multisample_state(spec: &PipelineSpec) -> wgpu::MultisampleState {
    wgpu::MultisampleState {
        count: spec.sample_count,
        ..Default::default()
    }
}

/// The fragment stage of `spec` (none for a depth-only pipeline).
fn fragment_state<'a>(
    spec: &'a PipelineSpec,
    module: &'a wgpu::ShaderModule,
) -> Option<wgpu::FragmentState<'a>> {
    spec.fragment_entry.map(|entry| wgpu::FragmentState {
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        targets: spec.targets,
    })
}

pub(crate) fn pipeline(context: &GpuContext, spec: &PipelineSpec) -> Tracked<wgpu::RenderPipeline> {
    let device = &context.device;
    let (module, layout) = module_and_layout(context, spec);
    context.resources.render_pipeline(
        device,
        &wgpu::RenderPipelineDescriptor {
            label: Some(spec.label),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(spec.vertex_entry),
                compilation_options: Default::default(),
                buffers: spec.buffers,
            },
            primitive: primitive_state(spec.topology),
            depth_stencil: spec.depth.clone(),
            multisample: multisample_state(spec),
            fragment: fragment_state(spec, &module),
            multiview_mask: None,
            cache: None,
        },
    )
}

/// [`pipeline`] for a pass that draws ribbons from `input`: mesh-shader ribbons
/// ([`shader_composer::RibbonInput::Mesh`]) take the source's task and mesh entry points
/// (`ts_main`, `ms_main` of `strand_mesh.wgsl`) in place of its vertex shader.
pub(crate) fn ribbon_pipeline(
    context: &GpuContext,
    spec: &PipelineSpec,
    input: shader_composer::RibbonInput,
) -> Tracked<wgpu::RenderPipeline> {
    if input != shader_composer::RibbonInput::Mesh {
        return pipeline(context, spec);
    }
    let (module, layout) = module_and_layout(context, spec);
    // strand_mesh.wgsl reads no workgroup memory it has not written (each strand's set-up,
    // its styled and morphed points), and the outputs past the counts it sets are never
    // read, so the zeroing naga would add to every mesh workgroup (its outputs too) is
    // skipped.
    let stage_options = || wgpu::PipelineCompilationOptions {
        zero_initialize_workgroup_memory: false,
        ..Default::default()
    };
    context.resources.mesh_pipeline(
        &context.device,
        &wgpu::MeshPipelineDescriptor {
            label: Some(spec.label),
            layout: Some(&layout),
            task: Some(wgpu::TaskState {
                module: &module,
                entry_point: Some("ts_main"),
                compilation_options: stage_options(),
            }),
            mesh: wgpu::MeshState {
                module: &module,
                entry_point: Some("ms_main"),
                compilation_options: stage_options(),
            },
            primitive: primitive_state(wgpu::PrimitiveTopology::TriangleList),
            depth_stencil: spec.depth.clone(),
            multisample: multisample_state(spec),
            fragment: fragment_state(spec, &module),
            multiview: None,
            cache: None,
        },
    )
}

/// The formats and sample count of the targets a renderer's pipelines draw into: our
/// [`crate::view::View`]'s, or a game's own (see [`crate::game`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Targets {
    pub color: wgpu::TextureFormat,
    /// A depth format (the depth test is "nearer wins": smaller values are nearer).
    pub depth: wgpu::TextureFormat,
    pub sample_count: u32,
}

impl Targets {
    /// The view's targets at `sample_count` samples.
    pub fn view(sample_count: u32) -> Self {
        Self {
            color: COLOR_FORMAT,
            depth: DEPTH_FORMAT,
            sample_count,
        }
    }
}

/// The depth test: nearer wins, written when `write`.
pub(crate) fn view_depth(targets: &Targets, write: bool) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format: targets.depth,
        depth_write_enabled: Some(write),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// The colour target, opaque.
pub(crate) fn view_color_target(targets: &Targets) -> [Option<wgpu::ColorTargetState>; 1] {
    [Some(targets.color.into())]
}

/// A uniform-buffer layout entry at `binding`, read by both stages.
/// A read-only storage buffer of at least `size` bytes seen by `visibility`.
pub(crate) fn storage_entry(
    binding: u32,
    size: u64,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: wgpu::BufferSize::new(size),
        },
        count: None,
    }
}

pub(crate) fn uniform_entry(
    binding: u32,
    size: usize,
    has_dynamic_offset: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset,
            min_binding_size: wgpu::BufferSize::new(size as u64),
        },
        count: None,
    }
}
