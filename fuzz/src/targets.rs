//! The fuzz targets: one per reader of outside data. Each takes any bytes; a returned
//! error is the expected outcome for most inputs, a panic is a bug.

use std::collections::HashMap;
use std::sync::OnceLock;

use hairloom_core::io::import::{ImportOptions, import_slice};
use hairloom_core::io::ktx2::{TexelFormat, read_texture};
use hairloom_core::io::runtime_bundle::{MANIFEST_FILE, Manifest, load_runtime_bundle_from};
use hairloom_core::runtime::strand_gen::{Filtering, StrandGen};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// `io::project::from_bytes`: parse, validate, migrate and verify the history.
    ProjectLoad,
    /// `io::import::import_slice` (GLB or glTF JSON), then the scalp the editor builds.
    GltfImport,
    /// `io::runtime_bundle::load_runtime_bundle_from` with one file of a valid bundle
    /// replaced by the input (see [`bundle_input`]), then strands generated from it.
    RuntimeBundle,
    /// `io::ktx2::read_texture` of a whole KTX2 file.
    Ktx2,
    /// A strand export of a project (the input after its first two bytes) at the size those
    /// bytes pick, up to and past the documented maxima (see [`strand_export_input`]):
    /// refused by the cap with its size, or generated and written in every format.
    StrandExport,
    /// `io::groom_in`'s readers (cyHair `.hair`, Alembic, USD text and crate files) under
    /// small caps: the first byte picks the format (see [`groom_input`]), the rest is the
    /// file. A groom read without error must keep the readers' promises (see
    /// [`check_groom`]): the fit indexes by them.
    GroomIn,
}

impl Target {
    pub const ALL: [Target; 6] = [
        Target::ProjectLoad,
        Target::GltfImport,
        Target::RuntimeBundle,
        Target::Ktx2,
        Target::StrandExport,
        Target::GroomIn,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Target::ProjectLoad => "project_load",
            Target::GltfImport => "gltf_import",
            Target::RuntimeBundle => "runtime_bundle",
            Target::Ktx2 => "ktx2",
            Target::StrandExport => "strand_export",
            Target::GroomIn => "groom_in",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }

    pub fn run(self, input: &[u8]) {
        match self {
            Target::ProjectLoad => project_load(input),
            Target::GltfImport => gltf_import(input),
            Target::RuntimeBundle => runtime_bundle(input),
            Target::Ktx2 => ktx2(input),
            Target::StrandExport => strand_export(input),
            Target::GroomIn => groom_in(input),
        }
    }
}

fn project_load(input: &[u8]) {
    let _ = hairloom_core::io::project::from_bytes(input, std::path::Path::new("fuzz.hairloom"));
}

fn gltf_import(input: &[u8]) {
    // Every mesh as one body, under caps counted over all of them.
    if let Ok((body, _)) = hairloom_core::io::import::import_body_slice(
        input,
        None,
        "fuzz.glb",
        &ImportOptions::default(),
    ) {
        let _ = body.validate();
    }
    if let Ok(imported) = import_slice(input, None, "fuzz.glb", &ImportOptions::default()) {
        let _ = imported.to_body().validate();
        let _ = imported.to_hair_mesh(|_| true).validate();
        // Every way of choosing where hair grows, on whatever materials and colours the
        // input claims.
        let mut regions = vec![
            hairloom_core::io::scalp_region::ScalpRegion::All,
            "colour:r>0.5".parse().expect("a valid region"),
        ];
        let materials = hairloom_core::io::scalp_region::material_faces(&imported);
        if let Some((name, _)) = materials.first() {
            regions.push(hairloom_core::io::scalp_region::ScalpRegion::Materials(
                vec![name.clone()],
            ));
        }
        for region in regions {
            if let Ok(keep) = region.faces(&imported) {
                let _ = imported.to_hair_mesh(|f| keep[f]).validate();
            }
        }
    }
}

/// The files of a valid runtime bundle (with a body), built once.
fn base_bundle() -> &'static [(String, Vec<u8>)] {
    static BASE: OnceLock<Vec<(String, Vec<u8>)>> = OnceLock::new();
    BASE.get_or_init(crate::corpus::bundle_with_body_files)
}

/// A runtime-bundle fuzz input: the first byte picks the file of [`base_bundle`] that the
/// rest replaces (modulo the file count; the manifest is last).
pub fn bundle_input(file_index: usize, bytes: &[u8]) -> Vec<u8> {
    let mut input = vec![file_index as u8];
    input.extend_from_slice(bytes);
    input
}

fn runtime_bundle(input: &[u8]) {
    let Some((&selector, payload)) = input.split_first() else {
        return;
    };
    let base = base_bundle();
    let mut files: HashMap<String, Vec<u8>> = base.iter().cloned().collect();
    let (name, _) = &base[selector as usize % base.len()];
    files.insert(name.clone(), payload.to_vec());
    let Ok(hair) = load_runtime_bundle_from(&files, "fuzz") else {
        return;
    };
    // What a loaded bundle is used for: roots and strand positions.
    let _ = hair.strand_roots();
    let generator = StrandGen {
        textures: &hair.textures,
        filtering: Filtering::Exact,
    };
    for block in 0..hair.textures.atlas.blocks.len().min(64) {
        let _ = generator.position(block, 0.3, 0.6, 0.7);
    }
    // Each root's set-up reads the painted maps at its root uv.
    for root in hair.strand_roots().iter().take(256) {
        let _ = generator.strand_input(root, &hair.styling.global);
    }
}

fn ktx2(input: &[u8]) {
    // Read with the format and size the file itself declares, so the reader gets past its
    // agreement checks and into the level data.
    let word = |at: usize| {
        input
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .unwrap_or(0)
    };
    let format = [
        TexelFormat::Rgba32Float,
        TexelFormat::Rg32Float,
        TexelFormat::R32Float,
        TexelFormat::Rgba16Float,
        TexelFormat::Rg16Float,
        TexelFormat::R16Float,
        TexelFormat::Rgba8Unorm,
    ]
    .into_iter()
    .find(|f| f.vk_number() == word(12))
    .unwrap_or(TexelFormat::Rgba32Float);
    let _ = read_texture(input, format, [word(20), word(24), word(28)]);
}

/// Strands per bundle a [`Target::StrandExport`] input's first byte picks: the documented
/// maximum (4096) among them, and one past it.
const STRANDS_PER_BUNDLE: [u32; 6] = [1, 8, 64, 256, 4096, 4097];

/// A strand-export fuzz input: `strands_per_bundle` (one of [`STRANDS_PER_BUNDLE`]) and
/// `vertices_log2` (0 to 11: the documented maximum 10 and one past it) before the project.
pub fn strand_export_input(strands_per_bundle: u32, vertices_log2: u32, project: &[u8]) -> Vec<u8> {
    let pick = STRANDS_PER_BUNDLE
        .iter()
        .position(|&n| n == strands_per_bundle)
        .unwrap_or(0);
    let mut input = vec![pick as u8, vertices_log2 as u8];
    input.extend_from_slice(project);
    input
}

/// Points above which an accepted export is only checked, not generated: the fuzz run's
/// own time bound (the cap itself is what the check tests).
const FUZZ_GENERATED_POINTS: u64 = 20_000;

fn strand_export(input: &[u8]) {
    use hairloom_core::io::alembic::{AlembicTarget, groom::Groom, groom_file};
    use hairloom_core::io::strand_files::{
        ScalpMesh, StrandExportSize, StrandLook, glb_lines, hair_file, usda_file,
    };
    use hairloom_core::strands::reference::{StrandOptions, generate};
    let [pick, log2, project @ ..] = input else {
        return;
    };
    let strands_per_bundle = STRANDS_PER_BUNDLE[*pick as usize % STRANDS_PER_BUNDLE.len()];
    let vertices_log2 = u32::from(*log2 % 12);
    let Ok(project) =
        hairloom_core::io::project::from_bytes(project, std::path::Path::new("fuzz.hairloom"))
    else {
        return;
    };
    let document = &project.document;
    let size = StrandExportSize::of(&document.hair_mesh, strands_per_bundle, vertices_log2);
    if size.check().is_err() || size.points > FUZZ_GENERATED_POINTS {
        return;
    }
    let strands = generate(
        document,
        &StrandOptions {
            strands_per_bundle,
            vertices_log2,
            ..StrandOptions::default()
        },
    );
    assert!(
        strands.iter().map(|s| s.points.len() as u64).sum::<u64>() <= size.points,
        "the export holds more points than its size said"
    );
    let look = StrandLook::new(
        &strands,
        1e-4,
        &document.scene.material,
        &document.root_maps,
    );
    let _ = hair_file(&strands, &look);
    let _ = usda_file(&strands, &ScalpMesh::of(&document.hair_mesh), &look);
    let _ = glb_lines(&strands);
    let groom = Groom::new(document, &strands, 1e-4);
    for target in AlembicTarget::ALL {
        let _ = groom_file(&groom, target);
    }
}

/// The groom formats a [`Target::GroomIn`] input's first byte picks (modulo their count),
/// by the extension the reader is given.
pub const GROOM_EXTENSIONS: [&str; 4] = ["hair", "abc", "usda", "usdc"];

/// A groom fuzz input: the format (an extension of [`GROOM_EXTENSIONS`]) before the file.
pub fn groom_input(extension: &str, file: &[u8]) -> Vec<u8> {
    let pick = GROOM_EXTENSIONS
        .iter()
        .position(|&e| e == extension)
        .expect("a groom extension the target knows");
    let mut input = vec![pick as u8];
    input.extend_from_slice(file);
    input
}

/// Caps small enough that an input claiming the most a cap allows still runs in
/// milliseconds; the checks are the same code as at the default caps.
const FUZZ_GROOM_LIMITS: hairloom_core::io::groom_in::GroomLimits =
    hairloom_core::io::groom_in::GroomLimits {
        max_file_bytes: 1 << 20,
        max_curves: 4096,
        max_points: 1 << 16,
        max_points_per_curve: 1024,
    };

fn groom_in(input: &[u8]) {
    if let Some(Ok(groom)) = read_groom_input(input) {
        check_groom(&groom, FUZZ_GROOM_LIMITS);
    }
}

/// Reads a [`Target::GroomIn`] input with its format's reader under the fuzz caps (`None`
/// for an empty input or a USD file that could not be written).
pub fn read_groom_input(
    input: &[u8],
) -> Option<
    Result<hairloom_core::io::groom_in::InputGroom, hairloom_core::io::groom_in::GroomReadError>,
> {
    use hairloom_core::io::groom_in::{alembic, hair, usd};
    use std::ops::ControlFlow;
    let (&pick, file) = input.split_first()?;
    let extension = GROOM_EXTENSIONS[pick as usize % GROOM_EXTENSIONS.len()];
    let name = std::path::PathBuf::from(format!("fuzz.{extension}"));
    let mut progress = |_| ControlFlow::Continue(());
    let read = match extension {
        "hair" => hair::parse(&name, file, FUZZ_GROOM_LIMITS, &mut progress),
        "abc" => alembic::parse(&name, file.to_vec(), FUZZ_GROOM_LIMITS, &mut progress),
        _ => {
            // The USD library opens files itself: each input goes into a folder of its own
            // (no file an earlier input left can be referenced; tests run in threads),
            // removed after the read.
            let folder = groom_folder();
            std::fs::create_dir_all(&folder).ok()?;
            let path = folder.join(&name);
            let read = std::fs::write(&path, file)
                .ok()
                .map(|()| usd::read(&path, FUZZ_GROOM_LIMITS, &mut progress));
            let _ = std::fs::remove_dir_all(&folder);
            read?
        }
    };
    Some(read)
}

/// A new folder for one USD input: this process's and this call's own.
fn groom_folder() -> std::path::PathBuf {
    static CALLS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    std::env::temp_dir().join(format!("hairloom-fuzz-groom-{}-{call}", std::process::id()))
}

/// What every groom reader promises of a groom it returns, asserted (a failure is a
/// finding): curves of 2 or more points within the caps, finite points, and per-point
/// widths and per-curve uvs and groups that match the counts.
pub fn check_groom(
    groom: &hairloom_core::io::groom_in::InputGroom,
    limits: hairloom_core::io::groom_in::GroomLimits,
) {
    let starts = &groom.starts;
    assert_eq!(starts.first(), Some(&0), "curves start at point 0");
    assert_eq!(
        starts.last().map(|&s| s as usize),
        Some(groom.points.len()),
        "the last curve ends at the last point"
    );
    assert!(
        starts
            .windows(2)
            .all(|w| w[1] >= w[0] + 2 && u64::from(w[1] - w[0]) <= limits.max_points_per_curve),
        "every curve has 2 to max_points_per_curve points"
    );
    let curves = groom.curve_count();
    assert!(
        curves >= 1 && curves as u64 <= limits.max_curves,
        "{curves} curves"
    );
    assert!(
        groom.points.len() as u64 <= limits.max_points,
        "points over the cap"
    );
    assert!(
        groom.points.iter().flatten().all(|c| c.is_finite()),
        "a point is not finite"
    );
    if let Some(widths) = &groom.widths_m {
        assert_eq!(widths.len(), groom.points.len(), "a width per point");
        assert!(
            widths.iter().all(|w| w.is_finite() && *w >= 0.0),
            "widths ≥ 0"
        );
    }
    if let Some(uvs) = &groom.root_uvs {
        assert_eq!(uvs.len(), curves, "a root uv per curve");
    }
    if let Some(groups) = &groom.groups {
        assert_eq!(groups.len(), curves, "a group per curve");
    }
}

/// The manifest of a runtime bundle's files, for crafting cases.
pub fn manifest_of(files: &[(String, Vec<u8>)]) -> Manifest {
    let (_, bytes) = files
        .iter()
        .find(|(n, _)| n == MANIFEST_FILE)
        .expect("a bundle has a manifest");
    serde_json::from_slice(bytes).expect("our manifest parses")
}
