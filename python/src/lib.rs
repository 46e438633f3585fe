//! The native half of the `spectral_skin` Python package: flat numpy arrays in and out, one row per
//! evaluation point. Broadcasting, defaults and result objects live in the Python half
//! (`python/spectral_skin/__init__.py`), which is the documented interface.
//!
//! Every call copies its inputs into owned vectors, releases the GIL (`py.detach`) and runs on
//! rayon's pool (or a pool of `threads` workers), so long calls use all cores and leave other
//! Python threads running.

use pyo3::prelude::*;

mod arrays;
mod colour;
mod error;
mod export;
mod fit;
mod forward;
mod maps;
mod params;

/// The extension module `spectral_skin._native`.
#[pymodule]
#[pyo3(name = "_native")]
fn native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SkinError", m.py().get_type::<error::SkinError>())?;
    m.add(
        "DEFAULT_SHAPE_ESCAPES",
        multipole::skin::DEFAULT_SHAPE_ESCAPES,
    )?;
    let export = skin_export::ExportOptions::default();
    m.add("DEFAULT_EXPORT_PHOTONS", export.photons)?;
    m.add("DEFAULT_EXPORT_VOLUME_PHOTONS", export.volume_photons)?;
    m.add("DEFAULT_EXPORT_ESCAPES", export.escapes)?;
    m.add_function(wrap_pyfunction!(params::skin_columns, m)?)?;
    m.add_function(wrap_pyfunction!(params::preset_row, m)?)?;
    m.add_function(wrap_pyfunction!(params::presets, m)?)?;
    m.add_function(wrap_pyfunction!(forward::coefficients, m)?)?;
    m.add_function(wrap_pyfunction!(forward::diffuse_reflectance, m)?)?;
    m.add_function(wrap_pyfunction!(forward::profile, m)?)?;
    m.add_function(wrap_pyfunction!(forward::monte_carlo, m)?)?;
    m.add_function(wrap_pyfunction!(forward::adding_doubling, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit_spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit_colour, m)?)?;
    m.add_function(wrap_pyfunction!(colour::xyz, m)?)?;
    m.add_function(wrap_pyfunction!(colour::lab_from_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(colour::lab_from_srgb, m)?)?;
    m.add_function(wrap_pyfunction!(colour::srgb_from_lab, m)?)?;
    m.add_function(wrap_pyfunction!(colour::delta_e_2000, m)?)?;
    m.add_function(wrap_pyfunction!(colour::ita, m)?)?;
    m.add_function(wrap_pyfunction!(export::export, m)?)?;
    m.add_function(wrap_pyfunction!(maps::maps, m)?)?;
    Ok(())
}
