//! The Hairloom editor: the interactive app (`app`) and the headless render path it shares
//! with the `hairloom render` command (`render`).

pub mod app;
pub mod files;
pub mod render;
