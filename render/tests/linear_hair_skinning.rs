//! Linear hair skinning (the LHS baseline, `shaders/linear_hair_skinning.wgsl`) against its
//! CPU mirror on a bent pose and a morphing LOD plan, and a skinned frame at rest against the
//! generated frame it stores (seed 000 §5: "identical images").

mod common;

use glam::{Quat, Vec3};
use hairloom_core::runtime::frame_plan::{LodSettings, plan_frame};
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::linear_hair_skinning::{GuidePose, SkinnedHair, guide_frames};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_render::device::{GpuContext, headless_for_test};
use hairloom_render::renderer::linear_hair_skinning::LinearHairSkinningRenderer;
use hairloom_render::renderer::strand_gen::{GpuHair, StrandGenRenderer, full_detail_plan};

const VERTICES: u32 = 33;

/// The long sample's runtime hair at `per_bundle` strands a bundle, uploaded, and its
/// strands generated on the GPU at full detail, bound to 2 % of them as guides.
fn skinned_sample(
    context: &GpuContext,
    per_bundle: u32,
) -> (RuntimeHair, StrandGenRenderer, GpuHair, SkinnedHair) {
    let document = common::sample("head_long_wavy");
    let runtime = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: per_bundle,
            ..RuntimeOptions::default()
        },
    );
    let generator = StrandGenRenderer::new(context);
    let hair = generator.upload(context, &runtime).expect("upload");
    let generated = generator
        .generate_positions(
            context,
            &hair,
            &full_detail_plan(hair.root_count, VERTICES),
            Filtering::Exact,
        )
        .expect("generate");
    let points: Vec<Vec3> = generated
        .iter()
        .map(|p| Vec3::from_slice(&p[..3]))
        .collect();
    let skinned = SkinnedHair::bind(&points, VERTICES, 0.02).expect("bind");
    (runtime, generator, hair, skinned)
}

#[test]
fn gpu_skinning_matches_the_cpu_mirror() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let (runtime, _generator, hair, skinned) = skinned_sample(&context, 16);
    // Bend every guide's lower half about its middle vertex and turn the whole pose.
    let turn = Quat::from_rotation_y(0.6);
    let v = VERTICES as usize;
    let mut pose = skinned.rest.clone();
    for g in 0..skinned.guides.len() {
        let pivot = pose.points[g * v + v / 2];
        for s in v / 2..v {
            let p = &mut pose.points[g * v + s];
            *p = pivot + Quat::from_rotation_x(0.5) * (*p - pivot);
        }
    }
    let pose = GuidePose {
        points: pose.points.iter().map(|p| turn * *p).collect(),
        references: pose.references.iter().map(|r| turn * *r).collect(),
    };
    let skinner = LinearHairSkinningRenderer::new(&context);
    let gpu = skinner.upload(&context, &skinned).expect("upload");
    skinner
        .set_pose(&context, &gpu, &skinned, &pose)
        .expect("pose");
    let (lo, hi) = runtime.textures.hair_bounds().expect("hair");
    let (camera, lod) = common::morphing_lod(lo, hi);
    let plan = plan_frame(&hair.bundles, 16, 5, &camera, &lod, usize::MAX / 2, &[]);
    let runs: Vec<_> = plan.batches.iter().flatten().copied().collect();
    assert!(runs.iter().any(|r| r.gamma > 0.0), "no run morphs");
    assert!(
        runs.iter().any(|r| r.vertex_count != runs[0].vertex_count),
        "one vertex count only"
    );
    let on_gpu = skinner.skin_positions(&context, &gpu, &plan).expect("skin");
    let frames = guide_frames(&pose, VERTICES);
    let mirror = skinned.skin_main(&pose, &frames, &runs);
    assert_eq!(on_gpu.len(), mirror.len());
    let size = (hi - lo).length();
    let worst = on_gpu
        .iter()
        .zip(&mirror)
        .map(|(a, b)| {
            assert_eq!(a[3], b[3], "along");
            Vec3::from_slice(a).distance(Vec3::from_slice(b))
        })
        .fold(0.0f32, f32::max);
    assert!(worst < 2e-6 * size, "worst {worst} m of {size} m");
    // The same in batches small enough that a frame takes several (runs after the first
    // batch's, batch-relative offsets).
    let batched = plan_frame(&hair.bundles, 16, 5, &camera, &lod, 4000, &[]);
    assert!(
        batched.batches.len() > 2,
        "{} batches",
        batched.batches.len()
    );
    let on_gpu_batched = skinner
        .skin_positions(&context, &gpu, &batched)
        .expect("skin");
    let mirror_batched: Vec<[f32; 4]> = batched
        .batches
        .iter()
        .flat_map(|batch| skinned.skin_main(&pose, &frames, batch))
        .collect();
    assert_eq!(on_gpu_batched.len(), mirror_batched.len());
    let worst_batched = on_gpu_batched
        .iter()
        .zip(&mirror_batched)
        .map(|(a, b)| Vec3::from_slice(a).distance(Vec3::from_slice(b)))
        .fold(0.0f32, f32::max);
    assert!(
        worst_batched < 2e-6 * size,
        "batched: worst {worst_batched} m"
    );
    // And the pose moved the hair: the mirror is not the rest.
    let rest = skinned.skin_main(&skinned.rest, &guide_frames(&skinned.rest, VERTICES), &runs);
    let moved = mirror
        .iter()
        .zip(&rest)
        .filter(|(a, b)| Vec3::from_slice(*a).distance(Vec3::from_slice(*b)) > 0.01 * size)
        .count();
    assert!(moved > mirror.len() / 2, "{moved} of {}", mirror.len());
}

#[test]
fn a_skinned_frame_at_rest_draws_the_generated_picture() {
    use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, default_scene};
    use hairloom_render::renderer::preview_body::GpuBody;
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let (runtime, generator, hair, skinned) = skinned_sample(&context, 12);
    let skinner = LinearHairSkinningRenderer::new(&context);
    let gpu = skinner.upload(&context, &skinned).expect("upload");
    let document = common::sample("head_long_wavy");
    let body = GpuBody::upload(&context, &document.body);
    let (lo, hi) = runtime.textures.hair_bounds().expect("hair");
    let preview = PreviewRenderer::new(&context);
    let (width, height) = (160, 160);
    for (direction, lod) in [
        (Vec3::new(0.75, 0.25, 1.0), LodSettings::default()),
        (
            Vec3::new(-1.0, 0.3, -0.4),
            LodSettings {
                enabled: false,
                ..LodSettings::default()
            },
        ),
    ] {
        let camera = Camera::framing(lo, hi, direction);
        let picture = |source| {
            let frame = default_scene(&body, source, VERTICES, (lo, hi), camera, &document.scene);
            let plan = preview.plan(&frame, width, height);
            let picture = preview
                .render(&context, &frame, &plan, width, height)
                .expect("frame");
            (picture, plan)
        };
        let (generated, generated_plan) = picture(HairSource::Generated {
            generator: &generator,
            hair: &hair,
            filtering: Filtering::Exact,
            lod,
            far: None,
            fur: None,
        });
        let (skinned_picture, skinned_plan) = picture(HairSource::Skinned {
            skinner: &skinner,
            skinned: &gpu,
            hair: &hair,
            lod,
        });
        assert_eq!(generated_plan, skinned_plan, "one plan for both");
        let (differing, drawn) = common::compare(&generated, &skinned_picture);
        assert!(drawn > 2000, "{drawn} pixels drawn");
        // f32 rounding of the skinned positions may move a ribbon edge across a sample.
        assert!(
            differing * 200 <= drawn,
            "{differing} of {drawn} pixels differ ({direction})"
        );
    }
}
