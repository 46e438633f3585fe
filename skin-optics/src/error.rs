//! Typed errors for invalid optical inputs.

use thiserror::Error;

/// An input outside the domain of the skin model. Every variant names the parameter and its valid range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OpticsError {
    /// A parameter is NaN or infinite.
    #[error("{name} = {value} is not a finite number (valid range {range})")]
    NonFinite {
        /// Parameter name as the user knows it.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Human-readable valid range, e.g. `[0, 1]`.
        range: &'static str,
    },
    /// A parameter lies outside its closed valid interval.
    #[error("{name} = {} outside {range}", crate::echo::Num(*.value))]
    OutOfRange {
        /// Parameter name as the user knows it.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Human-readable valid range, e.g. `[0, 1]`.
        range: &'static str,
    },
    /// A wavelength grid that is empty, unordered or has a non-positive step.
    #[error("invalid wavelength grid: {0}")]
    Grid(String),
    /// Two spectra on different wavelength grids were combined.
    #[error("spectra are on different wavelength grids")]
    GridMismatch,
}

/// Check that `value` is finite and in `[min, max]`; `range` is the text shown to the user.
pub(crate) fn check_range(
    name: &'static str,
    value: f64,
    min: f64,
    max: f64,
    range: &'static str,
) -> Result<f64, OpticsError> {
    if !value.is_finite() {
        return Err(OpticsError::NonFinite { name, value, range });
    }
    if value < min || value > max {
        return Err(OpticsError::OutOfRange { name, value, range });
    }
    Ok(value)
}

/// [`check_range`] on the half-open interval (0, `max`]: zero is rejected as out of range.
pub(crate) fn check_positive(
    name: &'static str,
    value: f64,
    max: f64,
    range: &'static str,
) -> Result<f64, OpticsError> {
    let v = check_range(name, value, 0.0, max, range)?;
    if v <= 0.0 {
        return Err(OpticsError::OutOfRange { name, value, range });
    }
    Ok(v)
}
