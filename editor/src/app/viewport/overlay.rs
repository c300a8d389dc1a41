//! The 2D overlay over the picture: the map being painted, hair-mesh wireframe, styling
//! frames, the selection and the region being dragged.

use hairloom_core::model::root_maps::{RootMapChannel, RootMaps, linear_to_srgb};

use super::*;

impl Viewport {
    /// The body's depth in this view, for depth-testing the overlay; rebuilt only when the
    /// document, the camera or the viewport's size changed.
    pub(super) fn body_depth(
        &mut self,
        state: &EditorState,
        projector: &Projector,
    ) -> Arc<select::DepthMap> {
        let key = BodyDepthKey {
            revision: state.shown_revision(),
            orbit: self.orbit,
            size: [projector.rect.width(), projector.rect.height()],
            bounds: self.camera_bounds,
        };
        if let Some((cached, depth)) = &self.body_depth
            && *cached == key
        {
            return Arc::clone(depth);
        }
        let body = &state.shown_document().body;
        let depth = Arc::new(select::DepthMap::rasterize(
            &body.positions,
            &body.triangles,
            |p| projector.project_local_depth(p),
            [
                projector.rect.width() as f64,
                projector.rect.height() as f64,
            ],
            2.0,
        ));
        self.body_depth = Some((key, Arc::clone(&depth)));
        depth
    }

    /// The hair-mesh wireframe (when on) and the selected bundles' outlines, drawn over the
    /// picture with the picture's camera; depth-tested against the body (what is behind the
    /// head is not drawn) unless X-ray is on.
    pub(super) fn paint_overlay(&mut self, ui: &egui::Ui, state: &EditorState, rect: egui::Rect) {
        let Some(projector) = self.projector(state, rect) else {
            return;
        };
        let depth = (!state.tool.xray).then(|| self.body_depth(state, &projector));
        let mesh = &state.shown_document().hair_mesh;
        let seen = |p: DVec3| {
            depth.as_ref().is_none_or(|depth| {
                projector
                    .project_local_depth(p)
                    .is_some_and(|q| depth.visible(q))
            })
        };
        let project = |p: DVec3| projector.project(p);
        let painter = ui.painter_at(rect);
        // Each edge is cut in pieces so an outline stops where the body covers it.
        const PIECES_PER_EDGE: usize = 4;
        let polyline = |points: &[DVec3], closed: bool, stroke: egui::Stroke| {
            for run in select::visible_runs(points, closed, PIECES_PER_EDGE, seen) {
                let run: Vec<_> = run.into_iter().filter_map(project).collect();
                painter.add(egui::Shape::line(run, stroke));
            }
        };
        let outline = |bundle: &hairloom_core::Bundle, stroke: egui::Stroke| {
            for layer in 0..=bundle.layers as usize {
                let corners: Vec<DVec3> = bundle
                    .vertices
                    .iter()
                    .filter_map(|&c| mesh.columns.get(c as usize)?.positions.get(layer).copied())
                    .collect();
                if corners.len() == bundle.vertices.len() {
                    polyline(&corners, true, stroke);
                }
            }
            for &c in &bundle.vertices {
                let Some(column) = mesh.columns.get(c as usize) else {
                    continue;
                };
                let end = (bundle.layers as usize).min(column.positions.len() - 1);
                polyline(&column.positions[..=end], false, stroke);
            }
        };
        if self.settings.map_overlay
            && state.tool.drag == DragTool::Groom
            && let Some(channel) = state.tool.brush.paint
        {
            self.paint_map_display(&painter, state, &projector, channel);
        }
        let vertex_mode = state.tool.mode == SelectMode::Vertices;
        if self.settings.wireframe || vertex_mode {
            let stroke = egui::Stroke::new(
                1.0,
                egui::Color32::from_rgba_unmultiplied(120, 170, 230, 110),
            );
            for bundle in mesh.bundles.iter().filter(|b| !b.removed) {
                outline(bundle, stroke);
            }
            if self
                .interior
                .as_ref()
                .is_none_or(|(r, _)| *r != state.shown_revision())
            {
                let topology = hairloom_core::Topology::build(mesh);
                let interior = (0..mesh.columns.len())
                    .map(|c| {
                        (0..mesh.columns[c].positions.len())
                            .map(|layer| mesh.is_interior(&topology, c, layer))
                            .collect()
                    })
                    .collect();
                self.interior = Some((state.shown_revision(), interior));
            }
            let interior = self.interior.as_ref().map(|(_, i)| i);
            for (c, column) in mesh.columns.iter().enumerate() {
                for (layer, p) in column.positions.iter().enumerate() {
                    let Some(at) = project(*p).filter(|_| seen(*p)) else {
                        continue;
                    };
                    let is_interior = interior
                        .and_then(|i| i.get(c)?.get(layer).copied())
                        .unwrap_or(false);
                    let colour = if is_interior {
                        egui::Color32::from_rgb(240, 200, 80) // placed automatically
                    } else {
                        egui::Color32::from_rgb(120, 200, 255) // shaped by the artist
                    };
                    painter.circle_filled(at, 1.8, colour);
                }
            }
        }
        let selected = egui::Stroke::new(1.5, egui::Color32::from_rgb(255, 150, 40));
        for &b in &state.selection {
            if let Some(bundle) = mesh.bundles.get(b as usize) {
                outline(bundle, selected);
            }
        }
        if self.settings.frame_glyphs {
            if self
                .frames
                .as_ref()
                .is_none_or(|(r, _)| *r != state.shown_revision())
            {
                let frames = (0..=mesh.max_layers())
                    .map(|layer| hairloom_core::geometry::frames::layer_frames(mesh, layer))
                    .collect();
                self.frames = Some((state.shown_revision(), frames));
            }
            let length = mesh.size() * 0.012;
            if let Some((_, frames)) = &self.frames {
                for (layer, frames) in frames.iter().enumerate() {
                    for (c, frame) in frames.iter().enumerate() {
                        let (Some(frame), Some(p)) = (
                            frame,
                            mesh.position(VertexRef {
                                column: c as u32,
                                layer: layer as u32,
                            }),
                        ) else {
                            continue;
                        };
                        let Some(at) = project(p).filter(|_| seen(p)) else {
                            continue;
                        };
                        let alpha = if frame.fallback { 90 } else { 220 };
                        for (axis, (r, g, b)) in [
                            (frame.u, (235, 70, 60)),
                            (frame.v, (90, 200, 90)),
                            (frame.w, (80, 140, 255)),
                        ] {
                            if let Some(tip) = project(p + axis * length) {
                                painter.line_segment(
                                    [at, tip],
                                    egui::Stroke::new(
                                        1.2,
                                        egui::Color32::from_rgba_unmultiplied(r, g, b, alpha),
                                    ),
                                );
                            }
                        }
                    }
                }
            }
        }
        if self.gizmo_shown && self.transform.is_none() {
            self.gizmo.paint(&painter);
        }
        if self.settings.styling_gizmo
            && self.transform.is_none()
            && let Some(projector) = self.projector(state, rect)
        {
            self.paint_styling_gizmo(&painter, state, &projector);
        }
        let orange = egui::Color32::from_rgb(255, 150, 40);
        for v in &state.vertex_selection {
            if let Some(at) = mesh.position(*v).and_then(project) {
                painter.circle_filled(at, 3.5, orange);
            }
        }
        // The region being dragged.
        if self.drag_path.len() > 1 {
            let stroke = egui::Stroke::new(1.0, egui::Color32::WHITE);
            let (first, last) = (self.drag_path[0], self.drag_path[self.drag_path.len() - 1]);
            match state.tool.drag {
                DragTool::Box => {
                    painter.rect_stroke(
                        egui::Rect::from_two_pos(first, last),
                        0.0,
                        stroke,
                        egui::StrokeKind::Middle,
                    );
                }
                DragTool::Lasso => {
                    painter.add(egui::Shape::closed_line(self.drag_path.clone(), stroke));
                }
                DragTool::Groom => {}
                DragTool::Paint => {
                    painter.circle_stroke(last, state.tool.paint_radius_px, stroke);
                    painter.add(egui::Shape::line(
                        self.drag_path.clone(),
                        egui::Stroke::new(
                            state.tool.paint_radius_px * 2.0,
                            egui::Color32::from_rgba_unmultiplied(255, 255, 255, 24),
                        ),
                    ));
                }
            }
        }
        // The grooming brush: its circle at its size on the hair (fainter off the hair).
        if state.tool.drag == DragTool::Groom
            && let Some(cursor) = self.brush_cursor
        {
            let alpha = if cursor.touches_hair { 230 } else { 110 };
            let colour = egui::Color32::from_rgba_unmultiplied(255, 200, 120, alpha);
            painter.circle_stroke(
                cursor.centre,
                cursor.radius_px,
                egui::Stroke::new(1.5, colour),
            );
            // Strength as an inner ring (a full-strength brush fills its circle).
            painter.circle_stroke(
                cursor.centre,
                cursor.radius_px * state.tool.brush.strength as f32,
                egui::Stroke::new(1.0, egui::Color32::from_white_alpha(alpha / 2)),
            );
        }
        if let Some(active) = &self.transform {
            if let Some(pivot) = project(active.pivot) {
                painter.circle_stroke(pivot, 5.0, egui::Stroke::new(1.5, orange));
                // The locked axis as a line through the pivot, in Blender's axis colours
                // (X red, Y green, Z blue) under the artist's convention.
                if let Some(axis) = active.axis {
                    let mut direction = DVec3::ZERO;
                    direction[axis] = 1.0;
                    let colour = match super::transform_tools::artist_axis(axis, state.tool.z_up) {
                        0 => egui::Color32::from_rgb(230, 70, 70),
                        1 => egui::Color32::from_rgb(110, 200, 80),
                        _ => egui::Color32::from_rgb(80, 140, 240),
                    };
                    let reach = 2.0;
                    if let (Some(a), Some(b)) = (
                        project(active.pivot - direction * reach),
                        project(active.pivot + direction * reach),
                    ) {
                        painter.line_segment([a, b], egui::Stroke::new(1.5, colour));
                    }
                }
                if let Some(pointer) = active.applied.as_ref().map(|(p, ..)| *p) {
                    painter.line_segment(
                        [pivot, pointer],
                        egui::Stroke::new(1.0, egui::Color32::from_white_alpha(120)),
                    );
                }
            }
            painter.text(
                rect.left_top() + egui::vec2(10.0, 10.0),
                egui::Align2::LEFT_TOP,
                &state.message,
                egui::FontId::proportional(14.0),
                egui::Color32::WHITE,
            );
        }
    }

    /// The map `channel` over the scalp while it is painted: the root faces cut finely, each
    /// corner coloured by the map at its uv ([`map_display_colour`]), faces turned away from
    /// the camera left out (the scalp hides them), drawn under the outlines.
    fn paint_map_display(
        &mut self,
        painter: &egui::Painter,
        state: &EditorState,
        projector: &Projector,
        channel: RootMapChannel,
    ) {
        let document = state.shown_document();
        if self
            .map_display
            .as_ref()
            .is_none_or(|(r, _)| *r != state.shown_revision())
        {
            let triangles = hairloom_core::edit::paint_maps::map_display_triangles(
                &document.hair_mesh,
                MAP_DISPLAY_CUTS,
            );
            self.map_display = Some((state.shown_revision(), triangles));
        }
        let Some((_, triangles)) = &self.map_display else {
            return;
        };
        let eye = projector
            .view
            .inverse()
            .transform_point3(Vec3::ZERO)
            .as_dvec3();
        let mut mesh = egui::Mesh::default();
        for triangle in triangles {
            let centre =
                (triangle.positions[0] + triangle.positions[1] + triangle.positions[2]) / 3.0;
            if triangle.normal.dot(eye - centre) <= 0.0 {
                continue;
            }
            let corners: Option<Vec<egui::Pos2>> = triangle
                .positions
                .iter()
                .map(|&p| projector.project(p))
                .collect();
            let Some(corners) = corners else {
                continue;
            };
            let first = mesh.vertices.len() as u32;
            for (at, uv) in corners.into_iter().zip(triangle.uvs) {
                mesh.colored_vertex(at, map_display_colour(&document.root_maps, channel, uv));
            }
            mesh.add_triangle(first, first + 1, first + 2);
        }
        painter.add(egui::Shape::mesh(mesh));
    }
}

/// Each fan triangle of a root face is cut into this many² for the map display: a 256² map
/// over ~400 faces shows its strokes, and ~13K triangles draw in well under a millisecond.
const MAP_DISPLAY_CUTS: u32 = 4;

/// How the map display colours a point of the scalp at `uv`. Grey maps run from blue (0: no
/// hair, no length, no clumping) through green to red (1, the unpainted value), as weight
/// paint does in Blender; the colour map shows its colour over grey by its weight.
pub(super) fn map_display_colour(
    maps: &RootMaps,
    channel: RootMapChannel,
    uv: glam::DVec2,
) -> egui::Color32 {
    if channel == RootMapChannel::Colour {
        let paint = maps.sample_colour(uv);
        let weight = paint.weight.clamp(0.0, 1.0);
        let byte = |linear: f64| {
            let c = 0.5 + (linear_to_srgb(linear.clamp(0.0, 1.0)) - 0.5) * weight;
            (c * 255.0).round() as u8
        };
        let [r, g, b] = paint.rgb_linear.map(byte);
        return egui::Color32::from_rgba_unmultiplied(r, g, b, (60.0 + 170.0 * weight) as u8);
    }
    let values = maps.sample(uv);
    let value = match channel {
        RootMapChannel::Density => values.density,
        RootMapChannel::Length => values.length,
        _ => values.clump,
    };
    let v = if value.is_finite() {
        value.clamp(0.0, 1.0)
    } else {
        0.0
    };
    // Blue → green → red.
    let (r, g, b) = if v < 0.5 {
        let t = 2.0 * v;
        (0.0, t, 1.0 - t)
    } else {
        let t = 2.0 * v - 1.0;
        (t, 1.0 - t, 0.0)
    };
    let byte = |c: f64| (40.0 + 200.0 * c).round() as u8;
    egui::Color32::from_rgba_unmultiplied(byte(r), byte(g), byte(b), 130)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_display_shows_grey_maps_blue_to_red_and_colour_by_its_weight() {
        let mut maps = RootMaps::blank(2, 1).expect("maps");
        // The left texel painted to 0 in every grey map and coloured green at full weight;
        // the right one left as it was.
        maps.texels_mut()[0] = [0, 0, 0, 255];
        maps.colour_texels_mut()[0] = [20, 200, 40, 255];
        let left = glam::DVec2::new(0.0, 0.5);
        let right = glam::DVec2::new(1.0, 0.5);
        for channel in [
            RootMapChannel::Density,
            RootMapChannel::Length,
            RootMapChannel::Clump,
        ] {
            let painted = map_display_colour(&maps, channel, left);
            let unpainted = map_display_colour(&maps, channel, right);
            assert!(
                painted.b() > painted.r() && painted.b() > painted.g(),
                "{painted:?}"
            );
            assert!(
                unpainted.r() > unpainted.g() && unpainted.r() > unpainted.b(),
                "{unpainted:?}"
            );
        }
        let green = map_display_colour(&maps, RootMapChannel::Colour, left);
        let none = map_display_colour(&maps, RootMapChannel::Colour, right);
        assert!(green.g() > green.r() && green.g() > green.b(), "{green:?}");
        assert!(green.a() > none.a(), "{green:?} over {none:?}");
        // Where no colour is painted the scalp shows grey, faintly.
        assert_eq!(none.r(), none.g());
        assert!(none.a() > 0 && none.a() < 128);
    }
}
