//! Helpers shared by this crate's unit tests.

use crate::units::Wavelength;

/// A wavelength the test knows to be valid, nm.
pub(crate) fn wl(nm: f64) -> Wavelength {
    Wavelength::new(nm).unwrap()
}

/// Relative difference |a − b| / |b|, for the hand-computed checks.
pub(crate) fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}
