//! The fur volume sampled into textures (seed 002 §2.2, §2.4): shell layers through a tall
//! Gaussian filter, one fin texture composited from a slab of the volume seen from the side,
//! and the shell levels of detail made by compositing pairs of shells.
//!
//! Every texel stores linear RGBA8: RGB is the strands' brightness (the material's colour and
//! the per-vertex colour multiply it at draw time), A their coverage. Beside each shell layer a
//! direction layer stores the strands' mean tangent (`0.5 + 0.5·t`, in the patch frame: x along
//! the direction field, y across it, z out of the skin), so that the Marschner model can shade
//! shells with the strands' own tangents rather than the single per-vertex vector the seed
//! shares between direction and offset (its §2.4 names this as its limit).

use glam::DVec3;

use crate::fur::volume::{FurVolume, wrap};

/// Shell texture parameters: seed 002 samples 16 layers of 128².
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShellParams {
    pub layer_count: u32,
    pub resolution: u32,
    /// Seed 002 makes the innermost layer the skin, fully opaque. Over a hair mesh the body
    /// is drawn as it is and the innermost shell holds only the strands at the roots.
    pub opaque_skin: bool,
}

impl Default for ShellParams {
    fn default() -> Self {
        Self {
            layer_count: 16,
            resolution: 128,
            opaque_skin: true,
        }
    }
}

/// The fin texture's size in seed 002: 512 × 64.
pub const FIN_WIDTH: u32 = 512;
pub const FIN_HEIGHT: u32 = 64;
/// The most shell layers (the seed's dice use 32; 64 leaves room for long fur).
pub const MAX_SHELL_LAYERS: u32 = 64;
/// The largest shell texture side.
pub const MAX_SHELL_RESOLUTION: u32 = 1024;
/// The most texels of all level-0 shells together (64 layers of 512², 16 of 1024²): bounds
/// the sampler's memory (40 bytes a texel while sampling).
pub const MAX_SHELL_TEXELS: u64 = 1 << 24;
/// The most strand samples the samplers take (their time), whatever the volume.
const MAX_STRAND_SAMPLES: f64 = 2e7;

#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FurTextureError {
    #[error("fur shells: layer_count is {0}, it must be a power of two in [2, 64]")]
    LayerCount(u32),
    #[error("fur shells: resolution is {0}, it must be in [8, 1024]")]
    Resolution(u32),
    #[error(
        "fur shells: {layers} layers of {resolution}² are {texels} texels, over the limit of 16 777 216"
    )]
    TooManyTexels {
        layers: u32,
        resolution: u32,
        texels: u64,
    },
}

/// Square RGBA8 layers, layer-major, row-major within a layer.
#[derive(Clone, Debug, PartialEq)]
pub struct Layers {
    pub resolution: u32,
    pub texels: Vec<[u8; 4]>,
}

impl Layers {
    pub fn layer_count(&self) -> usize {
        let side = self.resolution as usize;
        self.texels.len() / (side * side)
    }

    pub fn layer(&self, index: usize) -> &[[u8; 4]] {
        let size = (self.resolution * self.resolution) as usize;
        &self.texels[index * size..][..size]
    }

    /// Mean coverage of one layer in `[0, 1]`.
    pub fn mean_alpha(&self, index: usize) -> f64 {
        let layer = self.layer(index);
        layer.iter().map(|t| t[3] as f64).sum::<f64>() / (layer.len() as f64 * 255.0)
    }
}

/// The shells of one fur volume at every level of detail.
#[derive(Clone, Debug, PartialEq)]
pub struct ShellTextures {
    pub params: ShellParams,
    /// `levels[m]` holds the `layer_count >> m` shells drawn at level `m`; shell `k` of level
    /// `m` sits at the height of shell `k << m` of level 0. Level 0 is the sampled volume.
    pub levels: Vec<Layers>,
    /// Mean strand tangents of the level-0 shells (the coarser levels reuse the even shell's).
    pub directions: Layers,
    /// Height of the outermost shell above the skin, in metres (the volume's length).
    pub length_m: f64,
    /// The tile's width in metres: one texture repeat on the surface.
    pub tile_width_m: f64,
}

/// The fin texture: the volume seen from the side through a slab.
#[derive(Clone, Debug, PartialEq)]
pub struct FinTexture {
    pub width: u32,
    pub height: u32,
    /// Row 0 is the skin, the last row the tips.
    pub texels: Vec<[u8; 4]>,
    /// The slab's thickness in metres (how many strands one fin shows).
    pub slab_width_m: f64,
}

fn to_unorm8(value: f64) -> u8 {
    (value.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Accumulated optical depth, weighted brightness and tangent of one texel.
#[derive(Clone, Copy, Default)]
struct Accumulator {
    depth: f64,
    tint: f64,
    tangent: DVec3,
}

impl Accumulator {
    fn add(&mut self, depth: f64, tint: f64, tangent: DVec3) {
        self.depth += depth;
        self.tint += depth * tint;
        // Tangents are unsigned (a strand's two directions light alike); fold to +z.
        let signed = if tangent.z < 0.0 { -tangent } else { tangent };
        self.tangent += signed * depth;
    }

    fn rgba(&self) -> [u8; 4] {
        let alpha = 1.0 - (-self.depth).exp();
        let tint = if self.depth > 0.0 {
            self.tint / self.depth
        } else {
            0.0
        };
        [
            to_unorm8(tint),
            to_unorm8(tint),
            to_unorm8(tint),
            to_unorm8(alpha),
        ]
    }

    fn direction(&self) -> [u8; 4] {
        let t = self.tangent.try_normalize().unwrap_or(DVec3::Z);
        [
            to_unorm8(0.5 + 0.5 * t.x),
            to_unorm8(0.5 + 0.5 * t.y),
            to_unorm8(0.5 + 0.5 * t.z),
            255,
        ]
    }
}

/// `spacing_m`, or wider where the volume's strands are so long that it would take more than
/// [`MAX_STRAND_SAMPLES`] samples.
fn bounded_spacing(volume: &FurVolume, spacing_m: f64) -> f64 {
    let total_m: f64 = volume
        .strands
        .iter()
        .flat_map(|s| s.points.windows(2).map(|p| p[0].distance(p[1])))
        .filter(|l| l.is_finite())
        .sum();
    spacing_m.max(total_m / MAX_STRAND_SAMPLES)
}

/// Points along every strand no further apart than `spacing_m`, with the strand's tangent
/// there and the arc length each point stands for.
fn strand_samples(
    volume: &FurVolume,
    spacing_m: f64,
    mut visit: impl FnMut(DVec3, DVec3, f64, f64),
) {
    for strand in &volume.strands {
        for pair in strand.points.windows(2) {
            let segment = pair[1] - pair[0];
            let length = segment.length();
            if length <= 0.0 || !length.is_finite() {
                continue;
            }
            let tangent = segment / length;
            let count = (length / spacing_m).ceil().max(1.0) as usize;
            let ds = length / count as f64;
            for i in 0..count {
                let point = pair[0] + segment * ((i as f64 + 0.5) / count as f64);
                visit(point, tangent, ds, strand.tint as f64);
            }
        }
    }
}

impl ShellTextures {
    /// Samples `volume` into shells: layer `ℓ` sits at height `ℓ/(L−1)·length`, and each of its
    /// texels intersects the strands with a Gaussian that is one texel wide across the skin and
    /// one shell spacing tall, so every piece of strand lands in the shells nearest its height
    /// (seed 002: "the filter is tall because the inter-shell spacing is much greater than the
    /// grid spacing"). Coverage is `1 − exp(−τ)` of the filtered projected strand area τ. The
    /// innermost layer is the skin and fully opaque.
    pub fn sample(volume: &FurVolume, params: ShellParams) -> Result<Self, FurTextureError> {
        if !(2..=MAX_SHELL_LAYERS).contains(&params.layer_count)
            || !params.layer_count.is_power_of_two()
        {
            return Err(FurTextureError::LayerCount(params.layer_count));
        }
        if !(8..=MAX_SHELL_RESOLUTION).contains(&params.resolution) {
            return Err(FurTextureError::Resolution(params.resolution));
        }
        let texels = (params.resolution as u64)
            .saturating_pow(2)
            .saturating_mul(params.layer_count as u64);
        if texels > MAX_SHELL_TEXELS {
            return Err(FurTextureError::TooManyTexels {
                layers: params.layer_count,
                resolution: params.resolution,
                texels,
            });
        }
        let tile = volume.params.tile_width_m;
        let length = volume.params.length_m;
        let side = params.resolution as usize;
        let layers = params.layer_count as usize;
        let texel_m = tile / side as f64;
        let spacing_m = length / (layers - 1) as f64;
        // At most two texels wide, so the filter's reach stays a few texels however thick
        // the strands.
        let sigma_xy = (0.6 * texel_m).max(volume.params.strand_radius_m.min(2.0 * texel_m));
        let sigma_z = 0.5 * spacing_m;
        let radius = volume.params.strand_radius_m;
        let mut grid = vec![Accumulator::default(); layers * side * side];
        let reach = (3.0 * sigma_xy / texel_m).ceil() as i64;
        let norm_xy = 1.0 / (std::f64::consts::TAU * sigma_xy * sigma_xy);
        let norm_z = 1.0 / ((std::f64::consts::TAU).sqrt() * sigma_z);
        strand_samples(
            volume,
            bounded_spacing(volume, (0.5 * texel_m).min(0.25 * spacing_m)),
            |point, tangent, ds, tint| {
                // Seen along the skin normal, the strands inside one shell's slab (thickness
                // Δ) cover their projected area: a piece of length ds at angle θ to the normal
                // shows 2r·ds·sin θ from the side plus its share ds·|cos θ|/Δ of the end-on
                // disc πr². The tall Gaussian (∫ = 1) times Δ weighs slab membership.
                let sin_theta = (1.0 - tangent.z * tangent.z).max(0.0).sqrt();
                let lowest = ((point.z - 3.0 * sigma_z) / spacing_m).ceil().max(0.0) as usize;
                let highest =
                    (((point.z + 3.0 * sigma_z) / spacing_m).floor() as usize).min(layers - 1);
                let x = wrap(point.x, tile) / texel_m - 0.5;
                let y = wrap(point.y, tile) / texel_m - 0.5;
                let (cx, cy) = (x.round() as i64, y.round() as i64);
                for layer in lowest..=highest {
                    let dz = point.z - layer as f64 * spacing_m;
                    let wz = norm_z * (-0.5 * dz * dz / (sigma_z * sigma_z)).exp();
                    let area = (2.0 * radius * sin_theta * ds
                        + std::f64::consts::PI * radius * radius * tangent.z.abs() * ds
                            / spacing_m)
                        * wz
                        * spacing_m;
                    for j in -reach..=reach {
                        for i in -reach..=reach {
                            let dx = ((cx + i) as f64 - x) * texel_m;
                            let dy = ((cy + j) as f64 - y) * texel_m;
                            let g = norm_xy
                                * (-0.5 * (dx * dx + dy * dy) / (sigma_xy * sigma_xy)).exp();
                            let tx = (cx + i).rem_euclid(side as i64) as usize;
                            let ty = (cy + j).rem_euclid(side as i64) as usize;
                            grid[(layer * side + ty) * side + tx].add(area * g, tint, tangent);
                        }
                    }
                }
            },
        );
        let mut texels: Vec<[u8; 4]> = grid.iter().map(Accumulator::rgba).collect();
        let directions: Vec<[u8; 4]> = grid.iter().map(Accumulator::direction).collect();
        if params.opaque_skin {
            // The skin: opaque, with the mean brightness of the roots.
            let mean_tint = volume.strands.iter().map(|s| s.tint as f64).sum::<f64>()
                / volume.strands.len().max(1) as f64;
            for texel in &mut texels[..side * side] {
                let tint = to_unorm8(mean_tint);
                *texel = [tint, tint, tint, 255];
            }
        }
        let finest = Layers {
            resolution: params.resolution,
            texels,
        };
        let mut levels = vec![finest];
        while levels.last().is_some_and(|l| l.layer_count() > 1) {
            let coarser = coarser_level(levels.last().expect("levels has a finest level"));
            levels.push(coarser);
        }
        Ok(Self {
            params,
            levels,
            directions: Layers {
                resolution: params.resolution,
                texels: directions,
            },
            length_m: length,
            tile_width_m: tile,
        })
    }

    /// Bytes of every texture the runtime keeps for these shells (all levels and the
    /// direction layers), with a full mip chain when `mipmapped` (×4/3).
    pub fn memory_bytes(&self, mipmapped: bool) -> u64 {
        let texels: usize = self.levels.iter().map(|l| l.texels.len()).sum::<usize>()
            + self.directions.texels.len();
        with_mips(texels as u64 * 4, mipmapped)
    }

    /// Bytes of the seed's own set: the level-0 colour shells only.
    pub fn seed_memory_bytes(&self, mipmapped: bool) -> u64 {
        with_mips(self.levels[0].texels.len() as u64 * 4, mipmapped)
    }
}

fn with_mips(bytes: u64, mipmapped: bool) -> u64 {
    if mipmapped { bytes * 4 / 3 } else { bytes }
}

/// One level coarser (seed 002 §2.4): each pair of shells (2k, 2k+1) composited, the outer
/// over the inner, into shell k (which sits at the inner one's height).
pub fn coarser_level(fine: &Layers) -> Layers {
    let size = (fine.resolution * fine.resolution) as usize;
    let count = fine.layer_count() / 2;
    let mut texels = Vec::with_capacity(count * size);
    for k in 0..count {
        let inner = fine.layer(2 * k);
        let outer = fine.layer(2 * k + 1);
        texels.extend(inner.iter().zip(outer).map(|(&a, &b)| over(b, a)));
    }
    Layers {
        resolution: fine.resolution,
        texels,
    }
}

/// `top` composited over `bottom` (straight alpha).
pub fn over(top: [u8; 4], bottom: [u8; 4]) -> [u8; 4] {
    let at = top[3] as f64 / 255.0;
    let ab = bottom[3] as f64 / 255.0;
    let alpha = at + ab * (1.0 - at);
    if alpha <= 0.0 {
        return [0, 0, 0, 0];
    }
    let mut out = [0u8; 4];
    for c in 0..3 {
        let colour = (top[c] as f64 * at + bottom[c] as f64 * ab * (1.0 - at)) / alpha;
        out[c] = colour.round().clamp(0.0, 255.0) as u8;
    }
    out[3] = to_unorm8(alpha);
    out
}

/// The shell level of detail for fur whose length covers `length_px` pixels on screen, with
/// `layer_count` shells: the finest level keeps about one shell per pixel of fur length
/// (fewer shells than that cannot be told apart). Continuous, so the blend between a level
/// and the next follows the distance and never pops; `floor` is the level drawn, `fract` the
/// share of the next coarser level blended in.
pub fn shell_level(length_px: f64, layer_count: u32) -> f64 {
    let finest = (layer_count.max(1) as f64).log2();
    if !length_px.is_finite() || length_px <= 0.0 {
        return finest;
    }
    (layer_count as f64 / length_px).log2().clamp(0.0, finest)
}

impl FinTexture {
    /// Composites the strands in a slab `y ∈ [0, slab_width_m)` (wrapping) onto the `x, z`
    /// plane: `width` texels across one tile, `height` from skin to tips, each texel the
    /// strands' projected area through a one-texel Gaussian, coverage `1 − exp(−τ)`.
    pub fn sample(volume: &FurVolume, slab_width_m: f64, width: u32, height: u32) -> Self {
        let tile = volume.params.tile_width_m;
        let length = volume.params.length_m;
        let slab = if slab_width_m.is_finite() {
            slab_width_m.clamp(tile / 1024.0, tile)
        } else {
            tile / 8.0
        };
        let (w, h) = (
            width.clamp(1, 4096) as usize,
            height.clamp(1, 1024) as usize,
        );
        let du = tile / w as f64;
        let dz = length / h as f64;
        let sigma_u = (0.6 * du).max(volume.params.strand_radius_m.min(2.0 * du));
        let sigma_z = 0.6 * dz;
        let radius = volume.params.strand_radius_m;
        let mut grid = vec![Accumulator::default(); w * h];
        let reach_u = (3.0 * sigma_u / du).ceil() as i64;
        let reach_z = (3.0 * sigma_z / dz).ceil() as i64;
        let norm = 1.0 / (std::f64::consts::TAU * sigma_u * sigma_z);
        strand_samples(
            volume,
            bounded_spacing(volume, 0.5 * du.min(dz)),
            |point, tangent, ds, tint| {
                if wrap(point.y, tile) >= slab {
                    return;
                }
                // Seen along y, a strand piece covers 2r·ds·|sin| of its angle to the view.
                let sin_view = (1.0 - tangent.y * tangent.y).max(0.0).sqrt();
                let area = 2.0 * radius * ds * sin_view;
                let u = wrap(point.x, tile) / du - 0.5;
                let z = point.z / dz - 0.5;
                let (cu, cz) = (u.round() as i64, z.round() as i64);
                for j in -reach_z..=reach_z {
                    let row = cz + j;
                    if row < 0 || row >= h as i64 {
                        continue;
                    }
                    for i in -reach_u..=reach_u {
                        let du_m = ((cu + i) as f64 - u) * du;
                        let dz_m = (row as f64 - z) * dz;
                        let g = norm
                            * (-0.5
                                * (du_m * du_m / (sigma_u * sigma_u)
                                    + dz_m * dz_m / (sigma_z * sigma_z)))
                                .exp();
                        let column = (cu + i).rem_euclid(w as i64) as usize;
                        grid[row as usize * w + column].add(area * g, tint, tangent);
                    }
                }
            },
        );
        Self {
            width: w as u32,
            height: h as u32,
            texels: grid.iter().map(Accumulator::rgba).collect(),
            slab_width_m: slab,
        }
    }

    pub fn memory_bytes(&self, mipmapped: bool) -> u64 {
        with_mips(self.texels.len() as u64 * 4, mipmapped)
    }

    /// Mean coverage of one row (0: skin).
    pub fn row_alpha(&self, row: usize) -> f64 {
        let w = self.width as usize;
        self.texels[row * w..][..w]
            .iter()
            .map(|t| t[3] as f64)
            .sum::<f64>()
            / (w as f64 * 255.0)
    }
}

/// The mip chain of a `width × height` RGBA8 image (straight alpha): each level halves both
/// sides (down to 1) by a box filter over premultiplied colour, so that clear texels do not
/// darken their neighbours. Level 0 is the image itself.
pub fn mip_chain(texels: &[[u8; 4]], width: u32, height: u32) -> Vec<(u32, u32, Vec<[u8; 4]>)> {
    let mut levels = vec![(width, height, texels.to_vec())];
    while let Some((w, h, last)) = levels.last()
        && (*w > 1 || *h > 1)
    {
        let (w, h) = (*w as usize, *h as usize);
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut next = Vec::with_capacity(nw * nh);
        for y in 0..nh {
            for x in 0..nw {
                let mut sum = [0.0f64; 4];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let t = last[(2 * y + dy).min(h - 1) * w + (2 * x + dx).min(w - 1)];
                    let a = t[3] as f64 / 255.0;
                    for c in 0..3 {
                        sum[c] += t[c] as f64 * a;
                    }
                    sum[3] += a;
                }
                let alpha = sum[3] / 4.0;
                let colour = |c: usize| {
                    if sum[3] > 0.0 {
                        (sum[c] / sum[3]).round().clamp(0.0, 255.0) as u8
                    } else {
                        0
                    }
                };
                next.push([colour(0), colour(1), colour(2), to_unorm8(alpha)]);
            }
        }
        levels.push((nw as u32, nh as u32, next));
    }
    levels
}
