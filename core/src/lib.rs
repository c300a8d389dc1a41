//! Hairloom core: the hair-mesh document and everything computed from it on the CPU.
//!
//! Data flows one way: [`document::Document`] (edited only through [`edit`] functions
//! recorded as [`history::Command`]s) → derived geometry ([`interior`], [`frames`],
//! [`curve`]) → runtime data. This crate has no GPU or UI dependency; the f64 code here is
//! the reference every faster path is measured against.

pub mod atlas;
pub mod curve;
pub mod document;
pub mod edit;
pub mod export;
pub mod frames;
pub mod gpu_types;
pub mod history;
pub mod import;
pub mod interior;
pub mod lod;
pub mod mesh;
pub mod pick;
pub mod project;
pub mod random;
pub mod roots;
pub mod runtime;
pub mod samples;
pub mod select;
pub mod strands;
pub mod styling;
pub mod teapot;
pub mod uv;

pub use document::{BodyMesh, Document};
pub use history::{Command, History, Transaction};
pub use mesh::{Bundle, Column, HairMesh, Topology, VertexRef, WMode};
pub use project::Project;
