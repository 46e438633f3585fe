//! Typed errors of the fit: bad measured data (with its line), bad options, or a failing forward model.
//!
//! Kept beside the fit rather than in the crate's `error.rs` (owned by the diffusion work) so the fit's
//! data-format errors stay out of the physics error type; the forward model's errors are wrapped as-is.

use multipole::MultipoleError;
use skin_optics::OpticsError;
use thiserror::Error;

/// Why a fit could not run. Data errors name the line of the CSV (1-based) and the valid range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FitError {
    /// The CSV has no header line (every data line must follow `lambda_nm,reflectance[,weight]`).
    #[error(
        "line {line}: expected the header `lambda_nm,reflectance` or `lambda_nm,reflectance,weight`, found `{found}`"
    )]
    Header {
        /// Line number, 1-based.
        line: usize,
        /// The text found instead.
        found: String,
    },
    /// A data line with the wrong number of comma-separated fields.
    #[error("line {line}: {found} fields, expected {expected} (as the header)")]
    FieldCount {
        /// Line number, 1-based.
        line: usize,
        /// Fields found.
        found: usize,
        /// Fields the header announced.
        expected: usize,
    },
    /// A field that is not a finite number.
    #[error("line {line}: {column} `{text}` is not a finite number")]
    Number {
        /// Line number, 1-based.
        line: usize,
        /// Column name.
        column: &'static str,
        /// The text that failed to parse.
        text: String,
    },
    /// A value outside its valid range (wavelength, reflectance or weight).
    #[error("line {line}: {column} = {} outside {range}", skin_optics::echo::Num(*.value))]
    Value {
        /// Line number, 1-based.
        line: usize,
        /// Column name.
        column: &'static str,
        /// The offending value.
        value: f64,
        /// Valid range, e.g. `[0, 1]`.
        range: &'static str,
    },
    /// More data points than a fit accepts.
    #[error(
        "{points} data points; a spectrum fit accepts at most {max} (one per 0.1 nm over 400-700 nm)"
    )]
    TooMuchData {
        /// Data points found (counting stops one past the cap).
        points: usize,
        /// The cap, [`super::measured::MAX_POINTS`].
        max: usize,
    },
    /// Wavelengths that do not strictly increase.
    #[error("line {line}: wavelength {lambda_nm} nm does not increase (previous {previous_nm} nm)")]
    NotIncreasing {
        /// Line number, 1-based.
        line: usize,
        /// The offending wavelength, nm.
        lambda_nm: f64,
        /// The wavelength on the previous data line, nm.
        previous_nm: f64,
    },
    /// Too few data points to determine the fitted parameters, or all weights zero.
    #[error("{0}")]
    NotEnoughData(String),
    /// A fit option outside its range.
    #[error("fit option {name} = {} outside {range}", skin_optics::echo::Num(*.value))]
    Option {
        /// Option name, e.g. `"step_nm"`.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// Valid range.
        range: &'static str,
    },
    /// A name (geometry, model, parameter) that is not one of the valid ones.
    #[error("unknown {what} '{found}' (valid: {valid})")]
    Unknown {
        /// What was being named, e.g. `"geometry"`.
        what: &'static str,
        /// The text given.
        found: String,
        /// The valid names.
        valid: &'static str,
    },
    /// The surface lobe of the SCI geometry could not be built or integrated.
    #[error("surface lobe: {0}")]
    Surface(#[from] brdf::BrdfError),
    /// The forward model (diffuse reflectance) failed for a candidate skin.
    #[error("forward model: {0}")]
    Model(#[from] MultipoleError),
    /// Invalid optical input (wavelength, skin parameters).
    #[error(transparent)]
    Optics(#[from] OpticsError),
}
