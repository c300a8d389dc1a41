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
    /// Per atlas block: the fraction of its strands that grow (`Bundle::density`).
    pub block_density: Vec<f32>,
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
        let textures = RuntimeTextures::build(&document.hair_mesh, options.precision);
        let mut hair = Self {
            block_styling: block_styling(&textures, &document.styling),
            block_density: textures
                .atlas
                .blocks
                .iter()
                .map(|block| {
                    let bundle = document.hair_mesh.bundles.get(block.bundle as usize);
                    bundle.map_or(1.0, |b| b.density as f32)
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
            }
        }
        Ok(())
    }

    /// Takes new styling parameters (and group assignments) without touching the textures:
    /// what a styling-only edit changes.
    pub fn set_styling(&mut self, styling: &StylingSet) {
        self.block_styling = block_styling(&self.textures, styling);
        self.styling = styling.clone();
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
