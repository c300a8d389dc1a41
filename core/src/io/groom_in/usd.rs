//! USD grooms: every `BasisCurves` prim of the composed stage (`.usda`, `.usdc`, `.usdz`),
//! read through `openusd`, a pure-Rust USD library with composition (no C++ USD to build,
//! and it reads all three encodings). Points go through the prim's world transform; widths
//! (constant, per curve or per point) and the root uv primvar `surface_uv_coordinate`
//! (Blender's and ours) are kept; each prim is a group.
//!
//! A stage may name other layers (references, payloads, sublayers). They are read only from
//! inside the groom's own folder, as every input file's references are
//! (`docs/resource-policy.md`): the resolver refuses any other path.

use std::io;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use openusd::ar::{self, Asset, ResolvedPath, Resolver};
use openusd::gf;
use openusd::schemas::geom::{BasisCurves, Xform, Xformable};
use openusd::sdf;
use openusd::usd::{Prim, Stage, TimeCode};

use super::{GroomBuilder, GroomLimits, GroomReadError, InputGroom, without_panics};
use crate::io::input_files::{InputFolder, check_regular_file};

/// Most prims walked, so a stage of millions of empty prims cannot run unbounded.
const MAX_PRIMS: usize = 1 << 20;

/// The default resolver, limited to regular files inside one folder and under a size cap.
struct FolderResolver {
    inner: ar::DefaultResolver,
    folder: PathBuf,
    cap_bytes: u64,
}

impl FolderResolver {
    fn inside(&self, resolved: &Path) -> bool {
        // A package-relative path (`pkg.usdz[inner]`) is checked by its package.
        let text = resolved.to_string_lossy();
        let outer = text.split('[').next().unwrap_or("");
        std::fs::canonicalize(outer)
            .map(|p| p.starts_with(&self.folder))
            .unwrap_or(false)
    }
}

impl Resolver for FolderResolver {
    fn create_identifier(&self, asset_path: &str, anchor: Option<&ResolvedPath>) -> String {
        self.inner.create_identifier(asset_path, anchor)
    }

    fn resolve(&self, asset_path: &str) -> Option<ResolvedPath> {
        let resolved = self.inner.resolve(asset_path)?;
        self.inside(&resolved).then_some(resolved)
    }

    fn resolve_for_new_asset(&self, _asset_path: &str) -> Option<ResolvedPath> {
        None
    }

    fn open_asset(&self, resolved_path: &ResolvedPath) -> io::Result<Box<dyn Asset>> {
        let refused = || {
            io::Error::new(
                io::ErrorKind::PermissionDenied,
                "only regular files inside the groom's folder are read",
            )
        };
        if !self.inside(resolved_path) {
            return Err(refused());
        }
        let text = resolved_path.to_string_lossy();
        let outer = text.split('[').next().unwrap_or("");
        let metadata = std::fs::metadata(outer)?;
        if !metadata.is_file() {
            return Err(refused());
        }
        if metadata.len() > self.cap_bytes {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("larger than the cap of {} bytes", self.cap_bytes),
            ));
        }
        let mut asset = self.inner.open_asset(resolved_path)?;
        // Every layer of the stage comes through here (the root, references, sublayers,
        // a package's text layers): check USD text before the library composes it.
        let bytes = asset.read_all()?;
        // Anything but a crate file or a package is parsed as text (the parser takes
        // leading blank lines before `#usda`), so anything else is checked as text.
        let checked = if bytes.starts_with(b"PXR-USDC") {
            check_usdc_names(&bytes)
        } else if bytes.starts_with(b"PK") {
            // A package's layers come through here one by one, each checked on its own.
            Ok(())
        } else {
            check_usda_names(&bytes)
        };
        checked.map_err(|message| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{}: {message}", resolved_path.display()),
            )
        })?;
        Ok(Box::new(io::Cursor::new(bytes)))
    }

    fn identity(&self) -> String {
        format!("hairloom-folder:{}", self.folder.display())
    }
}

/// Refuses USD text whose prim names are not identifiers, whose path literals hold `{` or
/// `}`, or that has variant sets: `openusd` 0.6's composition recurses without end on such a
/// name (a stack overflow, which aborts the whole process, unsaved work and all) and loops
/// forever on such a path (found by the `groom_in` fuzz target); variant names become
/// braced paths the same way. Grooms do not use variants. The text is read with the
/// library's own tokenizer, so comments, strings and malformed quoting split exactly as
/// its parser splits them. Crate files (`.usdc`) hold the same names in a token table:
/// [`check_usdc_names`] checks them.
pub(crate) fn check_usda_names(bytes: &[u8]) -> Result<(), String> {
    use logos::Logos as _;
    use openusd::usda::token::Token;
    let text = std::str::from_utf8(bytes).map_err(|e| format!("not UTF-8 text ({e})"))?;
    let specifier = |t: &Option<Token>| matches!(t, Some(Token::Def | Token::Over | Token::Class));
    let type_name = |t: &Option<Token>| {
        matches!(
            t,
            Some(Token::Identifier(_) | Token::NamespacedIdentifier(_))
        )
    };
    // The two tokens before this one (lexer errors included, as `None`).
    let (mut before, mut last): (Option<Token>, Option<Token>) = (None, None);
    for token in Token::lexer(text) {
        let token = token.ok();
        match &token {
            Some(Token::VariantSet | Token::VariantSets | Token::Variants) => {
                return Err("variant sets are not read".into());
            }
            Some(Token::PathRef(path)) if path.contains(['{', '}']) => {
                return Err(format!(
                    "path <{}> holds a brace (variant selections are not read)",
                    shortened(path)
                ));
            }
            Some(Token::String(name))
                if (specifier(&last) || (specifier(&before) && type_name(&last)))
                    && !is_identifier(name) =>
            {
                return Err(format!(
                    "prim name {:?} is not an identifier (letters, digits and _)",
                    shortened(name)
                ));
            }
            _ => {}
        }
        before = last;
        last = token;
    }
    Ok(())
}

/// What [`check_usda_names`] refuses, in a crate file (`.usdc`): found by writing the text
/// cases with the library's own crate writer (the same stack overflow). The crate is opened
/// with the library's reader and every spec's path, every child-name list and every
/// path-valued field (references, payloads, inherits, specializes, relationship targets,
/// connections, relocates) is checked: prim paths of identifiers, properties of namespaced
/// identifiers, no variant selections, no variant sets. Attribute values (`default`,
/// `timeSamples`: the bulk of a groom) are not decoded here.
pub(crate) fn check_usdc_names(bytes: &[u8]) -> Result<(), String> {
    use openusd::sdf::{AbstractData as _, SpecType, Value};
    let data = openusd::usdc::CrateData::open(io::Cursor::new(bytes), true)
        .map_err(|e| format!("not a readable USD crate file ({e})"))?;
    let path_error = |path: &str, at: &str| {
        format!(
            "path <{}> in {at} is not a prim or property path of identifiers (braces, brackets \
             and variant selections are not read)",
            shortened(path)
        )
    };
    for spec in data.spec_paths() {
        let spec_text = spec.as_str();
        if matches!(
            data.spec_type(&spec),
            Some(SpecType::Variant | SpecType::VariantSet)
        ) {
            return Err("variant sets are not read".into());
        }
        if !is_plain_path(spec_text) {
            let name = spec_text.rsplit('/').next().unwrap_or(spec_text);
            return Err(format!(
                "prim name {:?} is not an identifier (letters, digits and _)",
                shortened(name)
            ));
        }
        for field in data.list_fields(&spec).unwrap_or_default() {
            if field.starts_with("variant") {
                return Err("variant sets are not read".into());
            }
            if matches!(field.as_str(), "default" | "timeSamples") {
                continue;
            }
            // A field the library cannot decode is its own error, reported when it reads it.
            let Ok(Some(value)) = data.try_field(&spec, &field) else {
                continue;
            };
            let at = || format!("{field} of <{}>", shortened(spec_text));
            let mut paths: Vec<&openusd::sdf::Path> = Vec::new();
            match value.as_ref() {
                Value::TokenVec(names) if field.ends_with("Children") => {
                    // Prim names are identifiers, property names namespaced ones (`a:b`).
                    let plain = |name: &str| name.split(':').all(is_identifier);
                    if let Some(name) = names.iter().find(|n| !plain(n.as_str())) {
                        let kind = if field == "primChildren" {
                            "prim"
                        } else {
                            "child"
                        };
                        return Err(format!(
                            "{kind} name {:?} in {} is not an identifier (letters, digits and _)",
                            shortened(name.as_str()),
                            at()
                        ));
                    }
                }
                Value::PathVec(list) => paths.extend(list),
                Value::PathListOp(op) => paths.extend(all_items(op)),
                Value::ReferenceListOp(op) => paths.extend(all_items(op).map(|r| &r.prim_path)),
                Value::PayloadListOp(op) => paths.extend(all_items(op).map(|p| &p.prim_path)),
                Value::Payload(payload) => paths.push(&payload.prim_path),
                Value::Relocates(pairs) => paths.extend(pairs.iter().flat_map(|(s, t)| [s, t])),
                _ => {}
            }
            if let Some(path) = paths.iter().find(|p| !is_plain_path(p.as_str())) {
                return Err(path_error(path.as_str(), &at()));
            }
        }
    }
    Ok(())
}

/// Every item of a list op, deleted and reordered ones too (the library composes those).
fn all_items<T: Default + Clone + PartialEq>(
    op: &openusd::sdf::ListOp<T>,
) -> impl Iterator<Item = &T> {
    op.iter().chain(&op.deleted_items).chain(&op.ordered_items)
}

/// A USD identifier: a letter or `_`, then letters, digits and `_`.
fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    chars.next().is_some_and(|c| c.is_alphabetic() || c == '_')
        && chars.all(|c| c.is_alphanumeric() || c == '_')
}

/// A prim path of identifiers (absolute or relative, `.` and `..` allowed), optionally
/// ending in a property whose name is identifiers joined by `:`; an empty path too (a
/// reference's "default prim"). No variant selection, target (`[…]`) or other character.
fn is_plain_path(path: &str) -> bool {
    let body = path.strip_prefix('/').unwrap_or(path);
    if body.is_empty() {
        return true;
    }
    let elements: Vec<&str> = body.split('/').collect();
    elements.iter().enumerate().all(|(i, element)| {
        if matches!(*element, "." | "..") {
            return true;
        }
        match element.split_once('.') {
            None => is_identifier(element),
            Some((prim, property)) => {
                i + 1 == elements.len()
                    && (is_identifier(prim) || (prim.is_empty() && elements.len() == 1))
                    && property.split(':').all(is_identifier)
            }
        }
    })
}

/// At most 64 characters of `text` for an error message (a name left open runs to the end
/// of the file).
fn shortened(text: &str) -> String {
    let mut short: String = text.chars().take(64).collect();
    if short.len() < text.len() {
        short.push('…');
    }
    short
}

pub fn read(
    path: &Path,
    limits: GroomLimits,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<InputGroom, GroomReadError> {
    // The named file itself: a regular file under the cap (this also refuses FIFOs and
    // devices before the USD library opens it).
    check_regular_file(path, limits.max_file_bytes, "a groom")?;
    let folder = InputFolder::of_file(path)?;
    let canonical_folder = std::fs::canonicalize(folder.path()).map_err(|source| {
        crate::io::input_files::InputFileError::Io {
            path: folder.path().display().to_string(),
            source,
        }
    })?;
    let root = std::fs::canonicalize(path).map_err(|source| {
        crate::io::input_files::InputFileError::Io {
            path: path.display().to_string(),
            source,
        }
    })?;
    without_panics(path, "the USD reader", || {
        read_stage(path, &root, canonical_folder, limits, progress)
    })
}

fn read_stage(
    path: &Path,
    root: &Path,
    folder: PathBuf,
    limits: GroomLimits,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<InputGroom, GroomReadError> {
    let mut builder = GroomBuilder::new(path, limits, progress);
    let resolver = FolderResolver {
        inner: ar::DefaultResolver::with_search_paths([folder.clone()]),
        folder,
        cap_bytes: limits.max_file_bytes,
    };
    let stage = Stage::builder()
        .resolver(resolver)
        .open(&root.to_string_lossy())
        .map_err(|e| builder.format_error(format!("not a USD stage: {e:#}")))?;
    let usd_error =
        |builder: &GroomBuilder, e: anyhow::Error| builder.format_error(format!("{e:#}"));
    let mut stack = vec![stage.prim(sdf::Path::abs_root())];
    let mut walked = 0usize;
    let mut curve_prims = 0i32;
    let mut skipped_types = std::collections::BTreeSet::new();
    while let Some(prim) = stack.pop() {
        walked += 1;
        if walked > MAX_PRIMS {
            return Err(GroomReadError::TooMany {
                file: builder.file().to_string(),
                what: "prims",
                count: walked as u64,
                cap: MAX_PRIMS as u64,
            });
        }
        let type_name = prim
            .type_name()
            .map_err(|e| usd_error(&builder, e))?
            .map(|t| t.as_str().to_string())
            .unwrap_or_default();
        match type_name.as_str() {
            "BasisCurves" => {
                read_curves(&stage, &prim, curve_prims, &mut builder)?;
                curve_prims += 1;
            }
            "NurbsCurves" | "HermiteCurves" => {
                skipped_types.insert(type_name);
            }
            _ => {}
        }
        let mut children = prim.children().map_err(|e| usd_error(&builder, e))?;
        children.reverse();
        stack.extend(children);
    }
    for skipped in skipped_types {
        builder.note(format!("{skipped} prims are not read (only BasisCurves)"));
    }
    builder.note(format!("USD: {curve_prims} BasisCurves prims"));
    let frame = StageFrame::of(&stage).map_err(|message| builder.format_error(message))?;
    if let Some(note) = frame.note() {
        builder.note(note);
    }
    let file = builder.file().to_string();
    let mut groom = builder.finish()?;
    frame
        .apply(&mut groom)
        .map_err(|message| GroomReadError::Format { file, message })?;
    Ok(groom)
}

/// The stage's axes and units (`upAxis`, `metersPerUnit`), which Hairloom's metres, +Y up
/// differ from in files made in Z-up tools (Blender's default USD export) or in
/// centimetres.
struct StageFrame {
    z_up: bool,
    meters_per_unit: f64,
}

impl StageFrame {
    /// USD's fallbacks where the root layer says nothing: Y up, and 0.01 metres per unit
    /// (`UsdGeomGetStageMetersPerUnit`'s centimetres).
    fn of(stage: &Stage) -> Result<Self, String> {
        let layer = stage.root_layer();
        let root = layer.pseudo_root();
        let up = root
            .as_ref()
            .and_then(|r| r.get::<sdf::Value>("upAxis"))
            .and_then(|v| v.try_as_token_ref().map(|t| t.as_str().to_string()));
        let z_up = match up.as_deref() {
            None | Some("Y") => false,
            Some("Z") => true,
            Some(other) => return Err(format!("upAxis \"{other}\" is neither Y nor Z")),
        };
        let meters_per_unit = match root
            .as_ref()
            .and_then(|r| r.get::<sdf::Value>("metersPerUnit"))
        {
            None => 0.01,
            Some(value) => {
                let m = value
                    .try_as_double_ref()
                    .copied()
                    .or_else(|| value.try_as_float_ref().map(|f| f64::from(*f)))
                    .or_else(|| value.try_as_int_ref().map(|i| f64::from(*i)))
                    .ok_or_else(|| "metersPerUnit is not a number".to_string())?;
                // A micrometre to a thousand kilometres per unit; beyond, f32 points would
                // overflow or vanish.
                if !(1e-6..=1e6).contains(&m) {
                    return Err(format!(
                        "metersPerUnit {m} is outside 1e-6 … 1e6 (not a length a groom is in)"
                    ));
                }
                m
            }
        };
        Ok(Self {
            z_up,
            meters_per_unit,
        })
    }

    fn note(&self) -> Option<String> {
        (self.z_up || self.meters_per_unit != 1.0).then(|| {
            format!(
                "stage {} up, {} m per unit: converted to metres, Y up",
                if self.z_up { "Z" } else { "Y" },
                self.meters_per_unit
            )
        })
    }

    /// Points to metres, Y up (Z up turns by −90° about x: its front, −Y, becomes +Z as in
    /// glTF), widths to metres.
    fn apply(&self, groom: &mut InputGroom) -> Result<(), String> {
        let m = self.meters_per_unit as f32;
        for p in &mut groom.points {
            let [x, y, z] = *p;
            *p = if self.z_up {
                [x * m, z * m, -y * m]
            } else {
                [x * m, y * m, z * m]
            };
        }
        if let Some(widths) = &mut groom.widths_m {
            for w in widths {
                *w *= m;
            }
        }
        match groom
            .points
            .iter()
            .position(|p| p.iter().any(|c| !c.is_finite()))
        {
            Some(i) => Err(format!(
                "point {i} is not finite in metres ({} m per unit)",
                self.meters_per_unit
            )),
            None => Ok(()),
        }
    }
}

/// The value of `attribute` at its default time, or at its first time sample.
fn value_of<T>(prim: &Prim, attribute: &str) -> anyhow::Result<Option<T>>
where
    T: TryFrom<sdf::Value>,
    T::Error: std::error::Error + Send + Sync + 'static,
{
    let attribute = prim.attribute(attribute);
    if let Some(value) = attribute.get::<T>()? {
        return Ok(Some(value));
    }
    match attribute.time_sample_times()?.first() {
        Some(&t) => attribute.get_at::<T>(TimeCode::new(t)),
        None => Ok(None),
    }
}

/// The world transform of `prim`: its own and every ancestor Xform's local transforms.
fn world_transform(stage: &Stage, prim: &Prim) -> anyhow::Result<gf::Matrix4d> {
    let mut matrix = gf::Matrix4d::IDENTITY;
    let mut path = Some(prim.path().clone());
    while let Some(p) = path {
        let local = if let Some(curves) = BasisCurves::get(stage, p.clone())? {
            Some((
                curves.local_to_parent_transform(TimeCode::EARLIEST)?,
                curves.resets_xform_stack()?,
            ))
        } else if let Some(xform) = Xform::get(stage, p.clone())? {
            Some((
                xform.local_to_parent_transform(TimeCode::EARLIEST)?,
                xform.resets_xform_stack()?,
            ))
        } else {
            None
        };
        if let Some((local, resets)) = local {
            // Row vectors: a point is p · M_local · M_parent …
            matrix = matrix * local;
            if resets {
                break;
            }
        }
        path = p.parent();
    }
    Ok(matrix)
}

fn read_curves(
    stage: &Stage,
    prim: &Prim,
    group: i32,
    builder: &mut GroomBuilder,
) -> Result<(), GroomReadError> {
    let name = prim.path().as_str().to_string();
    let error = |builder: &GroomBuilder, message: String| {
        builder.format_error(format!("{name}: {message}"))
    };
    let points: Vec<[f32; 3]> = value_of(prim, "points")
        .map_err(|e| error(builder, format!("points: {e:#}")))?
        .unwrap_or_default();
    let counts: Vec<i64> = match prim
        .attribute("curveVertexCounts")
        .get::<sdf::Value>()
        .map_err(|e| error(builder, format!("curveVertexCounts: {e:#}")))?
    {
        Some(sdf::Value::IntVec(v)) => v.into_iter().map(i64::from).collect(),
        Some(sdf::Value::Int64Vec(v)) => v,
        Some(other) => {
            return Err(error(
                builder,
                format!("curveVertexCounts is not an int array ({other:?})"),
            ));
        }
        None => return Err(error(builder, "has no curveVertexCounts".into())),
    };
    // Checked: int64 counts from the file could wrap a plain sum back to the point count.
    let total = counts.iter().try_fold(
        0i64,
        |sum, &c| if c < 0 { None } else { sum.checked_add(c) },
    );
    if total != Some(points.len() as i64) {
        let total = total.map_or_else(
            || "a negative or overflowing total".to_string(),
            |t| t.to_string(),
        );
        return Err(error(
            builder,
            format!(
                "curveVertexCounts add up to {total} (or hold a negative count) but there are {} points",
                points.len()
            ),
        ));
    }
    builder.expect(counts.len() as u64, points.len() as u64)?;
    let transform =
        world_transform(stage, prim).map_err(|e| error(builder, format!("transform: {e:#}")))?;
    let identity = transform == gf::Matrix4d::IDENTITY;
    let widths: Vec<f32> = value_of(prim, "widths")
        .map_err(|e| error(builder, format!("widths: {e:#}")))?
        .unwrap_or_default();
    // Widths scale with the transform's mean scale (the cube root of its determinant).
    let scale = if identity {
        1.0
    } else {
        let m = &transform.0;
        let det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8])
            + m[2] * (m[4] * m[9] - m[5] * m[8]);
        det.abs().cbrt() as f32
    };
    let uvs: Vec<[f32; 2]> = value_of(prim, "primvars:surface_uv_coordinate")
        .ok()
        .flatten()
        .unwrap_or_default();
    let mut first = 0usize;
    let mut curve_widths = Vec::new();
    for (i, &count) in counts.iter().enumerate() {
        let count = count as usize;
        let span = first..first + count;
        curve_widths.clear();
        let have_widths = if widths.len() == points.len() {
            curve_widths.extend(widths[span.clone()].iter().map(|w| w * scale));
            true
        } else if widths.len() == counts.len() {
            curve_widths.resize(count, widths[i] * scale);
            true
        } else if widths.len() == 1 {
            curve_widths.resize(count, widths[0] * scale);
            true
        } else {
            false
        };
        let curve = points[span].iter().map(|&p| {
            if identity {
                p
            } else {
                let q = transform.transform_point(gf::Vec3f {
                    x: p[0],
                    y: p[1],
                    z: p[2],
                });
                [q.x, q.y, q.z]
            }
        });
        builder.push(
            curve,
            have_widths.then_some(curve_widths.as_slice()),
            (uvs.len() == counts.len()).then(|| uvs[i]),
            Some(group),
        )?;
        first += count;
    }
    Ok(())
}
