//! The `skin` command line: one module per subcommand, argument structs shared between them.
//!
//! Only this crate knows about the command line; the physics crates take validated types.

pub mod args;
pub mod brdf;
pub mod fit;
mod fit_measured;
pub mod presets;
pub mod profile;
pub mod render;
pub mod spectrum;
