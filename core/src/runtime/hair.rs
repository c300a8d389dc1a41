//! The runtime asset: everything a game (or our renderer) needs to generate a head of hair
//! on the GPU — the five textures, the root sample sets, each bundle's placement and styling
//! index, the styling parameters and the opaque body. Made from a document
//! ([`RuntimeHair::from_document`]), loaded from a runtime bundle
//! ([`crate::io::runtime_bundle::load_runtime_bundle`]) and written to one
//! ([`crate::io::runtime_bundle::bundle_files`]). The editor, the CLI, the exporter and the
//! tests all go through it; `render` uploads it.

use glam::Vec2;

use crate::model::document::{BodyMesh, Document};
use crate::model::scene::Scene;
use crate::model::styling::StylingSet;
use crate::runtime::atlas::{Atlas, BundleBlock};
use crate::runtime::gpu_types::StrandRoot;
use crate::runtime::textures::{Precision, RuntimeTextures};
use crate::strands::reference::sample_set_size;

/// Strands per bundle of an export or a project render when none is given.
pub const DEFAULT_STRANDS_PER_BUNDLE: u32 = 64;
/// Seed of the root sample sets an export writes by default.
pub const DEFAULT_SAMPLE_SEED: u64 = 1;
/// Vertices per strand at full detail of an export by default: 2^5 + 1.
pub const DEFAULT_MAX_VERTICES_LOG2: u32 = 5;

/// Level-of-detail parameters a runtime bundle carries (seed 000 eq. 7-12).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LodEntry {
    pub alpha_strands: f64,
    pub alpha_vertices: f64,
    pub lambda: f64,
    pub max_vertices_log2: u32,
}

impl Default for LodEntry {
    fn default() -> Self {
        Self {
            alpha_strands: crate::runtime::frame_plan::DEFAULT_ALPHA_STRANDS,
            alpha_vertices: crate::runtime::frame_plan::DEFAULT_ALPHA_VERTICES,
            lambda: crate::runtime::frame_plan::DEFAULT_LAMBDA,
            max_vertices_log2: DEFAULT_MAX_VERTICES_LOG2,
        }
    }
}

/// How a document becomes a runtime asset.
#[derive(Clone, Debug)]
pub struct RuntimeOptions {
    pub precision: Precision,
    pub strands_per_bundle: u32,
    pub lod: LodEntry,
    pub sample_seed: u64,
}

impl Default for RuntimeOptions {
    fn default() -> Self {
        Self {
            precision: Precision::F32,
            strands_per_bundle: DEFAULT_STRANDS_PER_BUNDLE,
            lod: LodEntry::default(),
            sample_seed: DEFAULT_SAMPLE_SEED,
        }
    }
}

/// One head of hair as the runtime sees it (see the module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct RuntimeHair {
    /// The five textures and the atlas: each block is one bundle's placement.
    pub textures: RuntimeTextures,
    pub samples: RootSamples,
    /// Strands per bundle at full detail (≤ the sample sets' length).
    pub strands_per_bundle: u32,
    /// Per atlas block: 0 = global styling, `g + 1` = group `g` of [`Self::styling`].
    pub block_styling: Vec<u32>,
    /// Per atlas block: the fraction of its strands that grow (`Bundle::density`, times the
    /// styling's per-area share at `strands_per_bundle`: [`crate::strands::lod::grown_share`]).
    pub block_density: Vec<f32>,
    /// Per atlas block: the artist's `Bundle::density` and its root face's area (model units
    /// squared), from which `block_density` is worked out again when the strand count or the
    /// styling changes. Empty for a loaded bundle, whose densities already hold the share.
    pub block_bundle_density: Vec<f32>,
    pub block_root_area: Vec<f64>,
    pub styling: StylingSet,
    /// Lights, material and effects: how the hair is meant to be seen.
    pub scene: Scene,
    pub lod: LodEntry,
    /// The opaque body the hair grows on (empty when there is none).
    pub body: BodyMesh,
    /// Where the hair came from (the document's source), carried into the manifest.
    pub source: String,
    /// Seed the sample sets were drawn from, when they were drawn here (a loaded bundle
    /// has only its stored sets).
    pub sample_seed: Option<u64>,
    /// Where fur grows (the root faces and columns, read from the textures), for the `fur`
    /// effect.
    pub fur_base: crate::fur::base::FurBase,
}

/// Why a runtime asset could not be made or changed.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RuntimeHairError {
    #[error("--strands-per-bundle {asked} is more than the bundle's {available} samples")]
    NotEnoughSamples { asked: u32, available: usize },
}

impl RuntimeHair {
    /// Vertices per strand (2^N + 1, as N) that draw this hair's styling as curves
    /// ([`crate::strands::styling::strand_vertices_log2`] over the largest w stored).
    pub fn strand_vertices_log2(&self) -> u32 {
        let longest_w = self
            .textures
            .w
            .texels
            .iter()
            .map(|t| t.x as f64)
            .filter(|w| w.is_finite())
            .fold(0.0, f64::max);
        crate::strands::styling::strand_vertices_log2(&self.styling, longest_w)
    }

    /// What exporting `document` with `options` produces.
    pub fn from_document(document: &Document, options: &RuntimeOptions) -> Self {
        let mut textures = RuntimeTextures::build(&document.hair_mesh, options.precision);
        textures.root_maps = document.root_maps.clone();
        let blocks = &textures.atlas.blocks;
        let bundle_of = |block: &crate::runtime::atlas::BundleBlock| {
            document.hair_mesh.bundles.get(block.bundle as usize)
        };
        let mut hair = Self {
            block_styling: block_styling(&textures, &document.styling),
            block_density: Vec::new(),
            block_bundle_density: blocks
                .iter()
                .map(|block| bundle_of(block).map_or(1.0, |b| b.density as f32))
                .collect(),
            block_root_area: blocks
                .iter()
                .map(|block| {
                    bundle_of(block).map_or(0.0, |b| document.hair_mesh.root_face_area(&b.vertices))
                })
                .collect(),
            textures,
            samples: RootSamples::default(),
            strands_per_bundle: 0,
            styling: document.styling.clone(),
            scene: document.scene.clone(),
            lod: options.lod.clone(),
            body: document.body.clone(),
            source: document.source.clone(),
            sample_seed: Some(options.sample_seed),
            fur_base: Default::default(),
        };
        hair.fur_base = crate::fur::base::FurBase::from_textures(&hair.textures);
        hair.draw_samples(options.strands_per_bundle, options.sample_seed);
        hair
    }

    fn draw_samples(&mut self, strands_per_bundle: u32, seed: u64) {
        self.samples = RootSamples::progressive(sample_set_size(strands_per_bundle), seed);
        self.strands_per_bundle = strands_per_bundle;
        self.update_block_density();
    }

    /// Works each block's grown share out again from the artist's density, the root face's
    /// area and the styling's per-area target at the current strand count (a loaded bundle,
    /// with no areas, keeps the shares it was written with).
    fn update_block_density(&mut self) {
        if self.block_root_area.len() != self.block_bundle_density.len()
            || self.block_root_area.len() != self.textures.atlas.blocks.len()
        {
            return;
        }
        self.block_density = (0..self.block_root_area.len())
            .map(|block| {
                let params = self
                    .styling
                    .params_for(self.textures.atlas.blocks[block].bundle);
                crate::strands::lod::grown_share(
                    self.block_bundle_density[block] as f64,
                    params.density.strands_per_cm2,
                    self.block_root_area[block],
                    self.strands_per_bundle,
                ) as f32
            })
            .collect();
    }

    /// Draws `strands_per_bundle` strands per bundle: from the sample set an export of that
    /// count would write when the samples were drawn here, else from the stored sets (which
    /// must be long enough).
    pub fn set_strands_per_bundle(
        &mut self,
        strands_per_bundle: u32,
    ) -> Result<(), RuntimeHairError> {
        match self.sample_seed {
            Some(seed) => self.draw_samples(strands_per_bundle, seed),
            None => {
                let available = self.samples.quad.len().min(self.samples.triangle.len());
                if strands_per_bundle as usize > available {
                    return Err(RuntimeHairError::NotEnoughSamples {
                        asked: strands_per_bundle,
                        available,
                    });
                }
                self.strands_per_bundle = strands_per_bundle;
                self.update_block_density();
            }
        }
        Ok(())
    }

    /// Takes new styling parameters (and group assignments) without touching the textures:
    /// what a styling-only edit changes.
    pub fn set_styling(&mut self, styling: &StylingSet) {
        self.block_styling = block_styling(&self.textures, styling);
        self.styling = styling.clone();
        // A group's per-area target may have changed how many strands a bundle grows.
        self.update_block_density();
    }

    /// Where each block's hair is (culling and LOD inputs) and how densely it grows: what a
    /// frame plan ([`crate::runtime::frame_plan::plan_frame`]) takes.
    pub fn bundle_bounds(&self) -> Vec<crate::runtime::frame_plan::BundleBounds> {
        let mut bounds = self.textures.bundle_bounds();
        for (bundle, density) in bounds.iter_mut().zip(&self.block_density) {
            bundle.density = *density;
        }
        bounds
    }

    /// Strands block `block` grows at full detail: `⌈density · N⌉` of the
    /// `strands_per_bundle` roots laid out for it.
    pub fn block_strand_count(&self, block: usize) -> u32 {
        let density = self.block_density.get(block).copied().unwrap_or(1.0);
        crate::strands::lod::density_count(density as f64, self.strands_per_bundle)
    }

    /// The colour map at every root of [`Self::strand_roots`], packed as the renderers' per-root
    /// buffer holds it ([`crate::model::root_maps::PaintedColour::pack`]); empty when no
    /// colour map is painted. Each root's uv is read from the uv-texture exactly, as
    /// `strand_input` reads it: what a game does once at load (and again when the map
    /// changes), `docs/runtime-format.md` "Painted colour".
    pub fn root_paint(&self) -> Vec<u32> {
        let maps = &self.textures.root_maps;
        if !maps.has_colour() {
            return Vec::new();
        }
        let roots = self.strand_roots();
        // Deterministic chunks on every core: a stroke re-resolves every root per dab.
        crate::parallel::in_chunks(
            roots.len(),
            4096,
            std::thread::available_parallelism().map_or(1, |n| n.get()),
            |range| {
                roots[range]
                    .iter()
                    .map(|root| {
                        let texel = glam::Vec2::from_array(root.texel).extend(0.5);
                        let uv = crate::runtime::strand_gen::fetch(
                            &self.textures.uv,
                            texel,
                            crate::runtime::strand_gen::Filtering::Exact,
                        );
                        maps.sample_colour(glam::DVec2::new(uv.x as f64, uv.y as f64))
                            .pack()
                    })
                    .collect::<Vec<u32>>()
            },
        )
        .concat()
    }

    /// Every strand root at full detail, bundle-major (root `i` is sample
    /// `i % strands_per_bundle` of block `i / strands_per_bundle`), as the GPU lays them out.
    pub fn strand_roots(&self) -> Vec<StrandRoot> {
        self.textures.strand_roots(
            &self.samples,
            self.strands_per_bundle as usize,
            |index, _| self.block_styling[index],
        )
    }
}

/// Each block's index into the styling array for `styling`: 0 = global, `g + 1` = group `g`
/// (see [`StylingSet::group_of`]).
pub fn block_styling(textures: &RuntimeTextures, styling: &StylingSet) -> Vec<u32> {
    textures
        .atlas
        .blocks
        .iter()
        .map(|block| styling.group_of(block.bundle).map_or(0, |g| g as u32 + 1))
        .collect()
}

/// The root of the strand at `sample` (a manifest sample) of `block`, with the texel of the
/// bundle's centre strand (block centre, or the triangle's centroid) for twist, and `rank`,
/// the sample's place in the bundle ([`sample_rank`]).
pub fn strand_root(block: &BundleBlock, sample: [f32; 2], styling: u32, rank: f32) -> StrandRoot {
    let origin = Vec2::new(block.origin[0] as f32, block.origin[1] as f32) + 0.5;
    let centre = if Atlas::is_triangle(block) {
        Vec2::new(0.5, 1.0 / 3.0)
    } else {
        Vec2::splat(0.5)
    };
    let (s, t) =
        Atlas::sample_block_coords(block, glam::DVec2::new(sample[0] as f64, sample[1] as f64));
    StrandRoot {
        texel: (origin + Vec2::new(s as f32, t as f32)).to_array(),
        centre_texel: (origin + centre).to_array(),
        layers: block.layers,
        styling,
        rank,
        _padding: 0,
    }
}

/// `(j + ½) / N`, sample `j`'s place among a bundle's `N`, in f32 as the shader computes
/// it (`strand_root` in `shared/strand_vertex.wgsl`), so both sides agree exactly.
pub fn sample_rank(sample_index: usize, per_bundle: usize) -> f32 {
    (sample_index as f32 + 0.5) / per_bundle.max(1) as f32
}

/// Progressive root samples as a runtime bundle stores them (f32, seed 000 §3.3): quads in
/// block coordinates `[0,1)²`, triangles barycentric `(s, t)`, `s + t < 1`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RootSamples {
    pub quad: Vec<[f32; 2]>,
    pub triangle: Vec<[f32; 2]>,
}

impl RootSamples {
    /// `set` samples per domain from `seed` (what an export writes to its manifest).
    pub fn progressive(set: usize, seed: u64) -> Self {
        use crate::strands::roots::{SampleDomain, progressive_samples};
        let samples = |domain| {
            progressive_samples(set, domain, seed)
                .iter()
                .map(|p| [p.x as f32, p.y as f32])
                .collect()
        };
        Self {
            quad: samples(SampleDomain::Square),
            triangle: samples(SampleDomain::Triangle),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::samples::grid_scalp;
    use glam::DVec3;

    /// Issue 35: with a per-area target, strand counts follow root-face area (a face four
    /// times as large grows four times the strands, up to N), through a group's parameters
    /// too; a restyle and another strand count work the shares out again; off, every bundle
    /// grows N.
    #[test]
    fn strand_counts_follow_face_area_with_a_per_area_target() {
        // Two columns of 1 cm faces, then two of 2 cm: x spacing 1, 1, 2, 2 cm; y 1 cm.
        let xs = [0.0, 0.01, 0.02, 0.04, 0.06];
        let mut mesh = grid_scalp(4, 1, |s, t| {
            let i = (s * 4.0).round() as usize;
            DVec3::new(xs[i], 0.0, 0.01 * t)
        });
        for bundle in &mut mesh.bundles {
            bundle.layers = 1;
        }
        for column in &mut mesh.columns {
            let root = column.positions[0];
            column.positions.push(root + DVec3::Y * 0.05);
            column.w.push(0.05);
        }
        let mut document = Document::new("grid", mesh);
        let options = RuntimeOptions {
            strands_per_bundle: 64,
            ..RuntimeOptions::default()
        };
        let counts = |hair: &RuntimeHair| -> Vec<u32> {
            let mut by_bundle: Vec<(u32, u32)> = (0..hair.textures.atlas.blocks.len())
                .map(|b| {
                    (
                        hair.textures.atlas.blocks[b].bundle,
                        hair.block_strand_count(b),
                    )
                })
                .collect();
            by_bundle.sort();
            by_bundle.into_iter().map(|(_, n)| n).collect()
        };
        assert_eq!(
            counts(&RuntimeHair::from_document(&document, &options)),
            [64; 4]
        );
        document.styling.global.density.strands_per_cm2 = 20.0;
        let mut hair = RuntimeHair::from_document(&document, &options);
        assert_eq!(counts(&hair), [20, 20, 40, 40]);
        // Fewer strands a bundle: the large faces are capped at N.
        hair.set_strands_per_bundle(32).expect("samples");
        assert_eq!(counts(&hair), [20, 20, 32, 32]);
        hair.set_strands_per_bundle(64).expect("samples");
        // A group with its own target, taken by a restyle.
        let mut styling = document.styling.clone();
        let mut params = styling.global.clone();
        params.density.strands_per_cm2 = 10.0;
        styling.groups.push(crate::model::styling::StylingGroup {
            name: "sparse".into(),
            bundles: vec![0, 3],
            params,
        });
        hair.set_styling(&styling);
        assert_eq!(counts(&hair), [10, 20, 40, 20]);
        // The reference strands (exports) grow the same counts.
        document.styling = styling;
        let strands = crate::strands::reference::generate(
            &document,
            &crate::strands::reference::StrandOptions {
                strands_per_bundle: 64,
                vertices_log2: 2,
                ..Default::default()
            },
        );
        let mut per_bundle = [0u32; 4];
        for strand in &strands {
            per_bundle[strand.bundle as usize] += 1;
        }
        assert_eq!(per_bundle, [10, 20, 40, 20]);
    }
}
