//! The scene's light on the GPU: which effects a frame actually runs ([`ActiveEffects`]; the
//! lit shaders made of exactly those effects' modules are composed in
//! [`crate::renderer::shader_composer`]), the scene uniforms (group 1) and the bind group of
//! the effects' textures (group 2: opacity maps, first-hair depth, body depth,
//! dual-scattering tables), whose layout holds only the effects that run.
//!
//! The dual-scattering tables (`shaders/light/dual_scattering.wgsl` ↔
//! `hairloom_core::light::dual_scattering`) live here: two small textures made from the
//! material, and made again only when the material changes.

use hairloom_core::light::dual_scattering::{DualScatteringTables, PHI_COUNT, THETA_COUNT};
use hairloom_core::light::hair_bsdf::P_MAX;
use hairloom_core::light::kajiya_kay::KajiyaKayTable;
use hairloom_core::light::material::Fibre;
use hairloom_core::light::scene_uniforms::SceneUniforms;
use hairloom_core::model::scene::{
    Coverage, FarHair, Fur, HairMaterial, MultipleScattering, Scene, SelfShadowing, Shading,
};

use crate::device::GpuContext;
use crate::renderer::shader_composer::ShaderKey;
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
    /// Far hair's thick hairs (seed 001) where bundles are narrow enough.
    pub far_hair: bool,
    /// Fur's shells and fins (seed 002).
    pub fur: bool,
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
            // Fur draws far hair its own way (shells): with both named, fur wins and far hair's
            // thick hairs are not drawn over the shells.
            far_hair: effects.far_hair == FarHair::Aggregated && effects.fur != Fur::ShellsFins,
            fur: effects.fur == Fur::ShellsFins,
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
            far_hair: false,
            fur: false,
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

/// Group-2 bindings (shared by the lit shaders' modules).
pub mod binding {
    pub const OPACITY_LAYERS: u32 = 0;
    pub const FIRST_HAIR_DEPTH: u32 = 1;
    pub const BODY_DEPTH: u32 = 2;
    pub const BODY_DEPTH_SAMPLER: u32 = 3;
    pub const TABLE_SAMPLER: u32 = 4;
    pub const DS_PROFILE: u32 = 5;
    pub const DS_LOBES: u32 = 6;
    /// Far hair's aggregated BCSDF tables (`light/aggregated_bcsdf.wgsl`).
    pub const AGG_TABLES: u32 = 7;
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
    if effects.far_hair {
        entries.push(crate::renderer::storage_entry(
            binding::AGG_TABLES,
            16,
            wgpu::ShaderStages::FRAGMENT,
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
    /// Kajiya-Kay's weights by the angle between view and light, with the material they were
    /// made for (made when a scene shades with Kajiya-Kay; 65 × 4096 × 3 fibre evaluations).
    kajiya_kay: Option<(HairMaterial, KajiyaKayTable)>,
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
            kajiya_kay: None,
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
        if effects.shading == Shading::KajiyaKay {
            if self
                .kajiya_kay
                .as_ref()
                .is_none_or(|(made_from, _)| made_from != material)
            {
                let table = KajiyaKayTable::new(&Fibre::new(material));
                self.kajiya_kay = Some((material.clone(), table));
            }
        } else {
            self.kajiya_kay = None;
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

    /// Kajiya-Kay's weights for the material of the last [`Self::sync`] (`None` unless the
    /// scene shades with Kajiya-Kay).
    pub fn kajiya_kay_table(&self) -> Option<&KajiyaKayTable> {
        self.kajiya_kay.as_ref().map(|(_, table)| table)
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
