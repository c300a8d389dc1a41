//! Hair ribbons (`shaders/preview_hair.wgsl`, with `shared/ribbon.wgsl`): every strand
//! segment a viewer-facing quad with eq. 5-6 tangents (CPU mirror:
//! `hairloom_core::runtime::preview_hair`), lit by the scene through the modules its effects
//! name ([`crate::renderer::shader_composer::hair_shader`]). The same draw bindings (group 0)
//! serve the shadow passes ([`crate::renderer::hair_shadow`]): one uniform buffer holds every
//! view (the camera, then each shadow-casting light) of every batch of a frame.

use bytemuck::{Pod, Zeroable};

use hairloom_core::runtime::frame_plan::FramePlan;
use hairloom_core::runtime::frame_plan::{LodCamera, LodSettings};
use hairloom_core::runtime::gpu_types::{BundleLodGpu, LodParams, StrandRun};
use hairloom_core::runtime::strand_gen::Filtering;
use wgpu::util::DeviceExt;

use crate::device::GpuContext;
use crate::renderer::scene_lighting::ActiveEffects;
pub use crate::renderer::shader_composer::RibbonInput;
use crate::renderer::shader_composer::{ShaderKey, hair_shader};
use crate::renderer::strand_gen::{
    GENERATED_BINDING_OFFSET, GpuHair, StrandGenRenderer, mesh_shaders_available,
    source_layout_entries,
};

/// Where `strand_mesh.wgsl`'s task shader binds the bundles' LOD bounds and the frame's LOD
/// parameters (group 0).
pub const MESH_BUNDLES_BINDING: u32 = 32;
pub const MESH_LOD_BINDING: u32 = 33;
/// Where it binds far hair's level per bundle (a bundle at level 1 or more draws thick hairs,
/// not strands; one 0 when the scene has no far hair).
pub const MESH_FAR_LEVELS_BINDING: u32 = 34;
use crate::renderer::{
    PipelineSpec, Targets, ribbon_pipeline, storage_entry, uniform_entry, view_color_target,
    view_depth,
};
use crate::resources::Tracked;

/// The default variant's source (Marschner, deep opacity maps, body shadows, dual
/// scattering): what tests that append an entry point to the hair shader compile.
pub fn default_hair_shader() -> String {
    hair_shader(
        &ShaderKey {
            shading: hairloom_core::model::scene::Shading::Marschner,
            opacity_maps: hairloom_core::model::scene::SelfShadowing::DeepOpacityMaps,
            body_shadows: true,
            dual_scattering: true,
        },
        RibbonInput::Buffer,
    )
}

/// Keep in sync with `shaders/shared/ribbon.wgsl` (`HairUniforms`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct HairUniforms {
    pub view_projection: [[f32; 4]; 4],
    /// xyz: the viewer's position (w = 1) or the unit direction toward an orthographic viewer
    /// (w = 0).
    pub eye: [f32; 4],
    /// x: ribbon width at the root (m); y: world size of a pixel at unit distance
    /// (perspective) or everywhere (orthographic); z: narrowest ribbon drawn, in pixels; w: 0.
    pub width: [f32; 4],
    /// x, y: the batch's runs (first, count); z: shadow slot; w: 0.
    pub batch: [u32; 4],
}

/// What the mesh path's task shaders plan a frame's LOD from: the camera, the settings and the
/// full-detail vertex level (as the CPU frame plan does, `frame_plan::bundle_lod`).
#[derive(Clone, Debug)]
pub struct MeshLod {
    pub camera: LodCamera,
    pub settings: LodSettings,
    pub max_vertices_log2: u32,
    /// Far hair's level per bundle, as the frame plan has them (empty: none).
    pub far_levels: Vec<u32>,
}

/// Formats of the weighted blended transparency targets.
pub const OIT_ACCUMULATION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
pub const OIT_REVEALAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;

struct HairPipelines {
    key: (ShaderKey, bool, RibbonInput),
    /// Depth only: the nearest ribbon per sample, so the lit pass shades each once.
    depth: Tracked<wgpu::RenderPipeline>,
    /// Lit, where the depth pre-pass left this ribbon nearest.
    main: Tracked<wgpu::RenderPipeline>,
    /// Width-based coverage: the strands narrower than a pixel, into the OIT targets.
    oit: Option<Tracked<wgpu::RenderPipeline>>,
}

/// Where the hair's passes bind the colour map at each root (`root_paint` in
/// `shaders/preview_hair.wgsl`; [`GpuHair`]'s, or one 0 where strands have no runtime asset).
pub const ROOT_PAINT_BINDING: u32 = 3;

/// The ribbons' bindings and the lit pipelines of the current effects.
pub struct HairRenderer {
    /// One 0 (no colour): the per-root colours of strands with no runtime asset.
    no_paint: wgpu::Buffer,
    /// Group 0 with the vertices in a buffer.
    draw_layout: wgpu::BindGroupLayout,
    /// Group 0 with strand_gen's resources, for ribbons that generate their vertices.
    generated_layout: wgpu::BindGroupLayout,
    /// The same for task and mesh shaders, with the bundles' bounding spheres; only on a
    /// device with mesh shaders.
    mesh_layout: Option<wgpu::BindGroupLayout>,
    /// Bytes between two uniform entries (the adapter's dynamic-offset alignment).
    uniform_stride: u64,
    targets: Targets,
    pipelines: Option<HairPipelines>,
}

/// One frame's ribbon bindings: every view's uniforms for every batch, one bind group.
pub struct PreparedHair {
    group: wgpu::BindGroup,
    input: RibbonInput,
    stride: u64,
    batch_count: usize,
    /// Mesh-shader ribbons: the task workgroups of one draw (x, y: one per bundle).
    mesh_tasks: [u32; 2],
}

impl HairRenderer {
    /// Drawing into the view's targets at `sample_count` samples.
    pub fn new(context: &GpuContext, sample_count: u32) -> Self {
        Self::with_targets(context, Targets::view(sample_count))
    }

    /// Drawing into targets of other formats (a game's).
    pub fn with_targets(context: &GpuContext, targets: Targets) -> Self {
        let device = &context.device;
        let storage =
            |binding: u32, size: u64| storage_entry(binding, size, wgpu::ShaderStages::VERTEX);
        let draw_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview_hair"),
            entries: &[
                // Dynamic offset: one uniform buffer holds every view and batch of a frame.
                uniform_entry(0, size_of::<HairUniforms>(), true),
                storage(1, 16),
                storage(
                    2,
                    size_of::<hairloom_core::runtime::gpu_types::StrandRun>() as u64,
                ),
                storage(ROOT_PAINT_BINDING, 4),
            ],
        });
        let mut generated_entries = vec![
            uniform_entry(0, size_of::<HairUniforms>(), true),
            storage(
                2,
                size_of::<hairloom_core::runtime::gpu_types::StrandRun>() as u64,
            ),
            storage(ROOT_PAINT_BINDING, 4),
        ];
        generated_entries.extend(source_layout_entries(
            device,
            GENERATED_BINDING_OFFSET,
            wgpu::ShaderStages::VERTEX,
        ));
        let generated_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("preview_hair_generated"),
            entries: &generated_entries,
        });
        let mesh_layout = mesh_shaders_available(device).then(|| {
            let stages = wgpu::ShaderStages::TASK | wgpu::ShaderStages::MESH;
            let mut entries: Vec<wgpu::BindGroupLayoutEntry> = generated_entries
                .iter()
                .map(|entry| wgpu::BindGroupLayoutEntry {
                    visibility: match entry.binding {
                        0 => stages | wgpu::ShaderStages::FRAGMENT,
                        _ => stages,
                    },
                    ..*entry
                })
                .collect();
            entries.push(wgpu::BindGroupLayoutEntry {
                visibility: wgpu::ShaderStages::TASK,
                ..storage(MESH_BUNDLES_BINDING, size_of::<BundleLodGpu>() as u64)
            });
            entries.push(wgpu::BindGroupLayoutEntry {
                visibility: wgpu::ShaderStages::TASK,
                ..uniform_entry(MESH_LOD_BINDING, size_of::<LodParams>(), false)
            });
            entries.push(wgpu::BindGroupLayoutEntry {
                visibility: wgpu::ShaderStages::TASK,
                ..storage(MESH_FAR_LEVELS_BINDING, 4)
            });
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("preview_hair_mesh"),
                entries: &entries,
            })
        });
        let alignment = device.limits().min_uniform_buffer_offset_alignment as u64;
        let no_paint = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("root_paint_none"),
            contents: bytemuck::bytes_of(&0u32),
            usage: wgpu::BufferUsages::STORAGE,
        });
        Self {
            no_paint,
            draw_layout,
            generated_layout,
            mesh_layout,
            uniform_stride: (size_of::<HairUniforms>() as u64).div_ceil(alignment) * alignment,
            targets,
            pipelines: None,
        }
    }

    /// The formats and sample count the pipelines draw into.
    pub fn targets(&self) -> Targets {
        self.targets
    }

    /// Group 0 of every pipeline that draws ribbons from `input`.
    pub fn draw_layout(&self, input: RibbonInput) -> &wgpu::BindGroupLayout {
        match input {
            RibbonInput::Buffer => &self.draw_layout,
            RibbonInput::Generated => &self.generated_layout,
            // Without mesh shaders no mesh pipeline exists (the path is refused first:
            // `StrandGenRenderer::check_path`).
            RibbonInput::Mesh => self.mesh_layout.as_ref().unwrap_or(&self.generated_layout),
        }
    }

    /// The primitive topology of ribbons from `input`.
    pub fn topology(input: RibbonInput) -> wgpu::PrimitiveTopology {
        match input {
            RibbonInput::Buffer | RibbonInput::Mesh => wgpu::PrimitiveTopology::TriangleList,
            RibbonInput::Generated => wgpu::PrimitiveTopology::TriangleStrip,
        }
    }

    /// Makes the lit pipelines for `effects` and ribbons from `input` unless they exist (the
    /// previous ones are freed).
    pub fn ensure(
        &mut self,
        context: &GpuContext,
        effects: &ActiveEffects,
        scene_layout: &wgpu::BindGroupLayout,
        effects_layout: Option<&wgpu::BindGroupLayout>,
        input: RibbonInput,
    ) {
        let key = (effects.shader_key(), effects.width_oit, input);
        if self.pipelines.as_ref().is_some_and(|p| p.key == key) {
            return;
        }
        self.pipelines = None;
        let source = hair_shader(&key.0, input);
        let topology = Self::topology(input);
        let mut groups = vec![self.draw_layout(input), scene_layout];
        groups.extend(effects_layout);
        let depth = ribbon_pipeline(
            context,
            &PipelineSpec {
                label: "preview_hair_depth",
                source: &source,
                groups: &groups,
                buffers: &[],
                vertex_entry: "vs_main",
                topology,
                fragment_entry: Some("fs_depth"),
                // The view's colour target, untouched (the pass has it attached).
                targets: &[Some(wgpu::ColorTargetState {
                    format: self.targets.color,
                    blend: None,
                    write_mask: wgpu::ColorWrites::empty(),
                })],
                depth: Some(view_depth(&self.targets, true)),
                sample_count: self.targets.sample_count,
            },
            input,
        );
        let main = ribbon_pipeline(
            context,
            &PipelineSpec {
                label: "preview_hair",
                source: &source,
                groups: &groups,
                buffers: &[],
                vertex_entry: "vs_main",
                topology,
                fragment_entry: Some("fs_main"),
                targets: &view_color_target(&self.targets),
                depth: Some(wgpu::DepthStencilState {
                    depth_compare: Some(wgpu::CompareFunction::Equal),
                    ..view_depth(&self.targets, false)
                }),
                sample_count: self.targets.sample_count,
            },
            input,
        );
        let oit = key.1.then(|| {
            let add = wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            };
            let reveal = wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Zero,
                dst_factor: wgpu::BlendFactor::OneMinusSrc,
                operation: wgpu::BlendOperation::Add,
            };
            ribbon_pipeline(
                context,
                &PipelineSpec {
                    label: "preview_hair_oit",
                    source: &source,
                    groups: &groups,
                    buffers: &[],
                    vertex_entry: "vs_main",
                    topology,
                    fragment_entry: Some("fs_oit"),
                    targets: &[
                        Some(wgpu::ColorTargetState {
                            format: OIT_ACCUMULATION_FORMAT,
                            blend: Some(wgpu::BlendState {
                                color: add,
                                alpha: add,
                            }),
                            write_mask: wgpu::ColorWrites::ALL,
                        }),
                        Some(wgpu::ColorTargetState {
                            format: OIT_REVEALAGE_FORMAT,
                            blend: Some(wgpu::BlendState {
                                color: reveal,
                                alpha: reveal,
                            }),
                            write_mask: wgpu::ColorWrites::ALL,
                        }),
                    ],
                    // Behind opaque strands and the body; transparent strands do not hide
                    // each other.
                    depth: Some(view_depth(&self.targets, false)),
                    sample_count: self.targets.sample_count,
                },
                input,
            )
        });
        self.pipelines = Some(HairPipelines {
            key,
            depth,
            main,
            oit,
        });
    }

    /// One uniform buffer with every view of `views` (each with its own view, eye and width)
    /// for every batch of `batches` (their run ranges), at the dynamic-offset stride.
    fn uniforms(
        &self,
        context: &GpuContext,
        views: &[HairUniforms],
        batches: &[[u32; 2]],
    ) -> (Tracked<wgpu::Buffer>, usize) {
        let stride = self.uniform_stride as usize;
        let batch_count = batches.len().max(1);
        let mut bytes = vec![0u8; stride * batch_count * views.len().max(1)];
        for (v, view) in views.iter().enumerate() {
            for (b, &[first_run, run_count]) in batches.iter().enumerate() {
                let uniforms = HairUniforms {
                    batch: [first_run, run_count, view.batch[2], 0],
                    ..*view
                };
                bytes[(v * batch_count + b) * stride..][..size_of::<HairUniforms>()]
                    .copy_from_slice(bytemuck::bytes_of(&uniforms));
            }
        }
        let buffer = context.resources.buffer_init(
            &context.device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("preview_hair_uniforms"),
                contents: &bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        (buffer, batch_count)
    }

    fn uniform_entry<'a>(buffer: &'a wgpu::Buffer) -> wgpu::BindGroupEntry<'a> {
        wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer,
                offset: 0,
                size: wgpu::BufferSize::new(size_of::<HairUniforms>() as u64),
            }),
        }
    }

    /// The uniforms of every view in `views` for every batch of `batches`, and one bind
    /// group over them, the strand vertices, the runs and the per-root colours of the hair
    /// they were generated from (`None`: strands with no runtime asset, no colour map)
    /// ([`RibbonInput::Buffer`]).
    pub fn prepare(
        &self,
        context: &GpuContext,
        views: &[HairUniforms],
        batches: &[[u32; 2]],
        strands: &wgpu::Buffer,
        runs: &wgpu::Buffer,
        hair: Option<&GpuHair>,
    ) -> PreparedHair {
        let (uniforms, batch_count) = self.uniforms(context, views, batches);
        let group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview_hair"),
                layout: &self.draw_layout,
                entries: &[
                    Self::uniform_entry(&uniforms),
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: strands.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: runs.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: ROOT_PAINT_BINDING,
                        resource: hair
                            .map_or(&self.no_paint, |hair| &*hair.root_paint)
                            .as_entire_binding(),
                    },
                ],
            });
        PreparedHair {
            group,
            input: RibbonInput::Buffer,
            stride: self.uniform_stride,
            batch_count,
            mesh_tasks: [0; 2],
        }
    }

    /// As [`Self::prepare`], for ribbons that generate their own vertices from `hair`
    /// ([`RibbonInput::Generated`] or [`RibbonInput::Mesh`]): the bind group holds
    /// strand_gen's resources instead of vertices (and, for mesh shaders, the bundles'
    /// bounding spheres).
    #[expect(
        clippy::too_many_arguments,
        reason = "one frame's generation inputs, passed through"
    )]
    pub fn prepare_generated(
        &self,
        context: &GpuContext,
        views: &[HairUniforms],
        batches: &[[u32; 2]],
        generator: &StrandGenRenderer,
        hair: &GpuHair,
        filtering: Filtering,
        runs: &wgpu::Buffer,
        mesh_lod: Option<MeshLod>,
    ) -> PreparedHair {
        let input = if mesh_lod.is_some() {
            RibbonInput::Mesh
        } else {
            RibbonInput::Generated
        };
        let (uniforms, batch_count) = self.uniforms(context, views, batches);
        // first_run and run_count are per batch in the ribbons' uniforms; these are unused.
        let params = generator.params_buffer(context, hair, filtering, 0, &[]);
        let mut entries = vec![
            Self::uniform_entry(&uniforms),
            wgpu::BindGroupEntry {
                binding: 2,
                resource: runs.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: ROOT_PAINT_BINDING,
                resource: hair.root_paint.as_entire_binding(),
            },
        ];
        entries.extend(generator.source_entries(GENERATED_BINDING_OFFSET, hair, &params));
        // The mesh path's task shaders plan LOD themselves: one workgroup per bundle, in rows
        // the adapter's per-dimension limit allows.
        let mut mesh_tasks = [0; 2];
        let far_levels = mesh_lod.as_ref().map(|mesh_lod| {
            let levels: &[u32] = if mesh_lod.far_levels.is_empty() {
                &[0]
            } else {
                &mesh_lod.far_levels
            };
            context
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("strand_mesh_far_levels"),
                    contents: bytemuck::cast_slice(levels),
                    usage: wgpu::BufferUsages::STORAGE,
                })
        });
        let lod_buffer = mesh_lod.map(|mesh_lod| {
            let bundles = hair.bundles.len() as u32;
            let row = bundles
                .min(context.device.limits().max_task_workgroups_per_dimension)
                .max(1);
            mesh_tasks = [row, bundles.div_ceil(row)];
            let params = LodParams::new(
                &mesh_lod.camera,
                &mesh_lod.settings,
                hair.per_bundle,
                mesh_lod.max_vertices_log2,
                bundles,
                row,
            );
            context
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("strand_mesh_lod"),
                    contents: bytemuck::bytes_of(&params),
                    usage: wgpu::BufferUsages::UNIFORM,
                })
        });
        if let Some(lod_buffer) = &lod_buffer {
            entries.push(wgpu::BindGroupEntry {
                binding: MESH_BUNDLES_BINDING,
                resource: hair.bundle_lods().as_entire_binding(),
            });
            entries.push(wgpu::BindGroupEntry {
                binding: MESH_LOD_BINDING,
                resource: lod_buffer.as_entire_binding(),
            });
        }
        if let Some(far_levels) = &far_levels {
            entries.push(wgpu::BindGroupEntry {
                binding: MESH_FAR_LEVELS_BINDING,
                resource: far_levels.as_entire_binding(),
            });
        }
        let group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("preview_hair_generated"),
                layout: self.draw_layout(input),
                entries: &entries,
            });
        PreparedHair {
            group,
            input,
            stride: self.uniform_stride,
            batch_count,
            mesh_tasks,
        }
    }

    /// Draws batch `batch` (whose runs are `runs`) of view `view` with `pipeline`; groups 1
    /// and 2, when the pipeline has them, are set by the caller. Ribbons from a buffer are one
    /// triangle-list draw (6 vertices per segment); generated ribbons one draw per run, a
    /// strip of 2 vertices per strand vertex for each of its strands (the instances);
    /// mesh-shader ribbons one task workgroup per bundle, whatever the batches (drawn with
    /// the first; the task shaders cull and plan LOD).
    pub fn draw_with(
        pass: &mut wgpu::RenderPass<'_>,
        pipeline: &wgpu::RenderPipeline,
        prepared: &PreparedHair,
        view: usize,
        batch: usize,
        runs: &[StrandRun],
    ) {
        let segments = FramePlan::batch_segments(runs) as u32;
        let mesh = prepared.input == RibbonInput::Mesh;
        // Mesh-shader ribbons draw every bundle in one go (their task shaders plan LOD), with
        // the first batch.
        if (mesh && batch > 0) || (!mesh && segments == 0) {
            return;
        }
        pass.set_pipeline(pipeline);
        let index = (view * prepared.batch_count + batch) as u64;
        pass.set_bind_group(0, &prepared.group, &[(index * prepared.stride) as u32]);
        match prepared.input {
            RibbonInput::Buffer => pass.draw(0..segments * 6, 0..1),
            RibbonInput::Generated => {
                for run in runs.iter().filter(|r| r.strand_count > 0) {
                    // Strands before the run each have one more vertex than segments.
                    let first = run.vertex_offset - run.segment_offset;
                    pass.draw(
                        0..2 * run.vertex_count.max(2),
                        first..first + run.strand_count,
                    );
                }
            }
            RibbonInput::Mesh => {
                let [row, rows] = prepared.mesh_tasks;
                pass.draw_mesh_tasks(row, rows, 1);
            }
        }
    }

    /// The depth pre-pass pipeline (after [`Self::ensure`]).
    pub fn depth_pipeline(&self) -> Option<&wgpu::RenderPipeline> {
        self.pipelines.as_ref().map(|p| &*p.depth)
    }

    /// The opaque lit pipeline (after [`Self::ensure`]).
    pub fn main_pipeline(&self) -> Option<&wgpu::RenderPipeline> {
        self.pipelines.as_ref().map(|p| &*p.main)
    }

    /// The OIT pipeline, when width-based coverage is on.
    pub fn oit_pipeline(&self) -> Option<&wgpu::RenderPipeline> {
        self.pipelines.as_ref().and_then(|p| p.oit.as_deref())
    }
}
