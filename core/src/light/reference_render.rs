//! The CPU reference renderer: a path tracer that every GPU lighting configuration is
//! measured against (`hairloom bench shading`, ꟻLIP).
//!
//! - Geometry: the f64 reference strands as fibres (one cylinder per segment, radius from the
//!   same width and root-to-tip taper the GPU ribbons use) and the body's triangles, in one
//!   BVH (`obvhs`, PLOC-built: a well-kept crate, so no hand-written builder).
//! - Light transport: the same fibre model as the GPU ([`HairBsdf`], importance-sampled), a
//!   Lambertian body, the scene's lights with exact (ray-traced) shadows, the ambient light as
//!   a uniform environment reached by escaping paths, many bounces with Russian roulette.
//! - Output: radiance × exposure → the same ACES fit and sRGB encoding as the GPU picture; rays
//!   that leave the scene at once show the background.
//! - Deterministic: every sample's random numbers come from its pixel and index, so the image
//!   does not depend on the thread count. Multi-threaded over rows. Bounded in time: passes of
//!   samples stop once `max_seconds` is spent (the image says how many samples it holds).

use std::time::{Duration, Instant};

use glam::{DMat3, DVec3};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::ray::{Ray, RayHit};

use crate::light::hair_bsdf::HairBsdf;
use crate::light::material::{Fibre, strand_shading_random};
use crate::light::{linear_to_srgb, tonemap};
use crate::model::document::BodyMesh;
use crate::model::root_maps::PaintedColour;
use crate::model::scene::Scene;
use crate::strands::random::SplitMix64;

/// Strands as polylines for the reference: `points[first..first + count]` per strand.
#[derive(Clone, Debug, Default)]
pub struct Fibres {
    pub points: Vec<DVec3>,
    pub strands: Vec<FibreStrand>,
    /// Fibre width at the root (the GPU ribbon width); it tapers to 40% at the tip as the
    /// ribbons do.
    pub width_m: f64,
}

#[derive(Clone, Copy, Debug)]
pub struct FibreStrand {
    pub first: u32,
    pub count: u32,
    /// The strand's root index (bundle × roots per bundle + sample), for its random
    /// absorption variation.
    pub root: u32,
    /// The colour map at the strand's root (none: the material's colour), as the GPU's
    /// per-root colours hold it.
    pub paint: PaintedColour,
}

impl Fibres {
    pub fn push(&mut self, points: &[DVec3], root: u32) {
        self.push_painted(points, root, PaintedColour::NONE);
    }

    /// A strand whose root lies under the colour map's `paint`.
    pub fn push_painted(&mut self, points: &[DVec3], root: u32, paint: PaintedColour) {
        if points.len() < 2 {
            return;
        }
        self.strands.push(FibreStrand {
            first: self.points.len() as u32,
            count: points.len() as u32,
            root,
            paint,
        });
        self.points.extend_from_slice(points);
    }
}

/// The camera of a reference picture: the GPU camera's perspective (right-handed, Y up).
#[derive(Clone, Copy, Debug)]
pub struct ReferenceCamera {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    pub fov_y_rad: f64,
    pub width: u32,
    pub height: u32,
}

#[derive(Clone, Copy, Debug)]
pub struct ReferenceSettings {
    pub samples_per_pixel: u32,
    /// Scattering events along a path (beyond the first hit).
    pub max_bounces: u32,
    pub seed: u64,
    /// 0: every core.
    pub threads: usize,
    /// Stop after the pass that passes this budget (at least one pass always runs).
    pub max_seconds: f64,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        Self {
            samples_per_pixel: 64,
            max_bounces: 24,
            seed: 1,
            threads: 0,
            max_seconds: 600.0,
        }
    }
}

/// A finished reference picture.
#[derive(Clone, Debug)]
pub struct ReferenceImage {
    pub width: u32,
    pub height: u32,
    /// RGBA8, sRGB, rows top first (what the GPU read-back gives).
    pub pixels: Vec<u8>,
    pub samples_per_pixel: u32,
    pub seconds: f64,
    /// Rays traced (camera, bounce and shadow rays).
    pub rays: u64,
    /// Segments and triangles in the BVH.
    pub primitives: usize,
}

enum Primitive {
    Segment {
        a: DVec3,
        b: DVec3,
        radius: f64,
        strand: u32,
        /// Fraction along the strand at `a` and `b`.
        along: [f64; 2],
    },
    /// A body triangle: its corners and their smooth shading normals (zero where a vertex
    /// has none), as the GPU's body pass interpolates them.
    Triangle {
        corners: [DVec3; 3],
        normals: [DVec3; 3],
    },
}

struct Hit {
    t: f64,
    primitive: usize,
    /// Segment: parameter along the axis (metres from `a`).
    s: f64,
}

struct World<'a> {
    primitives: Vec<Primitive>,
    /// `None` when there is nothing to hit (no fibre, no body).
    bvh: Option<Bvh2>,
    fibres: &'a Fibres,
    scene: &'a Scene,
    fibre: Fibre,
    bsdf: HairBsdf,
}

/// `v` as obvhs's vector type (its own glam version), through `From<[f32; 3]>`.
fn to_a<T: From<[f32; 3]>>(v: DVec3) -> T {
    T::from([v.x as f32, v.y as f32, v.z as f32])
}

impl<'a> World<'a> {
    fn new(fibres: &'a Fibres, body: &BodyMesh, scene: &'a Scene) -> Self {
        let mut primitives = Vec::new();
        for (index, strand) in fibres.strands.iter().enumerate() {
            let points = &fibres.points[strand.first as usize..][..strand.count as usize];
            let last = (points.len() - 1) as f64;
            for (k, pair) in points.windows(2).enumerate() {
                let along = [k as f64 / last, (k + 1) as f64 / last];
                let width_m =
                    crate::strands::strand_width_m(fibres.width_m, 0.5 * (along[0] + along[1]));
                primitives.push(Primitive::Segment {
                    a: pair[0],
                    b: pair[1],
                    radius: 0.5 * width_m,
                    strand: index as u32,
                    along,
                });
            }
        }
        let vertex_normals = body.vertex_normals();
        for triangle in &body.triangles {
            let at = |values: &[[f32; 3]], i: usize| {
                let p = values
                    .get(triangle[i] as usize)
                    .copied()
                    .unwrap_or_default();
                DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)
            };
            primitives.push(Primitive::Triangle {
                corners: [0, 1, 2].map(|i| at(&body.positions, i)),
                normals: [0, 1, 2].map(|i| at(&vertex_normals, i)),
            });
        }
        let aabbs: Vec<Aabb> = primitives
            .iter()
            .map(|p| {
                let (lo, hi) = match p {
                    Primitive::Segment { a, b, radius, .. } => (
                        a.min(*b) - DVec3::splat(*radius),
                        a.max(*b) + DVec3::splat(*radius),
                    ),
                    Primitive::Triangle {
                        corners: [a, b, c], ..
                    } => (a.min(*b).min(*c), a.max(*b).max(*c)),
                };
                // Widen by a float's rounding so f32 boxes always hold the f64 shapes.
                let pad = DVec3::splat(1e-6 * (1.0 + lo.abs().max(hi.abs()).max_element()));
                Aabb {
                    min: to_a(lo - pad),
                    max: to_a(hi + pad),
                }
            })
            .collect();
        let bvh = (!aabbs.is_empty()).then(|| {
            build_bvh2(
                &aabbs,
                obvhs::BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        });
        let fibre = Fibre::new(&scene.material);
        Self {
            primitives,
            bvh,
            fibres,
            scene,
            bsdf: HairBsdf::new(&fibre),
            fibre,
        }
    }

    /// The nearest hit along `origin + t direction`, `t` in `(t_min, t_max)`, skipping
    /// `ignore` (the primitive a scattered ray leaves).
    fn intersect(
        &self,
        origin: DVec3,
        direction: DVec3,
        t_min: f64,
        t_max: f64,
        ignore: Option<usize>,
    ) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let ray = Ray::new(
            to_a(origin),
            to_a(direction),
            0.0,
            t_max.min(f32::MAX as f64) as f32,
        );
        let mut hit = RayHit::none();
        let mut best: Option<Hit> = None;
        bvh.ray_traverse(ray, &mut hit, |ray, id| {
            let primitive = bvh.primitive_indices[id] as usize;
            if Some(primitive) == ignore {
                return f32::INFINITY;
            }
            let found = match &self.primitives[primitive] {
                Primitive::Segment { a, b, radius, .. } => {
                    intersect_segment(origin, direction, *a, *b, *radius, t_min)
                }
                Primitive::Triangle { corners, .. } => {
                    intersect_triangle(origin, direction, corners, t_min).map(|t| (t, 0.0))
                }
            };
            match found {
                Some((t, s)) if t < t_max && (t as f32) <= ray.tmax => {
                    if best.as_ref().is_none_or(|b| t < b.t) {
                        best = Some(Hit { t, primitive, s });
                    }
                    t as f32
                }
                _ => f32::INFINITY,
            }
        });
        best
    }

    fn occluded(
        &self,
        origin: DVec3,
        direction: DVec3,
        t_min: f64,
        t_max: f64,
        ignore: Option<usize>,
    ) -> bool {
        self.intersect(origin, direction, t_min, t_max, ignore)
            .is_some()
    }

    /// Radiance arriving at the camera along one path (linear RGB), and rays traced.
    fn trace(
        &self,
        mut origin: DVec3,
        mut direction: DVec3,
        rng: &mut SplitMix64,
        max_bounces: u32,
    ) -> ([f64; 3], u64, bool) {
        let mut radiance = [0.0; 3];
        let mut throughput = [1.0; 3];
        let mut ignore = None;
        let mut rays = 0u64;
        let scene = self.scene;
        let ambient = scene.ambient.map(f64::from);
        for bounce in 0..=max_bounces {
            rays += 1;
            let Some(hit) = self.intersect(origin, direction, 1e-9, f64::INFINITY, ignore) else {
                if bounce == 0 {
                    return (radiance, rays, true);
                }
                for c in 0..3 {
                    radiance[c] += throughput[c] * ambient[c];
                }
                break;
            };
            let point = origin + direction * hit.t;
            let wo = -direction;
            // The local shading: f_s for a direction, and sampling the next one.
            let next = match &self.primitives[hit.primitive] {
                Primitive::Segment {
                    a,
                    b,
                    radius,
                    strand,
                    along,
                } => {
                    let length = (*b - *a).length().max(1e-300);
                    let x = (*b - *a) / length;
                    let z = (wo - x * wo.dot(x))
                        .try_normalize()
                        .unwrap_or_else(|| x.any_orthonormal_vector());
                    let y = z.cross(x);
                    let frame = DMat3::from_cols(x, y, z).transpose();
                    let axis_point = *a + x * hit.s.clamp(0.0, length);
                    let h = ((point - axis_point).dot(y) / radius).clamp(-1.0, 1.0);
                    let fraction =
                        along[0] + (along[1] - along[0]) * (hit.s / length).clamp(0.0, 1.0);
                    let strand = &self.fibres.strands[*strand as usize];
                    // The material under the colour map at the root, as every GPU path
                    // shades it (the ombré along the strand is in `sigma_a`).
                    let sigma_a = self
                        .fibre
                        .painted(&strand.paint)
                        .sigma_a(fraction, strand_shading_random(strand.root));
                    let wo_local = frame * wo;
                    // Direct light from every light, with exact shadows.
                    for light in &scene.lights {
                        let Some((wi, irradiance, distance)) = light_at(light, point) else {
                            continue;
                        };
                        rays += 1;
                        if self.occluded(point, wi, 1e-9, distance, Some(hit.primitive)) {
                            continue;
                        }
                        let f = self.bsdf.hair_bsdf(wo_local, frame * wi, h, sigma_a);
                        for c in 0..3 {
                            radiance[c] += throughput[c] * f[c] * irradiance[c];
                        }
                    }
                    let u = [
                        rng.next_f64(),
                        rng.next_f64(),
                        rng.next_f64(),
                        rng.next_f64(),
                    ];
                    self.bsdf
                        .sample(wo_local, h, sigma_a, u)
                        .map(|(wi_local, f, pdf)| {
                            let wi = frame.transpose() * wi_local;
                            (wi, f.map(|v| v / pdf))
                        })
                }
                Primitive::Triangle { corners, normals } => {
                    let normal = shading_normal(corners, normals, point, wo);
                    let albedo = scene.body_color.map(f64::from);
                    for light in &scene.lights {
                        let Some((wi, irradiance, distance)) = light_at(light, point) else {
                            continue;
                        };
                        let cosine = normal.dot(wi);
                        if cosine <= 0.0 {
                            continue;
                        }
                        rays += 1;
                        if self.occluded(point, wi, 1e-9, distance, Some(hit.primitive)) {
                            continue;
                        }
                        for c in 0..3 {
                            radiance[c] += throughput[c] * albedo[c] / std::f64::consts::PI
                                * cosine
                                * irradiance[c];
                        }
                    }
                    // Cosine-weighted: f cos / pdf = albedo.
                    let (u1, u2) = (rng.next_f64(), rng.next_f64());
                    let r = u1.sqrt();
                    let phi = std::f64::consts::TAU * u2;
                    let local =
                        DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
                    let tangent = normal.any_orthonormal_vector();
                    let bitangent = normal.cross(tangent);
                    Some((
                        tangent * local.x + bitangent * local.y + normal * local.z,
                        albedo,
                    ))
                }
            };
            let Some((wi, weight)) = next else { break };
            for c in 0..3 {
                throughput[c] *= weight[c];
            }
            // Russian roulette after a few bounces keeps long paths unbiased and cheap.
            if bounce >= 3 {
                let survive = throughput.iter().copied().fold(0.0, f64::max).min(0.95);
                if rng.next_f64() >= survive {
                    break;
                }
                throughput = throughput.map(|t| t / survive);
            }
            if !throughput.iter().all(|t| t.is_finite()) {
                break;
            }
            origin = point;
            direction = wi.normalize();
            ignore = Some(hit.primitive);
        }
        (radiance, rays, false)
    }
}

/// Direction toward `light` from `point`, its irradiance there and the distance to it.
fn light_at(light: &crate::model::scene::Light, point: DVec3) -> Option<(DVec3, [f64; 3], f64)> {
    let power = light.color.map(|c| c as f64 * light.intensity as f64);
    let (direction, distance) = light.source.toward(point)?;
    // A point light's irradiance falls off with the squared distance.
    let falloff = if distance.is_finite() {
        1.0 / (distance * distance)
    } else {
        1.0
    };
    Some((direction, power.map(|p| p * falloff), distance))
}

/// Ray against a cylinder segment (axis `a`→`b`, radius `radius`): the nearest `t > t_min`
/// whose axis parameter lies on the segment (its ends overlapping a little so joints between
/// segments leave no gaps), and that parameter.
fn intersect_segment(
    origin: DVec3,
    direction: DVec3,
    a: DVec3,
    b: DVec3,
    radius: f64,
    t_min: f64,
) -> Option<(f64, f64)> {
    let axis = b - a;
    let length = axis.length();
    if length.is_nan() || length <= 0.0 || radius.is_nan() || radius <= 0.0 {
        return None;
    }
    let u = axis / length;
    let w = origin - a;
    let d_perp = direction - u * direction.dot(u);
    let w_perp = w - u * w.dot(u);
    let qa = d_perp.length_squared();
    if qa < 1e-24 {
        return None;
    }
    let qb = 2.0 * w_perp.dot(d_perp);
    let qc = w_perp.length_squared() - radius * radius;
    let discriminant = qb * qb - 4.0 * qa * qc;
    if discriminant < 0.0 {
        return None;
    }
    let root = discriminant.sqrt();
    for t in [(-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)] {
        if t > t_min {
            let s = (w + direction * t).dot(u);
            if s >= -radius && s <= length + radius {
                return Some((t, s));
            }
        }
    }
    None
}

/// Möller–Trumbore ray-triangle intersection (both sides).
fn intersect_triangle(
    origin: DVec3,
    direction: DVec3,
    [p0, p1, p2]: &[DVec3; 3],
    t_min: f64,
) -> Option<f64> {
    let (e1, e2) = (*p1 - *p0, *p2 - *p0);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-18 {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - *p0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = direction.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > t_min).then_some(t)
}

/// The body's shading normal at `point` on a triangle, as `shaders/preview_body.wgsl` takes
/// it: the corners' normals interpolated (barycentric), turned to `wo`'s side of the face;
/// the face's own normal where they (nearly) cancel or a corner has none.
fn shading_normal(corners: &[DVec3; 3], normals: &[DVec3; 3], point: DVec3, wo: DVec3) -> DVec3 {
    let [p0, p1, p2] = *corners;
    let cross = (p1 - p0).cross(p2 - p0);
    let mut face = cross.normalize_or_zero();
    if face.dot(wo) < 0.0 {
        face = -face;
    }
    let area2 = cross.length_squared();
    if area2.is_nan() || area2 <= 0.0 {
        return face;
    }
    // Barycentric weights from the sub-triangles' areas (signed along the face's normal).
    let weight = |a: DVec3, b: DVec3| (b - a).cross(point - a).dot(cross) / area2;
    let interpolated =
        normals[0] * weight(p1, p2) + normals[1] * weight(p2, p0) + normals[2] * weight(p0, p1);
    let length = interpolated.length();
    if length.is_nan() || length <= 0.1 {
        return face;
    }
    let n = interpolated / length;
    if n.dot(face) < 0.0 { -n } else { n }
}

/// Path-traces `fibres` over `body` lit by `scene`, seen by `camera`.
pub fn render_reference(
    fibres: &Fibres,
    body: &BodyMesh,
    scene: &Scene,
    camera: &ReferenceCamera,
    settings: &ReferenceSettings,
) -> ReferenceImage {
    let started = Instant::now();
    let world = World::new(fibres, body, scene);
    let (width, height) = (camera.width.max(1), camera.height.max(1));
    let forward = (camera.target - camera.eye).normalize_or(DVec3::NEG_Z);
    let right = forward.cross(camera.up).normalize_or(DVec3::X);
    let up = right.cross(forward);
    let tan_half = (camera.fov_y_rad * 0.5).tan();
    let aspect = width as f64 / height as f64;
    let threads = if settings.threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        settings.threads
    };
    let pixel_count = (width * height) as usize;
    let mut sum = vec![[0.0f64; 3]; pixel_count];
    let mut background = vec![0u32; pixel_count];
    let mut rays = 0u64;
    let spp = settings.samples_per_pixel.max(1);
    // Passes of a few samples each, so the time budget is checked often.
    let per_pass = spp.div_ceil(8).max(1);
    let mut done = 0;
    while done < spp {
        let pass = per_pass.min(spp - done);
        let rows: Vec<(Vec<[f64; 3]>, Vec<u32>, u64)> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads)
                .map(|thread| {
                    let world = &world;
                    scope.spawn(move || {
                        let mut out = Vec::new();
                        let mut misses = Vec::new();
                        let mut rays = 0u64;
                        for y in (thread as u32..height).step_by(threads) {
                            for x in 0..width {
                                let pixel = (y * width + x) as u64;
                                let mut total = [0.0; 3];
                                let mut missed = 0;
                                for sample in done..done + pass {
                                    let mut rng = SplitMix64::new(
                                        settings.seed
                                            ^ pixel.wrapping_mul(0x9E37_79B9_7F4A_7C15)
                                            ^ (sample as u64).wrapping_mul(0xD1B5_4A32_D192_ED03),
                                    );
                                    let jx = rng.next_f64();
                                    let jy = rng.next_f64();
                                    let ndc_x = 2.0 * (x as f64 + jx) / width as f64 - 1.0;
                                    let ndc_y = 1.0 - 2.0 * (y as f64 + jy) / height as f64;
                                    let direction = (forward
                                        + right * (ndc_x * tan_half * aspect)
                                        + up * (ndc_y * tan_half))
                                        .normalize();
                                    let (radiance, traced, miss) = world.trace(
                                        camera.eye,
                                        direction,
                                        &mut rng,
                                        settings.max_bounces,
                                    );
                                    rays += traced;
                                    if miss {
                                        missed += 1;
                                    }
                                    for c in 0..3 {
                                        total[c] += radiance[c];
                                    }
                                }
                                out.push(total);
                                misses.push(missed);
                            }
                        }
                        (out, misses, rays)
                    })
                })
                .collect();
            handles
                .into_iter()
                .map(|h| {
                    h.join()
                        .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
                })
                .collect()
        });
        for (thread, (values, misses, traced)) in rows.into_iter().enumerate() {
            rays += traced;
            for (row_index, y) in (thread as u32..height).step_by(threads).enumerate() {
                for x in 0..width {
                    let i = (y * width + x) as usize;
                    let k = row_index * width as usize + x as usize;
                    for c in 0..3 {
                        sum[i][c] += values[k][c];
                    }
                    background[i] += misses[k];
                }
            }
        }
        done += pass;
        if started.elapsed().as_secs_f64() > settings.max_seconds {
            break;
        }
    }
    let exposure = scene.exposure as f64;
    let mut pixels = Vec::with_capacity(pixel_count * 4);
    for (total, &missed) in sum.iter().zip(&background) {
        // A pixel's value: the tone-mapped mean radiance of the samples that hit something,
        // blended with the background by the fraction that missed (as the GPU's MSAA resolve
        // blends coverage).
        let hit_fraction = 1.0 - missed as f64 / done as f64;
        for (c, channel) in total.iter().enumerate() {
            let mean_radiance = if hit_fraction > 0.0 {
                channel / (done as f64 * hit_fraction)
            } else {
                0.0
            };
            let display = tonemap((mean_radiance * exposure) as f32) as f64 * hit_fraction
                + scene.background[c] as f64 * (1.0 - hit_fraction);
            pixels.push((linear_to_srgb(display as f32) * 255.0).round() as u8);
        }
        pixels.push(255);
    }
    ReferenceImage {
        width,
        height,
        pixels,
        samples_per_pixel: done,
        seconds: started.elapsed().as_secs_f64(),
        rays,
        primitives: world.primitives.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::scene::{HairMaterial, Light, LightSource, Pigment};

    /// A curtain of parallel vertical fibres in front of the camera.
    fn curtain(count: usize, spacing: f64, width: f64) -> Fibres {
        let mut fibres = Fibres {
            width_m: width,
            ..Fibres::default()
        };
        for i in 0..count {
            let x = (i as f64 - count as f64 / 2.0) * spacing;
            let points: Vec<DVec3> = (0..9)
                .map(|k| DVec3::new(x, 1.0 - k as f64 * 0.25, 0.0))
                .collect();
            fibres.push(&points, i as u32);
        }
        fibres
    }

    fn camera(size: u32) -> ReferenceCamera {
        ReferenceCamera {
            eye: DVec3::new(0.0, 0.0, 3.0),
            target: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_rad: 0.8,
            width: size,
            height: size,
        }
    }

    fn one_light_scene(material: HairMaterial) -> Scene {
        Scene {
            lights: vec![Light::directional("front", [0.0, 0.3, 1.0], [1.0; 3], 2.0)],
            ambient: [0.0; 3],
            background: [0.0; 3],
            material,
            ..Scene::default()
        }
    }

    #[test]
    fn the_same_inputs_give_the_same_bytes_whatever_the_thread_count() {
        let fibres = curtain(24, 0.05, 0.02);
        let scene = one_light_scene(HairMaterial::default());
        let settings = ReferenceSettings {
            samples_per_pixel: 4,
            max_bounces: 8,
            threads: 1,
            ..ReferenceSettings::default()
        };
        let one = render_reference(
            &fibres,
            &BodyMesh::default(),
            &scene,
            &camera(24),
            &settings,
        );
        let three = render_reference(
            &fibres,
            &BodyMesh::default(),
            &scene,
            &camera(24),
            &ReferenceSettings {
                threads: 3,
                ..settings
            },
        );
        assert_eq!(one.pixels, three.pixels);
        assert_eq!(one.samples_per_pixel, 4);
        // Fibres are lit; the gaps between them show the background.
        let centre = ((12 * 24 + 12) * 4) as usize;
        let values: Vec<u8> = one.pixels.chunks(4).map(|p| p[0]).collect();
        assert!(values.iter().any(|&v| v > 40), "lit fibres");
        assert!(one.pixels[centre + 3] == 255);
    }

    /// Mean (r, g, b) over the picture's lit pixels.
    fn mean_lit_colour(pixels: &[u8]) -> [f64; 3] {
        let lit: Vec<&[u8]> = pixels
            .chunks(4)
            .filter(|p| p[0] as u32 + p[1] as u32 + p[2] as u32 > 30)
            .collect();
        assert!(!lit.is_empty(), "nothing lit");
        std::array::from_fn(|c| lit.iter().map(|p| p[c] as f64).sum::<f64>() / lit.len() as f64)
    }

    #[test]
    fn painted_strands_and_an_ombre_take_their_colour_in_the_path_tracer() {
        let settings = ReferenceSettings {
            samples_per_pixel: 4,
            max_bounces: 4,
            ..ReferenceSettings::default()
        };
        let render = |fibres: &Fibres, material: HairMaterial| {
            render_reference(
                fibres,
                &BodyMesh::default(),
                &one_light_scene(material),
                &camera(24),
                &settings,
            )
            .pixels
        };
        let plain = curtain(24, 0.05, 0.02);
        let brown = mean_lit_colour(&render(&plain, HairMaterial::default()));
        assert!(brown[0] > brown[2], "brown hair: {brown:?}");
        // The colour map's green at the roots turns every strand green.
        let mut green = Fibres {
            width_m: plain.width_m,
            ..Fibres::default()
        };
        for strand in &plain.strands {
            let points = &plain.points[strand.first as usize..][..strand.count as usize];
            let paint = PaintedColour {
                rgb_linear: [0.05, 0.4, 0.08],
                weight: 1.0,
            };
            green.push_painted(points, strand.root, paint);
        }
        let painted = mean_lit_colour(&render(&green, HairMaterial::default()));
        assert!(
            painted[1] > painted[0] && painted[1] > painted[2],
            "{painted:?}"
        );
        // An ombré to blue over the whole strand turns it blue.
        let blue = mean_lit_colour(&render(
            &plain,
            HairMaterial {
                ombre: Some(crate::model::scene::Ombre {
                    tip_rgb: [0.05, 0.1, 0.5],
                    start: 0.0,
                    end: 0.2,
                }),
                ..HairMaterial::default()
            },
        ));
        assert!(blue[2] > blue[0], "{blue:?}");
    }

    #[test]
    fn a_fibre_behind_others_is_darker_and_a_clear_fibre_transmits_more() {
        // Light from behind the curtain (toward the camera through it): clear fibres pass it
        // on (TT), black ones do not.
        let fibres = curtain(40, 0.02, 0.018);
        let render = |pigment| {
            let mut scene = one_light_scene(HairMaterial {
                pigment,
                ..HairMaterial::default()
            });
            scene.lights[0].source = LightSource::Directional {
                to_light: [0.0, 0.2, -1.0],
            };
            let image = render_reference(
                &fibres,
                &BodyMesh::default(),
                &scene,
                &camera(16),
                &ReferenceSettings {
                    samples_per_pixel: 8,
                    max_bounces: 6,
                    ..ReferenceSettings::default()
                },
            );
            image.pixels.chunks(4).map(|p| p[0] as u32).sum::<u32>()
        };
        let clear = render(Pigment::Melanin {
            eumelanin: 0.1,
            pheomelanin: 0.0,
        });
        let black = render(Pigment::Melanin {
            eumelanin: 8.0,
            pheomelanin: 0.0,
        });
        assert!(clear > black * 2, "clear {clear} black {black}");
    }

    #[test]
    fn the_time_budget_bounds_the_work_and_says_what_was_done() {
        let fibres = curtain(8, 0.1, 0.05);
        let scene = one_light_scene(HairMaterial::default());
        let image = render_reference(
            &fibres,
            &BodyMesh::default(),
            &scene,
            &camera(8),
            &ReferenceSettings {
                samples_per_pixel: 1_000_000,
                max_seconds: 0.0,
                ..ReferenceSettings::default()
            },
        );
        // One pass of an eighth of the samples, then the budget stops it.
        assert_eq!(image.samples_per_pixel, 125_000);
        assert!(image.rays > 0);
    }

    #[test]
    fn segment_and_triangle_intersections() {
        let hit = intersect_segment(
            DVec3::new(0.0, 0.5, 5.0),
            DVec3::NEG_Z,
            DVec3::ZERO,
            DVec3::Y,
            0.1,
            0.0,
        )
        .expect("hits the cylinder");
        assert!((hit.0 - 4.9).abs() < 1e-12 && (hit.1 - 0.5).abs() < 1e-12);
        // Parallel to the axis, beside it, beyond its end: misses.
        assert!(
            intersect_segment(
                DVec3::new(0.0, -5.0, 0.0),
                DVec3::Y,
                DVec3::ZERO,
                DVec3::Y,
                0.1,
                0.0
            )
            .is_none()
        );
        assert!(
            intersect_segment(
                DVec3::new(0.5, 0.5, 5.0),
                DVec3::NEG_Z,
                DVec3::ZERO,
                DVec3::Y,
                0.1,
                0.0
            )
            .is_none()
        );
        assert!(
            intersect_segment(
                DVec3::new(0.0, 1.5, 5.0),
                DVec3::NEG_Z,
                DVec3::ZERO,
                DVec3::Y,
                0.1,
                0.0
            )
            .is_none()
        );
        let triangle = [DVec3::ZERO, DVec3::X, DVec3::Y];
        assert!(
            (intersect_triangle(DVec3::new(0.2, 0.2, 1.0), DVec3::NEG_Z, &triangle, 0.0)
                .expect("hit")
                - 1.0)
                .abs()
                < 1e-12
        );
        assert!(
            intersect_triangle(DVec3::new(0.8, 0.8, 1.0), DVec3::NEG_Z, &triangle, 0.0).is_none()
        );
    }
}
