//! How each project was last viewed — camera orbit and the viewport's switches — kept per
//! user beside the recent-files list (`views.json` in the recovery folder), never in the
//! document or its undo history: looking around is not an edit.
//!
//! The file is a convenience: unreadable, oversized or hostile content is ignored entry by
//! entry (values outside their ranges are dropped, not clamped into a surprising view), and
//! a failure to store it never interrupts the artist.

use std::path::{Path, PathBuf};

use hairloom_core::runtime::strand_gen::Filtering;
use hairloom_core::runtime::textures::Precision;
use serde::{Deserialize, Serialize};

use super::viewport::{MAX_STRANDS_PER_BUNDLE, Orbit, ViewSettings};

/// One project's view.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SavedView {
    pub yaw_rad: f32,
    pub pitch_rad: f32,
    pub zoom: f32,
    pub pan: [f32; 2],
    pub wireframe: bool,
    pub frame_glyphs: bool,
    pub gizmo: bool,
    /// Views stored before the styling-direction gizmo existed read as off.
    #[serde(default)]
    pub styling_gizmo: bool,
    pub strands_per_bundle: u32,
    pub precision: Precision,
    pub filtering: Filtering,
    pub lod: bool,
}

impl SavedView {
    /// The view `orbit` and `settings` give.
    pub fn of(orbit: &Orbit, settings: &ViewSettings) -> Self {
        Self {
            yaw_rad: orbit.yaw_rad,
            pitch_rad: orbit.pitch_rad,
            zoom: orbit.zoom,
            pan: orbit.pan,
            wireframe: settings.wireframe,
            frame_glyphs: settings.frame_glyphs,
            gizmo: settings.gizmo,
            styling_gizmo: settings.styling_gizmo,
            strands_per_bundle: settings.strands_per_bundle,
            precision: settings.precision,
            filtering: settings.filtering,
            lod: settings.lod.enabled,
        }
    }

    /// Puts the view back into `orbit` and `settings` (LOD's tuning stays as it is).
    pub fn apply(&self, orbit: &mut Orbit, settings: &mut ViewSettings) {
        *orbit = Orbit {
            yaw_rad: self.yaw_rad,
            pitch_rad: self.pitch_rad,
            zoom: self.zoom,
            pan: self.pan,
        };
        settings.wireframe = self.wireframe;
        settings.frame_glyphs = self.frame_glyphs;
        settings.gizmo = self.gizmo;
        settings.styling_gizmo = self.styling_gizmo;
        settings.strands_per_bundle = self.strands_per_bundle;
        settings.precision = self.precision;
        settings.filtering = self.filtering;
        settings.lod.enabled = self.lod;
    }

    /// Whether every value is one the viewport could have produced.
    fn is_valid(&self) -> bool {
        let finite = [
            self.yaw_rad,
            self.pitch_rad,
            self.zoom,
            self.pan[0],
            self.pan[1],
        ]
        .iter()
        .all(|v| v.is_finite());
        finite
            && self.pitch_rad.abs() <= std::f32::consts::FRAC_PI_2
            && self.zoom > 0.0
            && self.zoom <= 1e3
            && self.pan.iter().all(|p| p.abs() <= 1e3)
            && (1..=MAX_STRANDS_PER_BUNDLE).contains(&self.strands_per_bundle)
    }
}

/// The views of recently viewed projects, newest first.
pub struct ViewMemory {
    file: PathBuf,
    views: Vec<(PathBuf, SavedView)>,
}

impl ViewMemory {
    /// Projects remembered (the oldest is forgotten first).
    pub const MAX: usize = 64;
    /// Larger files are not read (64 entries take a few kilobytes).
    const MAX_FILE_BYTES: u64 = 256 * 1024;

    /// The views stored in `file` (none when it is missing, too large or unreadable; invalid
    /// entries are skipped).
    pub fn load(file: PathBuf) -> Self {
        // The same rules as every input file: a FIFO cannot block the start, a link to a
        // device is refused, and the cap holds while reading.
        let views = hairloom_core::io::input_files::read_regular_file(
            &file,
            Self::MAX_FILE_BYTES,
            "the remembered views",
        )
        .ok()
        .and_then(|bytes| serde_json::from_slice::<Vec<serde_json::Value>>(&bytes).ok())
        .unwrap_or_default()
        .into_iter()
        .filter_map(|entry| serde_json::from_value::<(PathBuf, SavedView)>(entry).ok())
        .filter(|(_, view)| view.is_valid())
        .take(Self::MAX)
        .collect();
        Self { file, views }
    }

    /// The view `project` was last left in.
    pub fn recall(&self, project: &Path) -> Option<SavedView> {
        let project = std::path::absolute(project).unwrap_or_else(|_| project.to_path_buf());
        self.views
            .iter()
            .find(|(path, _)| *path == project)
            .map(|(_, view)| *view)
    }

    /// Remembers `view` for `project` and stores the list.
    pub fn remember(&mut self, project: &Path, view: SavedView) {
        if !view.is_valid() {
            return;
        }
        let project = std::path::absolute(project).unwrap_or_else(|_| project.to_path_buf());
        if self.views.first() == Some(&(project.clone(), view)) {
            return;
        }
        self.views.retain(|(path, _)| *path != project);
        self.views.insert(0, (project, view));
        self.views.truncate(Self::MAX);
        let Ok(text) = serde_json::to_vec_pretty(&self.views) else {
            return;
        };
        if let Some(dir) = self.file.parent() {
            let _ = super::recovery::create_private_dir(dir);
        }
        let _ = hairloom_core::io::project::write_atomic(&self.file, &text, |_| {});
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(yaw_rad: f32) -> SavedView {
        let mut settings = ViewSettings {
            wireframe: true,
            strands_per_bundle: 64,
            precision: Precision::F16,
            filtering: Filtering::Hardware8Bit,
            ..ViewSettings::default()
        };
        settings.lod.enabled = false;
        SavedView::of(
            &Orbit {
                yaw_rad,
                pitch_rad: -0.3,
                zoom: 0.5,
                pan: [0.1, -0.2],
            },
            &settings,
        )
    }

    #[test]
    fn views_round_trip_per_project_newest_first() {
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("views.json");
        let (a, b) = (dir.path().join("a.hairloom"), dir.path().join("b.hairloom"));
        let mut memory = ViewMemory::load(file.clone());
        assert_eq!(memory.recall(&a), None);
        memory.remember(&a, view(1.0));
        memory.remember(&b, view(2.0));
        memory.remember(&a, view(3.0));
        let loaded = ViewMemory::load(file.clone());
        assert_eq!(loaded.recall(&a), Some(view(3.0)));
        assert_eq!(loaded.recall(&b), Some(view(2.0)));
        // Applying a view gives back the orbit and switches it was made of.
        let (mut orbit, mut settings) = (Orbit::default(), ViewSettings::default());
        view(3.0).apply(&mut orbit, &mut settings);
        assert_eq!(SavedView::of(&orbit, &settings), view(3.0));
        assert!(!settings.lod.enabled && settings.wireframe);
        // The list is capped, the oldest forgotten first.
        for i in 0..ViewMemory::MAX {
            memory.remember(&dir.path().join(format!("p{i}.hairloom")), view(0.5));
        }
        let loaded = ViewMemory::load(file);
        assert_eq!(loaded.views.len(), ViewMemory::MAX);
        assert_eq!(loaded.recall(&a), None);
    }

    #[test]
    fn hostile_view_files_are_ignored_entry_by_entry() {
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("views.json");
        let a = dir.path().join("a.hairloom");
        let good = serde_json::to_value((&a, view(1.0))).expect("json");
        let mut bad_zoom = good.clone();
        bad_zoom[0] = dir.path().join("zoom.hairloom").to_string_lossy().into();
        bad_zoom[1]["zoom"] = (-1.0).into();
        let mut bad_strands = good.clone();
        bad_strands[0] = dir.path().join("strands.hairloom").to_string_lossy().into();
        bad_strands[1]["strands_per_bundle"] = 1_000_000.into();
        let text = serde_json::to_string(&vec![
            serde_json::json!("not an entry"),
            bad_zoom,
            bad_strands,
            good,
        ])
        .expect("json");
        std::fs::write(&file, text).expect("write");
        let memory = ViewMemory::load(file.clone());
        assert_eq!(memory.views.len(), 1);
        assert_eq!(memory.recall(&a), Some(view(1.0)));
        // Garbage, or a file too large to be a view list, reads as no views.
        std::fs::write(&file, b"{{{{").expect("write");
        assert!(ViewMemory::load(file.clone()).views.is_empty());
        std::fs::write(&file, vec![b' '; 300 * 1024]).expect("write");
        assert!(ViewMemory::load(file.clone()).views.is_empty());
        // A FIFO or a link to a device reads as no views at once (it blocked, or was read
        // until memory ran out).
        std::fs::remove_file(&file).expect("remove");
        std::os::unix::fs::symlink("/dev/zero", &file).expect("link");
        assert!(ViewMemory::load(file.clone()).views.is_empty());
        crate::app::test_support::make_fifo(&file);
        let views =
            crate::app::test_support::returns_promptly(move || ViewMemory::load(file).views.len());
        assert_eq!(views, 0);
        // A NaN view is never stored.
        let mut memory = ViewMemory::load(dir.path().join("other.json"));
        memory.remember(&a, view(f32::NAN));
        assert_eq!(memory.recall(&a), None);
    }
}
