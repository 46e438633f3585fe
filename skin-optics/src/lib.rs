#![doc = include_str!("../README.md")]
// Citations such as [DJ06] are keys of REFERENCES.md, not paths: rustdoc would report each one as
// an unresolved intra-doc link.
#![allow(rustdoc::broken_intra_doc_links)]

pub mod chromophores;
pub mod color;
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
