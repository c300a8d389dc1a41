//! GPU strand generation (`strand_gen.wgsl`) against its CPU mirror
//! (`StrandGen::main`) on the bundled samples, every styling op on, with a styling
//! group: exact filtering within 1e-5 × model size; hardware filtering within the bound the
//! CPU emulation of 8-bit weights documents. Runs on lavapipe in CI.

mod common;

use hairloom_core::model::styling::{StylingGroup, StylingParams, Twist};
use hairloom_core::runtime::hair::{RootSamples, RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::{Filtering, StrandGen};
use hairloom_core::runtime::textures::Precision;
use hairloom_render::device::headless_for_test;
use hairloom_render::renderer::strand_gen::{GenerationPath, StrandGenRenderer, full_detail_plan};

/// Both compute distributions of the work (per strand, per vertex): each must match the
/// mirror.
fn compute_renderers(context: &hairloom_render::device::GpuContext) -> [StrandGenRenderer; 2] {
    [
        GenerationPath::ComputePerStrand,
        GenerationPath::ComputePerVertex,
    ]
    .map(|path| StrandGenRenderer::with_path(context, path))
}

#[test]
fn gpu_strands_match_the_cpu_mirror() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let renderers = compute_renderers(&context);
    let renderer = &renderers[0];
    // Strands the hairline op leaves out (at their root) and strands it shortens, seen among
    // the group's roots of some sample.
    let (mut not_grown, mut shortened) = (0, 0);
    for name in ["head_curly", "head_long_wavy", "teapot_fur"] {
        let mut document = common::sample(name);
        // The sample's own ops plus twist (the one that reads the centre strand), and a group
        // with every op on a few bundles (the per-root styling index): ringlet and lock-wave
        // phases, sub-clumps and strays.
        document.styling.global.twist = Twist { turns_per_m: 4.0 };
        let mut group = StylingParams {
            seed: 9,
            ..StylingParams::every_op()
        };
        group.stray.fraction = 0.4;
        group.length.fraction = 0.4;
        // Wide enough that the group's bundles fall inside the falloff.
        group.hairline.width_m = 0.05;
        document.styling.groups.push(StylingGroup {
            name: "group".into(),
            bundles: vec![0, 1, 2, 5, 8],
            params: group,
        });
        let mesh = &document.hair_mesh;
        let size = mesh.size() as f32;
        let params: Vec<&StylingParams> = std::iter::once(&document.styling.global)
            .chain(document.styling.groups.iter().map(|g| &g.params))
            .collect();
        for precision in [Precision::F32, Precision::F16] {
            let runtime = RuntimeHair::from_document(
                &document,
                &RuntimeOptions {
                    precision,
                    strands_per_bundle: 6,
                    sample_seed: 5,
                    ..RuntimeOptions::default()
                },
            );
            let textures = &runtime.textures;
            let roots = runtime.strand_roots();
            assert!(roots.iter().any(|r| r.styling == 1) && roots.iter().any(|r| r.styling == 0));
            // Strays and clumped strands both among the group's.
            let generator = StrandGen {
                textures,
                filtering: Filtering::Exact,
            };
            let strays = roots
                .iter()
                .filter(|r| r.styling == 1)
                .map(|r| generator.strand_input(r, params[1]).styling.stray)
                .collect::<Vec<_>>();
            assert!(
                strays.contains(&true) && strays.contains(&false),
                "{name}: {strays:?}"
            );
            for root in roots.iter().filter(|r| r.styling == 1) {
                let input = generator.strand_input(root, params[1]);
                let without = StylingParams {
                    hairline: Default::default(),
                    ..params[1].clone()
                };
                let full = generator.strand_input(root, &without).length_fraction;
                if input.length_fraction == 0.0 {
                    not_grown += 1;
                } else if input.length_fraction < full {
                    shortened += 1;
                }
            }
            let hair = renderer.upload(&context, &runtime).expect("upload");
            assert_eq!(hair.root_count, roots.len());
            let vertex_count = 17u32;
            let plan = full_detail_plan(roots.len(), vertex_count);
            for (filtering, renderer) in [Filtering::Exact, Filtering::Hardware8Bit]
                .into_iter()
                .flat_map(|f| renderers.iter().map(move |r| (f, r)))
            {
                let path = renderer.path();
                let positions = match renderer.generate_positions(&context, &hair, &plan, filtering)
                {
                    Ok(positions) => positions,
                    Err(error) => panic!("{name} {precision:?} {filtering:?} {path:?}: {error}"),
                };
                assert_eq!(positions.len(), roots.len() * vertex_count as usize);
                let mirror = StrandGen {
                    textures,
                    filtering,
                };
                let expected = mirror.main(&roots, &plan.batches[0], &params);
                let mut worst = 0.0f32;
                for (got, expected) in positions.iter().zip(&expected) {
                    let got = glam::Vec3::new(got[0], got[1], got[2]);
                    assert!(got.is_finite(), "{name}: non-finite GPU position");
                    worst = worst.max(got.distance(*expected));
                }
                let bound = match filtering {
                    Filtering::Exact => 1e-5 * size,
                    // The texture unit's weights are not bit-exactly the CPU emulation's
                    // (8-bit fixed point; units truncate or round): each fetch may differ by
                    // ~1/256 of a neighbouring-texel step, and styling turns w errors into
                    // curl and wave phase errors. The sparse teapot (few, long bundles) is the
                    // worst: 2.0e-3 × size on lavapipe; the bound leaves 2× for other units.
                    Filtering::Hardware8Bit => 4e-3 * size,
                };
                eprintln!(
                    "{name} {precision:?} {filtering:?} {path:?}: max |GPU − CPU mirror| = {worst:.3e} (bound {bound:.3e}, size {size:.3})"
                );
                assert!(
                    worst <= bound,
                    "{name} {precision:?} {filtering:?} {path:?}: {worst} > {bound}"
                );
            }
        }
    }
    assert!(
        not_grown > 0 && shortened > 0,
        "the hairline op thins and shortens some of the group's strands: {not_grown} left out, {shortened} shortened"
    );
}

#[test]
fn generation_runs_in_batches_with_bounded_scratch() {
    use hairloom_render::renderer::strand_gen::BATCH_STRANDS;
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let renderer = StrandGenRenderer::new(&context);
    let document = common::sample("teapot_fur");
    let mut runtime = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            precision: Precision::F16,
            strands_per_bundle: 160,
            ..RuntimeOptions::default()
        },
    );
    // 288 bundles × 160 = 46,080 strands: 2 batches.
    let large = runtime.strand_roots();
    assert!(large.len() > BATCH_STRANDS);
    let large_hair = renderer.upload(&context, &runtime).expect("upload");
    // A prefix of the same sample set: 4 per bundle.
    runtime.samples = RootSamples {
        quad: runtime.samples.quad[..4].to_vec(),
        triangle: runtime.samples.triangle[..4].to_vec(),
    };
    runtime.sample_seed = None;
    runtime.set_strands_per_bundle(4).expect("4 of the samples");
    let small = runtime.strand_roots();
    let small_hair = renderer.upload(&context, &runtime).expect("upload");
    let textures = &runtime.textures;
    let vertex_count = 5;
    let small_plan = full_detail_plan(small.len(), vertex_count);
    let large_plan = full_detail_plan(large.len(), vertex_count);
    let a = renderer
        .time_generation(&context, &small_hair, &small_plan, Filtering::Exact)
        .expect("timing");
    let b = renderer
        .time_generation(&context, &large_hair, &large_plan, Filtering::Exact)
        .expect("timing");
    assert_eq!((a.batches, b.batches), (1, 2));
    // Scratch is one batch, whatever the strand count.
    assert_eq!(
        b.scratch_bytes,
        (BATCH_STRANDS as u64) * vertex_count as u64 * 16
    );
    assert!(b.scratch_bytes <= 64 << 20);
    // Batched read-back gives every strand once, in order: the second batch's first strand
    // is the root the first batch ended before.
    let positions = renderer
        .generate_positions(&context, &large_hair, &large_plan, Filtering::Exact)
        .expect("positions");
    assert_eq!(positions.len(), large.len() * vertex_count as usize);
    let mirror = StrandGen {
        textures,
        filtering: Filtering::Exact,
    };
    let params = [&document.styling.global];
    let boundary = &large_plan.batches[1][..1];
    assert_eq!(boundary[0].first_root as usize, BATCH_STRANDS);
    let expected: Vec<_> = mirror
        .main(&large, boundary, &params)
        .into_iter()
        .take(vertex_count as usize)
        .collect();
    let got = &positions[BATCH_STRANDS * vertex_count as usize..][..vertex_count as usize];
    for (g, e) in got.iter().zip(&expected) {
        assert!(
            glam::Vec3::new(g[0], g[1], g[2]).distance(*e)
                < 1e-5 * document.hair_mesh.size() as f32
        );
    }
    if context
        .device
        .features()
        .contains(wgpu::Features::TIMESTAMP_QUERY)
    {
        let (ta, tb) = (a.gpu_ms.expect("timestamps"), b.gpu_ms.expect("timestamps"));
        assert!(
            ta.is_finite() && tb.is_finite() && ta >= 0.0 && tb > 0.0,
            "{ta} {tb}"
        );
    }
}

#[test]
fn lod_runs_match_the_cpu_mirror_with_morphing() {
    use hairloom_core::runtime::frame_plan::plan_frame;
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let renderers = compute_renderers(&context);
    let renderer = &renderers[0];
    let document = common::sample("head_long_wavy");
    let runtime = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 32,
            ..RuntimeOptions::default()
        },
    );
    let textures = &runtime.textures;
    let roots = runtime.strand_roots();
    let hair = renderer.upload(&context, &runtime).expect("upload");
    // A camera far enough for partial strand counts, several vertex levels and morphing.
    let (lo, hi) = textures.hair_bounds().expect("hair");
    let (camera, lod) = common::morphing_lod(lo, hi);
    let plan = plan_frame(&hair.bundles, 32, 5, &camera, &lod, 4000, &[]);
    let runs: Vec<_> = plan.batches.iter().flatten().collect();
    assert!(
        plan.strands > 0 && plan.strands < roots.len(),
        "{}",
        plan.strands
    );
    assert!(runs.iter().any(|r| r.gamma > 0.0), "no run morphs");
    assert!(runs.iter().any(|r| r.vertex_count < 33), "no vertex LOD");
    assert!(plan.batches.len() > 1);
    let mirror = StrandGen {
        textures,
        filtering: Filtering::Exact,
    };
    let params = [&document.styling.global];
    let expected: Vec<_> = plan
        .batches
        .iter()
        .flat_map(|batch| mirror.main(&roots, batch, &params))
        .collect();
    for renderer in &renderers {
        let positions = renderer
            .generate_positions(&context, &hair, &plan, Filtering::Exact)
            .expect("positions");
        assert_eq!(positions.len(), plan.vertices);
        let size = document.hair_mesh.size() as f32;
        let worst = positions
            .iter()
            .zip(&expected)
            .map(|(g, e)| glam::Vec3::new(g[0], g[1], g[2]).distance(*e))
            .fold(0.0f32, f32::max);
        eprintln!(
            "LOD runs, {:?}: max |GPU − CPU mirror| = {worst:.3e} (size {size:.3})",
            renderer.path()
        );
        assert!(worst <= 1e-5 * size, "{worst}");
    }
}

#[test]
fn restyling_in_place_generates_what_a_fresh_upload_does() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let renderer = StrandGenRenderer::new(&context);
    let mut document = common::sample("head_curly");
    let options = RuntimeOptions {
        strands_per_bundle: 8,
        ..RuntimeOptions::default()
    };
    let mut runtime = RuntimeHair::from_document(&document, &options);
    let mut gpu = renderer.upload(&context, &runtime).expect("upload");
    // Other parameters and a new group (a longer styling array than was uploaded).
    document.styling.global.curl.radius_m = 0.007;
    document.styling.groups.push(StylingGroup {
        name: "fringe".into(),
        bundles: vec![0, 3, 4],
        params: StylingParams::every_op(),
    });
    runtime.set_styling(&document.styling);
    renderer.update_styling(&context, &mut gpu, &runtime);
    let fresh = renderer
        .upload(&context, &RuntimeHair::from_document(&document, &options))
        .expect("upload");
    let plan = full_detail_plan(gpu.root_count, 9);
    let restyled = renderer
        .generate_positions(&context, &gpu, &plan, Filtering::Exact)
        .expect("restyled");
    let uploaded = renderer
        .generate_positions(&context, &fresh, &plan, Filtering::Exact)
        .expect("fresh");
    assert_eq!(restyled, uploaded);
    let unstyled = renderer
        .generate_positions(
            &context,
            &renderer
                .upload(
                    &context,
                    &RuntimeHair::from_document(&common::sample("head_curly"), &options),
                )
                .expect("upload"),
            &plan,
            Filtering::Exact,
        )
        .expect("unstyled");
    assert_ne!(restyled, unstyled, "the new styling must show");
}

/// A hair mesh that moved (as motion and drape move it every frame) is written into the
/// uploaded textures in place and generates what a fresh upload does, in f16 too (whose
/// position offset follows the box); a changed layout is refused, nothing written.
#[test]
fn reshaping_in_place_generates_what_a_fresh_upload_does() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let renderer = StrandGenRenderer::new(&context);
    for precision in [Precision::F32, Precision::F16] {
        let mut document = common::sample("head_curly");
        let options = RuntimeOptions {
            strands_per_bundle: 8,
            precision,
            ..RuntimeOptions::default()
        };
        let mut gpu = renderer
            .upload(&context, &RuntimeHair::from_document(&document, &options))
            .expect("upload");
        let plan = full_detail_plan(gpu.root_count, 9);
        let before = renderer
            .generate_positions(&context, &gpu, &plan, Filtering::Exact)
            .expect("before");
        // Everything above the roots sways and sags (roots stay on the scalp).
        for (c, column) in document.hair_mesh.columns.iter_mut().enumerate() {
            for (k, p) in column.positions.iter_mut().enumerate().skip(1) {
                p.x += 0.004 * k as f64 * (c as f64 * 0.37).sin();
                p.y -= 0.003 * (k * k) as f64;
            }
        }
        document.hair_mesh.update_w();
        let moved = RuntimeHair::from_document(&document, &options);
        assert!(renderer.update_shape(&context, &mut gpu, &moved));
        let fresh = renderer.upload(&context, &moved).expect("upload");
        let reshaped = renderer
            .generate_positions(&context, &gpu, &plan, Filtering::Exact)
            .expect("reshaped");
        let uploaded = renderer
            .generate_positions(&context, &fresh, &plan, Filtering::Exact)
            .expect("fresh");
        assert_eq!(reshaped, uploaded, "{precision:?}");
        assert_ne!(reshaped, before, "{precision:?}: the motion must show");
        assert_eq!(gpu.bundles, fresh.bundles, "LOD bounds follow the mesh");
        // Another strand count needs other samples: refused.
        let denser = RuntimeHair::from_document(
            &document,
            &RuntimeOptions {
                strands_per_bundle: 16,
                ..options.clone()
            },
        );
        assert!(!renderer.update_shape(&context, &mut gpu, &denser));

        // One more layer on a bundle changes the layout: refused, the GPU hair untouched.
        let extruded = hairloom_core::edit::extrude(
            &document.hair_mesh,
            &[0],
            hairloom_core::edit::ExtrudeDirection::Vector {
                offset: [0.0, -0.02, 0.0],
            },
        )
        .expect("extrude");
        document.hair_mesh = extruded.mesh;
        let taller = RuntimeHair::from_document(&document, &options);
        assert!(!renderer.update_shape(&context, &mut gpu, &taller));
        let unchanged = renderer
            .generate_positions(&context, &gpu, &plan, Filtering::Exact)
            .expect("unchanged");
        assert_eq!(unchanged, uploaded);
    }
}

/// Above the adapter's limits the upload is refused by name before wgpu sees a descriptor
/// (wgpu would panic). Pure: runs without an adapter.
#[test]
fn hair_above_the_adapter_limits_is_refused_by_name() {
    use hairloom_render::renderer::strand_gen::{StrandGenError, check_adapter_limits};
    let hair =
        RuntimeHair::from_document(&common::sample("head_curly"), &RuntimeOptions::default());
    let depth = hair.textures.hair_mesh.depth;
    let layers = hair
        .textures
        .atlas
        .blocks
        .iter()
        .map(|b| b.layers)
        .max()
        .expect("bundles");
    let generous = wgpu::Limits::default();
    check_adapter_limits(&generous, &hair).expect("fits the default limits");
    let small = wgpu::Limits {
        max_texture_dimension_3d: depth - 1,
        ..wgpu::Limits::default()
    };
    let error = check_adapter_limits(&small, &hair).expect_err("one slice too many");
    assert!(
        matches!(error, StrandGenError::AdapterLimit { value, .. } if value == u64::from(depth))
    );
    let message = error.to_string();
    assert!(
        message.contains(&format!("hair_mesh texture's depth is {depth}"))
            && message.contains(&format!("max_texture_dimension_3d of {}", depth - 1))
            && message.contains(&format!("has {layers} layers")),
        "{message}"
    );
    let tiny_buffers = wgpu::Limits {
        max_storage_buffer_binding_size: 16,
        ..wgpu::Limits::default()
    };
    let message = check_adapter_limits(&tiny_buffers, &hair)
        .expect_err("buffers")
        .to_string();
    assert!(
        message.contains("max_storage_buffer_binding_size"),
        "{message}"
    );
}

/// Far hair's thick hairs (`thick_main`) against the mirror (`StrandGen::thick_main`) on the
/// long sample: every thick hair of every level, centres and both half-axes, exact filtering,
/// within the strands' bound; and the table names only grown strands of the right bundle.
#[test]
fn gpu_thick_hairs_match_the_cpu_mirror() {
    use hairloom_core::runtime::thick_hair::{FarHair, build_hierarchy};
    use hairloom_render::renderer::strand_gen::{GpuFarHair, ThickGenRenderer};
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let document = common::sample("head_long_wavy");
    let size = document.hair_mesh.size() as f32;
    let runtime = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 16,
            ..RuntimeOptions::default()
        },
    );
    let vertex_count = 9u32;
    let hierarchies = build_hierarchy(&runtime, vertex_count as usize).expect("hierarchy");
    let table = FarHair::new(&hierarchies, runtime.strands_per_bundle);
    assert!(!table.thick_hairs.is_empty());
    for thick in &table.thick_hairs {
        for corner in thick.corners {
            assert_eq!(corner / runtime.strands_per_bundle, thick.block);
            assert!(
                corner % runtime.strands_per_bundle
                    < runtime.block_strand_count(thick.block as usize)
            );
        }
    }
    let generator = StrandGenRenderer::new(&context);
    let thick_gen = ThickGenRenderer::new(&context);
    let hair = generator.upload(&context, &runtime).expect("upload");
    let far = GpuFarHair::upload(&context, table.clone());
    let count = table.thick_hairs.len() as u32;
    let readback = thick_gen
        .generate(
            &generator,
            &context,
            &hair,
            &far,
            0,
            count,
            vertex_count,
            Filtering::Exact,
        )
        .expect("thick hairs");
    let (positions, sections) = (readback.positions, readback.sections);
    let params: Vec<&StylingParams> = std::iter::once(&runtime.styling.global)
        .chain(runtime.styling.groups.iter().map(|g| &g.params))
        .collect();
    let mirror = StrandGen {
        textures: &runtime.textures,
        filtering: Filtering::Exact,
    };
    let expected = mirror.thick_main(
        &runtime.strand_roots(),
        &table.thick_hairs,
        vertex_count,
        &params,
    );
    assert_eq!(positions.len(), expected.len());
    let mut worst = 0.0f32;
    for (i, vertex) in expected.iter().enumerate() {
        let v = |x: [f32; 4]| glam::Vec3::new(x[0], x[1], x[2]);
        worst = worst
            .max(v(positions[i]).distance(vertex.centre))
            .max(v(sections[2 * i]).distance(vertex.major))
            .max(v(sections[2 * i + 1]).distance(vertex.minor));
        assert!((positions[i][3] - vertex.along).abs() < 1e-6);
        assert_eq!(sections[2 * i][3], vertex.members as f32);
    }
    let bound = 1e-5 * size;
    eprintln!("{count} thick hairs: max |GPU − CPU mirror| = {worst:.3e} (bound {bound:.3e})");
    assert!(worst <= bound, "{worst} > {bound}");
}

/// Far hair's deferred level choice (`far_lod.wgsl`, eq. 16) against its mirror
/// (`hairloom_core::runtime::far_lod`): frame after frame under a still camera at three
/// distances, the GPU chooses the levels the CPU does, settles, and goes coarser with
/// distance.
#[test]
fn gpu_far_levels_match_the_cpu_mirror_and_settle() {
    use hairloom_core::runtime::far_lod::{
        FarLodParams, measured_hairs, next_levels, thick_widths,
    };
    use hairloom_core::runtime::thick_hair::FarHair;
    use hairloom_render::renderer::far_lod::FarLodRenderer;
    use hairloom_render::renderer::strand_gen::ThickGenRenderer;
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let document = common::sample("head_long_wavy");
    let runtime = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 16,
            ..RuntimeOptions::default()
        },
    );
    let n = 9u32;
    let far = FarHair::build(&runtime, n as usize).expect("hierarchy");
    let generator = StrandGenRenderer::new(&context);
    let thick_gen = ThickGenRenderer::new(&context);
    let far_lod = FarLodRenderer::new(&context);
    let hair = generator.upload(&context, &runtime).expect("upload");
    let mirror = StrandGen {
        textures: &runtime.textures,
        filtering: Filtering::Exact,
    };
    let styling: Vec<&StylingParams> = std::iter::once(&runtime.styling.global)
        .chain(runtime.styling.groups.iter().map(|g| &g.params))
        .collect();
    let (lo, hi) = runtime.textures.hair_bounds().expect("hair");
    let centre = (lo + hi) * 0.5;
    let mut mean_levels = Vec::new();
    for distance_m in [0.8f32, 4.0, 20.0] {
        let eye = centre + glam::Vec3::new(0.3, 0.1, 1.0).normalize() * distance_m;
        let params = FarLodParams {
            eye: eye.extend(1.0).to_array(),
            pixel_at_unit: 2.0 * 15f32.to_radians().tan() / 1080.0,
            width_threshold_px: 2.0,
            vertex_count: n,
            count: 0,
        };
        let mut levels = vec![0u32; far.blocks.len()];
        let mut differing = 0usize;
        for frame in 0..10 {
            let gpu = far_lod
                .step(
                    &context, &generator, &thick_gen, &hair, &far, &levels, params,
                )
                .expect("far lod");
            let hairs = measured_hairs(&far, &levels);
            let vertices = mirror.thick_main(&runtime.strand_roots(), &hairs, n, &styling);
            let widths = thick_widths(
                &vertices,
                &hairs,
                &levels,
                &FarLodParams {
                    count: hairs.len() as u32,
                    ..params
                },
            );
            let cpu = next_levels(&levels, &widths, &far, params.width_threshold_px);
            // A width within f32 rounding of ε_w may fall either side: allow a handful.
            differing += gpu.iter().zip(&cpu).filter(|(g, c)| g != c).count();
            if frame == 9 {
                assert_eq!(
                    gpu, levels,
                    "{distance_m} m: still changing after 10 frames"
                );
            }
            levels = gpu;
        }
        assert!(
            differing <= far.blocks.len() / 100 + 1,
            "{distance_m} m: GPU and CPU chose differently {differing} times"
        );
        mean_levels.push(levels.iter().map(|&l| l as f64).sum::<f64>() / levels.len() as f64);
    }
    eprintln!("mean level at 0.8, 4 and 20 m: {mean_levels:?}");
    assert!(
        mean_levels.windows(2).all(|w| w[1] > w[0]),
        "{mean_levels:?}"
    );
}

/// Painted maps in root-uv space (density, length, clump): the GPU thins, shortens and
/// unclumps the strands exactly as the CPU mirror does, on the compute and the
/// vertex-shader paths, and a repaint taken in place (a new map size included) generates
/// what a fresh upload does.
#[test]
fn painted_maps_thin_shorten_and_unclump_on_the_gpu_as_on_the_cpu() {
    use hairloom_core::model::root_maps::{RootMapChannel, RootMaps};
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let renderers = compute_renderers(&context);
    let mut document = common::sample("head_curly");
    document.styling.global.clump.strength = 0.8;
    // 64² maps over uv [0, 1]²: no hair left of u = 0.5; half length above v = 0.5; no
    // clumping right of u = 0.6 (the scalp spans u 0.26 … 0.75).
    let side = 64u32;
    let image = |value: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
        (0..side * side)
            .map(|i| {
                let (x, y) = (i % side, i / side);
                value(
                    (x as f64 + 0.5) / side as f64,
                    (y as f64 + 0.5) / side as f64,
                )
            })
            .collect()
    };
    let mut maps = RootMaps::default();
    for (channel, values) in [
        (
            RootMapChannel::Density,
            image(&|u, _| if u < 0.5 { 0.0 } else { 1.0 }),
        ),
        (
            RootMapChannel::Length,
            image(&|_, v| if v < 0.5 { 0.5 } else { 1.0 }),
        ),
        (
            RootMapChannel::Clump,
            image(&|u, _| if u > 0.6 { 0.0 } else { 1.0 }),
        ),
    ] {
        maps.set_channel_from_image(channel, side, side, &values)
            .expect("map");
    }
    document.root_maps = maps;
    let options = RuntimeOptions {
        strands_per_bundle: 8,
        sample_seed: 5,
        ..RuntimeOptions::default()
    };
    let runtime = RuntimeHair::from_document(&document, &options);
    let roots = runtime.strand_roots();
    let mirror = StrandGen {
        textures: &runtime.textures,
        filtering: Filtering::Exact,
    };
    let params = [&document.styling.global];
    // The mirror itself obeys the maps.
    let (mut bare, mut halved, mut grown) = (0, 0, 0);
    let unpainted = RuntimeHair::from_document(
        &hairloom_core::model::document::Document {
            root_maps: RootMaps::default(),
            ..document.clone()
        },
        &options,
    );
    let plain = StrandGen {
        textures: &unpainted.textures,
        filtering: Filtering::Exact,
    };
    for root in &roots {
        let input = mirror.strand_input(root, params[0]);
        let full = plain.strand_input(root, params[0]);
        let (u, v) = (input.root_uv.x, input.root_uv.y);
        // Bilinear reads blend across one texel (1/64) at each edge: judged outside it.
        if u < 0.48 {
            assert_eq!(input.length_fraction, 0.0, "no hair left of u = 0.5");
            bare += 1;
        } else if u > 0.52 {
            grown += 1;
            let expected = if v < 0.48 {
                0.5
            } else if v > 0.52 {
                1.0
            } else {
                continue;
            };
            assert!(
                (input.length_fraction - expected * full.length_fraction).abs() < 0.01,
                "length map at {u:.3}, {v:.3}: {} of {}",
                input.length_fraction,
                full.length_fraction
            );
            if expected == 0.5 {
                halved += 1;
            }
            if u > 0.62 {
                assert_eq!(input.styling.clump_pull, glam::DVec2::ZERO);
            } else if u < 0.58 {
                assert_eq!(input.styling.clump_pull, full.styling.clump_pull);
            }
        }
    }
    assert!(
        bare > 100 && grown > 100 && halved > 50,
        "{bare} {grown} {halved}"
    );
    let vertex_count = 9u32;
    let plan = full_detail_plan(roots.len(), vertex_count);
    let expected = mirror.main(&roots, &plan.batches[0], &params);
    let size = document.hair_mesh.size() as f32;
    let worst_of = |positions: &[[f32; 4]]| {
        positions
            .iter()
            .zip(&expected)
            .map(|(g, e)| glam::Vec3::new(g[0], g[1], g[2]).distance(*e))
            .fold(0.0f32, f32::max)
    };
    let mut gpu = renderers[0].upload(&context, &runtime).expect("upload");
    let painted = renderers[0]
        .generate_positions(&context, &gpu, &plan, Filtering::Exact)
        .expect("positions");
    for renderer in &renderers {
        let positions = renderer
            .generate_positions(&context, &gpu, &plan, Filtering::Exact)
            .expect("positions");
        let worst = worst_of(&positions);
        eprintln!(
            "painted maps, {:?}: max |GPU − CPU mirror| = {worst:.3e}",
            renderer.path()
        );
        assert!(worst <= 1e-5 * size, "{worst}");
    }
    // Repainted in place at another size: what a fresh upload of the new maps generates.
    let mut repainted = document.clone();
    let mut small = RootMaps::blank(8, 8).expect("maps");
    small
        .set_channel_from_image(RootMapChannel::Density, 1, 1, &[0.3])
        .expect("map");
    repainted.root_maps = small;
    let mut runtime = runtime;
    runtime.textures.root_maps = repainted.root_maps.clone();
    renderers[0].update_styling(&context, &mut gpu, &runtime);
    let fresh = renderers[0]
        .upload(&context, &RuntimeHair::from_document(&repainted, &options))
        .expect("upload");
    let in_place = renderers[0]
        .generate_positions(&context, &gpu, &plan, Filtering::Exact)
        .expect("in place");
    let uploaded = renderers[0]
        .generate_positions(&context, &fresh, &plan, Filtering::Exact)
        .expect("fresh");
    assert_eq!(in_place, uploaded);
    assert_ne!(in_place, painted, "the repaint took");
}
