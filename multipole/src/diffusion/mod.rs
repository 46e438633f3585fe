//! Diffusion theory for layered media ([JMLH01], [DJ05]; docs/physics.md §2–§8): the boundary
//! condition, the diffusion medium, the dipole (semi-infinite) and multipole (finite slab)
//! solutions, frequency-domain stacking of layers, the inverse Hankel transform to radial profiles,
//! and the tabulated profile with its radius sampling.

pub mod boundary;
pub mod dipole;
pub mod hankel;
pub mod medium;
pub mod profile;
pub mod slab;
pub mod spatial;
pub mod stack;
