//! The scene's light on the GPU: which effects a frame actually runs ([`ActiveEffects`]), the
//! lit shaders composed from exactly those effects' modules (`shaders/light/*.wgsl`, stubs for
//! the rest), the scene uniforms (group 1) and the bind group of the effects' textures
//! (group 2: opacity maps, first-hair depth, body depth, dual-scattering tables), whose layout
//! holds only the effects that run.
//!
//! The dual-scattering tables (`shaders/light/dual_scattering.wgsl` ↔
//! `hairloom_core::light::dual_scattering`) live here: two small textures made from the
//! material, and made again only when the material changes.

use hairloom_core::light::dual_scattering::{DualScatteringTables, PHI_COUNT, THETA_COUNT};
use hairloom_core::light::hair_bsdf::P_MAX;
use hairloom_core::light::material::Fibre;
use hairloom_core::light::scene_uniforms::SceneUniforms;
use hairloom_core::model::scene::{
    Coverage, HairMaterial, MultipleScattering, Scene, SelfShadowing, Shading,
};

use crate::device::GpuContext;
use crate::renderer::uniform_entry;
use crate::resources::Tracked;

/// What a frame runs for a scene. An effect with nothing to act on is off: shadows need a
/// shadow-casting light, body shadows a body, dual scattering the Marschner model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ActiveEffects {
    pub shading: Shading,
    pub opacity_maps: SelfShadowing,
    pub body_shadows: bool,
    pub dual_scattering: bool,
    pub width_oit: bool,
    pub opacity_layers: u32,
    pub shadow_resolution: u32,
    /// Shadow-casting lights (each has its own maps).
    pub shadow_slots: u32,
}

impl ActiveEffects {
    pub fn new(scene: &Scene, has_body: bool) -> Self {
        let effects = &scene.effects;
        let slots = scene.shadowed_lights().len() as u32;
        let opacity_maps = if slots > 0 {
            effects.self_shadowing
        } else {
            SelfShadowing::None
        };
        Self {
            shading: effects.shading,
            opacity_maps,
            body_shadows: effects.body_shadows && slots > 0 && has_body,
            dual_scattering: effects.multiple_scattering == MultipleScattering::DualScattering
                && effects.shading == Shading::Marschner,
            width_oit: effects.coverage == Coverage::WidthOit,
            opacity_layers: effects.opacity_layers,
            shadow_resolution: effects.shadow_resolution,
            shadow_slots: if opacity_maps != SelfShadowing::None || effects.body_shadows && has_body
            {
                slots
            } else {
                0
            },
        }
    }

    /// No optional effect at all: what a picture cost before scenes.
    pub fn none() -> Self {
        Self {
            shading: Shading::KajiyaKay,
            opacity_maps: SelfShadowing::None,
            body_shadows: false,
            dual_scattering: false,
            width_oit: false,
            opacity_layers: 4,
            shadow_resolution: 1024,
            shadow_slots: 0,
        }
    }

    /// The part of the effects that decides which lit shader variant runs.
    pub fn shader_key(&self) -> ShaderKey {
        ShaderKey {
            shading: self.shading,
            opacity_maps: self.opacity_maps,
            body_shadows: self.body_shadows,
            dual_scattering: self.dual_scattering,
        }
    }
}

/// Which modules a lit shader is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ShaderKey {
    pub shading: Shading,
    pub opacity_maps: SelfShadowing,
    pub body_shadows: bool,
    pub dual_scattering: bool,
}

impl ShaderKey {
    /// Every variant the renderer can compose (the shader validation test compiles them all).
    pub fn all() -> Vec<ShaderKey> {
        let mut keys = Vec::new();
        for shading in [Shading::KajiyaKay, Shading::Marschner] {
            for opacity_maps in [
                SelfShadowing::None,
                SelfShadowing::OpacityShadowMaps,
                SelfShadowing::DeepOpacityMaps,
            ] {
                for body_shadows in [false, true] {
                    for dual_scattering in [false, true] {
                        if dual_scattering && shading != Shading::Marschner {
                            continue;
                        }
                        keys.push(ShaderKey {
                            shading,
                            opacity_maps,
                            body_shadows,
                            dual_scattering,
                        });
                    }
                }
            }
        }
        keys
    }
}

macro_rules! shader_file {
    ($path:literal) => {
        include_str!(concat!("../../../shaders/", $path))
    };
}

pub const STRAND_RUN: &str = shader_file!("shared/strand_run.wgsl");
pub const RIBBON: &str = shader_file!("shared/ribbon.wgsl");
pub const RIBBON_STORED: &str = shader_file!("shared/ribbon_stored.wgsl");
pub const RIBBON_GENERATED: &str = shader_file!("shared/ribbon_generated.wgsl");
pub const STRAND_VERTEX: &str = shader_file!("shared/strand_vertex.wgsl");
pub const STRAND_MESH: &str = shader_file!("strand_mesh.wgsl");
pub const STRAND_LOD: &str = shader_file!("shared/strand_lod.wgsl");

/// Where the ribbons' strand vertices come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RibbonInput {
    /// A buffer: the batch's scratch (compute generation) or stored vertices.
    #[default]
    Buffer,
    /// Generated in the ribbon vertex shader from the runtime textures.
    Generated,
    /// Generated by task and mesh shaders from the runtime textures (`strand_mesh.wgsl`),
    /// where the device has `EXPERIMENTAL_MESH_SHADER`.
    Mesh,
}

/// The ribbon modules for `input`: the runs, where the vertices come from, the ribbons.
fn ribbon_modules(input: RibbonInput) -> String {
    match input {
        RibbonInput::Buffer => [STRAND_RUN, RIBBON_STORED, RIBBON].concat(),
        RibbonInput::Generated | RibbonInput::Mesh => {
            [STRAND_RUN, STRAND_VERTEX, RIBBON_GENERATED, RIBBON].concat()
        }
    }
}

/// `strand_mesh.wgsl`'s work-distribution sizes, from their one definition in
/// [`crate::renderer::strand_gen`].
fn mesh_sizes() -> String {
    use crate::renderer::strand_gen::{
        MESH_CHUNK_SEGMENTS, MESH_MAX_STRANDS, MESH_STRAND_VERTICES,
    };
    format!(
        "const MESH_STRAND_VERTICES: u32 = {MESH_STRAND_VERTICES}u;\n\
         const MESH_CHUNK_SEGMENTS: u32 = {MESH_CHUNK_SEGMENTS}u;\n\
         const MESH_MAX_STRANDS: u32 = {MESH_MAX_STRANDS}u;\n"
    )
}

/// A pass's finished source for ribbons from `input`: mesh-shader ribbons append the task and
/// mesh entry points (which build the pass's own vertices through its `pass_vertex`) and
/// enable the WGSL extension they need.
fn with_mesh_stages(input: RibbonInput, source: String) -> String {
    match input {
        RibbonInput::Mesh => [
            "enable wgpu_mesh_shader;\n",
            &source,
            STRAND_LOD,
            &mesh_sizes(),
            STRAND_MESH,
        ]
        .concat(),
        RibbonInput::Buffer | RibbonInput::Generated => source,
    }
}
pub const SCENE: &str = shader_file!("shared/scene.wgsl");
pub const HAIR_BSDF: &str = shader_file!("light/hair_bsdf.wgsl");
pub const KAJIYA_KAY: &str = shader_file!("light/kajiya_kay.wgsl");
pub const DUAL_SCATTERING: &str = shader_file!("light/dual_scattering.wgsl");
pub const RADIANCE_KAJIYA_KAY: &str = shader_file!("light/radiance_kajiya_kay.wgsl");
pub const RADIANCE_MARSCHNER: &str = shader_file!("light/radiance_marschner.wgsl");
pub const RADIANCE_DUAL_SCATTERING: &str = shader_file!("light/radiance_dual_scattering.wgsl");
pub const OPACITY_LAYERS: &str = shader_file!("light/opacity_layers.wgsl");
pub const OPACITY_MAPS: &str = shader_file!("light/opacity_maps.wgsl");
pub const OPACITY_START_OSM: &str = shader_file!("light/opacity_start_osm.wgsl");
pub const OPACITY_START_DOM: &str = shader_file!("light/opacity_start_dom.wgsl");
pub const NO_OPACITY_MAPS: &str = shader_file!("light/no_opacity_maps.wgsl");
pub const BODY_SHADOWS: &str = shader_file!("light/body_shadows.wgsl");
pub const NO_BODY_SHADOWS: &str = shader_file!("light/no_body_shadows.wgsl");
pub const PREVIEW_HAIR: &str = shader_file!("preview_hair.wgsl");
pub const PREVIEW_BODY: &str = shader_file!("preview_body.wgsl");
pub const HAIR_SHADOW: &str = shader_file!("hair_shadow.wgsl");

/// The shadow modules of a lit shader: opacity-map lookups (or none) and body shadows (or none).
fn shadow_modules(key: &ShaderKey, source: &mut String) {
    match key.opacity_maps {
        SelfShadowing::None => source.push_str(NO_OPACITY_MAPS),
        kind => {
            source.push_str(OPACITY_LAYERS);
            source.push_str(if kind == SelfShadowing::DeepOpacityMaps {
                OPACITY_START_DOM
            } else {
                OPACITY_START_OSM
            });
            source.push_str(OPACITY_MAPS);
        }
    }
    source.push_str(if key.body_shadows {
        BODY_SHADOWS
    } else {
        NO_BODY_SHADOWS
    });
}

/// The hair's colour pass for `key`: runs, ribbons from `input`, the scene, the shading
/// model's modules, the shadow modules, then `preview_hair.wgsl`.
pub fn hair_shader(key: &ShaderKey, input: RibbonInput) -> String {
    let mut source = ribbon_modules(input);
    source.push_str(SCENE);
    match key.shading {
        Shading::KajiyaKay => {
            source.push_str(KAJIYA_KAY);
            source.push_str(RADIANCE_KAJIYA_KAY);
        }
        Shading::Marschner => {
            source.push_str(HAIR_BSDF);
            if key.dual_scattering {
                source.push_str(DUAL_SCATTERING);
                source.push_str(RADIANCE_DUAL_SCATTERING);
            } else {
                source.push_str(RADIANCE_MARSCHNER);
            }
        }
    }
    shadow_modules(key, &mut source);
    source.push_str(PREVIEW_HAIR);
    with_mesh_stages(input, source)
}

/// The body's colour pass for `key` (shading model and dual scattering do not apply).
pub fn body_shader(key: &ShaderKey) -> String {
    let mut source = SCENE.to_string();
    shadow_modules(key, &mut source);
    source.push_str(PREVIEW_BODY);
    source
}

/// The hair's shadow passes for opacity maps of `kind` (deep opacity maps read the first-hair
/// depth; opacity shadow maps start at the near plane).
pub fn hair_shadow_shader(kind: SelfShadowing, input: RibbonInput) -> String {
    let source = [
        ribbon_modules(input).as_str(),
        SCENE,
        OPACITY_LAYERS,
        if kind == SelfShadowing::DeepOpacityMaps {
            OPACITY_START_DOM
        } else {
            OPACITY_START_OSM
        },
        HAIR_SHADOW,
    ]
    .concat();
    with_mesh_stages(input, source)
}

/// Group-2 bindings (shared by the lit shaders' modules).
pub mod binding {
    pub const OPACITY_LAYERS: u32 = 0;
    pub const FIRST_HAIR_DEPTH: u32 = 1;
    pub const BODY_DEPTH: u32 = 2;
    pub const BODY_DEPTH_SAMPLER: u32 = 3;
    pub const TABLE_SAMPLER: u32 = 4;
    pub const DS_PROFILE: u32 = 5;
    pub const DS_LOBES: u32 = 6;
}

fn texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension,
            multisampled: false,
        },
        count: None,
    }
}

/// The group-2 layout of the lit shaders for `effects`; `None` when they take no group 2.
pub fn effects_layout(
    context: &GpuContext,
    effects: &ActiveEffects,
) -> Option<wgpu::BindGroupLayout> {
    let entries = effect_entries(effects);
    (!entries.is_empty()).then(|| {
        context
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("effects"),
                entries: &entries,
            })
    })
}

/// The group-2 layout entries of `effects` (empty: the shaders take no group 2).
pub fn effect_entries(effects: &ActiveEffects) -> Vec<wgpu::BindGroupLayoutEntry> {
    let mut entries = Vec::new();
    let float = wgpu::TextureSampleType::Float { filterable: true };
    if effects.opacity_maps != SelfShadowing::None {
        entries.push(texture_entry(
            binding::OPACITY_LAYERS,
            float,
            wgpu::TextureViewDimension::D2Array,
        ));
        if effects.opacity_maps == SelfShadowing::DeepOpacityMaps {
            entries.push(first_hair_depth_entry());
        }
    }
    if effects.body_shadows {
        entries.push(texture_entry(
            binding::BODY_DEPTH,
            wgpu::TextureSampleType::Depth,
            wgpu::TextureViewDimension::D2Array,
        ));
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: binding::BODY_DEPTH_SAMPLER,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
            count: None,
        });
    }
    if effects.dual_scattering {
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: binding::TABLE_SAMPLER,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        });
        entries.push(texture_entry(
            binding::DS_PROFILE,
            float,
            wgpu::TextureViewDimension::D2,
        ));
        entries.push(texture_entry(
            binding::DS_LOBES,
            float,
            wgpu::TextureViewDimension::D2Array,
        ));
    }
    entries
}

/// The first-hair depth of deep opacity maps, read by `textureLoad`.
pub fn first_hair_depth_entry() -> wgpu::BindGroupLayoutEntry {
    texture_entry(
        binding::FIRST_HAIR_DEPTH,
        wgpu::TextureSampleType::Depth,
        wgpu::TextureViewDimension::D2Array,
    )
}

/// The dual-scattering tables on the GPU.
pub struct DualScatteringTextures {
    material: HairMaterial,
    pub tables: DualScatteringTables,
    _profile: Tracked<wgpu::Texture>,
    _lobes: Tracked<wgpu::Texture>,
    pub profile_view: wgpu::TextureView,
    pub lobes_view: wgpu::TextureView,
}

impl DualScatteringTextures {
    fn new(context: &GpuContext, material: &HairMaterial) -> Self {
        let tables = DualScatteringTables::new(&Fibre::new(material));
        let half = |rows: &[[f32; 4]]| -> Vec<u8> {
            rows.iter()
                .flatten()
                .flat_map(|&v| half::f16::from_f32(v).to_le_bytes())
                .collect()
        };
        let make = |label: &str, width: u32, height: u32, layers: u32, bytes: &[u8]| {
            let texture = context.resources.texture(
                &context.device,
                &wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d {
                        width,
                        height,
                        depth_or_array_layers: layers,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba16Float,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                    view_formats: &[],
                },
            );
            context.queue.write_texture(
                texture.as_image_copy(),
                bytes,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(width * 8),
                    rows_per_image: Some(height),
                },
                wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: layers,
                },
            );
            texture
        };
        // Profile: three rows over |θ_i| (forward, backward, spread).
        let mut profile_rows = tables.forward.clone();
        profile_rows.extend_from_slice(&tables.backward);
        profile_rows.extend_from_slice(&tables.spread);
        let profile = make(
            "dual_scattering_profile",
            THETA_COUNT as u32,
            3,
            1,
            &half(&profile_rows),
        );
        let lobes = make(
            "dual_scattering_lobes",
            PHI_COUNT as u32,
            THETA_COUNT as u32,
            P_MAX as u32,
            &half(&tables.lobes),
        );
        Self {
            material: material.clone(),
            profile_view: profile.create_view(&Default::default()),
            lobes_view: lobes.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            }),
            tables,
            _profile: profile,
            _lobes: lobes,
        }
    }
}

/// The scene uniforms (group 1) and, when the scene asks for dual scattering, its tables.
pub struct SceneLighting {
    pub scene_layout: wgpu::BindGroupLayout,
    uniforms: Tracked<wgpu::Buffer>,
    pub scene_group: wgpu::BindGroup,
    pub dual_scattering: Option<DualScatteringTextures>,
    /// The material's mean forward transmittance per fibre, with the material it was made
    /// from (shadows without dual scattering need it; computing it costs a table).
    mean_forward: Option<(HairMaterial, [f32; 3])>,
    pub table_sampler: wgpu::Sampler,
    pub depth_sampler: wgpu::Sampler,
}

impl SceneLighting {
    pub fn new(context: &GpuContext) -> Self {
        let device = &context.device;
        let scene_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene"),
            entries: &[uniform_entry(0, size_of::<SceneUniforms>(), false)],
        });
        let uniforms = context.resources.buffer(
            device,
            &wgpu::BufferDescriptor {
                label: Some("scene_uniforms"),
                size: size_of::<SceneUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            },
        );
        let scene_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout: &scene_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniforms.as_entire_binding(),
            }],
        });
        let clamp = wgpu::AddressMode::ClampToEdge;
        Self {
            scene_layout,
            uniforms,
            scene_group,
            dual_scattering: None,
            mean_forward: None,
            table_sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("dual_scattering_tables"),
                address_mode_u: clamp,
                address_mode_v: clamp,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            }),
            depth_sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("body_shadow_compare"),
                address_mode_u: clamp,
                address_mode_v: clamp,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                compare: Some(wgpu::CompareFunction::LessEqual),
                ..Default::default()
            }),
        }
    }

    /// Makes (or frees) the dual-scattering tables as `effects` and the material ask, and
    /// returns the material's mean forward transmittance per fibre.
    pub fn sync(
        &mut self,
        context: &GpuContext,
        effects: &ActiveEffects,
        material: &HairMaterial,
    ) -> [f32; 3] {
        if effects.dual_scattering {
            if self
                .dual_scattering
                .as_ref()
                .is_none_or(|ds| &ds.material != material)
            {
                self.dual_scattering = Some(DualScatteringTextures::new(context, material));
            }
        } else {
            self.dual_scattering = None;
        }
        if let Some(ds) = &self.dual_scattering {
            return ds.tables.mean_forward;
        }
        match &self.mean_forward {
            Some((made_from, value)) if made_from == material => *value,
            _ => {
                let value = DualScatteringTables::new(&Fibre::new(material)).mean_forward;
                self.mean_forward = Some((material.clone(), value));
                value
            }
        }
    }

    /// The scene uniform buffer (what group 1 binds).
    pub fn uniform_buffer(&self) -> &wgpu::Buffer {
        &self.uniforms
    }

    /// Writes this frame's scene uniforms.
    pub fn write(&self, context: &GpuContext, uniforms: &SceneUniforms) {
        context
            .queue
            .write_buffer(&self.uniforms, 0, bytemuck::bytes_of(uniforms));
    }
}
