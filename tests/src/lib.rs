//! Helpers for Hairloom's cross-crate tests: small meshes, crafted glTF files, paths to the
//! bundled assets.

use std::path::PathBuf;

use glam::DVec3;
use hairloom_core::HairMesh;

/// The repository's `assets/` folder.
pub fn assets_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets")
}

/// Every bundled sample project.
pub fn sample_paths() -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(assets_dir().join("samples"))
        .map(|entries| {
            entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "hairloom"))
                .collect()
        })
        .unwrap_or_default();
    paths.sort();
    paths
}

/// A gently curved `nx × ny` quad scalp with uv = grid position, extruded `layers` times
/// by `step` along +z (all columns equally tall).
pub fn grid_mesh(nx: usize, ny: usize, layers: u32, step: f64) -> HairMesh {
    let scalp = hairloom_core::samples::grid_scalp(nx, ny, |s, t| {
        let (x, y) = (s * nx as f64, t * ny as f64);
        DVec3::new(x, y, 0.05 * (x * x + y * y))
    });
    hairloom_core::samples::straight_layers(scalp, layers, DVec3::Z * step)
}

/// Builds small glTF files for importer tests. Accessors are tightly packed in one buffer.
#[derive(Default)]
pub struct GltfBuilder {
    pub bin: Vec<u8>,
    pub views: Vec<serde_json::Value>,
    pub accessors: Vec<serde_json::Value>,
    pub meshes: Vec<serde_json::Value>,
}

impl GltfBuilder {
    /// Adds f32 data as an accessor of `type_name` ("VEC3", "VEC2", …); returns its index.
    pub fn add_f32(&mut self, values: &[f32], type_name: &str, count: usize) -> usize {
        let offset = self.bin.len();
        for v in values {
            self.bin.extend_from_slice(&v.to_le_bytes());
        }
        self.views.push(
            serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": values.len() * 4}),
        );
        let mut accessor = serde_json::json!({
            "bufferView": self.views.len() - 1, "componentType": 5126, "count": count, "type": type_name
        });
        if type_name == "VEC3" {
            // glTF requires min/max on POSITION accessors.
            let mut min = [f32::INFINITY; 3];
            let mut max = [f32::NEG_INFINITY; 3];
            for (i, v) in values.iter().enumerate().filter(|(_, v)| v.is_finite()) {
                min[i % 3] = min[i % 3].min(*v);
                max[i % 3] = max[i % 3].max(*v);
            }
            accessor["min"] = serde_json::json!(min.map(|v| if v.is_finite() { v } else { 0.0 }));
            accessor["max"] = serde_json::json!(max.map(|v| if v.is_finite() { v } else { 0.0 }));
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Adds u32 indices; returns the accessor index.
    pub fn add_indices(&mut self, indices: &[u32]) -> usize {
        let offset = self.bin.len();
        for v in indices {
            self.bin.extend_from_slice(&v.to_le_bytes());
        }
        self.views.push(
            serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": indices.len() * 4}),
        );
        self.accessors.push(serde_json::json!({
            "bufferView": self.views.len() - 1, "componentType": 5125, "count": indices.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }

    /// A unit quad (two triangles) with uv, as a mesh named `name`.
    pub fn add_quad_mesh(&mut self, name: &str) -> usize {
        let positions = [
            0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0,
        ];
        let uvs = [0.0f32, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
        let p = self.add_f32(&positions, "VEC3", 4);
        let t = self.add_f32(&uvs, "VEC2", 4);
        let i = self.add_indices(&[0, 1, 2, 0, 2, 3]);
        self.meshes.push(serde_json::json!({
            "name": name,
            "primitives": [{"attributes": {"POSITION": p, "TEXCOORD_0": t}, "indices": i, "mode": 4}]
        }));
        self.meshes.len() - 1
    }

    /// The glTF JSON document (buffer 0 is the GLB binary chunk).
    pub fn json(&self) -> serde_json::Value {
        let nodes: Vec<serde_json::Value> = (0..self.meshes.len())
            .map(|m| serde_json::json!({"mesh": m}))
            .collect();
        serde_json::json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": (0..self.meshes.len()).collect::<Vec<_>>()}],
            "nodes": nodes,
            "meshes": self.meshes,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{"byteLength": self.bin.len()}],
        })
    }

    /// A GLB file from `json` and this builder's binary chunk.
    pub fn glb(&self, json: &serde_json::Value) -> Vec<u8> {
        hairloom_core::io::strand_files::glb_container(json, self.bin.clone())
    }
}

/// A character of two meshes, "body" and "scalp", each a unit quad.
pub fn two_mesh_glb() -> Vec<u8> {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("body");
    builder.add_quad_mesh("scalp");
    builder.glb(&builder.json())
}

/// A body made of a strip of three unit quads along x as one mesh, "body": the first two
/// quads in a primitive with material "Scalp", the third in one with material "Skin", and
/// an 8-bit normalised COLOR_0 painted red (1) on the vertices at x = 0 and 1, black at
/// x = 2 and 3 (so the faces' mean red is 1, ½ and 0 along the strip).
pub fn body_with_materials_glb() -> Vec<u8> {
    let mut builder = GltfBuilder::default();
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    let mut colours = Vec::new();
    for y in 0..2 {
        for x in 0..4 {
            positions.extend([x as f32, y as f32, 0.0]);
            uvs.extend([x as f32 / 3.0, y as f32]);
            colours.extend([if x <= 1 { 255u8 } else { 0 }, 0, 0, 255]);
        }
    }
    let p = builder.add_f32(&positions, "VEC3", 8);
    let t = builder.add_f32(&uvs, "VEC2", 8);
    let offset = builder.bin.len();
    builder.bin.extend_from_slice(&colours);
    builder
        .views
        .push(serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": colours.len()}));
    builder.accessors.push(serde_json::json!({
        "bufferView": builder.views.len() - 1, "componentType": 5121, "normalized": true,
        "count": 8, "type": "VEC4"
    }));
    let c = builder.accessors.len() - 1;
    // Quad x..x+1 is vertices (x, x+1, x+5, x+4), counter-clockwise seen from +z.
    let quad = |x: u32| [x, x + 1, x + 5, x, x + 5, x + 4];
    let scalp = builder.add_indices(&[quad(0), quad(1)].concat());
    let skin = builder.add_indices(&quad(2));
    let attributes = serde_json::json!({"POSITION": p, "TEXCOORD_0": t, "COLOR_0": c});
    builder.meshes.push(serde_json::json!({
        "name": "body",
        "primitives": [
            {"attributes": attributes, "indices": scalp, "mode": 4, "material": 0},
            {"attributes": attributes, "indices": skin, "mode": 4, "material": 1}
        ]
    }));
    let mut json = builder.json();
    json["materials"] = serde_json::json!([{"name": "Scalp"}, {"name": "Skin"}]);
    builder.glb(&json)
}

/// A quad mesh whose node (translated by (0, 1, 0) and scaled 2×) is turned 90° about Y over
/// one second and lifted 0.5 along Y, with LINEAR keys; `edit` changes the JSON first.
pub fn animated_quad_glb(edit: impl Fn(&mut serde_json::Value)) -> Vec<u8> {
    let mut builder = GltfBuilder::default();
    builder.add_quad_mesh("body");
    let times = builder.add_f32(&[0.0, 1.0], "SCALAR", 2);
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let turns = builder.add_f32(&[0.0, 0.0, 0.0, 1.0, 0.0, half, 0.0, half], "VEC4", 2);
    let lifts = builder.add_f32(&[0.0, 1.0, 0.0, 0.0, 1.5, 0.0], "VEC3", 2);
    let mut json = builder.json();
    json["nodes"][0]["translation"] = serde_json::json!([0.0, 1.0, 0.0]);
    json["nodes"][0]["scale"] = serde_json::json!([2.0, 2.0, 2.0]);
    json["animations"] = serde_json::json!([{
        "channels": [
            {"sampler": 0, "target": {"node": 0, "path": "rotation"}},
            {"sampler": 1, "target": {"node": 0, "path": "translation"}}
        ],
        "samplers": [
            {"input": times, "output": turns, "interpolation": "LINEAR"},
            {"input": times, "output": lifts, "interpolation": "LINEAR"}
        ]
    }]);
    edit(&mut json);
    builder.glb(&json)
}

/// A small document whose runtime bundle differs per `variant` in geometry only (same
/// sizes and formats): the case where a mixed bundle would render silently wrong.
pub fn bundle_variant(variant: u32) -> hairloom_core::Document {
    let mut mesh = grid_mesh(3, 3, 2, 0.1);
    for column in &mut mesh.columns {
        for p in &mut column.positions {
            *p += DVec3::X * 0.05 * variant as f64;
        }
    }
    hairloom_core::geometry::interior::place_interior(&mut mesh, None);
    hairloom_core::Document::new("variant", mesh)
}

/// The runtime bundle files of [`bundle_variant`] `variant`, manifest last.
pub fn bundle_variant_files(variant: u32) -> Vec<(String, Vec<u8>)> {
    hairloom_core::io::runtime_bundle::runtime_bundle(
        &bundle_variant(variant),
        &hairloom_core::runtime::hair::RuntimeOptions::default(),
    )
    .expect("the variant exports")
}
