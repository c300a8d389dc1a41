//! The scene: how a project is lit and seen, what the hair is made of, and which effects the
//! renderer runs. Saved in the project, edited through the same undoable document diffs as
//! everything else, validated with errors that name the field.
//!
//! The effects are the mission's "compute only what the scene calls for": the renderer builds
//! its pass list from [`Effects`], and an effect that is off has no pipeline, texture, buffer
//! or dispatch (`hairloom_render::resources` lists what exists, and tests check it per scene).
//! Units are in the names; colours are linear RGB; directions are in the model's space (Y up).

use serde::{Deserialize, Serialize};

use crate::model::motion::Motion;

/// The most lights a scene may hold (the shaders' uniform array size).
pub const MAX_LIGHTS: usize = 8;
/// The most lights that may cast shadows: each one costs its own shadow passes and maps.
pub const MAX_SHADOWED_LIGHTS: usize = 2;
/// Opacity-map layer counts the renderer supports (layers are stored four to a texel).
pub const OPACITY_LAYER_CHOICES: [u32; 4] = [4, 8, 12, 16];
/// Smallest and largest shadow-map side, in texels (an adapter may allow less: checked when
/// the maps are made, with the adapter's limit named).
pub const SHADOW_RESOLUTION_RANGE: (u32, u32) = (64, 16384);

/// Where light comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum LightSource {
    /// A light at infinity; `to_light` points from the scene toward it (any length but 0).
    Directional { to_light: [f32; 3] },
    /// A light at a point (model space, metres); irradiance falls off with the squared
    /// distance.
    Point { position_m: [f32; 3] },
}

impl LightSource {
    /// The unit direction from `point` toward the light and the distance to it (infinite for
    /// a directional light); `None` for a zero direction or a point at the light.
    pub fn toward(&self, point: glam::DVec3) -> Option<(glam::DVec3, f64)> {
        match *self {
            LightSource::Directional { to_light } => {
                let direction = glam::Vec3::from(to_light).as_dvec3().try_normalize()?;
                Some((direction, f64::INFINITY))
            }
            LightSource::Point { position_m } => {
                let offset = glam::Vec3::from(position_m).as_dvec3() - point;
                let distance = offset.length();
                (distance > 1e-9).then(|| (offset / distance, distance))
            }
        }
    }
}

/// One light of the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    pub name: String,
    pub source: LightSource,
    /// Linear RGB, each channel in `[0, 1]`.
    pub color: [f32; 3],
    /// Directional: irradiance on a surface facing the light. Point: radiant intensity, the
    /// irradiance at 1 m. Both in the picture's linear units (exposure 1 maps 1 to white).
    pub intensity: f32,
    /// Whether this light casts shadows (self-shadowing and body shadows need at least one).
    #[serde(default)]
    pub casts_shadows: bool,
}

impl Light {
    pub fn directional(name: &str, to_light: [f32; 3], color: [f32; 3], intensity: f32) -> Self {
        Self {
            name: name.into(),
            source: LightSource::Directional { to_light },
            color,
            intensity,
            casts_shadows: false,
        }
    }
}

/// A named camera direction (`hairloom render --view NAME`, the editor's view menu).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraPreset {
    pub name: String,
    /// From the framed hair toward the camera.
    pub direction: [f32; 3],
    /// Vertical field of view.
    pub fov_deg: f32,
}

/// What gives a fibre its colour: the absorption coefficient inside the fibre, `σ_a`, per
/// unit of fibre radius (pbrt's and Blender's Principled Hair convention), given directly,
/// from melanin concentrations, or from a colour by Chiang et al. 2016's inversion.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Pigment {
    /// Eumelanin (brown-black) and pheomelanin (red-yellow) concentrations: 0.3 is blond,
    /// 1.3 brown, 8 black (d'Eon et al. 2011's measured absorption per unit concentration).
    Melanin { eumelanin: f32, pheomelanin: f32 },
    /// The colour a thick mass of this hair shows (each channel in `[0, 1]`), converted to
    /// absorption with the material's azimuthal roughness (Chiang et al. 2016, eq. 9).
    Color { rgb: [f32; 3] },
    /// `σ_a` per channel, per unit of fibre radius.
    Absorption { sigma_a: [f32; 3] },
}

/// The fibre material: the physically based parameters of Blender's Principled Hair (Chiang),
/// pbrt-v4's `HairBxDF` and Unreal's hair shading, plus root-to-tip and per-strand variation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HairMaterial {
    pub pigment: Pigment,
    /// Longitudinal roughness β_m in `[0, 1]` (how far highlights spread along the fibre).
    pub longitudinal_roughness: f32,
    /// Azimuthal roughness β_n in `[0, 1]` (how far light spreads around the fibre).
    pub azimuthal_roughness: f32,
    /// Tilt α of the cuticle scales, which shifts the highlights along the fibre.
    pub cuticle_tilt_deg: f32,
    /// Index of refraction of the fibre (1.55 for keratin).
    pub ior: f32,
    /// Absorption at the tip relative to the root (below 1: sun-lightened tips).
    pub tip_absorption_factor: f32,
    /// Per-strand random spread of the absorption, in `[0, 1]` (0: every strand alike).
    pub strand_absorption_variation: f32,
    /// Colour along the strand (an ombré, a dip-dye, lightened ends): none keeps the root's
    /// colour to the tip. Files from before it have none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ombre: Option<Ombre>,
}

/// An ombré: along every strand the hair turns from its own colour (the material's, or the
/// colour map's at its root) to `tip_rgb`, smoothly from `start` to `end` (fractions of the
/// strand's length, root 0, tip 1). The blend is in colour, so half-way looks half-way; the
/// absorption that shows it follows (Chiang et al. 2016, eq. 9), and the tip factor and the
/// per-strand variation still apply on top.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ombre {
    /// The colour a thick mass of the ends shows (linear, each channel in `[0, 1]`).
    pub tip_rgb: [f32; 3],
    /// Where along the strand the colour starts to turn, in `[0, 1]`.
    pub start: f32,
    /// Where it has turned fully, in `[start, 1]` (equal to `start`: a hard dip-dye line).
    pub end: f32,
}

impl Default for Ombre {
    fn default() -> Self {
        // Lightened ends: a honey blond over the lower half.
        Self {
            tip_rgb: [0.55, 0.38, 0.2],
            start: 0.4,
            end: 0.9,
        }
    }
}

impl Default for HairMaterial {
    fn default() -> Self {
        Self {
            // A medium brown (a thick mass of it shows about sRGB (65, 38, 10)).
            pigment: Pigment::Melanin {
                eumelanin: 0.45,
                pheomelanin: 0.3,
            },
            longitudinal_roughness: 0.3,
            azimuthal_roughness: 0.3,
            cuticle_tilt_deg: 2.0,
            ior: 1.55,
            tip_absorption_factor: 0.7,
            strand_absorption_variation: 0.2,
            ombre: None,
        }
    }
}

/// The shading model of the hair.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shading {
    /// Kajiya & Kay 1989: a diffuse and a shifted specular lobe around the tangent.
    KajiyaKay,
    /// The Marschner R / TT / TRT fibre model in Chiang et al. 2016's energy-conserving form
    /// (the model the CPU reference path tracer uses too).
    #[default]
    Marschner,
}

/// How hair shadows itself.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SelfShadowing {
    None,
    /// Kim & Neumann 2001 (seed 004): layers evenly spaced over the hair's depth range seen
    /// from the light.
    OpacityShadowMaps,
    /// Yuksel & Keyser 2008 (seed 001): layers that start at the first hair each texel sees,
    /// so they follow the hair's shape.
    #[default]
    DeepOpacityMaps,
}

/// Light scattered between fibres more than once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MultipleScattering {
    None,
    /// Zinke et al. 2008: global forward scattering from the opacity maps, local back
    /// scattering from tables precomputed from the material.
    #[default]
    DualScattering,
}

/// How strands thinner than a pixel are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coverage {
    /// Ribbons at their width; multisampling alone smooths them.
    #[default]
    Msaa,
    /// Ribbons at least a pixel wide with their true coverage as opacity, blended order-
    /// independently (McGuire & Bavoil 2013) so thin strands neither alias nor pop.
    WidthOit,
}

/// How hair far from the camera is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FarHair {
    /// Every bundle as strands, thinned and thickened by strand LOD (seed 000 eq. 7-8).
    #[default]
    Strands,
    /// Seed 001: a bundle whose strands would be thinner than `far_width_px` draws the thick
    /// hairs of its hierarchy instead, shaded by the aggregated BCSDF, its level chosen each
    /// frame from the widths measured in the last (eq. 16).
    Aggregated,
}

/// Whether hair is also drawn as fur: shells and fins (seed 002).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fur {
    #[default]
    Off,
    /// Seed 002: concentric shells along the hair mesh's columns, textured from a volume of
    /// real strands laid over the root faces by lapped patches, and fins at silhouette edges;
    /// strands near the camera, shells and fins far, cross-faded by the fur's length on
    /// screen ([`FurShells`]).
    ShellsFins,
}

/// Strands a fur tile holds when the scene leaves its width to the hair: enough that the
/// repeat does not show, few enough that a strand is a texel or two wide at 128².
pub const FUR_TILE_STRANDS: f64 = 400.0;

/// How fur's shells and fins are made and when they replace the strands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FurShells {
    /// The strand volume the textures are sampled from.
    pub preset: crate::fur::volume::FurPreset,
    /// Shell layers: a power of two in [2, 64] (seed 002: 16).
    pub shell_count: u32,
    /// Side of each shell texture in texels, in [8, 1024] (seed 002: 128).
    pub shell_resolution: u32,
    /// One repeat of the fur texture on the surface; `None` sizes it to hold about
    /// [`FUR_TILE_STRANDS`] of the hair's own strands (their density on the root faces).
    pub tile_width_m: Option<f32>,
    /// Where the fur looks shorter than this on screen (root to tip), only shells and fins
    /// draw it.
    pub shells_below_px: f32,
    /// Where it looks longer than this, only strands; in between both, cross-faded.
    pub strands_above_px: f32,
}

impl Default for FurShells {
    fn default() -> Self {
        Self {
            preset: crate::fur::volume::FurPreset::Straight,
            shell_count: 16,
            shell_resolution: 128,
            tile_width_m: None,
            shells_below_px: 12.0,
            strands_above_px: 48.0,
        }
    }
}

impl FurShells {
    /// How much the shells show (0: strands only, 1: shells only) for fur `length_px` long
    /// on screen: a smoothstep between the two thresholds, so it never pops.
    pub fn shell_weight(&self, length_px: f32) -> f32 {
        if length_px.is_nan() {
            return 1.0;
        }
        let (lo, hi) = (
            self.shells_below_px,
            self.strands_above_px.max(self.shells_below_px),
        );
        if hi <= lo {
            return if length_px <= lo { 1.0 } else { 0.0 };
        }
        let t = ((length_px - lo) / (hi - lo)).clamp(0.0, 1.0);
        let weight = 1.0 - t * t * (3.0 - 2.0 * t);
        // Thresholds that are not numbers (a scene nobody validated): strands alone.
        if weight.is_nan() { 0.0 } else { weight }
    }

    pub fn validate(&self) -> Result<(), InvalidScene> {
        if !(2..=64).contains(&self.shell_count) || !self.shell_count.is_power_of_two() {
            return Err(invalid(
                "effects.fur_shells.shell_count",
                format!(
                    "{} shells: choose a power of two in [2, 64]",
                    self.shell_count
                ),
            ));
        }
        let texels = (self.shell_resolution as u64)
            .saturating_pow(2)
            .saturating_mul(self.shell_count as u64);
        if texels > crate::fur::textures::MAX_SHELL_TEXELS {
            return Err(invalid(
                "effects.fur_shells.shell_resolution",
                format!(
                    "{} shells of {}² are {texels} texels, over the limit of {}",
                    self.shell_count,
                    self.shell_resolution,
                    crate::fur::textures::MAX_SHELL_TEXELS
                ),
            ));
        }
        if !(8..=1024).contains(&self.shell_resolution) {
            return Err(invalid(
                "effects.fur_shells.shell_resolution",
                format!(
                    "{} texels is outside the valid range [8, 1024]",
                    self.shell_resolution
                ),
            ));
        }
        if let Some(width) = self.tile_width_m {
            check_range("effects.fur_shells.tile_width_m", width, 1e-4, 1.0)?;
        }
        check_range(
            "effects.fur_shells.shells_below_px",
            self.shells_below_px,
            0.0,
            1e5,
        )?;
        check_range(
            "effects.fur_shells.strands_above_px",
            self.strands_above_px,
            self.shells_below_px,
            1e5,
        )
    }
}

/// Range of ε_w, the widest a drawn thick hair may look, in pixels.
pub const FAR_WIDTH_RANGE_PX: (f32, f32) = (0.5, 32.0);

/// The effects a scene asks for; each one absent has no GPU passes or resources.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Effects {
    pub shading: Shading,
    pub self_shadowing: SelfShadowing,
    /// Layers of the opacity maps (one of [`OPACITY_LAYER_CHOICES`]).
    pub opacity_layers: u32,
    /// Deep opacity maps: the depth behind the first hair over which the layers lie; `None`
    /// is 15% of the hair's bounding-sphere diameter.
    pub opacity_depth_m: Option<f32>,
    /// The head shadows the hair and the hair shadows the head.
    pub body_shadows: bool,
    /// Side of every shadow map, in texels.
    pub shadow_resolution: u32,
    pub multiple_scattering: MultipleScattering,
    pub coverage: Coverage,
    /// Offsets h across a fibre averaged for strands thinner than two pixels (Gauss-Legendre
    /// points, one of [`FIBRE_OFFSET_CHOICES`]): an accuracy switch of the Marschner model,
    /// measured in `hairloom bench shading`.
    pub fibre_offsets: u32,
    /// Far hair (seed 001) or strands everywhere.
    pub far_hair: FarHair,
    /// ε_w: the widest a thick hair may look where far hair draws it, in pixels (seed 001
    /// uses 2); within [`FAR_WIDTH_RANGE_PX`].
    pub far_width_px: f32,
    /// Fur as shells and fins (seed 002), or strands only. Not part of [`Effects::all`]:
    /// fur is another look of the hair, named on its own.
    pub fur: Fur,
    pub fur_shells: FurShells,
}

/// Gauss-Legendre point counts the shaders have.
pub const FIBRE_OFFSET_CHOICES: [u32; 3] = [1, 2, 3];

impl Default for Effects {
    fn default() -> Self {
        Self {
            shading: Shading::Marschner,
            self_shadowing: SelfShadowing::DeepOpacityMaps,
            opacity_layers: 4,
            opacity_depth_m: None,
            body_shadows: true,
            shadow_resolution: 1024,
            multiple_scattering: MultipleScattering::DualScattering,
            coverage: Coverage::Msaa,
            fibre_offsets: 3,
            far_hair: FarHair::Strands,
            far_width_px: 2.0,
            fur: Fur::Off,
            fur_shells: FurShells::default(),
        }
    }
}

/// The names of the optional effects, as `hairloom render --effects` and the Scene panel
/// use them.
pub const EFFECT_NAMES: [&str; 8] = [
    "marschner",
    "opacity-shadow-maps",
    "deep-opacity-maps",
    "body-shadows",
    "dual-scattering",
    "width-oit",
    "far-aggregated",
    "fur",
];

impl Effects {
    /// Every optional effect off: Kajiya-Kay, no shadows, no multiple scattering, MSAA (the
    /// picture before scenes existed). Map sizes are kept.
    pub fn none(&self) -> Self {
        Self {
            shading: Shading::KajiyaKay,
            self_shadowing: SelfShadowing::None,
            body_shadows: false,
            multiple_scattering: MultipleScattering::None,
            coverage: Coverage::Msaa,
            far_hair: FarHair::Strands,
            fur: Fur::Off,
            ..self.clone()
        }
    }

    /// Every effect of hair on, deep opacity maps for self-shadowing (fur stays as it is: it
    /// is another look, not an accuracy switch).
    pub fn all(&self) -> Self {
        Self {
            shading: Shading::Marschner,
            self_shadowing: SelfShadowing::DeepOpacityMaps,
            body_shadows: true,
            multiple_scattering: MultipleScattering::DualScattering,
            coverage: Coverage::WidthOit,
            far_hair: FarHair::Aggregated,
            ..self.clone()
        }
    }

    /// The names (from [`EFFECT_NAMES`]) of the effects that are on.
    pub fn names(&self) -> Vec<&'static str> {
        let mut names = Vec::new();
        if self.shading == Shading::Marschner {
            names.push("marschner");
        }
        match self.self_shadowing {
            SelfShadowing::None => {}
            SelfShadowing::OpacityShadowMaps => names.push("opacity-shadow-maps"),
            SelfShadowing::DeepOpacityMaps => names.push("deep-opacity-maps"),
        }
        if self.body_shadows {
            names.push("body-shadows");
        }
        if self.multiple_scattering == MultipleScattering::DualScattering {
            names.push("dual-scattering");
        }
        if self.coverage == Coverage::WidthOit {
            names.push("width-oit");
        }
        if self.far_hair == FarHair::Aggregated {
            names.push("far-aggregated");
        }
        if self.fur == Fur::ShellsFins {
            names.push("fur");
        }
        names
    }

    /// `none`, `all` or a comma-separated list of [`EFFECT_NAMES`]: exactly those effects on,
    /// the others off, map sizes from `self`.
    pub fn parse_list(&self, list: &str) -> Result<Self, String> {
        match list.trim() {
            "none" => return Ok(self.none()),
            "all" => return Ok(self.all()),
            _ => {}
        }
        let mut effects = self.none();
        for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            match name {
                "marschner" => effects.shading = Shading::Marschner,
                "kajiya-kay" => effects.shading = Shading::KajiyaKay,
                "opacity-shadow-maps" | "deep-opacity-maps"
                    if effects.self_shadowing != SelfShadowing::None =>
                {
                    return Err(format!(
                        "--effects: {name} and {} are two kinds of self-shadowing; name one",
                        effects
                            .names()
                            .iter()
                            .find(|n| n.contains("opacity"))
                            .copied()
                            .unwrap_or("")
                    ));
                }
                "opacity-shadow-maps" => effects.self_shadowing = SelfShadowing::OpacityShadowMaps,
                "deep-opacity-maps" => effects.self_shadowing = SelfShadowing::DeepOpacityMaps,
                "body-shadows" => effects.body_shadows = true,
                "dual-scattering" => {
                    effects.multiple_scattering = MultipleScattering::DualScattering
                }
                "width-oit" => effects.coverage = Coverage::WidthOit,
                "far-aggregated" => effects.far_hair = FarHair::Aggregated,
                "fur" => effects.fur = Fur::ShellsFins,
                other => {
                    return Err(format!(
                        "--effects: unknown effect {other:?}; the effects are none, all, {}",
                        EFFECT_NAMES.join(", ")
                    ));
                }
            }
        }
        Ok(effects)
    }

    /// Whether the scene needs shadow passes for its shadow-casting lights.
    pub fn needs_shadow_maps(&self) -> bool {
        self.self_shadowing != SelfShadowing::None || self.body_shadows
    }
}

/// How a project is lit and seen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scene {
    pub lights: Vec<Light>,
    /// Uniform light from every direction (an environment), linear RGB radiance.
    pub ambient: [f32; 3],
    /// What the camera sees behind everything (not a light), linear RGB.
    pub background: [f32; 3],
    /// Scale of linear radiance before tone mapping (ACES fit, Narkowicz 2015).
    pub exposure: f32,
    pub cameras: Vec<CameraPreset>,
    pub material: HairMaterial,
    /// Diffuse albedo of the body, linear RGB.
    pub body_color: [f32; 3],
    pub effects: Effects,
    /// What moves the hair (head animation, gravity, wind) and how it is simulated; `None`
    /// is a still scene, where no simulator exists and nothing is stepped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motion: Option<Motion>,
}

impl Default for Scene {
    /// A key / fill / rim rig: a warm key from the front right above and a rim from behind
    /// cast shadows; a cool fill from the left does not.
    fn default() -> Self {
        Self {
            lights: vec![
                Light {
                    casts_shadows: true,
                    ..Light::directional("key", [0.55, 0.75, 0.9], [1.0, 0.96, 0.9], 4.0)
                },
                Light::directional("fill", [-0.85, 0.25, 0.45], [0.75, 0.85, 1.0], 1.0),
                Light {
                    casts_shadows: true,
                    ..Light::directional("rim", [-0.2, 0.55, -1.0], [1.0, 0.97, 0.92], 2.5)
                },
            ],
            ambient: [0.08, 0.085, 0.1],
            background: [0.02, 0.022, 0.026],
            exposure: 1.0,
            cameras: vec![
                CameraPreset::new("three-quarter", [0.75, 0.25, 1.0]),
                CameraPreset::new("front", [0.0, 0.1, 1.0]),
                CameraPreset::new("side", [1.0, 0.1, 0.0]),
                CameraPreset::new("back", [0.0, 0.2, -1.0]),
                CameraPreset::new("top", [0.0, 1.0, 0.05]),
            ],
            material: HairMaterial::default(),
            body_color: [0.5, 0.35, 0.28],
            effects: Effects::default(),
            motion: None,
        }
    }
}

impl CameraPreset {
    pub fn new(name: &str, direction: [f32; 3]) -> Self {
        Self {
            name: name.into(),
            direction,
            fov_deg: 30.0,
        }
    }
}

/// A named problem in a scene: `path` is relative to the scene (`lights[1].intensity`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct InvalidScene {
    pub path: String,
    pub message: String,
}

fn invalid(path: impl Into<String>, message: impl Into<String>) -> InvalidScene {
    InvalidScene {
        path: path.into(),
        message: message.into(),
    }
}

fn check_range(path: &str, value: f32, lo: f32, hi: f32) -> Result<(), InvalidScene> {
    if !value.is_finite() {
        return Err(invalid(path, format!("{value} is not a finite number")));
    }
    if !(lo..=hi).contains(&value) {
        return Err(invalid(
            path,
            format!("{value} is outside the valid range [{lo}, {hi}]"),
        ));
    }
    Ok(())
}

fn check_color(path: &str, rgb: [f32; 3], hi: f32) -> Result<(), InvalidScene> {
    for (c, &value) in rgb.iter().enumerate() {
        check_range(&format!("{path}[{c}]"), value, 0.0, hi)?;
    }
    Ok(())
}

fn check_direction(path: &str, v: [f32; 3]) -> Result<(), InvalidScene> {
    if !v.iter().all(|c| c.is_finite()) {
        return Err(invalid(path, format!("{v:?} is not a finite direction")));
    }
    let length_squared: f32 = v.iter().map(|c| c * c).sum();
    if length_squared.is_nan() || length_squared <= 1e-12 {
        return Err(invalid(path, "a direction cannot have zero length"));
    }
    Ok(())
}

/// Largest light intensity and colour-channel values a file may hold (a sun is about 10 in
/// these units at exposure 1); larger values are typing mistakes, not lighting.
pub const MAX_INTENSITY: f32 = 10_000.0;

impl HairMaterial {
    /// This material as the scene-wide tables (dual scattering, forward transmittance, far
    /// hair, Kajiya-Kay's weights) are made from it: its own colour, no ombré. Renderers
    /// key their table caches on it, so shaping an ombré rebuilds none.
    pub fn for_tables(&self) -> HairMaterial {
        HairMaterial {
            ombre: None,
            ..self.clone()
        }
    }

    pub fn validate(&self) -> Result<(), InvalidScene> {
        let at = |field: &str| format!("material.{field}");
        match &self.pigment {
            Pigment::Melanin {
                eumelanin,
                pheomelanin,
            } => {
                check_range(&at("pigment.melanin.eumelanin"), *eumelanin, 0.0, 50.0)?;
                check_range(&at("pigment.melanin.pheomelanin"), *pheomelanin, 0.0, 50.0)?;
            }
            Pigment::Color { rgb } => check_color(&at("pigment.color.rgb"), *rgb, 1.0)?,
            Pigment::Absorption { sigma_a } => {
                check_color(&at("pigment.absorption.sigma_a"), *sigma_a, 1000.0)?
            }
        }
        check_range(
            &at("longitudinal_roughness"),
            self.longitudinal_roughness,
            0.0,
            1.0,
        )?;
        check_range(
            &at("azimuthal_roughness"),
            self.azimuthal_roughness,
            0.0,
            1.0,
        )?;
        check_range(&at("cuticle_tilt_deg"), self.cuticle_tilt_deg, -20.0, 20.0)?;
        check_range(&at("ior"), self.ior, 1.0, 3.0)?;
        check_range(
            &at("tip_absorption_factor"),
            self.tip_absorption_factor,
            0.0,
            10.0,
        )?;
        check_range(
            &at("strand_absorption_variation"),
            self.strand_absorption_variation,
            0.0,
            1.0,
        )?;
        if let Some(ombre) = &self.ombre {
            check_color(&at("ombre.tip_rgb"), ombre.tip_rgb, 1.0)?;
            check_range(&at("ombre.start"), ombre.start, 0.0, 1.0)?;
            check_range(
                &at("ombre.end"),
                ombre.end,
                ombre.start.clamp(0.0, 1.0),
                1.0,
            )?;
        }
        Ok(())
    }
}

impl Effects {
    pub fn validate(&self) -> Result<(), InvalidScene> {
        if !FIBRE_OFFSET_CHOICES.contains(&self.fibre_offsets) {
            return Err(invalid(
                "effects.fibre_offsets",
                format!(
                    "{} offsets are not supported; choose {:?}",
                    self.fibre_offsets, FIBRE_OFFSET_CHOICES
                ),
            ));
        }
        if !OPACITY_LAYER_CHOICES.contains(&self.opacity_layers) {
            return Err(invalid(
                "effects.opacity_layers",
                format!(
                    "{} layers are not supported; choose {:?}",
                    self.opacity_layers, OPACITY_LAYER_CHOICES
                ),
            ));
        }
        if let Some(depth) = self.opacity_depth_m {
            check_range("effects.opacity_depth_m", depth, 1e-6, 1e3)?;
        }
        let (lo, hi) = FAR_WIDTH_RANGE_PX;
        check_range("effects.far_width_px", self.far_width_px, lo, hi)?;
        self.fur_shells.validate()?;
        let (lo, hi) = SHADOW_RESOLUTION_RANGE;
        if !(lo..=hi).contains(&self.shadow_resolution) {
            return Err(invalid(
                "effects.shadow_resolution",
                format!(
                    "{} texels is outside the valid range [{lo}, {hi}]",
                    self.shadow_resolution
                ),
            ));
        }
        Ok(())
    }
}

impl Scene {
    /// Checks every value; the error names the field (`lights[0].source.directional.to_light`).
    pub fn validate(&self) -> Result<(), InvalidScene> {
        if self.lights.len() > MAX_LIGHTS {
            return Err(invalid(
                "lights",
                format!(
                    "{} lights are more than the {MAX_LIGHTS} a scene may hold",
                    self.lights.len()
                ),
            ));
        }
        for (i, light) in self.lights.iter().enumerate() {
            let at = |field: &str| format!("lights[{i}].{field}");
            match light.source {
                LightSource::Directional { to_light } => {
                    check_direction(&at("source.directional.to_light"), to_light)?
                }
                LightSource::Point { position_m } => {
                    if !position_m.iter().all(|c| c.is_finite()) {
                        return Err(invalid(
                            at("source.point.position_m"),
                            format!("{position_m:?} is not a finite position"),
                        ));
                    }
                }
            }
            check_color(&at("color"), light.color, 1.0)?;
            check_range(&at("intensity"), light.intensity, 0.0, MAX_INTENSITY)?;
        }
        let shadowed = self.lights.iter().filter(|l| l.casts_shadows).count();
        if shadowed > MAX_SHADOWED_LIGHTS {
            return Err(invalid(
                "lights",
                format!(
                    "{shadowed} lights cast shadows; at most {MAX_SHADOWED_LIGHTS} may (each costs its own shadow passes)"
                ),
            ));
        }
        check_color("ambient", self.ambient, MAX_INTENSITY)?;
        check_color("background", self.background, 1.0)?;
        check_range("exposure", self.exposure, 1e-3, 1e3)?;
        for (i, camera) in self.cameras.iter().enumerate() {
            check_direction(&format!("cameras[{i}].direction"), camera.direction)?;
            check_range(&format!("cameras[{i}].fov_deg"), camera.fov_deg, 1.0, 170.0)?;
        }
        self.material.validate()?;
        check_color("body_color", self.body_color, 1.0)?;
        self.effects.validate()?;
        match &self.motion {
            Some(motion) => motion.validate(),
            None => Ok(()),
        }
    }

    /// The lights that cast shadows, in order (at most [`MAX_SHADOWED_LIGHTS`] in a valid
    /// scene): each one's index in [`Self::lights`].
    pub fn shadowed_lights(&self) -> Vec<usize> {
        (0..self.lights.len())
            .filter(|&i| self.lights[i].casts_shadows)
            .take(MAX_SHADOWED_LIGHTS)
            .collect()
    }

    /// The camera preset called `name`.
    pub fn camera(&self, name: &str) -> Option<&CameraPreset> {
        self.cameras.iter().find(|c| c.name == name)
    }

    /// This scene with its lights turned by `angle_rad` about the vertical (y) axis through
    /// `centre`: with the camera turned as much, the model seems to turn on a turntable
    /// under studio lights that stay where they were relative to the camera.
    pub fn lights_turned(&self, angle_rad: f64, centre: glam::DVec3) -> Scene {
        let turn = glam::DQuat::from_rotation_y(angle_rad);
        let mut scene = self.clone();
        for light in &mut scene.lights {
            light.source = match light.source {
                LightSource::Directional { to_light } => LightSource::Directional {
                    to_light: (turn * glam::Vec3::from(to_light).as_dvec3())
                        .as_vec3()
                        .to_array(),
                },
                LightSource::Point { position_m } => LightSource::Point {
                    position_m: (centre
                        + turn * (glam::Vec3::from(position_m).as_dvec3() - centre))
                        .as_vec3()
                        .to_array(),
                },
            };
        }
        scene
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turned_lights_keep_their_place_relative_to_a_turned_camera() {
        let mut scene = Scene::default();
        scene.lights.push(Light {
            name: "bulb".into(),
            source: LightSource::Point {
                position_m: [1.0, 2.0, 0.0],
            },
            color: [1.0; 3],
            intensity: 1.0,
            casts_shadows: false,
        });
        let centre = glam::DVec3::new(1.0, 0.0, -1.0);
        let quarter = scene.lights_turned(std::f64::consts::FRAC_PI_2, centre);
        for (before, after) in scene.lights.iter().zip(&quarter.lights) {
            // A quarter turn about y takes x to −z and z to x, heights kept.
            match (&before.source, &after.source) {
                (
                    LightSource::Directional { to_light: a },
                    LightSource::Directional { to_light: b },
                ) => {
                    let expected = [a[2], a[1], -a[0]];
                    for (got, want) in b.iter().zip(expected) {
                        assert!((got - want).abs() < 1e-6, "{a:?} → {b:?}");
                    }
                }
                (LightSource::Point { position_m: a }, LightSource::Point { position_m: b }) => {
                    // (1, 2, 0) is (0, 2, 1) from the centre: a quarter turn makes it (1, 2, 0)
                    // from the centre, (2, 2, −1) in the scene.
                    assert_eq!(*a, [1.0, 2.0, 0.0]);
                    for (got, want) in b.iter().zip([2.0, 2.0, -1.0]) {
                        assert!((got - want).abs() < 1e-6, "{b:?}");
                    }
                }
                _ => panic!("a light changed its kind"),
            }
        }
        // A whole turn is no turn; nothing else of the scene changes.
        let whole = scene.lights_turned(std::f64::consts::TAU, centre);
        assert_eq!(whole.effects, scene.effects);
        assert_eq!(whole.cameras, scene.cameras);
        assert_eq!(scene.lights_turned(0.0, centre), scene);
    }

    #[test]
    fn the_default_scene_is_valid_and_round_trips_through_json() {
        let scene = Scene::default();
        scene.validate().expect("default scene");
        let json = serde_json::to_string(&scene).expect("serialise");
        let back: Scene = serde_json::from_str(&json).expect("parse");
        assert_eq!(back, scene);
        assert_eq!(scene.shadowed_lights(), vec![0, 2]);
    }

    #[test]
    fn bad_values_are_refused_with_the_field_named() {
        type Change = Box<dyn Fn(&mut Scene)>;
        let cases: Vec<(Change, &str)> = vec![
            (
                Box::new(|s| s.material.longitudinal_roughness = -0.1),
                "material.longitudinal_roughness",
            ),
            (
                Box::new(|s| {
                    s.lights[1].source = LightSource::Directional {
                        to_light: [f32::NAN, 1.0, 0.0],
                    }
                }),
                "lights[1].source.directional.to_light",
            ),
            (
                Box::new(|s| s.lights[0].source = LightSource::Directional { to_light: [0.0; 3] }),
                "lights[0].source.directional.to_light",
            ),
            (
                Box::new(|s| s.effects.shadow_resolution = 1 << 20),
                "effects.shadow_resolution",
            ),
            (
                Box::new(|s| s.effects.opacity_layers = 5),
                "effects.opacity_layers",
            ),
            (
                Box::new(|s| s.lights[2].intensity = f32::INFINITY),
                "lights[2].intensity",
            ),
            (Box::new(|s| s.material.ior = 0.5), "material.ior"),
            (
                Box::new(|s| {
                    s.material.pigment = Pigment::Color {
                        rgb: [0.5, 1.5, 0.2],
                    }
                }),
                "material.pigment.color.rgb[1]",
            ),
            (Box::new(|s| s.lights[1].casts_shadows = true), "lights"),
            (
                Box::new(|s| s.lights = vec![s.lights[1].clone(); MAX_LIGHTS + 1]),
                "lights",
            ),
            (Box::new(|s| s.exposure = 0.0), "exposure"),
            (
                Box::new(|s| s.cameras[0].fov_deg = 180.0),
                "cameras[0].fov_deg",
            ),
            (
                Box::new(|s| s.effects.far_width_px = f32::NAN),
                "effects.far_width_px",
            ),
            (
                Box::new(|s| s.effects.far_width_px = 0.0),
                "effects.far_width_px",
            ),
            (
                Box::new(|s| s.effects.fur_shells.shell_count = 12),
                "effects.fur_shells.shell_count",
            ),
            (
                Box::new(|s| s.effects.fur_shells.shell_resolution = u32::MAX),
                "effects.fur_shells.shell_resolution",
            ),
            (
                Box::new(|s| s.effects.fur_shells.tile_width_m = Some(f32::INFINITY)),
                "effects.fur_shells.tile_width_m",
            ),
            (
                Box::new(|s| s.effects.fur_shells.strands_above_px = 1.0),
                "effects.fur_shells.strands_above_px",
            ),
            (
                Box::new(|s| {
                    s.material.ombre = Some(Ombre {
                        tip_rgb: [0.5, f32::NAN, 0.2],
                        ..Ombre::default()
                    })
                }),
                "material.ombre.tip_rgb[1]",
            ),
            (
                Box::new(|s| {
                    s.material.ombre = Some(Ombre {
                        tip_rgb: [0.5, 0.2, 1.5],
                        ..Ombre::default()
                    })
                }),
                "material.ombre.tip_rgb[2]",
            ),
            (
                Box::new(|s| {
                    s.material.ombre = Some(Ombre {
                        end: 1.01,
                        ..Ombre::default()
                    })
                }),
                "material.ombre.end",
            ),
            (
                Box::new(|s| {
                    s.material.ombre = Some(Ombre {
                        start: -0.1,
                        ..Ombre::default()
                    })
                }),
                "material.ombre.start",
            ),
            (
                Box::new(|s| {
                    s.material.ombre = Some(Ombre {
                        start: 0.6,
                        end: 0.3,
                        ..Ombre::default()
                    })
                }),
                "material.ombre.end",
            ),
        ];
        for (change, path) in cases {
            let mut scene = Scene::default();
            change(&mut scene);
            let error = scene.validate().expect_err(path);
            assert_eq!(error.path, path, "{error}");
        }
    }

    #[test]
    fn effect_lists_parse_by_name() {
        let effects = Effects::default();
        assert_eq!(
            effects.parse_list("none").expect("none").names(),
            Vec::<&str>::new()
        );
        assert_eq!(
            effects.parse_list("all").expect("all").names(),
            vec![
                "marschner",
                "deep-opacity-maps",
                "body-shadows",
                "dual-scattering",
                "width-oit",
                "far-aggregated"
            ]
        );
        let some = effects
            .parse_list("marschner, opacity-shadow-maps")
            .expect("two");
        assert_eq!(some.names(), vec!["marschner", "opacity-shadow-maps"]);
        assert_eq!(some.shadow_resolution, effects.shadow_resolution);
        let unknown = effects.parse_list("marschner,bloom").expect_err("bloom");
        assert!(unknown.contains("\"bloom\""), "{unknown}");
        let both = effects
            .parse_list("opacity-shadow-maps,deep-opacity-maps")
            .expect_err("two kinds");
        assert!(both.contains("two kinds"), "{both}");
        for name in EFFECT_NAMES {
            assert_eq!(effects.parse_list(name).expect(name).names(), vec![name]);
        }
    }
}
