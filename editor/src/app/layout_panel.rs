//! uv / w layout panel: the root layer's uv layout in 2D (face corners, seams in red,
//! selected bundles filled), drag a uv vertex (every corner of that column on the same side
//! of a seam follows; one undo step per drag), w per layer (automatic from path length or
//! edited per vertex), and the texture atlas the runtime export will use.

use std::collections::BTreeMap;

use glam::DVec2;
use hairloom_core::edit;
use hairloom_core::model::change::ChangeKind;
use hairloom_core::model::mesh::WMode;
use hairloom_core::runtime::atlas::{Atlas, build_atlas};
use hairloom_core::runtime::textures::MAX_REGION_SIDE;
use hairloom_core::{HairMesh, VertexRef};

use super::state::EditorState;

/// Pick distance for a uv vertex, in points.
const UV_PICK_PX: f32 = 7.0;

/// A uv vertex being dragged: the corners that move together and where the drag began.
struct UvDrag {
    corners: Vec<(u32, u32)>,
    start_uv: DVec2,
}

#[derive(Default)]
pub struct LayoutPanel {
    drag: Option<UvDrag>,
    /// The atlas for the document revision it was built at (rebuilt only on change).
    atlas: Option<(u64, Atlas)>,
    /// Where the uv view was last drawn (tests drag in it).
    pub uv_rect: Option<egui::Rect>,
}

/// The corners sharing `column` and (bit-for-bit) `uv`: one uv vertex of the layout.
fn corners_at(mesh: &HairMesh, column: u32, uv: DVec2) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for (b, bundle) in mesh.bundles.iter().enumerate() {
        for (k, (&c, &corner_uv)) in bundle.vertices.iter().zip(&bundle.uvs).enumerate() {
            if c == column && corner_uv == uv {
                out.push((b as u32, k as u32));
            }
        }
    }
    out
}

/// Root-layer edges whose two sides disagree on uv: the layout's seams.
fn seam_edges(mesh: &HairMesh) -> Vec<[DVec2; 2]> {
    // Edge (sorted columns) → the uv pairs each bundle gives it.
    let mut edges: BTreeMap<(u32, u32), Vec<[DVec2; 2]>> = BTreeMap::new();
    for bundle in mesh.bundles.iter().filter(|b| !b.removed) {
        let n = bundle.vertices.len();
        for i in 0..n {
            let j = (i + 1) % n;
            let (a, b) = (bundle.vertices[i], bundle.vertices[j]);
            let (ua, ub) = (bundle.uvs[i], bundle.uvs[j]);
            let (key, uvs) = if a < b {
                ((a, b), [ua, ub])
            } else {
                ((b, a), [ub, ua])
            };
            edges.entry(key).or_default().push(uvs);
        }
    }
    edges
        .into_values()
        .filter(|sides| sides.len() == 2 && sides[0] != sides[1])
        .flatten()
        .collect()
}

impl LayoutPanel {
    pub fn ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        ui.heading("Root uv layout");
        self.uv_view(ui, state);
        ui.separator();
        self.w_ui(ui, state);
        ui.separator();
        self.atlas_view(ui, state);
    }

    fn uv_view(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        let side = ui.available_width().clamp(120.0, 420.0);
        let (rect, response) =
            ui.allocate_exact_size(egui::vec2(side, side), egui::Sense::click_and_drag());
        self.uv_rect = Some(rect);
        let to_screen = |uv: DVec2| {
            egui::pos2(
                rect.left() + uv.x as f32 * rect.width(),
                rect.bottom() - uv.y as f32 * rect.height(),
            )
        };
        let to_uv = |p: egui::Pos2| {
            DVec2::new(
                ((p.x - rect.left()) / rect.width()) as f64,
                ((rect.bottom() - p.y) / rect.height()) as f64,
            )
        };
        // Drag a uv vertex: the preview always starts from the document before the drag.
        if response.drag_started()
            && let Some(pointer) = response.interact_pointer_pos()
        {
            let mesh = &state.document().hair_mesh;
            let nearest = mesh
                .bundles
                .iter()
                .filter(|b| !b.removed)
                .flat_map(|b| b.vertices.iter().copied().zip(b.uvs.iter().copied()))
                .map(|(c, uv)| (c, uv, to_screen(uv).distance(pointer)))
                .filter(|(_, _, d)| *d <= UV_PICK_PX)
                .min_by(|a, b| a.2.total_cmp(&b.2));
            if let Some((column, uv, _)) = nearest {
                let corners = corners_at(mesh, column, uv);
                state.commit_edit();
                self.drag = Some(UvDrag {
                    corners,
                    start_uv: uv,
                });
            }
        }
        if let Some(drag) = &self.drag {
            if response.dragged()
                && let Some(pointer) = response.interact_pointer_pos()
            {
                let target = to_uv(pointer).clamp(DVec2::ZERO, DVec2::ONE);
                let changes: Vec<(u32, u32, DVec2)> =
                    drag.corners.iter().map(|&(b, k)| (b, k, target)).collect();
                let start = state.edit_start().hair_mesh.clone();
                match edit::set_corner_uvs(&start, &changes) {
                    Ok(outcome) => {
                        state.edit(ChangeKind::Reshape, "Move uv").hair_mesh = outcome.mesh;
                        state.message = format!(
                            "uv ({:.4}, {:.4}) to ({:.4}, {:.4})",
                            drag.start_uv.x, drag.start_uv.y, target.x, target.y
                        );
                    }
                    Err(error) => state.message = format!("Move uv: {error}"),
                }
            }
            if response.drag_stopped() {
                state.commit_edit();
                self.drag = None;
            }
        }
        if response.clicked()
            && let Some(pointer) = response.interact_pointer_pos()
        {
            // A click inside a face selects its bundle, as in the outliner.
            let uv = to_uv(pointer);
            let hit = state
                .document()
                .hair_mesh
                .bundles
                .iter()
                .enumerate()
                .filter(|(_, b)| !b.removed)
                .find(|(_, b)| {
                    let polygon: Vec<[f64; 2]> = b.uvs.iter().map(|p| [p.x, p.y]).collect();
                    hairloom_core::edit::select::point_in_polygon([uv.x, uv.y], &polygon)
                })
                .map(|(i, _)| i as u32);
            let add = ui.input(|i| i.modifiers.shift || i.modifiers.command);
            if !add {
                state.selection.clear();
            }
            if let Some(b) = hit {
                state.selection.insert(b);
            }
        }

        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 2.0, ui.visuals().extreme_bg_color);
        let mesh = &state.document().hair_mesh;
        let edge = egui::Stroke::new(0.6, ui.visuals().weak_text_color());
        let selected_fill = egui::Color32::from_rgba_unmultiplied(255, 150, 40, 90);
        for (b, bundle) in mesh.bundles.iter().enumerate() {
            if bundle.removed {
                continue;
            }
            let points: Vec<egui::Pos2> = bundle.uvs.iter().map(|&uv| to_screen(uv)).collect();
            let fill = if state.selection.contains(&(b as u32)) {
                selected_fill
            } else {
                egui::Color32::TRANSPARENT
            };
            painter.add(egui::Shape::convex_polygon(points, fill, edge));
        }
        let seam = egui::Stroke::new(1.6, egui::Color32::from_rgb(230, 70, 60));
        for [a, b] in seam_edges(mesh) {
            painter.line_segment([to_screen(a), to_screen(b)], seam);
        }
        if let Some(drag) = &self.drag
            && let Some(&(b, k)) = drag.corners.first()
            && let Some(uv) = mesh
                .bundles
                .get(b as usize)
                .and_then(|bundle| bundle.uvs.get(k as usize))
        {
            painter.circle_filled(to_screen(*uv), 4.0, egui::Color32::from_rgb(255, 150, 40));
        }
        ui.label(
            egui::RichText::new(
                "drag a corner to move its uv; click a face to select; seams in red",
            )
            .small()
            .weak(),
        );
    }

    fn w_ui(&mut self, ui: &mut egui::Ui, state: &mut EditorState) {
        ui.heading("w per layer");
        let mode = state.document().hair_mesh.w_mode;
        ui.horizontal(|ui| {
            for (value, label) in [
                (WMode::FromPathLength, "auto (path length)"),
                (WMode::Manual, "edited"),
            ] {
                if ui.selectable_label(mode == value, label).clicked() && mode != value {
                    let ok = state.edit_mesh("w mode", |mesh, _| edit::set_w_mode(mesh, value));
                    if ok {
                        state.message = format!("w: {label}");
                    }
                }
            }
        });
        // The column of the single selected vertex (or the first corner of the first selected
        // bundle): its w at every layer, editable.
        let mesh = &state.document().hair_mesh;
        let column = state
            .vertex_selection
            .first()
            .map(|v| v.column)
            .or_else(|| {
                let b = *state.selection.first()?;
                mesh.bundles.get(b as usize)?.vertices.first().copied()
            });
        let Some(column) = column.filter(|&c| (c as usize) < mesh.columns.len()) else {
            ui.weak("select a bundle or a vertex to see its column's w");
            return;
        };
        let ws = mesh.columns[column as usize].w.clone();
        egui::Grid::new("w per layer").striped(true).show(ui, |ui| {
            ui.label(format!("column {column}"));
            ui.label("w");
            ui.end_row();
            for (layer, w) in ws.iter().enumerate() {
                let label = ui.label(format!("layer {layer}"));
                let mut value = *w;
                let response = ui
                    .add_enabled(
                        layer > 0,
                        egui::DragValue::new(&mut value)
                            .speed(0.001)
                            .max_decimals(4),
                    )
                    .labelled_by(label.id);
                if response.changed() && value != *w {
                    let vertex = VertexRef {
                        column,
                        layer: layer as u32,
                    };
                    let start = state.edit_start().hair_mesh.clone();
                    match edit::set_w(&start, vertex, value) {
                        Ok(outcome) => {
                            state.edit(ChangeKind::Reshape, "set w").hair_mesh = outcome.mesh
                        }
                        Err(error) => state.message = format!("set w: {error}"),
                    }
                }
                if response.drag_stopped() || (response.changed() && !response.dragged()) {
                    state.commit_edit();
                }
                ui.end_row();
            }
        });
    }

    fn atlas_view(&mut self, ui: &mut egui::Ui, state: &EditorState) {
        ui.heading("Runtime texture atlas");
        if self
            .atlas
            .as_ref()
            .is_none_or(|(revision, _)| *revision != state.revision)
        {
            self.atlas = Some((
                state.revision,
                build_atlas(&state.document().hair_mesh, MAX_REGION_SIDE),
            ));
        }
        let Some((_, atlas)) = &self.atlas else {
            return;
        };
        if atlas.width == 0 || atlas.height == 0 {
            ui.weak("no bundle grows hair: the atlas is empty");
            return;
        }
        ui.label(format!(
            "{} × {} texels per slice, {} used ({:.0} %), {} blocks",
            atlas.width,
            atlas.height,
            atlas.used_texels(),
            100.0 * atlas.used_texels() as f64 / (atlas.width * atlas.height) as f64,
            atlas.blocks.len()
        ));
        let width = ui.available_width().clamp(120.0, 420.0);
        let scale = width / atlas.width as f32;
        let (rect, _) = ui.allocate_exact_size(
            egui::vec2(width, atlas.height as f32 * scale),
            egui::Sense::hover(),
        );
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 0.0, ui.visuals().extreme_bg_color);
        for block in &atlas.blocks {
            let min = rect.min + egui::vec2(block.origin[0] as f32, block.origin[1] as f32) * scale;
            let texel = egui::Rect::from_min_size(min, egui::vec2(2.0, 2.0) * scale);
            let selected = state.selection.contains(&block.bundle);
            let colour = if selected {
                egui::Color32::from_rgb(255, 150, 40)
            } else {
                // A stable hue per bundle so neighbouring blocks are told apart.
                let hue = (block.bundle as f32 * 0.618_034).fract();
                egui::Color32::from(egui::ecolor::Hsva::new(hue, 0.45, 0.65, 1.0))
            };
            painter.rect_filled(texel.shrink(0.25 * scale.min(2.0)), 0.0, colour);
        }
    }
}
