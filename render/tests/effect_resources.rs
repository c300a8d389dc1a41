//! Effects on demand: per scene, exactly the GPU resources its effects need exist — an effect
//! the scene does not name has no pipeline, texture or buffer — and taking an effect away
//! frees its resources (the registry of `hairloom_render::resources` lists what is alive).

use std::collections::BTreeSet;

use glam::Vec3;
use hairloom_core::model::scene::{
    Coverage, Effects, FarHair, Fur, MultipleScattering, Scene, SelfShadowing, Shading,
};
use hairloom_core::runtime::frame_plan::LodSettings;
use hairloom_core::runtime::hair::{RuntimeHair, RuntimeOptions};
use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::thick_hair::FarHair as FarTable;
use hairloom_render::device::headless_for_test;
use hairloom_render::frame::Phase;
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, default_scene};
use hairloom_render::renderer::preview_body::GpuBody;
use hairloom_render::renderer::strand_gen::{GpuFarHair, StrandGenRenderer};

/// Every label an optional effect may own, by effect.
const OPACITY_SHADOW_MAPS: &[&str] = &["opacity_layers", "hair_shadow_opacity"];
const DEEP_OPACITY_MAPS: &[&str] = &[
    "opacity_layers",
    "hair_shadow_opacity",
    "first_hair_depth",
    "hair_shadow_depth",
];
const BODY_SHADOWS: &[&str] = &["body_shadow_depth", "body_shadow"];
const DUAL_SCATTERING: &[&str] = &["dual_scattering_profile", "dual_scattering_lobes"];
const WIDTH_OIT: &[&str] = &[
    "oit_accumulation",
    "oit_revealage",
    "oit_composite",
    "preview_hair_oit",
];
const FAR_HAIR: &[&str] = &[
    "far_hair_aggregated_tables",
    "far_hair_depth",
    "far_hair",
    "thick_gen",
    "thick_widths",
    "next_levels",
];
/// Fur's pipelines (its textures belong to the hair asset, made where a scene asks).
const FUR: &[&str] = &["fur_shells", "fur_fins"];
/// Far hair into the lights' opacity maps (with self-shadowing).
const FAR_HAIR_SHADOWS: &[&str] = &["far_hair_shadow_opacity"];
const FAR_HAIR_DEEP_SHADOWS: &[&str] = &["far_hair_shadow_opacity", "far_hair_shadow_depth"];

fn effect_labels() -> BTreeSet<&'static str> {
    [
        OPACITY_SHADOW_MAPS,
        DEEP_OPACITY_MAPS,
        BODY_SHADOWS,
        DUAL_SCATTERING,
        WIDTH_OIT,
        FAR_HAIR,
        FAR_HAIR_DEEP_SHADOWS,
        FUR,
    ]
    .concat()
    .into_iter()
    .collect()
}

/// The effect labels `effects` must have alive (the default scene has shadow-casting lights
/// and the sample has a body).
fn expected(effects: &Effects) -> BTreeSet<&'static str> {
    let mut labels = BTreeSet::new();
    match effects.self_shadowing {
        SelfShadowing::None => {}
        SelfShadowing::OpacityShadowMaps => labels.extend(OPACITY_SHADOW_MAPS),
        SelfShadowing::DeepOpacityMaps => labels.extend(DEEP_OPACITY_MAPS),
    }
    if effects.body_shadows {
        labels.extend(BODY_SHADOWS);
    }
    if effects.multiple_scattering == MultipleScattering::DualScattering
        && effects.shading == Shading::Marschner
    {
        labels.extend(DUAL_SCATTERING);
    }
    if effects.coverage == Coverage::WidthOit {
        labels.extend(WIDTH_OIT);
    }
    if effects.far_hair == FarHair::Aggregated {
        labels.extend(FAR_HAIR);
        match effects.self_shadowing {
            SelfShadowing::None => {}
            SelfShadowing::OpacityShadowMaps => labels.extend(FAR_HAIR_SHADOWS),
            SelfShadowing::DeepOpacityMaps => labels.extend(FAR_HAIR_DEEP_SHADOWS),
        }
    }
    if effects.fur == Fur::ShellsFins {
        labels.extend(FUR);
    }
    labels
}

/// The frame builder's renderers `effects` must have (the lighting, body and hair always).
fn expected_renderers(effects: &Effects) -> BTreeSet<&'static str> {
    let mut names = BTreeSet::from(["scene lighting", "body", "hair ribbons"]);
    if effects.self_shadowing != SelfShadowing::None {
        names.insert("hair shadows");
    }
    if effects.body_shadows {
        names.insert("body shadows");
    }
    if effects.coverage == Coverage::WidthOit {
        names.insert("width coverage");
    }
    if effects.far_hair == FarHair::Aggregated {
        names.insert("far hair");
    }
    if effects.fur == Fur::ShellsFins {
        names.insert("fur");
    }
    names
}

#[test]
fn each_scene_has_exactly_the_resources_its_effects_need() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/samples/head_curly.hairloom");
    let document = hairloom_core::io::project::load(&path)
        .expect("sample")
        .document;
    let hair = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 4,
            ..RuntimeOptions::default()
        },
    );
    let generator = StrandGenRenderer::new(&context);
    let gpu_hair = generator.upload(&context, &hair).expect("upload");
    let far = GpuFarHair::upload(&context, FarTable::build(&hair, 9).expect("hierarchy"));
    let body = GpuBody::upload(&context, &hair.body);
    let renderer = PreviewRenderer::new(&context);
    let (lo, hi) = hair.textures.hair_bounds().expect("hair");
    let camera = Camera::framing(lo, hi, Vec3::new(0.75, 0.25, 1.0));
    let base = Scene {
        effects: Effects {
            shadow_resolution: 128,
            ..Effects::default()
        },
        ..Scene::default()
    };
    let none = base.effects.none();
    let alone = |f: fn(&mut Effects)| {
        let mut effects = none.clone();
        f(&mut effects);
        effects
    };
    let scenes = [
        none.clone(),
        alone(|e| e.shading = Shading::Marschner),
        alone(|e| e.self_shadowing = SelfShadowing::OpacityShadowMaps),
        alone(|e| e.self_shadowing = SelfShadowing::DeepOpacityMaps),
        alone(|e| e.body_shadows = true),
        // Dual scattering extends the Marschner model: alone (with Kajiya-Kay) it runs nothing.
        alone(|e| e.multiple_scattering = MultipleScattering::DualScattering),
        alone(|e| {
            e.shading = Shading::Marschner;
            e.multiple_scattering = MultipleScattering::DualScattering;
        }),
        alone(|e| e.coverage = Coverage::WidthOit),
        alone(|e| e.far_hair = FarHair::Aggregated),
        alone(|e| {
            e.far_hair = FarHair::Aggregated;
            e.self_shadowing = SelfShadowing::OpacityShadowMaps;
        }),
        alone(|e| e.fur = Fur::ShellsFins),
        base.effects.all(),
        Effects {
            opacity_layers: 16,
            ..base.effects.all()
        },
        none.clone(),
    ];
    let mut bytes_by_scene = Vec::new();
    for effects in scenes {
        let lighting = Scene {
            effects: effects.clone(),
            ..base.clone()
        };
        let scene = default_scene(
            &body,
            HairSource::Generated {
                generator: &generator,
                hair: &gpu_hair,
                filtering: Filtering::Exact,
                lod: LodSettings::default(),
                far: Some(&far),
                fur: None,
            },
            17,
            (lo, hi),
            camera,
            &lighting,
        );
        let plan = renderer.plan(&scene, 48, 48);
        let pixels = renderer
            .render(&context, &scene, &plan, 48, 48)
            .unwrap_or_else(|e| panic!("{:?}: {e}", effects.names()));
        assert_eq!(pixels.len(), 48 * 48 * 4);
        let live = context.resources.live_labels();
        let present: BTreeSet<&str> = effect_labels()
            .into_iter()
            .filter(|label| live.contains_key(*label))
            .collect();
        assert_eq!(
            present,
            expected(&effects),
            "effects {:?}: live {:?}",
            effects.names(),
            live
        );
        // Always there: the frame's own renderers and the hair.
        for label in [
            "preview_hair",
            "preview_body",
            "strand_gen",
            "hair_mesh",
            "view_color",
        ] {
            assert!(live.contains_key(label), "{label} missing: {live:?}");
        }
        // The frame builder's renderers are exactly the scene's, and a frame records only
        // the phases they name, in order.
        let renderers: BTreeSet<&str> = renderer
            .participants()
            .iter()
            .map(|(name, _)| *name)
            .collect();
        assert_eq!(
            renderers,
            expected_renderers(&effects),
            "effects {:?}",
            effects.names()
        );
        let phases: Vec<Phase> = Phase::ORDER
            .into_iter()
            .filter(|phase| {
                renderer
                    .participants()
                    .iter()
                    .any(|(_, named)| named.contains(phase))
            })
            .collect();
        let mut wanted = Vec::new();
        if effects.far_hair == FarHair::Aggregated {
            wanted.push(Phase::Generation);
        }
        if effects.self_shadowing != SelfShadowing::None || effects.body_shadows {
            wanted.push(Phase::ShadowViews);
        }
        wanted.push(Phase::Opaque);
        if effects.fur == Fur::ShellsFins {
            wanted.push(Phase::Fur);
        }
        wanted.extend([Phase::DepthPrePass, Phase::Lit]);
        if effects.coverage == Coverage::WidthOit {
            wanted.extend([Phase::Coverage, Phase::Composite]);
        }
        assert_eq!(phases, wanted, "effects {:?}", effects.names());
        bytes_by_scene.push(context.resources.live_bytes());
    }
    // All effects with 16 layers hold more than none; back to none frees it all again.
    let (first, last) = (bytes_by_scene[0], *bytes_by_scene.last().expect("scenes"));
    assert!(bytes_by_scene[12] > bytes_by_scene[11] && bytes_by_scene[11] > first);
    assert_eq!(first, last, "turning every effect off frees what they made");
}

#[test]
fn a_shadow_map_above_the_adapter_limit_is_refused_by_name() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let body = GpuBody::empty();
    let renderer = PreviewRenderer::new(&context);
    let limit = context.device.limits().max_texture_dimension_2d;
    let lighting = Scene {
        effects: Effects {
            shadow_resolution: limit + 1,
            ..Effects::default()
        },
        ..Scene::default()
    };
    let scene = default_scene(
        &body,
        HairSource::Vertices(&[[0.0, 0.0, 0.0, 0.0], [0.0, 0.1, 0.0, 1.0]]),
        2,
        (Vec3::splat(-0.1), Vec3::splat(0.1)),
        Camera::framing(Vec3::splat(-0.1), Vec3::splat(0.1), Vec3::Z),
        &lighting,
    );
    let plan = renderer.plan(&scene, 16, 16);
    let error = renderer
        .render(&context, &scene, &plan, 16, 16)
        .expect_err("above the limit");
    let message = error.to_string();
    assert!(
        message.contains("scene.effects.shadow_resolution")
            && message.contains("max_texture_dimension_2d"),
        "{message}"
    );
    assert!(
        !context
            .resources
            .live_labels()
            .contains_key("opacity_layers"),
        "nothing was made"
    );
}

#[test]
fn each_effect_is_measured_switched_on_and_off() {
    use hairloom_render::measure::{effect_costs, toggled_effects};
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/samples/teapot_fur.hairloom");
    let document = hairloom_core::io::project::load(&path)
        .expect("sample")
        .document;
    let hair = RuntimeHair::from_document(
        &document,
        &RuntimeOptions {
            strands_per_bundle: 2,
            ..RuntimeOptions::default()
        },
    );
    let generator = StrandGenRenderer::new(&context);
    let gpu_hair = generator.upload(&context, &hair).expect("upload");
    let far = GpuFarHair::upload(&context, FarTable::build(&hair, 9).expect("hierarchy"));
    let body = GpuBody::upload(&context, &hair.body);
    let (lo, hi) = hair.textures.hair_bounds().expect("hair");
    let lighting = Scene {
        effects: Effects {
            shadow_resolution: 64,
            ..Effects::default()
        },
        ..document.scene.clone()
    };
    let scene = default_scene(
        &body,
        HairSource::Generated {
            generator: &generator,
            hair: &gpu_hair,
            filtering: Filtering::Exact,
            lod: LodSettings::default(),
            far: Some(&far),
            fur: None,
        },
        9,
        (lo, hi),
        Camera::framing(lo, hi, Vec3::new(0.3, 0.5, 1.0)),
        &lighting,
    );
    let mut configurations = vec![("the scene", lighting.effects.clone())];
    configurations.extend(toggled_effects(&lighting.effects));
    let costs = effect_costs(&context, &scene, &configurations, 32, 32, 1).expect("measured");
    let names: Vec<&str> = costs.iter().map(|c| c.name).collect();
    assert_eq!(
        names,
        vec![
            "the scene",
            "marschner",
            "self-shadowing",
            "body-shadows",
            "dual-scattering",
            "width-oit",
            "far-hair",
            "fur"
        ]
    );
    for cost in &costs {
        assert!(cost.frame_ms.is_finite() && cost.frame_ms > 0.0, "{cost:?}");
        assert!(cost.strands > 0);
    }
    // Switching self-shadowing off (the scene has it on) frees its maps: less memory.
    assert!(costs[2].live_bytes < costs[0].live_bytes, "{costs:?}");
    // Switching width-based coverage on adds its targets, far hair its tables.
    assert!(costs[5].live_bytes > costs[0].live_bytes, "{costs:?}");
    assert!(costs[6].live_bytes > costs[0].live_bytes, "{costs:?}");
}
