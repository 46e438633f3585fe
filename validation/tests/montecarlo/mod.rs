//! The Monte Carlo reference: closed forms, conservation, determinism, published totals.

mod closed_forms;
mod determinism;
mod energy;
mod far_field;
pub(crate) mod mcml;
mod reference;

/// Photon count for a test: `release` in release builds, a tenth of it in debug builds.
pub fn photons(release: u64) -> u64 {
    if cfg!(debug_assertions) {
        (release / 10).max(1000)
    } else {
        release
    }
}
