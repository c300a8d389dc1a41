//! Every WGSL file in `shaders/` parses and validates with naga (no GPU needed), and every
//! struct shared with Rust has the same size on both sides.

use std::path::Path;

/// Every `.wgsl` file under `dir` (recursively), sorted by path.
fn wgsl_files(dir: &Path) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).expect("shaders/ exists") {
        let path = entry.expect("dir entry").path();
        if path.is_dir() {
            out.extend(wgsl_files(&path));
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            let source = std::fs::read_to_string(&path).expect("read shader");
            out.push((path.display().to_string(), source));
        }
    }
    out.sort();
    out
}

/// The sources the renderer compiles: each shader with the shared files it includes, in
/// every combination of effect modules it can be composed of.
fn embedded() -> Vec<(String, String)> {
    use hairloom_core::model::scene::SelfShadowing;
    use hairloom_render::renderer::oit_composite::oit_composite_shader;
    use hairloom_render::renderer::shader_composer::{
        RibbonInput, ShaderKey, body_shader, hair_shader, hair_shadow_shader,
    };
    let inputs = [
        RibbonInput::Buffer,
        RibbonInput::Generated,
        RibbonInput::Mesh,
    ];
    let mut sources = vec![(
        "strand_gen".to_string(),
        hairloom_render::renderer::strand_gen::SHADER_SOURCE.to_string(),
    )];
    for key in ShaderKey::all() {
        for input in inputs {
            sources.push((
                format!("preview_hair {key:?} {input:?}"),
                hair_shader(&key, input),
            ));
        }
        sources.push((format!("preview_body {key:?}"), body_shader(&key)));
        sources.push((
            format!("far_hair {key:?}"),
            hairloom_render::renderer::shader_composer::far_hair_shader(&key),
        ));
        sources.push((
            format!("fur {key:?}"),
            hairloom_render::renderer::shader_composer::fur_shader(&key),
        ));
    }
    for kind in [
        SelfShadowing::OpacityShadowMaps,
        SelfShadowing::DeepOpacityMaps,
    ] {
        for input in inputs {
            sources.push((
                format!("hair_shadow {kind:?} {input:?}"),
                hair_shadow_shader(kind, input),
            ));
        }
        sources.push((
            format!("far_hair_shadow {kind:?}"),
            hairloom_render::renderer::shader_composer::far_hair_shadow_shader(kind),
        ));
    }
    for samples in [1, 4] {
        sources.push((
            format!("oit_composite {samples}×"),
            oit_composite_shader(samples),
        ));
    }
    sources.push((
        "far_lod".to_string(),
        hairloom_render::renderer::far_lod::FAR_LOD_SOURCE.to_string(),
    ));
    // Far hair's shading model, after the fibre model it builds on.
    sources.push((
        "aggregated_bcsdf".to_string(),
        format!(
            "{}\n{}",
            hairloom_render::renderer::preview_hair::default_hair_shader(),
            hairloom_render::renderer::shader_composer::aggregated_bcsdf_module()
        ),
    ));
    sources.push((
        "linear_hair_skinning".to_string(),
        hairloom_render::renderer::linear_hair_skinning::SHADER_SOURCE.to_string(),
    ));
    sources.push((
        "viewport_blit".to_string(),
        hairloom_render::renderer::viewport_blit::VIEWPORT_BLIT_SHADER.to_string(),
    ));
    sources
}

fn parse(name: &str, source: &str) -> naga::Module {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
    module
}

#[test]
fn every_shader_validates() {
    let sources = embedded();
    for (name, source) in &sources {
        parse(name, source);
    }
    // Every file on disk is part of what the renderer embeds (a shader, a shared file or an
    // effect module of at least one composed source); none is left out or stale.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders");
    let files = wgsl_files(&dir);
    assert!(files.len() >= 4, "{files:?}");
    for (path, source) in &files {
        let used = sources.iter().any(|(_, s)| s.contains(source.as_str()));
        assert!(
            used,
            "{path} is not part of any shader the renderer compiles"
        );
    }
}

/// Size of the WGSL struct `name` in `module`, by naga's layouter.
fn wgsl_struct_size(module: &naga::Module, name: &str) -> Option<u32> {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).ok()?;
    let (handle, _) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))?;
    Some(layouter[handle].size)
}

#[test]
fn gpu_structs_match_their_wgsl() {
    use hairloom_core::light::scene_uniforms::{GpuLight, GpuShadowView, SceneUniforms};
    use hairloom_core::runtime::gpu_types::{
        BundleGpu, BundleLodGpu, LodParams, StrandGenParams, StrandRoot, StrandRun, StylingGpu,
        ThickGenParams, ThickHairGpu,
    };
    use hairloom_render::renderer::preview_body::BodyUniforms;
    use hairloom_render::renderer::preview_hair::{HairUniforms, default_hair_shader};
    use hairloom_render::renderer::strand_gen::SHADER_SOURCE;
    let hair_shader = default_hair_shader();
    let body_shader = hairloom_render::renderer::shader_composer::body_shader(
        &hairloom_render::renderer::shader_composer::ShaderKey::all()[0],
    );
    let mesh_shader = hairloom_render::renderer::shader_composer::hair_shader(
        &hairloom_render::renderer::shader_composer::ShaderKey::all()[0],
        hairloom_render::renderer::shader_composer::RibbonInput::Mesh,
    );
    let far_shader = hairloom_render::renderer::shader_composer::far_hair_shader(
        &hairloom_render::renderer::shader_composer::ShaderKey::all()[0],
    );
    let (hair, body, mesh, far) = (
        hair_shader.as_str(),
        body_shader.as_str(),
        mesh_shader.as_str(),
        far_shader.as_str(),
    );
    for (source, name, rust_size) in [
        (
            SHADER_SOURCE,
            "StrandGenParams",
            size_of::<StrandGenParams>(),
        ),
        (SHADER_SOURCE, "StrandRoot", size_of::<StrandRoot>()),
        (SHADER_SOURCE, "Styling", size_of::<StylingGpu>()),
        (SHADER_SOURCE, "BundleGpu", size_of::<BundleGpu>()),
        (SHADER_SOURCE, "StrandRun", size_of::<StrandRun>()),
        (SHADER_SOURCE, "ThickHairGpu", size_of::<ThickHairGpu>()),
        (SHADER_SOURCE, "ThickGenParams", size_of::<ThickGenParams>()),
        (
            hairloom_render::renderer::far_lod::FAR_LOD_SOURCE,
            "FarLodParams",
            size_of::<hairloom_core::runtime::far_lod::FarLodParams>(),
        ),
        (hair, "StrandRun", size_of::<StrandRun>()),
        (
            hairloom_render::renderer::linear_hair_skinning::SHADER_SOURCE,
            "SkinParams",
            size_of::<hairloom_core::runtime::linear_hair_skinning::SkinParams>(),
        ),
        (
            hairloom_render::renderer::linear_hair_skinning::SHADER_SOURCE,
            "SkinBinding",
            size_of::<hairloom_core::runtime::linear_hair_skinning::SkinBinding>(),
        ),
        (hair, "HairUniforms", size_of::<HairUniforms>()),
        // Far hair binds the strands' view uniforms as its own.
        (far, "FarView", size_of::<HairUniforms>()),
        (body, "BodyUniforms", size_of::<BodyUniforms>()),
        (hair, "SceneUniforms", size_of::<SceneUniforms>()),
        (hair, "SceneLight", size_of::<GpuLight>()),
        (hair, "ShadowView", size_of::<GpuShadowView>()),
        (body, "SceneUniforms", size_of::<SceneUniforms>()),
        (mesh, "BundleLodGpu", size_of::<BundleLodGpu>()),
        (mesh, "LodParams", size_of::<LodParams>()),
    ] {
        let module = parse(name, source);
        let wgsl_size = wgsl_struct_size(&module, name)
            .unwrap_or_else(|| panic!("{name} missing from its shader"));
        assert_eq!(
            wgsl_size as usize, rust_size,
            "{name}: WGSL {wgsl_size} bytes, Rust {rust_size}"
        );
    }
}

/// The mesh path's groups fit NVIDIA's mesh-shader limits, which wgpu does not check:
/// 28 KiB of workgroup memory (naga's SPIR-V keeps the outputs there too, then copies them
/// out) and 32 KiB of outputs counted in 16-byte attribute slots.
#[test]
fn mesh_shader_groups_fit_nvidia_limits() {
    use hairloom_core::model::scene::SelfShadowing;
    use hairloom_render::renderer::shader_composer::{
        RibbonInput, ShaderKey, hair_shader, hair_shadow_shader,
    };
    let mut sources: Vec<(String, String)> = ShaderKey::all()
        .iter()
        .map(|key| (format!("{key:?}"), hair_shader(key, RibbonInput::Mesh)))
        .collect();
    for kind in [
        SelfShadowing::OpacityShadowMaps,
        SelfShadowing::DeepOpacityMaps,
    ] {
        sources.push((
            format!("shadow {kind:?}"),
            hair_shadow_shader(kind, RibbonInput::Mesh),
        ));
    }
    for (name, source) in &sources {
        let module = parse(name, source);
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).expect("layout");
        let workgroup_bytes: u32 = module
            .global_variables
            .iter()
            .filter(|(_, v)| v.space == naga::AddressSpace::WorkGroup)
            .map(|(_, v)| layouter[v.ty].size)
            .sum();
        assert!(
            workgroup_bytes <= 28 * 1024,
            "{name}: {workgroup_bytes} B of workgroup memory"
        );
        // The vertices' attribute slots: the position and each location.
        let vertices = module
            .types
            .iter()
            .find_map(|(_, t)| match &t.inner {
                naga::TypeInner::Struct { members, .. }
                    if members.iter().any(|m| {
                        m.binding == Some(naga::Binding::BuiltIn(naga::BuiltIn::Vertices))
                    }) =>
                {
                    members.iter().find_map(|m| {
                        (m.binding == Some(naga::Binding::BuiltIn(naga::BuiltIn::Vertices)))
                            .then_some(m.ty)
                    })
                }
                _ => None,
            })
            .expect("mesh output");
        let naga::TypeInner::Array { base, size, .. } = module.types[vertices].inner else {
            panic!("{name}: vertices is not an array");
        };
        let naga::ArraySize::Constant(count) = size else {
            panic!("{name}: vertices has no fixed size");
        };
        let naga::TypeInner::Struct { members, .. } = &module.types[base].inner else {
            panic!("{name}: a vertex is not a struct");
        };
        let output_bytes = count.get() * members.len() as u32 * 16;
        assert!(
            output_bytes <= 32 * 1024,
            "{name}: {output_bytes} B of vertex outputs"
        );
        eprintln!(
            "{name}: {workgroup_bytes} B workgroup memory, {output_bytes} B of vertex outputs"
        );
    }
}
