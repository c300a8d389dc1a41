//! Alembic grooms (`.abc`, Ogawa): what Unreal's Groom importer and Unity's hair packages
//! read. No Rust crate writes Alembic, so the three layers are here: the [`ogawa`]
//! container, the [`archive`] object/property layer, and this file's groom: two `ICurves`
//! objects, `hair` (the strands) and `guides` (the hair mesh's columns, `groom_guide = 1`),
//! with the attributes of Epic's "Alembic for Grooms" specification 1.5.
//!
//! Axes and units depend on the application the file is for ([`AlembicTarget`]): Alembic's
//! own convention (y up, right-handed) in metres for Blender and Houdini, in centimetres for
//! Maya and Unity, and Unreal's z-up left-handed centimetres for Unreal, so that each
//! reads the groom upright, facing its front, at its size, with the default import settings
//! (checked in Blender through `bpy` in `make test`; the others worked out from their
//! importers' sources and documentation, see the README).
//!
//! Widths taper from root to tip as the renderers draw them and every point carries the
//! hair's colour (`groom_color`), so a groom lands looking like the one in the editor.

pub mod archive;
pub mod groom;
pub mod ogawa;

use archive::{Archive, Metadata, Object, Pod, Property, Samples};
use groom::{Groom, GroomCurves};

/// Groom specification version written (`groom_version_major` / `_minor`).
pub const GROOM_VERSION: (i16, i16) = (1, 5);

/// The application an `.abc` is written for: its axes and units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AlembicTarget {
    /// Blender's Alembic importer converts Alembic's y up to its z up itself; metres.
    #[default]
    Blender,
    /// Houdini: y up, metres (its scene unit).
    Houdini,
    /// Maya: y up, centimetres (its internal unit, which its importer reads).
    Maya,
    /// Unity's Alembic package: y up, centimetres: its default Scale Factor is 0.01 (it
    /// expects Maya's centimetres) and its default Swap Handedness turns our right-handed
    /// points into its left-handed space.
    Unity,
    /// Unreal's groom importer applies only its conversion settings (rotation 0, scale 1 by
    /// default) and works in centimetres in a left-handed z-up space: a model point
    /// `(x, y, z)` is written `(x, z, y)` · 100, so the head stands up and faces +Y as
    /// Unreal's characters do.
    Unreal,
}

impl AlembicTarget {
    pub const ALL: [Self; 5] = [
        Self::Blender,
        Self::Houdini,
        Self::Maya,
        Self::Unity,
        Self::Unreal,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Self::Blender => "blender",
            Self::Houdini => "houdini",
            Self::Maya => "maya",
            Self::Unity => "unity",
            Self::Unreal => "unreal",
        }
    }

    /// The target called `name` (as `--for` takes it), or an error naming the choices.
    pub fn parse(name: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|t| t.name().eq_ignore_ascii_case(name))
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|t| t.name()).collect();
                format!(
                    "no Alembic target {name:?}: choose one of {}",
                    names.join(", ")
                )
            })
    }

    /// File units per metre.
    pub fn units_per_m(self) -> f32 {
        match self {
            Self::Maya | Self::Unity | Self::Unreal => 100.0,
            Self::Blender | Self::Houdini => 1.0,
        }
    }

    /// Whether the file's axes are z up (Unreal) rather than Alembic's y up.
    pub fn z_up(self) -> bool {
        self == Self::Unreal
    }

    /// A model point (metres, y up, right-handed) in the file's axes and units.
    pub fn to_file(self, [x, y, z]: [f32; 3]) -> [f32; 3] {
        let scale = self.units_per_m();
        if self.z_up() {
            [x * scale, z * scale, y * scale]
        } else {
            [x * scale, y * scale, z * scale]
        }
    }

    /// What the archive's description says of its axes and units.
    fn describe(self) -> String {
        let units = if self.units_per_m() == 1.0 {
            "metres"
        } else {
            "centimetres"
        };
        let axes = if self.z_up() {
            "z up, left-handed"
        } else {
            "y up"
        };
        format!(
            "Hair groom for {}: strands and guides, {units}, {axes}",
            self.name()
        )
    }
}

/// The `.abc` of one groom (a static file) for `target`. Refused when the groom's arrays
/// disagree (see [`groom_animation`]).
pub fn groom_file(groom: &Groom, target: AlembicTarget) -> Result<Vec<u8>, String> {
    groom_animation(std::slice::from_ref(groom), 1.0, target)
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
        let point_count = curves.points.len();
        if curves.widths_m.len() != point_count
            || !(curves.colors.is_empty() || curves.colors.len() == point_count)
        {
            return Err(format!(
                "{name}: {} widths and {} colours for {point_count} points",
                curves.widths_m.len(),
                curves.colors.len()
            ));
        }
        if let Some(bad) = curves
            .widths_m
            .iter()
            .find(|w| !(w.is_finite() && **w >= 0.0))
        {
            return Err(format!("{name}: width {bad} is not a width"));
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
pub fn groom_animation(
    frames: &[Groom],
    frames_per_second: f64,
    target: AlembicTarget,
) -> Result<Vec<u8>, String> {
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
    let hair = curves_object(
        "hair",
        frames.iter().map(|g| &g.strands),
        first,
        false,
        target,
    );
    let guides = curves_object(
        "guides",
        frames.iter().map(|g| &g.guides),
        first,
        true,
        target,
    );
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
            ("_ai_Description", &target.describe()),
            ("_ai_DCC_FPS", &fps),
        ]),
        frames_per_second,
    };
    Ok(archive.write())
}

/// An `ICurves` object: linear curves with their widths (per point, tapering), `groom_*`
/// attributes per curve (and colour per point) and the groom-level user properties, in
/// `target`'s axes and units.
fn curves_object<'a>(
    name: &str,
    frames: impl Iterator<Item = &'a GroomCurves>,
    groom: &Groom,
    guides: bool,
    target: AlembicTarget,
) -> Object {
    let frames: Vec<&GroomCurves> = frames.collect();
    let curves = frames[0];
    let points: Vec<Vec<f32>> = frames
        .iter()
        .map(|c| c.points.iter().flat_map(|&p| target.to_file(p)).collect())
        .collect();
    let bounds: Vec<Vec<f64>> = points.iter().map(|p| bounds_of(p)).collect();
    let point_refs: Vec<&[f32]> = points.iter().map(Vec::as_slice).collect();
    let bound_refs: Vec<&[f64]> = bounds.iter().map(Vec::as_slice).collect();
    let curve_count = curves.vertex_counts.len();
    let scale = target.units_per_m();
    let widths: Vec<f32> = curves.widths_m.iter().map(|w| w * scale).collect();

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
            "vtx",
            "",
            Samples::new(Pod::F32, 1, &[&widths]),
        ),
    ];
    if !curves.colors.is_empty() {
        arb.push(geom_param(
            "groom_color",
            "vtx",
            "rgb",
            Samples::new(
                Pod::F32,
                3,
                &[bytemuck::cast_slice::<[f32; 3], f32>(&curves.colors)],
            ),
        ));
    }
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
        geom_param("width", "vtx", "", Samples::new(Pod::F32, 1, &[&widths])),
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

#[cfg(test)]
mod tests {
    use super::AlembicTarget;

    /// Literal expectations, independent of `to_file`'s own arithmetic: a model point
    /// (x right, y up, z toward the face), metres.
    #[test]
    fn each_target_gets_its_axes_and_units() {
        let p = [1.0, 2.0, 3.0];
        assert_eq!(AlembicTarget::Blender.to_file(p), [1.0, 2.0, 3.0]);
        assert_eq!(AlembicTarget::Houdini.to_file(p), [1.0, 2.0, 3.0]);
        assert_eq!(AlembicTarget::Maya.to_file(p), [100.0, 200.0, 300.0]);
        assert_eq!(AlembicTarget::Unity.to_file(p), [100.0, 200.0, 300.0]);
        // Unreal: z up, the face toward +y, centimetres.
        assert_eq!(AlembicTarget::Unreal.to_file(p), [100.0, 300.0, 200.0]);
        for target in AlembicTarget::ALL {
            assert_eq!(AlembicTarget::parse(target.name()), Ok(target));
        }
        let error = AlembicTarget::parse("3dsmax").expect_err("unknown");
        assert!(
            error.contains("blender, houdini, maya, unity, unreal"),
            "{error}"
        );
    }
}
