//! Far hair in a frame (seed 001; `shaders/far_hair.wgsl`, `far_hair_lit.wgsl`,
//! `far_hair_shadow.wgsl`): the thick hairs of every bundle whose level is 1 or more,
//! generated each frame from the hair mesh's textures (`thick_main`, through
//! [`ThickGenRenderer`]), drawn as ribbons as wide as their cross-sections look, with the
//! share of each ribbon a real cluster's fibres cover kept by a stable hashed alpha test,
//! shaded by the aggregated BCSDF (tables from the material, in the effects group), into the
//! view's depth pre-pass and lit pass and into each shadow-casting light's maps. The level of
//! each bundle is chosen by eq. 16 from the widths measured in the last frame
//! ([`FarLodRenderer`], [`hairloom_core::runtime::far_lod`]); the frame plan leaves those
//! bundles' strands out. Exists only while a scene names `far: aggregated`. CPU mirrors:
//! `StrandGen::thick_main`, `hairloom_core::light::aggregated_bcsdf`.

use hairloom_core::light::aggregated_bcsdf::AggregatedTables;
use hairloom_core::light::material::Fibre;
use hairloom_core::model::scene::{HairMaterial, SelfShadowing};
use hairloom_core::runtime::far_lod::{FarLodParams, drawn_hairs, first_levels};
use hairloom_core::runtime::frame_plan::BundleBounds;
use hairloom_core::runtime::gpu_types::ThickGenParams;
use hairloom_core::runtime::strand_gen::Filtering;

use crate::device::GpuContext;
use crate::renderer::far_lod::FarLodRenderer;
use crate::renderer::hair_shadow::{HairShadowRenderer, ShaderEntries};
use crate::renderer::preview_hair::HairUniforms;
use crate::renderer::scene_lighting::ActiveEffects;
use crate::renderer::shader_composer::{ShaderKey, far_hair_shader, far_hair_shadow_shader};
use crate::renderer::strand_gen::{
    GpuFarHair, GpuHair, StrandGenError, StrandGenRenderer, ThickGenRenderer, ThickOutput,
};
use crate::renderer::{
    PipelineSpec, Targets, storage_entry, uniform_entry, view_color_target, view_depth,
};
use crate::resources::Tracked;

struct FarPipelines {
    key: ShaderKey,
    depth: Tracked<wgpu::RenderPipeline>,
    main: Tracked<wgpu::RenderPipeline>,
}

struct FarShadowPipelines {
    key: (SelfShadowing, u32, u32, u32),
    /// Deep opacity maps: the thick hairs' first-hair depth.
    depth: Option<Tracked<wgpu::RenderPipeline>>,
    opacity: Tracked<wgpu::RenderPipeline>,
}

/// Far hair's pipelines, tables and level choice.
pub struct FarHairRenderer {
    thick_gen: ThickGenRenderer,
    lod: FarLodRenderer,
    /// Group 0 of every far-hair pipeline: the views, the thick hairs' centres and sections.
    layout: wgpu::BindGroupLayout,
    uniform_stride: u64,
    targets: Targets,
    /// The aggregated BCSDF's tables (`light/aggregated_bcsdf.wgsl`, effects group binding
    /// [`crate::renderer::scene_lighting::binding::AGG_TABLES`]) and the material they are of.
    tables: Tracked<wgpu::Buffer>,
    material: HairMaterial,
    pipelines: Option<FarPipelines>,
    shadow_pipelines: Option<FarShadowPipelines>,
}

/// One frame's thick hairs: where they are generated, the views' uniforms, one bind group.
pub struct PreparedFar {
    group: wgpu::BindGroup,
    records: Tracked<wgpu::Buffer>,
    positions: Tracked<wgpu::Buffer>,
    sections: Tracked<wgpu::Buffer>,
    stride: u64,
    /// Thick hairs drawn, and vertices each.
    pub count: u32,
    pub vertex_count: u32,
}

impl PreparedFar {
    /// Segments drawn per view.
    pub fn segments(&self) -> u32 {
        self.count * (self.vertex_count - 1)
    }

    /// Bytes of the frame's thick-hair buffers.
    pub fn bytes(&self) -> u64 {
        self.records.size() + self.positions.size() + self.sections.size()
    }
}

impl FarHairRenderer {
    pub fn new(context: &GpuContext, targets: Targets, material: &HairMaterial) -> Self {
        let device = &context.device;
        let storage =
            |binding: u32, size: u64| storage_entry(binding, size, wgpu::ShaderStages::VERTEX);
        let uniforms = uniform_entry(0, size_of::<HairUniforms>(), true);
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("far_hair"),
            entries: &[uniforms, storage(1, 16), storage(2, 32)],
        });
        let alignment = device.limits().min_uniform_buffer_offset_alignment as u64;
        Self {
            thick_gen: ThickGenRenderer::new(context),
            lod: FarLodRenderer::new(context),
            layout,
            uniform_stride: (size_of::<HairUniforms>() as u64).div_ceil(alignment) * alignment,
            targets,
            tables: Self::upload_tables(context, material),
            material: material.clone(),
            pipelines: None,
            shadow_pipelines: None,
        }
    }

    fn upload_tables(context: &GpuContext, material: &HairMaterial) -> Tracked<wgpu::Buffer> {
        let tables = AggregatedTables::new(&Fibre::new(material));
        context.resources.buffer_init(
            &context.device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("far_hair_aggregated_tables"),
                contents: bytemuck::cast_slice(&tables.data),
                usage: wgpu::BufferUsages::STORAGE,
            },
        )
    }

    /// The aggregated BCSDF's tables (the effects group binds them).
    pub fn tables(&self) -> &wgpu::Buffer {
        &self.tables
    }

    /// Makes the pipelines for `effects` (group 1 the scene, group 2 the effects) and the
    /// tables for `material`; cheap when nothing changed.
    pub fn ensure(
        &mut self,
        context: &GpuContext,
        effects: &ActiveEffects,
        material: &HairMaterial,
        scene_layout: &wgpu::BindGroupLayout,
        effects_layout: Option<&wgpu::BindGroupLayout>,
    ) {
        if &self.material != material {
            self.tables = Self::upload_tables(context, material);
            self.material = material.clone();
        }
        let key = effects.shader_key();
        if self.pipelines.as_ref().is_some_and(|p| p.key == key) {
            return;
        }
        let source = far_hair_shader(&key);
        let mut groups = vec![&self.layout, scene_layout];
        groups.extend(effects_layout);
        let spec = |label, fragment_entry, targets, depth| PipelineSpec {
            label,
            source: &source,
            groups: &groups,
            buffers: &[],
            vertex_entry: "vs_far",
            topology: wgpu::PrimitiveTopology::TriangleList,
            fragment_entry: Some(fragment_entry),
            targets,
            depth: Some(depth),
            sample_count: self.targets.sample_count,
        };
        let untouched = [Some(wgpu::ColorTargetState {
            format: self.targets.color,
            blend: None,
            write_mask: wgpu::ColorWrites::empty(),
        })];
        let depth = crate::renderer::pipeline(
            context,
            &spec(
                "far_hair_depth",
                "fs_far_depth",
                &untouched,
                view_depth(&self.targets, true),
            ),
        );
        let lit_targets = view_color_target(&self.targets);
        let main = crate::renderer::pipeline(
            context,
            &spec(
                "far_hair",
                "fs_far",
                &lit_targets,
                wgpu::DepthStencilState {
                    depth_compare: Some(wgpu::CompareFunction::Equal),
                    ..view_depth(&self.targets, false)
                },
            ),
        );
        self.pipelines = Some(FarPipelines { key, depth, main });
    }

    /// Whether it draws into the lights' opacity maps (there are some).
    pub fn draws_shadows(&self) -> bool {
        self.shadow_pipelines.is_some()
    }

    /// Drops the shadow pipelines (the scene has no opacity maps now).
    pub fn forget_shadow_pipelines(&mut self) {
        self.shadow_pipelines = None;
    }

    /// Drops the pipelines (their group layouts were made again).
    pub fn forget_pipelines(&mut self) {
        self.pipelines = None;
        self.shadow_pipelines = None;
    }

    /// Makes the pipelines that draw thick hairs into `hair_shadow`'s maps.
    pub fn ensure_shadows(
        &mut self,
        context: &GpuContext,
        hair_shadow: &HairShadowRenderer,
        scene_layout: &wgpu::BindGroupLayout,
    ) {
        let key = (
            hair_shadow.kind,
            hair_shadow.layers,
            hair_shadow.slots,
            hair_shadow.resolution,
        );
        if self.shadow_pipelines.as_ref().is_some_and(|p| p.key == key) {
            return;
        }
        let source = far_hair_shadow_shader(hair_shadow.kind);
        let entries = |label, fragment_entry| ShaderEntries {
            label,
            source: &source,
            vertex_entry: "vs_far",
            fragment_entry: Some(fragment_entry),
        };
        let depth = hair_shadow.depth_pipeline_for(
            context,
            entries("far_hair_shadow_depth", "fs_far_depth"),
            &[&self.layout],
        );
        let opacity = hair_shadow.opacity_pipeline_for(
            context,
            entries("far_hair_shadow_opacity", "fs_far_opacity"),
            &self.layout,
            scene_layout,
        );
        self.shadow_pipelines = Some(FarShadowPipelines {
            key,
            depth,
            opacity,
        });
    }

    /// Where the level choice starts for `far` with no last frame (see
    /// [`hairloom_core::runtime::far_lod::first_levels`]).
    pub fn first_levels(
        far: &GpuFarHair,
        bundles: &[BundleBounds],
        params: &FarLodParams,
    ) -> Vec<u32> {
        let eye = glam::Vec3::new(params.eye[0], params.eye[1], params.eye[2]);
        first_levels(
            &far.table,
            bundles,
            eye,
            params.pixel_at_unit,
            params.width_threshold_px,
        )
    }

    /// The frame's thick hairs for bundles drawing `levels`, generated at `vertex_count`
    /// vertices each (by [`Self::encode_generation`]), seen from every view of `views` (the
    /// camera, then each shadow-casting light, as the strands' are). `None` when no bundle
    /// draws far hair.
    pub fn prepare(
        &self,
        context: &GpuContext,
        far: &GpuFarHair,
        levels: &[u32],
        vertex_count: u32,
        views: &[HairUniforms],
    ) -> Option<PreparedFar> {
        let hairs = drawn_hairs(&far.table, levels);
        if hairs.is_empty() {
            return None;
        }
        let count = hairs.len() as u32;
        let n = vertex_count.max(2);
        let records = ThickGenRenderer::upload_records(context, &hairs);
        let vertices = u64::from(count * n);
        let scratch = |label: &str, size: u64| {
            context.resources.buffer(
                &context.device,
                &wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: wgpu::BufferUsages::STORAGE,
                    mapped_at_creation: false,
                },
            )
        };
        let positions = scratch("far_hair_positions", vertices * 16);
        let sections = scratch("far_hair_sections", vertices * 32);
        let stride = self.uniform_stride as usize;
        let mut bytes = vec![0u8; stride * views.len().max(1)];
        for (v, view) in views.iter().enumerate() {
            let uniforms = HairUniforms {
                batch: [count, n, view.batch[2], 0],
                ..*view
            };
            bytes[v * stride..][..size_of::<HairUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(&uniforms));
        }
        let uniforms = context.resources.buffer_init(
            &context.device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("far_hair_uniforms"),
                contents: &bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        let group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("far_hair"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                            buffer: &uniforms,
                            offset: 0,
                            size: wgpu::BufferSize::new(size_of::<HairUniforms>() as u64),
                        }),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: positions.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: sections.as_entire_binding(),
                    },
                ],
            });
        Some(PreparedFar {
            group,
            records,
            positions,
            sections,
            stride: self.uniform_stride,
            count,
            vertex_count: n,
        })
    }

    /// Records the generation of the frame's thick hairs (before any pass draws them).
    pub fn encode_generation(
        &self,
        context: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        generator: &StrandGenRenderer,
        hair: &GpuHair,
        filtering: Filtering,
        prepared: &PreparedFar,
    ) {
        self.thick_gen.encode(
            generator,
            context,
            encoder,
            hair,
            &prepared.records,
            ThickGenParams {
                first: 0,
                count: prepared.count,
                vertex_count: prepared.vertex_count,
                output_offset: 0,
            },
            filtering,
            ThickOutput {
                positions: &prepared.positions,
                sections: &prepared.sections,
            },
        );
    }

    /// Eq. 16 for the next frame: the widths of the thick hairs of `levels` and of the next
    /// coarser ones seen from `params.eye`, measured on the GPU, and the levels they choose
    /// (read back; the next frame's plan uses them).
    pub fn next_levels(
        &self,
        context: &GpuContext,
        generator: &StrandGenRenderer,
        hair: &GpuHair,
        far: &GpuFarHair,
        levels: &[u32],
        params: FarLodParams,
    ) -> Result<Vec<u32>, StrandGenError> {
        self.lod.step(
            context,
            generator,
            &self.thick_gen,
            hair,
            &far.table,
            levels,
            params,
        )
    }

    fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        pipeline: &wgpu::RenderPipeline,
        prepared: &PreparedFar,
        view: usize,
    ) {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(
            0,
            &prepared.group,
            &[(view as u64 * prepared.stride) as u32],
        );
        pass.draw(0..prepared.segments() * 6, 0..1);
    }

    /// The camera's depth pre-pass of the thick hairs (groups 1 and 2 bound by the caller).
    pub fn draw_depth(&self, pass: &mut wgpu::RenderPass<'_>, prepared: &PreparedFar) {
        if let Some(p) = &self.pipelines {
            self.draw(pass, &p.depth, prepared, 0);
        }
    }

    /// The camera's lit thick hairs, where the pre-pass left them nearest.
    pub fn draw_lit(&self, pass: &mut wgpu::RenderPass<'_>, prepared: &PreparedFar) {
        if let Some(p) = &self.pipelines {
            self.draw(pass, &p.main, prepared, 0);
        }
    }

    /// The thick hairs into light `slot`'s maps: the first-hair depth (deep opacity maps),
    /// then the opacity layers, each after the strands' (loaded, not cleared).
    pub fn encode_shadow(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        hair_shadow: &HairShadowRenderer,
        scene_group: &wgpu::BindGroup,
        prepared: &PreparedFar,
        slot: usize,
    ) {
        let Some(pipelines) = &self.shadow_pipelines else {
            return;
        };
        if let (Some(pipeline), Some(mut pass)) = (
            &pipelines.depth,
            hair_shadow.depth_pass(encoder, slot, false),
        ) {
            self.draw(&mut pass, pipeline, prepared, slot + 1);
        }
        let mut pass = hair_shadow.opacity_pass(encoder, scene_group, slot, false);
        self.draw(&mut pass, &pipelines.opacity, prepared, slot + 1);
    }
}
