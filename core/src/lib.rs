//! Hairloom core: the hair-mesh document and everything computed from it on the CPU.
//!
//! The folders follow the pipeline, and data flows one way through them:
//!
//! | folder | stage |
//! |---|---|
//! | [`model`] | the document (hair mesh, body, styling parameters) and its undo history |
//! | [`edit`] | edits as pure functions (topology, transforms, coordinates, wisps), selection and picking |
//! | [`geometry`] | derived f64 geometry: interior vertices, styling frames, column curves, uv |
//! | [`strands`] | root samples, random numbers, styling ops, LOD formulas, the f64 reference strands |
//! | [`simulate`] | hair that moves: the body's distance field, wind, XPBD on the hair-mesh vertices, drape |
//! | [`light`] | the scene's light on the CPU: fibre material, the Marschner model, dual-scattering tables, opacity-map math, the reference path tracer |
//! | [`runtime`] | the runtime asset ([`runtime::hair::RuntimeHair`]: textures, samples, placements, styling) and the CPU mirror of every shader |
//! | [`cards`] | hair cards from bundles: card strips with the strands baked into an atlas |
//! | [`fur`] | fur as shells and fins (seed 002): the strand volume, its shell and fin textures, lapped patches over any mesh |
//! | [`fit`] | grooms made elsewhere turned into a hair mesh and styling, and the fit's measured error |
//! | [`io`] | project files, glTF import, the runtime bundle (KTX2 + manifest) strand exports, Alembic grooms and card glTF, grooms read in |
//! | [`samples`] | the bundled sample projects, built by code |
//!
//! This crate has no GPU or UI dependency; the f64 code here is the reference every faster
//! path is measured against.

pub mod cards;
pub mod edit;
pub mod fit;
pub mod fur;
pub mod geometry;
pub mod io;
pub mod light;
pub mod model;
pub mod parallel;
pub mod runtime;
pub mod samples;
pub mod simulate;
pub mod strands;

pub use io::project::Project;
pub use model::document::{BodyMesh, Document};
pub use model::history::{Command, History, Transaction};
pub use model::mesh::{Bundle, Column, HairMesh, Topology, VertexRef, WMode};
