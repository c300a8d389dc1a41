//! Alembic grooms through `ogawa-rs`: every `ICurves` object (plain curves as Blender,
//! Houdini and Maya write them, and Unreal's groom schema). Unreal's guide curves
//! (`groom_guide` = 1) are skipped: they drive simulation, they are not hair. Widths come
//! from `width` (or `groom_width`), root uv from `groom_root_uv` (or Blender's `surface_uv_coordinate`),
//! groups from `groom_group_id`; the first time sample is read.
//!
//! `ogawa-rs` trusts the sizes a file states (it allocates what a blob header claims) and
//! panics on types it does not read (wide strings), so before it sees a file,
//! [`check_ogawa_tree`] walks the whole Ogawa tree and refuses any blob or group that does
//! not fit inside the file; a panic left in the crate becomes a named error
//! ([`without_panics`]).
//!
//! Transforms: every `IXform` above a curves object applies, as the Alembic library composes
//! them (`.ops` and `.vals` read here, since `ogawa-rs` 0.4 reads no `IXform` samples; see
//! [`xform_matrix`]): scale, translate, axis-angle and axis rotations and matrices in stack
//! order, each transform on its parent's unless `.inherits` says not. Widths scale with the
//! transform's mean scale. The first sample of an animated transform is read.

use std::io::{Cursor, Read, Seek, SeekFrom};
use std::ops::ControlFlow;
use std::path::Path;

use glam::{DMat4, DVec3};
use ogawa_rs::{Archive, ArchiveReader, ObjectReader, PodArray, PropertyReader, Schema};

use super::{GroomBuilder, GroomLimits, GroomReadError, InputGroom, without_panics};

/// Deepest object hierarchy and most Ogawa nodes walked.
const MAX_DEPTH: usize = 64;
const MAX_NODES: usize = 1 << 22;
const DATA_BIT: u64 = 1 << 63;

/// A file held in memory, as `ogawa-rs` reads one.
struct BytesReader(Cursor<Vec<u8>>);

impl Read for BytesReader {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.0.read(buf)
    }
}

impl Seek for BytesReader {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.0.seek(pos)
    }
}

impl ArchiveReader for BytesReader {
    fn size(&self) -> u64 {
        self.0.get_ref().len() as u64
    }
}

/// Parses Alembic bytes (`path` only names the file in errors).
pub fn parse(
    path: &Path,
    bytes: Vec<u8>,
    limits: GroomLimits,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<InputGroom, GroomReadError> {
    check_ogawa_tree(&bytes).map_err(|message| GroomReadError::Format {
        file: path.display().to_string(),
        message,
    })?;
    without_panics(path, "the Alembic reader", move || {
        let mut builder = GroomBuilder::new(path, limits, progress);
        let mut reader = BytesReader(Cursor::new(bytes));
        let archive = Archive::new(&mut reader)
            .map_err(|e| builder.format_error(format!("not an Alembic archive: {e:?}")))?;
        let root = archive
            .load_root_object(&mut reader)
            .map_err(|e| builder.format_error(format!("no root object: {e:?}")))?;
        let mut walk = Walk {
            reader: &mut reader,
            archive: &archive,
            builder: &mut builder,
            guides_skipped: 0,
            transforms_applied: 0,
        };
        walk.object(&root, 0, DMat4::IDENTITY)?;
        let (guides, transforms) = (walk.guides_skipped, walk.transforms_applied);
        if guides > 0 {
            builder.note(format!("{guides} guide curves skipped"));
        }
        if transforms > 0 {
            builder.note(format!(
                "{transforms} curves objects placed by the transforms above them"
            ));
        }
        builder.note("Alembic (Ogawa)");
        builder.finish()
    })
}

/// Walks every group and data blob reachable from the root, refusing sizes and offsets that
/// do not fit in the file, so no later read can allocate more than the file holds.
pub fn check_ogawa_tree(bytes: &[u8]) -> Result<(), String> {
    if bytes.len() < 16 || &bytes[..5] != b"Ogawa" {
        return Err("not an Alembic (Ogawa) file".into());
    }
    let len = bytes.len() as u64;
    let u64_at = |at: u64| word_at(bytes, at);
    let root = u64_at(8).ok_or("truncated header")?;
    let mut stack = vec![root];
    let mut seen = std::collections::HashSet::new();
    // In a well-formed file each child slot is its own 8-byte word: groups that share their
    // slots (a hostile file) could otherwise push far more children than the file holds.
    let mut children_pushed = 0u64;
    while let Some(offset) = stack.pop() {
        if seen.len() > MAX_NODES {
            return Err(format!("more than {MAX_NODES} Ogawa nodes"));
        }
        if !seen.insert(offset) {
            continue;
        }
        if offset & DATA_BIT != 0 {
            let at = offset & !DATA_BIT;
            if at == 0 {
                continue; // empty data
            }
            let size = u64_at(at).ok_or_else(|| format!("data at {at} lies outside the file"))?;
            if size > len || at + 8 > len - size {
                return Err(format!(
                    "data at {at} claims {size} bytes, past the file's end"
                ));
            }
        } else {
            if offset == 0 {
                continue; // empty group
            }
            let count =
                u64_at(offset).ok_or_else(|| format!("group at {offset} lies outside the file"))?;
            if count > len / 8 || offset + 8 > len - 8 * count {
                return Err(format!(
                    "group at {offset} claims {count} children, past the file's end"
                ));
            }
            children_pushed += count;
            if children_pushed > len / 8 {
                return Err(format!(
                    "groups list more children ({children_pushed}) than the file has words"
                ));
            }
            for k in 0..count {
                stack.push(u64_at(offset + 8 + 8 * k).ok_or("group child outside the file")?);
            }
        }
    }
    check_time_samplings(bytes, root)
}

/// The little-endian word at byte `at`; `None` past the end.
fn word_at(bytes: &[u8], at: u64) -> Option<u64> {
    let at = usize::try_from(at).ok()?;
    let slice = bytes.get(at..at.checked_add(8)?)?;
    Some(u64::from_le_bytes(slice.try_into().ok()?))
}

/// The archive's time samplings (the root group's fifth child, a data blob): `ogawa-rs`
/// allocates each entry's sample list from a count in the blob (up to 32 GiB) before it
/// reads a sample, so every count is checked against what the blob holds first.
fn check_time_samplings(bytes: &[u8], root: u64) -> Result<(), String> {
    let u64_at = |at: u64| word_at(bytes, at);
    let Some(count) = u64_at(root) else {
        return Ok(());
    };
    if count < 5 {
        return Ok(()); // not an archive the crate reads; it says so itself
    }
    let Some(child) = root.checked_add(8 + 8 * 4).and_then(u64_at) else {
        return Ok(());
    };
    if child & DATA_BIT == 0 || child & !DATA_BIT == 0 {
        return Ok(());
    }
    let at = child & !DATA_BIT;
    let Some(size) = u64_at(at) else {
        return Ok(());
    };
    let blob = usize::try_from(at + 8)
        .ok()
        .and_then(|start| bytes.get(start..start.checked_add(usize::try_from(size).ok()?)?))
        .ok_or("the time samplings lie outside the file")?;
    let mut pos = 0usize;
    while pos < blob.len() {
        // max sample (u32), time per cycle (f64), samples per cycle (u32), then the samples.
        let header = blob
            .get(pos..pos + 16)
            .ok_or("a time sampling is cut short")?;
        let samples = u32::from_le_bytes(header[12..16].try_into().map_err(|_| "cut short")?);
        let needed = 8 * samples as usize;
        if needed > blob.len() - pos - 16 {
            return Err(format!(
                "a time sampling claims {samples} samples, more than its {} bytes hold",
                blob.len() - pos - 16
            ));
        }
        pos += 16 + needed;
    }
    Ok(())
}

struct Walk<'a, 'b> {
    reader: &'a mut BytesReader,
    archive: &'a Archive,
    builder: &'a mut GroomBuilder<'b>,
    guides_skipped: usize,
    /// Curves objects with a non-identity world transform.
    transforms_applied: usize,
}

impl Walk<'_, '_> {
    fn error(&self, object: &ObjectReader, what: &str, e: impl std::fmt::Debug) -> GroomReadError {
        self.builder
            .format_error(format!("{}: {what}: {e:?}", object.header.full_name))
    }

    /// Reads `object` and its children; `world` is the transform its parent places it by.
    fn object(
        &mut self,
        object: &ObjectReader,
        depth: usize,
        world: DMat4,
    ) -> Result<(), GroomReadError> {
        if depth > MAX_DEPTH {
            return Err(self
                .builder
                .format_error(format!("objects nest deeper than {MAX_DEPTH}")));
        }
        let schema = object.header.meta_data.tokens.get("schema").cloned();
        let mut world = world;
        match schema.as_deref() {
            Some("AbcGeom_Curve_v2") => {
                if world != DMat4::IDENTITY {
                    self.transforms_applied += 1;
                }
                self.curves(object, world)?;
            }
            Some("AbcGeom_Xform_v3") => {
                let (local, inherits) = self.xform(object)?;
                world = if inherits { world * local } else { local };
            }
            _ => {}
        }
        for i in 0..object.child_count() {
            let child = object
                .load_child(
                    i,
                    self.reader,
                    &self.archive.indexed_meta_data,
                    &self.archive.time_samplings,
                )
                .map_err(|e| self.error(object, "child", e))?;
            self.object(&child, depth + 1, world)?;
        }
        Ok(())
    }

    /// An `IXform`'s own matrix (first sample) and whether it applies on top of its
    /// parent's (`.inherits`, true when absent), from its `.xform` compound's `.ops` (one
    /// byte per operation: type in the high nibble) and `.vals` (every channel of every
    /// operation, in order; scalar, or an array property when long).
    fn xform(&mut self, object: &ObjectReader) -> Result<(DMat4, bool), GroomReadError> {
        let Some(props) = object.properties() else {
            return Ok((DMat4::IDENTITY, true));
        };
        let schema = match props
            .load_sub_property_by_name(".xform", self.reader, self.archive)
            .map_err(|e| self.error(object, ".xform", e))?
        {
            Some(PropertyReader::Compound(c)) => c,
            _ => return Ok((DMat4::IDENTITY, true)),
        };
        let mut first_sample = |name: &str| -> Result<Option<PodArray>, GroomReadError> {
            let property = schema
                .load_sub_property_by_name(name, self.reader, self.archive)
                .map_err(|e| self.error(object, name, e))?;
            let sample = match property {
                Some(PropertyReader::Scalar(p)) if p.sample_count() > 0 => {
                    p.load_sample(0, self.reader)
                }
                Some(PropertyReader::Array(a)) if a.sample_count() > 0 => {
                    a.load_sample(0, self.reader)
                }
                _ => return Ok(None),
            };
            sample.map(Some).map_err(|e| self.error(object, name, e))
        };
        let ops = match first_sample(".ops")? {
            Some(PodArray::U8(ops)) => ops,
            None => Vec::new(),
            Some(other) => {
                return Err(self.error(object, ".ops", format!("not bytes: {other:?}")));
            }
        };
        let vals = match first_sample(".vals")? {
            Some(PodArray::F64(vals)) => vals,
            None => Vec::new(),
            Some(_) => return Err(self.error(object, ".vals", "not 64-bit floats")),
        };
        let inherits = match first_sample(".inherits")? {
            Some(PodArray::Boolean(b)) => b.first().copied().unwrap_or(true),
            _ => true,
        };
        let matrix = xform_matrix(&ops, &vals).map_err(|e| self.error(object, ".vals", e))?;
        Ok((matrix, inherits))
    }

    /// The array `name` of the curves' `.arbGeomParams`, first sample.
    fn arb_param(&mut self, object: &ObjectReader, name: &str) -> Option<PodArray> {
        let props = object.properties()?;
        let geom = match props
            .load_sub_property_by_name(".geom", self.reader, self.archive)
            .ok()??
        {
            PropertyReader::Compound(c) => c,
            _ => return None,
        };
        let params = match geom
            .load_sub_property_by_name(".arbGeomParams", self.reader, self.archive)
            .ok()??
        {
            PropertyReader::Compound(c) => c,
            _ => return None,
        };
        match params
            .load_sub_property_by_name(name, self.reader, self.archive)
            .ok()??
        {
            PropertyReader::Array(a) => a.load_sample(0, self.reader).ok(),
            _ => None,
        }
    }

    /// The curves of `object`, placed by `world`.
    fn curves(&mut self, object: &ObjectReader, world: DMat4) -> Result<(), GroomReadError> {
        let Schema::Curves(curves) = Schema::parse(object, self.reader, self.archive)
            .map_err(|e| self.error(object, "curves", e))?
        else {
            return Ok(());
        };
        let counts = curves
            .load_n_vertices_sample(0, self.reader)
            .map_err(|e| self.error(object, "nVertices", e))?;
        let points = curves
            .load_positions_sample(0, self.reader)
            .map_err(|e| self.error(object, "P", e))?;
        // Points in the groom's space; widths by the transform's mean scale.
        let width_scale = world.determinant().abs().cbrt() as f32;
        let points: Vec<[f32; 3]> = if world == DMat4::IDENTITY {
            points
        } else {
            points
                .iter()
                .map(|p| {
                    // Projective, as Imath's `V3d * M44d` (a well-formed transform is affine).
                    world
                        .project_point3(glam::Vec3::from_array(*p).as_dvec3())
                        .as_vec3()
                        .to_array()
                })
                .collect()
        };
        let total: i64 = counts.iter().map(|&c| i64::from(c.max(0))).sum();
        if counts.iter().any(|&c| c < 0) || total != points.len() as i64 {
            return Err(self.builder.format_error(format!(
                "{}: nVertices add up to {total} (or hold a negative count) but P has {} points",
                object.header.full_name,
                points.len()
            )));
        }
        let curve_count = counts.len();
        let per_curve_i32 = |array: Option<PodArray>| match array {
            Some(PodArray::I32(v)) if v.len() == curve_count => Some(v),
            _ => None,
        };
        let guide = per_curve_i32(self.arb_param(object, "groom_guide"));
        let groups = per_curve_i32(self.arb_param(object, "groom_group_id"));
        let widths = match curves.load_widths_sample(0, self.reader).ok().flatten() {
            Some(w) => Some(w),
            None => match self.arb_param(object, "groom_width") {
                Some(PodArray::F32(w)) => Some(w),
                _ => None,
            },
        };
        // Unreal's groom attribute, else Blender's (it writes the hair's surface uv).
        let root_uvs: Option<Vec<[f32; 2]>> = ["groom_root_uv", "surface_uv_coordinate"]
            .into_iter()
            .find_map(|name| match self.arb_param(object, name) {
                Some(PodArray::F32(v)) if v.len() == 2 * curve_count => {
                    Some(v.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
                }
                _ => None,
            });
        self.builder
            .expect(curve_count as u64, points.len() as u64)?;
        let mut first = 0usize;
        let mut curve_widths = Vec::new();
        for (i, &count) in counts.iter().enumerate() {
            let span = first..first + count as usize;
            first = span.end;
            if guide.as_ref().is_some_and(|g| g[i] != 0) {
                self.guides_skipped += 1;
                continue;
            }
            curve_widths.clear();
            let have_widths = match &widths {
                Some(w) if w.len() == points.len() => {
                    curve_widths.extend_from_slice(&w[span.clone()]);
                    true
                }
                Some(w) if w.len() == curve_count => {
                    curve_widths.resize(span.len(), w[i]);
                    true
                }
                Some(w) if w.len() == 1 => {
                    curve_widths.resize(span.len(), w[0]);
                    true
                }
                _ => false,
            };
            if width_scale != 1.0 {
                for w in &mut curve_widths {
                    *w *= width_scale;
                }
            }
            self.builder.push(
                points[span].iter().copied(),
                have_widths.then_some(curve_widths.as_slice()),
                root_uvs.as_ref().map(|uv| uv[i]),
                groups.as_ref().map(|g| g[i]),
            )?;
        }
        Ok(())
    }
}

/// An `IXform` sample's matrix from its operation codes and channel values, as the Alembic
/// library's `XformSample::getMatrix` builds it: each operation (scale 0, translate 1,
/// rotate about an axis by degrees 2, matrix 3, rotate about x / y / z 4–6; high nibble of
/// its code) is applied before the ones listed ahead of it — in Imath's row-vector terms
/// `M = m_n … m_1`, here with column vectors `M = m_1 … m_n`. Channels the values run short
/// of are 0, as the library leaves them; an unknown operation has no channels and no effect,
/// as in the library; a rotation about a zero axis scales by its cosine, as Imath's does.
/// Non-finite values are refused.
pub fn xform_matrix(ops: &[u8], vals: &[f64]) -> Result<DMat4, String> {
    if let Some(bad) = vals.iter().find(|v| !v.is_finite()) {
        return Err(format!("a transform value is not finite ({bad})"));
    }
    let mut at = 0usize;
    let mut take = |count: usize| -> Vec<f64> {
        let channels = (0..count)
            .map(|k| vals.get(at + k).copied().unwrap_or(0.0))
            .collect();
        at += count;
        channels
    };
    // Imath normalises a zero axis to zero, which leaves cos θ on the diagonal: a uniform
    // scale (a crafted file; kept as the library reads it).
    let rotation = |axis: DVec3, degrees: f64| match axis.try_normalize() {
        Some(axis) => DMat4::from_axis_angle(axis, degrees.to_radians()),
        None => DMat4::from_scale(DVec3::splat(degrees.to_radians().cos())),
    };
    let mut matrix = DMat4::IDENTITY;
    for &op in ops {
        let local = match op >> 4 {
            0 => DMat4::from_scale(DVec3::from_slice(&take(3))),
            1 => DMat4::from_translation(DVec3::from_slice(&take(3))),
            2 => {
                let c = take(4);
                rotation(DVec3::new(c[0], c[1], c[2]), c[3])
            }
            // Imath's row-major rows are glam's columns: the same 16 values in order.
            3 => DMat4::from_cols_slice(&take(16)),
            4 => rotation(DVec3::X, take(1)[0]),
            5 => rotation(DVec3::Y, take(1)[0]),
            6 => rotation(DVec3::Z, take(1)[0]),
            _ => DMat4::IDENTITY,
        };
        matrix *= local;
    }
    if !matrix.is_finite() {
        return Err("the transform is not finite".into());
    }
    Ok(matrix)
}
