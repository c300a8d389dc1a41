//! A view: the render targets of one picture (colour, MSAA colour, depth), kept across
//! frames and made again only when the size changes, and the read-back of its pixels.

use crate::device::{GpuContext, read_buffer};
use crate::resources::Tracked;

/// Colour target format; the picture is sRGB.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The non-sRGB view format of the resolved colour target: sampling it returns the
/// sRGB-encoded bytes, which is what egui composites.
pub const UI_VIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The MSAA sample count for the view's targets: 8× where the device allows it for colour,
/// depth and the width-based coverage targets, else 4× (which WebGPU guarantees), else none.
///
/// Counts beyond 1 and 4 are adapter-specific: a device may use them only when it was made
/// with `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES` (found on an NVIDIA H200, whose adapter
/// reports 8× for `Rgba8UnormSrgb` but whose device, made without the feature, refuses it).
pub fn sample_count(context: &GpuContext) -> u32 {
    supported_sample_count(
        context.device.features(),
        |format| context.adapter.get_texture_format_features(format).flags,
        &[
            COLOR_FORMAT,
            DEPTH_FORMAT,
            crate::renderer::preview_hair::OIT_ACCUMULATION_FORMAT,
            crate::renderer::preview_hair::OIT_REVEALAGE_FORMAT,
        ],
    )
}

/// The largest of 8 and 4 samples that every format in `formats` supports on a device with
/// `device_features`, else 1 (see [`sample_count`]).
pub fn supported_sample_count(
    device_features: wgpu::Features,
    adapter_flags: impl Fn(wgpu::TextureFormat) -> wgpu::TextureFormatFeatureFlags,
    formats: &[wgpu::TextureFormat],
) -> u32 {
    let adapter_specific =
        device_features.contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
    [8, 4]
        .into_iter()
        .filter(|&count| count == 4 || adapter_specific)
        .find(|&count| {
            formats
                .iter()
                .all(|&format| adapter_flags(format).sample_count_supported(count))
        })
        .unwrap_or(1)
}

/// The targets of one `width × height` picture.
pub struct View {
    pub width: u32,
    pub height: u32,
    pub sample_count: u32,
    /// Single-sampled colour: what is read back or sampled by a UI.
    resolved: Tracked<wgpu::Texture>,
    resolved_view: wgpu::TextureView,
    _msaa: Option<Tracked<wgpu::Texture>>,
    msaa_view: Option<wgpu::TextureView>,
    _depth: Tracked<wgpu::Texture>,
    depth_view: wgpu::TextureView,
}

impl View {
    pub fn new(context: &GpuContext, width: u32, height: u32, sample_count: u32) -> Self {
        let (width, height) = (width.max(1), height.max(1));
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        // The colour target may also be viewed without the sRGB suffix (see UI_VIEW_FORMAT).
        let ui_view = [UI_VIEW_FORMAT];
        let target =
            |label: &str, format: wgpu::TextureFormat, samples: u32, usage: wgpu::TextureUsages| {
                context.resources.texture(
                    &context.device,
                    &wgpu::TextureDescriptor {
                        label: Some(label),
                        size,
                        mip_level_count: 1,
                        sample_count: samples,
                        dimension: wgpu::TextureDimension::D2,
                        format,
                        usage,
                        view_formats: if format == COLOR_FORMAT && samples == 1 {
                            &ui_view
                        } else {
                            &[]
                        },
                    },
                )
            };
        let resolved = target(
            "view_color",
            COLOR_FORMAT,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let msaa = (sample_count > 1).then(|| {
            target(
                "view_msaa",
                COLOR_FORMAT,
                sample_count,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )
        });
        let depth = target(
            "view_depth",
            DEPTH_FORMAT,
            sample_count,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        Self {
            width,
            height,
            sample_count,
            resolved_view: resolved.create_view(&Default::default()),
            resolved,
            msaa_view: msaa.as_ref().map(|t| t.create_view(&Default::default())),
            _msaa: msaa,
            depth_view: depth.create_view(&Default::default()),
            _depth: depth,
        }
    }

    /// Keeps this view when it already has this size, else makes a new one.
    pub fn ensure<'v>(
        view: &'v mut Option<View>,
        context: &GpuContext,
        width: u32,
        height: u32,
        sample_count: u32,
    ) -> &'v View {
        let (width, height) = (width.max(1), height.max(1));
        let fits = view
            .as_ref()
            .is_some_and(|v| (v.width, v.height, v.sample_count) == (width, height, sample_count));
        if !fits {
            *view = Some(View::new(context, width, height, sample_count));
        }
        view.as_ref().expect("made above")
    }

    /// The resolved colour texture.
    pub fn color(&self) -> &wgpu::Texture {
        &self.resolved
    }

    /// Where passes draw (the MSAA target when there is one) and what the last pass
    /// resolves into.
    pub fn attachments(&self) -> (&wgpu::TextureView, Option<&wgpu::TextureView>) {
        match &self.msaa_view {
            Some(msaa) => (msaa, Some(&self.resolved_view)),
            None => (&self.resolved_view, None),
        }
    }

    pub fn depth(&self) -> &wgpu::TextureView {
        &self.depth_view
    }

    /// Submits `encoder` with a copy of the colour target and returns its RGBA8 (sRGB) rows,
    /// top first.
    pub fn read_back(
        context: &GpuContext,
        color: &wgpu::Texture,
        mut encoder: wgpu::CommandEncoder,
    ) -> Result<Vec<u8>, String> {
        let (width, height) = (color.width(), color.height());
        // Rows of a texture-to-buffer copy are padded to 256 bytes.
        let padded_row = (width * 4).div_ceil(256) * 256;
        let readback = context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("view_readback"),
            size: (padded_row * height) as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: color,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        context.queue.submit([encoder.finish()]);
        let mapped = read_buffer(context, &readback)?;
        let mut pixels = Vec::with_capacity((width * height * 4) as usize);
        for row in 0..height {
            let start = (row * padded_row) as usize;
            pixels.extend_from_slice(&mapped[start..start + (width * 4) as usize]);
        }
        Ok(pixels)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eight_samples_need_the_adapter_specific_feature_on_the_device() {
        use wgpu::TextureFormatFeatureFlags as F;
        let all = |_| F::MULTISAMPLE_X2 | F::MULTISAMPLE_X4 | F::MULTISAMPLE_X8;
        let formats = [COLOR_FORMAT, DEPTH_FORMAT];
        // The H200's case: the adapter reports 8×, the device was made without the feature.
        assert_eq!(
            supported_sample_count(wgpu::Features::empty(), all, &formats),
            4
        );
        let specific = wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES;
        assert_eq!(supported_sample_count(specific, all, &formats), 8);
        // One format without 8× keeps every target at 4×.
        let depth_without_8 = |format| {
            if format == DEPTH_FORMAT {
                F::MULTISAMPLE_X4
            } else {
                all(format)
            }
        };
        assert_eq!(
            supported_sample_count(specific, depth_without_8, &formats),
            4
        );
        assert_eq!(
            supported_sample_count(specific, |_| F::empty(), &formats),
            1
        );
    }
}
