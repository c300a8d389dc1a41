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
