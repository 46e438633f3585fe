#![doc = include_str!("../README.md")]

pub mod compare;
pub mod engines;
pub mod mcml;
pub mod shape_error;
/// The layered Monte Carlo (owned by `multipole`, which uses it for exact profile shapes).
pub use multipole::exact::montecarlo;
pub mod mean_colours;
pub mod measured;
pub mod measured_colour;
pub mod measured_report;
pub mod noise_chart;
pub mod presets;
