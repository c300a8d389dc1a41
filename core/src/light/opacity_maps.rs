//! Shadow views and opacity-map layers: how a shadow-casting light sees the hair, where the
//! opacity layers lie, and how many fibres lie between a point and the light. CPU mirror of
//! `shaders/light/opacity_maps.wgsl` (same names: `layer_end`, `hairs_in_front`,
//! `light_distance`).
//!
//! - **Opacity shadow maps** (Kim & Neumann 2001, seed 004): `K` layers evenly spaced over the
//!   hair's depth range seen from the light, `end_k = near + (far − near)(k + 1)/K`.
//! - **Deep opacity maps** (Yuksel & Keyser 2008, seed 001): a depth pass first finds, per
//!   texel, the first hair `z₀` the light meets; the layers follow it,
//!   `end_k = z₀ + D ((k + 1)/K)²` (thin layers near the surface where shadows change fastest).
//!
//! Each layer holds the fibres met up to its end (coverage-weighted: a fibre narrower than a
//! texel adds its width over the texel's), so layer values grow with `k`; the number in front
//! of a point at distance `z` is the piecewise-linear interpolation between `(start, 0)` and
//! the layer ends, and the last layer's value beyond it. Points outside the light's view see no
//! fibres (their lookups return 0, never NaN).

use glam::{Mat4, Vec3, Vec4Swizzles};

use crate::model::scene::{LightSource, SelfShadowing};

/// How a shadow-casting light projects: orthographic for directional lights, perspective for
/// point lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowView {
    pub view_projection: Mat4,
    pub perspective: bool,
    /// Distances from the light (the view's near and far planes): the hair's bounding sphere
    /// lies between them.
    pub near: f32,
    pub far: f32,
    /// World size of one texel: at unit distance for a perspective view, everywhere for an
    /// orthographic one.
    pub texel_size: f32,
    /// The light's position (perspective) or the direction toward it (orthographic, unit).
    pub eye: Vec3,
}

impl ShadowView {
    /// Frames the sphere `(center, radius)` (the hair, padded) from `source`, `resolution`
    /// texels a side.
    pub fn fit(source: &LightSource, center: Vec3, radius: f32, resolution: u32) -> Self {
        let radius = if radius.is_finite() {
            radius.max(1e-4)
        } else {
            1.0
        };
        let resolution = resolution.max(1) as f32;
        match *source {
            LightSource::Directional { to_light } => {
                let direction = Vec3::from(to_light).normalize_or(Vec3::Y);
                let eye = center + direction * (2.0 * radius);
                let view = Mat4::look_at_rh(eye, center, up_for(direction));
                let (near, far) = (radius, 3.0 * radius);
                let projection = Mat4::orthographic_rh(-radius, radius, -radius, radius, near, far);
                Self {
                    view_projection: projection * view,
                    perspective: false,
                    near,
                    far,
                    texel_size: 2.0 * radius / resolution,
                    eye: direction,
                }
            }
            LightSource::Point { position_m } => {
                let eye = Vec3::from(position_m);
                let offset = center - eye;
                let distance = offset.length();
                // A light inside (or at) the hair's sphere: a wide cone toward the centre.
                let (fov, near, far) = if distance > radius * 1.05 {
                    (
                        (2.0 * (radius / distance).asin()).clamp(0.1, 2.6),
                        (distance - radius).max(radius * 0.01),
                        distance + radius,
                    )
                } else {
                    (2.6, radius * 0.01, distance + radius)
                };
                let forward = if distance > 1e-6 {
                    offset / distance
                } else {
                    -Vec3::Y
                };
                let view = Mat4::look_at_rh(eye, eye + forward, up_for(-forward));
                let projection = Mat4::perspective_rh(fov, 1.0, near, far);
                Self {
                    view_projection: projection * view,
                    perspective: true,
                    near,
                    far,
                    texel_size: 2.0 * (fov * 0.5).tan() / resolution,
                    eye,
                }
            }
        }
    }

    /// Light-space texture coordinates (`x`, `y` in `[0, 1]`, `y` down) and depth in `[0, 1]`
    /// of `world`; `None` outside the view.
    pub fn project(&self, world: Vec3) -> Option<Vec3> {
        let clip = self.view_projection * world.extend(1.0);
        if clip.w.is_nan() || clip.w <= 0.0 {
            return None;
        }
        let ndc = clip.xyz() / clip.w;
        let inside = ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0 && (0.0..=1.0).contains(&ndc.z);
        inside.then(|| Vec3::new(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5, ndc.z))
    }

    /// Distance from the light of a point at NDC depth `z`.
    pub fn light_distance(&self, z: f32) -> f32 {
        light_distance(z, self.near, self.far, self.perspective)
    }
}

/// An up vector not parallel to `direction`.
fn up_for(direction: Vec3) -> Vec3 {
    if direction.y.abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// Distance from the light of NDC depth `z` (`[0, 1]`, wgpu's convention) for a view with
/// planes at `near` and `far`: linear for orthographic views, `near·far / (far − z(far −
/// near))` for glam's right-handed perspective.
pub fn light_distance(z: f32, near: f32, far: f32, perspective: bool) -> f32 {
    if perspective {
        near * far / (far - z * (far - near)).max(1e-12)
    } else {
        near + z * (far - near)
    }
}

/// The distance from the light at which layer `k` of `layers` ends. `start` is the first
/// hair's distance (deep opacity maps) or the view's near plane (opacity shadow maps);
/// `depth` the distance the layers span (`far − near` for opacity shadow maps).
pub(crate) fn layer_end(kind: SelfShadowing, k: u32, layers: u32, start: f32, depth: f32) -> f32 {
    let fraction = (k + 1) as f32 / layers.max(1) as f32;
    match kind {
        SelfShadowing::DeepOpacityMaps => start + depth * fraction * fraction,
        _ => start + depth * fraction,
    }
}

/// Fibres between the light and a point at distance `z` from it, from one texel's layer
/// values (cumulative, `values[k]` at [`layer_end`] `k`).
pub fn hairs_in_front(kind: SelfShadowing, z: f32, start: f32, depth: f32, values: &[f32]) -> f32 {
    let layers = values.len() as u32;
    if layers == 0 || !z.is_finite() || !start.is_finite() || z <= start {
        return 0.0;
    }
    let (mut previous_end, mut previous_value) = (start, 0.0);
    for (k, &value) in values.iter().enumerate() {
        let end = layer_end(kind, k as u32, layers, start, depth);
        if z <= end {
            let t = ((z - previous_end) / (end - previous_end).max(1e-12)).clamp(0.0, 1.0);
            return (previous_value + (value - previous_value) * t).max(0.0);
        }
        (previous_end, previous_value) = (end, value);
    }
    previous_value.max(0.0)
}

/// The layer a fibre fragment at distance `z` adds its coverage to, and every later one: the
/// first `k` with `z ≤ end_k` (`layers` when it lies beyond them all, where it adds nothing).
pub fn first_layer(kind: SelfShadowing, z: f32, layers: u32, start: f32, depth: f32) -> u32 {
    (0..layers)
        .find(|&k| z <= layer_end(kind, k, layers, start, depth))
        .unwrap_or(layers)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_accumulate_and_lookups_interpolate_between_them() {
        for kind in [
            SelfShadowing::OpacityShadowMaps,
            SelfShadowing::DeepOpacityMaps,
        ] {
            let (start, depth, layers) = (1.0, 0.4, 8);
            // Fibres at these distances, each covering the texel.
            let fibres = [1.01, 1.02, 1.05, 1.1, 1.2, 1.33];
            let mut values = vec![0.0f32; layers as usize];
            for &z in &fibres {
                for v in values
                    .iter_mut()
                    .skip(first_layer(kind, z, layers, start, depth) as usize)
                {
                    *v += 1.0;
                }
            }
            // Monotone in depth; 0 in front of the first hair; every fibre beyond the last.
            let mut last = -1.0;
            for i in 0..100 {
                let z = 0.9 + i as f32 * 0.01;
                let n = hairs_in_front(kind, z, start, depth, &values);
                assert!(
                    n >= last - 1e-6 && n.is_finite(),
                    "{kind:?} z {z}: {n} after {last}"
                );
                last = n;
            }
            assert_eq!(hairs_in_front(kind, 0.99, start, depth, &values), 0.0);
            assert_eq!(
                hairs_in_front(kind, 5.0, start, depth, &values),
                fibres.len() as f32
            );
            // At a layer end the lookup is exactly the count up to it.
            for k in 0..layers {
                let end = layer_end(kind, k, layers, start, depth);
                let expected = fibres.iter().filter(|&&z| z <= end).count() as f32;
                let n = hairs_in_front(kind, end, start, depth, &values);
                assert!(
                    (n - expected).abs() < 1e-5,
                    "{kind:?} layer {k}: {n} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn lookups_never_return_nan() {
        let values = [1.0, 2.0, 3.0, 4.0];
        for z in [f32::NAN, f32::INFINITY, -f32::INFINITY, -1.0, 0.0, 1e30] {
            for (start, depth) in [(0.0, 0.0), (f32::NAN, 1.0), (1.0, f32::NAN), (1.0, -1.0)] {
                for kind in [
                    SelfShadowing::OpacityShadowMaps,
                    SelfShadowing::DeepOpacityMaps,
                ] {
                    let n = hairs_in_front(kind, z, start, depth, &values);
                    assert!(n.is_finite(), "{z} {start} {depth}: {n}");
                }
            }
        }
        assert_eq!(
            hairs_in_front(SelfShadowing::DeepOpacityMaps, 1.0, 0.0, 1.0, &[]),
            0.0
        );
    }

    #[test]
    fn views_frame_the_hair_and_points_outside_are_outside() {
        let center = Vec3::new(0.1, 1.6, 0.0);
        let radius = 0.2;
        for source in [
            LightSource::Directional {
                to_light: [0.3, 1.0, 0.5],
            },
            LightSource::Directional {
                to_light: [0.0, 1.0, 0.0],
            },
            LightSource::Point {
                position_m: [1.0, 2.5, 1.0],
            },
            LightSource::Point {
                position_m: [0.1, 1.6, 0.05],
            },
        ] {
            let view = ShadowView::fit(&source, center, radius, 1024);
            assert!(view.view_projection.is_finite(), "{source:?}");
            // The sphere's centre projects inside and in depth between the planes.
            let p = view.project(center).expect("centre inside");
            assert!(
                (p.x - 0.5).abs() < 0.01 && (p.y - 0.5).abs() < 0.01,
                "{p:?}"
            );
            let distance = view.light_distance(p.z);
            let expected = if view.perspective {
                (center - view.eye).length()
            } else {
                2.0 * radius
            };
            assert!(
                (distance - expected).abs() < 1e-3 * radius.max(expected),
                "{distance} vs {expected}"
            );
            // Far outside is outside.
            assert!(
                view.project(center + Vec3::new(50.0, 0.0, 50.0)).is_none() || view.perspective
            );
            assert!(view.project(Vec3::splat(f32::NAN)).is_none());
        }
    }
}
