//! The renderers a frame is made of, kept between frames: the ones every frame has (scene
//! lighting, hair ribbons, body) and the effect renderers, which exist only while the scene's
//! effects name them.

use hairloom_core::model::scene::{FarHair, Scene, SelfShadowing};
use hairloom_core::runtime::far_lod::FarLodParams;
use hairloom_core::runtime::frame_plan::FramePlan;

use super::{FrameCamera, FrameError, FrameRenderer, HairSource, Phase};
use crate::device::GpuContext;
use crate::renderer::Targets;
use crate::renderer::body_shadow::BodyShadowRenderer;
use crate::renderer::far_hair::FarHairRenderer;
use crate::renderer::fur::FurRenderer;
use crate::renderer::hair_shadow::HairShadowRenderer;
use crate::renderer::oit_composite::OitRenderer;
use crate::renderer::preview_body::BodyRenderer;
use crate::renderer::preview_hair::{HairRenderer, RibbonInput};
use crate::renderer::scene_lighting::{ActiveEffects, SceneLighting, binding, effects_layout};

/// Which group-2 layout the lit shaders were made against.
type EffectsLayoutKey = (SelfShadowing, bool, bool, bool);

/// One renderer per feature, made for the targets they draw into.
pub struct FrameRenderers {
    pub(crate) lighting: SceneLighting,
    pub(crate) hair: HairRenderer,
    pub(crate) body: BodyRenderer,
    /// The group-2 layout of the lit shaders, for the effects that make it up.
    effects_layout: Option<(EffectsLayoutKey, Option<wgpu::BindGroupLayout>)>,
    pub(crate) hair_shadow: Option<HairShadowRenderer>,
    pub(crate) body_shadow: Option<BodyShadowRenderer>,
    pub(crate) oit: Option<OitRenderer>,
    pub(crate) far_hair: Option<FarHairRenderer>,
    pub(crate) fur: Option<FurRenderer>,
    /// Far hair: the level each bundle draws next frame (eq. 16's choice from the widths
    /// measured in the last; empty until a frame of far hair is planned).
    pub(crate) far_levels: Vec<u32>,
    targets: Targets,
    /// What the last [`Self::sync`] made them for.
    pub(crate) active: ActiveEffects,
    /// The material's mean forward transmittance per fibre (shadows use it).
    pub(crate) mean_forward: [f32; 3],
}

impl FrameRenderers {
    /// The renderers every frame has, for `targets`; effects come with [`Self::sync`].
    pub fn new(context: &GpuContext, targets: Targets) -> Self {
        Self {
            lighting: SceneLighting::new(context),
            hair: HairRenderer::with_targets(context, targets),
            body: BodyRenderer::with_targets(context, targets),
            effects_layout: None,
            hair_shadow: None,
            body_shadow: None,
            oit: None,
            far_hair: None,
            fur: None,
            far_levels: Vec::new(),
            targets,
            active: ActiveEffects::none(),
            mean_forward: [1.0; 3],
        }
    }

    pub fn targets(&self) -> Targets {
        self.targets
    }

    /// Makes what `active` needs for `scene` with ribbons fed by `input`, and frees what it
    /// does not. Cheap when nothing changed.
    pub fn sync(
        &mut self,
        context: &GpuContext,
        active: &ActiveEffects,
        scene: &Scene,
        input: RibbonInput,
    ) {
        // The tables are the material's own colour: an ombré changes none of them.
        let tables_material = scene.material.for_tables();
        self.mean_forward = self.lighting.sync(context, active, &tables_material);
        let layout_key = (
            active.opacity_maps,
            active.body_shadows,
            active.dual_scattering,
            active.far_hair,
        );
        if self
            .effects_layout
            .as_ref()
            .is_none_or(|(key, _)| *key != layout_key)
        {
            self.effects_layout = Some((layout_key, effects_layout(context, active)));
            // Pipelines made with the old layout go with it.
            self.hair = HairRenderer::with_targets(context, self.targets);
            self.body = BodyRenderer::with_targets(context, self.targets);
            if let Some(far) = &mut self.far_hair {
                far.forget_pipelines();
            }
            if let Some(fur) = &mut self.fur {
                fur.forget_pipelines();
            }
        }
        let effects_layout = self.effects_layout.as_ref().and_then(|(_, l)| l.as_ref());
        self.hair.ensure(
            context,
            active,
            &self.lighting.scene_layout,
            effects_layout,
            input,
        );
        self.body.ensure(
            context,
            active.shader_key(),
            &self.lighting.scene_layout,
            effects_layout,
        );
        let slots = active.shadow_slots;
        self.hair_shadow = if active.opacity_maps != SelfShadowing::None && slots > 0 {
            match self.hair_shadow.take() {
                Some(kept)
                    if kept.fits(
                        active.opacity_maps,
                        active.opacity_layers,
                        active.shadow_resolution,
                        slots,
                        input,
                    ) =>
                {
                    Some(kept)
                }
                // The old maps are freed before the new ones are made.
                _ => Some(HairShadowRenderer::new(
                    context,
                    &self.hair,
                    &self.lighting.scene_layout,
                    active.opacity_maps,
                    active.opacity_layers,
                    active.shadow_resolution,
                    slots,
                    input,
                )),
            }
        } else {
            None
        };
        self.body_shadow = if active.body_shadows && slots > 0 {
            match self.body_shadow.take() {
                Some(kept)
                    if (kept.resolution, kept.slots) == (active.shadow_resolution, slots) =>
                {
                    Some(kept)
                }
                _ => Some(BodyShadowRenderer::new(
                    context,
                    &self.body,
                    active.shadow_resolution,
                    slots,
                )),
            }
        } else {
            None
        };
        self.oit = if active.width_oit {
            self.oit
                .take()
                .or_else(|| Some(OitRenderer::new(context, self.targets.sample_count)))
        } else {
            None
        };
        if active.far_hair {
            let far = self.far_hair.get_or_insert_with(|| {
                FarHairRenderer::new(context, self.targets, &tables_material)
            });
            let effects_layout = self.effects_layout.as_ref().and_then(|(_, l)| l.as_ref());
            far.ensure(
                context,
                active,
                &tables_material,
                &self.lighting.scene_layout,
                effects_layout,
            );
            match &self.hair_shadow {
                Some(hair_shadow) => {
                    far.ensure_shadows(context, hair_shadow, &self.lighting.scene_layout)
                }
                None => far.forget_shadow_pipelines(),
            }
        } else {
            self.far_hair = None;
            self.far_levels.clear();
        }
        if active.fur {
            let fur = self
                .fur
                .get_or_insert_with(|| FurRenderer::new(context, self.targets));
            let effects_layout = self.effects_layout.as_ref().and_then(|(_, l)| l.as_ref());
            fur.ensure(context, active, &self.lighting.scene_layout, effects_layout);
        } else {
            self.fur = None;
        }
        self.active = *active;
    }

    /// The far-hair level of every bundle for a frame of `scene` seen by `camera` with `hair`
    /// (empty: strands everywhere, when the scene draws no far hair or the hair has no
    /// hierarchy): the choice the last frame measured ([`Self::advance_far_levels`]), or,
    /// with none, the first guess from the stored widths. Plan the frame with these.
    pub fn far_levels(
        &mut self,
        scene: &Scene,
        hair: &HairSource,
        camera: &FrameCamera,
    ) -> Vec<u32> {
        let HairSource::Generated {
            hair,
            far: Some(far),
            ..
        } = hair
        else {
            self.far_levels.clear();
            return Vec::new();
        };
        if scene.effects.far_hair != FarHair::Aggregated {
            self.far_levels.clear();
            return Vec::new();
        }
        let blocks = &far.table.blocks;
        if self.far_levels.len() != blocks.len() {
            self.far_levels = FarHairRenderer::first_levels(
                far,
                &hair.bundles,
                &far_lod_params(scene, camera, 0),
            );
        }
        // A hair made again may have fewer levels in a bundle than it drew.
        for (level, block) in self.far_levels.iter_mut().zip(blocks) {
            *level = (*level).min(block.len() as u32);
        }
        self.far_levels.clone()
    }

    /// Eq. 16 after a frame planned as `plan` of `scene` from `camera`: the widths of the
    /// thick hairs it drew (and the next coarser ones), measured on the GPU at
    /// `vertex_count` vertices, choose each bundle's level for the next frame.
    pub fn advance_far_levels(
        &mut self,
        context: &GpuContext,
        scene: &Scene,
        hair: &HairSource,
        camera: &FrameCamera,
        vertex_count: u32,
        plan: &FramePlan,
    ) -> Result<(), FrameError> {
        let (
            Some(renderer),
            HairSource::Generated {
                generator,
                hair,
                far: Some(far),
                ..
            },
        ) = (&self.far_hair, hair)
        else {
            return Ok(());
        };
        if plan.far_levels.is_empty() {
            return Ok(());
        }
        self.far_levels = renderer
            .next_levels(
                context,
                generator,
                hair,
                far,
                &plan.far_levels,
                far_lod_params(scene, camera, vertex_count),
            )
            .map_err(FrameError::Generation)?;
        Ok(())
    }

    fn effects_layout(&self) -> Option<&wgpu::BindGroupLayout> {
        self.effects_layout.as_ref().and_then(|(_, l)| l.as_ref())
    }

    /// The group-2 bind group of the lit shaders over the effect renderers that exist;
    /// `None` when the shaders take no group 2.
    pub(crate) fn effects_group(&self, context: &GpuContext) -> Option<wgpu::BindGroup> {
        let layout = self.effects_layout()?;
        let mut entries = Vec::new();
        let view = |binding, view| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        };
        if let Some(hair_shadow) = &self.hair_shadow {
            entries.push(view(binding::OPACITY_LAYERS, &hair_shadow.opacity_view));
            if let Some(first_hair) = hair_shadow.first_hair_view() {
                entries.push(view(binding::FIRST_HAIR_DEPTH, first_hair));
            }
        }
        if let Some(body_shadow) = &self.body_shadow {
            entries.push(view(binding::BODY_DEPTH, &body_shadow.array_view));
            entries.push(wgpu::BindGroupEntry {
                binding: binding::BODY_DEPTH_SAMPLER,
                resource: wgpu::BindingResource::Sampler(&self.lighting.depth_sampler),
            });
        }
        if let Some(ds) = &self.lighting.dual_scattering {
            entries.push(wgpu::BindGroupEntry {
                binding: binding::TABLE_SAMPLER,
                resource: wgpu::BindingResource::Sampler(&self.lighting.table_sampler),
            });
            entries.push(view(binding::DS_PROFILE, &ds.profile_view));
            entries.push(view(binding::DS_LOBES, &ds.lobes_view));
        }
        if let Some(far) = &self.far_hair {
            entries.push(wgpu::BindGroupEntry {
                binding: binding::AGG_TABLES,
                resource: far.tables().as_entire_binding(),
            });
        }
        Some(
            context
                .device
                .create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("effects"),
                    layout,
                    entries: &entries,
                }),
        )
    }

    /// Every renderer that exists now, with the phases it takes part in, in the order they
    /// were made (what a frame of the last synced scene records).
    pub fn participants(&self) -> Vec<(&'static str, &'static [Phase])> {
        let mut all: Vec<&dyn FrameRenderer> = vec![&self.lighting, &self.body, &self.hair];
        if let Some(r) = &self.hair_shadow {
            all.push(r);
        }
        if let Some(r) = &self.body_shadow {
            all.push(r);
        }
        if let Some(r) = &self.oit {
            all.push(r);
        }
        if let Some(r) = &self.far_hair {
            all.push(r);
        }
        if let Some(r) = &self.fur {
            all.push(r);
        }
        all.iter().map(|r| (r.name(), r.phases())).collect()
    }

    /// The phases a frame records now, in order.
    pub fn phases(&self) -> Vec<Phase> {
        let named: Vec<Phase> = self
            .participants()
            .iter()
            .flat_map(|(_, phases)| phases.iter().copied())
            .collect();
        Phase::ORDER
            .into_iter()
            .filter(|phase| named.contains(phase))
            .collect()
    }
}

/// The level choice's parameters for `scene` seen by `camera`.
fn far_lod_params(scene: &Scene, camera: &FrameCamera, vertex_count: u32) -> FarLodParams {
    FarLodParams {
        eye: camera.eye.extend(1.0).to_array(),
        pixel_at_unit: camera.pixel_at_unit(),
        width_threshold_px: scene.effects.far_width_px,
        vertex_count,
        count: 0,
    }
}

impl FrameRenderer for SceneLighting {
    fn name(&self) -> &'static str {
        "scene lighting"
    }
    fn phases(&self) -> &'static [Phase] {
        // Its uniforms and tables are read by every lit pass; it records none of its own.
        &[]
    }
}

impl FrameRenderer for BodyRenderer {
    fn name(&self) -> &'static str {
        "body"
    }
    fn phases(&self) -> &'static [Phase] {
        &[Phase::Opaque]
    }
}

impl FrameRenderer for HairRenderer {
    fn name(&self) -> &'static str {
        "hair ribbons"
    }
    fn phases(&self) -> &'static [Phase] {
        &[Phase::DepthPrePass, Phase::Lit]
    }
}

impl FrameRenderer for HairShadowRenderer {
    fn name(&self) -> &'static str {
        "hair shadows"
    }
    fn phases(&self) -> &'static [Phase] {
        &[Phase::ShadowViews]
    }
}

impl FrameRenderer for BodyShadowRenderer {
    fn name(&self) -> &'static str {
        "body shadows"
    }
    fn phases(&self) -> &'static [Phase] {
        &[Phase::ShadowViews]
    }
}

impl FrameRenderer for OitRenderer {
    fn name(&self) -> &'static str {
        "width coverage"
    }
    fn phases(&self) -> &'static [Phase] {
        &[Phase::Coverage, Phase::Composite]
    }
}

impl FrameRenderer for FurRenderer {
    fn name(&self) -> &'static str {
        "fur"
    }
    fn phases(&self) -> &'static [Phase] {
        &[Phase::Fur]
    }
}

impl FrameRenderer for FarHairRenderer {
    fn name(&self) -> &'static str {
        "far hair"
    }
    fn phases(&self) -> &'static [Phase] {
        if self.draws_shadows() {
            &[
                Phase::Generation,
                Phase::ShadowViews,
                Phase::DepthPrePass,
                Phase::Lit,
            ]
        } else {
            &[Phase::Generation, Phase::DepthPrePass, Phase::Lit]
        }
    }
}
