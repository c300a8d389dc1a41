//! Far hair's hierarchy (seed 001 §5.1, on hair meshes): each bundle's strands, as generated
//! (styling included), grouped into levels of thick hairs whose cross-section area grows
//! about ×4 per level, from single strands (level 0) to one thick hair per bundle; and each
//! thick hair's elliptical cross-section fitted at every control point by PCA of its
//! members' points, the axis nearest the mean tangent dropped (§5.1 step 3).
//!
//! Two choices differ from the seed, both so that a thick hair follows the hair mesh (motion,
//! drape, a drag) with no per-frame refit on the CPU:
//! - A bundle is the natural cluster (its corner columns are the seed's guides), and the
//!   levels inside it come from balanced bisection along the strands' principal axis (a
//!   k-d tree over whole strands, the seed's `D(i, j)` metric) instead of k-means: it is
//!   deterministic, `O(m log m)` for `m` strands where k-means is `O(m · k)` per iteration,
//!   and nested — a thick hair is the union of about four of the level below, so switching
//!   levels swaps a hair for the hairs it covers.
//! - The four corners are member *strands* (the ones that track the ends of the two kept axes
//!   best over the whole length), not one point per control point: the GPU generates those
//!   four strands as it generates any strand, and the centre and axes follow from them
//!   ([`CrossSection::from_corners`]); [`ThickHair::corner_fit_error_m`] says how far that is
//!   from the PCA fit.

use glam::{DMat3, DVec3};

/// How much a thick hair's cross-section area grows from one level to the next (seed 001:
/// "approximately four times").
pub const AREA_RATIO_PER_LEVEL: usize = 4;

/// Why a bundle's strands cannot be grouped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ThickHairError {
    #[error("strand {strand} has {found} control points where the bundle's first has {expected}")]
    ControlPointCount {
        strand: usize,
        found: usize,
        expected: usize,
    },
    #[error("strand {strand} point {point} is not finite ({value:?})")]
    NotFinite {
        strand: usize,
        point: usize,
        value: [f64; 3],
    },
    #[error("a strand needs at least 2 control points, found {0}")]
    TooFewControlPoints(usize),
}

/// A thick hair's elliptical cross-section at one control point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrossSection {
    pub centre: DVec3,
    /// Unit mean tangent of the members here.
    pub tangent: DVec3,
    /// Half-axis vectors across the hair (orthogonal to each other; `major` the longer).
    /// Their lengths cover every member's point here.
    pub major: DVec3,
    pub minor: DVec3,
}

impl CrossSection {
    /// The section the four corner points span (`+major`, `-major`, `+minor`, `-minor`
    /// ends): what the GPU derives from the four corner strands it generated.
    pub fn from_corners(corners: [DVec3; 4], tangent: DVec3) -> Self {
        let [a, b, c, d] = corners;
        CrossSection {
            centre: (a + b + c + d) * 0.25,
            tangent,
            major: (a - b) * 0.5,
            minor: (c - d) * 0.5,
        }
    }

    /// Width seen across `view` (a unit direction from the eye): the ellipse's extent
    /// perpendicular to both the view and the tangent.
    pub fn width_across_m(&self, view: DVec3) -> f64 {
        let across = view.cross(self.tangent);
        let length = across.length();
        if length < 1e-12 {
            // Seen end-on: the larger diameter.
            return 2.0 * self.major.length().max(self.minor.length());
        }
        let across = across / length;
        2.0 * (self.major.dot(across).powi(2) + self.minor.dot(across).powi(2)).sqrt()
    }
}

/// One thick hair: the bundle strands it stands for and its cross-sections.
#[derive(Clone, Debug, PartialEq)]
pub struct ThickHair {
    /// Indices into the bundle's strands, ascending.
    pub members: Vec<u32>,
    /// The corner strands: nearest the `+major`, `-major`, `+minor` and `-minor` ends along
    /// the whole length.
    pub corners: [u32; 4],
    /// One per control point, root first.
    pub sections: Vec<CrossSection>,
}

impl ThickHair {
    /// Largest distance, over control points, between the PCA centre and the centre the
    /// four corner strands give.
    pub fn corner_fit_error_m(&self, strands: &[Vec<DVec3>]) -> f64 {
        self.sections
            .iter()
            .enumerate()
            .map(|(k, section)| {
                let corners = self.corners.map(|c| strands[c as usize][k]);
                let from_corners = CrossSection::from_corners(corners, section.tangent);
                (from_corners.centre - section.centre).length()
            })
            .fold(0.0, f64::max)
    }
}

/// A bundle's levels: `levels[0]` holds every grown strand alone, each next level thick hairs
/// of about [`AREA_RATIO_PER_LEVEL`] times the members, the last one thick hair.
#[derive(Clone, Debug, PartialEq)]
pub struct BundleHierarchy {
    pub levels: Vec<Vec<ThickHair>>,
}

/// Groups one bundle's `strands` (control points root first, the same count each) into
/// levels and fits every thick hair's cross-sections.
pub fn build_bundle_hierarchy(strands: &[Vec<DVec3>]) -> Result<BundleHierarchy, ThickHairError> {
    let all: Vec<u32> = (0..strands.len() as u32).collect();
    build_bundle_hierarchy_of(strands, &all)
}

/// [`build_bundle_hierarchy`] over the strands `grown` names (sorted, in range) only: a
/// strand the hairline op does not grow lies at its root and joins no thick hair (as a
/// corner it would pull the hair's centre onto the scalp). Indices still count every strand.
pub fn build_bundle_hierarchy_of(
    strands: &[Vec<DVec3>],
    grown: &[u32],
) -> Result<BundleHierarchy, ThickHairError> {
    check_strands(strands)?;
    let all: Vec<u32> = grown
        .iter()
        .copied()
        .filter(|&i| (i as usize) < strands.len())
        .collect();
    if all.is_empty() {
        return Ok(BundleHierarchy { levels: Vec::new() });
    }
    let tangents: Vec<Vec<DVec3>> = strands.iter().map(|s| strand_tangents(s)).collect();
    let mut levels = Vec::new();
    let mut most = 1usize;
    loop {
        let mut groups = Vec::new();
        split_into(strands, all.clone(), most, &mut groups);
        groups.sort_by_key(|g| g[0]);
        let level: Vec<ThickHair> = groups
            .into_iter()
            .map(|members| fit_thick_hair(strands, &tangents, members))
            .collect();
        let done = level.len() == 1;
        levels.push(level);
        if done {
            break;
        }
        most = most.saturating_mul(AREA_RATIO_PER_LEVEL);
    }
    Ok(BundleHierarchy { levels })
}

/// Every bundle's hierarchy for `hair` as the runtime draws it at full detail
/// (`vertex_count` control points per strand, styling included), in atlas block order;
/// strand indices count a bundle's grown strands in the GPU's root order.
pub fn build_hierarchy(
    hair: &crate::runtime::hair::RuntimeHair,
    vertex_count: usize,
) -> Result<Vec<BundleHierarchy>, ThickHairError> {
    let strands = crate::runtime::strand_gen::runtime_strands(
        hair,
        vertex_count,
        crate::runtime::strand_gen::Filtering::Exact,
    );
    // Per block: its strands' points, and which of them grow (the hairline op leaves some at
    // their root). Blocks by root number, so a block that grows none (density 0) keeps its
    // place and every later block its own.
    let per_bundle = hair.strands_per_bundle.max(1) as usize;
    let mut by_block: Vec<(Vec<Vec<DVec3>>, Vec<u32>)> =
        vec![(Vec::new(), Vec::new()); hair.textures.atlas.blocks.len()];
    for strand in strands {
        if let Some((points, grown)) = by_block.get_mut(strand.root as usize / per_bundle) {
            if strand.length_fraction > 0.0 {
                grown.push(points.len() as u32);
            }
            points.push(strand.points);
        }
    }
    by_block
        .iter()
        .map(|(strands, grown)| build_bundle_hierarchy_of(strands, grown))
        .collect()
}

/// One level of one bundle in [`FarHair`]: its thick hairs `thick_hairs[first..][..count]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FarLevel {
    pub first: u32,
    pub count: u32,
    /// The largest diameter (twice the major half-axis) of any of its thick hairs at any
    /// control point: the widest it can look from anywhere.
    pub widest_m: f64,
}

/// Far hair's hierarchy as the GPU draws it: every thick hair of every bundle's levels from
/// 1 up (level 0 is the strands themselves), flat, with each bundle's levels.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FarHair {
    pub thick_hairs: Vec<crate::runtime::gpu_types::ThickHairGpu>,
    /// Per atlas block, its levels from 1 up (`levels[j − 1]` is level `j`); empty for a
    /// bundle of one strand.
    pub blocks: Vec<Vec<FarLevel>>,
}

impl FarHair {
    /// The table of `hierarchies` (one per atlas block, from [`build_hierarchy`]) for a hair
    /// with `per_bundle` roots per bundle.
    pub fn new(hierarchies: &[BundleHierarchy], per_bundle: u32) -> Self {
        let mut far = FarHair::default();
        for (block, hierarchy) in hierarchies.iter().enumerate() {
            let first_root = block as u32 * per_bundle;
            let mut levels = Vec::new();
            for (level, hairs) in hierarchy.levels.iter().enumerate().skip(1) {
                let first = far.thick_hairs.len() as u32;
                let mut widest_m = 0.0f64;
                for hair in hairs {
                    for section in &hair.sections {
                        widest_m = widest_m.max(2.0 * section.major.length());
                    }
                    far.thick_hairs
                        .push(crate::runtime::gpu_types::ThickHairGpu {
                            corners: hair.corners.map(|c| first_root + c),
                            members: hair.members.len() as u32,
                            block: block as u32,
                            level: level as u32,
                            _padding: 0,
                        });
                }
                levels.push(FarLevel {
                    first,
                    count: hairs.len() as u32,
                    widest_m,
                });
            }
            far.blocks.push(levels);
        }
        far
    }

    /// The level block `block` draws when a pixel spans `pixel_m` at its distance: the
    /// coarsest whose widest thick hair is at most `width_threshold_px` pixels wide (seed 001
    /// §5.1 step 5, ε_w), or 0 (the strands) when even level 1 is wider. Non-finite or
    /// non-positive inputs draw the strands.
    pub fn level_for(&self, block: usize, pixel_m: f64, width_threshold_px: f64) -> usize {
        let Some(levels) = self.blocks.get(block) else {
            return 0;
        };
        if !(pixel_m > 0.0 && pixel_m.is_finite() && width_threshold_px > 0.0) {
            return 0;
        }
        levels
            .iter()
            .rposition(|level| level.widest_m <= width_threshold_px * pixel_m)
            .map_or(0, |j| j + 1)
    }
}

/// The far-hair file of a runtime bundle (`far_hair.HASH.bin`, `docs/runtime-format.md`):
/// a 24-byte header (`"HLFH"`, version 1, blocks, level entries, thick hairs, 0), the level
/// entries (block, first, count: u32; widest diameter: f32 — each block's levels from 1 up,
/// blocks ascending), then the thick hairs as [`ThickHairGpu`](crate::runtime::gpu_types::ThickHairGpu)
/// (32 bytes), all little-endian.
pub const FAR_HAIR_MAGIC: [u8; 4] = *b"HLFH";
/// Version of the far-hair file layout.
pub const FAR_HAIR_FILE_VERSION: u32 = 1;
const FAR_HAIR_HEADER_BYTES: usize = 24;
const FAR_LEVEL_BYTES: usize = 16;
const THICK_HAIR_BYTES: usize = 32;

impl FarHair {
    /// The table of `hair` as the runtime draws it at full detail with `vertex_count`
    /// control points per strand (what an export stores).
    pub fn build(
        hair: &crate::runtime::hair::RuntimeHair,
        vertex_count: usize,
    ) -> Result<Self, ThickHairError> {
        Ok(Self::new(
            &build_hierarchy(hair, vertex_count)?,
            hair.strands_per_bundle,
        ))
    }

    /// The far-hair file's bytes (see [`FAR_HAIR_MAGIC`]).
    pub fn to_bytes(&self) -> Vec<u8> {
        let levels: usize = self.blocks.iter().map(Vec::len).sum();
        let mut out = Vec::with_capacity(
            FAR_HAIR_HEADER_BYTES
                + levels * FAR_LEVEL_BYTES
                + self.thick_hairs.len() * THICK_HAIR_BYTES,
        );
        out.extend_from_slice(&FAR_HAIR_MAGIC);
        for word in [
            FAR_HAIR_FILE_VERSION,
            self.blocks.len() as u32,
            levels as u32,
            self.thick_hairs.len() as u32,
            0,
        ] {
            out.extend_from_slice(&word.to_le_bytes());
        }
        for (block, block_levels) in self.blocks.iter().enumerate() {
            for level in block_levels {
                for word in [block as u32, level.first, level.count] {
                    out.extend_from_slice(&word.to_le_bytes());
                }
                out.extend_from_slice(&(level.widest_m as f32).to_le_bytes());
            }
        }
        for hair in &self.thick_hairs {
            out.extend_from_slice(bytemuck::bytes_of(hair));
        }
        out
    }

    /// Reads and checks a far-hair file for a bundle whose blocks grow `grown[b]` of
    /// `per_bundle` strands each: sizes, every level inside the table, every thick hair in
    /// its block's level with corners among the block's grown strands and a member count the
    /// block can have. The message names the first problem.
    pub fn from_bytes(bytes: &[u8], grown: &[u32], per_bundle: u32) -> Result<Self, String> {
        let word = |at: usize| -> u32 {
            u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        };
        if bytes.len() < FAR_HAIR_HEADER_BYTES || bytes[..4] != FAR_HAIR_MAGIC {
            return Err("not a far-hair file (no \"HLFH\" header)".into());
        }
        if word(4) != FAR_HAIR_FILE_VERSION {
            return Err(format!(
                "far-hair file version {} is not supported (this build reads {FAR_HAIR_FILE_VERSION})",
                word(4)
            ));
        }
        let (blocks, level_count, hair_count) =
            (word(8) as usize, word(12) as usize, word(16) as usize);
        if blocks != grown.len() {
            return Err(format!(
                "the file has {blocks} bundles, the manifest {}",
                grown.len()
            ));
        }
        // Sizes first, in u64, so that hostile counts cannot overflow or allocate.
        let expected = FAR_HAIR_HEADER_BYTES as u64
            + level_count as u64 * FAR_LEVEL_BYTES as u64
            + hair_count as u64 * THICK_HAIR_BYTES as u64;
        if bytes.len() as u64 != expected {
            return Err(format!(
                "{} bytes where {level_count} levels and {hair_count} thick hairs take {expected}",
                bytes.len()
            ));
        }
        let mut far = FarHair {
            thick_hairs: Vec::with_capacity(hair_count),
            blocks: vec![Vec::new(); blocks],
        };
        let hairs_at = FAR_HAIR_HEADER_BYTES + level_count * FAR_LEVEL_BYTES;
        for i in 0..hair_count {
            let at = hairs_at + i * THICK_HAIR_BYTES;
            far.thick_hairs.push(bytemuck::pod_read_unaligned(
                &bytes[at..at + THICK_HAIR_BYTES],
            ));
        }
        let mut last_block = 0;
        // Levels tile the thick hairs in order, so every record is checked once.
        let mut next = 0u64;
        for i in 0..level_count {
            let at = FAR_HAIR_HEADER_BYTES + i * FAR_LEVEL_BYTES;
            let (block, first, count) = (word(at) as usize, word(at + 4), word(at + 8));
            let widest_m = f32::from_le_bytes([
                bytes[at + 12],
                bytes[at + 13],
                bytes[at + 14],
                bytes[at + 15],
            ]) as f64;
            if block >= blocks || block < last_block {
                return Err(format!(
                    "level entry {i}: bundle {block} is out of order or past the {blocks} bundles"
                ));
            }
            last_block = block;
            if count == 0 || first as u64 != next || next + count as u64 > hair_count as u64 {
                return Err(format!(
                    "level entry {i}: thick hairs {first}..{} do not follow on from {next} inside the {hair_count} in the file",
                    first as u64 + count as u64
                ));
            }
            next += count as u64;
            if !(widest_m.is_finite() && widest_m >= 0.0) {
                return Err(format!("level entry {i}: widest diameter {widest_m} m"));
            }
            far.blocks[block].push(FarLevel {
                first,
                count,
                widest_m,
            });
            let level = far.blocks[block].len() as u32;
            for (j, hair) in far.thick_hairs[first as usize..][..count as usize]
                .iter()
                .enumerate()
            {
                let t = first as usize + j;
                if hair.block as usize != block || hair.level != level {
                    return Err(format!(
                        "thick hair {t}: says bundle {} level {}, listed under bundle {block} level {level}",
                        hair.block, hair.level
                    ));
                }
                if hair.members == 0 || hair.members > grown[block] {
                    return Err(format!(
                        "thick hair {t}: {} members in a bundle growing {}",
                        hair.members, grown[block]
                    ));
                }
                for corner in hair.corners {
                    let (owner, sample) = (corner / per_bundle.max(1), corner % per_bundle.max(1));
                    if owner as usize != block || sample >= grown[block] {
                        return Err(format!(
                            "thick hair {t}: corner root {corner} is not a grown strand of bundle {block}"
                        ));
                    }
                }
            }
        }
        if next != hair_count as u64 {
            return Err(format!(
                "the levels list {next} of the {hair_count} thick hairs in the file"
            ));
        }
        Ok(far)
    }
}

fn check_strands(strands: &[Vec<DVec3>]) -> Result<(), ThickHairError> {
    let Some(first) = strands.first() else {
        return Ok(());
    };
    let expected = first.len();
    if expected < 2 {
        return Err(ThickHairError::TooFewControlPoints(expected));
    }
    for (strand, points) in strands.iter().enumerate() {
        if points.len() != expected {
            return Err(ThickHairError::ControlPointCount {
                strand,
                found: points.len(),
                expected,
            });
        }
        if let Some((point, p)) = points.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(ThickHairError::NotFinite {
                strand,
                point,
                value: p.to_array(),
            });
        }
    }
    Ok(())
}

/// Unit tangents by central differences (one-sided at the ends); zero where the strand does
/// not move.
fn strand_tangents(points: &[DVec3]) -> Vec<DVec3> {
    let last = points.len() - 1;
    (0..=last)
        .map(|k| (points[(k + 1).min(last)] - points[k.saturating_sub(1)]).normalize_or_zero())
        .collect()
}

/// Splits `members` at the median of their projections on the principal axis of the whole
/// strands (the seed's `D(i, j)`: all control points at once) until each group has at most
/// `most` strands.
fn split_into(strands: &[Vec<DVec3>], members: Vec<u32>, most: usize, out: &mut Vec<Vec<u32>>) {
    if members.len() <= most {
        out.push(members);
        return;
    }
    let axis = principal_strand_axis(strands, &members);
    let mut keyed: Vec<(f64, u32)> = members
        .iter()
        .map(|&i| {
            let projection: f64 = strands[i as usize]
                .iter()
                .zip(&axis)
                .map(|(p, a)| p.dot(*a))
                .sum();
            (projection, i)
        })
        .collect();
    // Ties (coincident strands) fall back on the index: deterministic halves.
    keyed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut low: Vec<u32> = keyed[..keyed.len() / 2].iter().map(|k| k.1).collect();
    let mut high: Vec<u32> = keyed[keyed.len() / 2..].iter().map(|k| k.1).collect();
    low.sort_unstable();
    high.sort_unstable();
    split_into(strands, low, most, out);
    split_into(strands, high, most, out);
}

/// The direction of largest spread of `members` as whole strands (one 3-vector per control
/// point, unit overall), by power iteration on their covariance; a fixed direction where
/// they do not spread.
fn principal_strand_axis(strands: &[Vec<DVec3>], members: &[u32]) -> Vec<DVec3> {
    let n = strands[members[0] as usize].len();
    let count = members.len() as f64;
    let mean: Vec<DVec3> = (0..n)
        .map(|k| {
            members
                .iter()
                .map(|&i| strands[i as usize][k])
                .sum::<DVec3>()
                / count
        })
        .collect();
    let centred = |i: u32, k: usize| strands[i as usize][k] - mean[k];
    // Start from the member farthest from the mean: never orthogonal to a real spread.
    let far = members
        .iter()
        .copied()
        .max_by(|&a, &b| {
            let d = |i| (0..n).map(|k| centred(i, k).length_squared()).sum::<f64>();
            d(a).total_cmp(&d(b)).then(b.cmp(&a))
        })
        .unwrap_or(members[0]);
    let mut axis: Vec<DVec3> = (0..n).map(|k| centred(far, k)).collect();
    for _ in 0..24 {
        let norm = axis.iter().map(|a| a.length_squared()).sum::<f64>().sqrt();
        if norm < 1e-300 {
            break;
        }
        axis.iter_mut().for_each(|a| *a /= norm);
        let mut next = vec![DVec3::ZERO; n];
        for &i in members {
            let projection: f64 = (0..n).map(|k| centred(i, k).dot(axis[k])).sum();
            for (k, value) in next.iter_mut().enumerate() {
                *value += centred(i, k) * projection;
            }
        }
        axis = next;
    }
    let norm = axis.iter().map(|a| a.length_squared()).sum::<f64>().sqrt();
    if norm < 1e-300 || !norm.is_finite() {
        // No spread at all (coincident strands): any split is as good.
        return vec![DVec3::X; n];
    }
    axis.into_iter().map(|a| a / norm).collect()
}

fn fit_thick_hair(strands: &[Vec<DVec3>], tangents: &[Vec<DVec3>], members: Vec<u32>) -> ThickHair {
    let n = strands[members[0] as usize].len();
    let sections: Vec<CrossSection> = (0..n)
        .map(|k| {
            let points: Vec<DVec3> = members.iter().map(|&i| strands[i as usize][k]).collect();
            let tangent = members
                .iter()
                .map(|&i| tangents[i as usize][k])
                .sum::<DVec3>();
            fit_cross_section(&points, tangent)
        })
        .collect();
    // The corner strands: nearest each axis end summed over the length.
    let ends: [fn(&CrossSection) -> DVec3; 4] = [
        |s| s.centre + s.major,
        |s| s.centre - s.major,
        |s| s.centre + s.minor,
        |s| s.centre - s.minor,
    ];
    let corners = ends.map(|end| {
        members
            .iter()
            .copied()
            .min_by(|&a, &b| {
                let miss = |i: u32| {
                    sections
                        .iter()
                        .enumerate()
                        .map(|(k, s)| (strands[i as usize][k] - end(s)).length_squared())
                        .sum::<f64>()
                };
                miss(a).total_cmp(&miss(b)).then(a.cmp(&b))
            })
            .unwrap_or(members[0])
    });
    ThickHair {
        members,
        corners,
        sections,
    }
}

/// The ellipse of `points` across `tangent` (any length; a zero tangent takes the points'
/// own longest axis as the direction along the hair): PCA of the points, the eigenvector
/// nearest the tangent dropped, the two kept axes scaled to cover every point. One point,
/// coincident or collinear points give zero-length axes where there is no spread, never a
/// NaN.
pub fn fit_cross_section(points: &[DVec3], tangent: DVec3) -> CrossSection {
    let count = points.len().max(1) as f64;
    let centre = points.iter().sum::<DVec3>() / count;
    let mut covariance = DMat3::ZERO;
    for p in points {
        let d = *p - centre;
        covariance += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
    }
    covariance *= 1.0 / count;
    let (values, vectors) = symmetric_eigen(covariance);
    let tangent = tangent.normalize_or_zero();
    // The axis along the hair: nearest the tangent, or without one the longest.
    let along = if tangent == DVec3::ZERO {
        (0..3)
            .max_by(|&a, &b| values[a].total_cmp(&values[b]))
            .unwrap_or(0)
    } else {
        (0..3)
            .max_by(|&a, &b| {
                vectors[a]
                    .dot(tangent)
                    .abs()
                    .total_cmp(&vectors[b].dot(tangent).abs())
            })
            .unwrap_or(0)
    };
    let tangent = if tangent == DVec3::ZERO {
        vectors[along]
    } else {
        tangent
    };
    let mut kept: Vec<usize> = (0..3).filter(|&i| i != along).collect();
    kept.sort_by(|&a, &b| values[b].total_cmp(&values[a]));
    // Across the hair exactly: the kept axes with the tangent taken out, orthonormal.
    let first = (vectors[kept[0]] - tangent * vectors[kept[0]].dot(tangent)).normalize_or_zero();
    let (first, second) = if first == DVec3::ZERO {
        let (a, b) = tangent.any_orthonormal_pair();
        (a, b)
    } else {
        (first, tangent.cross(first).normalize_or_zero())
    };
    let reach = |axis: DVec3| {
        points
            .iter()
            .map(|p| (*p - centre).dot(axis).abs())
            .fold(0.0, f64::max)
    };
    let (a, b) = (reach(first), reach(second));
    let (major, minor) = if a >= b {
        (first * a, second * b)
    } else {
        (second * b, first * a)
    };
    CrossSection {
        centre,
        tangent,
        major,
        minor,
    }
}

/// Eigenvalues and unit eigenvectors of a symmetric 3 × 3 matrix by cyclic Jacobi rotations
/// (a dozen sweeps reach f64 precision for 3 × 3; glam has no eigensolver, and a linear
/// algebra crate for one 3 × 3 is more than the problem).
fn symmetric_eigen(m: DMat3) -> ([f64; 3], [DVec3; 3]) {
    let mut a = m.to_cols_array_2d();
    let mut v = DMat3::IDENTITY.to_cols_array_2d();
    for _ in 0..16 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        let scale = a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2);
        if off <= 1e-30 * scale.max(1e-300) || !off.is_finite() {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q].abs() < 1e-300 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J on rows/columns p and q.
            for row in &mut a {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (row_p, row_q) = (a[p], a[q]);
            for (k, (apk, aqk)) in row_p.into_iter().zip(row_q).enumerate() {
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    // `v` holds the eigenvectors as its columns (stored column-major: v[col][row]).
    let vectors = DMat3::from_cols_array_2d(&v).transpose();
    let vectors = [vectors.x_axis, vectors.y_axis, vectors.z_axis].map(DVec3::normalize_or_zero);
    ([a[0][0], a[1][1], a[2][2]], vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `m` parallel strands along +z on an ellipse of half-axes 3 and 1 (x, y), `n` points.
    fn elliptic_bundle(m: usize, n: usize) -> Vec<Vec<DVec3>> {
        (0..m)
            .map(|i| {
                let angle = std::f64::consts::TAU * i as f64 / m as f64;
                let ring = 0.3 + 0.7 * ((i * 7) % 5) as f64 / 4.0;
                let base = DVec3::new(3.0 * ring * angle.cos(), ring * angle.sin(), 0.0);
                (0..n)
                    .map(|k| base + DVec3::new(0.0, 0.0, k as f64))
                    .collect()
            })
            .collect()
    }

    #[test]
    fn strands_that_do_not_grow_join_no_thick_hair() {
        // 24 strands; every third lies at its root (the hairline op does not grow it).
        let mut strands = elliptic_bundle(24, 5);
        for strand in strands.iter_mut().step_by(3) {
            let root = strand[0];
            strand.iter_mut().for_each(|p| *p = root);
        }
        let grown: Vec<u32> = (0..24).filter(|i| i % 3 != 0).collect();
        let hierarchy = build_bundle_hierarchy_of(&strands, &grown).expect("builds");
        for level in &hierarchy.levels {
            let mut members: Vec<u32> = level.iter().flat_map(|h| h.members.clone()).collect();
            members.sort_unstable();
            assert_eq!(members, grown, "each level holds the grown strands once");
            for hair in level {
                assert!(hair.corners.iter().all(|c| grown.contains(c)));
            }
        }
        assert_eq!(hierarchy.levels.last().map(Vec::len), Some(1));
        // None grown: no levels, as for an empty bundle.
        let none = build_bundle_hierarchy_of(&strands, &[]).expect("builds");
        assert!(none.levels.is_empty());
    }

    #[test]
    fn the_eigen_solver_recovers_a_rotated_ellipsoid() {
        let rotation = DMat3::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1);
        let m = rotation * DMat3::from_diagonal(DVec3::new(9.0, 4.0, 0.25)) * rotation.transpose();
        let (values, vectors) = symmetric_eigen(m);
        let mut sorted = values;
        sorted.sort_by(f64::total_cmp);
        for (got, want) in sorted.iter().zip([0.25, 4.0, 9.0]) {
            assert!((got - want).abs() < 1e-9, "{values:?}");
        }
        for (value, vector) in values.iter().zip(vectors) {
            let residual = (m * vector - vector * *value).length();
            assert!(residual < 1e-9, "{residual}");
            assert!((vector.length() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn an_elliptic_cluster_fits_its_ellipse_across_the_tangent() {
        let strands = elliptic_bundle(40, 5);
        let points: Vec<DVec3> = strands.iter().map(|s| s[2]).collect();
        let section = fit_cross_section(&points, DVec3::Z);
        assert!(section.centre.truncate().length() < 0.2, "{section:?}");
        // The major axis lies along x, about 3 long; the minor along y, about 1.
        assert!(
            section.major.normalize().dot(DVec3::X).abs() > 0.99,
            "{section:?}"
        );
        assert!((section.major.length() - 3.0).abs() < 0.35, "{section:?}");
        assert!((section.minor.length() - 1.0).abs() < 0.2, "{section:?}");
        assert!(section.major.dot(DVec3::Z).abs() < 1e-9);
        assert!(section.minor.dot(section.major).abs() < 1e-9);
        // Every member lies inside its ellipse.
        for p in &points {
            let d = *p - section.centre;
            let (x, y) = (
                d.dot(section.major) / section.major.length_squared(),
                d.dot(section.minor) / section.minor.length_squared(),
            );
            assert!(x.abs() <= 1.0 + 1e-9 && y.abs() <= 1.0 + 1e-9);
        }
        // Seen along y the hair is about 6 wide, along x about 2.
        assert!((section.width_across_m(DVec3::Y) - 2.0 * section.major.length()).abs() < 1e-9);
        assert!((section.width_across_m(DVec3::X) - 2.0 * section.minor.length()).abs() < 1e-9);
    }

    #[test]
    fn degenerate_clusters_stay_finite() {
        let finite = |s: &CrossSection| {
            s.centre.is_finite()
                && s.tangent.is_finite()
                && s.major.is_finite()
                && s.minor.is_finite()
        };
        let p = DVec3::new(1.0, 2.0, 3.0);
        for (name, points, tangent) in [
            ("one strand", vec![p], DVec3::Z),
            ("coincident", vec![p; 9], DVec3::Z),
            (
                "collinear across",
                (0..5).map(|i| p + DVec3::X * i as f64).collect(),
                DVec3::Z,
            ),
            (
                "collinear along",
                (0..5).map(|i| p + DVec3::Z * i as f64).collect(),
                DVec3::Z,
            ),
            (
                "no tangent",
                (0..5).map(|i| p + DVec3::X * i as f64).collect(),
                DVec3::ZERO,
            ),
            (
                "flat",
                vec![p, p + DVec3::X, p - DVec3::X, p + DVec3::X * 1e-12],
                DVec3::Z,
            ),
            ("empty", vec![], DVec3::Y),
        ] {
            let section = fit_cross_section(&points, tangent);
            assert!(finite(&section), "{name}: {section:?}");
            assert!(
                (section.tangent.length() - 1.0).abs() < 1e-9 || points.is_empty(),
                "{name}"
            );
            assert!(section.major.length() >= section.minor.length(), "{name}");
        }
        // Collinear across the hair: a line of half-length 2, no minor axis.
        let line: Vec<DVec3> = (0..5).map(|i| DVec3::X * i as f64).collect();
        let section = fit_cross_section(&line, DVec3::Z);
        assert!((section.major.length() - 2.0).abs() < 1e-9);
        assert!(section.minor.length() < 1e-9);
    }

    #[test]
    fn levels_grow_four_times_and_nest_down_to_one_hair() {
        let strands = elliptic_bundle(64, 6);
        let hierarchy = build_bundle_hierarchy(&strands).expect("builds");
        let sizes: Vec<usize> = hierarchy.levels.iter().map(Vec::len).collect();
        assert_eq!(sizes, vec![64, 16, 4, 1]);
        for (level, hairs) in hierarchy.levels.iter().enumerate() {
            // Every strand in exactly one thick hair per level.
            let mut all: Vec<u32> = hairs.iter().flat_map(|h| h.members.clone()).collect();
            all.sort_unstable();
            assert_eq!(all, (0..64).collect::<Vec<u32>>(), "level {level}");
            for hair in hairs {
                assert_eq!(hair.members.len(), 4usize.pow(level as u32));
                assert_eq!(hair.sections.len(), 6);
                assert!(hair.corners.iter().all(|c| hair.members.contains(c)));
            }
            // Nested: each thick hair is a union of hairs of the level below.
            if level > 0 {
                for hair in hairs {
                    for finer in &hierarchy.levels[level - 1] {
                        let inside = finer.members.iter().filter(|m| hair.members.contains(m));
                        let count = inside.count();
                        assert!(count == 0 || count == finer.members.len(), "level {level}");
                    }
                }
            }
        }
        // The coarsest hair covers the bundle's ellipse, and its corner strands give back its
        // centre within a fraction of its size.
        let top = &hierarchy.levels[3][0];
        let error = top.corner_fit_error_m(&strands);
        assert!(error < 0.5, "corner centre off by {error}");
        assert!(top.sections[0].major.length() > 2.0);
    }

    /// A thick hair follows the hair mesh as its corner strands do: after the mesh bends,
    /// the centre its four corner strands give is as close to a fresh PCA fit of the moved
    /// members as it was before the bend — no refit is needed per frame.
    #[test]
    fn a_hierarchy_follows_a_bent_hair_mesh_through_its_corner_strands() {
        use crate::model::document::Document;
        use crate::runtime::hair::{RuntimeHair, RuntimeOptions};
        use crate::runtime::strand_gen::{Filtering, runtime_strands};
        use crate::samples::{grid_scalp, straight_layers};
        let scalp = grid_scalp(2, 2, |x, y| DVec3::new(x * 0.02, y * 0.02, 0.0));
        let mut document = Document::new("grid", straight_layers(scalp, 4, DVec3::Z * 0.02));
        let options = RuntimeOptions {
            strands_per_bundle: 64,
            ..RuntimeOptions::default()
        };
        let n = 9;
        let points = |document: &Document| -> Vec<Vec<DVec3>> {
            let hair = RuntimeHair::from_document(document, &options);
            runtime_strands(&hair, n, Filtering::Exact)
                .into_iter()
                .map(|s| s.points)
                .collect()
        };
        let modelled = points(&document);
        let hierarchies =
            build_hierarchy(&RuntimeHair::from_document(&document, &options), n).expect("builds");
        assert!(!hierarchies.is_empty());
        // Bend every column sideways, more toward the tips.
        for column in &mut document.hair_mesh.columns {
            for (k, p) in column.positions.iter_mut().enumerate() {
                p.x += 0.004 * (k * k) as f64;
            }
        }
        let bent = points(&document);
        assert_eq!(bent.len(), modelled.len());
        let corner_miss = |top: &ThickHair, block: &[Vec<DVec3>], k: usize| {
            let members: Vec<DVec3> = top.members.iter().map(|&i| block[i as usize][k]).collect();
            let tangent = top
                .members
                .iter()
                .map(|&i| strand_tangents(&block[i as usize])[k])
                .sum::<DVec3>();
            let refit = fit_cross_section(&members, tangent);
            let corners = top.corners.map(|c| block[c as usize][k]);
            (CrossSection::from_corners(corners, refit.tangent).centre - refit.centre).length()
        };
        let mut first = 0;
        let mut moved_m = 0.0f64;
        for hierarchy in &hierarchies {
            let count = hierarchy.levels[0].len();
            let range = first..first + count;
            first += count;
            let top = hierarchy
                .levels
                .last()
                .and_then(|l| l.first())
                .expect("a top hair");
            let size = top.sections[0].major.length().max(1e-6);
            for k in 0..n {
                let before = corner_miss(top, &modelled[range.clone()], k);
                let after = corner_miss(top, &bent[range.clone()], k);
                assert!(
                    after <= before + 0.05 * size,
                    "control point {k}: the corners miss by {after} m after the bend, {before} m before (hair {size} m)"
                );
                moved_m = moved_m.max((bent[range.start][k] - modelled[range.start][k]).length());
            }
        }
        assert!(
            moved_m > 0.01,
            "the bend moved the strands by only {moved_m} m"
        );
    }

    /// A block that grows no strand (density 0, a painted bald patch) keeps its place: the
    /// blocks after it keep their own hierarchies, and the file loads back.
    #[test]
    fn a_bald_block_keeps_every_later_blocks_hierarchy() {
        use crate::model::document::Document;
        use crate::runtime::hair::{RuntimeHair, RuntimeOptions};
        use crate::samples::{grid_scalp, straight_layers};
        let scalp = grid_scalp(3, 1, |x, y| DVec3::new(x * 0.03, y * 0.01, 0.0));
        let mut document = Document::new("grid", straight_layers(scalp, 2, DVec3::Z * 0.02));
        document.hair_mesh.bundles[1].density = 0.0;
        let per_bundle = 16;
        let hair = RuntimeHair::from_document(
            &document,
            &RuntimeOptions {
                strands_per_bundle: per_bundle,
                ..RuntimeOptions::default()
            },
        );
        let hierarchies = build_hierarchy(&hair, 5).expect("builds");
        assert_eq!(hierarchies.len(), hair.textures.atlas.blocks.len());
        assert!(hierarchies[1].levels.is_empty(), "the bald block has none");
        assert!(
            !hierarchies[2].levels.is_empty(),
            "the last block keeps its own"
        );
        let table = FarHair::new(&hierarchies, per_bundle);
        let grown: Vec<u32> = (0..hierarchies.len())
            .map(|b| hair.block_strand_count(b))
            .collect();
        let loaded = FarHair::from_bytes(&table.to_bytes(), &grown, per_bundle).expect("loads");
        // The file holds widths in f32.
        assert_eq!(loaded.thick_hairs, table.thick_hairs);
        let counts = |far: &FarHair| -> Vec<Vec<(u32, u32)>> {
            far.blocks
                .iter()
                .map(|levels| levels.iter().map(|l| (l.first, l.count)).collect())
                .collect()
        };
        assert_eq!(counts(&loaded), counts(&table));
    }

    #[test]
    fn the_far_hair_table_names_corner_strands_and_picks_levels_by_width() {
        use crate::model::document::Document;
        use crate::runtime::hair::{RuntimeHair, RuntimeOptions};
        use crate::runtime::strand_gen::{Filtering, StrandGen, runtime_strands};
        use crate::samples::{grid_scalp, straight_layers};
        let scalp = grid_scalp(2, 2, |x, y| DVec3::new(x * 0.02, y * 0.02, 0.0));
        let document = Document::new("grid", straight_layers(scalp, 4, DVec3::Z * 0.02));
        let per_bundle = 64;
        let hair = RuntimeHair::from_document(
            &document,
            &RuntimeOptions {
                strands_per_bundle: per_bundle,
                ..RuntimeOptions::default()
            },
        );
        let n = 9;
        let hierarchies = build_hierarchy(&hair, n).expect("builds");
        let table = FarHair::new(&hierarchies, per_bundle);
        assert_eq!(table.blocks.len(), hierarchies.len());
        for (block, (levels, hierarchy)) in table.blocks.iter().zip(&hierarchies).enumerate() {
            // Levels 1.. of 64 strands: 16, 4 and 1 thick hairs, each wider than the last.
            let counts: Vec<u32> = levels.iter().map(|l| l.count).collect();
            assert_eq!(counts, [16, 4, 1]);
            assert_eq!(levels.len(), hierarchy.levels.len() - 1);
            for pair in levels.windows(2) {
                assert!(pair[1].widest_m > pair[0].widest_m, "{levels:?}");
            }
            for (j, level) in levels.iter().enumerate() {
                let hairs = &table.thick_hairs[level.first as usize..][..level.count as usize];
                for (thick, fitted) in hairs.iter().zip(&hierarchy.levels[j + 1]) {
                    assert_eq!(thick.block as usize, block);
                    assert_eq!(thick.level as usize, j + 1);
                    assert_eq!(thick.members as usize, fitted.members.len());
                    assert_eq!(
                        thick.corners,
                        fitted.corners.map(|c| block as u32 * per_bundle + c)
                    );
                }
            }
            // ε_w picks the coarsest level under it: a pixel so large that everything is
            // thin draws one hair; one so small that nothing is draws the strands; between
            // two levels' widths, the finer.
            let threshold = 2.0;
            assert_eq!(table.level_for(block, 1.0, threshold), levels.len());
            assert_eq!(table.level_for(block, 1e-9, threshold), 0);
            for j in 0..levels.len() - 1 {
                let between = 0.5 * (levels[j].widest_m + levels[j + 1].widest_m);
                assert_eq!(
                    table.level_for(block, between / threshold, threshold),
                    j + 1
                );
            }
            for bad in [f64::NAN, 0.0, -1.0, f64::INFINITY] {
                assert_eq!(table.level_for(block, bad, threshold), 0);
            }
        }
        assert_eq!(table.level_for(table.blocks.len(), 1.0, 2.0), 0);
        // The GPU's thick hair (its corner strands' centre and half-axes) is the corners'
        // section of the strands as drawn.
        let strands = runtime_strands(&hair, n, Filtering::Exact);
        let generator = StrandGen {
            textures: &hair.textures,
            filtering: Filtering::Exact,
        };
        let params = [&hair.styling.global];
        let vertices =
            generator.thick_main(&hair.strand_roots(), &table.thick_hairs, n as u32, &params);
        let size = document.hair_mesh.size();
        for (t, thick) in table.thick_hairs.iter().enumerate() {
            for k in 0..n {
                let corners = thick.corners.map(|c| {
                    let block = (c / per_bundle) as usize;
                    let first: usize = (0..block)
                        .map(|b| hair.block_strand_count(b) as usize)
                        .sum();
                    strands[first + (c % per_bundle) as usize].points[k]
                });
                let section = CrossSection::from_corners(corners, DVec3::Z);
                let vertex = &vertices[t * n + k];
                assert!((vertex.centre.as_dvec3() - section.centre).length() < 1e-6 * size);
                assert!((vertex.major.as_dvec3() - section.major).length() < 1e-6 * size);
                assert!((vertex.minor.as_dvec3() - section.minor).length() < 1e-6 * size);
            }
        }
    }

    #[test]
    fn odd_counts_coincident_strands_and_bad_input() {
        for m in [1usize, 2, 3, 5, 17, 100] {
            let hierarchy = build_bundle_hierarchy(&elliptic_bundle(m, 3)).expect("builds");
            assert_eq!(
                hierarchy.levels.last().map(Vec::len),
                Some(1),
                "{m} strands"
            );
            assert_eq!(hierarchy.levels[0].len(), m);
            for hairs in &hierarchy.levels {
                assert!(hairs.iter().all(|h| h.members.len() <= 4usize.pow(6)));
            }
        }
        let same = vec![vec![DVec3::ONE, DVec3::ONE * 2.0]; 20];
        let hierarchy = build_bundle_hierarchy(&same).expect("coincident strands");
        for hair in hierarchy.levels.iter().flatten() {
            for s in &hair.sections {
                assert!(s.centre.is_finite() && s.major.is_finite() && s.minor.is_finite());
            }
        }
        assert_eq!(build_bundle_hierarchy(&[]).expect("empty").levels.len(), 0);
        let mut bad = elliptic_bundle(4, 3);
        bad[2][1].y = f64::NAN;
        assert!(matches!(
            build_bundle_hierarchy(&bad),
            Err(ThickHairError::NotFinite {
                strand: 2,
                point: 1,
                ..
            })
        ));
        let mut ragged = elliptic_bundle(4, 3);
        ragged[3].pop();
        assert!(matches!(
            build_bundle_hierarchy(&ragged),
            Err(ThickHairError::ControlPointCount {
                strand: 3,
                found: 2,
                expected: 3
            })
        ));
        assert_eq!(
            build_bundle_hierarchy(&[vec![DVec3::ZERO]]),
            Err(ThickHairError::TooFewControlPoints(1))
        );
    }
}
