//! The skin written for another renderer or simulator (`skin_export`), as text.

use crate::arrays::{In1, vec1};
use crate::error::Bad;
use crate::params::skin_of;
use pyo3::prelude::*;
use skin_export::{ColourSpace, ExportOptions, Format};
use skin_optics::WavelengthGrid;

/// The file text of `format` for one skin and the notes on what it holds.
#[pyfunction]
#[pyo3(signature = (format, params, from_nm, to_nm, step_nm, escapes, photons, volume_photons, colour_space, mcx_lambda_nm))]
#[allow(clippy::too_many_arguments)]
pub fn export(
    py: Python<'_>,
    format: &str,
    params: In1<'_>,
    from_nm: f64,
    to_nm: f64,
    step_nm: f64,
    escapes: u64,
    photons: u64,
    volume_photons: u64,
    colour_space: &str,
    mcx_lambda_nm: f64,
) -> PyResult<(String, Vec<String>)> {
    let format: Format = format.parse().map_err(|e| Bad::new("format", e))?;
    let skin = skin_of(&vec1(&params))?;
    let opts = ExportOptions {
        grid: WavelengthGrid::new(from_nm, to_nm, step_nm)
            .map_err(|e| Bad::new("from_nm/to_nm/step_nm", e))?,
        escapes,
        photons,
        volume_photons,
        colour_space: colour_space
            .parse::<ColourSpace>()
            .map_err(|e| Bad::new("colour_space", e))?,
        lambda_nm: mcx_lambda_nm,
        ..ExportOptions::default()
    };
    opts.validate().map_err(|e| Bad::new("export options", e))?;
    let out = py
        .detach(|| skin_export::export(&skin, format, &opts))
        .map_err(|e| Bad::new("export", e))?;
    Ok((out.text, out.notes))
}
