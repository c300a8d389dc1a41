//! The scene as every lit shader receives it: lights, shadow views, the fibre model's
//! constants, dual-scattering constants and the body's colour, in one uniform block. Built
//! here, from the document's [`Scene`], so that the CPU mirrors and the reference renderer
//! use exactly the numbers the GPU gets.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::light::dual_scattering::DualScatteringTables;
use crate::light::hair_bsdf::HairBsdf;
use crate::light::kajiya_kay::{KajiyaKayTable, KajiyaKayWeights};
use crate::light::material::Fibre;
use crate::light::opacity_maps::ShadowView;
use crate::model::scene::{
    Coverage, LightSource, MAX_LIGHTS, MAX_SHADOWED_LIGHTS, Scene, SelfShadowing, Shading,
};

/// One light. Keep in sync with `shaders/shared/scene.wgsl` (`SceneLight`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    /// xyz: unit direction toward the light (w = 0) or its position in metres (w = 1).
    pub vector: [f32; 4],
    /// rgb: colour × intensity; w: the light's shadow slot, or −1 when it casts none.
    pub radiance: [f32; 4],
    /// Kajiya-Kay's weights for this light ([`SceneUniforms::match_kajiya_kay`]; 0 under
    /// Marschner shading): rgb the tint of its diffuse and secondary lobes, w its primary
    /// highlight's weight.
    pub kajiya_kay: [f32; 4],
}

/// A shadow-casting light's view. Keep in sync with `shaders/shared/scene.wgsl` (`ShadowView`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuShadowView {
    pub view_projection: [[f32; 4]; 4],
    /// x: near, y: far (distances from the light), z: 1 for a perspective view, w: texel size.
    pub params: [f32; 4],
    /// x: the depth the opacity layers span, y: the lookup bias (metres), z, w: unused.
    pub layers: [f32; 4],
}

/// Keep in sync with `shaders/shared/scene.wgsl` (`SceneUniforms`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SceneUniforms {
    pub lights: [GpuLight; MAX_LIGHTS],
    pub shadows: [GpuShadowView; MAX_SHADOWED_LIGHTS],
    /// x: light count, y: opacity layers, z: self-shadowing (0 none, 1 opacity shadow maps,
    /// 2 deep opacity maps), w: coverage (0 MSAA, 1 width-based OIT).
    pub counts: [u32; 4],
    /// rgb: ambient radiance; w: exposure.
    pub ambient: [f32; 4],
    /// rgb: background (linear); w: unused.
    pub background: [f32; 4],
    /// rgb: absorption at the root; w: tip factor.
    pub sigma_a: [f32; 4],
    /// x: per-strand variation, y: η, z: azimuthal logistic scale s, w: β_n.
    pub fibre: [f32; 4],
    /// The longitudinal variances v_R, v_TT, v_TRT, v_residual.
    pub lobe_variance: [f32; 4],
    /// sin(2^k α) and cos(2^k α), k = 0, 1, 2 (w unused).
    pub tilt_sin: [f32; 4],
    pub tilt_cos: [f32; 4],
    /// rgb: mean forward transmittance of one fibre (shadows without dual scattering).
    pub forward_transmittance: [f32; 4],
    /// Dual scattering: each lobe's shift (xyz: R, TT, TRT) in θ_h.
    pub ds_lobe_shift: [f32; 4],
    /// Dual scattering: each lobe's variance in θ_h.
    pub ds_lobe_variance: [f32; 4],
    /// rgb: the body's albedo.
    pub body_color: [f32; 4],
    /// x: Gauss-Legendre offsets across thin fibres (1 to 3); y, z, w: 0.
    pub quality: [u32; 4],
    /// The ombré ([`crate::model::scene::Ombre`]): rgb the tip colour (linear), w 1 when
    /// the material has one (0: none, the rest unused).
    pub ombre_tip: [f32; 4],
    /// x: where the ombré starts, y: where it ends (fractions along the strand); z, w: 0.
    pub ombre_span: [f32; 4],
}

/// Deep opacity maps' default depth (the layers' span behind the first hair) as a fraction of
/// the hair's bounding-sphere diameter.
pub const DEFAULT_OPACITY_DEPTH_FRACTION: f32 = 0.15;

/// The shadow views of a scene's shadow-casting lights, framing the hair's bounding sphere.
pub fn shadow_views(scene: &Scene, center: Vec3, radius: f32) -> Vec<ShadowView> {
    scene
        .shadowed_lights()
        .into_iter()
        .map(|i| {
            ShadowView::fit(
                &scene.lights[i].source,
                center,
                radius,
                scene.effects.shadow_resolution,
            )
        })
        .collect()
}

/// The hair's bounding sphere from its box, padded a little so no strand lies on the edge of
/// a shadow view.
pub fn bounding_sphere(lo: Vec3, hi: Vec3) -> (Vec3, f32) {
    ((lo + hi) * 0.5, ((hi - lo).length() * 0.5 * 1.1).max(1e-4))
}

impl SceneUniforms {
    /// The uniforms of `scene` with its shadow `views` (from [`shadow_views`]),
    /// dual-scattering `tables` (when the material's tables exist) and the hair's bounding
    /// sphere radius (the deep opacity maps' default depth is
    /// [`DEFAULT_OPACITY_DEPTH_FRACTION`] of its diameter).
    /// `strand_width_m` sets the opacity lookups' bias (two widths: a fibre does not shadow
    /// itself).
    pub fn new(
        scene: &Scene,
        views: &[ShadowView],
        tables: Option<&DualScatteringTables>,
        mean_forward: [f32; 3],
        radius: f32,
        strand_width_m: f32,
    ) -> Self {
        let fibre = Fibre::new(&scene.material);
        let bsdf = HairBsdf::new(&fibre);
        let mut uniforms = Self::default();
        let shadowed = scene.shadowed_lights();
        for (i, light) in scene.lights.iter().take(MAX_LIGHTS).enumerate() {
            let vector = match light.source {
                LightSource::Directional { to_light } => {
                    Vec3::from(to_light).normalize_or(Vec3::Y).extend(0.0)
                }
                LightSource::Point { position_m } => Vec3::from(position_m).extend(1.0),
            };
            let slot = shadowed
                .iter()
                .position(|&s| s == i)
                .filter(|&s| s < views.len())
                .map_or(-1.0, |s| s as f32);
            uniforms.lights[i] = GpuLight {
                vector: vector.to_array(),
                radiance: [
                    light.color[0] * light.intensity,
                    light.color[1] * light.intensity,
                    light.color[2] * light.intensity,
                    slot,
                ],
                kajiya_kay: [0.0; 4],
            };
        }
        let effects = &scene.effects;
        let dom_depth = effects
            .opacity_depth_m
            .unwrap_or(DEFAULT_OPACITY_DEPTH_FRACTION * 2.0 * radius);
        for (slot, view) in views.iter().take(MAX_SHADOWED_LIGHTS).enumerate() {
            let depth = match effects.self_shadowing {
                SelfShadowing::DeepOpacityMaps => dom_depth,
                _ => view.far - view.near,
            };
            uniforms.shadows[slot] = GpuShadowView {
                view_projection: view.view_projection.to_cols_array_2d(),
                params: [
                    view.near,
                    view.far,
                    if view.perspective { 1.0 } else { 0.0 },
                    view.texel_size,
                ],
                layers: [depth, 2.0 * strand_width_m, 0.0, 0.0],
            };
        }
        uniforms.counts = [
            scene.lights.len().min(MAX_LIGHTS) as u32,
            effects.opacity_layers,
            match effects.self_shadowing {
                SelfShadowing::None => 0,
                SelfShadowing::OpacityShadowMaps => 1,
                SelfShadowing::DeepOpacityMaps => 2,
            },
            match effects.coverage {
                Coverage::Msaa => 0,
                Coverage::WidthOit => 1,
            },
        ];
        let rgb = |v: [f32; 3], w: f32| [v[0], v[1], v[2], w];
        uniforms.ambient = rgb(scene.ambient, scene.exposure);
        uniforms.background = rgb(scene.background, 0.0);
        uniforms.sigma_a = rgb(
            fibre.sigma_a_root.map(|s| s as f32),
            fibre.tip_absorption_factor as f32,
        );
        uniforms.fibre = [
            fibre.strand_absorption_variation as f32,
            bsdf.eta as f32,
            bsdf.s as f32,
            fibre.beta_n as f32,
        ];
        uniforms.lobe_variance = bsdf.v.map(|v| v as f32);
        uniforms.tilt_sin = rgb(bsdf.sin_2k_alpha.map(|v| v as f32), 0.0);
        uniforms.tilt_cos = rgb(bsdf.cos_2k_alpha.map(|v| v as f32), 0.0);
        uniforms.forward_transmittance = rgb(mean_forward, 0.0);
        if let Some(tables) = tables {
            uniforms.ds_lobe_shift = rgb(tables.lobe_shift, 0.0);
            uniforms.ds_lobe_variance = rgb(tables.lobe_variance, 0.0);
        }
        uniforms.body_color = rgb(scene.body_color, 0.0);
        uniforms.quality = [effects.fibre_offsets.clamp(1, 3), 0, 0, 0];
        if let Some(ombre) = &fibre.ombre {
            uniforms.ombre_tip = rgb(ombre.tip_rgb.map(|c| c as f32), 1.0);
            uniforms.ombre_span = [ombre.start as f32, ombre.end as f32, 0.0, 0.0];
        }
        uniforms
    }

    /// Kajiya-Kay's weights for each light of `scene` seen from `eye` at the hair's centre
    /// `hair_center`, from the material's `table` ([`KajiyaKayTable`]: the Marschner model's
    /// mean colour for the angle between this view and light); nothing when the scene shades
    /// with Marschner.
    pub fn match_kajiya_kay(
        &mut self,
        scene: &Scene,
        hair_center: Vec3,
        eye: Vec3,
        table: &KajiyaKayTable,
    ) {
        if scene.effects.shading != Shading::KajiyaKay {
            return;
        }
        let to_viewer = (eye - hair_center).as_dvec3();
        for (light, gpu) in scene.lights.iter().zip(self.lights.iter_mut()) {
            let weights = light
                .source
                .toward(hair_center.as_dvec3())
                .map_or(KajiyaKayWeights::NONE, |(to_light, _)| {
                    table.at(to_viewer, to_light)
                });
            gpu.kajiya_kay = [
                weights.tint[0] as f32,
                weights.tint[1] as f32,
                weights.tint[2] as f32,
                weights.primary as f32,
            ];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lights_know_their_shadow_slots_and_views_frame_the_hair() {
        let scene = Scene::default();
        let (center, radius) =
            bounding_sphere(Vec3::new(-0.1, 1.4, -0.1), Vec3::new(0.1, 1.8, 0.1));
        let views = shadow_views(&scene, center, radius);
        assert_eq!(views.len(), 2);
        let uniforms = SceneUniforms::new(&scene, &views, None, [0.5; 3], radius, 0.0005);
        assert_eq!(uniforms.counts[0], 3);
        let slots: Vec<f32> = uniforms
            .lights
            .iter()
            .take(3)
            .map(|l| l.radiance[3])
            .collect();
        assert_eq!(slots, vec![0.0, -1.0, 1.0]);
        for view in &uniforms.shadows {
            assert!(view.view_projection.iter().flatten().all(|v| v.is_finite()));
        }
        // A scene whose lights cast no shadows has no views and no slots.
        let mut unshadowed = scene.clone();
        unshadowed
            .lights
            .iter_mut()
            .for_each(|l| l.casts_shadows = false);
        let uniforms = SceneUniforms::new(&unshadowed, &[], None, [0.5; 3], radius, 0.0005);
        assert!(uniforms.lights.iter().take(3).all(|l| l.radiance[3] < 0.0));
    }
}
