//! The drop-in game runtime draws what `hairloom render` draws: a runtime bundle recorded
//! through `GameHair` into a render pass the test owns (its own targets, camera and clear)
//! matches the editor's preview of the same bundle and scene.

use glam::Vec3;
use hairloom_core::model::scene::{SelfShadowing, Shading};
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_render::device::headless_for_test;
use hairloom_render::game::{
    GameCamera, GameFrameStats, GameHair, GameHairError, HairId, game_scene,
};
use hairloom_render::hair_asset::{AssetChange, Restyling};
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, default_scene};
use hairloom_render::renderer::Targets;
use hairloom_render::renderer::preview_body::GpuBody;
use hairloom_render::renderer::strand_gen::{GenerationPath, StrandGenRenderer};
use hairloom_render::view::View;

const SIZE: u32 = 160;
const VERTICES_LOG2: u32 = 4;

fn bundle() -> RuntimeHair {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/samples/head_short_straight.hairloom");
    let document = hairloom_core::io::project::load(&path)
        .expect("sample")
        .document;
    let mut hair = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 8,
            ..RuntimeOptions::default()
        },
    );
    // Marschner with dual scattering: the shading the game path keeps, at its dearest.
    hair.scene.effects.shading = Shading::Marschner;
    hair
}

fn mean_abs_difference(a: &[u8], b: &[u8]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).abs())
        .sum::<f64>()
        / a.len() as f64
}

/// One frame through the game API into `view`, cleared to `background`, in a pass this
/// test owns; returns what `prepare` planned and the pixels.
fn draw(
    context: &hairloom_render::device::GpuContext,
    game: &mut GameHair,
    view: &View,
    camera: &GameCamera,
    background: wgpu::Color,
) -> (GameFrameStats, Vec<u8>) {
    let mut encoder = context
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("game"),
        });
    let stats = game.prepare(&mut encoder, camera);
    {
        let (target, resolve) = view.attachments();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("game"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: resolve,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(background),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: view.depth(),
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        game.draw(&mut pass);
    }
    let pixels = View::read_back(context, view.color(), encoder).expect("read back");
    (stats, pixels)
}

#[test]
fn game_runtime_draws_what_the_preview_draws() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let hair = bundle();
    let scene = game_scene(&hair.scene);
    // The sample's scene casts shadows: the game path records those passes too.
    assert_eq!(scene.effects.self_shadowing, SelfShadowing::DeepOpacityMaps);
    assert!(scene.effects.body_shadows);
    let (lo, hi) = hair.textures.hair_bounds().expect("hair");
    let camera = Camera::framing(lo, hi, Vec3::new(0.75, 0.25, 1.0));
    let lod = LodSettings::default();

    // The editor's preview of the bundle, with the scene the game path draws.
    let generator = StrandGenRenderer::new(&context);
    let gpu_hair = generator.upload(&context, &hair).expect("upload");
    let body = GpuBody::upload(&context, &hair.body);
    let preview = PreviewRenderer::new(&context);
    let preview_scene = default_scene(
        &body,
        HairSource::Generated {
            generator: &generator,
            hair: &gpu_hair,
            filtering: Filtering::Exact,
            lod,
            far: None,
            fur: None,
        },
        (1 << VERTICES_LOG2) + 1,
        (lo, hi),
        camera,
        &scene,
    );
    let plan = preview.plan(&preview_scene, SIZE, SIZE);
    let expected = preview
        .render(&context, &preview_scene, &plan, SIZE, SIZE)
        .expect("preview");

    // The same bundle through the game API, into targets and a pass the test owns.
    let sample_count = preview.sample_count;
    let view = View::new(&context, SIZE, SIZE, sample_count);
    let mut game = GameHair::new(
        &context.adapter,
        &context.device,
        &context.queue,
        &hair,
        Targets::view(sample_count),
    )
    .expect("the bundle loads");
    game.set_lod(lod);
    game.set_vertices_log2(VERTICES_LOG2);
    // The preview's path (the game's default is mesh shaders where the device has them)
    // and filtering (the game's is measured on the adapter).
    game.set_generation(GenerationPath::ComputePerStrand)
        .expect("compute per strand");
    game.set_filtering(Filtering::Exact)
        .expect("exact filtering");
    let game_camera = GameCamera {
        view_projection: camera.view_projection(1.0),
        eye: camera.eye,
        fov_y_rad: camera.fov_y_rad,
        viewport_height_px: SIZE,
    };
    let [r, g, b] = scene.background;
    let background = wgpu::Color {
        r: r as f64,
        g: g as f64,
        b: b as f64,
        a: 1.0,
    };
    let (stats, drawn) = draw(&context, &mut game, &view, &game_camera, background);
    assert_eq!(stats.strands, plan.strands);
    assert_eq!(stats.vertices, plan.vertices);
    assert_eq!(stats.strands_over_limit, 0);

    let hair_pixels = expected
        .chunks_exact(4)
        .zip(drawn.chunks_exact(4))
        .filter(|(a, _)| a[..3] != expected[..3])
        .count();
    assert!(
        hair_pixels > (SIZE * SIZE / 20) as usize,
        "the preview drew almost nothing ({hair_pixels} pixels differ from the corner)"
    );
    let difference = mean_abs_difference(&expected, &drawn);
    eprintln!("game runtime vs preview: mean difference {difference:.4} per channel");
    // The same pipelines on the same inputs: the same pixels.
    assert!(
        expected == drawn,
        "game runtime vs preview: mean difference {difference:.3} per channel"
    );

    // Generated in the ribbons' vertex shader instead: no compute pass, no scratch, the same
    // picture (and the same plan, since the compute path's one batch held every strand).
    game.set_generation(GenerationPath::VertexShader)
        .expect("the vertex-shader path");
    let (vs_stats, vs_drawn) = draw(&context, &mut game, &view, &game_camera, background);
    assert_eq!(
        (vs_stats.strands, vs_stats.vertices),
        (stats.strands, stats.vertices)
    );
    assert!(stats.scratch_bytes >= stats.vertices as u64 * 16);
    assert_eq!(vs_stats.scratch_bytes, 0, "no scratch buffer");
    let differing = drawn
        .chunks_exact(4)
        .zip(vs_drawn.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 2))
        .count();
    eprintln!("game runtime, vertex-shader generation: {differing} pixels differ by > 2/255");
    assert!(
        differing * 1000 <= (SIZE * SIZE) as usize,
        "{differing} pixels differ"
    );
    // Task and mesh shaders where the device has them (Mesa 25's lavapipe under `make
    // test`'s mesh run, NVIDIA): their own LOD, no scratch, the same picture.
    if GenerationPath::MeshShader.available(&context.device) {
        game.set_generation(GenerationPath::MeshShader)
            .expect("the mesh-shader path");
        assert_eq!(game.generation(), GenerationPath::MeshShader);
        let (mesh_stats, mesh_drawn) = draw(&context, &mut game, &view, &game_camera, background);
        assert_eq!(mesh_stats.scratch_bytes, 0, "no scratch buffer");
        let differing = drawn
            .chunks_exact(4)
            .zip(mesh_drawn.chunks_exact(4))
            .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 2))
            .count();
        eprintln!("game runtime, mesh-shader generation: {differing} pixels differ by > 2/255");
        assert!(
            differing * 1000 <= (SIZE * SIZE) as usize,
            "{differing} pixels differ"
        );
    }
    game.set_generation(GenerationPath::ComputePerStrand)
        .expect("back to compute");

    // Without the body the picture loses it: the switch is real.
    game.set_draw_body(false);
    let (_, hair_only) = draw(&context, &mut game, &view, &game_camera, background);
    assert!(mean_abs_difference(&hair_only, &drawn) > 1.0);
}

/// A game that restyles its hair at run time (a curl that grows, say) takes the change the
/// way the editor does: the styling buffers are rewritten in place — no byte more on the
/// GPU — and the frame shows exactly what a bundle exported with that styling shows.
#[test]
fn a_restyle_reaches_the_game_in_place_and_matches_a_fresh_bundle() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/samples/head_short_straight.hairloom");
    let mut document = hairloom_core::io::project::load(&path)
        .expect("sample")
        .document;
    let options = RuntimeOptions {
        strands_per_bundle: 8,
        ..RuntimeOptions::default()
    };
    let hair = RuntimeHair::from_document(&document, &options);
    let (lo, hi) = hair.textures.hair_bounds().expect("hair");
    let camera = Camera::framing(lo, hi, Vec3::new(0.75, 0.25, 1.0));
    let game_camera = GameCamera {
        view_projection: camera.view_projection(1.0),
        eye: camera.eye,
        fov_y_rad: camera.fov_y_rad,
        viewport_height_px: SIZE,
    };
    let sample_count = PreviewRenderer::new(&context).sample_count;
    let view = View::new(&context, SIZE, SIZE, sample_count);
    let game_of = |hair: &RuntimeHair| {
        let mut game = GameHair::new(
            &context.adapter,
            &context.device,
            &context.queue,
            hair,
            Targets::view(sample_count),
        )
        .expect("the bundle loads");
        game.set_vertices_log2(VERTICES_LOG2);
        game.set_generation(GenerationPath::ComputePerStrand)
            .expect("compute per strand");
        game.set_filtering(Filtering::Exact)
            .expect("exact filtering");
        game
    };
    let background = wgpu::Color::BLACK;
    let mut game = game_of(&hair);
    let (_, straight) = draw(&context, &mut game, &view, &game_camera, background);
    let resident = game.resident_bytes();

    let curl = &mut document.styling.global.curl;
    curl.radius_m = 0.01;
    curl.turns_per_m = 60.0;
    game.apply(AssetChange::Restyle(Box::new(Restyling::of(&document))))
        .expect("a restyle");
    let (_, curled) = draw(&context, &mut game, &view, &game_camera, background);
    assert_eq!(game.resident_bytes(), resident, "a restyle allocated");
    let change = mean_abs_difference(&straight, &curled);
    eprintln!("game restyle: the picture changed by {change:.3} per channel");
    assert!(
        change > 0.5,
        "the curl changed the picture by only {change:.3}"
    );

    let mut fresh = game_of(&RuntimeHair::from_document(&document, &options));
    let (_, expected) = draw(&context, &mut fresh, &view, &game_camera, background);
    assert!(
        expected == curled,
        "restyled in place vs made afresh: mean difference {:.3}",
        mean_abs_difference(&expected, &curled)
    );

    // A second model in the same runtime (a crowd of hairstyles sharing its pipelines): the
    // straight cut added to the curled runtime draws as its own runtime did, and selecting
    // the first model again draws the curls.
    let straight_id = fresh.add_hair(&hair).expect("a second model");
    assert_eq!(straight_id, HairId(1));
    fresh.select_hair(straight_id).expect("select");
    let (_, second) = draw(&context, &mut fresh, &view, &game_camera, background);
    assert!(
        second == straight,
        "second model vs its own runtime: mean difference {:.3}",
        mean_abs_difference(&second, &straight)
    );
    fresh.select_hair(HairId(0)).expect("select");
    let (_, first) = draw(&context, &mut fresh, &view, &game_camera, background);
    assert!(first == curled, "the first model again");
    assert!(matches!(
        fresh.select_hair(HairId(2)),
        Err(GameHairError::UnknownHair { id: 2, count: 2 })
    ));
    assert_eq!(fresh.selected_hair(), HairId(0));
}

/// The game's default filtering is chosen by measuring both on its adapter: both timed,
/// the 8-bit weights' error measured against exact filtering, and the choice follows the rule.
#[test]
fn the_game_measures_its_filtering_on_its_adapter() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let hair = bundle();
    let (lo, hi) = hair.textures.hair_bounds().expect("hair");
    let size = (hi - lo).length() as f64;
    let game = GameHair::new(
        &context.adapter,
        &context.device,
        &context.queue,
        &hair,
        Targets::view(1),
    )
    .expect("the bundle loads");
    let measure = *game.filtering_measure();
    assert!(measure.strands > 0, "{measure:?}");
    assert!(
        measure.exact_ms.is_finite() && measure.exact_ms > 0.0,
        "{measure:?}"
    );
    // f16 textures filter on every adapter we run on.
    let hardware_ms = measure.hardware_ms.expect("hardware filtering measured");
    assert!(hardware_ms.is_finite() && hardware_ms > 0.0, "{measure:?}");
    // 8-bit weights move vertices by a fraction of a millimetre on a head (an adapter that
    // filters in float, as llvmpipe does, by nothing at all).
    assert!(measure.hardware_error_max_m >= 0.0, "{measure:?}");
    assert!(measure.hardware_error_max_m < 2e-3 * size, "{measure:?}");
    assert!(measure.hardware_error_mean_m <= measure.hardware_error_max_m);
    // Half the width of a strand, which is a little over a thousandth of the hair's size.
    let width = hairloom_render::preview::default_strand_width_m(lo, hi) as f64;
    assert!(
        (measure.tolerance_m - 0.5 * width).abs() < 1e-9,
        "{measure:?}"
    );
    // The rule, from the numbers: hardware weights only where faster by 5 % and within it.
    let hardware_pays = hardware_ms <= 0.95 * measure.exact_ms
        && measure.hardware_error_max_m <= measure.tolerance_m;
    let expected = if hardware_pays {
        Filtering::Hardware8Bit
    } else {
        Filtering::Exact
    };
    assert_eq!(game.filtering(), expected, "{measure:?}");
}
