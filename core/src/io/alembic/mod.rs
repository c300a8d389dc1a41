//! Alembic grooms (`.abc`, Ogawa): what Unreal's Groom importer and Unity's hair packages
//! read. No Rust crate writes Alembic, so the three layers are here: the [`ogawa`]
//! container, the [`archive`] object/property layer, and this file's groom: two `ICurves`
//! objects, `hair` (the strands) and `guides` (the hair mesh's columns, `groom_guide = 1`),
//! with the attributes of Epic's "Alembic for Grooms" specification 1.5.
//!
//! Axes and units: metres, Z up. A point `(x, y, z)` of the model (y up, right-handed) is
//! written `(x, z, y)`: the mirror that takes a right-handed y-up space to Unreal's
//! left-handed z-up one, the same mapping Unreal's import conversion applies to y-up files
//! when users set rotation X 90° and scale Y −1. So the groom imports upright with the
//! conversion's rotation left at zero; its scale must be 100, because Unreal works in
//! centimetres. (Checked by reading the files back: the hair's height is along z. No
//! Unreal or Unity ran here.)

pub mod archive;
pub mod groom;
pub mod ogawa;

use archive::{Archive, Metadata, Object, Pod, Property, Samples};
use groom::{Groom, GroomCurves};

/// Groom specification version written (`groom_version_major` / `_minor`).
pub const GROOM_VERSION: (i16, i16) = (1, 5);

/// Model space (y up) to the file's (z up, mirrored): see the module comment.
pub fn to_file_axes([x, y, z]: [f32; 3]) -> [f32; 3] {
    [x, z, y]
}

/// The `.abc` of one groom (a static file). Refused when the groom's arrays disagree (see
/// [`groom_animation`]).
pub fn groom_file(groom: &Groom) -> Result<Vec<u8>, String> {
    groom_animation(std::slice::from_ref(groom), 1.0)
}

/// Whether a groom's arrays agree: as many points as its curves' vertex counts add up to,
/// one value per curve of every per-curve attribute, and per strand its guides.
fn check_groom(groom: &Groom) -> Result<(), String> {
    for (name, curves) in [("strands", &groom.strands), ("guides", &groom.guides)] {
        let points: i64 = curves.vertex_counts.iter().map(|&c| i64::from(c)).sum();
        if curves.vertex_counts.iter().any(|&c| c < 2) || points != curves.points.len() as i64 {
            return Err(format!(
                "{name}: {} points for vertex counts adding up to {points} (each at least 2)",
                curves.points.len()
            ));
        }
        let count = curves.vertex_counts.len();
        for (attribute, len) in [
            ("root_uv", curves.root_uv.len()),
            ("group_id", curves.group_id.len()),
            ("id", curves.id.len()),
        ] {
            if len != count {
                return Err(format!(
                    "{name}: {len} {attribute} values for {count} curves"
                ));
            }
        }
    }
    let strands = groom.strands.vertex_counts.len();
    if groom.closest_guides.len() != strands || groom.guide_weights.len() != strands {
        return Err(format!(
            "{} closest guides and {} guide weights for {strands} strands",
            groom.closest_guides.len(),
            groom.guide_weights.len()
        ));
    }
    Ok(())
}

/// An animated `.abc`: the points and bounds of every frame's strands and guides as time
/// samples at `frames_per_second`; everything else from the first frame. Every frame must
/// have the curves of the first (counts); an empty list is refused.
pub fn groom_animation(frames: &[Groom], frames_per_second: f64) -> Result<Vec<u8>, String> {
    let first = crate::io::strand_files::first_frame(frames, frames_per_second)?;
    for (i, frame) in frames.iter().enumerate() {
        check_groom(frame).map_err(|e| format!("frame {i}: {e}"))?;
    }
    for (i, frame) in frames.iter().enumerate() {
        if frame.strands.vertex_counts != first.strands.vertex_counts
            || frame.guides.vertex_counts != first.guides.vertex_counts
        {
            return Err(format!("frame {i} has other curves than frame 0"));
        }
    }
    let hair = curves_object("hair", frames.iter().map(|g| &g.strands), first, false);
    let guides = curves_object("guides", frames.iter().map(|g| &g.guides), first, true);
    // A frame rate only means something for an animation.
    let fps = if frames.len() > 1 {
        format!("{frames_per_second:.6}")
    } else {
        String::new()
    };
    let archive = Archive {
        objects: vec![hair, guides],
        metadata: Metadata::new(&[
            (
                "_ai_Application",
                &format!("Hairloom {}", env!("CARGO_PKG_VERSION")),
            ),
            (
                "_ai_Description",
                "Hair groom: strands and guides, metres, z up",
            ),
            ("_ai_DCC_FPS", &fps),
        ]),
        frames_per_second,
    };
    Ok(archive.write())
}

/// An `ICurves` object: linear curves with their widths, `groom_*` attributes per curve
/// and the groom-level user properties.
fn curves_object<'a>(
    name: &str,
    frames: impl Iterator<Item = &'a GroomCurves>,
    groom: &Groom,
    guides: bool,
) -> Object {
    let frames: Vec<&GroomCurves> = frames.collect();
    let curves = frames[0];
    let points: Vec<Vec<f32>> = frames
        .iter()
        .map(|c| c.points.iter().flat_map(|&p| to_file_axes(p)).collect())
        .collect();
    let bounds: Vec<Vec<f64>> = points.iter().map(|p| bounds_of(p)).collect();
    let point_refs: Vec<&[f32]> = points.iter().map(Vec::as_slice).collect();
    let bound_refs: Vec<&[f64]> = bounds.iter().map(Vec::as_slice).collect();
    let curve_count = curves.vertex_counts.len();
    let width_m = groom.width_m;

    let mut arb = vec![
        geom_param(
            "groom_guide",
            "uni",
            "",
            Samples::new(Pod::I32, 1, &[&vec![i32::from(guides); curve_count]]),
        ),
        geom_param(
            "groom_id",
            "uni",
            "",
            Samples::new(Pod::I32, 1, &[&curves.id]),
        ),
        geom_param(
            "groom_group_id",
            "uni",
            "",
            Samples::new(Pod::I32, 1, &[&curves.group_id]),
        ),
        geom_param(
            "groom_root_uv",
            "uni",
            "vector",
            Samples::new(
                Pod::F32,
                2,
                &[bytemuck::cast_slice::<[f32; 2], f32>(&curves.root_uv)],
            ),
        ),
        geom_param(
            "groom_width",
            "uni",
            "",
            Samples::new(Pod::F32, 1, &[&vec![width_m; curve_count]]),
        ),
    ];
    if !guides {
        arb.push(geom_param(
            "groom_closest_guides",
            "uni",
            "vector",
            Samples::new(
                Pod::I32,
                3,
                &[bytemuck::cast_slice::<[i32; 3], i32>(&groom.closest_guides)],
            ),
        ));
        arb.push(geom_param(
            "groom_guide_weights",
            "uni",
            "vector",
            Samples::new(
                Pod::F32,
                3,
                &[bytemuck::cast_slice::<[f32; 3], f32>(&groom.guide_weights)],
            ),
        ));
    }
    let tool = format!("Hairloom {}\0", env!("CARGO_PKG_VERSION"));
    let user = vec![
        Property::scalar(
            "groom_version_major",
            Metadata::default(),
            Samples::new(Pod::I16, 1, &[&[GROOM_VERSION.0]]),
        ),
        Property::scalar(
            "groom_version_minor",
            Metadata::default(),
            Samples::new(Pod::I16, 1, &[&[GROOM_VERSION.1]]),
        ),
        Property::scalar(
            "groom_tool",
            Metadata::default(),
            Samples::new(Pod::String, 1, &[tool.as_bytes()]),
        ),
    ];
    let geom = vec![
        Property::scalar(
            ".selfBnds",
            Metadata::new(&[("interpretation", "box")]),
            Samples::new(Pod::F64, 6, &bound_refs),
        ),
        Property::array(
            "P",
            Metadata::new(&[("geoScope", "vtx"), ("interpretation", "point")]),
            Samples::new(Pod::F32, 3, &point_refs),
        ),
        Property::array(
            "nVertices",
            Metadata::default(),
            Samples::new(Pod::I32, 1, &[&curves.vertex_counts]),
        ),
        // Linear, non-periodic, no basis.
        Property::scalar(
            "curveBasisAndType",
            Metadata::default(),
            Samples::new(Pod::U8, 4, &[&[1u8, 0, 0, 0]]),
        ),
        geom_param("width", "con", "", Samples::new(Pod::F32, 1, &[&[width_m]])),
        Property::compound(".arbGeomParams", Metadata::default(), arb),
        Property::compound(".userProperties", Metadata::default(), user),
    ];
    let schema = "AbcGeom_Curve_v2";
    Object {
        name: name.into(),
        metadata: Metadata::new(&[
            ("schema", schema),
            ("schemaBaseType", "AbcGeom_GeomBase_v1"),
            ("schemaObjTitle", &format!("{schema}:.geom")),
        ]),
        properties: vec![Property::compound(
            ".geom",
            Metadata::new(&[
                ("schema", schema),
                ("schemaBaseType", "AbcGeom_GeomBase_v1"),
            ]),
            geom,
        )],
        children: Vec::new(),
    }
}

/// A non-indexed geometry parameter: an array property with the metadata that says its
/// scope (`con`stant, `uni`form = per curve, `vtx` = per point) and element type.
fn geom_param(name: &str, scope: &str, interpretation: &str, samples: Samples) -> Property {
    let extent = samples.extent.to_string();
    let metadata = Metadata::new(&[
        ("arrayExtent", "1"),
        ("geoScope", scope),
        ("interpretation", interpretation),
        ("isGeomParam", "true"),
        ("podExtent", &extent),
        ("podName", samples.pod.name()),
    ]);
    Property::array(name, metadata, samples)
}

/// `[min x, min y, min z, max x, max y, max z]` of packed xyz points; zero when empty.
fn bounds_of(points: &[f32]) -> Vec<f64> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points.chunks_exact(3) {
        for k in 0..3 {
            lo[k] = lo[k].min(f64::from(p[k]));
            hi[k] = hi[k].max(f64::from(p[k]));
        }
    }
    if points.is_empty() {
        return vec![0.0; 6];
    }
    lo.into_iter().chain(hi).collect()
}
