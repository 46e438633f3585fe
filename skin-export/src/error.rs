//! Errors of an export: every message names the parameter or input line and its valid range.

use multipole::MultipoleError;
use skin_optics::OpticsError;
use thiserror::Error;

/// Why an export failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The format name is not one of [`crate::Format::ALL`].
    #[error(
        "unknown export format '{0}' (valid: openpbr, standard-surface, unreal, hdrp, gaussians, burley, pbrt, mitsuba, mcml, mcx, blender, blender-json)"
    )]
    UnknownFormat(String),
    /// A numeric option outside its range.
    #[error("{name} = {value} outside {range}")]
    OutOfRange {
        /// The option (with its unit).
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The valid range.
        range: &'static str,
    },
    /// A colour space the format cannot carry.
    #[error("--colour-space {space}: {format} cannot carry it (valid: {valid})")]
    ColourSpace {
        /// The format's name.
        format: &'static str,
        /// The refused colour space.
        space: &'static str,
        /// What the format takes.
        valid: &'static str,
    },
    /// Bad skin parameters or wavelengths.
    #[error(transparent)]
    Optics(#[from] OpticsError),
    /// The transport models failed (profiles, adding-doubling, Monte Carlo).
    #[error(transparent)]
    Transport(#[from] MultipoleError),
    /// An MCML input that does not parse.
    #[error("MCML input line {line}: {message}")]
    Mci {
        /// 1-based line number in the input.
        line: usize,
        /// What was expected there.
        message: String,
    },
    /// A Cycles calibration table that does not parse or fit.
    #[error("Cycles calibration table line {line}: {message}")]
    Calibration {
        /// 1-based line number (0: the table as a whole).
        line: usize,
        /// What was wrong.
        message: String,
    },
    /// A chromophore texture that cannot be exported: the channel or option, and what is wrong.
    #[error("{key}: {message}")]
    Texture {
        /// The channel (melanin, eumelanin, hemoglobin), `size` or `format`.
        key: &'static str,
        /// What was wrong, with the valid range.
        message: String,
    },
    /// A fit that found no admissible value.
    #[error("{0}")]
    Fit(String),
}

/// Reject `value` outside [lo, hi] (or non-finite) as [`ExportError::OutOfRange`].
pub fn check(
    name: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    range: &'static str,
) -> Result<f64, ExportError> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(ExportError::OutOfRange { name, value, range })
    }
}
