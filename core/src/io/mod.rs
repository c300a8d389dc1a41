//! Files in and out: project files, glTF scalp import, and the exports (the runtime bundle
//! with its KTX2 textures, and strand files for other tools, Alembic grooms among them), and
//! grooms made in other tools read back in ([`groom_in`]).

pub mod alembic;
pub mod cards_gltf;
pub mod groom_in;
pub mod import;
pub mod input_files;
pub mod ktx2;
pub mod project;
pub mod runtime_bundle;
pub mod scalp_region;
pub mod strand_files;
