//! A groom as Unreal's Groom importer and Unity's hair package read it: the strands, and
//! the hair mesh's columns as guide curves the strands follow when the engine simulates.
//!
//! The method already has what an engine's guide-based simulation needs. A strand is a
//! blend of its bundle's corner columns (seed 000 §3.1): its root is the corners weighted by
//! its face coordinate, and so is its shape before styling. So the corner columns are
//! its natural guides and those weights its guide weights, no nearest-neighbour search.
//! Unreal blends at most three guides per strand, so a quad strand keeps its three
//! heaviest corners, renormalised.

use glam::DVec3;

use crate::Document;
use crate::geometry::curve::{SegmentForm, curve_point, curve_segments};
use crate::io::strand_files::{StrandLook, tapered_widths_m};
use crate::strands::reference::Strand;

/// Points per layer along a guide: the column's cubic curve sampled finely enough that a
/// guide bends like the strands it carries (a column has only a handful of vertices).
pub const GUIDE_POINTS_PER_LAYER: usize = 4;

/// Curves with the per-curve attributes of a groom.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GroomCurves {
    pub points: Vec<[f32; 3]>,
    /// Points of each curve, in order.
    pub vertex_counts: Vec<i32>,
    /// Root uv of each curve in the scalp's styling uv space.
    pub root_uv: Vec<[f32; 2]>,
    /// Styling group of each curve: 0 for the global parameters, `g + 1` for group `g`.
    pub group_id: Vec<i32>,
    /// Unique over strands and guides together (guides first), so a strand names its guides.
    pub id: Vec<i32>,
    /// Width at every point, metres: the root width tapering to the tip as the renderers
    /// draw it ([`tapered_widths_m`]).
    pub widths_m: Vec<f32>,
    /// Colour at every point (linear RGB; what a mass of the hair shows), or empty (guides).
    pub colors: Vec<[f32; 3]>,
}

/// A groom: strands, their guides and which guides move each strand.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Groom {
    pub strands: GroomCurves,
    /// Per strand: the `id`s of its three guides (the heaviest corner columns of its bundle;
    /// a guide repeats with weight 0 where a bundle has fewer usable corners).
    pub closest_guides: Vec<[i32; 3]>,
    /// Per strand: the weights of `closest_guides`, summing to 1.
    pub guide_weights: Vec<[f32; 3]>,
    pub guides: GroomCurves,
    /// Strand width at the root, metres.
    pub width_m: f32,
}

impl Groom {
    /// The groom of `strands`, generated from `document`, `width_m` wide at their roots and
    /// coloured by the document's hair material. Guides are the columns of the
    /// bundles that grow the strands, one per styling group that uses the column (Unreal
    /// simulates each group on its own, so a strand's guides must be in its group), each as
    /// tall as the tallest of those bundles.
    pub fn new(document: &Document, strands: &[Strand], width_m: f32) -> Self {
        let mesh = &document.hair_mesh;
        let group_of = |bundle: u32| -> i32 {
            document
                .styling
                .group_of(bundle)
                .map_or(0, |g| g as i32 + 1)
        };
        // (group, column) → guide index; guides in first-use order so ids are stable, each with
        // the most layers of the bundles that use it.
        let mut guide_of = std::collections::BTreeMap::<(i32, u32), usize>::new();
        let mut guide_keys: Vec<(i32, u32, usize)> = Vec::new();
        for (b, bundle) in mesh.bundles.iter().enumerate() {
            if bundle.removed || bundle.layers == 0 {
                continue;
            }
            let group = group_of(b as u32);
            for &column in &bundle.vertices {
                let index = *guide_of.entry((group, column)).or_insert_with(|| {
                    guide_keys.push((group, column, 0));
                    guide_keys.len() - 1
                });
                let layers = &mut guide_keys[index].2;
                *layers = (*layers).max(bundle.layers as usize);
            }
        }
        let mut guides = GroomCurves::default();
        for (index, &(group, column, layers)) in guide_keys.iter().enumerate() {
            let positions = &mesh.columns[column as usize].positions;
            // A valid mesh has every layer of its bundles. A column too short for its
            // bundles (an invalid mesh) still gives a two-point guide, so every id a strand
            // names exists and every curve has the two points readers require.
            let layers = layers.min(positions.len().saturating_sub(1));
            if layers == 0 {
                let root = positions.first().copied().unwrap_or_default();
                guides.points.extend([root.as_vec3().to_array(); 2]);
                guides.vertex_counts.push(2);
                guides.widths_m.extend(tapered_widths_m(2, width_m));
            } else {
                let segments = curve_segments(&positions[..=layers]);
                let count = layers * GUIDE_POINTS_PER_LAYER + 1;
                for k in 0..count {
                    let t = k as f64 / GUIDE_POINTS_PER_LAYER as f64;
                    let p: DVec3 = curve_point(&segments, t, SegmentForm::ExactCubic);
                    guides.points.push(p.as_vec3().to_array());
                }
                guides.vertex_counts.push(count as i32);
                guides.widths_m.extend(tapered_widths_m(count, width_m));
            }
            let bundle_uv = first_uv_of_column(document, column);
            guides.root_uv.push(bundle_uv);
            guides.group_id.push(group);
            guides.id.push(index as i32);
        }

        let guide_count = guides.id.len() as i32;
        let mut groom = Groom {
            guides,
            width_m,
            ..Groom::default()
        };
        for (i, strand) in strands.iter().enumerate() {
            let bundle = &mesh.bundles[strand.bundle as usize];
            let group = group_of(strand.bundle);
            let weights = strand.coord.weights(bundle.corner_count());
            let mut corners: Vec<(f64, i32)> = bundle
                .vertices
                .iter()
                .zip(weights)
                .filter_map(|(&column, w)| {
                    guide_of
                        .get(&(group, column))
                        .map(|&g| (w.max(0.0), g as i32))
                })
                .collect();
            // Heaviest first; a tie keeps corner order, so the choice is deterministic.
            corners.sort_by(|a, b| b.0.total_cmp(&a.0));
            corners.truncate(3);
            let total: f64 = corners.iter().map(|c| c.0).sum();
            let mut ids = [corners.first().map_or(0, |c| c.1); 3];
            // No guide at all (a bundle whose columns made none): the first weight carries
            // everything, so the weights still sum to one.
            let mut w = [1.0f32, 0.0, 0.0];
            for (k, &(weight, id)) in corners.iter().enumerate() {
                ids[k] = id;
                w[k] = if total > 0.0 {
                    (weight / total) as f32
                } else {
                    1.0 / corners.len() as f32
                };
            }
            groom.closest_guides.push(ids);
            groom.guide_weights.push(w);
            let curves = &mut groom.strands;
            curves
                .points
                .extend(strand.points.iter().map(|p| p.as_vec3().to_array()));
            curves.vertex_counts.push(strand.points.len() as i32);
            curves.root_uv.push(strand.root_uv.as_vec2().to_array());
            curves.group_id.push(group);
            curves.id.push(guide_count + i as i32);
        }
        let look = StrandLook::new(
            strands,
            width_m,
            &document.scene.material,
            &document.root_maps,
        );
        (groom.strands.widths_m, groom.strands.colors) = (look.widths_m, look.colors);
        groom
    }
}

/// The uv of `column` at the first bundle corner it is (a column on a uv seam has several;
/// a guide's root uv is only informative).
fn first_uv_of_column(document: &Document, column: u32) -> [f32; 2] {
    document
        .hair_mesh
        .bundles
        .iter()
        .find_map(|b| {
            b.vertices
                .iter()
                .position(|&v| v == column)
                .map(|k| b.uvs[k].as_vec2().to_array())
        })
        .unwrap_or([0.0; 2])
}
