//! Typed errors of the layered-transport crate: every variant names the parameter, its value and its range.
//!
//! `check_range` returns this crate's error type, so every range check of the crate reports
//! through it.

use skin_optics::OpticsError;
use thiserror::Error;

/// An input outside the domain of a transport method.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MultipoleError {
    /// A physical parameter (coefficient, thickness, index, radius) is NaN, infinite or out of range.
    #[error("{name} = {} outside {range}", skin_optics::echo::Num(*.value))]
    OutOfRange {
        /// Parameter name with its symbol and unit, e.g. `"σa (mm⁻¹)"`.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Human-readable valid range, e.g. `[0, 1e6]`.
        range: &'static str,
    },
    /// A numerical knob (`ProfileOptions`, `DiffusionOptions`) is out of range.
    #[error("option {name} = {} outside {range}", skin_optics::echo::Num(*.value))]
    InvalidOption {
        /// Knob name, e.g. `"radial_samples"`.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Human-readable valid range.
        range: &'static str,
    },
    /// A layer stack that cannot be combined (empty, or a semi-infinite layer above another layer).
    #[error("invalid layer stack: {0}")]
    Stack(&'static str),
    /// A layered medium that cannot be built (empty, or a semi-infinite layer not last).
    #[error("invalid layered medium: {0}")]
    Layers(String),
    /// An unknown method name (valid: `exact`, `multipole`).
    #[error("unknown method '{0}' (valid: exact, multipole)")]
    UnknownMethod(String),
    /// Invalid input to the exact (adding-doubling) transport solver.
    #[error(transparent)]
    Exact(#[from] AddingDoublingError),
    /// A profile table that is not finite and non-negative, or whose radii do not increase.
    #[error("invalid profile table: {0}")]
    Profile(&'static str),
    /// An error from the optical coefficients (wavelength, grid).
    #[error(transparent)]
    Optics(#[from] OpticsError),
}

/// Invalid input to the adding-doubling solver, naming the parameter, its value and its valid range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AddingDoublingError {
    /// A parameter outside its valid range (or not a number).
    #[error("{name} = {value} outside {range}")]
    OutOfRange {
        /// Parameter name.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Valid range, as text.
        range: &'static str,
    },
    /// A semi-infinite layer that does not absorb has no finite answer to converge to numerically.
    #[error("a semi-infinite layer needs sigma_a > 0 (got {sigma_a_per_mm} mm⁻¹)")]
    SemiInfiniteWithoutAbsorption {
        /// Its absorption coefficient, mm⁻¹.
        sigma_a_per_mm: f64,
    },
    /// The adding equations met a singular matrix (a lossless loop between two layers).
    #[error("singular matrix while {0} (a non-absorbing layer against a totally reflecting one?)")]
    Singular(&'static str),
}

/// Check that `value` is finite and in `[min, max]`; `range` is the text shown to the user.
pub(crate) fn check_range(
    name: &'static str,
    value: f64,
    min: f64,
    max: f64,
    range: &'static str,
) -> Result<f64, MultipoleError> {
    if value.is_finite() && value >= min && value <= max {
        Ok(value)
    } else {
        Err(MultipoleError::OutOfRange { name, value, range })
    }
}

/// Check that the knob `value` is finite and in `[min, max]`; `range` is the text shown to the user.
pub(crate) fn check_option(
    name: &'static str,
    value: f64,
    min: f64,
    max: f64,
    range: &'static str,
) -> Result<(), MultipoleError> {
    if value.is_finite() && value >= min && value <= max {
        Ok(())
    } else {
        Err(MultipoleError::InvalidOption { name, value, range })
    }
}
