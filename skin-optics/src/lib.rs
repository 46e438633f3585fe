#![doc = include_str!("../README.md")]

pub mod chromophores;
pub mod color;
pub mod error;
pub mod lab;
pub mod measured;
pub mod params;
pub mod physiology;
pub mod spectrum;
mod table;
pub mod units;

pub use chromophores::{LayerCoefficients, SkinCoefficients};
pub use error::OpticsError;
pub use params::{Preset, SkinParams};
pub use physiology::{Extension, Physiology};
pub use spectrum::{GridSpectrum, WavelengthGrid};
pub use units::Wavelength;
