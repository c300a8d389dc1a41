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

use glam::DVec2;
use serde::{Deserialize, Serialize};

/// The largest side a painted map may have (texels): 4096² RGBA8 is 64 MiB.
pub const MAX_ROOT_MAP_SIDE: u32 = 4096;

/// The side of the maps painting starts on when there are none yet.
pub const DEFAULT_ROOT_MAP_SIDE: u32 = 256;

/// One of the painted maps (its channel of the RGBA8 texture).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RootMapChannel {
    /// The share of strands that grow (r).
    Density,
    /// The share of its length a strand keeps (g).
    Length,
    /// The share of the clump op's pull a strand feels (b).
    Clump,
}

impl RootMapChannel {
    pub const ALL: [RootMapChannel; 3] = [Self::Density, Self::Length, Self::Clump];

    pub fn index(self) -> usize {
        match self {
            Self::Density => 0,
            Self::Length => 1,
            Self::Clump => 2,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Self::Density => "Density",
            Self::Length => "Length",
            Self::Clump => "Clump",
        }
    }

    /// Parses `density`, `length` or `clump`.
    pub fn parse(text: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|c| c.label().eq_ignore_ascii_case(text.trim()))
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
}

/// The painted maps: an RGBA8 texture in root-uv space, or none (1 everywhere).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "StoredRootMaps", into = "StoredRootMaps")]
pub struct RootMaps {
    width: u32,
    height: u32,
    texels: Vec<[u8; 4]>,
}

/// How a project file stores the maps: the texels as base64 (a JSON array of numbers would
/// be four times the size).
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StoredRootMaps {
    width: u32,
    height: u32,
    rgba8_base64: String,
}

impl TryFrom<StoredRootMaps> for RootMaps {
    type Error = RootMapError;

    fn try_from(stored: StoredRootMaps) -> Result<Self, Self::Error> {
        use base64::Engine as _;
        if stored.width == 0 && stored.height == 0 && stored.rgba8_base64.is_empty() {
            return Ok(Self::default());
        }
        check_size(stored.width, stored.height)?;
        // Checked before decoding: a hostile file cannot make us decode more than the size says.
        let expected = stored.width as usize * stored.height as usize * 4;
        if stored.rgba8_base64.len() > expected.div_ceil(3) * 4 + 4 {
            return Err(RootMapError::WrongLength {
                width: stored.width,
                height: stored.height,
                bytes: stored.rgba8_base64.len() / 4 * 3,
                expected,
            });
        }
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(stored.rgba8_base64.as_bytes())
            .map_err(|e| RootMapError::Base64(e.to_string()))?;
        Self::from_rgba8(stored.width, stored.height, &bytes)
    }
}

impl From<RootMaps> for StoredRootMaps {
    fn from(maps: RootMaps) -> Self {
        use base64::Engine as _;
        Self {
            width: maps.width,
            height: maps.height,
            rgba8_base64: base64::engine::general_purpose::STANDARD.encode(maps.rgba8()),
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
        })
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
        check_size(width, height)?;
        if values.len() != width as usize * height as usize {
            return Err(RootMapError::WrongLength {
                width,
                height,
                bytes: values.len(),
                expected: width as usize * height as usize,
            });
        }
        if self.is_empty() {
            *self = Self::blank(width, height)?;
        }
        let (w, h) = (self.width, self.height);
        let image = |x: u32, y: u32| {
            let v = values[(y * width + x) as usize];
            if v.is_nan() { 0.0 } else { v }
        };
        for y in 0..h {
            for x in 0..w {
                let uv = DVec2::new((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                let value = bilinear(width, height, uv, image);
                self.texels[(y * w + x) as usize][channel.index()] = unit_to_byte(value);
            }
        }
        Ok(())
    }

    /// One map as values in `[0, 1]`, row-major (empty when nothing is painted).
    pub fn channel_values(&self, channel: RootMapChannel) -> Vec<f64> {
        self.texels
            .iter()
            .map(|t| t[channel.index()] as f64 / 255.0)
            .collect()
    }

    /// Forgets one map (1 everywhere); with none of the three left painted, the texture goes.
    pub fn clear_channel(&mut self, channel: RootMapChannel) {
        for texel in &mut self.texels {
            texel[channel.index()] = 255;
        }
        if self.texels.iter().all(|t| t[..3] == [255, 255, 255]) {
            *self = Self::default();
        }
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
}
