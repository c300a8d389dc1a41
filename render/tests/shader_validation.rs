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

/// The sources the renderer compiles: each shader with the shared files it includes.
fn embedded() -> [(&'static str, &'static str); 3] {
    [
        (
            "strand_gen",
            hairloom_render::renderer::strand_gen::SHADER_SOURCE,
        ),
        (
            "preview_hair",
            hairloom_render::renderer::preview_hair::HAIR_SHADER,
        ),
        (
            "preview_body",
            hairloom_render::renderer::preview_body::BODY_SHADER,
        ),
    ]
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
    for (name, source) in embedded() {
        parse(name, source);
    }
    // Every file on disk is what the renderer embeds: a shader (the tail of one embedded
    // source) or a shared file (prepended to at least one); none is left out or stale.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders");
    let files = wgsl_files(&dir);
    assert!(files.len() >= 4, "{files:?}");
    for (path, source) in &files {
        let used = embedded()
            .iter()
            .any(|(_, s)| s.ends_with(source.as_str()) || s.starts_with(source.as_str()));
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
    use hairloom_core::runtime::gpu_types::{
        BundleGpu, StrandGenParams, StrandRoot, StrandRun, StylingGpu,
    };
    use hairloom_render::renderer::preview_body::{BODY_SHADER, BodyUniforms};
    use hairloom_render::renderer::preview_hair::{HAIR_SHADER, HairUniforms};
    use hairloom_render::renderer::strand_gen::SHADER_SOURCE;
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
        (HAIR_SHADER, "StrandRun", size_of::<StrandRun>()),
        (HAIR_SHADER, "HairUniforms", size_of::<HairUniforms>()),
        (BODY_SHADER, "BodyUniforms", size_of::<BodyUniforms>()),
    ] {
        let module = parse(name, source);
        let wgsl_size = wgsl_struct_size(&module, name)
            .unwrap_or_else(|| panic!("{name} missing from strand_gen.wgsl"));
        assert_eq!(
            wgsl_size as usize, rust_size,
            "{name}: WGSL {wgsl_size} bytes, Rust {rust_size}"
        );
    }
}
