//! The Utah teapot (Newell 1975) as a scalp: 32 bicubic Bézier patches tessellated into
//! quads and welded along patch borders. Degenerate patch edges (the lid knob and the
//! bottom centre collapse a patch edge to a point) become triangles after welding.

use glam::{DVec2, DVec3};

use crate::model::mesh::HairMesh;

/// A parse error naming the line.
#[derive(Debug, thiserror::Error)]
#[error("teapot data line {line}: {message}")]
pub struct TeapotError {
    pub line: usize,
    pub message: String,
}

/// Bézier patches: 16 control-point indices each (4×4, row-major) and the points.
#[derive(Clone, Debug)]
pub struct Patches {
    pub patches: Vec<[usize; 16]>,
    pub points: Vec<DVec3>,
}

/// Parses the text format of `shared/data/utah_teapot.txt`: `#` comments, `patches N` then
/// N rows of 16 indices, `points M` then M rows of `x y z`.
pub fn parse(text: &str) -> Result<Patches, TeapotError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let header = |lines: &mut dyn Iterator<Item = (usize, &str)>,
                  word: &str|
     -> Result<usize, TeapotError> {
        let (line, text) = lines.next().ok_or(TeapotError {
            line: 0,
            message: format!("missing \"{word}\" header"),
        })?;
        let mut parts = text.split_whitespace();
        if parts.next() != Some(word) {
            return Err(TeapotError {
                line,
                message: format!("expected \"{word} N\""),
            });
        }
        parts
            .next()
            .and_then(|n| n.parse().ok())
            .ok_or(TeapotError {
                line,
                message: format!("bad count after \"{word}\""),
            })
    };
    let patch_count = header(&mut lines, "patches")?;
    let mut patches = Vec::with_capacity(patch_count);
    for _ in 0..patch_count {
        let (line, text) = lines.next().ok_or(TeapotError {
            line: 0,
            message: "missing patch rows".into(),
        })?;
        let values: Vec<usize> = text
            .split_whitespace()
            .map(|v| {
                v.parse().map_err(|_| TeapotError {
                    line,
                    message: format!("bad index \"{v}\""),
                })
            })
            .collect::<Result<_, _>>()?;
        let patch: [usize; 16] = values.try_into().map_err(|_| TeapotError {
            line,
            message: "a patch needs 16 indices".into(),
        })?;
        patches.push(patch);
    }
    let point_count = header(&mut lines, "points")?;
    let mut points = Vec::with_capacity(point_count);
    for _ in 0..point_count {
        let (line, text) = lines.next().ok_or(TeapotError {
            line: 0,
            message: "missing point rows".into(),
        })?;
        let values: Vec<f64> = text
            .split_whitespace()
            .map(|v| {
                v.parse().map_err(|_| TeapotError {
                    line,
                    message: format!("bad number \"{v}\""),
                })
            })
            .collect::<Result<_, _>>()?;
        let [x, y, z] = values[..] else {
            return Err(TeapotError {
                line,
                message: "a point needs 3 numbers".into(),
            });
        };
        let p = DVec3::new(x, y, z);
        if !p.is_finite() {
            return Err(TeapotError {
                line,
                message: "point is not finite".into(),
            });
        }
        points.push(p);
    }
    for (i, patch) in patches.iter().enumerate() {
        if let Some(&bad) = patch.iter().find(|&&v| v >= points.len()) {
            return Err(TeapotError {
                line: 0,
                message: format!(
                    "patch {i} uses point {bad}, but there are {} points",
                    points.len()
                ),
            });
        }
    }
    Ok(Patches { patches, points })
}

fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t]
}

/// Tessellates every patch into `n × n` quads, welds coincident vertices (tolerance
/// `1e-9` of the model size), turns quads with a collapsed edge into triangles and drops
/// fully collapsed ones. The teapot's z-up data is rotated to y-up. uv is the patch
/// parameter mapped into a 8×4 atlas of the 32 patches.
pub(crate) fn tessellate(patches: &Patches, n: usize) -> HairMesh {
    let n = n.max(1);
    let mut positions: Vec<DVec3> = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let mut uvs: Vec<Vec<DVec2>> = Vec::new();
    let scale = patches
        .points
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max)
        .max(1.0);
    let tolerance = 1e-9 * scale;
    let mut lookup: std::collections::HashMap<(i64, i64, i64), u32> =
        std::collections::HashMap::new();
    let mut vertex = |p: DVec3, positions: &mut Vec<DVec3>| {
        let q = (p / tolerance).round();
        let key = (q.x as i64, q.y as i64, q.z as i64);
        *lookup.entry(key).or_insert_with(|| {
            positions.push(p);
            (positions.len() - 1) as u32
        })
    };
    for (index, patch) in patches.patches.iter().enumerate() {
        let control: Vec<DVec3> = patch.iter().map(|&i| patches.points[i]).collect();
        let eval = |u: f64, v: f64| {
            let bu = bernstein(u);
            let bv = bernstein(v);
            let mut p = DVec3::ZERO;
            for (r, br) in bu.iter().enumerate() {
                for (c, bc) in bv.iter().enumerate() {
                    p += control[r * 4 + c] * (br * bc);
                }
            }
            // z-up to y-up.
            DVec3::new(p.x, p.z, -p.y)
        };
        let atlas = DVec2::new((index % 8) as f64, (index / 8) as f64);
        let mut grid = vec![0u32; (n + 1) * (n + 1)];
        for i in 0..=n {
            for j in 0..=n {
                let p = eval(i as f64 / n as f64, j as f64 / n as f64);
                grid[i * (n + 1) + j] = vertex(p, &mut positions);
            }
        }
        for i in 0..n {
            for j in 0..n {
                // Winding chosen so faces point out of the teapot body.
                let corners = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)];
                let mut face: Vec<u32> = Vec::new();
                let mut face_uv: Vec<DVec2> = Vec::new();
                for (a, b) in corners {
                    let v = grid[a * (n + 1) + b];
                    if face.last() != Some(&v) && face.first() != Some(&v) {
                        face.push(v);
                        face_uv.push(
                            (atlas + DVec2::new(b as f64, a as f64) / n as f64)
                                / DVec2::new(8.0, 4.0),
                        );
                    }
                }
                if face.len() >= 3 {
                    faces.push(face);
                    uvs.push(face_uv);
                }
            }
        }
    }
    HairMesh::from_scalp(&positions, &faces, &uvs)
}
