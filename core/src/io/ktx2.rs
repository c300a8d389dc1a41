//! KTX2 textures of the runtime bundle: the texel formats (with their Vulkan names), texel
//! bytes at f32 or f16, writing a single-level uncompressed file and reading one back with
//! every header field checked against what the manifest says.

use glam::Vec4;

use crate::io::runtime_bundle::ExportError;
use crate::runtime::half::{f16_bits, f16_to_f32};
use crate::runtime::textures::{Precision, Texture3d};

/// Texel formats the runtime bundle uses, with their Vulkan names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexelFormat {
    Rgba32Float,
    Rg32Float,
    R32Float,
    Rgba16Float,
    Rg16Float,
    R16Float,
}

impl TexelFormat {
    pub fn vk_name(self) -> &'static str {
        match self {
            Self::Rgba32Float => "R32G32B32A32_SFLOAT",
            Self::Rg32Float => "R32G32_SFLOAT",
            Self::R32Float => "R32_SFLOAT",
            Self::Rgba16Float => "R16G16B16A16_SFLOAT",
            Self::Rg16Float => "R16G16_SFLOAT",
            Self::R16Float => "R16_SFLOAT",
        }
    }

    fn ktx2(self) -> ktx2::Format {
        match self {
            Self::Rgba32Float => ktx2::Format::R32G32B32A32_SFLOAT,
            Self::Rg32Float => ktx2::Format::R32G32_SFLOAT,
            Self::R32Float => ktx2::Format::R32_SFLOAT,
            Self::Rgba16Float => ktx2::Format::R16G16B16A16_SFLOAT,
            Self::Rg16Float => ktx2::Format::R16G16_SFLOAT,
            Self::R16Float => ktx2::Format::R16_SFLOAT,
        }
    }

    pub fn channels(self) -> usize {
        match self {
            Self::Rgba32Float | Self::Rgba16Float => 4,
            Self::Rg32Float | Self::Rg16Float => 2,
            Self::R32Float | Self::R16Float => 1,
        }
    }

    pub fn bytes_per_channel(self) -> usize {
        match self {
            Self::Rgba32Float | Self::Rg32Float | Self::R32Float => 4,
            _ => 2,
        }
    }

    /// Format of a runtime texture with `channels` channels at `precision`. The uv-texture
    /// (the only two-channel one) stays f32 at every precision: the root uv seeds every
    /// per-strand random value, and f16 would quantise it to 1/2048 — whole rows of
    /// neighbouring strands would share their curl phase and clump. It is one 2D slice, so
    /// this costs 4 bytes per atlas texel.
    pub fn for_precision(precision: Precision, channels: usize) -> Self {
        match (precision, channels) {
            (_, 2) => Self::Rg32Float,
            (Precision::F32, 4) => Self::Rgba32Float,
            (Precision::F32, _) => Self::R32Float,
            (Precision::F16, 4) => Self::Rgba16Float,
            (Precision::F16, _) => Self::R16Float,
        }
    }
}
/// Texel bytes of `texels` in `format` (the first `format.channels()` components of each).
pub fn texel_bytes(texels: &[Vec4], format: TexelFormat) -> Vec<u8> {
    let channels = format.channels();
    let mut out = Vec::with_capacity(texels.len() * channels * format.bytes_per_channel());
    for texel in texels {
        for c in 0..channels {
            if format.bytes_per_channel() == 4 {
                out.extend_from_slice(&texel[c].to_le_bytes());
            } else {
                out.extend_from_slice(&f16_bits(texel[c]).to_le_bytes());
            }
        }
    }
    out
}

/// A single-level, uncompressed KTX2 file (2D when `depth == 0`, else 3D).
pub fn ktx2_bytes(
    format: TexelFormat,
    width: u32,
    height: u32,
    depth: u32,
    data: &[u8],
) -> Result<Vec<u8>, ExportError> {
    let (basic, type_size) =
        ktx2::dfd::Basic::from_format(format.ktx2()).map_err(|e| ExportError::Ktx2 {
            format: format.vk_name(),
            message: format!("{e:?}"),
        })?;
    let block = ktx2::dfd::Block::Basic(basic).to_vec();
    let dfd_total = 4 + block.len();
    let level_index_offset = ktx2::Header::LENGTH;
    let dfd_offset = level_index_offset + ktx2::LevelIndex::LENGTH;
    let kvd_offset = dfd_offset + dfd_total;
    let mut kvd = Vec::new();
    let writer = format!("KTXwriter\0hairloom {}\0", env!("CARGO_PKG_VERSION"));
    kvd.extend_from_slice(&(writer.len() as u32).to_le_bytes());
    kvd.extend_from_slice(writer.as_bytes());
    while !kvd.len().is_multiple_of(4) {
        kvd.push(0);
    }
    // Level data aligned to lcm(texel size, 4).
    let texel_size = format.channels() * format.bytes_per_channel();
    let alignment = if texel_size.is_multiple_of(4) {
        texel_size
    } else {
        texel_size * 4 / gcd(texel_size, 4)
    };
    let mut level_offset = kvd_offset + kvd.len();
    level_offset = level_offset.div_ceil(alignment) * alignment;
    let to_u32 = |v: usize| u32::try_from(v).map_err(|_| ExportError::TooLarge(v));
    let header = ktx2::Header {
        format: Some(format.ktx2()),
        type_size,
        pixel_width: width,
        pixel_height: height,
        pixel_depth: depth,
        layer_count: 0,
        face_count: 1,
        level_count: 1,
        supercompression_scheme: None,
        index: ktx2::Index {
            dfd_byte_offset: to_u32(dfd_offset)?,
            dfd_byte_length: to_u32(dfd_total)?,
            kvd_byte_offset: to_u32(kvd_offset)?,
            kvd_byte_length: to_u32(kvd.len())?,
            sgd_byte_offset: 0,
            sgd_byte_length: 0,
        },
    };
    let level = ktx2::LevelIndex {
        byte_offset: level_offset as u64,
        byte_length: data.len() as u64,
        uncompressed_byte_length: data.len() as u64,
    };
    let mut out = Vec::with_capacity(level_offset + data.len());
    out.extend_from_slice(&header.as_bytes());
    out.extend_from_slice(&level.as_bytes());
    out.extend_from_slice(&to_u32(dfd_total)?.to_le_bytes());
    out.extend_from_slice(&block);
    out.extend_from_slice(&kvd);
    out.resize(level_offset, 0);
    out.extend_from_slice(data);
    Ok(out)
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// Reads a KTX2 file written by [`ktx2_bytes`] into a texture, checking its format and
/// size against `format` and `expected_size` (depth 0: a 2D texture) and that every texel
/// value is finite. The message names what is wrong.
pub fn read_texture(
    bytes: &[u8],
    format: TexelFormat,
    expected_size: [u32; 3],
) -> Result<Texture3d, String> {
    let reader = ktx2::Reader::new(bytes).map_err(|e| format!("not a valid KTX2 file: {e:?}"))?;
    let header = reader.header();
    if header.format != Some(format.ktx2()) {
        return Err(format!(
            "KTX2 format {:?} does not match the manifest ({})",
            header.format,
            format.vk_name()
        ));
    }
    let size = [header.pixel_width, header.pixel_height, header.pixel_depth];
    if size != expected_size {
        return Err(format!(
            "KTX2 size {size:?} does not match the manifest {expected_size:?}"
        ));
    }
    let Some(level) = reader.levels().next() else {
        return Err("no mip level".into());
    };
    let depth = size[2].max(1);
    let channels = format.channels();
    let texel_bytes = channels * format.bytes_per_channel();
    // Checked: a hostile header must not wrap the byte count and pass the length check.
    let texel_count = (size[0] as usize)
        .checked_mul(size[1] as usize)
        .and_then(|n| n.checked_mul(depth as usize))
        .filter(|n| n.checked_mul(texel_bytes).is_some())
        .ok_or_else(|| format!("KTX2 size {size:?} is too large"))?;
    if level.data.len() != texel_count * texel_bytes {
        return Err(format!(
            "{} bytes of texels, expected {}",
            level.data.len(),
            texel_count * texel_bytes
        ));
    }
    let mut texels = Vec::with_capacity(texel_count);
    for chunk in level.data.chunks_exact(texel_bytes) {
        let mut texel = Vec4::ZERO;
        for c in 0..channels {
            let value = if format.bytes_per_channel() == 4 {
                f32::from_le_bytes([
                    chunk[4 * c],
                    chunk[4 * c + 1],
                    chunk[4 * c + 2],
                    chunk[4 * c + 3],
                ])
            } else {
                f16_to_f32(u16::from_le_bytes([chunk[2 * c], chunk[2 * c + 1]]))
            };
            if !value.is_finite() {
                return Err(format!("texel {} channel {c} is not finite", texels.len()));
            }
            texel[c] = value;
        }
        texels.push(texel);
    }
    Ok(Texture3d {
        width: size[0],
        height: size[1],
        depth,
        texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ktx2_files_read_back_with_the_ktx2_crate() {
        let texels: Vec<Vec4> = (0..2 * 3 * 4)
            .map(|i| Vec4::new(i as f32, -(i as f32), 0.5, 1.0))
            .collect();
        for format in [
            TexelFormat::Rgba32Float,
            TexelFormat::Rgba16Float,
            TexelFormat::R32Float,
            TexelFormat::Rg16Float,
        ] {
            let data = texel_bytes(&texels, format);
            let bytes = ktx2_bytes(format, 2, 3, 4, &data).expect("ktx2");
            let reader = ktx2::Reader::new(&bytes).expect("valid KTX2");
            let header = reader.header();
            assert_eq!(
                (header.pixel_width, header.pixel_height, header.pixel_depth),
                (2, 3, 4)
            );
            assert_eq!(header.format, Some(format.ktx2()));
            let level = reader.levels().next().expect("one level");
            assert_eq!(level.data, &data[..]);
            assert_eq!(reader.dfd_blocks().len(), 1);
        }
    }
}
