//! Fur in a frame (seed 002; `shaders/fur.wgsl`): fins near the silhouette, then shells from
//! the innermost out, over the opaque body, lit by the scene's hair model with its shadows.
//! Exists only while a scene names `fur: shells_fins`.
//!
//! The fur asset ([`GpuFur`]) is made from the hair's [`FurBase`] (its root faces and
//! columns) and the scene's [`FurShells`]: a strand volume grown by the preset, sampled into
//! shell layers at every level of detail, their strand directions and a fin texture (each
//! with a mip chain), and the lapped patches' corners and fin edges. Each frame chooses the
//! shell level from the fur's length on screen and how much the shells show against the
//! strands ([`FurShells::shell_weight`]). CPU mirrors: `hairloom_core::fur`.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hairloom_core::fur::base::{FurBase, FurColumnGpu, FurCornerGpu, FurFinGpu, FurGeometry};
use hairloom_core::fur::lapped::LappedError;
use hairloom_core::fur::textures::{
    FIN_HEIGHT, FIN_WIDTH, FinTexture, FurTextureError, ShellParams, ShellTextures, mip_chain,
    shell_level,
};
use hairloom_core::fur::volume::{FurPreset, FurVolume, FurVolumeError, MAX_VOLUME_STRANDS};
use hairloom_core::model::scene::{FUR_TILE_STRANDS, Fur, FurShells, Scene};

use crate::device::GpuContext;
use crate::frame::{FrameCamera, HairSource};
use crate::renderer::scene_lighting::ActiveEffects;
use crate::renderer::shader_composer::{ShaderKey, fur_shader};
use crate::renderer::{PipelineSpec, Targets, storage_entry, uniform_entry, view_depth};
use crate::resources::Tracked;

/// Keep in sync with `shaders/fur.wgsl` (`FurUniforms`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FurUniforms {
    pub view_projection: [[f32; 4]; 4],
    pub eye: [f32; 4],
    /// Shells drawn, level, level-0 layers, 1 when a coarser level exists.
    pub shells: [u32; 4],
    /// Share of the coarser level, shell weight, alpha test, fibres crossed straight through.
    pub blend: [f32; 4],
    /// The tile's width in metres (y, z, w unused).
    pub shape: [f32; 4],
}

const _: () = assert!(size_of::<FurUniforms>() == 128);

/// Why fur could not be made.
#[derive(Debug, thiserror::Error)]
pub enum FurError {
    #[error("fur: no root faces to grow on (no bundle with layers grows hair)")]
    NoSurface,
    #[error("fur: {0}")]
    Surface(#[from] LappedError),
    #[error("fur: {0}")]
    Settings(String),
    #[error("{0}")]
    Limit(String),
    #[error(transparent)]
    Volume(#[from] FurVolumeError),
    #[error(transparent)]
    Textures(#[from] FurTextureError),
}

/// The strands fur stands in for: how dense they grow on the root faces and how thick
/// they are, so that shells show as much hair as the strands they replace.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FurStrands {
    pub per_m2: f64,
    pub radius_m: f64,
}

/// What a fur asset was made from; made again when any of it changes.
#[derive(Clone, Debug, PartialEq)]
struct FurKey {
    settings: FurShells,
    base: FurBase,
    strands: FurStrands,
}

/// Fur on the GPU: the shells' textures at every level, the fin texture, the patches.
pub struct GpuFur {
    key: FurKey,
    columns: Tracked<wgpu::Buffer>,
    corners: Tracked<wgpu::Buffer>,
    fins: Tracked<wgpu::Buffer>,
    shell_colour: wgpu::TextureView,
    shell_direction: wgpu::TextureView,
    fin_texture: wgpu::TextureView,
    textures: Vec<Tracked<wgpu::Texture>>,
    pub corner_count: u32,
    pub fin_count: u32,
    pub patch_count: u32,
    pub layer_count: u32,
    /// Fibres a ray crosses going straight out through the whole fur: the strands' density ×
    /// width × length × the mean sine between a ray and randomly turned fibres (π/4), the
    /// same for any combing (a sheared column is thinner by what it is longer).
    pub fibres_through: f32,
    /// One repeat of the fur texture on the surface.
    pub tile_width_m: f32,
    /// The fur's mean length, and a sphere around it.
    pub length_m: f32,
    pub centre: Vec3,
    pub radius_m: f32,
    /// Bytes of the seed's own set (16 layers and the fin, with mips) for these settings.
    pub seed_bytes: u64,
}

impl GpuFur {
    /// Grows the volume, samples its textures, covers `base` with patches and uploads it all
    /// (the costly part: tens of milliseconds to seconds; not per frame).
    pub fn build(
        context: &GpuContext,
        base: &FurBase,
        settings: &FurShells,
        strands: FurStrands,
    ) -> Result<Self, FurError> {
        settings
            .validate()
            .map_err(|e| FurError::Settings(e.to_string()))?;
        if base.triangles.is_empty() {
            return Err(FurError::NoSurface);
        }
        let per_m2 = if strands.per_m2.is_finite() && strands.per_m2 > 0.0 {
            strands.per_m2.min(1e9)
        } else {
            1e6
        };
        let mut volume_params = settings.preset.params();
        // The preset's own count is its density relative to the straight preset's.
        let density_share =
            volume_params.strand_count as f64 / FurPreset::Straight.params().strand_count as f64;
        let tile_width_m = match settings.tile_width_m {
            Some(width) => width as f64,
            None => (FUR_TILE_STRANDS / per_m2).sqrt().clamp(0.002, 0.5),
        };
        // The surface first: a mesh it cannot cover fails before the volume is grown.
        let geometry = FurGeometry::build(
            base,
            tile_width_m,
            3.0 * tile_width_m,
            FurPreset::Straight.params().seed,
        )?;
        let corner_bytes = (geometry.corners.len() * size_of::<FurCornerGpu>()) as u64;
        let limit = context.device.limits().max_storage_buffer_binding_size;
        if corner_bytes > limit {
            return Err(FurError::Limit(format!(
                "fur: {} root triangles need {corner_bytes} bytes of corners, above this adapter's max_storage_buffer_binding_size of {limit}",
                base.triangles.len()
            )));
        }
        volume_params.tile_width_m = tile_width_m;
        volume_params.strand_count = (per_m2 * tile_width_m * tile_width_m * density_share)
            .round()
            .clamp(1.0, MAX_VOLUME_STRANDS as f64) as u32;
        volume_params.length_m = (base.mean_length_m() as f64).clamp(1e-5, 1.0);
        volume_params.strand_radius_m = strands
            .radius_m
            .clamp(1e-7, volume_params.tile_width_m * 0.1);
        volume_params.curl_radius_m = volume_params
            .curl_radius_m
            .min(volume_params.tile_width_m * 0.5);
        let volume = FurVolume::grow(&volume_params)?;
        let shells = ShellTextures::sample(
            &volume,
            ShellParams {
                layer_count: settings.shell_count,
                resolution: settings.shell_resolution,
                opaque_skin: false,
            },
        )?;
        let fin = FinTexture::sample(
            &volume,
            volume_params.tile_width_m / 8.0,
            FIN_WIDTH,
            FIN_HEIGHT,
        );
        let layer_count = settings.shell_count;
        let fibres_through = (per_m2
            * 2.0
            * volume_params.strand_radius_m
            * volume_params.length_m
            * std::f64::consts::FRAC_PI_4) as f32;
        let storage = |label: &str, contents: &[u8]| {
            context.resources.buffer_init(
                &context.device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage: wgpu::BufferUsages::STORAGE,
                },
            )
        };
        // Storage bindings need at least one element.
        fn at_least_one<T: Default + Clone>(items: &[T]) -> Vec<T> {
            if items.is_empty() {
                vec![T::default()]
            } else {
                items.to_vec()
            }
        }
        let columns = storage(
            "fur_columns",
            bytemuck::cast_slice(&at_least_one::<FurColumnGpu>(&geometry.columns)),
        );
        let corners = storage(
            "fur_corners",
            bytemuck::cast_slice(&at_least_one::<FurCornerGpu>(&geometry.corners)),
        );
        let fins = storage(
            "fur_fins",
            bytemuck::cast_slice(&at_least_one::<FurFinGpu>(&geometry.fins)),
        );
        let resolution = settings.shell_resolution;
        let mut colour_layers: Vec<&[[u8; 4]]> = Vec::new();
        for level in &shells.levels {
            for l in 0..level.layer_count() {
                colour_layers.push(level.layer(l));
            }
        }
        let direction_layers: Vec<&[[u8; 4]]> = (0..shells.directions.layer_count())
            .map(|l| shells.directions.layer(l))
            .collect();
        let shell_colour = upload_layers(
            context,
            "fur_shell_colour",
            resolution,
            resolution,
            &colour_layers,
        );
        let shell_direction = upload_layers(
            context,
            "fur_shell_direction",
            resolution,
            resolution,
            &direction_layers,
        );
        let fin_texture = upload_layers(context, "fur_fin", fin.width, fin.height, &[&fin.texels]);
        let array_view = |texture: &wgpu::Texture| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                ..Default::default()
            })
        };
        let (centre, radius_m) = base.bounds();
        Ok(Self {
            key: FurKey {
                settings: settings.clone(),
                base: base.clone(),
                strands,
            },
            columns,
            corners,
            fins,
            shell_colour: array_view(&shell_colour),
            shell_direction: array_view(&shell_direction),
            fin_texture: fin_texture.create_view(&wgpu::TextureViewDescriptor::default()),
            textures: vec![shell_colour, shell_direction, fin_texture],
            corner_count: geometry.corners.len() as u32,
            fin_count: geometry.fins.len() as u32,
            patch_count: geometry.patch_count,
            layer_count,
            fibres_through,
            tile_width_m: tile_width_m as f32,
            length_m: base.mean_length_m(),
            centre,
            radius_m,
            seed_bytes: shells.seed_memory_bytes(true) + fin.memory_bytes(true),
        })
    }

    /// The fur's root-to-tip length on screen, seen by `camera` from outside its sphere.
    pub fn length_px(&self, camera: &FrameCamera) -> f32 {
        let distance_m = (camera.eye.distance(self.centre) - self.radius_m).max(1e-3);
        self.length_m / (distance_m * camera.pixel_at_unit())
    }

    /// Whether it was made from `base` with `settings`.
    /// (The cross-fade thresholds are read per frame: changing them makes nothing again.)
    pub fn fits(&self, base: &FurBase, settings: &FurShells, strands: FurStrands) -> bool {
        asset_settings(&self.key.settings) == asset_settings(settings)
            && self.key.base == *base
            && self.key.strands == strands
    }

    /// Bytes of its buffers and textures.
    pub fn bytes(&self) -> u64 {
        self.columns.size()
            + self.corners.size()
            + self.fins.size()
            + self.textures.iter().map(|t| texture_bytes(t)).sum::<u64>()
    }
}

/// The part of the settings the asset is made from.
fn asset_settings(settings: &FurShells) -> FurShells {
    FurShells {
        shells_below_px: 0.0,
        strands_above_px: 0.0,
        ..settings.clone()
    }
}

fn texture_bytes(texture: &wgpu::Texture) -> u64 {
    let size = texture.size();
    (0..texture.mip_level_count())
        .map(|level| {
            let w = (size.width >> level).max(1) as u64;
            let h = (size.height >> level).max(1) as u64;
            w * h * size.depth_or_array_layers as u64 * 4
        })
        .sum()
}

/// An RGBA8 array texture of `layers` (each `width × height`) with a full mip chain.
fn upload_layers(
    context: &GpuContext,
    label: &str,
    width: u32,
    height: u32,
    layers: &[&[[u8; 4]]],
) -> Tracked<wgpu::Texture> {
    let chains: Vec<_> = layers
        .iter()
        .map(|texels| mip_chain(texels, width, height))
        .collect();
    let mip_level_count = chains.first().map_or(1, Vec::len) as u32;
    let texture = context.resources.texture(
        &context.device,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: layers.len() as u32,
            },
            mip_level_count,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
    );
    for level in 0..mip_level_count as usize {
        for (layer, chain) in chains.iter().enumerate() {
            let (w, h, texels) = &chain[level];
            context.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: level as u32,
                    origin: wgpu::Origin3d {
                        x: 0,
                        y: 0,
                        z: layer as u32,
                    },
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(texels),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(w * 4),
                    rows_per_image: Some(*h),
                },
                wgpu::Extent3d {
                    width: *w,
                    height: *h,
                    depth_or_array_layers: 1,
                },
            );
        }
    }
    texture
}

struct FurPipelines {
    key: ShaderKey,
    /// Shells alone draw the fur: they write depth.
    shells: Tracked<wgpu::RenderPipeline>,
    /// Shells fading in over the strands: depth-tested only, so faint shells never hide the
    /// strands behind them.
    fading_shells: Tracked<wgpu::RenderPipeline>,
    fins: Tracked<wgpu::RenderPipeline>,
}

/// Fur's bindings and pipelines.
pub struct FurRenderer {
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    fin_sampler: wgpu::Sampler,
    targets: Targets,
    pipelines: Option<FurPipelines>,
}

/// One frame's fur: its uniforms and bindings, and what it draws.
pub struct PreparedFur {
    group: wgpu::BindGroup,
    /// Shells drawn (instances of the root faces) at `level`.
    pub shells: u32,
    pub level: f32,
    /// How much the shells show against the strands (1: shells only).
    pub weight: f32,
    /// The fur's length on screen.
    pub length_px: f32,
    corners: u32,
    fins: u32,
}

/// The share of strands a frame of `scene` seen by `camera` draws: where the scene draws fur
/// and the hair has it, what the shells leave to the strands (`1 −`
/// [`FurShells::shell_weight`]); 1 otherwise. Plan the frame's strands with it
/// (`LodSettings::strand_keep`), on the CPU and the mesh path alike.
pub fn strand_keep(scene: &Scene, hair: &HairSource, camera: &FrameCamera) -> f64 {
    match hair {
        HairSource::Generated { fur: Some(fur), .. } if scene.effects.fur == Fur::ShellsFins => {
            let weight = scene.effects.fur_shells.shell_weight(fur.length_px(camera)) as f64;
            if weight.is_nan() {
                1.0
            } else {
                1.0 - weight.clamp(0.0, 1.0)
            }
        }
        _ => 1.0,
    }
}

fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// Below this coverage a fur fragment writes nothing (seed 002's alpha test).
const ALPHA_TEST: f32 = 0.02;

impl FurRenderer {
    pub fn new(context: &GpuContext, targets: Targets) -> Self {
        let device = &context.device;
        let storage =
            |binding: u32, size: u64| storage_entry(binding, size, wgpu::ShaderStages::VERTEX);
        let texture = |binding: u32, view_dimension| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension,
                multisampled: false,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fur"),
            entries: &[
                uniform_entry(0, size_of::<FurUniforms>(), false),
                storage(1, size_of::<FurColumnGpu>() as u64),
                storage(2, size_of::<FurCornerGpu>() as u64),
                storage(3, size_of::<FurFinGpu>() as u64),
                texture(4, wgpu::TextureViewDimension::D2Array),
                texture(5, wgpu::TextureViewDimension::D2Array),
                texture(6, wgpu::TextureViewDimension::D2),
                sampler_entry(7),
                sampler_entry(8),
            ],
        });
        // The fur tile repeats across each patch (seed 002: texture wrapping); the fin's
        // height (v) does not.
        let make_sampler = |label, address_mode_v| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                address_mode_u: wgpu::AddressMode::Repeat,
                address_mode_v,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                mipmap_filter: wgpu::MipmapFilterMode::Linear,
                ..Default::default()
            })
        };
        let sampler = make_sampler("fur", wgpu::AddressMode::Repeat);
        let fin_sampler = make_sampler("fur_fin", wgpu::AddressMode::ClampToEdge);
        Self {
            layout,
            sampler,
            fin_sampler,
            targets,
            pipelines: None,
        }
    }

    /// Makes the pipelines for `effects` (group 1 the scene, group 2 the effects); cheap when
    /// nothing changed.
    pub fn ensure(
        &mut self,
        context: &GpuContext,
        effects: &ActiveEffects,
        scene_layout: &wgpu::BindGroupLayout,
        effects_layout: Option<&wgpu::BindGroupLayout>,
    ) {
        let key = effects.shader_key();
        if self.pipelines.as_ref().is_some_and(|p| p.key == key) {
            return;
        }
        let source = fur_shader(&key);
        let mut groups = vec![&self.layout, scene_layout];
        groups.extend(effects_layout);
        let blended = [Some(wgpu::ColorTargetState {
            format: self.targets.color,
            blend: Some(wgpu::BlendState::ALPHA_BLENDING),
            write_mask: wgpu::ColorWrites::ALL,
        })];
        let spec = |label, vertex_entry, fragment_entry, depth_write| PipelineSpec {
            label,
            source: &source,
            groups: &groups,
            buffers: &[],
            vertex_entry,
            topology: wgpu::PrimitiveTopology::TriangleList,
            fragment_entry: Some(fragment_entry),
            targets: &blended,
            depth: Some(view_depth(&self.targets, depth_write)),
            sample_count: self.targets.sample_count,
        };
        // Shells test and write depth (the alpha test keeps empty texels out of it); fins only
        // test it (seed 002 §2.3).
        let shells =
            crate::renderer::pipeline(context, &spec("fur_shells", "vs_shell", "fs_shell", true));
        let fading_shells = crate::renderer::pipeline(
            context,
            &spec("fur_shells_fading", "vs_shell", "fs_shell", false),
        );
        let fins = crate::renderer::pipeline(context, &spec("fur_fins", "vs_fin", "fs_fin", false));
        self.pipelines = Some(FurPipelines {
            key,
            shells,
            fading_shells,
            fins,
        });
    }

    /// Drops the pipelines (their group-2 layout changed).
    pub fn forget_pipelines(&mut self) {
        self.pipelines = None;
    }

    /// This frame's fur seen by `camera`, or `None` where the strands alone draw it.
    pub fn prepare(
        &self,
        context: &GpuContext,
        fur: &GpuFur,
        settings: &FurShells,
        camera: &FrameCamera,
    ) -> Option<PreparedFur> {
        let length_px = fur.length_px(camera);
        let weight = settings.shell_weight(length_px);
        if weight <= 0.0 || fur.corner_count == 0 {
            return None;
        }
        let level = shell_level(length_px as f64, fur.layer_count) as f32;
        let coarsest = fur.layer_count.ilog2();
        let m = (level.floor() as u32).min(coarsest);
        let t = if m < coarsest { level - m as f32 } else { 0.0 };
        let uniforms = FurUniforms {
            view_projection: camera.view_projection.to_cols_array_2d(),
            eye: camera.eye.extend(1.0).to_array(),
            shells: [
                fur.layer_count >> m,
                m,
                fur.layer_count,
                u32::from(m < coarsest),
            ],
            blend: [t, weight, ALPHA_TEST, fur.fibres_through],
            shape: [fur.tile_width_m, 0.0, 0.0, 0.0],
        };
        let buffer = wgpu::util::DeviceExt::create_buffer_init(
            &context.device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("fur_uniforms"),
                contents: bytemuck::bytes_of(&uniforms),
                usage: wgpu::BufferUsages::UNIFORM,
            },
        );
        let group = context
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("fur"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: fur.columns.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: fur.corners.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: fur.fins.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: wgpu::BindingResource::TextureView(&fur.shell_colour),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: wgpu::BindingResource::TextureView(&fur.shell_direction),
                    },
                    wgpu::BindGroupEntry {
                        binding: 6,
                        resource: wgpu::BindingResource::TextureView(&fur.fin_texture),
                    },
                    wgpu::BindGroupEntry {
                        binding: 7,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                    wgpu::BindGroupEntry {
                        binding: 8,
                        resource: wgpu::BindingResource::Sampler(&self.fin_sampler),
                    },
                ],
            });
        Some(PreparedFur {
            group,
            shells: fur.layer_count >> m,
            level,
            weight,
            length_px,
            corners: fur.corner_count,
            fins: fur.fin_count,
        })
    }

    /// Fins, then shells from the innermost out (instances draw in order, so each shell
    /// blends over the ones inside it); groups 1 and 2 set by the caller.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, prepared: &PreparedFur) {
        let Some(pipelines) = &self.pipelines else {
            return;
        };
        pass.set_bind_group(0, &prepared.group, &[]);
        if prepared.fins > 0 {
            pass.set_pipeline(&pipelines.fins);
            pass.draw(0..6, 0..prepared.fins);
        }
        pass.set_pipeline(if prepared.weight >= 1.0 {
            &pipelines.shells
        } else {
            &pipelines.fading_shells
        });
        pass.draw(0..prepared.corners, 0..prepared.shells);
    }
}
