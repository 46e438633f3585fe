#![doc = include_str!("../README.md")]

pub mod diffusion;
pub mod error;
pub mod exact;
pub mod layered;
pub mod sampling;
pub mod skin;

// The modules by their short names, so `multipole::slab::Slab`, `multipole::montecarlo::run`, ...
// keep working next to the grouped paths.
pub use diffusion::{boundary, dipole, hankel, medium, profile, slab, spatial, stack};
pub use exact::{adding_doubling, montecarlo};

pub use diffusion::dipole::Dipole;
pub use diffusion::medium::Medium;
pub use diffusion::profile::Profile;
pub use diffusion::slab::{Poles, Slab};
pub use diffusion::spatial::ProfileOptions;
pub use diffusion::stack::{DiffusionLayer, Response, Stack};
pub use error::MultipoleError;
pub use layered::{DEFAULT_G, Layer, LayeredMedium};
pub use skin::{Method, SpectralProfiles};
