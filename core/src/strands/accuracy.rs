//! What each accuracy switch of strand evaluation costs, measured on the CPU (`hairloom
//! bench accuracy` prints and plots it; GPU accuracy lives in `hairloom_render::measure`).
//!
//! Every switch of the strand-evaluation path is compared with the f64 reference (column
//! blend of centripetal Catmull-Rom columns, exact cubics) at the same strands and curve
//! parameters, and timed on the CPU (one thread). Vertex counts are compared, styled, against
//! a 257-vertex styled reference. Errors are in model units (metres for the samples); the
//! bundle width (mean root-edge length) puts them in proportion.

use std::time::Instant;

use glam::{DVec2, DVec3};

use crate::geometry::curve::{CurveDefinition, ReferenceStrand, SegmentForm};
use crate::model::document::Document;
use crate::runtime::atlas::Atlas;
use crate::runtime::strand_gen::{Filtering, StrandGen};
use crate::runtime::textures::{Precision, RuntimeTextures};
use crate::strands::reference::{StrandOptions, generate};
use crate::strands::roots::{SampleDomain, progressive_samples};

/// Vertices per strand used for the curve switches.
const CURVE_VERTICES: usize = 33;

/// One measured switch.
#[derive(Clone, Debug, PartialEq)]
pub struct CpuAccuracyRow {
    pub switch: String,
    pub max_error: f64,
    pub mean_error: f64,
    /// Max error against the f64 two-quadratic model (what the texture path implements):
    /// isolates filtering and storage error from the curve approximation.
    pub max_vs_quadratics: Option<f64>,
    pub ms_per_million: f64,
    /// What the storage costs: the five textures' GPU bytes per hair-mesh vertex (texture
    /// path rows only).
    pub texture_bytes_per_vertex: Option<f64>,
}

/// Every switch measured on one document.
#[derive(Clone, Debug, PartialEq)]
pub struct CpuAccuracy {
    /// The f64 reference first, then the curve definitions, the texture paths and the
    /// styled vertex counts.
    pub rows: Vec<CpuAccuracyRow>,
    /// Strands compared per switch.
    pub strands: usize,
    /// Mean root-edge length: errors in proportion to a bundle.
    pub bundle_width: f64,
}

/// Strands to measure: (atlas block index, block coords, bundle-corner weights).
fn strand_set(textures: &RuntimeTextures, per_bundle: u32) -> Vec<(usize, DVec2, [f64; 4])> {
    let quad = progressive_samples(per_bundle as usize, SampleDomain::Square, 7);
    let triangle = progressive_samples(per_bundle as usize, SampleDomain::Triangle, 7);
    let mut out = Vec::new();
    for (index, block) in textures.atlas.blocks.iter().enumerate() {
        let samples = if Atlas::is_triangle(block) {
            &triangle
        } else {
            &quad
        };
        for sample in samples {
            let (s, t) = Atlas::sample_block_coords(block, *sample);
            let coords = DVec2::new(s, t);
            out.push((
                index,
                coords,
                Atlas::corner_weights(block, coords.x, coords.y),
            ));
        }
    }
    out
}

fn taus(layers: u32) -> impl Iterator<Item = f64> {
    (0..CURVE_VERTICES).map(move |k| layers as f64 * k as f64 / (CURVE_VERTICES - 1) as f64)
}

/// Measures every switch on `document`'s strands, `per_bundle` strands per bundle.
pub fn measure_cpu_accuracy(document: &Document, per_bundle: u32) -> CpuAccuracy {
    let mesh = &document.hair_mesh;
    let f32_textures = RuntimeTextures::build(mesh, Precision::F32);
    let f16_textures = RuntimeTextures::build(mesh, Precision::F16);
    let strands = strand_set(&f32_textures, per_bundle);
    let bundle_width = mean_root_edge(mesh);
    let layers_of = |block: usize| f32_textures.atlas.blocks[block].layers;

    // Every measured strand by the f64 evaluator, with the time it took.
    let evaluate = |definition: CurveDefinition, form: SegmentForm| -> (Vec<Vec<DVec3>>, f64) {
        let start = Instant::now();
        let points: Vec<Vec<DVec3>> = strands
            .iter()
            .filter_map(|(block, _, weights)| {
                let bundle = f32_textures.atlas.blocks[*block].bundle as usize;
                let strand = ReferenceStrand::with_weights(mesh, bundle, *weights)?;
                Some(
                    taus(layers_of(*block))
                        .map(|t| strand.point(t, definition, form))
                        .collect(),
                )
            })
            .collect();
        let vertices = (points.len() * CURVE_VERTICES).max(1) as f64;
        (points, start.elapsed().as_secs_f64() * 1e3 * 1e6 / vertices)
    };
    let (reference, reference_ms) = evaluate(CurveDefinition::ColumnBlend, SegmentForm::ExactCubic);
    let vertex_total = (reference.len() * CURVE_VERTICES) as f64;

    let (quadratic_model, _) = evaluate(CurveDefinition::ColumnBlend, SegmentForm::TwoQuadratics);
    let compare_with = |points: &[Vec<DVec3>], against: &[Vec<DVec3>]| -> (f64, f64) {
        let mut max: f64 = 0.0;
        let mut sum = 0.0;
        let mut count = 0usize;
        for (a, b) in points.iter().zip(against) {
            for (p, q) in a.iter().zip(b) {
                let d = p.distance(*q);
                max = max.max(d);
                sum += d;
                count += 1;
            }
        }
        (max, sum / count.max(1) as f64)
    };
    let compare = |points: &[Vec<DVec3>]| compare_with(points, &reference);
    let mut rows = vec![CpuAccuracyRow {
        switch: "reference: f64, column blend, exact cubic".into(),
        max_error: 0.0,
        mean_error: 0.0,
        max_vs_quadratics: None,
        ms_per_million: reference_ms,
        texture_bytes_per_vertex: None,
    }];
    for (name, definition, form) in [
        (
            "f64, per-strand centripetal (2009 definition)",
            CurveDefinition::PerStrandCentripetal,
            SegmentForm::ExactCubic,
        ),
        (
            "f64, column blend, two quadratics",
            CurveDefinition::ColumnBlend,
            SegmentForm::TwoQuadratics,
        ),
    ] {
        let (points, ms) = evaluate(definition, form);
        let (max, mean) = compare(&points);
        rows.push(CpuAccuracyRow {
            switch: name.into(),
            max_error: max,
            mean_error: mean,
            max_vs_quadratics: None,
            ms_per_million: ms,
            texture_bytes_per_vertex: None,
        });
    }
    for (name, textures, filtering) in [
        (
            "texture path f32, exact filtering",
            &f32_textures,
            Filtering::Exact,
        ),
        (
            "texture path f32, 8-bit hardware weights",
            &f32_textures,
            Filtering::Hardware8Bit,
        ),
        (
            "texture path f16, exact filtering",
            &f16_textures,
            Filtering::Exact,
        ),
        (
            "texture path f16, 8-bit hardware weights",
            &f16_textures,
            Filtering::Hardware8Bit,
        ),
    ] {
        let path = StrandGen {
            textures,
            filtering,
        };
        let start = Instant::now();
        let points: Vec<Vec<DVec3>> = strands
            .iter()
            .map(|(block, coords, _)| {
                taus(layers_of(*block))
                    .map(|t| {
                        path.position(*block, coords.x as f32, coords.y as f32, t as f32)
                            .as_dvec3()
                    })
                    .collect()
            })
            .collect();
        let ms = start.elapsed().as_secs_f64() * 1e3 * 1e6 / vertex_total;
        let (max, mean) = compare(&points);
        let (vs_quadratics, _) = compare_with(&points, &quadratic_model);
        rows.push(CpuAccuracyRow {
            switch: name.into(),
            max_error: max,
            mean_error: mean,
            max_vs_quadratics: Some(vs_quadratics),
            ms_per_million: ms,
            texture_bytes_per_vertex: Some(
                textures.gpu_bytes() as f64 / mesh.vertex_count().max(1) as f64,
            ),
        });
    }
    rows.extend(vertex_count_rows(document, per_bundle));
    CpuAccuracy {
        rows,
        strands: reference.len(),
        bundle_width,
    }
}

/// Styled strands with 5, 9, 17, 33 and 65 vertices against a 257-vertex styled reference:
/// each reference vertex is compared with the coarse polyline at the same curve parameter.
fn vertex_count_rows(document: &Document, per_bundle: u32) -> Vec<CpuAccuracyRow> {
    let options = |log2: u32| StrandOptions {
        strands_per_bundle: per_bundle,
        vertices_log2: log2,
        ..StrandOptions::default()
    };
    let reference = generate(document, &options(8));
    let mut rows = Vec::new();
    for log2 in 2..=6u32 {
        let start = Instant::now();
        let coarse = generate(document, &options(log2));
        let vertices = coarse.iter().map(|s| s.points.len()).sum::<usize>() as f64;
        let ms = start.elapsed().as_secs_f64() * 1e3 * 1e6 / vertices;
        let (mut max, mut sum, mut count): (f64, f64, usize) = (0.0, 0.0, 0);
        for (fine, coarse) in reference.iter().zip(&coarse) {
            let segments = coarse.points.len() - 1;
            for (i, p) in fine.points.iter().enumerate() {
                let t = i as f64 / (fine.points.len() - 1) as f64 * segments as f64;
                let k = (t.floor() as usize).min(segments - 1);
                let q = coarse.points[k].lerp(coarse.points[k + 1], t - k as f64);
                let d = p.distance(q);
                max = max.max(d);
                sum += d;
                count += 1;
            }
        }
        rows.push(CpuAccuracyRow {
            switch: format!("styled, {} vertices vs 257", (1 << log2) + 1),
            max_error: max,
            mean_error: sum / count.max(1) as f64,
            max_vs_quadratics: None,
            ms_per_million: ms,
            texture_bytes_per_vertex: None,
        });
    }
    rows
}

/// Mean root-edge length of the bundles (1 without any).
pub(crate) fn mean_root_edge(mesh: &crate::model::mesh::HairMesh) -> f64 {
    let mut total = 0.0;
    let mut count = 0;
    for bundle in &mesh.bundles {
        let n = bundle.vertices.len();
        for i in 0..n {
            let a = mesh.columns[bundle.vertices[i] as usize].positions[0];
            let b = mesh.columns[bundle.vertices[(i + 1) % n] as usize].positions[0];
            total += a.distance(b);
            count += 1;
        }
    }
    if count == 0 {
        1.0
    } else {
        total / count as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::test_meshes::grid;

    /// The table's rows say what the switches do: the reference is exact, f32 exact
    /// filtering adds only rounding to the two-quadratic model, f16 and 8-bit weights add
    /// more, f16 halves the bytes, and more vertices per strand means less error.
    #[test]
    fn each_switch_is_measured_against_the_reference_with_its_cost() {
        let mut mesh = grid(3, 2, 3, 0.5);
        // Bend the columns so the curve switches differ.
        for (c, column) in mesh.columns.iter_mut().enumerate() {
            for (k, p) in column.positions.iter_mut().enumerate() {
                p.x += 0.2 * (k as f64).powi(2) * (1.0 + 0.1 * c as f64);
            }
        }
        crate::geometry::interior::place_interior(&mut mesh, None);
        let document = Document::new("bent grid", mesh);
        let measured = measure_cpu_accuracy(&document, 4);
        let row = |name: &str| {
            measured
                .rows
                .iter()
                .find(|r| r.switch == name)
                .unwrap_or_else(|| panic!("no row {name}"))
        };
        assert_eq!(measured.strands, 6 * 4);
        assert_eq!(measured.rows.len(), 3 + 4 + 5);
        assert_eq!(
            row("reference: f64, column blend, exact cubic").max_error,
            0.0
        );
        let quadratics = row("f64, column blend, two quadratics");
        assert!(quadratics.max_error > 0.0);
        let exact = row("texture path f32, exact filtering");
        let half = row("texture path f16, exact filtering");
        let hardware = row("texture path f32, 8-bit hardware weights");
        assert!(exact.max_vs_quadratics.expect("texture row") < 1e-6);
        assert!(half.max_vs_quadratics > exact.max_vs_quadratics);
        assert!(hardware.max_vs_quadratics > exact.max_vs_quadratics);
        let bytes = |r: &CpuAccuracyRow| r.texture_bytes_per_vertex.expect("texture row");
        assert!(bytes(half) < bytes(exact) && bytes(half) * 2.0 > bytes(exact) * 0.9);
        let styled: Vec<f64> = measured
            .rows
            .iter()
            .filter(|r| r.switch.starts_with("styled"))
            .map(|r| r.max_error)
            .collect();
        assert!(styled.windows(2).all(|w| w[1] <= w[0]), "{styled:?}");
        assert!(measured.rows.iter().all(|r| r.ms_per_million > 0.0));
        assert!(measured.bundle_width > 0.9 && measured.bundle_width < 1.1);
    }
}
