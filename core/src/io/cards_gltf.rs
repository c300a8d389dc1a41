//! Hair cards as binary glTF: one mesh of card strips (positions, normals, tangents, atlas
//! uvs) with a material whose base colour is the baked albedo atlas (PNG, embedded; its alpha
//! is the strands' coverage, so `alphaMode` is `MASK`), double-sided because a card is seen
//! from both sides. glTF has no material slots for the other baked maps (coverage, depth,
//! flow, root to tip, id): they are embedded too, as textures the material's
//! `extras.hairloom_maps` names (`{"texture": index, "file": the same PNG beside the GLB}`),
//! so a loader that reads extras finds them in the file itself.

use crate::cards::CardMesh;
use crate::io::strand_files::glb_container;

/// Names of the maps written beside a card file, in `extras.hairloom_maps`.
pub const CARD_MAPS: [&str; 5] = ["coverage", "depth", "flow", "root_to_tip", "id"];

/// One baked map embedded in a card GLB: its name (see [`CARD_MAPS`]), the file name of the
/// same PNG beside the GLB, and the PNG.
pub struct CardMap<'a> {
    pub name: &'a str,
    pub file: String,
    pub png: &'a [u8],
}

/// The GLB of one level of detail, `albedo_png` embedded as its base colour and every map
/// of `maps` as a texture named in the material's extras.
pub fn card_glb(name: &str, mesh: &CardMesh, albedo_png: &[u8], maps: &[CardMap]) -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut push_view = |bin: &mut Vec<u8>, bytes: &[u8], target: Option<u32>| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let mut view = serde_json::json!({
            "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()
        });
        if let Some(target) = target {
            view["target"] = target.into();
        }
        bin.extend_from_slice(bytes);
        views.push(view);
        views.len() - 1
    };
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in &mesh.positions {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    if mesh.positions.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    const ARRAY_BUFFER: u32 = 34962;
    const ELEMENT_ARRAY_BUFFER: u32 = 34963;
    let positions = push_view(
        &mut bin,
        bytemuck::cast_slice(&mesh.positions),
        Some(ARRAY_BUFFER),
    );
    let normals = push_view(
        &mut bin,
        bytemuck::cast_slice(&mesh.normals),
        Some(ARRAY_BUFFER),
    );
    let tangents = push_view(
        &mut bin,
        bytemuck::cast_slice(&mesh.tangents),
        Some(ARRAY_BUFFER),
    );
    let uvs = push_view(
        &mut bin,
        bytemuck::cast_slice(&mesh.uvs),
        Some(ARRAY_BUFFER),
    );
    let indices = push_view(
        &mut bin,
        bytemuck::cast_slice(&mesh.indices),
        Some(ELEMENT_ARRAY_BUFFER),
    );
    let image = push_view(&mut bin, albedo_png, None);
    let mut images = vec![serde_json::json!({"bufferView": image, "mimeType": "image/png"})];
    let mut extras = serde_json::Map::new();
    for map in maps {
        let view = push_view(&mut bin, map.png, None);
        images.push(
            serde_json::json!({"bufferView": view, "mimeType": "image/png", "name": map.name}),
        );
        // Texture i shows image i (texture 0 is the albedo).
        extras.insert(
            map.name.to_string(),
            serde_json::json!({"texture": images.len() - 1, "file": map.file}),
        );
    }
    let textures: Vec<serde_json::Value> = (0..images.len())
        .map(|i| serde_json::json!({"source": i, "sampler": 0}))
        .collect();
    let count = mesh.positions.len();
    let json = serde_json::json!({
        "asset": {"version": "2.0", "generator": format!("hairloom {}", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": name}],
        "meshes": [{"name": name, "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3},
            "indices": 4, "material": 0, "mode": 4
        }]}],
        "materials": [{
            "name": "hair_cards",
            "pbrMetallicRoughness": {
                "baseColorTexture": {"index": 0},
                "metallicFactor": 0.0,
                "roughnessFactor": 0.6
            },
            "alphaMode": "MASK",
            "alphaCutoff": 0.3,
            "doubleSided": true,
            "extras": {"hairloom_maps": extras}
        }],
        "textures": textures,
        // Linear without mipmaps: tiles meet edge to edge, so coarser mip levels would blend
        // neighbouring cards (an engine that builds mipmaps should stop at the tile size).
        "samplers": [{"magFilter": 9729, "minFilter": 9729, "wrapS": 33071, "wrapT": 33071}],
        "images": images,
        "accessors": [
            {"bufferView": positions, "componentType": 5126, "count": count, "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": normals, "componentType": 5126, "count": count, "type": "VEC3"},
            {"bufferView": tangents, "componentType": 5126, "count": count, "type": "VEC4"},
            {"bufferView": uvs, "componentType": 5126, "count": count, "type": "VEC2"},
            {"bufferView": indices, "componentType": 5125, "count": mesh.indices.len(), "type": "SCALAR"}
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}]
    });
    glb_container(&json, bin)
}
