//! The body under the hair shades smoothly: a coarse sphere (15° facets) lit by the default
//! rig with body shadows shows no facet steps (smooth normals from
//! `BodyMesh::vertex_normals`, interpolated), and no dark lines along its triangles' edges
//! (shadow lookups at the centroid, offset along the normal).
//! `HAIRLOOM_DUMP_RGBA=FILE` writes the picture (200 × 200 RGBA8) to look at.

use glam::Vec3;
use hairloom_core::model::document::BodyMesh;
use hairloom_core::model::scene::{LightSource, Scene};
use hairloom_render::device::headless_for_test;
use hairloom_render::preview::{Camera, HairSource, PreviewRenderer, default_scene};
use hairloom_render::renderer::preview_body::GpuBody;

/// A latitude-longitude sphere of `radius` with `rings` × `columns` quads.
fn sphere(radius: f32, rings: u32, columns: u32) -> BodyMesh {
    let mut positions = Vec::new();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        let ring_radius = if r == 0 || r == rings {
            0.0
        } else {
            radius * theta.sin()
        };
        for c in 0..columns {
            let phi = std::f32::consts::TAU * c as f32 / columns as f32;
            positions.push([
                ring_radius * phi.cos(),
                radius * theta.cos(),
                ring_radius * phi.sin(),
            ]);
        }
    }
    let at = |r: u32, c: u32| r * columns + c % columns;
    let mut triangles = Vec::new();
    for r in 0..rings {
        for c in 0..columns {
            triangles.push([at(r, c), at(r, c + 1), at(r + 1, c)]);
            triangles.push([at(r, c + 1), at(r + 1, c + 1), at(r + 1, c)]);
        }
    }
    BodyMesh {
        positions,
        triangles,
    }
}

#[test]
fn a_faceted_sphere_shades_without_steps_or_edge_lines() {
    let Some(context) = headless_for_test(module_path!()) else {
        return;
    };
    let body = GpuBody::upload(&context, &sphere(0.1, 12, 24));
    // One short strand hidden inside the sphere: the frame needs hair to draw.
    let strand = [
        [0.0, 0.0, 0.0, 0.0],
        [0.0, 0.01, 0.0, 0.5],
        [0.0, 0.02, 0.0, 1.0],
    ];
    let mut scene = Scene::default();
    scene.effects = scene
        .effects
        .none()
        .parse_list("marschner,body-shadows")
        .expect("effects");
    let (lo, hi) = (Vec3::splat(-0.1), Vec3::splat(0.1));
    let camera = Camera::framing(lo, hi, Vec3::new(0.3, 0.2, 1.0));
    let frame = default_scene(
        &body,
        HairSource::Vertices(&strand),
        3,
        (lo, hi),
        camera,
        &scene,
    );
    let preview = PreviewRenderer::new(&context);
    let size = 200;
    let plan = preview.plan(&frame, size, size);
    let picture = preview
        .render(&context, &frame, &plan, size, size)
        .expect("frame");
    if let Ok(path) = std::env::var("HAIRLOOM_DUMP_RGBA") {
        std::fs::write(path, &picture).expect("dump");
    }
    let luminance: Vec<f32> = picture
        .chunks(4)
        .map(|p| 0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32)
        .collect();
    let background = luminance[0];
    let at = |x: u32, y: u32| luminance[(y * size + x) as usize];
    // Pixels whose 5 × 5 neighbourhood is all sphere (away from the silhouette).
    let inside = |x: u32, y: u32| {
        (x.saturating_sub(2)..=(x + 2).min(size - 1)).all(|i| {
            (y.saturating_sub(2)..=(y + 2).min(size - 1))
                .all(|j| (at(i, j) - background).abs() > 1.0)
        })
    };
    // The sphere's true normal at a pixel (the camera's ray against the round sphere). Pixels
    // near the key light's terminator are left out: there a coarse mesh's polygonal
    // shadow outline meets the smooth shading (the shadow-terminator problem, which a
    // scan's 1-2° facets keep to a sliver); everything else must be smooth.
    let key = Vec3::from(match scene.lights[0].source {
        LightSource::Directional { to_light } => to_light,
        LightSource::Point { position_m } => position_m,
    })
    .normalize();
    let forward = (camera.target - camera.eye).normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    let half = (0.5 * camera.fov_y_rad).tan();
    let normal_at = |x: u32, y: u32| {
        let u = (2.0 * (x as f32 + 0.5) / size as f32 - 1.0) * half;
        let v = (1.0 - 2.0 * (y as f32 + 0.5) / size as f32) * half;
        let ray = (forward + right * u + up * v).normalize();
        // |eye + t ray| = 0.1, nearest t.
        let b = camera.eye.dot(ray);
        let c = camera.eye.length_squared() - 0.01;
        let disc = b * b - c;
        (disc > 0.0).then(|| (camera.eye + ray * (-b - disc.sqrt())).normalize())
    };
    let mut worst_step = 0.0f32;
    let mut interior = 0;
    for y in 2..size - 2 {
        for x in 2..size - 2 {
            if !inside(x, y) || normal_at(x, y).is_none_or(|n| n.dot(key).abs() < 0.3) {
                continue;
            }
            interior += 1;
            // The second difference: a smooth gradient has none, a facet edge or a dark
            // line along an edge has one.
            let across_x = (at(x - 1, y) + at(x + 1, y) - 2.0 * at(x, y)).abs();
            let across_y = (at(x, y - 1) + at(x, y + 1) - 2.0 * at(x, y)).abs();
            worst_step = worst_step.max(across_x).max(across_y);
        }
    }
    eprintln!("{interior} interior pixels, worst second difference {worst_step:.2} / 255");
    assert!(interior > 4_000, "the sphere is not in the picture");
    // Flat 15° facets under this light step by tens of levels; smooth shading (8-bit
    // rounding, the soft shadow's tent) stays within a few.
    assert!(
        worst_step <= 10.0,
        "a step of {worst_step:.1} / 255 inside the sphere: facets or edge lines show"
    );
}
