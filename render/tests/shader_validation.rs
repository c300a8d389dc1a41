//! Every WGSL file in `shaders/` parses and validates with naga (no GPU needed), and every
//! struct shared with Rust has the same size on both sides.

use std::path::Path;

fn shaders() -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shaders");
    let mut out: Vec<(String, String)> = std::fs::read_dir(&dir)
        .expect("shaders/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "wgsl"))
        .map(|p| {
            (
                p.display().to_string(),
                std::fs::read_to_string(&p).expect("read shader"),
            )
        })
        .collect();
    out.sort();
    out
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
    let shaders = shaders();
    assert!(!shaders.is_empty());
    for (name, source) in &shaders {
        parse(name, source);
    }
    // The source the renderer embeds is the file on disk.
    assert!(
        shaders
            .iter()
            .any(|(_, s)| s == hairloom_render::strand_gen::SHADER_SOURCE)
    );
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
    use hairloom_render::preview::{BODY_SHADER, BodyUniforms, HAIR_SHADER, HairUniforms};
    use hairloom_render::strand_gen::SHADER_SOURCE;
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
