//! Reading grooms made in other tools: strands from Alembic (`.abc`: plain `ICurves` as
//! Blender, Houdini and Maya write them, and Unreal's groom schema), USD (`.usda`, `.usdc`,
//! `.usdz` `BasisCurves`) and cyHair `.hair`, into one [`InputGroom`] that
//! [`crate::fit`] turns into a hair mesh.
//!
//! Every reader goes through [`GroomBuilder`], which checks each curve as it arrives (a
//! non-finite point, an empty curve or a one-point curve is a named error with the curve's
//! index), holds the caps of [`GroomLimits`] (so memory stays bounded whatever the file
//! claims), reports progress and stops when the caller cancels.

pub mod alembic;
pub mod hair;
pub mod usd;

use std::ops::ControlFlow;
use std::path::Path;

use crate::io::input_files::InputFileError;

/// Caps on what a groom file may hold (docs/resource-policy.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroomLimits {
    pub max_file_bytes: u64,
    pub max_curves: u64,
    pub max_points: u64,
    pub max_points_per_curve: u64,
}

impl Default for GroomLimits {
    fn default() -> Self {
        Self {
            // A 4 Mi-strand groom of 32-point f32 curves is about 1.6 GB of points.
            max_file_bytes: 2 << 30,
            max_curves: 4 << 20,
            // The export cap: 32 Mi points are 384 MB as f32, the largest groom kept in memory.
            max_points: crate::io::strand_files::MAX_EXPORT_POINTS,
            max_points_per_curve: 1 << 16,
        }
    }
}

/// Why a groom was not read.
#[derive(Debug, thiserror::Error)]
pub enum GroomReadError {
    #[error(transparent)]
    File(#[from] InputFileError),
    #[error("{file}: {message}")]
    Format { file: String, message: String },
    #[error(
        "{file}: the extension \"{extension}\" is not a groom format (.abc, .usda, .usdc, .usdz or .hair)"
    )]
    UnknownFormat { file: String, extension: String },
    #[error("{file}: curve {curve}, point {point} is not finite ({value:?})")]
    NonFinite {
        file: String,
        curve: usize,
        point: usize,
        value: [f32; 3],
    },
    #[error("{file}: curve {curve} has no points")]
    EmptyCurve { file: String, curve: usize },
    #[error("{file}: curve {curve} has a single point; a strand needs a root and a tip")]
    SinglePointCurve { file: String, curve: usize },
    #[error("{file}: {count} {what} is more than the cap of {cap} (docs/resource-policy.md)")]
    TooMany {
        file: String,
        what: &'static str,
        count: u64,
        cap: u64,
    },
    #[error("{file}: holds no curves")]
    NoCurves { file: String },
    #[error("reading {file} was cancelled")]
    Cancelled { file: String },
}

/// The strands of a groom, in the file's units and axes (after its transforms where the
/// format has them), with what the file says about them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct InputGroom {
    pub points: Vec<[f32; 3]>,
    /// Curve `i` is `points[starts[i] .. starts[i + 1]]`; one more entry than curves.
    pub starts: Vec<u32>,
    /// Width at every point, where the file has widths.
    pub widths_m: Option<Vec<f32>>,
    /// Root uv on the scalp per curve, where the file has it.
    pub root_uvs: Option<Vec<[f32; 2]>>,
    /// Group per curve (Alembic `groom_group_id`, one per USD prim), where the file has them.
    pub groups: Option<Vec<i32>>,
    /// What the file was and what was not taken from it.
    pub notes: Vec<String>,
}

impl InputGroom {
    pub fn curve_count(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    pub fn curve(&self, index: usize) -> &[[f32; 3]] {
        &self.points[self.starts[index] as usize..self.starts[index + 1] as usize]
    }

    pub fn curves(&self) -> impl Iterator<Item = &[[f32; 3]]> {
        self.starts
            .windows(2)
            .map(|w| &self.points[w[0] as usize..w[1] as usize])
    }

    /// Axis-aligned bounds of every point; `None` when there are none.
    pub fn bounds(&self) -> Option<([f32; 3], [f32; 3])> {
        let first = *self.points.first()?;
        Some(self.points.iter().fold((first, first), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
            )
        }))
    }

    /// Length of the bounds' diagonal.
    pub fn diagonal(&self) -> f64 {
        self.bounds()
            .map(|(lo, hi)| {
                let d: f64 = (0..3).map(|i| (hi[i] as f64 - lo[i] as f64).powi(2)).sum();
                d.sqrt()
            })
            .unwrap_or(0.0)
    }
}

/// How often the builder reports progress, in curves.
const PROGRESS_EVERY: usize = 4096;

/// Collects curves under the caps, checking each one; the readers' common back end.
pub struct GroomBuilder<'a> {
    file: String,
    limits: GroomLimits,
    groom: InputGroom,
    progress: &'a mut dyn FnMut(f64) -> ControlFlow<()>,
    expected_curves: usize,
}

impl<'a> GroomBuilder<'a> {
    pub fn new(
        file: &Path,
        limits: GroomLimits,
        progress: &'a mut dyn FnMut(f64) -> ControlFlow<()>,
    ) -> Self {
        Self {
            file: file.display().to_string(),
            limits,
            groom: InputGroom {
                starts: vec![0],
                ..InputGroom::default()
            },
            progress,
            expected_curves: 0,
        }
    }

    pub fn file(&self) -> &str {
        &self.file
    }

    pub fn format_error(&self, message: impl Into<String>) -> GroomReadError {
        GroomReadError::Format {
            file: self.file.clone(),
            message: message.into(),
        }
    }

    /// Says how many curves and points are coming (for the progress fraction), refusing
    /// counts over the caps before anything of that size is held.
    pub fn expect(&mut self, curves: u64, points: u64) -> Result<(), GroomReadError> {
        let total_curves = self.groom.curve_count() as u64 + curves;
        let total_points = self.groom.points.len() as u64 + points;
        self.check_caps(total_curves, total_points)?;
        self.expected_curves = total_curves as usize;
        Ok(())
    }

    fn check_caps(&self, curves: u64, points: u64) -> Result<(), GroomReadError> {
        let too_many = |what, count, cap| GroomReadError::TooMany {
            file: self.file.clone(),
            what,
            count,
            cap,
        };
        if curves > self.limits.max_curves {
            return Err(too_many("curves", curves, self.limits.max_curves));
        }
        if points > self.limits.max_points {
            return Err(too_many("points", points, self.limits.max_points));
        }
        Ok(())
    }

    pub fn note(&mut self, note: impl Into<String>) {
        self.groom.notes.push(note.into());
    }

    /// Adds one curve (and its per-point widths, root uv and group where the file has them:
    /// an attribute some curves lack is dropped for all, with a note).
    pub fn push(
        &mut self,
        points: impl ExactSizeIterator<Item = [f32; 3]>,
        widths_m: Option<&[f32]>,
        root_uv: Option<[f32; 2]>,
        group: Option<i32>,
    ) -> Result<(), GroomReadError> {
        let curve = self.groom.curve_count();
        let count = points.len();
        match count {
            0 => {
                return Err(GroomReadError::EmptyCurve {
                    file: self.file.clone(),
                    curve,
                });
            }
            1 => {
                return Err(GroomReadError::SinglePointCurve {
                    file: self.file.clone(),
                    curve,
                });
            }
            _ => {}
        }
        if count as u64 > self.limits.max_points_per_curve {
            return Err(GroomReadError::TooMany {
                file: self.file.clone(),
                what: "points in one curve",
                count: count as u64,
                cap: self.limits.max_points_per_curve,
            });
        }
        self.check_caps(curve as u64 + 1, (self.groom.points.len() + count) as u64)?;
        for (k, p) in points.enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(GroomReadError::NonFinite {
                    file: self.file.clone(),
                    curve,
                    point: k,
                    value: p,
                });
            }
            self.groom.points.push(p);
        }
        self.groom.starts.push(self.groom.points.len() as u32);
        let first = curve == 0;
        keep_attribute(&mut self.groom.widths_m, widths_m, first, |all, w| {
            all.extend(
                w.iter()
                    .map(|w| if w.is_finite() { w.max(0.0) } else { 0.0 }),
            )
        });
        keep_attribute(
            &mut self.groom.root_uvs,
            root_uv.as_ref(),
            first,
            |all, uv| all.push(*uv),
        );
        keep_attribute(&mut self.groom.groups, group.as_ref(), first, |all, g| {
            all.push(*g)
        });
        if (curve + 1).is_multiple_of(PROGRESS_EVERY) {
            let fraction = (curve + 1) as f64 / self.expected_curves.max(curve + 1) as f64;
            if (self.progress)(fraction).is_break() {
                return Err(GroomReadError::Cancelled {
                    file: self.file.clone(),
                });
            }
        }
        Ok(())
    }

    pub fn finish(mut self) -> Result<InputGroom, GroomReadError> {
        if self.groom.curve_count() == 0 {
            return Err(GroomReadError::NoCurves { file: self.file });
        }
        let _ = (self.progress)(1.0);
        if self.groom.widths_m.is_none() {
            self.groom.notes.push("no widths".into());
        }
        Ok(self.groom)
    }
}

/// Appends `value` to `all` while every curve so far had the attribute; the first curve
/// without it drops it for all (a partial attribute cannot be matched to curves).
fn keep_attribute<T, V: ?Sized>(
    all: &mut Option<Vec<T>>,
    value: Option<&V>,
    first: bool,
    append: impl FnOnce(&mut Vec<T>, &V),
) {
    match (value, first) {
        (Some(v), true) => {
            let mut list = Vec::new();
            append(&mut list, v);
            *all = Some(list);
        }
        (Some(v), false) => {
            if let Some(list) = all {
                append(list, v);
            }
        }
        (None, _) => *all = None,
    }
}

/// Reads the groom at `path`; the format follows the extension. `progress` gets the
/// fraction read (0 to 1) and may break to cancel.
pub fn read_groom(
    path: &Path,
    limits: GroomLimits,
    progress: &mut dyn FnMut(f64) -> ControlFlow<()>,
) -> Result<InputGroom, GroomReadError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match extension.as_str() {
        "hair" => hair::parse(path, &read_groom_bytes(path, limits)?, limits, progress),
        "abc" => alembic::parse(path, read_groom_bytes(path, limits)?, limits, progress),
        "usda" | "usdc" | "usdz" | "usd" => usd::read(path, limits, progress),
        _ => Err(GroomReadError::UnknownFormat {
            file: path.display().to_string(),
            extension,
        }),
    }
}

/// The whole file, refused when it is not a regular file inside its folder or is over
/// the byte cap (the binary formats are parsed from memory).
fn read_groom_bytes(path: &Path, limits: GroomLimits) -> Result<Vec<u8>, GroomReadError> {
    Ok(crate::io::input_files::read_regular_file(
        path,
        limits.max_file_bytes,
        "a groom",
    )?)
}

/// Runs a third-party reader that may panic on a hostile file (`ogawa-rs` panics on types
/// it does not read and asserts on malformed input), turning a panic into a named error.
pub(crate) fn without_panics<T>(
    file: &Path,
    reader: &str,
    run: impl FnOnce() -> Result<T, GroomReadError>,
) -> Result<T, GroomReadError> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
        Ok(result) => result,
        Err(_) => Err(GroomReadError::Format {
            file: file.display().to_string(),
            message: format!("{reader} could not parse it (a malformed or unsupported file)"),
        }),
    }
}

#[cfg(test)]
mod tests;
