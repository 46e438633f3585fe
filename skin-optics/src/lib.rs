#![doc = include_str!("../README.md")]

pub mod chromophores;
pub mod color;
pub mod echo;
pub mod error;
pub mod lab;
pub mod params;
pub mod spectrum;
mod table;
pub mod units;

pub use chromophores::{LayerCoefficients, SkinCoefficients};
pub use error::OpticsError;
pub use params::{Preset, SkinParams};
pub use spectrum::{GridSpectrum, WavelengthGrid};
pub use units::Wavelength;
