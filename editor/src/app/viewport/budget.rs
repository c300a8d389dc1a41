//! The viewport's frame budget while the artist interacts (Blender's answer to a slow
//! frame: draw less while the input moves). Interactive frames drop the optional effects,
//! draw fewer pixels and bias strand and vertex LOD toward fewer strands, by one effort
//! figure that learns from what the last interactive frame cost; the full picture follows
//! once input has been still for [`SETTLE`].

use hairloom_core::runtime::frame_plan::LodSettings;

/// The frame time interactive frames aim for.
pub const FRAME_BUDGET_MS: f64 = 120.0;
/// How long input must be still before the full picture is drawn again.
pub const SETTLE: std::time::Duration = std::time::Duration::from_millis(400);

/// How much of the picture a frame draws.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameQuality {
    /// The scene's effects at the viewport's full size, the artist's LOD settings.
    Full,
    /// While the artist interacts and the full frame is over budget: no optional effect,
    /// drawn at `scale` of the viewport's size (then stretched), with strand and vertex LOD
    /// on and their α scaled by `detail` (fewer strands, thickened to keep coverage).
    Interactive { scale: f32, detail: f32 },
}

impl FrameQuality {
    /// The size drawn for a viewport of `full` pixels.
    pub fn size(self, full: [u32; 2]) -> [u32; 2] {
        match self {
            FrameQuality::Full => full,
            FrameQuality::Interactive { scale, .. } => {
                full.map(|side| ((side as f32 * scale).round() as u32).max(1))
            }
        }
    }

    /// The LOD settings drawn with, from the artist's.
    pub fn lod(self, chosen: LodSettings) -> LodSettings {
        match self {
            FrameQuality::Full => chosen,
            FrameQuality::Interactive { detail, .. } => chosen.with_detail(detail as f64),
        }
    }
}

/// Interactive frames never go below this fraction of the viewport's side (a quarter:
/// the picture still reads as the hairstyle, stretched 4×).
pub const MIN_SCALE: f32 = 0.25;
/// Nor below this LOD detail (α scaled by 1/50: a few strands per bundle, thick).
pub const MIN_DETAIL: f32 = 0.02;

/// The interactive frames' effort `e ∈ [MIN_SCALE² · MIN_DETAIL, 1]`, roughly the fraction
/// of the full picture's cost they may spend. Pixels go first (scale `√e`, down to
/// [`MIN_SCALE`]), then strands and vertices (LOD detail `e / scale²`): at a small size,
/// strand LOD already thins bundles that span few pixels, and the detail bias goes further.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InteractiveEffort {
    effort: f32,
}

impl InteractiveEffort {
    pub const MIN: f32 = MIN_SCALE * MIN_SCALE * MIN_DETAIL;

    /// The first guess when the full picture took `full_frame_ms`: the budget's share of it.
    pub fn from_full_frame(full_frame_ms: f64) -> Self {
        let share = FRAME_BUDGET_MS / full_frame_ms.max(1e-3);
        Self {
            effort: clamp_effort(share as f32),
        }
    }

    pub fn effort(self) -> f32 {
        self.effort
    }

    /// The quality an interactive frame draws at this effort.
    pub fn quality(self) -> FrameQuality {
        let scale = self.effort.sqrt().clamp(MIN_SCALE, 1.0);
        // Above the smallest size every strand is drawn (exactly, not e / √e² ≈ 1).
        let detail = if scale > MIN_SCALE {
            1.0
        } else {
            (self.effort / (scale * scale)).clamp(MIN_DETAIL, 1.0)
        };
        FrameQuality::Interactive { scale, detail }
    }

    /// Learns from an interactive frame that took `frame_ms` at this effort: cost is taken as
    /// proportional to effort, and the effort moves halfway (in ratio) toward the budget, so
    /// one noisy frame does not swing it.
    pub fn learn(&mut self, frame_ms: f64) {
        if !frame_ms.is_finite() || frame_ms <= 0.0 {
            return;
        }
        let ratio = (FRAME_BUDGET_MS / frame_ms).sqrt() as f32;
        self.effort = clamp_effort(self.effort * ratio);
    }
}

fn clamp_effort(effort: f32) -> f32 {
    if effort.is_nan() {
        InteractiveEffort::MIN
    } else {
        effort.clamp(InteractiveEffort::MIN, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame's cost in a simple model of a CPU adapter: a fixed part, a part per pixel
    /// and a part per strand vertex (strands drop with detail and with size, as LOD does
    /// once bundles span few pixels).
    fn modelled_ms(quality: FrameQuality) -> f64 {
        match quality {
            FrameQuality::Full => 20_000.0,
            FrameQuality::Interactive { scale, detail } => {
                let (scale, detail) = (scale as f64, detail as f64);
                40.0 + 600.0 * scale * scale + 1_900.0 * (scale * detail).min(1.0)
            }
        }
    }

    #[test]
    fn effort_settles_within_the_budget() {
        let mut effort = InteractiveEffort::from_full_frame(modelled_ms(FrameQuality::Full));
        let mut last = f64::INFINITY;
        for _ in 0..30 {
            last = modelled_ms(effort.quality());
            effort.learn(last);
        }
        assert!(
            (FRAME_BUDGET_MS * 0.5..=FRAME_BUDGET_MS * 1.05).contains(&last),
            "settled at {last:.1} ms ({:?})",
            effort.quality()
        );
    }

    #[test]
    fn pixels_go_before_strands() {
        let quality = |effort| InteractiveEffort { effort }.quality();
        assert_eq!(
            quality(1.0),
            FrameQuality::Interactive {
                scale: 1.0,
                detail: 1.0
            }
        );
        // A quarter of the effort: half the side, every strand.
        assert_eq!(
            quality(0.25),
            FrameQuality::Interactive {
                scale: 0.5,
                detail: 1.0
            }
        );
        // Below MIN_SCALE² the size stays and detail drops.
        let FrameQuality::Interactive { scale, detail } = quality(0.01) else {
            unreachable!()
        };
        assert_eq!(scale, MIN_SCALE);
        assert!((detail - 0.16).abs() < 1e-6, "{detail}");
        // Effort is monotone in both.
        let mut previous = (0.0, 0.0);
        for step in 0..=100 {
            let FrameQuality::Interactive { scale, detail } = quality(step as f32 / 100.0) else {
                unreachable!()
            };
            assert!(scale >= previous.0 && detail >= previous.1);
            previous = (scale, detail);
        }
    }

    #[test]
    fn hostile_frame_times_leave_effort_bounded() {
        let mut effort = InteractiveEffort::from_full_frame(f64::NAN);
        assert!(effort.effort().is_finite());
        for ms in [0.0, -5.0, f64::NAN, f64::INFINITY, 1e-300, 1e300] {
            effort.learn(ms);
            let e = effort.effort();
            assert!((InteractiveEffort::MIN..=1.0).contains(&e), "{ms} -> {e}");
        }
        assert_eq!(
            InteractiveEffort::from_full_frame(1e9).effort(),
            InteractiveEffort::MIN
        );
        assert_eq!(InteractiveEffort::from_full_frame(1.0).effort(), 1.0);
    }
}
