//! `hairloom bench crowd`: many characters in one frame (the paper's Fig. 1 scene: a crowd,
//! each character with its own transform, LOD by its own distance). One runtime asset is
//! uploaded once through the game runtime (`hairloom_render::game::GameHair`); each character
//! is drawn with the camera moved into its model space (view-projection × model, the eye by
//! the inverse transform), so culling and LOD see its own distance and the textures are
//! shared. Characters stand on a square grid facing the camera (translations only: the
//! scene's directional lights stay correct). Per character count: frame time, strands and
//! vertices drawn, the GPU memory generation keeps (shared textures + the largest scratch)
//! against storing every character's strands explicitly.

use std::path::PathBuf;
use std::time::Instant;

use glam::{Mat4, Vec3};
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_render::device::{GpuContext, describe};
use hairloom_render::game::{GameCamera, GameHair};
use hairloom_render::preview::{Camera, PreviewRenderer};
use hairloom_render::renderer::Targets;
use hairloom_render::renderer::strand_gen::GenerationPath;
use hairloom_render::view::View;

pub struct CrowdSettings {
    pub project: Option<PathBuf>,
    pub characters: Vec<usize>,
    pub strands: usize,
    pub size: String,
    pub runs: usize,
    /// Where to write each crowd's last frame as `crowd_N.png` (to look at what was timed).
    pub out: Option<PathBuf>,
    /// Where strands are generated; `None`: the game runtime's default
    /// ([`GenerationPath::preferred`]).
    pub generation: Option<GenerationPath>,
    /// Every character with its own hair model (seed 000 Fig. 1 and Fig. 9), made from
    /// `samples` by [`variant`]; otherwise one model drawn N times.
    pub unique: bool,
    /// The samples unique models are varied from (names in `assets/samples/`).
    pub samples: Vec<String>,
    /// Level of detail off (every strand at full detail): the paper's "without LOD" rows.
    pub no_lod: bool,
}

/// A number in `[0, 1)` for character `i`'s `k`-th choice (SplitMix64): the variants are
/// the same in every run.
fn pick(i: usize, k: u64) -> f64 {
    let mut z =
        (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ k.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// Where the sample `name` lives (`assets/samples/NAME.hairloom`).
fn default_sample_path_of(name: &str) -> PathBuf {
    hairloom_core::samples::default_sample_path().with_file_name(format!("{name}.hairloom"))
}

/// Character `i`'s own hair model: sample `i mod n` with its styling varied (curl, wave,
/// noise and clump amplitudes ×0.5-1.5, curl and wave rates ×0.7-1.3, length variation
/// ±0.1, a seed of its own, per group as well as globally) and its strand count (×0.8-1.2
/// of `strands`). A variation outside the styling ranges keeps the sample's own styling.
/// The colour is the runtime's scene's, shared by every model (`GameHair::add_hair`).
fn variant(
    documents: &[hairloom_core::model::document::Document],
    i: usize,
    strands: usize,
) -> anyhow::Result<(RuntimeHair, usize)> {
    use hairloom_core::model::styling::StylingParams;
    let mut document = documents[i % documents.len()].clone();
    let vary = |p: &mut StylingParams| {
        let scale = |k: u64| 0.5 + pick(i, k);
        let rate = |k: u64| 0.7 + 0.6 * pick(i, k);
        p.curl.radius_m *= scale(1);
        p.curl.turns_per_m *= rate(2);
        p.wave.amplitude_m *= scale(3);
        p.wave.frequency_per_m *= rate(4);
        p.noise.amplitude_m *= scale(5);
        p.clump.strength = (p.clump.strength * scale(6)).min(1.0);
        p.length.fraction = (p.length.fraction + 0.2 * pick(i, 7) - 0.1).clamp(0.0, 0.9);
        p.seed = p.seed.wrapping_add(i as u32 * 7919 + 1);
    };
    let mut styling = document.styling.clone();
    vary(&mut styling.global);
    for group in &mut styling.groups {
        vary(&mut group.params);
    }
    if styling.validate().is_ok() {
        document.styling = styling;
    }
    // f16 textures, as compact as the paper's (the accuracy table: 0.07 mm more error).
    let mut hair = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            precision: hairloom_core::runtime::textures::Precision::F16,
            ..RuntimeOptions::default()
        },
    );
    let bundles = hair.textures.atlas.blocks.len().max(1);
    let target = strands as f64 * (0.8 + 0.4 * pick(i, 10));
    hair.set_strands_per_bundle((target as usize).div_ceil(bundles).clamp(1, 4096) as u32)?;
    hair.scene.effects = hair.scene.effects.none();
    Ok((hair, document.hair_mesh.vertex_count()))
}

pub fn run(settings: &CrowdSettings) -> anyhow::Result<()> {
    let path = settings
        .project
        .clone()
        .unwrap_or_else(hairloom_core::samples::default_sample_path);
    let (width, height) = super::render::parse_size(&settings.size)?;
    let document = hairloom_core::io::project::load(&path)?.document;
    let mut hair = RuntimeHair::from_document(&document, &RuntimeOptions::default());
    let bundles = hair.textures.atlas.blocks.len().max(1);
    hair.set_strands_per_bundle(settings.strands.div_ceil(bundles).clamp(1, 4096) as u32)?;
    // The method's own cost, as in `bench gpu`: no optional effect.
    hair.scene.effects = hair.scene.effects.none();
    // Unique models: one per character of the largest crowd, varied from the samples.
    let (models, mesh_vertices): (Vec<RuntimeHair>, Vec<usize>) = if settings.unique {
        let documents = settings
            .samples
            .iter()
            .map(|name| {
                let path = default_sample_path_of(name);
                hairloom_core::io::project::load(&path)
                    .map(|p| p.document)
                    .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        anyhow::ensure!(!documents.is_empty(), "--unique needs at least one sample");
        let most = settings.characters.iter().copied().max().unwrap_or(1);
        (0..most)
            .map(|i| variant(&documents, i, settings.strands))
            .collect::<anyhow::Result<Vec<_>>>()?
            .into_iter()
            .unzip()
    } else {
        (Vec::new(), Vec::new())
    };
    if let Some(first) = models.first() {
        hair = first.clone();
    }
    let context = GpuContext::new_headless()?;
    let sample_count = PreviewRenderer::new(&context).sample_count;
    let mut game = GameHair::new(
        &context.adapter,
        &context.device,
        &context.queue,
        &hair,
        Targets::view(sample_count),
    )?;
    if let Some(path) = settings.generation {
        game.set_generation(path)?;
    }
    if settings.no_lod {
        game.set_lod(hairloom_core::runtime::frame_plan::LodSettings {
            enabled: false,
            ..hairloom_core::runtime::frame_plan::LodSettings::default()
        });
    }
    let lod = if settings.no_lod { "LOD off" } else { "LOD on" };
    // The other unique models, sharing the runtime's pipelines.
    let mut ids = vec![game.selected_hair()];
    for model in models.iter().skip(1) {
        ids.push(game.add_hair(model)?);
    }
    let model_bytes: Vec<u64> = ids
        .iter()
        .map(|&id| {
            game.select_hair(id)?;
            Ok(game.resident_bytes())
        })
        .collect::<Result<_, hairloom_render::game::GameHairError>>()?;
    let view = View::new(&context, width, height, sample_count);
    let (mut lo, mut hi) = hair
        .textures
        .hair_bounds()
        .ok_or_else(|| anyhow::anyhow!("no bundle grows hair"))?;
    for (model_lo, model_hi) in models.iter().filter_map(|m| m.textures.hair_bounds()) {
        lo = lo.min(model_lo);
        hi = hi.max(model_hi);
    }
    let extent = hi - lo;
    let spacing = extent.x.max(extent.z) * 1.6;
    let strands_per_character = hair.strand_roots().len();
    // Strands of each unique model (the one model otherwise).
    let model_strands: Vec<usize> = if models.is_empty() {
        vec![strands_per_character]
    } else {
        models.iter().map(|m| m.strand_roots().len()).collect()
    };
    if settings.unique {
        println!(
            "Crowd of unique hair models: N characters, each its own model varied from {} (styling, {}-{} strands), one frame, {width}x{height}, {sample_count}× MSAA, {lod}",
            settings.samples.join(", "),
            model_strands.iter().min().unwrap_or(&0),
            model_strands.iter().max().unwrap_or(&0),
        );
    } else {
        println!(
            "Crowd: N characters of {strands_per_character} strands each, one frame, {width}x{height}, {sample_count}× MSAA, {lod}: {}",
            path.display()
        );
    }
    println!("adapter: {}", describe(&context.adapter_info));
    println!("machine: {}", super::machine());
    println!(
        "generation: {}; characters one after another, each planned, submitted and finished before the next (one scratch buffer alive at a time); times: wall from the first character's planning to the last one's end, median of {} after a warm-up",
        game.generation().name(),
        settings.runs
    );
    println!(
        "{:>10} {:>12} {:>12} {:>10} {:>14} {:>12} {:>13} {:>10}",
        "characters",
        "strands",
        "vertices",
        "ms",
        "ms/character",
        "memory MB",
        "stored MB",
        "mem ratio"
    );
    for &count in &settings.characters {
        let side = (count as f64).sqrt().ceil() as usize;
        // Row r further away; centred left to right.
        let offsets: Vec<Vec3> = (0..count)
            .map(|i| {
                let (row, column) = (i / side, i % side);
                Vec3::new(
                    (column as f32 - (side as f32 - 1.0) * 0.5) * spacing,
                    0.0,
                    -(row as f32) * spacing,
                )
            })
            .collect();
        // A camera that frames the whole grid from the front, slightly above.
        let crowd_lo = lo
            + Vec3::new(
                -(side as f32 - 1.0) * 0.5 * spacing,
                0.0,
                -((side - 1) as f32) * spacing,
            );
        let crowd_hi = hi + Vec3::new((side as f32 - 1.0) * 0.5 * spacing, 0.0, 0.0);
        let camera = Camera::framing(crowd_lo, crowd_hi, Vec3::new(0.0, 0.35, 1.0));
        let aspect = width as f32 / height as f32;
        let view_projection = camera.view_projection(aspect);
        let mut frame = || -> anyhow::Result<(f64, usize, usize, u64)> {
            let start = Instant::now();
            let (mut strands, mut vertices, mut scratch, mut over) = (0, 0, 0u64, 0);
            for (i, offset) in offsets.iter().enumerate() {
                let model = Mat4::from_translation(*offset);
                let character_camera = GameCamera {
                    view_projection: view_projection * model,
                    eye: camera.eye - *offset,
                    fov_y_rad: camera.fov_y_rad,
                    viewport_height_px: height,
                };
                if settings.unique {
                    game.select_hair(ids[i % ids.len()])?;
                }
                let mut encoder =
                    context
                        .device
                        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                            label: Some("crowd"),
                        });
                let stats = game.prepare(&mut encoder, &character_camera);
                strands += stats.strands;
                over += stats.strands_over_limit;
                vertices += stats.vertices;
                scratch = scratch.max(stats.scratch_bytes);
                {
                    let (target, resolve) = view.attachments();
                    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                        label: Some("crowd"),
                        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                            view: target,
                            depth_slice: None,
                            resolve_target: resolve,
                            ops: wgpu::Operations {
                                load: if i == 0 {
                                    wgpu::LoadOp::Clear(wgpu::Color::BLACK)
                                } else {
                                    wgpu::LoadOp::Load
                                },
                                store: wgpu::StoreOp::Store,
                            },
                        })],
                        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                            view: view.depth(),
                            depth_ops: Some(wgpu::Operations {
                                load: if i == 0 {
                                    wgpu::LoadOp::Clear(1.0)
                                } else {
                                    wgpu::LoadOp::Load
                                },
                                store: wgpu::StoreOp::Store,
                            }),
                            stencil_ops: None,
                        }),
                        timestamp_writes: None,
                        occlusion_query_set: None,
                        multiview_mask: None,
                    });
                    game.draw(&mut pass);
                }
                context.queue.submit([encoder.finish()]);
                context
                    .device
                    .poll(wgpu::PollType::wait_indefinitely())
                    .map_err(|e| anyhow::anyhow!("waiting for the GPU: {e}"))?;
            }
            if over > 0 {
                anyhow::bail!("{over} strands exceeded the device's per-frame generation limit");
            }
            Ok((
                start.elapsed().as_secs_f64() * 1e3,
                strands,
                vertices,
                scratch,
            ))
        };
        frame()?;
        let mut timings = Vec::new();
        for _ in 0..settings.runs.max(1) {
            timings.push(frame()?);
        }
        timings.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (ms, strands, vertices, scratch) = timings[timings.len() / 2];
        if let Some(out) = &settings.out {
            std::fs::create_dir_all(out)?;
            let encoder = context
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            let pixels = View::read_back(&context, view.color(), encoder)
                .map_err(|e| anyhow::anyhow!("reading the frame back: {e}"))?;
            super::render::write_png(
                &out.join(format!("crowd_{count}.png")),
                &pixels,
                width,
                height,
            )?;
        }
        let full_vertex_count = (1usize << hair.lod.max_vertices_log2.min(8)) + 1;
        let (memory, stored) = if settings.unique {
            // Every character's own model, and every character's strands stored.
            let drawn = count.min(model_bytes.len());
            (
                model_bytes[..drawn].iter().sum::<u64>() + scratch,
                model_strands[..drawn]
                    .iter()
                    .map(|&n| (n * full_vertex_count * 16) as u64)
                    .sum::<u64>(),
            )
        } else {
            // One character's strands at full detail, 16 B per vertex, stored explicitly:
            // what an explicit renderer instancing one stored copy keeps, whatever the count.
            (
                game.resident_bytes() + scratch,
                (strands_per_character * full_vertex_count * 16) as u64,
            )
        };
        println!(
            "{:>10} {:>12} {:>12} {:>10.1} {:>14.1} {:>12.2} {:>13.1} {:>9.0}×",
            count,
            strands,
            vertices,
            ms,
            ms / count as f64,
            memory as f64 / 1e6,
            stored as f64 / 1e6,
            stored as f64 / memory as f64
        );
    }
    if settings.unique {
        let kb: Vec<f64> = model_bytes.iter().map(|&b| b as f64 / 1e3).collect();
        let per_vertex = model_bytes.iter().sum::<u64>() as f64
            / mesh_vertices.iter().sum::<usize>().max(1) as f64;
        println!(
            "memory: every character's own model (f16 textures, placements, samples, styling: {:.1}-{:.1} KB a model for {}-{} hair-mesh vertices, {per_vertex:.0} B a vertex) + the largest scratch; stored: every character's strands at full detail, 16 B per vertex. {}",
            kb.iter().copied().fold(f64::INFINITY, f64::min),
            kb.iter().copied().fold(0.0, f64::max),
            mesh_vertices.iter().min().unwrap_or(&0),
            mesh_vertices.iter().max().unwrap_or(&0),
            if settings.samples.iter().all(|s| s.starts_with("teapot")) {
                "Seed 000 Fig. 9: 200 teapots of 50K strands in 3.2 MB (11-27 KB a teapot of 198-378 vertices, 71 B a vertex), 1.8 ms with LOD at 8× MSAA, 1.1 ms without MSAA, 150 ms without LOD (RTX 4090)."
            } else {
                "Seed 000 Fig. 1: 100 models of 100K strands in 1.7 MB (13-21 KB a model of 185 vertices; 71 B a vertex across its Fig. 10), 2 ms with LOD, 47 ms without (RTX 4090, 8× MSAA)."
            }
        );
    } else {
        println!(
            "memory: the bundle's textures, placements, samples and styling once (shared by every character) + the largest scratch; stored: one character's strands at full detail, 16 B per vertex (one copy instanced by every character)."
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unique_models_differ_in_styling_and_strand_count() -> anyhow::Result<()> {
        let sample = hairloom_core::io::project::load(&default_sample_path_of("head_curly"))?;
        let documents = [sample.document.clone()];
        let models = (0..6)
            .map(|i| variant(&documents, i, 2000))
            .collect::<anyhow::Result<Vec<_>>>()?;
        for (i, (a, vertices)) in models.iter().enumerate() {
            assert_eq!(*vertices, sample.document.hair_mesh.vertex_count());
            a.styling.validate().map_err(anyhow::Error::msg)?;
            let strands = a.strand_roots().len() as f64;
            // ×0.8-1.2 of the target, up to a bundle's worth of rounding and density.
            assert!((1000.0..3000.0).contains(&strands), "{i}: {strands}");
            assert_ne!(
                a.styling, sample.document.styling,
                "{i} kept the sample's styling"
            );
            for (j, (b, _)) in models.iter().enumerate().skip(i + 1) {
                assert_ne!(a.styling, b.styling, "{i} and {j}");
            }
        }
        // The same character gets the same model in every run.
        assert_eq!(variant(&documents, 3, 2000)?.0.styling, models[3].0.styling);
        Ok(())
    }
}
