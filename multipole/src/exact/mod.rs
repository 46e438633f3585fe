//! Exact transport in plane-parallel layers, the methods diffusion is judged against: deterministic
//! adding-doubling for the totals (docs/physics.md §10) and the layered Monte Carlo for radial
//! profiles and as an independent reference (docs/physics.md §11).

pub mod adding_doubling;
pub mod montecarlo;
