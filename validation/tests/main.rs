//! Cross-crate properties and Monte Carlo agreement, one test binary (house style).
//!
//! Photon counts are scaled down in debug builds (`cargo test` without `--release`): every
//! tolerance is stated in standard errors, so the tests stay meaningful at either count.

mod exact;
mod montecarlo;
mod properties;
