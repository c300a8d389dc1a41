//! Painting the viewport: uploading the hair when the document changed (styling-only
//! changes in place), and drawing the frame on the GPU into the preview's kept view.

use super::*;

impl Viewport {
    /// The quality of the next frame: full unless the artist is interacting and the full
    /// picture is over [`FRAME_BUDGET_MS`]. Learns from the last timed frame: a full frame's
    /// time decides whether to degrade, an interactive frame's time adapts the scale.
    fn frame_quality(
        &mut self,
        ui: &egui::Ui,
        state: &EditorState,
        size: [u32; 2],
        settings: ViewSettings,
    ) -> FrameQuality {
        let timed = self.frame_quality.lock().ok().and_then(|mut q| q.take());
        if let (Some(quality), Some(ms)) = (timed, self.frame_ms()) {
            match quality {
                FrameQuality::Full => self.full_frame_ms = Some(ms),
                FrameQuality::Interactive { scale } => {
                    // Pixels go as the square of the scale; move halfway toward the budget.
                    let ideal = scale * (FRAME_BUDGET_MS / ms.max(1e-3)).sqrt() as f32;
                    self.interactive_scale = (0.5 * (scale + ideal)).clamp(0.2, 1.0);
                }
            }
        }
        let content = (state.shown_revision(), settings, self.orbit, size);
        let changed = self
            .drawn
            .is_none_or(|d| (d.revision, d.settings, d.orbit, d.size) != content);
        let now = std::time::Instant::now();
        if changed {
            self.last_change = Some(now);
        }
        let interacting = state.edit_open()
            || self.transform.is_some()
            || ui.input(|i| i.pointer.any_down() || i.smooth_scroll_delta != egui::Vec2::ZERO)
            || self
                .last_change
                .is_some_and(|t| now.duration_since(t) < SETTLE);
        let over_budget = self.full_frame_ms.is_some_and(|ms| ms > FRAME_BUDGET_MS);
        if interacting && over_budget {
            // Come back for the full picture once input is still.
            ui.ctx().request_repaint_after(SETTLE);
            FrameQuality::Interactive {
                scale: self.interactive_scale,
            }
        } else {
            FrameQuality::Full
        }
    }

    /// Generates and draws the strands when the document, settings, view or size changed.
    pub(super) fn draw(&mut self, ui: &mut egui::Ui, state: &mut EditorState, rect: egui::Rect) {
        let problem = self.device_problem.lock().ok().and_then(|p| p.clone());
        if let Some(problem) = problem {
            // Nothing more is drawn on a device in this state; the document is untouched
            // and can still be saved and exported.
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                format!("{problem}\nSave your work and restart Hairloom to draw again."),
                egui::FontId::proportional(14.0),
                ui.visuals().error_fg_color,
            );
            self.error = Some(problem);
            return;
        }
        if self.gpu.is_none() {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "No GPU device: the viewport is off (hairloom render still works)",
                egui::FontId::proportional(14.0),
                ui.visuals().weak_text_color(),
            );
            return;
        }
        // The overlay does not change the picture: leave it out of what triggers GPU work.
        let settings = ViewSettings {
            wireframe: false,
            frame_glyphs: false,
            gizmo: false,
            ..self.settings
        };
        let pixels_per_point = ui.ctx().pixels_per_point();
        let full_size = [
            ((rect.width() * pixels_per_point).round() as u32).clamp(1, 8192),
            ((rect.height() * pixels_per_point).round() as u32).clamp(1, 8192),
        ];
        let quality = self.frame_quality(ui, state, full_size, settings);
        let size = match quality {
            FrameQuality::Full => full_size,
            FrameQuality::Interactive { scale } => {
                full_size.map(|side| ((side as f32 * scale).round() as u32).max(1))
            }
        };
        let Some(gpu) = self.gpu.as_mut() else {
            return;
        };
        let key = (state.shown_revision(), settings);
        if self.uploaded != Some(key) {
            let document = state.shown_document();
            // A styling-only change (same hair mesh, body and view settings) rewrites the
            // styling buffers in place: no texture rebuild, no re-upload.
            let restyle = match (&mut gpu.hair, self.uploaded) {
                (Some(uploaded), Some((_, uploaded_settings)))
                    if uploaded_settings == settings
                        && uploaded.mesh == document.hair_mesh
                        && uploaded.hair.body == document.body =>
                {
                    uploaded.hair.set_styling(&document.styling);
                    gpu.generator
                        .update_styling(&gpu.context, &mut uploaded.gpu, &uploaded.hair);
                    true
                }
                _ => false,
            };
            if restyle {
                self.uploads.styling += 1;
            } else {
                let hair = RuntimeHair::from_document(
                    document,
                    &RuntimeOptions {
                        precision: self.settings.precision,
                        strands_per_bundle: self.settings.strands_per_bundle,
                        ..RuntimeOptions::default()
                    },
                );
                // Above the adapter's limits nothing is uploaded and the viewport says
                // which limit; the document is untouched (undo the edit, or save it).
                self.upload_error = None;
                gpu.hair = match (
                    hair.textures.hair_bounds(),
                    gpu.generator.upload(&gpu.context, &hair),
                ) {
                    (Some(bounds), Ok(uploaded)) => Some(UploadedHair {
                        gpu: uploaded,
                        body: GpuBody::upload(&gpu.context, &hair.body),
                        bounds,
                        hair,
                        mesh: document.hair_mesh.clone(),
                    }),
                    (_, Err(error)) => {
                        self.upload_error = Some(format!("cannot draw this hair: {error}"));
                        None
                    }
                    (None, Ok(_)) => None,
                };
                self.uploads.full += 1;
            }
            self.uploaded = Some(key);
            self.drawn = None;
        }
        let drawn = DrawnKey {
            revision: state.shown_revision(),
            settings,
            orbit: self.orbit,
            size: full_size,
            quality,
        };
        if self.drawn != Some(drawn) {
            self.error = None;
            match gpu.hair.as_ref() {
                Some(hair) => {
                    if !self.framed_from_hair {
                        self.camera_bounds = Some(hair.bounds);
                        self.framed_from_hair = true;
                    }
                    let (lo, hi) = self.camera_bounds.unwrap_or(hair.bounds);
                    let document_scene = &state.document().scene;
                    let interactive_scene;
                    let lighting = match quality {
                        FrameQuality::Full => document_scene,
                        FrameQuality::Interactive { .. } => {
                            interactive_scene = hairloom_core::model::scene::Scene {
                                effects: document_scene.effects.none(),
                                ..document_scene.clone()
                            };
                            &interactive_scene
                        }
                    };
                    let scene = default_scene(
                        &hair.body,
                        HairSource::Generated {
                            generator: &gpu.generator,
                            hair: &hair.gpu,
                            filtering: self.settings.filtering,
                            lod: self.settings.lod,
                        },
                        17,
                        hair.bounds,
                        self.orbit.camera(lo, hi),
                        lighting,
                    );
                    let plan = gpu.preview.plan(&scene, size[0], size[1]);
                    self.drawn_strands = plan.strands;
                    self.drawn_vertices = plan.vertices;
                    let started = std::time::Instant::now();
                    let rendered =
                        gpu.preview
                            .render_texture(&gpu.context, &scene, &plan, size[0], size[1]);
                    // The status bar says what generating and drawing this frame cost, from
                    // submission to the GPU finishing it, without waiting here: egui's own
                    // submission on the same queue orders the texture before its use.
                    let (frame_ms, timed_quality, ctx) = (
                        Arc::clone(&self.frame_ms),
                        Arc::clone(&self.frame_quality),
                        ui.ctx().clone(),
                    );
                    gpu.context.queue.on_submitted_work_done(move || {
                        if let (Ok(mut slot), Ok(mut timed)) =
                            (frame_ms.lock(), timed_quality.lock())
                        {
                            *slot = Some(started.elapsed().as_secs_f64() * 1e3);
                            *timed = Some(quality);
                        }
                        ctx.request_repaint(); // the status bar shows the new time
                    });
                    self.shown_quality = quality;
                    match rendered {
                        Ok(texture) => {
                            // egui composites gamma-encoded bytes: sample the sRGB image raw.
                            let view = texture.create_view(&wgpu::TextureViewDescriptor {
                                format: Some(PreviewRenderer::UI_VIEW_FORMAT),
                                ..Default::default()
                            });
                            let mut renderer = gpu.egui_renderer.write();
                            let id = match gpu.texture.take() {
                                Some((_, id)) => {
                                    renderer.update_egui_texture_from_wgpu_texture(
                                        &gpu.context.device,
                                        &view,
                                        wgpu::FilterMode::Linear,
                                        id,
                                    );
                                    id
                                }
                                None => renderer.register_native_texture(
                                    &gpu.context.device,
                                    &view,
                                    wgpu::FilterMode::Linear,
                                ),
                            };
                            gpu.texture = Some((texture, id));
                        }
                        Err(error) => self.error = Some(error.to_string()),
                    }
                }
                None => {
                    self.error = Some(
                        self.upload_error
                            .clone()
                            .unwrap_or_else(|| "no bundle grows hair".into()),
                    )
                }
            }
            self.drawn = Some(drawn);
        }
        match (&gpu.texture, &self.error) {
            (_, Some(error)) => {
                ui.painter().text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    error,
                    egui::FontId::proportional(14.0),
                    ui.visuals().error_fg_color,
                );
            }
            (Some((_, id)), None) => {
                ui.painter().image(
                    *id,
                    rect,
                    egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                    egui::Color32::WHITE,
                );
            }
            (None, None) => {}
        }
    }
}
