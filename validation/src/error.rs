//! Typed errors of the validation crate: every variant names the parameter, its value and its valid range.

use thiserror::Error;

/// An invalid input to the Monte Carlo or the comparison.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ValidationError {
    /// A parameter is NaN, infinite or outside its valid interval.
    #[error("{name} = {value} outside {range}")]
    OutOfRange {
        /// Parameter name as the user knows it.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Human-readable valid range, e.g. `[0, 1]`.
        range: &'static str,
    },
    /// A layer stack that cannot be simulated (empty, or a semi-infinite layer that is not the last).
    #[error("invalid layer stack: {0}")]
    Stack(String),
    /// An invalid skin parameter or wavelength.
    #[error(transparent)]
    Optics(#[from] skin_optics::OpticsError),
}

/// Check that `value` is finite and in `[min, max]`; `range` is the text shown to the user.
pub(crate) fn check_range(
    name: &'static str,
    value: f64,
    min: f64,
    max: f64,
    range: &'static str,
) -> Result<f64, ValidationError> {
    if value.is_finite() && (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(ValidationError::OutOfRange { name, value, range })
    }
}
