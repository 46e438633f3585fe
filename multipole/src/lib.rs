#![doc = include_str!("../README.md")]

pub mod adding_doubling;
pub mod boundary;
pub mod dipole;
pub mod error;
pub mod fit;
pub mod hankel;
pub mod medium;
pub mod montecarlo;
pub mod profile;
pub mod skin;
pub mod slab;
pub mod spatial;
pub mod stack;

pub use dipole::Dipole;
pub use error::MultipoleError;
pub use medium::Medium;
pub use profile::Profile;
pub use skin::{Method, SpectralProfiles};
pub use slab::{Poles, Slab};
pub use spatial::ProfileOptions;
pub use stack::{Layer, Response, Stack};
