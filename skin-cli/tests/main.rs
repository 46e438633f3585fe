//! The `skin` command line end to end: each subcommand's output, errors and files.

mod bad_scenes;
mod cli_brdf;
mod cli_explain;
mod cli_fit;
mod cli_maps;
mod cli_measured;
mod cli_profile;
mod cli_render;
mod cli_spectrum;
mod common;
mod export;
mod fuzz;
mod memory_bound;
