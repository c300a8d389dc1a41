//! The Hairloom editor: the interactive app (`app`) and the export-to-disk code it shares
//! with the `hairloom` command line (`files`). The command line itself is in `src/cli/`
//! (the binary); measuring lives in `hairloom-render` (GPU) and `hairloom-core` (CPU).

pub mod app;
pub mod files;
pub mod progress;
