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
    /// The painted maps (`root_maps`): bytes, read as byte / 255.
    Rgba8Unorm,
    /// The colour map (`colour_map`): sRGB-encoded rgb, linear alpha; read as the stored
    /// byte / 255 (a GPU sampling it as an sRGB texture decodes the rgb).
    Rgba8Srgb,
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
            Self::Rgba8Unorm => "R8G8B8A8_UNORM",
            Self::Rgba8Srgb => "R8G8B8A8_SRGB",
        }
    }

    /// The `VkFormat` number KTX2 headers store.
    pub fn vk_number(self) -> u32 {
        self.ktx2().value()
    }

    fn ktx2(self) -> ktx2::Format {
        match self {
            Self::Rgba32Float => ktx2::Format::R32G32B32A32_SFLOAT,
            Self::Rg32Float => ktx2::Format::R32G32_SFLOAT,
            Self::R32Float => ktx2::Format::R32_SFLOAT,
            Self::Rgba16Float => ktx2::Format::R16G16B16A16_SFLOAT,
            Self::Rg16Float => ktx2::Format::R16G16_SFLOAT,
            Self::R16Float => ktx2::Format::R16_SFLOAT,
            Self::Rgba8Unorm => ktx2::Format::R8G8B8A8_UNORM,
            Self::Rgba8Srgb => ktx2::Format::R8G8B8A8_SRGB,
        }
    }

    pub fn channels(self) -> usize {
        match self {
            Self::Rgba32Float | Self::Rgba16Float | Self::Rgba8Unorm | Self::Rgba8Srgb => 4,
            Self::Rg32Float | Self::Rg16Float => 2,
            Self::R32Float | Self::R16Float => 1,
        }
    }

    pub fn bytes_per_channel(self) -> usize {
        match self {
            Self::Rgba32Float | Self::Rg32Float | Self::R32Float => 4,
            Self::Rgba8Unorm | Self::Rgba8Srgb => 1,
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
            } else if format.bytes_per_channel() == 1 {
                out.push((texel[c].clamp(0.0, 1.0) * 255.0).round() as u8);
            } else {
                out.extend_from_slice(&f16_bits(texel[c]).to_le_bytes());
            }
        }
    }
    out
}

/// A single-level, uncompressed KTX2 file (2D when `depth == 0`, else 3D).
pub(crate) fn ktx2_bytes(
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

/// The 12 bytes every KTX2 file starts with.
const KTX2_IDENTIFIER: [u8; 12] = [
    0xAB, b'K', b'T', b'X', b' ', b'2', b'0', 0xBB, b'\r', b'\n', 0x1A, b'\n',
];

/// Bytes of the KTX2 header and of one level-index entry.
const HEADER_BYTES: usize = 80;
const LEVEL_INDEX_BYTES: usize = 24;

/// Reads a KTX2 file written by [`ktx2_bytes`] into a texture, checking its format and
/// size against `format` and `expected_size` (depth 0: a 2D texture) and that every texel
/// value is finite. The message names what is wrong.
///
/// The header is parsed here, with checked arithmetic, rather than by `ktx2::Reader`:
/// that reader parses the data format descriptor eagerly and panics on some malformed
/// ones (ktx2 0.5.0: a texel-block dimension byte of 255 overflows and unwraps `None`).
/// The descriptor is only bounds-checked: for an uncompressed file `vkFormat` is
/// authoritative (KTX2 spec §3.1), and it must equal the manifest's format.
pub fn read_texture(
    bytes: &[u8],
    format: TexelFormat,
    expected_size: [u32; 3],
) -> Result<Texture3d, String> {
    if bytes.len() < HEADER_BYTES + LEVEL_INDEX_BYTES {
        return Err(format!(
            "{} bytes is shorter than a KTX2 header and level index",
            bytes.len()
        ));
    }
    if bytes[..12] != KTX2_IDENTIFIER {
        return Err("not a KTX2 file (wrong identifier)".into());
    }
    let word =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let long = |at: usize| u64::from(word(at)) | (u64::from(word(at + 4)) << 32);
    let vk_format = word(12);
    if vk_format != format.ktx2().value() {
        return Err(format!(
            "KTX2 vkFormat {vk_format} does not match the manifest ({} = {})",
            format.vk_name(),
            format.ktx2().value()
        ));
    }
    let type_size = word(16);
    if type_size as usize != format.bytes_per_channel() {
        return Err(format!(
            "KTX2 typeSize {type_size} does not match {}",
            format.vk_name()
        ));
    }
    let size = [word(20), word(24), word(28)];
    if size != expected_size {
        return Err(format!(
            "KTX2 size {size:?} does not match the manifest {expected_size:?}"
        ));
    }
    let (layers, faces, levels, supercompression) = (word(32), word(36), word(40), word(44));
    if layers != 0 || faces != 1 || levels > 1 || supercompression != 0 {
        return Err(format!(
            "KTX2 with {layers} array layers, {faces} faces, {levels} levels and \
             supercompression {supercompression}: a runtime texture is one uncompressed level"
        ));
    }
    let in_file = |offset: u64, length: u64| {
        offset
            .checked_add(length)
            .is_some_and(|end| end <= bytes.len() as u64)
    };
    let (dfd_offset, dfd_length) = (word(48), word(52));
    if dfd_length < 4 || !in_file(dfd_offset.into(), dfd_length.into()) {
        return Err(format!(
            "KTX2 data format descriptor ({dfd_length} bytes at {dfd_offset}) is outside the file"
        ));
    }
    if word(dfd_offset as usize) != dfd_length {
        return Err("KTX2 data format descriptor's own length disagrees with the index".into());
    }
    let (level_offset, level_length) = (long(HEADER_BYTES), long(HEADER_BYTES + 8));
    if !in_file(level_offset, level_length) {
        return Err(format!(
            "KTX2 level ({level_length} bytes at {level_offset}) runs past the end of the file ({} bytes)",
            bytes.len()
        ));
    }
    let data = &bytes[level_offset as usize..(level_offset + level_length) as usize];
    let depth = size[2].max(1);
    let channels = format.channels();
    let texel_bytes = channels * format.bytes_per_channel();
    // Checked: a hostile header must not wrap the byte count and pass the length check.
    let texel_count = (size[0] as usize)
        .checked_mul(size[1] as usize)
        .and_then(|n| n.checked_mul(depth as usize))
        .filter(|n| n.checked_mul(texel_bytes).is_some())
        .ok_or_else(|| format!("KTX2 size {size:?} is too large"))?;
    if data.len() != texel_count * texel_bytes {
        return Err(format!(
            "{} bytes of texels, expected {}",
            data.len(),
            texel_count * texel_bytes
        ));
    }
    let mut texels = Vec::with_capacity(texel_count);
    for chunk in data.chunks_exact(texel_bytes) {
        let mut texel = Vec4::ZERO;
        for c in 0..channels {
            let value = if format.bytes_per_channel() == 1 {
                chunk[c] as f32 / 255.0
            } else if format.bytes_per_channel() == 4 {
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

    fn small_file(format: TexelFormat) -> (Vec<u8>, Vec<Vec4>) {
        let texels: Vec<Vec4> = (0..2 * 3 * 4)
            .map(|i| Vec4::new(i as f32, -(i as f32), 0.5, 1.0))
            .collect();
        let bytes = ktx2_bytes(format, 2, 3, 4, &texel_bytes(&texels, format)).expect("ktx2");
        (bytes, texels)
    }

    #[test]
    fn our_reader_reads_what_we_write() {
        for format in [TexelFormat::Rgba32Float, TexelFormat::R16Float] {
            let (bytes, texels) = small_file(format);
            let texture = read_texture(&bytes, format, [2, 3, 4]).expect("reads");
            for (read, written) in texture.texels.iter().zip(&texels) {
                for c in 0..format.channels() {
                    assert_eq!(read[c], written[c]);
                }
            }
        }
    }

    #[test]
    fn hostile_headers_are_named_errors() {
        let format = TexelFormat::Rgba32Float;
        let (bytes, _) = small_file(format);
        let set = |at: usize, value: u32| {
            let mut b = bytes.clone();
            b[at..at + 4].copy_from_slice(&value.to_le_bytes());
            b
        };
        // A descriptor whose texel-block dimension bytes are 255 (panics inside the ktx2
        // crate's parser): vkFormat decides, so the file still reads.
        let dfd_offset = u32::from_le_bytes(bytes[48..52].try_into().expect("4")) as usize;
        let mut dimension_255 = bytes.clone();
        dimension_255[dfd_offset + 4 + 12..dfd_offset + 4 + 16].fill(255);
        assert!(read_texture(&dimension_255, format, [2, 3, 4]).is_ok());
        // 65536 x 65536 x 2^28 texels: the byte count must not wrap to pass the check.
        let mut huge = set(20, 65536);
        huge[24..28].copy_from_slice(&65536u32.to_le_bytes());
        huge[28..32].copy_from_slice(&(1u32 << 28).to_le_bytes());
        let error = read_texture(&huge, format, [65536, 65536, 1 << 28]).expect_err("huge");
        assert!(error.contains("too large"), "{error}");
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (bytes[..50].to_vec(), "shorter than a KTX2 header"),
            (set(0, 0), "identifier"),
            (set(12, 97), "vkFormat 97"),
            (set(16, 2), "typeSize"),
            (set(40, 5), "5 levels"),
            (set(44, 1), "supercompression 1"),
            (set(48, u32::MAX), "outside the file"),
            (set(52, u32::MAX - 2), "outside the file"),
            (set(HEADER_BYTES, u32::MAX), "runs past the end"),
            (set(HEADER_BYTES + 8, 7), "bytes of texels"),
        ];
        for (case, expected) in cases {
            let error = read_texture(&case, format, [2, 3, 4]).expect_err(expected);
            assert!(error.contains(expected), "{expected}: {error}");
        }
        let mut nan = bytes.clone();
        let level_offset = u32::from_le_bytes(bytes[80..84].try_into().expect("4")) as usize;
        nan[level_offset..level_offset + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        let error = read_texture(&nan, format, [2, 3, 4]).expect_err("NaN");
        assert!(error.contains("not finite"), "{error}");
    }
}
