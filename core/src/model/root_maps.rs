//! Maps painted over the scalp in root-uv space: where hair grows (density), how much of its
//! bundle's length it keeps (length) and how strongly it clumps (clump). One RGBA8 texture —
//! r density, g length, b clump, a unused (255) — sampled at each strand's root uv (the hair
//! mesh's uv layout, which an import takes from the glTF's `TEXCOORD_0`), so a mask painted
//! on the scalp in another tool lines up. Texel row 0 is `v = 0`, the top row of an image,
//! as glTF's uv convention has it.
//!
//! Every value is a share in `[0, 1]`: a strand of rank `r = (j + ½)/N` (its place in its
//! bundle's progressive sample set) grows where `r < density`, keeps `length` of the length
//! it would have, and feels `clump` of its styling group's clump and sub-clump pulls. Empty
//! maps (the default) are 1 everywhere: nothing changes. The runtime bundle carries them as
//! `root_maps.HASH.ktx2` (`docs/runtime-format.md`, "Painted maps").
//!
//! The colour map is a second RGBA8 texture of the same size (present only once painted):
//! rgb the colour a thick mass of the hair shows there (sRGB-encoded, as a colour picker and
//! an image give it), a the share of it the strand takes over the material's own colour
//! (0: none; see [`crate::light::material::Fibre::painted`]). It colours whole strands by
//! their root, as dyed or greying hair is; the root-to-tip darkening and per-strand variation
//! of the material still apply. The runtime bundle carries it as `colour_map.HASH.ktx2`.

use glam::DVec2;
use serde::{Deserialize, Serialize};

/// The largest side a painted map may have (texels): 4096² RGBA8 is 64 MiB.
pub const MAX_ROOT_MAP_SIDE: u32 = 4096;

/// The side of the maps painting starts on when there are none yet.
pub const DEFAULT_ROOT_MAP_SIDE: u32 = 256;

/// One of the painted maps: a channel of the RGBA8 texture, or the colour map (a texture of
/// its own).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RootMapChannel {
    /// The share of strands that grow (r).
    Density,
    /// The share of its length a strand keeps (g).
    Length,
    /// The share of the clump op's pull a strand feels (b).
    Clump,
    /// The strand's colour and how much of it it takes (the colour map).
    Colour,
}

impl RootMapChannel {
    /// The three grey maps of the RGBA8 texture.
    pub const ALL: [RootMapChannel; 3] = [Self::Density, Self::Length, Self::Clump];
    /// Every map a brush paints.
    pub const PAINTABLE: [RootMapChannel; 4] =
        [Self::Density, Self::Length, Self::Clump, Self::Colour];

    /// The grey map's channel of the RGBA8 texture (`None` for the colour map).
    pub fn grey_index(self) -> Option<usize> {
        match self {
            Self::Density => Some(0),
            Self::Length => Some(1),
            Self::Clump => Some(2),
            Self::Colour => None,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Self::Density => "Density",
            Self::Length => "Length",
            Self::Clump => "Clump",
            Self::Colour => "Colour",
        }
    }

    /// Parses `density`, `length`, `clump` or `colour` (`color` too).
    pub fn parse(text: &str) -> Option<Self> {
        let text = text.trim();
        if text.eq_ignore_ascii_case("color") {
            return Some(Self::Colour);
        }
        Self::PAINTABLE
            .into_iter()
            .find(|c| c.label().eq_ignore_ascii_case(text))
    }
}

/// The colour map at one root uv: the colour a thick mass of the hair shows (linear RGB) and
/// the share of it the strand takes over the material's own (0: none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaintedColour {
    pub rgb_linear: [f64; 3],
    pub weight: f64,
}

impl PaintedColour {
    pub const NONE: PaintedColour = PaintedColour {
        rgb_linear: [0.0; 3],
        weight: 0.0,
    };

    /// Packed as the renderers' per-root buffer holds it: sRGB-encoded rgb in bytes 0-2, the
    /// weight in byte 3 (WGSL's `unpack4x8unorm` order). Mirror of `root_paint` in
    /// `shaders/preview_hair.wgsl`, which decodes it.
    pub fn pack(&self) -> u32 {
        let [r, g, b] = self.rgb_linear.map(|c| unit_to_byte(linear_to_srgb(c)));
        u32::from_le_bytes([r, g, b, unit_to_byte(self.weight)])
    }

    /// What [`Self::pack`] keeps of a colour (8 bits per channel).
    pub fn unpack(packed: u32) -> Self {
        let [r, g, b, a] = packed.to_le_bytes();
        PaintedColour {
            rgb_linear: [r, g, b].map(|c| srgb_to_linear(c as f64 / 255.0)),
            weight: a as f64 / 255.0,
        }
    }
}

/// The sRGB transfer function's inverse (IEC 61966-2-1): an encoded value to linear.
pub fn srgb_to_linear(encoded: f64) -> f64 {
    if encoded <= 0.04045 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// [`srgb_to_linear`] of every byte / 255, computed once: the colour map's texels are decoded
/// per root, four texels of three channels each, and `powf` dominated that.
fn srgb_byte_table() -> &'static [f64; 256] {
    static TABLE: std::sync::OnceLock<[f64; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|b| srgb_to_linear(b as f64 / 255.0)))
}

/// The sRGB transfer function: linear to an encoded value (NaN and out-of-range clamped).
pub fn linear_to_srgb(linear: f64) -> f64 {
    let linear = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    if linear <= 0.0031308 {
        linear * 12.92
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// The maps' values at one root uv.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootMapValues {
    pub density: f64,
    pub length: f64,
    pub clump: f64,
}

impl RootMapValues {
    pub const NONE: RootMapValues = RootMapValues {
        density: 1.0,
        length: 1.0,
        clump: 1.0,
    };

    /// The share of its length a strand of rank `rank` keeps under these values: 0 where
    /// the density map does not grow it (a NaN rank grows nothing), else the length map's.
    pub fn length_scale(&self, rank: f64) -> f64 {
        if rank.partial_cmp(&self.density) != Some(std::cmp::Ordering::Less) {
            return 0.0;
        }
        self.length
    }
}

/// Why painted maps were refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RootMapError {
    #[error(
        "a painted map of {width} × {height} texels is larger than {MAX_ROOT_MAP_SIDE} on a side"
    )]
    TooLarge { width: u32, height: u32 },
    #[error("a painted map of {width} × {height} texels has a zero side")]
    Empty { width: u32, height: u32 },
    #[error("a painted map of {width} × {height} texels holds {bytes} bytes, not {expected}")]
    WrongLength {
        width: u32,
        height: u32,
        bytes: usize,
        expected: usize,
    },
    #[error("painted map texels are not valid base64: {0}")]
    Base64(String),
    #[error("the colour map is painted from a colour image, not a grey one")]
    NotGrey,
}

/// The painted maps: an RGBA8 texture in root-uv space, or none (1 everywhere), and the
/// colour map of the same size, or none (no colour painted).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "StoredRootMaps", into = "StoredRootMaps")]
pub struct RootMaps {
    width: u32,
    height: u32,
    texels: Vec<[u8; 4]>,
    /// Empty, or one per texel: sRGB colour and weight. Present only with `texels`.
    colour: Vec<[u8; 4]>,
}

/// How a project file stores the maps: the texels as base64 (a JSON array of numbers would
/// be four times the size).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StoredRootMaps {
    width: u32,
    height: u32,
    rgba8_base64: String,
    /// The colour map (absent in files from before it, and while none is painted).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    colour_rgba8_base64: Option<String>,
}

/// Decodes one stored texture of `width × height` RGBA8 texels, checking the text's length
/// before decoding: a hostile file cannot make us decode more than the size says.
fn decode_texels(width: u32, height: u32, text: &str) -> Result<Vec<u8>, RootMapError> {
    use base64::Engine as _;
    let expected = width as usize * height as usize * 4;
    if text.len() > expected.div_ceil(3) * 4 + 4 {
        return Err(RootMapError::WrongLength {
            width,
            height,
            bytes: text.len() / 4 * 3,
            expected,
        });
    }
    base64::engine::general_purpose::STANDARD
        .decode(text.as_bytes())
        .map_err(|e| RootMapError::Base64(e.to_string()))
}

impl TryFrom<StoredRootMaps> for RootMaps {
    type Error = RootMapError;

    fn try_from(stored: StoredRootMaps) -> Result<Self, Self::Error> {
        if stored.width == 0
            && stored.height == 0
            && stored.rgba8_base64.is_empty()
            && stored.colour_rgba8_base64.is_none()
        {
            return Ok(Self::default());
        }
        check_size(stored.width, stored.height)?;
        let bytes = decode_texels(stored.width, stored.height, &stored.rgba8_base64)?;
        let mut maps = Self::from_rgba8(stored.width, stored.height, &bytes)?;
        if let Some(text) = &stored.colour_rgba8_base64 {
            let bytes = decode_texels(stored.width, stored.height, text)?;
            maps.set_colour_rgba8(&bytes)?;
        }
        Ok(maps)
    }
}

impl From<RootMaps> for StoredRootMaps {
    fn from(maps: RootMaps) -> Self {
        use base64::Engine as _;
        let engine = base64::engine::general_purpose::STANDARD;
        Self {
            width: maps.width,
            height: maps.height,
            rgba8_base64: engine.encode(maps.rgba8()),
            colour_rgba8_base64: maps
                .has_colour()
                .then(|| engine.encode(maps.colour_rgba8())),
        }
    }
}

/// Refuses a side of 0 or over [`MAX_ROOT_MAP_SIDE`] (without allocating anything).
pub fn check_size(width: u32, height: u32) -> Result<(), RootMapError> {
    if width > MAX_ROOT_MAP_SIDE || height > MAX_ROOT_MAP_SIDE {
        return Err(RootMapError::TooLarge { width, height });
    }
    if width == 0 || height == 0 {
        return Err(RootMapError::Empty { width, height });
    }
    Ok(())
}

fn unit_to_byte(value: f64) -> u8 {
    if value.is_nan() {
        return 0;
    }
    (value.clamp(0.0, 1.0) * 255.0).round() as u8
}

impl RootMaps {
    /// Maps of `width × height` texels, 1 everywhere (nothing painted yet).
    pub fn blank(width: u32, height: u32) -> Result<Self, RootMapError> {
        check_size(width, height)?;
        Ok(Self {
            width,
            height,
            texels: vec![[255; 4]; width as usize * height as usize],
            colour: Vec::new(),
        })
    }

    /// Maps from RGBA8 bytes (row-major, row 0 at `v = 0`).
    pub fn from_rgba8(width: u32, height: u32, bytes: &[u8]) -> Result<Self, RootMapError> {
        check_size(width, height)?;
        let expected = width as usize * height as usize * 4;
        if bytes.len() != expected {
            return Err(RootMapError::WrongLength {
                width,
                height,
                bytes: bytes.len(),
                expected,
            });
        }
        Ok(Self {
            width,
            height,
            texels: bytes
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
            colour: Vec::new(),
        })
    }

    /// Checks an image of `width × height` holding `values` values, and makes blank maps of
    /// its size where nothing is painted yet (an image onto painted maps is resampled).
    fn ready_for_image(
        &mut self,
        width: u32,
        height: u32,
        values: usize,
    ) -> Result<(), RootMapError> {
        check_size(width, height)?;
        if values != width as usize * height as usize {
            return Err(RootMapError::WrongLength {
                width,
                height,
                bytes: values,
                expected: width as usize * height as usize,
            });
        }
        if self.is_empty() {
            *self = Self::blank(width, height)?;
        }
        Ok(())
    }

    /// Sets the colour map from RGBA8 bytes of these maps' size (sRGB rgb, weight a).
    pub fn set_colour_rgba8(&mut self, bytes: &[u8]) -> Result<(), RootMapError> {
        let expected = self.texels.len() * 4;
        if self.is_empty() || bytes.len() != expected {
            return Err(RootMapError::WrongLength {
                width: self.width,
                height: self.height,
                bytes: bytes.len(),
                expected,
            });
        }
        self.colour = bytes
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        Ok(())
    }

    /// Every texel of both textures: the grey maps', then the colour map's (none when none is
    /// painted). Index `i` of this order is what [`Self::stacked_texel`] reads.
    pub fn stacked_texels(&self) -> impl Iterator<Item = &[u8; 4]> {
        self.texels.iter().chain(&self.colour)
    }

    /// Texel `index` of [`Self::stacked_texels`].
    pub fn stacked_texel(&self, index: usize) -> Option<&[u8; 4]> {
        match index.checked_sub(self.texels.len()) {
            None => self.texels.get(index),
            Some(i) => self.colour.get(i),
        }
    }

    /// Texel `index` of [`Self::stacked_texels`], to write.
    pub fn stacked_texel_mut(&mut self, index: usize) -> Option<&mut [u8; 4]> {
        match index.checked_sub(self.texels.len()) {
            None => self.texels.get_mut(index),
            Some(i) => self.colour.get_mut(i),
        }
    }

    /// Whether a colour map is painted.
    pub fn has_colour(&self) -> bool {
        !self.colour.is_empty()
    }

    /// The colour map's texels (empty when none is painted).
    pub fn colour_texels(&self) -> &[[u8; 4]] {
        &self.colour
    }

    /// The colour map's texels, made (no colour: weight 0) if there were none yet; the maps
    /// must not be empty (paint on [`Self::blank`] maps).
    pub fn colour_texels_mut(&mut self) -> &mut [[u8; 4]] {
        if self.colour.is_empty() {
            self.colour = vec![[0; 4]; self.texels.len()];
        }
        &mut self.colour
    }

    /// The colour map's bytes (what the runtime bundle's `colour_map` KTX2 file holds).
    pub fn colour_rgba8(&self) -> Vec<u8> {
        self.colour.iter().flatten().copied().collect()
    }

    /// Forgets the colour map; with no grey map painted either, the maps go.
    pub fn clear_colour(&mut self) {
        self.colour = Vec::new();
        self.drop_if_unpainted();
    }

    fn drop_if_unpainted(&mut self) {
        if self.colour.is_empty() && self.texels.iter().all(|t| t[..3] == [255, 255, 255]) {
            *self = Self::default();
        }
    }

    /// Whether `channel` holds anything painted.
    pub fn is_painted(&self, channel: RootMapChannel) -> bool {
        match channel.grey_index() {
            Some(c) => self.texels.iter().any(|t| t[c] != 255),
            None => self.colour.iter().any(|t| t[3] != 0),
        }
    }

    /// The colour map at `uv` (the renderers' per-root colour, [`crate::runtime::hair::
    /// RuntimeHair::root_paint`]): bilinear between texel centres as [`Self::sample`], of
    /// the weight and of the linear colour (each texel decoded from sRGB first, as a GPU's
    /// sRGB texture does) weighted by each texel's weight — premultiplied, so the rim of a
    /// stroke is its colour at less weight, never a blend with the colour of texels that
    /// hold none.
    pub fn sample_colour(&self, uv: DVec2) -> PaintedColour {
        if self.colour.is_empty() {
            return PaintedColour::NONE;
        }
        let decoded = srgb_byte_table();
        let texel = |x: u32, y: u32| self.colour[(y * self.width + x) as usize];
        let weight = bilinear(self.width, self.height, uv, |x, y| {
            texel(x, y)[3] as f64 / 255.0
        });
        if weight <= 0.0 {
            return PaintedColour::NONE;
        }
        let premultiplied = |c: usize| {
            bilinear(self.width, self.height, uv, |x, y| {
                let t = texel(x, y);
                decoded[t[c] as usize] * (t[3] as f64 / 255.0)
            })
        };
        PaintedColour {
            rgb_linear: [0, 1, 2].map(|c| premultiplied(c) / weight),
            weight,
        }
    }

    /// Replaces the colour map by an image of `width × height` sRGB colours and weights in
    /// `[0, 1]` (row 0 at `v = 0`), resampled bilinearly to these maps' size; maps with
    /// nothing painted take the image's size. NaN counts as 0.
    pub fn set_colour_from_image(
        &mut self,
        width: u32,
        height: u32,
        values: &[[f64; 4]],
    ) -> Result<(), RootMapError> {
        self.ready_for_image(width, height, values.len())?;
        let (w, h) = (self.width, self.height);
        let colour = self.colour_texels_mut();
        for y in 0..h {
            for x in 0..w {
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                let texel = &mut colour[(y * w + x) as usize];
                for (c, byte) in texel.iter_mut().enumerate() {
                    let value = bilinear(width, height, uv, |ix, iy| {
                        let v = values[(iy * width + ix) as usize][c];
                        if v.is_nan() { 0.0 } else { v }
                    });
                    *byte = unit_to_byte(value);
                }
            }
        }
        // A transparent image paints no colour: no colour map is left behind.
        if !self.is_painted(RootMapChannel::Colour) {
            self.clear_colour();
        }
        Ok(())
    }

    /// Whether nothing is painted (no texture: 1 everywhere).
    pub fn is_empty(&self) -> bool {
        self.texels.is_empty()
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn texels(&self) -> &[[u8; 4]] {
        &self.texels
    }

    pub fn texels_mut(&mut self) -> &mut [[u8; 4]] {
        &mut self.texels
    }

    /// The texels as bytes (what the runtime bundle's KTX2 file holds).
    pub fn rgba8(&self) -> Vec<u8> {
        self.texels.iter().flatten().copied().collect()
    }

    /// Replaces one map by a grey image of `width × height` values in `[0, 1]` (row 0 at
    /// `v = 0`), resampled bilinearly to these maps' size; maps with nothing painted take
    /// the image's size. NaN counts as 0.
    pub fn set_channel_from_image(
        &mut self,
        channel: RootMapChannel,
        width: u32,
        height: u32,
        values: &[f64],
    ) -> Result<(), RootMapError> {
        let Some(index) = channel.grey_index() else {
            return Err(RootMapError::NotGrey);
        };
        self.ready_for_image(width, height, values.len())?;
        let (w, h) = (self.width, self.height);
        let image = |x: u32, y: u32| {
            let v = values[(y * width + x) as usize];
            if v.is_nan() { 0.0 } else { v }
        };
        for y in 0..h {
            for x in 0..w {
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                let value = bilinear(width, height, uv, image);
                self.texels[(y * w + x) as usize][index] = unit_to_byte(value);
            }
        }
        Ok(())
    }

    /// One map as values in `[0, 1]`, row-major (empty when nothing is painted); the colour
    /// map's weights for [`RootMapChannel::Colour`].
    pub fn channel_values(&self, channel: RootMapChannel) -> Vec<f64> {
        match channel.grey_index() {
            Some(c) => self.texels.iter().map(|t| t[c] as f64 / 255.0).collect(),
            None => self.colour.iter().map(|t| t[3] as f64 / 255.0).collect(),
        }
    }

    /// Forgets one map (1 everywhere, or no colour); with nothing left painted, the
    /// texture goes.
    pub fn clear_channel(&mut self, channel: RootMapChannel) {
        let Some(c) = channel.grey_index() else {
            self.clear_colour();
            return;
        };
        for texel in &mut self.texels {
            texel[c] = 255;
        }
        self.drop_if_unpainted();
    }

    /// The maps at `uv` (mirror of `root_map_values` in `shaders/shared/strand_vertex.wgsl`):
    /// bilinear between texel centres (texel `i` centred at `(i + ½)/W`), clamped at the
    /// edges, from the bytes / 255. A NaN uv reads texel (0, 0).
    pub fn sample(&self, uv: DVec2) -> RootMapValues {
        if self.is_empty() {
            return RootMapValues::NONE;
        }
        let at = |c: usize| {
            bilinear(self.width, self.height, uv, |x, y| {
                self.texels[(y * self.width + x) as usize][c] as f64 / 255.0
            })
        };
        RootMapValues {
            density: at(0),
            length: at(1),
            clump: at(2),
        }
    }
}

/// Bilinear read of a `width × height` grid at `uv` (texel centres at `(i + ½)/size`,
/// clamped to the edge; NaN reads texel 0).
fn bilinear(width: u32, height: u32, uv: DVec2, texel: impl Fn(u32, u32) -> f64) -> f64 {
    let axis = |c: f64, size: u32| {
        let x = (c * size as f64 - 0.5).clamp(0.0, (size - 1) as f64);
        let x = if x.is_nan() { 0.0 } else { x };
        let i0 = (x.floor() as u32).min(size - 1);
        let i1 = (i0 + 1).min(size - 1);
        (i0, i1, x - i0 as f64)
    };
    let (x0, x1, fx) = axis(uv.x, width);
    let (y0, y1, fy) = axis(uv.y, height);
    let row = |y: u32| texel(x0, y) + (texel(x1, y) - texel(x0, y)) * fx;
    row(y0) + (row(y1) - row(y0)) * fy
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_maps_change_nothing() {
        let maps = RootMaps::default();
        assert_eq!(maps.sample(DVec2::new(0.3, 0.7)), RootMapValues::NONE);
        // Every rank of a progressive set is below 1: every strand grows at full length.
        assert_eq!(RootMapValues::NONE.length_scale(0.999), 1.0);
        assert_eq!(RootMapValues::NONE.length_scale(f64::NAN), 0.0);
    }

    #[test]
    fn sampling_is_bilinear_between_texel_centres_and_clamped() {
        let mut maps = RootMaps::blank(4, 2).expect("test value");
        // Density: 0 in column 0, 1 elsewhere.
        for y in 0..2 {
            maps.texels_mut()[y * 4][0] = 0;
        }
        assert_eq!(maps.sample(DVec2::new(0.125, 0.5)).density, 0.0);
        assert_eq!(maps.sample(DVec2::new(-3.0, 0.5)).density, 0.0, "clamped");
        assert!((maps.sample(DVec2::new(0.25, 0.5)).density - 0.5).abs() < 1e-12);
        assert_eq!(maps.sample(DVec2::new(0.375, 9.0)).density, 1.0);
        assert_eq!(maps.sample(DVec2::new(f64::NAN, 0.5)).density, 0.0);
        assert_eq!(maps.sample(DVec2::new(0.9, 0.1)).length, 1.0);
    }

    #[test]
    fn density_decides_by_rank_and_length_scales() {
        let values = RootMapValues {
            density: 0.5,
            length: 0.25,
            clump: 1.0,
        };
        assert_eq!(values.length_scale(0.49), 0.25);
        assert_eq!(values.length_scale(0.5), 0.0);
        assert_eq!(values.length_scale(0.9), 0.0);
    }

    #[test]
    fn project_text_round_trips_and_hostile_text_is_refused() {
        let mut maps = RootMaps::blank(3, 2).expect("test value");
        maps.texels_mut()[4] = [10, 20, 30, 255];
        let text = serde_json::to_string(&maps).expect("test value");
        assert!(text.contains("rgba8_base64"), "{text}");
        assert_eq!(
            serde_json::from_str::<RootMaps>(&text).expect("test value"),
            maps
        );
        let empty = serde_json::to_string(&RootMaps::default()).expect("test value");
        assert_eq!(
            serde_json::from_str::<RootMaps>(&empty).expect("test value"),
            RootMaps::default()
        );
        for (text, names) in [
            (
                r#"{"width":5000,"height":2,"rgba8_base64":""}"#,
                "larger than 4096",
            ),
            (r#"{"width":0,"height":2,"rgba8_base64":""}"#, "zero side"),
            (r#"{"width":2,"height":2,"rgba8_base64":"AAAA"}"#, "not 16"),
            (
                r#"{"width":1,"height":1,"rgba8_base64":"!!!!"}"#,
                "not valid base64",
            ),
            (
                r#"{"width":1,"height":1,"rgba8_base64":"AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA"}"#,
                "not 4",
            ),
        ] {
            let error = serde_json::from_str::<RootMaps>(text)
                .expect_err("refused")
                .to_string();
            assert!(error.contains(names), "{text}: {error}");
        }
    }

    #[test]
    fn an_image_fills_one_channel_resampled_and_clearing_forgets_it() {
        let mut maps = RootMaps::default();
        // 2 × 1: black on the left, white on the right.
        maps.set_channel_from_image(RootMapChannel::Length, 2, 1, &[0.0, 1.0])
            .expect("test value");
        assert_eq!((maps.width(), maps.height()), (2, 1));
        assert_eq!(maps.texels(), &[[255, 0, 255, 255], [255, 255, 255, 255]]);
        // Onto 4 × 1 maps the image is resampled.
        let mut wide = RootMaps::blank(4, 1).expect("test value");
        wide.set_channel_from_image(RootMapChannel::Clump, 2, 1, &[0.0, f64::NAN])
            .expect("test value");
        assert!(wide.texels().iter().all(|t| t[2] == 0));
        wide.set_channel_from_image(RootMapChannel::Clump, 2, 1, &[0.0, 1.0])
            .expect("test value");
        let clump: Vec<u8> = wide.texels().iter().map(|t| t[2]).collect();
        assert_eq!(clump, vec![0, 64, 191, 255]);
        assert!(
            wide.set_channel_from_image(RootMapChannel::Clump, 2, 2, &[0.0])
                .is_err()
        );
        maps.clear_channel(RootMapChannel::Length);
        assert!(maps.is_empty(), "nothing painted is left");
        wide.clear_channel(RootMapChannel::Density);
        assert!(!wide.is_empty(), "the clump map is still painted");
    }

    #[test]
    fn the_colour_map_samples_in_linear_light_packs_and_round_trips() {
        let mut maps = RootMaps::blank(2, 1).expect("test value");
        assert_eq!(maps.sample_colour(DVec2::splat(0.5)), PaintedColour::NONE);
        assert!(!maps.is_painted(RootMapChannel::Colour));
        maps.colour_texels_mut()[0] = [255, 0, 0, 255];
        maps.colour_texels_mut()[1] = [0, 0, 0, 0];
        assert!(maps.is_painted(RootMapChannel::Colour));
        // Half-way between red and no colour: red at half the weight (premultiplied: never
        // a blend with the black a texel without colour holds).
        let half = maps.sample_colour(DVec2::new(0.5, 0.5));
        assert!((half.rgb_linear[0] - 1.0).abs() < 1e-12, "{half:?}");
        assert!((half.weight - 0.5).abs() < 1e-12, "{half:?}");
        // Half-way between two colours at full weight: their linear mean (not the sRGB
        // bytes' mean, which would be 0.214 linear).
        maps.colour_texels_mut()[1] = [0, 0, 0, 255];
        let half = maps.sample_colour(DVec2::new(0.5, 0.5));
        assert!((half.rgb_linear[0] - 0.5).abs() < 1e-12, "{half:?}");
        maps.colour_texels_mut()[1] = [0, 0, 0, 0];
        // Packing keeps 8 bits of sRGB: within half a step.
        for colour in [
            PaintedColour {
                rgb_linear: [0.5, 0.02, 0.9],
                weight: 0.25,
            },
            PaintedColour {
                rgb_linear: [f64::NAN, -1.0, 7.0],
                weight: f64::NAN,
            },
        ] {
            let back = PaintedColour::unpack(colour.pack());
            for c in 0..3 {
                let expected = linear_to_srgb(colour.rgb_linear[c]);
                assert!(
                    (linear_to_srgb(back.rgb_linear[c]) - expected).abs() <= 0.5 / 255.0 + 1e-12,
                    "{colour:?} -> {back:?}"
                );
            }
            assert!(back.weight.is_finite());
        }
        // The project text carries the colour map; text from before it has none.
        let text = serde_json::to_string(&maps).expect("test value");
        assert!(text.contains("colour_rgba8_base64"), "{text}");
        assert_eq!(
            serde_json::from_str::<RootMaps>(&text).expect("test value"),
            maps
        );
        let old = r#"{"width":1,"height":1,"rgba8_base64":"AAAA/w=="}"#;
        assert!(
            !serde_json::from_str::<RootMaps>(old)
                .expect("test value")
                .has_colour()
        );
        let wrong =
            r#"{"width":1,"height":1,"rgba8_base64":"AAAA/w==","colour_rgba8_base64":"AAAAAAAA"}"#;
        let error = serde_json::from_str::<RootMaps>(wrong)
            .expect_err("refused")
            .to_string();
        assert!(error.contains("not 4"), "{error}");
        // Clearing the colour leaves the grey maps; with nothing else painted the maps go.
        let mut density = maps.clone();
        density.texels_mut()[0][0] = 0;
        density.clear_channel(RootMapChannel::Colour);
        assert!(!density.has_colour() && !density.is_empty());
        maps.clear_channel(RootMapChannel::Colour);
        assert!(maps.is_empty());
        // Clearing a grey map keeps a painted colour.
        let mut colour_only = RootMaps::blank(2, 1).expect("test value");
        colour_only.colour_texels_mut()[0] = [1, 2, 3, 4];
        colour_only.clear_channel(RootMapChannel::Density);
        assert!(colour_only.has_colour());
        assert_eq!(RootMapChannel::parse("Color"), Some(RootMapChannel::Colour));
    }

    #[test]
    fn a_colour_image_fills_the_colour_map_resampled() {
        let mut maps = RootMaps::default();
        maps.set_colour_from_image(2, 1, &[[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, f64::NAN]])
            .expect("test value");
        assert_eq!((maps.width(), maps.height()), (2, 1));
        assert_eq!(maps.colour_texels(), &[[255, 0, 0, 255], [0, 0, 255, 0]]);
        assert!(
            maps.texels().iter().all(|t| *t == [255; 4]),
            "grey maps unpainted"
        );
        let error = maps
            .set_channel_from_image(RootMapChannel::Colour, 1, 1, &[0.5])
            .expect_err("a colour map is not grey");
        assert_eq!(error, RootMapError::NotGrey);
        // A transparent image leaves no colour map behind.
        maps.set_colour_from_image(1, 1, &[[0.5, 0.5, 0.5, 0.0]])
            .expect("test value");
        assert!(maps.is_empty(), "nothing painted is left");
    }
}
