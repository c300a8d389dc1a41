//! Painting the viewport: uploading the hair when the document changed (styling-only
//! changes in place), and drawing the frame on the GPU into the preview's kept view.

use super::*;

impl Viewport {
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
        let Some(gpu) = self.gpu.as_mut() else {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "No GPU device: the viewport is off (hairloom render still works)",
                egui::FontId::proportional(14.0),
                ui.visuals().weak_text_color(),
            );
            return;
        };
        // The overlay does not change the picture: leave it out of what triggers GPU work.
        let settings = ViewSettings {
            wireframe: false,
            frame_glyphs: false,
            gizmo: false,
            ..self.settings
        };
        let key = (state.revision, settings);
        if self.uploaded != Some(key) {
            let document = state.document();
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
        let pixels_per_point = ui.ctx().pixels_per_point();
        let size = [
            ((rect.width() * pixels_per_point).round() as u32).clamp(1, 8192),
            ((rect.height() * pixels_per_point).round() as u32).clamp(1, 8192),
        ];
        let drawn = DrawnKey {
            revision: state.revision,
            settings,
            orbit: self.orbit,
            size,
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
                        &state.document().scene,
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
                    let (frame_ms, ctx) = (Arc::clone(&self.frame_ms), ui.ctx().clone());
                    gpu.context.queue.on_submitted_work_done(move || {
                        if let Ok(mut slot) = frame_ms.lock() {
                            *slot = Some(started.elapsed().as_secs_f64() * 1e3);
                        }
                        ctx.request_repaint(); // the status bar shows the new time
                    });
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
