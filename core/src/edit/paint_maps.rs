//! Painting the maps of [`crate::model::root_maps`] on the scalp: a dab is a sphere around a
//! point of the scalp, and it changes every map texel whose root lies inside it. Each texel's
//! root is found once per stroke by rasterising the hair mesh's root faces into the maps in
//! uv space ([`RootMapRaster`]), so the brush's radius is a distance on the head whatever the
//! uv layout stretches, and texels no root face covers are left alone.

use glam::{DVec2, DVec3};

use crate::edit::falloff_weight;
use crate::model::mesh::HairMesh;
use crate::model::root_maps::{RootMapChannel, RootMaps};

/// Where on the scalp each map texel's centre lies: the root face covering it in uv space,
/// interpolated. `None` for texels no face covers.
pub struct RootMapRaster {
    width: u32,
    height: u32,
    /// Per texel: the root position and the root face's unit normal.
    texels: Vec<Option<(DVec3, DVec3)>>,
}

impl RootMapRaster {
    /// Rasterises every root face of `mesh` that grows hair (and the bare ones: a map may be
    /// painted before hair grows there) into a `width × height` grid over uv `[0, 1]²`.
    /// Quads are split along their 0-2 diagonal; faces of no uv area are skipped.
    pub fn new(mesh: &HairMesh, width: u32, height: u32) -> Self {
        let mut texels = vec![None; width as usize * height as usize];
        for_each_root_triangle(mesh, |p, uv| {
            let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            rasterise_triangle(width, height, uv, |index, weights| {
                let position = p[0] * weights[0] + p[1] * weights[1] + p[2] * weights[2];
                if position.is_finite() {
                    texels[index] = Some((position, normal));
                }
            });
        });
        Self {
            width,
            height,
            texels,
        }
    }

    /// Texels some root face covers.
    pub fn covered(&self) -> usize {
        self.texels.iter().filter(|t| t.is_some()).count()
    }

    /// The scalp point of texel `(x, y)`, if a root face covers it.
    pub fn root_of(&self, x: u32, y: u32) -> Option<DVec3> {
        self.texels
            .get((y * self.width + x) as usize)
            .copied()
            .flatten()
            .map(|(p, _)| p)
    }
}

/// Calls `triangle(root positions, uvs)` for every root face of `mesh` with a uv per corner
/// (removed bundles left out, bare ones kept: a map may be painted before hair grows there),
/// quads and polygons fanned from their first corner (the 0-2 diagonal of a quad).
fn for_each_root_triangle(mesh: &HairMesh, mut triangle: impl FnMut([DVec3; 3], [DVec2; 3])) {
    for bundle in &mesh.bundles {
        if bundle.removed || bundle.vertices.len() < 3 || bundle.uvs.len() != bundle.vertices.len()
        {
            continue;
        }
        let roots: Option<Vec<DVec3>> = bundle
            .vertices
            .iter()
            .map(|&v| mesh.columns.get(v as usize)?.positions.first().copied())
            .collect();
        let Some(roots) = roots else {
            continue;
        };
        for fan in 1..bundle.vertices.len() - 1 {
            let ids = [0, fan, fan + 1];
            triangle(ids.map(|i| roots[i]), ids.map(|i| bundle.uvs[i]));
        }
    }
}

/// One triangle of [`map_display_triangles`]: its corners on the scalp, their uvs (where a
/// display reads the maps) and the root face's unit normal (to leave faces turned away).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapDisplayTriangle {
    pub positions: [DVec3; 3],
    pub uvs: [DVec2; 3],
    pub normal: DVec3,
}

/// The scalp under the painted maps, for showing them while painting: every root face of
/// `mesh` (as [`RootMapRaster`] covers them) cut into `cuts²` triangles per fan triangle, so a
/// display that colours each corner by the map at its uv shows detail finer than a face.
/// Triangles of no area or with a non-finite corner are left out; `cuts` is clamped to
/// `1..=16`.
pub fn map_display_triangles(mesh: &HairMesh, cuts: u32) -> Vec<MapDisplayTriangle> {
    let n = cuts.clamp(1, 16) as usize;
    let mut out = Vec::new();
    for_each_root_triangle(mesh, |p, uv| {
        let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        if normal == DVec3::ZERO || !normal.is_finite() {
            return;
        }
        // Barycentric lattice point (i, j) of the n-cut triangle.
        let at = |i: usize, j: usize| {
            let (b1, b2) = (i as f64 / n as f64, j as f64 / n as f64);
            let b0 = 1.0 - b1 - b2;
            (
                p[0] * b0 + p[1] * b1 + p[2] * b2,
                uv[0] * b0 + uv[1] * b1 + uv[2] * b2,
            )
        };
        let mut push = |corners: [(usize, usize); 3]| {
            let points = corners.map(|(i, j)| at(i, j));
            let triangle = MapDisplayTriangle {
                positions: points.map(|(p, _)| p),
                uvs: points.map(|(_, uv)| uv),
                normal,
            };
            if triangle.positions.iter().all(|p| p.is_finite())
                && triangle.uvs.iter().all(|uv| uv.is_finite())
            {
                out.push(triangle);
            }
        };
        for i in 0..n {
            for j in 0..n - i {
                push([(i, j), (i + 1, j), (i, j + 1)]);
                if i + j + 1 < n {
                    push([(i + 1, j), (i + 1, j + 1), (i, j + 1)]);
                }
            }
        }
    });
    out
}

/// Calls `texel(index, barycentric weights)` for every texel whose centre lies in the uv
/// triangle `uv` (edges shared by two triangles count for one of them only by the top-left
/// rule's spirit: a centre exactly on an edge may be written twice, with the same value).
fn rasterise_triangle(
    width: u32,
    height: u32,
    uv: [DVec2; 3],
    mut texel: impl FnMut(usize, [f64; 3]),
) {
    let area = (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]);
    if !area.is_finite() || area.abs() < 1e-14 {
        return;
    }
    let size = DVec2::new(width as f64, height as f64);
    let lo = uv[0].min(uv[1]).min(uv[2]) * size;
    let hi = uv[0].max(uv[1]).max(uv[2]) * size;
    let x0 = (lo.x - 0.5).ceil().clamp(0.0, width as f64) as u32;
    let x1 = ((hi.x - 0.5).floor() + 1.0).clamp(0.0, width as f64) as u32;
    let y0 = (lo.y - 0.5).ceil().clamp(0.0, height as f64) as u32;
    let y1 = ((hi.y - 0.5).floor() + 1.0).clamp(0.0, height as f64) as u32;
    for y in y0..y1 {
        for x in x0..x1 {
            let c = DVec2::new((x as f64 + 0.5) / size.x, (y as f64 + 0.5) / size.y);
            let w1 = (c - uv[0]).perp_dot(uv[2] - uv[0]) / area;
            let w2 = (uv[1] - uv[0]).perp_dot(c - uv[0]) / area;
            let w0 = 1.0 - w1 - w2;
            const EDGE: f64 = -1e-9;
            if w0 >= EDGE && w1 >= EDGE && w2 >= EDGE {
                texel((y * width + x) as usize, [w0, w1, w2]);
            }
        }
    }
}

/// One dab of a map brush.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapDab {
    pub channel: RootMapChannel,
    /// A point on the scalp (model units).
    pub centre_m: [f64; 3],
    pub radius_m: f64,
    /// The value painted toward, a share in `[0, 1]`: for the colour map, the colour's weight
    /// (0 takes the colour away).
    pub value: f64,
    /// The colour map's colour (sRGB); the grey maps ignore it.
    pub colour_srgb: [u8; 3],
    /// How far toward it one dab goes at the centre (`0 … 1`), falling off to the rim.
    pub strength: f64,
    /// Only texels whose root face looks toward the viewer (`None`: all).
    pub view_direction: Option<[f64; 3]>,
    /// Also paint the mirror image across `x = mirror_plane_x`.
    pub mirror_x: bool,
    pub mirror_plane_x: f64,
}

/// Applies `dab` to `maps` (which must be `raster`'s size: made blank at
/// [`crate::model::root_maps::DEFAULT_ROOT_MAP_SIDE`] first when nothing is painted yet).
/// Returns how many texels changed. Each changes by at least one step of 1/255 toward the
/// value where the dab reaches it, so repeated light dabs always arrive.
pub fn paint_dab(maps: &mut RootMaps, raster: &RootMapRaster, dab: &MapDab) -> usize {
    if (maps.width(), maps.height()) != (raster.width, raster.height)
        || dab.radius_m.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        || !dab.strength.is_finite()
        || !dab.value.is_finite()
    {
        return 0;
    }
    let centre = DVec3::from_array(dab.centre_m);
    if !centre.is_finite() {
        return 0;
    }
    let mirrored = DVec3::new(2.0 * dab.mirror_plane_x - centre.x, centre.y, centre.z);
    let target = (dab.value.clamp(0.0, 1.0) * 255.0).round();
    let strength = dab.strength.clamp(0.0, 1.0);
    let view = dab.view_direction.map(DVec3::from_array);
    // How far each texel the dab reaches goes toward the target (0: not reached).
    let weights = raster.texels.iter().map(|root| {
        let Some((position, normal)) = root else {
            return 0.0;
        };
        if let Some(view) = view
            && normal.dot(view) > 0.0
        {
            return 0.0;
        }
        let mut weight = falloff_weight(position.distance(centre), dab.radius_m);
        if dab.mirror_x {
            weight = weight.max(falloff_weight(position.distance(mirrored), dab.radius_m));
        }
        weight * strength
    });
    let weights: Vec<f64> = weights.collect();
    let mut changed = 0;
    match dab.channel.grey_index() {
        Some(channel) => {
            for (texel, &weight) in maps.texels_mut().iter_mut().zip(&weights) {
                if weight > 0.0 && step_toward(&mut texel[channel], target, weight) {
                    changed += 1;
                }
            }
        }
        None => {
            if target == 0.0 && !maps.has_colour() {
                return 0;
            }
            for (texel, &weight) in maps.colour_texels_mut().iter_mut().zip(&weights) {
                if weight <= 0.0 {
                    continue;
                }
                let before = *texel;
                // A texel with no colour yet has no colour to blend from: it takes the brush's.
                if texel[3] == 0 && target > 0.0 {
                    texel[..3].copy_from_slice(&dab.colour_srgb);
                } else if target > 0.0 {
                    for (byte, target) in texel.iter_mut().zip(dab.colour_srgb) {
                        step_toward(byte, target as f64, weight);
                    }
                }
                step_toward(&mut texel[3], target, weight);
                if *texel != before {
                    changed += 1;
                }
            }
            if !maps.is_painted(RootMapChannel::Colour) {
                maps.clear_colour();
            }
        }
    }
    changed
}

/// Moves `byte` toward `target` by `weight` of the way, at least one step of 1/255 (so
/// repeated light dabs always arrive); whether it changed.
fn step_toward(byte: &mut u8, target: f64, weight: f64) -> bool {
    let old = *byte as f64;
    let mut new = (old + (target - old) * weight).round();
    if new == old && old != target {
        new = old + (target - old).signum();
    }
    *byte = new as u8;
    new != old
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::root_maps::DEFAULT_ROOT_MAP_SIDE;
    use crate::samples::grid_scalp;

    fn scalp() -> HairMesh {
        // A 4 × 4 grid of quads over x, z ∈ [0, 0.4] (y = 0) with uvs over [0, 1]².
        grid_scalp(4, 4, |s, t| DVec3::new(0.4 * s, 0.0, 0.4 * t))
    }

    #[test]
    fn the_map_display_covers_every_root_face_once_at_its_uvs() {
        let mut mesh = scalp();
        let area = |a: DVec3, b: DVec3, c: DVec3| 0.5 * (b - a).cross(c - a).length();
        let uv_area = |t: &MapDisplayTriangle| {
            let [a, b, c] = t.uvs;
            0.5 * ((b - a).perp_dot(c - a)).abs()
        };
        for cuts in [1, 3] {
            let triangles = map_display_triangles(&mesh, cuts);
            // 16 quads, two fan triangles each, cuts² pieces each.
            assert_eq!(triangles.len(), 16 * 2 * (cuts * cuts) as usize);
            let world: f64 = triangles
                .iter()
                .map(|t| area(t.positions[0], t.positions[1], t.positions[2]))
                .sum();
            let uv: f64 = triangles.iter().map(uv_area).sum();
            assert!((world - 0.16).abs() < 1e-9, "{world}");
            assert!((uv - 1.0).abs() < 1e-9, "{uv}");
            // Each corner's uv maps to its position as the grid lays them out (x = 0.4 u).
            for t in &triangles {
                for k in 0..3 {
                    assert!((t.positions[k].x - 0.4 * t.uvs[k].x).abs() < 1e-9);
                }
                assert!((t.normal.length() - 1.0).abs() < 1e-9);
            }
        }
        // Degenerate input: a face collapsed to a point and one with a NaN root are left out;
        // out-of-range cuts are clamped.
        let first = mesh.bundles[0].vertices[0] as usize;
        mesh.columns[first].positions[0] = DVec3::NAN;
        let triangles = map_display_triangles(&mesh, 0);
        assert!(triangles.len() < 32, "{}", triangles.len());
        assert!(
            triangles
                .iter()
                .all(|t| t.positions.iter().all(|p| p.is_finite()))
        );
        assert!(map_display_triangles(&mesh, u32::MAX).len() <= 32 * 256);
    }

    #[test]
    fn the_raster_covers_the_scalp_faces_once_with_their_roots() {
        let mesh = scalp();
        let raster = RootMapRaster::new(&mesh, 32, 32);
        let (lo, hi) = mesh.bounds().expect("a scalp");
        assert!(raster.covered() > 0);
        for y in 0..32 {
            for x in 0..32 {
                if let Some(p) = raster.root_of(x, y) {
                    assert!(p.is_finite());
                    assert!(p.cmpge(lo - 1e-9).all() && p.cmple(hi + 1e-9).all(), "{p}");
                }
            }
        }
    }

    #[test]
    fn a_dab_paints_near_its_centre_only_mirrored_and_front_facing() {
        let mesh = scalp();
        let side = DEFAULT_ROOT_MAP_SIDE;
        let raster = RootMapRaster::new(&mesh, side, side);
        assert!(raster.covered() > 1000, "{}", raster.covered());
        let mut maps = RootMaps::blank(side, side).expect("maps");
        let (lo, hi) = mesh.bounds().expect("a scalp");
        let corner = DVec3::new(lo.x + 0.05, lo.y, lo.z + 0.05);
        let dab = MapDab {
            channel: RootMapChannel::Density,
            centre_m: corner.to_array(),
            radius_m: 0.04,
            value: 0.0,
            colour_srgb: [0; 3],
            strength: 1.0,
            view_direction: None,
            mirror_x: false,
            mirror_plane_x: 0.5 * (lo.x + hi.x),
        };
        let changed = paint_dab(&mut maps, &raster, &dab);
        assert!(changed > 0);
        let texel = |maps: &RootMaps, p: DVec3| -> u8 {
            let mut best = (f64::INFINITY, 255);
            for y in 0..side {
                for x in 0..side {
                    if let Some(root) = raster.root_of(x, y) {
                        let d = root.distance(p);
                        if d < best.0 {
                            best = (d, maps.texels()[(y * side + x) as usize][0]);
                        }
                    }
                }
            }
            best.1
        };
        assert_eq!(texel(&maps, corner), 0, "painted at the centre");
        let far = DVec3::new(hi.x - 0.05, lo.y, hi.z - 0.05);
        assert_eq!(texel(&maps, far), 255, "untouched far away");
        // Only density changed.
        assert!(maps.texels().iter().all(|t| t[1] == 255 && t[2] == 255));
        // Mirrored: the other side too.
        let mirror = DVec3::new(hi.x - 0.05, lo.y, lo.z + 0.05);
        assert_eq!(texel(&maps, mirror), 255);
        paint_dab(
            &mut maps,
            &raster,
            &MapDab {
                mirror_x: true,
                ..dab
            },
        );
        assert_eq!(texel(&maps, mirror), 0, "the mirror image is painted");
        // Seen from the side its normal points to (the roots face +y or −y): a view looking
        // along the normal is behind the scalp, and paints nothing.
        let normal = raster.texels.iter().flatten().next().expect("a texel").1;
        let mut fresh = RootMaps::blank(side, side).expect("maps");
        let behind = MapDab {
            view_direction: Some(normal.to_array()),
            ..dab
        };
        assert_eq!(paint_dab(&mut fresh, &raster, &behind), 0);
        let front = MapDab {
            view_direction: Some((-normal).to_array()),
            ..dab
        };
        assert!(paint_dab(&mut fresh, &raster, &front) > 0);
        // Light dabs still arrive: strength 0.001 moves each reached texel a step.
        let mut light = RootMaps::blank(side, side).expect("maps");
        let before = light.clone();
        paint_dab(
            &mut light,
            &raster,
            &MapDab {
                strength: 0.001,
                ..dab
            },
        );
        assert_ne!(light, before);
        // Degenerate dabs change nothing.
        for bad in [
            MapDab {
                radius_m: f64::NAN,
                ..dab
            },
            MapDab {
                centre_m: [f64::NAN, 0.0, 0.0],
                ..dab
            },
            MapDab {
                value: f64::INFINITY,
                colour_srgb: [0; 3],
                ..dab
            },
        ] {
            let mut maps = RootMaps::blank(side, side).expect("maps");
            assert_eq!(paint_dab(&mut maps, &raster, &bad), 0);
        }
        // Maps of another size than the raster's: nothing.
        let mut other = RootMaps::blank(8, 8).expect("maps");
        assert_eq!(paint_dab(&mut other, &raster, &dab), 0);
    }

    #[test]
    fn a_colour_dab_paints_colour_and_weight_and_ctrl_takes_it_away() {
        let mesh = scalp();
        let side = 64;
        let raster = RootMapRaster::new(&mesh, side, side);
        let mut maps = RootMaps::blank(side, side).expect("maps");
        let (lo, hi) = mesh.bounds().expect("a scalp");
        let centre = 0.5 * (lo + hi);
        let dab = MapDab {
            channel: RootMapChannel::Colour,
            centre_m: centre.to_array(),
            radius_m: 0.05,
            value: 1.0,
            colour_srgb: [200, 40, 10],
            strength: 1.0,
            view_direction: None,
            mirror_x: false,
            mirror_plane_x: centre.x,
        };
        // Taking colour away where none is painted changes nothing and makes no colour map.
        assert_eq!(
            paint_dab(&mut maps, &raster, &MapDab { value: 0.0, ..dab }),
            0
        );
        assert!(!maps.has_colour());
        let changed = paint_dab(&mut maps, &raster, &dab);
        assert!(changed > 0);
        assert!(
            maps.texels().iter().all(|t| *t == [255; 4]),
            "grey maps untouched"
        );
        let painted: Vec<&[u8; 4]> = maps.colour_texels().iter().filter(|t| t[3] > 0).collect();
        assert_eq!(painted.len(), changed);
        // A texel with no colour before takes the brush's colour whole (never a blend with
        // the black of "no colour"), whatever weight the falloff gives it.
        assert!(
            painted.iter().all(|t| t[..3] == [200, 40, 10]),
            "{painted:?}"
        );
        assert!(
            painted.iter().any(|t| t[3] > 240),
            "near full weight at the centre"
        );
        // A second colour blends over the first.
        paint_dab(
            &mut maps,
            &raster,
            &MapDab {
                colour_srgb: [0, 0, 255],
                strength: 0.5,
                ..dab
            },
        );
        assert!(
            maps.colour_texels()
                .iter()
                .any(|t| t[2] > 0 && t[2] < 255 && t[0] > 0),
            "half-way colours"
        );
        // Ctrl (weight 0) at full strength takes it all away: the colour map goes.
        for _ in 0..300 {
            paint_dab(&mut maps, &raster, &MapDab { value: 0.0, ..dab });
        }
        assert!(!maps.has_colour());
    }
}
