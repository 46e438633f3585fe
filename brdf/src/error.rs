//! Typed errors for invalid BRDF parameters.

use thiserror::Error;

/// A parameter outside the domain of the surface-reflection model. Every variant carries the parameter
/// name, the offending value and the valid range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BrdfError {
    /// A parameter is NaN or infinite.
    #[error("{name} = {value} is not a finite number (valid range {range})")]
    NonFinite {
        /// Parameter name as the user knows it.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Human-readable valid range, e.g. `(0, 1]`.
        range: &'static str,
    },
    /// A parameter lies outside its valid interval.
    #[error("{name} = {value} outside {range}")]
    OutOfRange {
        /// Parameter name as the user knows it.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Human-readable valid range, e.g. `(0, 1]`.
        range: &'static str,
    },
}

/// Validate a Beckmann roughness (RMS slope) m: finite and in (0, 1].
pub fn check_roughness(roughness_m: f32) -> Result<f32, BrdfError> {
    check_f32(
        "roughness m",
        roughness_m,
        0.0,
        1.0,
        Bounds::OpenBelow,
        "(0, 1]",
    )
}

/// Validate an oiliness ρ_s (linear scale of the lobe): finite and in [0, 1].
pub fn check_oiliness(oiliness_rho_s: f32) -> Result<f32, BrdfError> {
    check_f32(
        "oiliness ρ_s",
        oiliness_rho_s,
        0.0,
        1.0,
        Bounds::Closed,
        "[0, 1]",
    )
}

/// Validate a relative refractive index η: finite and in [1, 3].
pub fn check_eta(eta: f32) -> Result<f32, BrdfError> {
    check_f32("eta η", eta, 1.0, 3.0, Bounds::Closed, "[1, 3]")
}

/// [`check_range`] for an f32 parameter, returning it unchanged.
fn check_f32(
    name: &'static str,
    value: f32,
    min: f64,
    max: f64,
    bounds: Bounds,
    range: &'static str,
) -> Result<f32, BrdfError> {
    check_range(name, f64::from(value), min, max, bounds, range).map(|_| value)
}

/// Which end of an interval is open.
#[derive(Clone, Copy)]
pub(crate) enum Bounds {
    /// `[min, max]`.
    Closed,
    /// `(min, max]`.
    OpenBelow,
}

/// Check that `value` is finite and inside the interval; `range` is the text shown to the user.
pub(crate) fn check_range(
    name: &'static str,
    value: f64,
    min: f64,
    max: f64,
    bounds: Bounds,
    range: &'static str,
) -> Result<f64, BrdfError> {
    if !value.is_finite() {
        return Err(BrdfError::NonFinite { name, value, range });
    }
    let below = match bounds {
        Bounds::Closed => value < min,
        Bounds::OpenBelow => value <= min,
    };
    if below || value > max {
        return Err(BrdfError::OutOfRange { name, value, range });
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn open_lower_bound_rejects_the_bound_itself() {
        assert!(check_range("m", 0.0, 0.0, 1.0, Bounds::OpenBelow, "(0, 1]").is_err());
        assert!(check_range("m", 1.0, 0.0, 1.0, Bounds::OpenBelow, "(0, 1]").is_ok());
        assert!(check_range("m", f64::NAN, 0.0, 1.0, Bounds::OpenBelow, "(0, 1]").is_err());
        let e = check_range("roughness m", 1.5, 0.0, 1.0, Bounds::OpenBelow, "(0, 1]").unwrap_err();
        assert_eq!(e.to_string(), "roughness m = 1.5 outside (0, 1]");
    }
}
