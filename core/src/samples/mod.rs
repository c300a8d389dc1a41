//! The bundled sample projects, built by code from the originals in `shared/data/`:
//!
//! - the real head scan "Infinite, 3D Head Scan" by Lee Perry-Smith (CC BY 3.0, based on a
//!   work at www.triplegangers.com), whose scalp region becomes the root layer of three
//!   hairstyles: short straight, long wavy and curly;
//! - the Utah teapot (Newell 1975, public domain), tessellated and furred.
//!
//! `cargo run -p hairloom-core --example make_samples` rewrites `assets/samples/`; the
//! builders are deterministic, so the files only change when this code does. Styling
//! parameters (wave, curl) are added by the styling stage; the samples here fix the hair
//! *shape* (the hair mesh).

pub mod teapot;

use glam::DVec3;

use crate::edit::{ExtrudeDirection, extrude};
use crate::geometry::{interior, uv};
use crate::io::import::{ImportError, ImportOptions, import_slice};
use crate::io::project::Project;
use crate::model::document::{BodyMesh, Document};
use crate::model::mesh::{HairMesh, VertexRef};
use crate::model::scene::{HairMaterial, Pigment};
use crate::model::styling::{
    Clump, Curl, Frizz, Hairline, LengthVariation, Noise, Stray, StylingParams, Wave,
};

/// The sample every tool opens when none is named (the editor embeds the same file).
pub const DEFAULT_SAMPLE: &str = "head_long_wavy.hairloom";

/// Where [`DEFAULT_SAMPLE`] lives in the source tree (`assets/samples/`), for the CLI's
/// benchmarks and measurements.
pub fn default_sample_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/samples")
        .join(DEFAULT_SAMPLE)
}

/// Attribution required by the head scan's licence; shipped in every head sample.
pub const HEAD_CREDIT: &str = "Head: \"Infinite, 3D Head Scan\" by Lee Perry-Smith, licensed under CC BY 3.0 \
(https://creativecommons.org/licenses/by/3.0/), based on a work at www.triplegangers.com.";
/// Attribution of the teapot geometry.
pub const TEAPOT_CREDIT: &str = "Utah teapot by Martin Newell (1975), public-domain geometry.";

/// Model units (metres) per unit of the head scan file: the scan measures about 4.9 units
/// from chin (y ≈ −0.9) to crown (y ≈ 3.98), and a head is about 0.22 m.
pub const HEAD_SCALE: f64 = 0.045;
/// Centre of the cranium in file units (the samples put it at the origin).
pub const HEAD_CRANIUM_CENTER: DVec3 = DVec3::new(-0.08, 1.9, 0.1);
/// Cranium ellipsoid radii in file units, used to keep sample hair outside the head.
pub const HEAD_CRANIUM_RADII: DVec3 = DVec3::new(1.75, 2.1, 2.05);

/// Which face of the head scan is scalp, from its centroid `p` and normal `n` in file units:
/// above a hairline plane that rises from the nape (y ≈ 0.3 at the back) to the forehead
/// (y ≈ 3.0 at the front), excluding the ears (far to the side and low) and faces that
/// point down.
pub(crate) fn is_head_scalp(p: DVec3, n: DVec3) -> bool {
    let above_hairline = p.y > 1.6 + 0.69 * p.z;
    let ear = p.x.abs() > 1.35 && p.y < 2.2;
    above_hairline && !ear && n.y > -0.35
}

/// The head scan: its scalp as a hair mesh with generated uv (metres, cranium at the
/// origin) and the whole scan as the body.
pub(crate) fn head_scalp(glb: &[u8]) -> Result<(HairMesh, BodyMesh), ImportError> {
    let options = ImportOptions {
        scale: 1.0,
        ..ImportOptions::default()
    };
    let mut imported = import_slice(glb, None, "LeePerrySmith.glb", &options)?;
    let keep: Vec<bool> = imported
        .faces
        .iter()
        .map(|face| {
            let p: Vec<DVec3> = face
                .iter()
                .map(|&v| imported.positions[v as usize])
                .collect();
            let centroid = p.iter().copied().sum::<DVec3>() / p.len() as f64;
            let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            is_head_scalp(centroid, normal)
        })
        .collect();
    let keep = largest_component(&imported.faces, &keep);
    for p in &mut imported.positions {
        *p = (*p - HEAD_CRANIUM_CENTER) * HEAD_SCALE;
    }
    let mut scalp = imported.to_hair_mesh(|f| keep[f]);
    // The scan's texture layout has seams across the scalp; a seamless projection from
    // above the crown, tilted back, gives smooth styling frames.
    let axis = DVec3::new(0.0, 1.0, -0.35).normalize();
    uv::generate_uv(&mut scalp, Some((DVec3::ZERO, axis, DVec3::X)));
    Ok((scalp, imported.to_body()))
}

/// Keeps only the largest edge-connected group of kept faces (drops stray islands).
fn largest_component(faces: &[Vec<u32>], keep: &[bool]) -> Vec<bool> {
    let mut faces_of_vertex: std::collections::HashMap<u32, Vec<usize>> =
        std::collections::HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        if keep[f] {
            for &v in face {
                faces_of_vertex.entry(v).or_default().push(f);
            }
        }
    }
    let mut label = vec![usize::MAX; faces.len()];
    let mut sizes = Vec::new();
    for start in 0..faces.len() {
        if !keep[start] || label[start] != usize::MAX {
            continue;
        }
        let id = sizes.len();
        let mut size = 0;
        let mut stack = vec![start];
        label[start] = id;
        while let Some(f) = stack.pop() {
            size += 1;
            for v in &faces[f] {
                for &g in &faces_of_vertex[v] {
                    if label[g] == usize::MAX {
                        label[g] = id;
                        stack.push(g);
                    }
                }
            }
        }
        sizes.push(size);
    }
    let best = (0..sizes.len()).max_by_key(|&i| sizes[i]);
    label.iter().map(|&l| Some(l) == best).collect()
}

/// A hairstyle's shape: how each layer moves away from the previous one.
#[derive(Clone, Copy, Debug)]
pub struct Growth {
    /// Number of layers.
    pub layers: u32,
    /// Length of each layer step in metres.
    pub step_m: f64,
    /// 0 = straight out along the normal, 1 = hanging straight down by the last layer.
    pub gravity: f64,
    /// Minimum clearance from the cranium ellipsoid at the tip, as a fraction of its size.
    pub volume: f64,
    /// Where the tips end: a haircut line, so hair from the crown is longer than hair from
    /// the nape (every column the same length would end in steps, one per root height).
    /// `None`: every layer step is `step_m`.
    pub cut: Option<Cut>,
}

/// A haircut line: the height the tips end at, from the back of the head to the face.
#[derive(Clone, Copy, Debug)]
pub struct Cut {
    /// Tip height (model y, metres) of hair from the back of the head.
    pub back_y_m: f64,
    /// Tip height of hair from the front hairline (face-framing layers are usually shorter).
    pub front_y_m: f64,
}

impl Cut {
    /// The tip height for hair rooted at `root` (model space, cranium at the origin, of
    /// front-to-back radius `radius_z_m`).
    fn tip_y_m(&self, root: DVec3, radius_z_m: f64) -> f64 {
        let front = (root.z / radius_z_m).clamp(-1.0, 1.0) * 0.5 + 0.5;
        self.back_y_m + (self.front_y_m - self.back_y_m) * front
    }

    /// The layer step that puts the tip of a column rooted at `root` on the cut line, found
    /// by bisection over `tip_y(step)` (tips fall lower as steps grow), within half and 1.6
    /// times `nominal_m`.
    fn step_for(
        &self,
        root: DVec3,
        radius_z_m: f64,
        nominal_m: f64,
        tip_y: impl Fn(f64) -> f64,
    ) -> f64 {
        let target_y = self.tip_y_m(root, radius_z_m);
        let (mut low, mut high) = (0.5 * nominal_m, 1.6 * nominal_m);
        for _ in 0..24 {
            let mid = 0.5 * (low + high);
            if tip_y(mid) > target_y {
                low = mid;
            } else {
                high = mid;
            }
        }
        0.5 * (low + high)
    }
}

/// Grows `scalp` into a hair mesh: the first layer along the root normals, later layers
/// bending toward −y by `growth.gravity` while staying outside the cranium ellipsoid
/// (`radii_m` around the origin). Interior vertices are then placed by the regular method.
pub fn grow(scalp: &HairMesh, growth: Growth, radii_m: DVec3) -> HairMesh {
    let all: Vec<u32> = (0..scalp.bundles.len() as u32).collect();
    let mut mesh = scalp.clone();
    for _ in 0..growth.layers {
        match extrude(
            &mesh,
            &all,
            ExtrudeDirection::AlongNormal {
                distance: growth.step_m,
            },
        ) {
            Ok(outcome) => mesh = outcome.mesh,
            Err(_) => return mesh,
        }
    }
    let normals = root_normals(&mesh);
    for (c, column) in mesh.columns.iter_mut().enumerate() {
        let (root, n) = (column.positions[0], normals[c]);
        let layers = column.positions.len() - 1;
        let step_m = growth.cut.map_or(growth.step_m, |cut| {
            cut.step_for(root, radii_m.z, growth.step_m, |step_m| {
                comb_column(root, n, layers, step_m, &growth, radii_m)
                    .last()
                    .map_or(root.y, |tip| tip.y)
            })
        });
        column.positions = comb_column(root, n, layers, step_m, &growth, radii_m);
    }
    if growth.cut.is_none() {
        interior::place_interior(&mut mesh, None);
    } else {
        // Hair cut to a line: every column is combed, the inner ones too, and they keep
        // their combed places (locked). A layer's interior placed from its rim (the
        // hairline) would not follow columns of different lengths: crown hair is longer
        // than nape hair, so rim-placed crown columns would cut across the head.
        lock_interior(&mut mesh, &all);
    }
    mesh.update_w();
    mesh
}

/// The first layer step as a fraction of the others (see [`comb_column`]).
const FIRST_LAYER_STEP: f64 = 0.3;

/// One column combed from its root (normal `n`): out along the normal, then bending toward
/// −y by `growth.gravity`, front hair swept back, each vertex kept outside the inflated
/// cranium ellipsoid.
fn comb_column(
    root: DVec3,
    n: DVec3,
    layers: usize,
    step_m: f64,
    growth: &Growth,
    radii_m: DVec3,
) -> Vec<DVec3> {
    let mut positions = Vec::with_capacity(layers + 1);
    positions.push(root);
    let mut previous = root;
    for k in 1..=layers {
        let fraction = k as f64 / growth.layers.max(1) as f64;
        // Hair leaves the scalp and lies down soon after: bend grows fast near the root.
        let bend = (growth.gravity * fraction.sqrt() * 1.3).min(1.0);
        let outward = DVec3::new(n.x, 0.0, n.z).normalize_or_zero() * 0.3;
        // Hair from the front of the scalp sweeps back over the crown instead of falling
        // over the face; long (cut) hair then turns to hang.
        let front = (root.z / radii_m.z).max(0.0);
        let hang = if growth.cut.is_some() {
            fraction.min(1.0)
        } else {
            0.0
        };
        // Crown hair with no side to fall to (root normal straight up) is combed back too.
        let sweep = DVec3::new(0.0, 0.0, -(0.6 + 3.0 * front) * (1.0 - hang));
        let down = (-DVec3::Y + outward * (1.0 - hang) + sweep).normalize();
        let direction = n.lerp(down, bend).normalize_or(n);
        // Hair leaves the scalp and lies down on it within a centimetre: a full first step
        // would lift the first layer off the scalp, and the strand's curve from the root to
        // it would cut through the curved scalp (a bald patch behind the hairline).
        let step_m = if k == 1 {
            FIRST_LAYER_STEP * step_m
        } else {
            step_m
        };
        let mut p = previous + direction * step_m;
        // Keep clear of the head: push out of the inflated cranium ellipsoid.
        let clearance = 1.0 + growth.volume * fraction.sqrt();
        let q = p / radii_m;
        if q.length() < clearance {
            p = q.normalize_or(DVec3::Y) * clearance * radii_m;
        }
        positions.push(p);
        previous = p;
    }
    positions
}

/// Pushes every hair-mesh vertex out of the body with the simulator's collision, holding
/// the grown style (no gravity, full style hold) for half a second of steps: the growth's
/// ellipsoid is only a stand-in for the scan's real surface (ears, neck and nape stick out of
/// it). Interior vertices keep their simulated places: re-placing them from the exterior
/// would put some back inside (the placement knows nothing of the body), so the next edit of
/// one of their layers may too — a limit of automatic interior placement on curved bodies.
pub(crate) fn keep_out_of_body(mesh: &HairMesh, body: &BodyMesh) -> HairMesh {
    use crate::model::motion::{HairPhysics, Motion};
    let motion = Motion {
        gravity_m_per_s2: 0.0,
        physics: HairPhysics {
            retention_root: 1.0,
            retention_tip: 0.6,
            volume_m_per_layer: 0.0,
            // Strands run between the hair-mesh vertices, curving as they go; the curves
            // are lifted clear afterwards (`lift_curves_out_of_body`), so the vertices may
            // rest close to the scalp.
            collision_margin_m: CURVE_CLEARANCE_M,
            ..HairPhysics::default()
        },
        ..Motion::default()
    };
    let mut sim = crate::simulate::HairSim::with_body(mesh, body, &motion, &[]);
    for _ in 0..30 {
        sim.step();
    }
    let mut settled = sim.posed_mesh();
    let sdf = crate::simulate::body_sdf::BodySdf::for_hair(body, &settled);
    lift_curves_out_of_body(&mut settled, &sdf, CURVE_CLEARANCE_M);
    settled.update_w();
    settled
}

/// How far the column curves are kept from the body between their vertices (see
/// [`lift_curves_out_of_body`]).
const CURVE_CLEARANCE_M: f64 = 0.003;

/// Lifts the strand curves clear of the body by `clearance_m`: the collision keeps hair-mesh
/// *vertices* out, but hair lying on a curved scalp sags under it between them — a long layer
/// step's curve is a chord under the curvature, and so is a strand between the corners of a
/// bundle that fans out over the crown. Each bundle is sampled where strands grow (its
/// corners, edge midpoints and centre, as the runtime blends the corner columns' cubics);
/// where a layer segment dips below the clearance, the corner vertices at both ends of that
/// segment move out along the field's gradient by the shortfall, weighted by how near each
/// end is to the dip. A few rounds settle it (a move changes neighbouring tangents). Roots
/// stay on the scalp.
fn lift_curves_out_of_body(
    mesh: &mut HairMesh,
    sdf: &crate::simulate::body_sdf::BodySdf,
    clearance_m: f64,
) {
    use crate::geometry::curve::{CurveDefinition, ReferenceStrand, SegmentForm};
    const ROUNDS: usize = 12;
    const SAMPLES_PER_SEGMENT: usize = 8;
    for _ in 0..ROUNDS {
        // The largest push each (column, layer) vertex is asked for this round.
        let mut pushes: Vec<Vec<DVec3>> = mesh
            .columns
            .iter()
            .map(|c| vec![DVec3::ZERO; c.positions.len()])
            .collect();
        // A removed bundle grows no strands to lift.
        for (b, bundle) in mesh.bundles.iter().enumerate().filter(|(_, b)| !b.removed) {
            let corners = bundle.vertices.len().min(4);
            let mut samples: Vec<[f64; 4]> = Vec::with_capacity(2 * corners + 1);
            for i in 0..corners {
                let mut corner = [0.0; 4];
                corner[i] = 1.0;
                samples.push(corner);
                let mut edge = [0.0; 4];
                edge[i] = 0.5;
                edge[(i + 1) % corners] = 0.5;
                samples.push(edge);
            }
            samples.push(std::array::from_fn(|i| {
                if i < corners {
                    1.0 / corners as f64
                } else {
                    0.0
                }
            }));
            for weights in samples {
                let Some(strand) = ReferenceStrand::with_weights(mesh, b, weights) else {
                    continue;
                };
                for k in 0..strand.layers {
                    // The strand grows out of the scalp: the clearance it needs ramps up over
                    // the first half of the first layer.
                    let needed_m = |t: f64| clearance_m * (2.0 * (k as f64 + t)).min(1.0);
                    let worst = (1..SAMPLES_PER_SEGMENT)
                        .map(|i| {
                            let t = i as f64 / SAMPLES_PER_SEGMENT as f64;
                            let p = strand.point(
                                k as f64 + t,
                                CurveDefinition::ColumnBlend,
                                SegmentForm::ExactCubic,
                            );
                            (t, p, needed_m(t) - sdf.distance_m(p))
                        })
                        .max_by(|a, b| a.2.total_cmp(&b.2));
                    let Some((t, p, shortfall_m)) = worst else {
                        continue;
                    };
                    // (NaN, a point off the field, is no shortfall either.)
                    if shortfall_m.is_nan() || shortfall_m <= 0.0 {
                        continue;
                    }
                    let out = sdf.gradient(p) * shortfall_m;
                    // Ends moved by a₀ and a₁ move the dip by about a₀(1−t) + a₁t: weights
                    // (1−t, t) over the sum of squares of the movable ones (not the root)
                    // make that the whole shortfall.
                    let ends = [(k, 1.0 - t), (k + 1, t)];
                    let norm: f64 = ends
                        .iter()
                        .filter(|(layer, _)| *layer > 0)
                        .map(|(_, along)| along * along)
                        .sum();
                    for (layer, along) in ends {
                        if layer == 0 {
                            continue;
                        }
                        for (i, &column) in bundle.vertices.iter().enumerate().take(corners) {
                            if weights[i] > 0.0 {
                                let slot = &mut pushes[column as usize][layer];
                                let push = out * (along / norm);
                                if push.length() > slot.length() {
                                    *slot = push;
                                }
                            }
                        }
                    }
                }
            }
        }
        let mut moved = false;
        for (column, column_pushes) in mesh.columns.iter_mut().zip(pushes) {
            for (position, push) in column.positions.iter_mut().zip(column_pushes) {
                if push != DVec3::ZERO {
                    *position += push;
                    moved = true;
                }
            }
        }
        if !moved {
            break;
        }
    }
}

/// Area-weighted root-layer vertex normals.
fn root_normals(mesh: &HairMesh) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; mesh.columns.len()];
    for bundle in &mesh.bundles {
        let n = bundle.vertices.len();
        for i in 0..n {
            let at = |k: usize| mesh.columns[bundle.vertices[k % n] as usize].positions[0];
            let normal = (at(i + 1) - at(i)).cross(at(i + n - 1) - at(i));
            normals[bundle.vertices[i] as usize] += normal;
        }
    }
    normals
        .into_iter()
        .map(|n| n.normalize_or(DVec3::Y))
        .collect()
}

/// The head hairstyles: a short crop, wavy shoulder-length hair, curls and long straight
/// hair (the last draped: see [`DRAPED_STYLES`]).
pub const HEAD_STYLES: [(&str, Growth); 4] = [
    (
        "head_short_straight",
        Growth {
            layers: 2,
            step_m: 0.012,
            gravity: 1.0,
            volume: 0.09,
            cut: None,
        },
    ),
    (
        "head_long_wavy",
        Growth {
            layers: 6,
            step_m: 0.045,
            gravity: 1.0,
            volume: 0.06,
            cut: Some(Cut {
                back_y_m: -0.17,
                front_y_m: -0.13,
            }),
        },
    ),
    (
        "head_curly",
        Growth {
            layers: 4,
            step_m: 0.025,
            gravity: 0.65,
            volume: 0.16,
            cut: None,
        },
    ),
    (
        "head_long_straight",
        Growth {
            layers: 7,
            step_m: 0.05,
            gravity: 1.0,
            volume: 0.03,
            cut: Some(Cut {
                back_y_m: -0.26,
                front_y_m: -0.2,
            }),
        },
    ),
];

/// The styles whose combed mesh is then draped (`simulate::drape`): the hair falls under
/// gravity onto the head and shoulders and settles, so long hair rests where it lands
/// instead of where the comb put it. (The curls are draped too, with their front held: see
/// `head_projects`.)
pub const DRAPED_STYLES: [&str; 1] = ["head_long_straight"];

/// The styling of each head sample.
pub(crate) fn head_style(name: &str) -> StylingParams {
    let base = StylingParams {
        noise: Noise {
            amplitude_m: 0.0015,
            frequency_per_m: 12.0,
            octaves: 2,
        },
        clump: Clump {
            strength: 0.35,
            clumps_per_uv: 60.0,
            radius_m: 0.006,
            tightening: 1.5,
            sub_strength: 0.5,
            sub_clumps_per_uv: 240.0,
            sub_radius_m: 0.002,
        },
        // Soft ends: strands end anywhere in the last quarter of their bundle.
        length: LengthVariation { fraction: 0.25 },
        // A few flyaways leave the mass.
        stray: Stray {
            fraction: 0.04,
            // Drifts are symmetric in (û, v̂): more than 8 mm reaches under the skin where
            // the hair lies on it (the temples).
            amplitude_m: 0.008,
            frequency_per_m: 6.0,
            length_min: 0.4,
        },
        // Hair thins out and grows short over the last 1.5 cm before the border (the
        // hairline, the nape, around the ears) instead of ending in a hard comb line.
        hairline: Hairline {
            width_m: 0.015,
            edge_density: 0.3,
            edge_length: 0.5,
        },
        ..StylingParams::default()
    };
    match name {
        // Straight and sleek: less noise, tighter clumps.
        "head_long_straight" | "head_ponytail" => StylingParams {
            noise: Noise {
                amplitude_m: 0.001,
                frequency_per_m: 8.0,
                octaves: 2,
            },
            clump: Clump {
                strength: 0.45,
                clumps_per_uv: 70.0,
                radius_m: 0.005,
                tightening: 2.0,
                sub_strength: 0.5,
                sub_clumps_per_uv: 280.0,
                sub_radius_m: 0.0015,
            },
            length: LengthVariation { fraction: 0.15 },
            ..base
        },
        "head_long_wavy" => StylingParams {
            wave: Wave {
                amplitude_m: 0.013,
                frequency_per_m: 7.0,
                direction_rad: 0.0,
                phase_spread: 0.1,
                ramp_in_m: 0.05,
                // Each lock waves as one, a little out of step with its neighbours: the
                // crests (and the highlights on them) run as bands across the head, broken
                // at the locks. Locks at any phase drew a patchwork of pale blotches.
                clump_coherence: 0.9,
                lock_phase_spread: 0.2,
            },
            ..base
        },
        "head_curly" => StylingParams {
            // Ringlets: the strands of a lock share its helix and gather early (a clump
            // cell is about 9 mm on the scalp: 0.55 m per uv).
            curl: Curl {
                radius_m: 0.006,
                turns_per_m: 45.0,
                ramp_in_m: 0.01,
                radius_jitter: 0.15,
                clump_coherence: 1.0,
                radius_tip_scale: 0.8,
                rate_tip_scale: 1.2,
            },
            noise: Noise {
                amplitude_m: 0.0008,
                frequency_per_m: 12.0,
                octaves: 2,
            },
            frizz: Frizz {
                amplitude_m: 0.0008,
                frequency_per_m: 150.0,
                fraction: 0.1,
            },
            clump: Clump {
                strength: 0.85,
                clumps_per_uv: 60.0,
                radius_m: 0.009,
                tightening: 0.5,
                sub_strength: 0.3,
                sub_clumps_per_uv: 240.0,
                sub_radius_m: 0.0023,
            },
            ..base
        },
        _ => base,
    }
}

/// The fibre material of each head sample: three hair colours from melanin, so the samples
/// show what the material does.
pub(crate) fn head_material(name: &str) -> HairMaterial {
    let base = HairMaterial::default();
    match name {
        // Auburn: little eumelanin, much pheomelanin.
        "head_curly" => HairMaterial {
            pigment: Pigment::Melanin {
                eumelanin: 0.2,
                pheomelanin: 0.9,
            },
            ..base
        },
        // Medium brown, smoother than the default: the waves tilt the fibres through the
        // primary highlight's angle, and a narrow lobe keeps it on the crests as bands (at
        // 0.3 it greyed most of the back).
        "head_long_wavy" => HairMaterial {
            longitudinal_roughness: 0.2,
            ..base
        },
        // Light brown.
        "head_long_straight" => HairMaterial {
            pigment: Pigment::Melanin {
                eumelanin: 0.55,
                pheomelanin: 0.35,
            },
            longitudinal_roughness: 0.2,
            ..base
        },
        // Dark brown.
        "head_ponytail" => HairMaterial {
            pigment: Pigment::Melanin {
                eumelanin: 1.4,
                pheomelanin: 0.3,
            },
            longitudinal_roughness: 0.22,
            ..base
        },
        // Near black, a little smoother.
        "head_short_straight" => HairMaterial {
            pigment: Pigment::Melanin {
                eumelanin: 2.5,
                pheomelanin: 0.2,
            },
            longitudinal_roughness: 0.25,
            ..base
        },
        _ => base,
    }
}

/// A ponytail: all hair gathered over the scalp to a tie at the back of the head, then a
/// tail hanging from it.
#[derive(Clone, Copy, Debug)]
pub struct Ponytail {
    /// Layers from the scalp to the tie (the hair lying on the scalp).
    pub gather_layers: u32,
    /// Layers of the tail below the tie.
    pub tail_layers: u32,
    pub tail_step_m: f64,
    /// Where the tie sits: a direction from the cranium's centre in the cranium ellipsoid's
    /// unit-sphere space (x right, y up, z front).
    pub tie_direction: DVec3,
    /// The tie's radius as an angle on that unit sphere.
    pub tie_radius_rad: f64,
}

/// The ponytail sample: gathered a little above the occipital bone, a 30 cm tail.
pub const HEAD_PONYTAIL: (&str, Ponytail) = (
    "head_ponytail",
    Ponytail {
        gather_layers: 6,
        tail_layers: 6,
        tail_step_m: 0.05,
        tie_direction: DVec3::new(0.0, 0.0, -1.0),
        tie_radius_rad: 0.3,
    },
);

/// Gathers `scalp` into a ponytail: each column runs over the cranium ellipsoid (`radii_m`)
/// along the great circle from its root to its own place in the tie — an azimuthal
/// equidistant map of the scalp around the tie, so neighbouring roots stay neighbours and no
/// bundle folds over — lifted a little more the farther it came (front hair lies over back
/// hair at the tie), then hangs from the tie as a tapering tail. Every vertex is placed, so
/// interior vertices are locked where they were put, as for cut hair.
pub fn gather_ponytail(scalp: &HairMesh, tail: Ponytail, radii_m: DVec3) -> HairMesh {
    let all: Vec<u32> = (0..scalp.bundles.len() as u32).collect();
    let mut mesh = scalp.clone();
    for _ in 0..tail.gather_layers + tail.tail_layers {
        match extrude(
            &mesh,
            &all,
            ExtrudeDirection::AlongNormal { distance: 0.01 },
        ) {
            Ok(outcome) => mesh = outcome.mesh,
            Err(_) => return mesh,
        }
    }
    let tie = tail.tie_direction.normalize();
    let e1 = DVec3::X.reject_from_normalized(tie).normalize();
    let e2 = tie.cross(e1);
    // Each root's angle from the tie and its azimuth about it.
    let polar = |root: DVec3| {
        let s = (root / radii_m).normalize_or(tie);
        let angle = s.dot(tie).clamp(-1.0, 1.0).acos();
        (angle, s.dot(e2).atan2(s.dot(e1)))
    };
    let farthest = mesh
        .columns
        .iter()
        .map(|c| polar(c.positions[0]).0)
        .fold(1e-6, f64::max);
    let on_sphere = |angle: f64, azimuth: f64| {
        tie * angle.cos() + (e1 * azimuth.cos() + e2 * azimuth.sin()) * angle.sin()
    };
    let gather = tail.gather_layers as usize;
    let tie_centre = tie * radii_m * 1.06;
    for column in &mut mesh.columns {
        let root = column.positions[0];
        let (angle, azimuth) = polar(root);
        let reach = angle / farthest;
        let start = (root / radii_m).normalize_or(tie);
        let end = on_sphere(tail.tie_radius_rad * reach.sqrt(), azimuth);
        let mut positions = vec![root];
        for k in 1..=gather {
            let f = k as f64 / gather as f64;
            let direction = slerp(start, end, f);
            // Lifted off the ellipsoid a little, more the farther the hair has come.
            let lift = 1.0 + 0.04 * reach * f;
            positions.push(direction * radii_m * lift);
        }
        // The tail: out from the tie, turning down, tapering.
        let offset = positions[gather] - tie_centre;
        let mut centre = tie_centre;
        for j in 1..=tail.tail_layers as usize {
            let turn = (j as f64 / 2.0).min(1.0);
            let direction = (tie * (1.0 - turn) - DVec3::Y * (0.3 + turn)).normalize();
            centre += direction * tail.tail_step_m;
            let taper = 1.0 - 0.3 * j as f64 / tail.tail_layers as f64;
            // The tie's cross-section turns with the tail, so the tail stays round
            // instead of flattening into a ribbon as it turns down.
            let turned = glam::DQuat::from_rotation_arc(tie, direction) * offset;
            positions.push(centre + turned * taper);
        }
        column.positions = positions;
    }
    lock_interior(&mut mesh, &all);
    mesh.update_w();
    mesh
}

/// Locks the interior vertices of `bundles` where a builder placed them (automatic
/// placement from each layer's rim would not follow a comb that placed every column).
fn lock_interior(mesh: &mut HairMesh, bundles: &[u32]) {
    let topology = crate::model::mesh::Topology::build(mesh);
    let interior: Vec<VertexRef> = crate::edit::select::bundle_vertices_above_root(mesh, bundles)
        .into_iter()
        .filter(|v| mesh.is_interior(&topology, v.column as usize, v.layer as usize))
        .collect();
    mesh.set_locked(&interior, true);
}

/// Spherical interpolation between unit vectors (linear where they nearly coincide).
fn slerp(a: DVec3, b: DVec3, t: f64) -> DVec3 {
    let angle = a.dot(b).clamp(-1.0, 1.0).acos();
    if angle < 1e-6 {
        return a.lerp(b, t).normalize_or(a);
    }
    (a * ((1.0 - t) * angle).sin() + b * (t * angle).sin()) / angle.sin()
}

/// Builds the head sample projects from the scan's GLB bytes.
pub fn head_projects(glb: &[u8]) -> Result<Vec<(String, Project)>, ImportError> {
    let (scalp, body) = head_scalp(glb)?;
    let radii_m = HEAD_CRANIUM_RADII * HEAD_SCALE;
    // Lets the hair fall and settle, keeping `held` where it is, then lifts the curves
    // between vertices clear of the body as for every sample. A drape that cannot run (it
    // only refuses an empty or invalid mesh, which the builders never make) leaves the mesh
    // as it was: still a valid sample.
    let drape = |mesh: &mut HairMesh, held: &[VertexRef]| {
        if let Ok((outcome, _)) = crate::simulate::drape(mesh, &body, &[], held) {
            *mesh = outcome.mesh;
            let sdf = crate::simulate::body_sdf::BodySdf::for_hair(&body, mesh);
            lift_curves_out_of_body(mesh, &sdf, CURVE_CLEARANCE_M);
            mesh.update_w();
        }
    };
    let mut meshes: Vec<(&str, HairMesh)> = HEAD_STYLES
        .iter()
        .map(|(name, growth)| {
            let shaped = grow(&scalp, *growth, radii_m);
            let mut mesh = keep_out_of_body(&shaped, &body);
            if DRAPED_STYLES.contains(name) {
                drape(&mut mesh, &[]);
            }
            if *name == "head_curly" {
                // The front's hair keeps its sweep back off the face (held, like vertices an
                // artist locked); the rest falls and settles instead of standing out as a bowl.
                let held: Vec<VertexRef> = mesh
                    .columns
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| c.positions[0].z > 0.35 * radii_m.z)
                    .flat_map(|(c, column)| {
                        (0..column.positions.len() as u32).map(move |layer| VertexRef {
                            column: c as u32,
                            layer,
                        })
                    })
                    .collect();
                drape(&mut mesh, &held);
            }
            (*name, mesh)
        })
        .collect();
    // The ponytail: gathered, kept out of the head, and the tail draped from the tie (the
    // gathered layers held, like vertices an artist locked).
    let (name, ponytail) = HEAD_PONYTAIL;
    let mut mesh = keep_out_of_body(&gather_ponytail(&scalp, ponytail, radii_m), &body);
    let held: Vec<VertexRef> = (0..mesh.columns.len() as u32)
        .flat_map(|column| {
            (0..=ponytail.gather_layers).map(move |layer| VertexRef { column, layer })
        })
        .collect();
    drape(&mut mesh, &held);
    meshes.push((name, mesh));
    Ok(meshes
        .into_iter()
        .map(|(name, mesh)| {
            let mut document = Document::new(name, mesh);
            document.styling.global = head_style(name);
            document.scene.material = head_material(name);
            document.source = HEAD_CREDIT.to_string();
            document.body = body.clone();
            (name.to_string(), Project::new(document))
        })
        .collect())
}

/// The furry teapot: the teapot tessellated 3×3 per patch, scaled to about 0.3 m across,
/// with one layer of short fur. (One layer: the teapot is made of open patches whose few
/// rims say little about a middle layer far from them, see `interior`.)
pub fn teapot_project(teapot_text: &str) -> Result<Project, crate::samples::teapot::TeapotError> {
    let patches = crate::samples::teapot::parse(teapot_text)?;
    let mut scalp = crate::samples::teapot::tessellate(&patches, 3);
    let scale = 0.3 / 6.4; // the teapot is about 6.4 units from spout to handle
    for column in &mut scalp.columns {
        column.positions[0] *= scale;
    }
    let body = BodyMesh {
        positions: scalp
            .columns
            .iter()
            .map(|c| c.positions[0].as_vec3().to_array())
            .collect(),
        triangles: scalp
            .bundles
            .iter()
            .flat_map(|b| {
                let v = &b.vertices;
                let mut t = vec![[v[0], v[1], v[2]]];
                if v.len() == 4 {
                    t.push([v[0], v[2], v[3]]);
                }
                t
            })
            .collect(),
    };
    let all: Vec<u32> = (0..scalp.bundles.len() as u32).collect();
    let mut mesh = scalp;
    if let Ok(outcome) = extrude(
        &mesh,
        &all,
        ExtrudeDirection::AlongNormal { distance: 0.012 },
    ) {
        mesh = outcome.mesh;
    }
    let mut document = Document::new("teapot_fur", mesh);
    document.styling.global = StylingParams {
        frizz: Frizz {
            amplitude_m: 0.002,
            frequency_per_m: 200.0,
            fraction: 0.6,
        },
        length: LengthVariation { fraction: 0.4 },
        ..StylingParams::default()
    };
    // Light, rough fur.
    document.scene.material = HairMaterial {
        pigment: Pigment::Melanin {
            eumelanin: 0.12,
            pheomelanin: 0.15,
        },
        longitudinal_roughness: 0.4,
        azimuthal_roughness: 0.5,
        ..HairMaterial::default()
    };
    // Seed 002's subject: strands near, shells and fins far.
    document.scene.effects.fur = crate::model::scene::Fur::ShellsFins;
    document.source = TEAPOT_CREDIT.to_string();
    document.body = body;
    Ok(Project::new(document))
}

/// Number of columns whose tip lies inside the cranium ellipsoid (`radii_m` around the
/// origin); the samples keep hair outside the head, and tests check it.
pub fn tips_inside_ellipsoid(mesh: &HairMesh, radii_m: DVec3) -> usize {
    mesh.columns
        .iter()
        .filter(|c| c.positions.len() > 1)
        .filter(|c| {
            c.positions
                .last()
                .is_some_and(|p| (*p / radii_m).length() < 0.98)
        })
        .count()
}

/// A scalp of `nx × ny` quads over the unit square: `position(s, t)` places the vertex at
/// grid coordinates `s, t ∈ [0, 1]`, and its uv is `(s, t)`. Used by tests and benchmarks.
pub fn grid_scalp(nx: usize, ny: usize, position: impl Fn(f64, f64) -> DVec3) -> HairMesh {
    let (nx, ny) = (nx.max(1), ny.max(1));
    let index = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let coords = |v: u32| {
        let v = v as usize;
        (
            (v % (nx + 1)) as f64 / nx as f64,
            (v / (nx + 1)) as f64 / ny as f64,
        )
    };
    let positions: Vec<DVec3> = (0..(nx + 1) * (ny + 1))
        .map(|v| {
            let (s, t) = coords(v as u32);
            position(s, t)
        })
        .collect();
    let mut faces = Vec::with_capacity(nx * ny);
    let mut uvs = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let face = vec![
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            ];
            uvs.push(
                face.iter()
                    .map(|&v| {
                        let (s, t) = coords(v);
                        glam::DVec2::new(s, t)
                    })
                    .collect(),
            );
            faces.push(face);
        }
    }
    HairMesh::from_scalp(&positions, &faces, &uvs)
}

/// Gives every bundle `layers` layers whose columns go straight up from the root by `step`
/// per layer (a quick hair mesh for tests; real tools extrude along normals).
pub fn straight_layers(mut mesh: HairMesh, layers: u32, step: DVec3) -> HairMesh {
    for column in &mut mesh.columns {
        let root = column.positions[0];
        column.positions = (0..=layers).map(|k| root + step * k as f64).collect();
    }
    for bundle in &mut mesh.bundles {
        bundle.layers = layers;
    }
    mesh.update_w();
    mesh
}

/// A UV-sphere body of `radius_m` around the origin, outward-facing: a stand-in head for
/// tests and benchmarks of collision and simulation.
pub fn sphere_body(radius_m: f64, rings: u32, segments: u32) -> BodyMesh {
    let (rings, segments) = (rings.max(2), segments.max(3));
    let mut positions = Vec::new();
    for r in 0..=rings {
        let theta = std::f64::consts::PI * r as f64 / rings as f64;
        for s in 0..segments {
            let phi = std::f64::consts::TAU * s as f64 / segments as f64;
            let p = DVec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            positions.push((p * radius_m).as_vec3().to_array());
        }
    }
    let mut triangles = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let a = r * segments + s;
            let b = r * segments + (s + 1) % segments;
            let (c, d) = (a + segments, b + segments);
            triangles.push([a, b, c]);
            triangles.push([b, d, c]);
        }
    }
    BodyMesh {
        positions,
        triangles,
    }
}

/// A cap of hair on [`sphere_body`]: an `n × n` grid of quads over the sphere's crown
/// (within `cap_rad` of the top), each column going straight out along its root's normal by
/// `step_m` per layer. The simulator's test and benchmark subject.
pub fn sphere_cap(radius_m: f64, cap_rad: f64, n: usize, layers: u32, step_m: f64) -> HairMesh {
    let direction = |s: f64, t: f64| {
        let (a, b) = ((2.0 * s - 1.0) * cap_rad, (2.0 * t - 1.0) * cap_rad);
        DVec3::new(a.sin(), 1.0, -b.sin()).normalize()
    };
    let mut mesh = grid_scalp(n, n, |s, t| direction(s, t) * radius_m);
    for column in &mut mesh.columns {
        let root = column.positions[0];
        let normal = root.normalize_or(DVec3::Y);
        column.positions = (0..=layers)
            .map(|k| root + normal * (step_m * k as f64))
            .collect();
    }
    for bundle in &mut mesh.bundles {
        bundle.layers = layers;
    }
    interior::place_interior(&mut mesh, None);
    mesh.update_w();
    mesh
}
