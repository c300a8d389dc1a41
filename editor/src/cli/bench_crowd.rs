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
    let view = View::new(&context, width, height, sample_count);
    let (lo, hi) = hair
        .textures
        .hair_bounds()
        .ok_or_else(|| anyhow::anyhow!("no bundle grows hair"))?;
    let extent = hi - lo;
    let spacing = extent.x.max(extent.z) * 1.6;
    let strands_per_character = hair.strand_roots().len();
    println!(
        "Crowd: N characters of {strands_per_character} strands each, one frame, {width}x{height}, {sample_count}× MSAA, LOD on: {}",
        path.display()
    );
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
        let memory = game.resident_bytes() + scratch;
        // One character's strands at full detail, 16 B per vertex, stored explicitly: what an
        // explicit renderer instancing one stored copy keeps, whatever the count.
        let full_vertices =
            strands_per_character * ((1usize << hair.lod.max_vertices_log2.min(8)) + 1);
        let stored = (full_vertices * 16) as u64;
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
    println!(
        "memory: the bundle's textures, placements, samples and styling once (shared by every character) + the largest scratch; stored: one character's strands at full detail, 16 B per vertex (one copy instanced by every character)."
    );
    Ok(())
}
