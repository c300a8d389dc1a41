//! The saved document: the hair mesh, the body it grows on, its styling and its scene.
//!
//! View state (camera, selection, GPU handles) never lives here: undo never moves the
//! camera and project files hold only what the artist made.

use serde::{Deserialize, Serialize};

use crate::model::mesh::{HairMesh, InvalidMesh};
use crate::model::scene::Scene;
use crate::model::styling::StylingSet;

/// A triangle mesh drawn under the hair (the head, the teapot) and used for depth testing.
/// Positions are `f32` because the body is display-only; the hair mesh is `f64`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyMesh {
    pub positions: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

impl BodyMesh {
    pub fn validate(&self) -> Result<(), InvalidMesh> {
        for (i, p) in self.positions.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(InvalidMesh {
                    path: format!("positions[{i}]"),
                    message: "position is not finite".into(),
                });
            }
        }
        let count = self.positions.len();
        for (t, triangle) in self.triangles.iter().enumerate() {
            for (c, &v) in triangle.iter().enumerate() {
                if v as usize >= count {
                    return Err(InvalidMesh {
                        path: format!("triangles[{t}][{c}]"),
                        message: format!("vertex index {v} out of range ({count} positions)"),
                    });
                }
            }
        }
        Ok(())
    }
}

/// Everything an artist makes, saved in a project file and edited through commands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Document {
    /// A human-readable name (the sample's or imported file's name).
    pub name: String,
    /// Where the scalp and body came from, with attribution when a licence asks for it.
    #[serde(default)]
    pub source: String,
    pub hair_mesh: HairMesh,
    #[serde(default)]
    pub body: BodyMesh,
    /// Styling parameters: global values with per-bundle-group overrides.
    #[serde(default)]
    pub styling: StylingSet,
    /// Lights, cameras, the hair material and the effects the renderer runs. Files from
    /// before scenes existed (format version 1) get the default scene.
    #[serde(default)]
    pub scene: Scene,
}

/// A validation problem anywhere in a document, with the JSON path of the value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{path}: {message}")]
pub struct InvalidDocument {
    pub path: String,
    pub message: String,
}

impl Document {
    pub fn new(name: impl Into<String>, hair_mesh: HairMesh) -> Self {
        Self {
            name: name.into(),
            source: String::new(),
            hair_mesh,
            body: BodyMesh::default(),
            styling: StylingSet::default(),
            scene: Scene::default(),
        }
    }

    /// Validates the whole document; paths are relative to the document.
    pub fn validate(&self) -> Result<(), InvalidDocument> {
        self.hair_mesh.validate().map_err(|e| InvalidDocument {
            path: format!("hair_mesh.{}", e.path),
            message: e.message,
        })?;
        self.body.validate().map_err(|e| InvalidDocument {
            path: format!("body.{}", e.path),
            message: e.message,
        })?;
        self.styling.validate().map_err(|message| {
            let (path, message) = message.split_once(": ").unwrap_or(("", &message));
            InvalidDocument {
                path: format!("styling.{path}"),
                message: message.to_string(),
            }
        })?;
        self.scene.validate().map_err(|e| InvalidDocument {
            path: format!("scene.{}", e.path),
            message: e.message,
        })
    }
}
