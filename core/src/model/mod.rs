//! What the artist makes and saves: the hair mesh, the body it grows on, the styling
//! parameters, the scene (lights, material, effects), and the undo history of commands over them. Nothing here is view state.

pub mod change;
pub mod document;
pub mod history;
pub mod mesh;
pub mod motion;
pub mod root_maps;
pub mod scene;
pub mod styling;
