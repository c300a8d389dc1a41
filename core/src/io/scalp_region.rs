//! Where hair grows on an imported mesh. A whole body imported as a scalp would make every
//! face of the face, neck and shoulders a bundle; the artist names the scalp instead — by the
//! glTF material its faces use, by a mask painted into the file's vertex colours, or (in the
//! editor) by faces selected on the body before bundles are made. The whole mesh stays the
//! body either way.

use std::fmt;
use std::str::FromStr;

use crate::io::import::ImportedMesh;

/// One channel of a face's mean vertex colour (COLOR_0, linear).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColourChannel {
    Red,
    Green,
    Blue,
    Alpha,
}

impl ColourChannel {
    pub const ALL: [Self; 4] = [Self::Red, Self::Green, Self::Blue, Self::Alpha];

    fn index(self) -> usize {
        match self {
            Self::Red => 0,
            Self::Green => 1,
            Self::Blue => 2,
            Self::Alpha => 3,
        }
    }

    pub fn letter(self) -> char {
        ['r', 'g', 'b', 'a'][self.index()]
    }
}

/// Which faces of an imported mesh become bare bundles.
#[derive(Clone, Debug, PartialEq)]
pub enum ScalpRegion {
    /// Every face (a mesh that is only a scalp).
    All,
    /// Faces whose glTF primitive uses one of these materials (by name, or `material N`
    /// for an unnamed one).
    Materials(Vec<String>),
    /// Faces whose mean vertex colour has `channel` above `threshold` (or below it, when
    /// `above` is false: a mask painted dark on a white default).
    VertexColour {
        channel: ColourChannel,
        above: bool,
        threshold: f64,
    },
    /// Faces by index into [`ImportedMesh::faces`] (a selection made on the body).
    Faces(Vec<usize>),
}

/// Why a region cannot be cut from a mesh, or cannot be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScalpRegionError {
    #[error(
        "mesh \"{mesh}\" has no material named \"{name}\" (its materials: {available}); name one with --hair-on material:NAME"
    )]
    UnknownMaterial {
        mesh: String,
        name: String,
        available: String,
    },
    #[error(
        "mesh \"{mesh}\" has no vertex colours (COLOR_0), so a painted mask cannot choose its scalp"
    )]
    NoVertexColour { mesh: String },
    #[error("face {face} is out of range: mesh \"{mesh}\" has {faces} faces")]
    FaceOutOfRange {
        mesh: String,
        face: usize,
        faces: usize,
    },
    #[error("no face of mesh \"{mesh}\" is in the region {region}: no bundle would grow hair")]
    Empty { mesh: String, region: String },
    #[error(
        "cannot read hair region \"{text}\": {why} (use all, material:NAME[,NAME…] or colour:CHANNEL>VALUE / colour:CHANNEL<VALUE with CHANNEL r, g, b or a)"
    )]
    Parse { text: String, why: String },
}

impl fmt::Display for ScalpRegion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::All => write!(f, "all"),
            Self::Materials(names) => write!(f, "material:{}", names.join(",")),
            Self::VertexColour {
                channel,
                above,
                threshold,
            } => write!(
                f,
                "colour:{}{}{threshold}",
                channel.letter(),
                if *above { '>' } else { '<' }
            ),
            Self::Faces(faces) => write!(f, "{} selected faces", faces.len()),
        }
    }
}

impl FromStr for ScalpRegion {
    type Err = ScalpRegionError;

    /// `all`, `material:Scalp,Brows`, `colour:r>0.5` (or `color:`), `colour:g<0.25`.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let fail = |why: &str| ScalpRegionError::Parse {
            text: text.to_string(),
            why: why.to_string(),
        };
        let trimmed = text.trim();
        if trimmed.eq_ignore_ascii_case("all") {
            return Ok(Self::All);
        }
        let (kind, rest) = trimmed
            .split_once(':')
            .ok_or_else(|| fail("expected KIND:VALUE"))?;
        match kind.to_ascii_lowercase().as_str() {
            "material" => {
                let names: Vec<String> = rest
                    .split(',')
                    .map(str::trim)
                    .filter(|n| !n.is_empty())
                    .map(str::to_string)
                    .collect();
                if names.is_empty() {
                    return Err(fail("no material named"));
                }
                Ok(Self::Materials(names))
            }
            "colour" | "color" => {
                let (at, above) = match (rest.find('>'), rest.find('<')) {
                    (Some(at), None) => (at, true),
                    (None, Some(at)) => (at, false),
                    _ => return Err(fail("expected one of > or <")),
                };
                let channel = match rest[..at].trim().to_ascii_lowercase().as_str() {
                    "r" | "red" => ColourChannel::Red,
                    "g" | "green" => ColourChannel::Green,
                    "b" | "blue" => ColourChannel::Blue,
                    "a" | "alpha" => ColourChannel::Alpha,
                    _ => return Err(fail("unknown colour channel")),
                };
                let threshold: f64 = rest[at + 1..]
                    .trim()
                    .parse()
                    .map_err(|_| fail("the threshold is not a number"))?;
                if !(0.0..=1.0).contains(&threshold) {
                    return Err(fail("the threshold must lie in [0, 1]"));
                }
                Ok(Self::VertexColour {
                    channel,
                    above,
                    threshold,
                })
            }
            _ => Err(fail("unknown kind")),
        }
    }
}

impl ScalpRegion {
    /// Which faces of `mesh` are in the region: one flag per face, at least one set.
    pub fn faces(&self, mesh: &ImportedMesh) -> Result<Vec<bool>, ScalpRegionError> {
        let count = mesh.faces.len();
        let keep = match self {
            Self::All => vec![true; count],
            Self::Materials(names) => {
                for name in names {
                    if !mesh
                        .primitive_materials
                        .iter()
                        .any(|m| m.as_deref() == Some(name))
                    {
                        return Err(ScalpRegionError::UnknownMaterial {
                            mesh: mesh.mesh_name.clone(),
                            name: name.clone(),
                            available: material_list(mesh),
                        });
                    }
                }
                // Once per primitive, then a lookup per face.
                let chosen: Vec<bool> = mesh
                    .primitive_materials
                    .iter()
                    .map(|m| m.as_ref().is_some_and(|m| names.contains(m)))
                    .collect();
                mesh.face_primitives
                    .iter()
                    .map(|&p| chosen[p as usize])
                    .collect()
            }
            Self::VertexColour {
                channel,
                above,
                threshold,
            } => {
                let colours =
                    mesh.face_colours
                        .as_ref()
                        .ok_or_else(|| ScalpRegionError::NoVertexColour {
                            mesh: mesh.mesh_name.clone(),
                        })?;
                colours
                    .iter()
                    .map(|c| {
                        let value = c[channel.index()];
                        if *above {
                            value > *threshold
                        } else {
                            value < *threshold
                        }
                    })
                    .collect()
            }
            Self::Faces(faces) => {
                let mut keep = vec![false; count];
                for &face in faces {
                    *keep
                        .get_mut(face)
                        .ok_or_else(|| ScalpRegionError::FaceOutOfRange {
                            mesh: mesh.mesh_name.clone(),
                            face,
                            faces: count,
                        })? = true;
                }
                keep
            }
        };
        if !keep.contains(&true) {
            return Err(ScalpRegionError::Empty {
                mesh: mesh.mesh_name.clone(),
                region: self.to_string(),
            });
        }
        Ok(keep)
    }
}

/// Each material of `mesh` with the number of faces that use it, in primitive order (a
/// material used by several primitives once); faces of primitives with no material are
/// not listed.
pub fn material_faces(mesh: &ImportedMesh) -> Vec<(String, usize)> {
    let mut out: Vec<(String, usize)> = Vec::new();
    // Each primitive's entry in `out`, found once; then a face is one lookup.
    let slot: Vec<Option<usize>> = mesh
        .primitive_materials
        .iter()
        .map(|material| {
            let name = material.as_ref()?;
            Some(match out.iter().position(|(n, _)| n == name) {
                Some(at) => at,
                None => {
                    out.push((name.clone(), 0));
                    out.len() - 1
                }
            })
        })
        .collect();
    for &p in &mesh.face_primitives {
        if let Some(at) = slot[p as usize] {
            out[at].1 += 1;
        }
    }
    out
}

fn material_list(mesh: &ImportedMesh) -> String {
    let list = material_faces(mesh);
    if list.is_empty() {
        "none".into()
    } else {
        list.iter()
            .map(|(name, faces)| format!("\"{name}\" ({})", face_count(*faces)))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// "1 face", "2 faces".
pub fn face_count(faces: usize) -> String {
    if faces == 1 {
        "1 face".into()
    } else {
        format!("{faces} faces")
    }
}
