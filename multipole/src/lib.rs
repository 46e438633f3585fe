#![doc = include_str!("../README.md")]

pub mod diffusion;
pub mod error;
pub mod exact;
pub mod layered;
pub mod sampling;
pub mod skin;

pub use diffusion::profile::Profile;
pub use error::MultipoleError;
pub use layered::{DEFAULT_G, Layer, LayeredMedium, Surface};
pub use skin::{Method, ProfileOptions, SpectralProfiles};
