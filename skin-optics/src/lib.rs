#![doc = include_str!("../README.md")]
// Citations such as [DJ06] are keys of REFERENCES.md, not paths: rustdoc would report each one as
// an unresolved intra-doc link.
#![allow(rustdoc::broken_intra_doc_links)]

pub mod chromophores;
pub mod coefficients;
pub mod color;
pub mod echo;
pub mod error;
pub mod lab;
pub mod measured;
pub mod params;
pub mod physiology;
pub mod spectrum;
mod table;
#[cfg(test)]
mod test_util;
pub mod units;

pub use coefficients::{LayerCoefficients, SkinCoefficients};
pub use error::OpticsError;
pub use params::{Preset, SkinParams};
pub use physiology::{Extension, Physiology};
pub use spectrum::{GridSpectrum, WavelengthGrid};
pub use units::Wavelength;
