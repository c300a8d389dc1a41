//! Hair cards from bundles: the game-ready fallback for hair that cannot afford strands.
//!
//! A hair mesh has cards almost for free: each bundle becomes one card strip along its
//! centre surface — the bundle's centre curve (the column blend at the root face's centre),
//! widened across the bundle — and the strands it grows are baked into that card's own tile
//! of a texture atlas, seen along the card's normal:
//! - **albedo** (sRGB, alpha = coverage): the fibre colour of the scene's material at that
//!   point along the strand (the same absorption the shaders use, root-to-tip included);
//! - **coverage**: `1 − (1 − α)ⁿ` over the `n` strands crossing a texel;
//! - **depth**: the nearest strand's offset along the card's normal, 0.5 on the card plane,
//!   scaled by [`HairCards::depth_range_m`];
//! - **flow**: the strands' direction in the card's (u, v), as `0.5 + 0.5·dir` in red and green;
//! - **root to tip**: fraction along the strand, for gradients and alpha ramps;
//! - **id**: one random value per strand, for per-strand variation in the game's shader;
//! - **root uv**: the scalp uv of the nearest strand's root (red, green), for textures a
//!   game looks up by root (Unreal's card attribute texture carries it).
//!
//! A card is widened wherever its strands reach beyond the bundle's own width (styling can
//! carry them there), so every strand lands inside its card. Level of detail lowers the
//! segments along each card ([`CardOptions::segments_per_layer`] halved per level), keeping
//! its outline and texture.

use glam::{DVec3, Vec3};

use crate::Document;
use crate::geometry::curve::{CurveDefinition, FaceCoord, ReferenceStrand, SegmentForm};
use crate::light::material::Fibre;
use crate::strands::random::{hash_to_unit, pcg_hash};
use crate::strands::reference::Strand;

/// How cards are made and baked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CardOptions {
    /// Segments per layer of the finest level; each further level halves them (at least one).
    pub segments_per_layer: u32,
    /// Levels of detail (1 to 4).
    pub levels: u32,
    /// Texels of one card's tile, across × along. Halved (across first) when the cards would
    /// not fit `max_atlas_px`.
    pub tile_px: [u32; 2],
    /// Largest atlas side (at most [`MAX_ATLAS_PX`]).
    pub max_atlas_px: u32,
    /// Opacity one strand gives a texel it crosses.
    pub strand_alpha: f32,
}

impl Default for CardOptions {
    fn default() -> Self {
        Self {
            segments_per_layer: 4,
            levels: 3,
            tile_px: [32, 128],
            max_atlas_px: MAX_ATLAS_PX,
            strand_alpha: 0.35,
        }
    }
}

/// Largest atlas side we make (what every engine loads).
pub const MAX_ATLAS_PX: u32 = 4096;

/// One level of detail: every card as triangles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CardMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    /// xyz along the card's u (across), w = 1 (handedness).
    pub tangents: Vec<[f32; 4]>,
    /// Into the atlas: u across the card's tile, v from root (top of the tile) to tip.
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
}

impl CardMesh {
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }
}

/// The baked maps, each `width × height`, rows top first.
#[derive(Clone, Debug, PartialEq)]
pub struct CardAtlas {
    pub width: u32,
    pub height: u32,
    /// RGBA8, sRGB colour, alpha = coverage.
    pub albedo: Vec<u8>,
    pub coverage: Vec<u8>,
    pub depth: Vec<u8>,
    /// RGB8: red, green = direction in the card's (u, v); blue 0.
    pub flow: Vec<u8>,
    pub root_to_tip: Vec<u8>,
    pub id: Vec<u8>,
    /// Root uv of the nearest strand, two channels per texel (0 where no strand is).
    pub root_uv: Vec<u8>,
}

/// The texture set Unreal's groom cards take (Groom asset ▸ Cards ▸ Textures), named as its
/// card texture generator names them: `(file stem, channels, pixels)`.
pub const UNREAL_CARD_TEXTURES: [&str; 4] = [
    "T_HairCards_Depth",
    "T_HairCards_Coverage",
    "T_HairCards_Tangent",
    "T_HairCards_Attribute",
];

impl CardAtlas {
    /// Unreal's card textures from the same bake ([`UNREAL_CARD_TEXTURES`]): depth (L8),
    /// coverage (L8), tangent (RGB8: the strands' direction in the card's (u, v) and 0 out
    /// of the card, each as `0.5 + 0.5·x`), attribute (RGBA8: root u, root v, coordinate
    /// along the strand from root to tip, per-strand seed).
    pub fn unreal_textures(&self) -> [(&'static str, u8, Vec<u8>); 4] {
        let texels = (self.width * self.height) as usize;
        let mut tangent = Vec::with_capacity(texels * 3);
        let mut attribute = Vec::with_capacity(texels * 4);
        for i in 0..texels {
            tangent.extend_from_slice(&[self.flow[3 * i], self.flow[3 * i + 1], 128]);
            attribute.extend_from_slice(&[
                self.root_uv[2 * i],
                self.root_uv[2 * i + 1],
                self.root_to_tip[i],
                self.id[i],
            ]);
        }
        let [depth, coverage, tangent_name, attribute_name] = UNREAL_CARD_TEXTURES;
        [
            (depth, 1, self.depth.clone()),
            (coverage, 1, self.coverage.clone()),
            (tangent_name, 3, tangent),
            (attribute_name, 4, attribute),
        ]
    }
}

/// Cards of a hairstyle: the levels of detail and the atlas they share.
#[derive(Clone, Debug, PartialEq)]
pub struct HairCards {
    pub levels: Vec<CardMesh>,
    pub atlas: CardAtlas,
    /// Depth 0 and 255 in the depth map are this far below and above the card, metres.
    pub depth_range_m: f32,
    /// Cards made (bundles that grow hair).
    pub cards: usize,
    /// Strand points baked.
    pub baked_points: usize,
}

/// A card's frame along its centre curve.
struct CardFrame {
    centre: DVec3,
    /// Unit, across the bundle.
    across: DVec3,
    /// Unit, the card's normal.
    normal: DVec3,
}

struct Card {
    bundle: usize,
    layers: f64,
    /// Frames at `t = k / FRAME_STEPS_PER_LAYER`.
    frames: Vec<CardFrame>,
    /// Half-width at each frame.
    half_width_m: Vec<f64>,
}

const FRAME_STEPS_PER_LAYER: usize = 8;

impl Card {
    fn new(document: &Document, bundle: usize) -> Option<Self> {
        let mesh = &document.hair_mesh;
        let b = mesh.bundles.get(bundle)?;
        if b.removed || b.layers == 0 {
            return None;
        }
        let corners = b.vertices.len();
        let (centre, left, right) = if corners == 3 {
            (
                FaceCoord {
                    s: 1.0 / 3.0,
                    t: 1.0 / 3.0,
                },
                FaceCoord { s: 0.0, t: 0.0 },
                FaceCoord { s: 0.5, t: 0.5 },
            )
        } else {
            (
                FaceCoord { s: 0.5, t: 0.5 },
                FaceCoord { s: 0.0, t: 0.5 },
                FaceCoord { s: 1.0, t: 0.5 },
            )
        };
        let curve = |coord| ReferenceStrand::new(mesh, bundle, coord);
        let (centre, left, right) = (curve(centre)?, curve(left)?, curve(right)?);
        let at = |strand: &ReferenceStrand, t: f64| {
            strand.point(t, CurveDefinition::ColumnBlend, SegmentForm::ExactCubic)
        };
        let steps = b.layers as usize * FRAME_STEPS_PER_LAYER;
        let dt = 1.0 / FRAME_STEPS_PER_LAYER as f64;
        let mut frames = Vec::with_capacity(steps + 1);
        let mut half_width_m = Vec::with_capacity(steps + 1);
        let mut last_across = DVec3::X;
        for k in 0..=steps {
            let t = k as f64 * dt;
            let c = at(&centre, t);
            let along = (at(&centre, (t + 0.5 * dt).min(b.layers as f64))
                - at(&centre, (t - 0.5 * dt).max(0.0)))
            .normalize_or(DVec3::Y);
            let span = at(&right, t) - at(&left, t);
            // Across the bundle, square to the centre curve; a degenerate span keeps the
            // previous direction so the strip does not flip.
            let across = (span - along * span.dot(along)).normalize_or(last_across);
            last_across = across;
            frames.push(CardFrame {
                centre: c,
                across,
                normal: across.cross(along).normalize_or(DVec3::Z),
            });
            half_width_m.push(0.5 * span.length());
        }
        Some(Self {
            bundle,
            layers: b.layers as f64,
            frames,
            half_width_m,
        })
    }

    /// The frame at `t` (nearest sample; frames are 1/8 layer apart).
    fn frame(&self, t: f64) -> (usize, &CardFrame) {
        let k = ((t * FRAME_STEPS_PER_LAYER as f64).round().max(0.0) as usize)
            .min(self.frames.len() - 1);
        (k, &self.frames[k])
    }
}

/// Where a strand point sits on its card: across (metres from the centre curve), along
/// (`t / layers`), and its height above the card (metres).
struct CardPoint {
    frame: usize,
    across_m: f64,
    along: f64,
    depth_m: f64,
}

/// The cards of `strands` (generated from `document`), baked.
pub fn hair_cards(document: &Document, strands: &[Strand], options: &CardOptions) -> HairCards {
    let cards: Vec<Card> = (0..document.hair_mesh.bundles.len())
        .filter_map(|b| Card::new(document, b))
        .collect();
    let card_of_bundle: std::collections::HashMap<usize, usize> = cards
        .iter()
        .enumerate()
        .map(|(i, c)| (c.bundle, i))
        .collect();

    // Every strand point on its card; cards widen to hold them.
    let mut cards = cards;
    let mut placed: Vec<(usize, usize, Vec<CardPoint>)> = Vec::new();
    let mut depth_range_m: f64 = 1e-4;
    for (index, strand) in strands.iter().enumerate() {
        let Some(&c) = card_of_bundle.get(&(strand.bundle as usize)) else {
            continue;
        };
        let card = &mut cards[c];
        let tau_max = card.layers * strand.length_fraction;
        let n = strand.points.len().max(2);
        let mut points = Vec::with_capacity(strand.points.len());
        for (k, p) in strand.points.iter().enumerate() {
            let t = tau_max * k as f64 / (n - 1) as f64;
            let (frame_index, frame) = card.frame(t);
            let offset = *p - frame.centre;
            let across_m = offset.dot(frame.across);
            let depth_m = offset.dot(frame.normal);
            depth_range_m = depth_range_m.max(depth_m.abs());
            points.push(CardPoint {
                frame: frame_index,
                across_m,
                along: t / card.layers,
                depth_m,
            });
        }
        for point in &points {
            let w = &mut card.half_width_m[point.frame];
            *w = w.max(point.across_m.abs() * 1.02);
        }
        placed.push((c, index, points));
    }
    // A smooth outline: each frame's half-width is at least its neighbours' within half a
    // layer, so one stray strand makes a bulge, not a spike.
    for card in &mut cards {
        let raw = card.half_width_m.clone();
        let reach = FRAME_STEPS_PER_LAYER / 2;
        for (k, w) in card.half_width_m.iter_mut().enumerate() {
            let lo = k.saturating_sub(reach);
            let hi = (k + reach).min(raw.len() - 1);
            *w = raw[lo..=hi].iter().copied().fold(1e-5, f64::max);
        }
    }

    // The atlas: one tile per card, shrunk until the cards fit.
    let max_px = options.max_atlas_px.clamp(16, MAX_ATLAS_PX);
    let mut tile = options.tile_px.map(|v| v.clamp(2, max_px));
    let (columns, rows) = loop {
        let columns = (max_px / tile[0]).max(1) as usize;
        let rows = cards.len().div_ceil(columns).max(1);
        if rows as u32 * tile[1] <= max_px || tile[1] <= 2 {
            break (columns.min(cards.len().max(1)), rows);
        }
        if tile[0] >= tile[1] / 4 && tile[0] > 2 {
            tile[0] /= 2;
        } else {
            tile[1] /= 2;
        }
    };
    let (width, height) = (columns as u32 * tile[0], rows as u32 * tile[1]);
    let tile_origin = |c: usize| {
        [
            (c % columns) as u32 * tile[0],
            (c / columns) as u32 * tile[1],
        ]
    };

    let levels = (0..options.levels.clamp(1, 4))
        .map(|level| {
            let per_layer = (options.segments_per_layer >> level).max(1) as usize;
            card_mesh(&cards, per_layer, tile, tile_origin, (width, height))
        })
        .collect();

    let atlas = bake(
        document,
        strands,
        &cards,
        &placed,
        tile,
        tile_origin,
        (width, height),
        depth_range_m,
        options.strand_alpha,
    );
    let baked_points = placed.iter().map(|(_, _, p)| p.len()).sum();
    HairCards {
        levels,
        atlas,
        depth_range_m: depth_range_m as f32,
        cards: cards.len(),
        baked_points,
    }
}

/// Texel position of a card point: x across the tile, y from root (0) to tip.
fn texel(card: &Card, point: &CardPoint, tile: [u32; 2]) -> (f64, f64) {
    // The same mapping as the mesh's uvs: texel centres 0.5 … size − 0.5.
    let u = 0.5 + 0.5 * point.across_m / card.half_width_m[point.frame];
    (
        0.5 + u * (tile[0] as f64 - 1.0),
        0.5 + point.along * (tile[1] as f64 - 1.0),
    )
}

fn card_mesh(
    cards: &[Card],
    per_layer: usize,
    tile: [u32; 2],
    tile_origin: impl Fn(usize) -> [u32; 2],
    (width, height): (u32, u32),
) -> CardMesh {
    let mut mesh = CardMesh::default();
    for (c, card) in cards.iter().enumerate() {
        let segments = card.layers as usize * per_layer;
        let origin = tile_origin(c);
        let first = mesh.positions.len() as u32;
        for j in 0..=segments {
            let t = j as f64 / per_layer as f64;
            let (k, frame) = card.frame(t);
            let h = card.half_width_m[k];
            for side in [-1.0, 1.0] {
                let p = frame.centre + frame.across * (side * h);
                mesh.positions.push(p.as_vec3().to_array());
                mesh.normals.push(frame.normal.as_vec3().to_array());
                let a: Vec3 = frame.across.as_vec3();
                mesh.tangents.push([a.x, a.y, a.z, 1.0]);
                // Texel centres at the tile's edges, so filtering at full resolution never reads a
                // neighbour (see the sampler in `io::cards_gltf`).
                let u = if side < 0.0 {
                    0.5
                } else {
                    tile[0] as f64 - 0.5
                };
                let v = (t / card.layers) * (tile[1] as f64 - 1.0) + 0.5;
                mesh.uvs.push([
                    ((origin[0] as f64 + u) / width as f64) as f32,
                    ((origin[1] as f64 + v) / height as f64) as f32,
                ]);
            }
            if j > 0 {
                let (a, b) = (first + 2 * (j as u32 - 1), first + 2 * j as u32);
                mesh.indices
                    .extend_from_slice(&[a, a + 1, b + 1, a, b + 1, b]);
            }
        }
    }
    mesh
}

#[expect(
    clippy::too_many_arguments,
    reason = "the bake's inputs, each used once"
)]
fn bake(
    document: &Document,
    strands: &[Strand],
    cards: &[Card],
    placed: &[(usize, usize, Vec<CardPoint>)],
    tile: [u32; 2],
    tile_origin: impl Fn(usize) -> [u32; 2],
    (width, height): (u32, u32),
    depth_range_m: f64,
    strand_alpha: f32,
) -> CardAtlas {
    let texels = (width * height) as usize;
    let mut count = vec![0u32; texels];
    let mut colour = vec![[0f64; 3]; texels];
    let mut flow = vec![[0f64; 2]; texels];
    let mut along_sum = vec![0f64; texels];
    let mut depth = vec![f64::NEG_INFINITY; texels];
    let mut id = vec![0u8; texels];
    let mut root_uv = vec![0u8; texels * 2];
    let fibre = Fibre::new(&document.scene.material);
    for (c, index, points) in placed {
        let card = &cards[*c];
        let origin = tile_origin(*c);
        let strand_id = hash_to_unit(pcg_hash(
            (strands[*index].bundle << 12) ^ (*index as u32).wrapping_mul(0x9E37_79B9),
        ));
        // The colour map at the strand's root, as every renderer reads it.
        let painted = fibre.painted(&document.root_maps.sample_colour(strands[*index].root_uv));
        for pair in points.windows(2) {
            let (x0, y0) = texel(card, &pair[0], tile);
            let (x1, y1) = texel(card, &pair[1], tile);
            let direction = glam::DVec2::new(x1 - x0, y1 - y0);
            let length = direction.length();
            let unit = direction / length.max(1e-12);
            let steps = (2.0 * length).ceil().max(1.0) as usize;
            let mut last = usize::MAX;
            for s in 0..=steps {
                let f = s as f64 / steps as f64;
                let x = (x0 + (x1 - x0) * f).clamp(0.0, tile[0] as f64 - 1.0);
                let y = (y0 + (y1 - y0) * f).clamp(0.0, tile[1] as f64 - 1.0);
                let at = (origin[1] + y as u32) as usize * width as usize
                    + (origin[0] + x as u32) as usize;
                if at == last {
                    continue;
                }
                last = at;
                let along = pair[0].along + (pair[1].along - pair[0].along) * f;
                let d = pair[0].depth_m + (pair[1].depth_m - pair[0].depth_m) * f;
                count[at] += 1;
                let rgb = painted.color(painted.sigma_a(along, strand_id));
                for k in 0..3 {
                    colour[at][k] += rgb[k];
                }
                flow[at][0] += unit.x;
                flow[at][1] += unit.y;
                along_sum[at] += along;
                if d > depth[at] {
                    depth[at] = d;
                    id[at] = (strand_id * 255.0).round() as u8;
                    let uv = strands[*index].root_uv;
                    root_uv[2 * at] = unit_to_u8(uv.x);
                    root_uv[2 * at + 1] = unit_to_u8(uv.y);
                }
            }
        }
    }
    let to_u8 = unit_to_u8;
    let mut atlas = CardAtlas {
        width,
        height,
        albedo: Vec::with_capacity(texels * 4),
        coverage: Vec::with_capacity(texels),
        depth: Vec::with_capacity(texels),
        flow: Vec::with_capacity(texels * 3),
        root_to_tip: Vec::with_capacity(texels),
        id,
        root_uv,
    };
    for i in 0..texels {
        let n = count[i];
        let coverage = 1.0 - (1.0 - strand_alpha as f64).powi(n as i32);
        if n == 0 {
            atlas.albedo.extend_from_slice(&[0, 0, 0, 0]);
            atlas.depth.push(128);
            atlas.flow.extend_from_slice(&[128, 255, 0]);
            atlas.root_to_tip.push(0);
        } else {
            let mean = colour[i].map(|c| c / n as f64);
            for c in mean {
                atlas
                    .albedo
                    .push(to_u8(crate::light::linear_to_srgb(c as f32) as f64));
            }
            atlas.albedo.push(to_u8(coverage));
            atlas
                .depth
                .push(to_u8(0.5 + 0.5 * depth[i] / depth_range_m));
            let f = glam::DVec2::from(flow[i]).normalize_or(glam::DVec2::Y);
            atlas
                .flow
                .extend_from_slice(&[to_u8(0.5 + 0.5 * f.x), to_u8(0.5 + 0.5 * f.y), 0]);
            atlas.root_to_tip.push(to_u8(along_sum[i] / n as f64));
        }
        atlas.coverage.push(to_u8(coverage));
    }
    atlas
}

/// `x` in [0, 1] as an 8-bit channel (clamped; NaN is 0).
fn unit_to_u8(x: f64) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[cfg(test)]
mod tests;
