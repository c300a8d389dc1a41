//! The runtime asset on the GPU ([`GpuHair`]): uploaded once, its textures rewritten in place
//! by a reshape and its styling buffers by a restyle.

use hairloom_core::io::ktx2::TexelFormat;
use hairloom_core::model::root_maps::RootMaps;
use hairloom_core::runtime::frame_plan::BundleBounds;
use hairloom_core::runtime::gpu_types::{BundleGpu, BundleLodGpu, StylingGpu, styling_array};
use hairloom_core::runtime::hair::RuntimeHair;
use hairloom_core::runtime::textures::{Precision, RuntimeTextures, Texture3d};

use super::*;
use crate::device::GpuContext;
use crate::resources::Tracked;

/// Everything generation reads, uploaded once (the game's per-asset data): the five
/// textures, one placement per bundle, the root sample sets and the styling array. Nothing
/// is stored per strand.
pub struct GpuHair {
    pub position_offset: [f32; 3],
    /// The five textures (hair_mesh, uv, w, u, v): kept so the registry lists them while
    /// the hair lives, and rewritten in place by [`StrandGenRenderer::update_shape`].
    pub(super) textures: Vec<Tracked<wgpu::Texture>>,
    pub(super) hair_mesh: wgpu::TextureView,
    pub(super) uv: wgpu::TextureView,
    pub(super) w: wgpu::TextureView,
    pub(super) u: wgpu::TextureView,
    pub(super) v: wgpu::TextureView,
    /// The painted maps (one white texel when none), replaced when their size changes.
    pub(super) root_maps: Tracked<wgpu::Texture>,
    pub(super) root_maps_view: wgpu::TextureView,
    /// The maps the texture holds (compared on a restyle, so a styling tick writes nothing).
    root_maps_shown: RootMaps,
    /// The colour map at every root, packed ([`RuntimeHair::root_paint`]; one 0, no colour,
    /// when none is painted): what the hair's colour pass reads per strand.
    pub(crate) root_paint: Tracked<wgpu::Buffer>,
    /// The uv-texture the per-root colours were read at (a reshape that moves uvs — a
    /// Layout edit — reads them again; motion, which moves none, does not).
    root_uv_shown: Vec<glam::Vec4>,
    pub(super) bundle_buffer: Tracked<wgpu::Buffer>,
    /// Each bundle's bounds and sizes for LOD, for the mesh path's task shaders.
    pub(super) bundle_lods: Tracked<wgpu::Buffer>,
    pub(super) samples: Tracked<wgpu::Buffer>,
    pub(super) sample_set: u32,
    /// Strands at full detail: bundles × `per_bundle`.
    pub root_count: usize,
    pub(super) styling: Tracked<wgpu::Buffer>,
    /// Bounds of every bundle (block order) for LOD and culling.
    pub bundles: Vec<BundleBounds>,
    /// Roots per bundle (roots are bundle-major).
    pub per_bundle: u32,
    /// Bytes of the textures, roots and styling on the GPU.
    pub bytes: u64,
    layout: TextureLayout,
}

/// The painted maps' texture: RGBA8 in root-uv space, or one white texel when nothing is
/// painted (the shader then reads 1 everywhere and needs no switch).
/// The maps' size and RGBA8 bytes as the GPU holds them: one white texel when nothing is
/// painted.
fn root_map_texels(maps: &RootMaps) -> (u32, u32, Vec<u8>) {
    if maps.is_empty() {
        (1, 1, vec![255; 4])
    } else {
        (maps.width(), maps.height(), maps.rgba8())
    }
}

/// The per-root colours of `hair` in a storage buffer (one 0 when no colour is painted: a
/// storage binding is never empty).
fn upload_root_paint(context: &GpuContext, hair: &RuntimeHair) -> Tracked<wgpu::Buffer> {
    let mut paint = hair.root_paint();
    if paint.is_empty() {
        paint.push(0);
    }
    context.resources.buffer_init(
        &context.device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("root_paint"),
            contents: bytemuck::cast_slice(&paint),
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        },
    )
}

/// Works out `hair`'s per-root colours again into `gpu` (in place where the count is the same).
fn refresh_root_paint(context: &GpuContext, gpu: &mut GpuHair, hair: &RuntimeHair) {
    gpu.root_uv_shown.clone_from(&hair.textures.uv.texels);
    let before = gpu.root_paint.size();
    let paint = hair.root_paint();
    if !paint.is_empty() && paint.len() as u64 * 4 == before {
        context
            .queue
            .write_buffer(&gpu.root_paint, 0, bytemuck::cast_slice(&paint));
    } else {
        gpu.root_paint = upload_root_paint(context, hair);
        gpu.bytes = gpu.bytes - before + gpu.root_paint.size();
    }
}

fn upload_root_maps(
    context: &GpuContext,
    maps: &RootMaps,
) -> (Tracked<wgpu::Texture>, wgpu::TextureView) {
    let (width, height, bytes) = root_map_texels(maps);
    let texture = context.resources.texture(
        &context.device,
        &wgpu::TextureDescriptor {
            label: Some("root_maps"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
    );
    write_root_maps(context, &texture, width, height, &bytes);
    let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    (texture, view)
}

fn write_root_maps(
    context: &GpuContext,
    texture: &wgpu::Texture,
    width: u32,
    height: u32,
    bytes: &[u8],
) {
    write_level(context, texture, [width, height, 1], 4, bytes);
}

fn upload_texture(
    context: &GpuContext,
    label: &str,
    texture: &Texture3d,
    precision: Precision,
    channels: usize,
) -> (Tracked<wgpu::Texture>, wgpu::TextureView, u64) {
    let export_format = TexelFormat::for_precision(precision, channels);
    let format = match export_format {
        TexelFormat::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
        TexelFormat::Rg32Float => wgpu::TextureFormat::Rg32Float,
        TexelFormat::R32Float => wgpu::TextureFormat::R32Float,
        TexelFormat::Rgba16Float => wgpu::TextureFormat::Rgba16Float,
        TexelFormat::Rg16Float => wgpu::TextureFormat::Rg16Float,
        TexelFormat::R16Float => wgpu::TextureFormat::R16Float,
        TexelFormat::Rgba8Unorm => wgpu::TextureFormat::Rgba8Unorm,
        TexelFormat::Rgba8Srgb => wgpu::TextureFormat::Rgba8UnormSrgb,
    };
    let bytes = hairloom_core::io::ktx2::texel_bytes(&texture.texels, export_format);
    let size = wgpu::Extent3d {
        width: texture.width,
        height: texture.height,
        depth_or_array_layers: texture.depth,
    };
    let gpu_texture = context.resources.texture(
        &context.device,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
    );
    write_texels(
        context,
        &gpu_texture,
        texture,
        &bytes,
        channels,
        export_format,
    );
    let view = gpu_texture.create_view(&wgpu::TextureViewDescriptor::default());
    (gpu_texture, view, bytes.len() as u64)
}

/// Writes `bytes` (the texels of `texture` in `format`) into all of `gpu_texture`.
fn write_texels(
    context: &GpuContext,
    gpu_texture: &wgpu::Texture,
    texture: &Texture3d,
    bytes: &[u8],
    channels: usize,
    format: TexelFormat,
) {
    let texel_size = (channels * format.bytes_per_channel()) as u32;
    let size = [texture.width, texture.height, texture.depth];
    write_level(context, gpu_texture, size, texel_size, bytes);
}

/// Writes the whole of a texture's one level, `[width, height, depth]` texels of
/// `texel_size` bytes each.
fn write_level(
    context: &GpuContext,
    texture: &wgpu::Texture,
    [width, height, depth]: [u32; 3],
    texel_size: u32,
    bytes: &[u8],
) {
    context.queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(width * texel_size),
            rows_per_image: Some(height),
        },
        wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: depth,
        },
    );
}

/// What the GPU textures and placements of a [`GpuHair`] were laid out for: a reshaped hair
/// mesh with the same layout can be written into them in place.
#[derive(Clone, Debug, PartialEq)]
struct TextureLayout {
    precision: Precision,
    /// `[width, height, depth]` of hair_mesh, uv, w, u, v.
    sizes: [[u32; 3]; 5],
    blocks: Vec<hairloom_core::runtime::atlas::BundleBlock>,
    per_bundle: u32,
}

impl TextureLayout {
    fn of(hair: &RuntimeHair, per_bundle: u32) -> Self {
        let t = &hair.textures;
        Self {
            precision: t.precision,
            sizes: [&t.hair_mesh, &t.uv, &t.w, &t.u, &t.v].map(|x| [x.width, x.height, x.depth]),
            blocks: t.atlas.blocks.clone(),
            per_bundle,
        }
    }
}

/// One placement per atlas block with its styling index (never empty: a storage buffer
/// cannot be).
fn bundle_placements(textures: &RuntimeTextures, block_styling: &[u32]) -> Vec<BundleGpu> {
    let mut bundles: Vec<BundleGpu> = textures
        .atlas
        .blocks
        .iter()
        .enumerate()
        .map(|(i, block)| BundleGpu::new(block, block_styling.get(i).copied().unwrap_or(0)))
        .collect();
    if bundles.is_empty() {
        bundles.push(BundleGpu::default());
    }
    bundles
}

/// Each bundle's bounds and sizes for the mesh path's LOD (never empty: a storage buffer
/// cannot be).
fn bundle_lods(bounds: &[BundleBounds], per_bundle: u32) -> Vec<BundleLodGpu> {
    let mut bundles: Vec<BundleLodGpu> = bounds
        .iter()
        .map(|b| BundleLodGpu::new(b, per_bundle))
        .collect();
    if bundles.is_empty() {
        bundles.push(BundleLodGpu::default());
    }
    bundles
}

/// The styling array, or the default parameters when it is empty.
fn styling_or_default(styling: Vec<StylingGpu>) -> Vec<StylingGpu> {
    if styling.is_empty() {
        vec![StylingGpu::from(
            &hairloom_core::model::styling::StylingParams::default(),
        )]
    } else {
        styling
    }
}

impl GpuHair {
    /// The colour map at every root, packed (one 0 when none is painted): what the colour
    /// pass reads per strand.
    pub fn root_paint(&self) -> &wgpu::Buffer {
        &self.root_paint
    }

    /// Each bundle's bounds and LOD sizes (block order): what the mesh path's task shaders
    /// cull and plan with.
    pub fn bundle_lods(&self) -> &wgpu::Buffer {
        &self.bundle_lods
    }
}

impl StrandGenRenderer {
    /// Takes `hair`'s painted maps into `gpu`: written in place at the same size, a new
    /// texture otherwise (bind groups are made per frame, so the next frame reads it); the
    /// per-root colours are worked out again when the colour map changed.
    pub fn update_root_maps(&self, context: &GpuContext, gpu: &mut GpuHair, hair: &RuntimeHair) {
        let maps = &hair.textures.root_maps;
        // A styling tick leaves the maps alone: nothing to write.
        if gpu.root_maps_shown == *maps {
            return;
        }
        let shown = &gpu.root_maps_shown;
        let same_size = (shown.width(), shown.height()) == (maps.width(), maps.height());
        let colour_changed = !same_size || shown.colour_texels() != maps.colour_texels();
        // A colour stroke leaves the grey maps alone: their texture is not written again.
        let grey_changed = !same_size || shown.texels() != maps.texels();
        if colour_changed {
            refresh_root_paint(context, gpu, hair);
        }
        if grey_changed {
            self.write_grey_maps(context, gpu, maps);
        }
        gpu.root_maps_shown = maps.clone();
    }

    /// Writes the grey maps' texture of `gpu` (in place at the same size, a new one otherwise).
    fn write_grey_maps(&self, context: &GpuContext, gpu: &mut GpuHair, maps: &RootMaps) {
        let (width, height, bytes) = root_map_texels(maps);
        if (gpu.root_maps.width(), gpu.root_maps.height()) == (width, height) {
            write_root_maps(context, &gpu.root_maps, width, height, &bytes);
        } else {
            let before = 4 * u64::from(gpu.root_maps.width()) * u64::from(gpu.root_maps.height());
            let (texture, view) = upload_root_maps(context, maps);
            gpu.bytes = gpu.bytes - before + 4 * u64::from(width) * u64::from(height);
            gpu.root_maps = texture;
            gpu.root_maps_view = view;
        }
    }

    /// Uploads a runtime asset: the five textures (f32 or f16 as built), every bundle's block
    /// placement with its styling index, the first `strands_per_bundle` root samples of each
    /// domain and the styling array. Root `i` is then sample `i % strands_per_bundle` of
    /// block `i / strands_per_bundle`, as [`RuntimeHair::strand_roots`] lays roots out on the
    /// CPU.
    ///
    /// Refused, with nothing created, when a resource would exceed the adapter's limits
    /// ([`check_adapter_limits`]).
    pub fn upload(
        &self,
        context: &GpuContext,
        hair: &RuntimeHair,
    ) -> Result<GpuHair, StrandGenError> {
        check_adapter_limits(&context.device.limits(), hair)?;
        let (textures, samples) = (&hair.textures, &hair.samples);
        let per_bundle = hair.strands_per_bundle as usize;
        let block_styling = &hair.block_styling;
        let precision = textures.precision;
        let (t0, hair_mesh, a) =
            upload_texture(context, "hair_mesh", &textures.hair_mesh, precision, 4);
        let (t1, uv, b) = upload_texture(context, "uv", &textures.uv, precision, 2);
        let (t2, w, c) = upload_texture(context, "w", &textures.w, precision, 1);
        let (t3, u, d) = upload_texture(context, "u", &textures.u, precision, 4);
        let (t4, v, e) = upload_texture(context, "v", &textures.v, precision, 4);
        let buffer = |label: &str, contents: &[u8]| {
            context.resources.buffer_init(
                &context.device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    // COPY_DST: styling edits rewrite the bundle and styling buffers in place.
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                },
            )
        };
        let per_bundle = per_bundle
            .min(samples.quad.len())
            .min(samples.triangle.len());
        let bundles = bundle_placements(textures, block_styling);
        let block_count = textures.atlas.blocks.len();
        let sample_set = per_bundle.max(1);
        let mut sample_data: Vec<[f32; 2]> = Vec::with_capacity(2 * sample_set);
        for set in [&samples.quad, &samples.triangle] {
            sample_data.extend(set.iter().take(sample_set));
            sample_data.resize(
                sample_data.len().div_ceil(sample_set) * sample_set,
                [0.0; 2],
            );
        }
        let styling = styling_or_default(styling_array(&hair.styling));
        let styling_bytes: &[u8] = bytemuck::cast_slice(&styling);
        let (root_maps, root_maps_view) = upload_root_maps(context, &textures.root_maps);
        let root_paint = upload_root_paint(context, hair);
        let root_maps_bytes = 4 * u64::from(root_maps.width()) * u64::from(root_maps.height());
        let bundle_bytes: &[u8] = bytemuck::cast_slice(&bundles);
        let sample_bytes: &[u8] = bytemuck::cast_slice(&sample_data);
        let bounds = hair.bundle_bounds();
        let lods = bundle_lods(&bounds, per_bundle as u32);
        let lod_bytes: &[u8] = bytemuck::cast_slice(&lods);
        Ok(GpuHair {
            position_offset: textures.position_offset.to_array(),
            textures: vec![t0, t1, t2, t3, t4],
            hair_mesh,
            uv,
            w,
            u,
            v,
            root_maps,
            root_maps_view,
            root_maps_shown: textures.root_maps.clone(),
            bytes: a
                + b
                + c
                + d
                + e
                + root_maps_bytes
                + root_paint.size()
                + (bundle_bytes.len() + lod_bytes.len() + sample_bytes.len() + styling_bytes.len())
                    as u64,
            root_paint,
            root_uv_shown: textures.uv.texels.clone(),
            bundle_buffer: buffer("strand_gen_bundles", bundle_bytes),
            bundle_lods: buffer("strand_mesh_bundle_lods", lod_bytes),
            samples: buffer("strand_gen_samples", sample_bytes),
            sample_set: sample_set as u32,
            root_count: block_count * per_bundle,
            styling: buffer("strand_gen_styling", styling_bytes),
            bundles: bounds,
            per_bundle: per_bundle as u32,
            layout: TextureLayout::of(hair, per_bundle as u32),
        })
    }

    /// Takes a reshaped `hair` (the hair mesh moved — motion, drape, a vertex drag — with the
    /// same atlas, texture sizes, precision and strands per bundle) into `gpu` by rewriting its five
    /// textures, placements and bounds in place: no allocation, no sample upload. Returns
    /// `false`, writing nothing, when the layout differs (then upload afresh).
    pub fn update_shape(
        &self,
        context: &GpuContext,
        gpu: &mut GpuHair,
        hair: &RuntimeHair,
    ) -> bool {
        let per_bundle = (hair.strands_per_bundle as usize)
            .min(hair.samples.quad.len())
            .min(hair.samples.triangle.len()) as u32;
        if TextureLayout::of(hair, per_bundle) != gpu.layout {
            return false;
        }
        let textures = &hair.textures;
        let precision = textures.precision;
        for (gpu_texture, (texture, channels)) in gpu.textures.iter().zip([
            (&textures.hair_mesh, 4),
            (&textures.uv, 2),
            (&textures.w, 1),
            (&textures.u, 4),
            (&textures.v, 4),
        ]) {
            let format = TexelFormat::for_precision(precision, channels);
            let bytes = hairloom_core::io::ktx2::texel_bytes(&texture.texels, format);
            write_texels(context, gpu_texture, texture, &bytes, channels, format);
        }
        // A reshape may move the roots' uvs (a Layout edit): the colour map is read there.
        if textures.root_maps.has_colour() && gpu.root_uv_shown != textures.uv.texels {
            refresh_root_paint(context, gpu, hair);
        }
        gpu.position_offset = textures.position_offset.to_array();
        gpu.bundles = hair.bundle_bounds();
        context.queue.write_buffer(
            &gpu.bundle_lods,
            0,
            bytemuck::cast_slice(&bundle_lods(&gpu.bundles, gpu.per_bundle)),
        );
        self.update_styling(context, gpu, hair);
        true
    }

    /// Takes `hair`'s styling (parameters and group assignments) into `gpu` without touching
    /// its textures or samples: the bundle and styling buffers are rewritten in place (the
    /// styling buffer is replaced only when groups were added). What a styling-only edit
    /// costs; `hair` must be the asset `gpu` was uploaded from, restyled.
    pub fn update_styling(&self, context: &GpuContext, gpu: &mut GpuHair, hair: &RuntimeHair) {
        self.update_root_maps(context, gpu, hair);
        // A group's per-area density target changes how many strands each bundle grows.
        let bounds = hair.bundle_bounds();
        if bounds.len() == gpu.bundles.len() && bounds != gpu.bundles {
            gpu.bundles = bounds;
            context.queue.write_buffer(
                &gpu.bundle_lods,
                0,
                bytemuck::cast_slice(&bundle_lods(&gpu.bundles, gpu.per_bundle)),
            );
        }
        let bundles = bundle_placements(&hair.textures, &hair.block_styling);
        context
            .queue
            .write_buffer(&gpu.bundle_buffer, 0, bytemuck::cast_slice(&bundles));
        let styling = styling_or_default(styling_array(&hair.styling));
        let bytes: &[u8] = bytemuck::cast_slice(&styling);
        if bytes.len() as u64 <= gpu.styling.size() {
            context.queue.write_buffer(&gpu.styling, 0, bytes);
        } else {
            gpu.bytes += bytes.len() as u64 - gpu.styling.size();
            gpu.styling = context.resources.buffer_init(
                &context.device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some("strand_gen_styling"),
                    contents: bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                },
            );
        }
    }
}
