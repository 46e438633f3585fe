//! Fits over batches: N measured spectra or N colours, one independent fit each, in parallel.

use crate::arrays::{In1, In2, finite, out1, out2, rows, vec1};
use crate::error::{Bad, Checked, on_threads};
use crate::forward::{geometry_of, method_of};
use crate::params::{WIDTH, row_of};
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use skin_fit::{FitOptions, MeasuredOptions, MeasuredSpectrum, ModelChoice};
use skin_optics::lab::Lab;

fn model_of(name: &str) -> Checked<ModelChoice> {
    name.parse::<ModelChoice>()
        .map_err(|_| Bad::new("model", format!("'{name}' is not one of seed, full, auto")))
}

/// A (N, M) block as a 2-D array result.
fn block<'py>(py: Python<'py>, v: Vec<f64>, cols: usize) -> PyResult<Bound<'py, PyArray2<f64>>> {
    out2(py, v, cols)
}

/// The fitted skins as rows of the parameter block (`params.WIDTH` columns).
fn params_block<'py, 'a>(
    py: Python<'py>,
    skins: impl Iterator<Item = &'a skin_optics::SkinParams>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    block(py, skins.flat_map(row_of).collect(), WIDTH)
}

/// Fit each row of `reflectance` (N × M, on `lambda_nm`) with `skin_fit::fit_measured`: the seed
/// model under SCE is `fit_spectrum` bit for bit. Returns the fitted parameter rows (N × 10), the
/// weighted RMS residuals, the model spectra (N × M) and the instrument's surface term.
#[pyfunction]
#[pyo3(signature = (lambda_nm, reflectance, weights, method, geometry, model, noise, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit_spectrum<'py>(
    py: Python<'py>,
    lambda_nm: In1<'py>,
    reflectance: In2<'py>,
    weights: Option<In2<'py>>,
    method: &str,
    geometry: &str,
    model: &str,
    noise: f64,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let lambda = vec1(&lambda_nm);
    let m = lambda.len();
    let (r, _) = rows(&reflectance, Some(m), "reflectance")?;
    let w = match &weights {
        Some(w) => Some(rows(w, Some(m), "weights")?.0),
        None => None,
    };
    if let Some(w) = &w
        && w.len() != r.len()
    {
        return Err(Bad::new("weights", "shape differs from reflectance's").into());
    }
    if !(noise.is_finite() && noise > 0.0) {
        return Err(Bad::new("noise", format!("{noise} outside (0, inf)")).into());
    }
    let opts = MeasuredOptions {
        geometry: geometry_of(geometry)?,
        model: model_of(model)?,
        noise,
        fit: FitOptions {
            method: method_of(method)?,
            ..FitOptions::default()
        },
        ..MeasuredOptions::default()
    };
    let n = r.len().checked_div(m).unwrap_or(0);
    let fits = py.detach(|| {
        on_threads(threads, || {
            (0..n)
                .into_par_iter()
                .map(|i| {
                    let spectrum = MeasuredSpectrum::new(
                        lambda.clone(),
                        r[i * m..(i + 1) * m].to_vec(),
                        w.as_ref().map(|w| w[i * m..(i + 1) * m].to_vec()),
                    )
                    .map_err(|e| Bad::new("reflectance", format!("spectrum {i}: {e}")))?;
                    skin_fit::fit_measured(&spectrum, &opts)
                        .map_err(|e| Bad::new("reflectance", format!("spectrum {i}: {e}")))
                })
                .collect::<Checked<Vec<_>>>()
        })
    })??;
    let d = PyDict::new(py);
    d.set_item("params", params_block(py, fits.iter().map(|f| &f.skin))?)?;
    d.set_item("rms", out1(py, fits.iter().map(|f| f.rms).collect()))?;
    d.set_item(
        "model",
        block(py, fits.iter().flat_map(|f| f.model.clone()).collect(), m)?,
    )?;
    d.set_item(
        "surface_reflectance",
        out1(py, fits.iter().map(|f| f.surface_reflectance).collect()),
    )?;
    Ok(d)
}

/// Fit each CIELAB row (N × 3) with `skin_fit::fit_colour`: parameter rows, the model's CIELAB,
/// the CIEDE2000 residual and whether the colour is in the skin gamut.
#[pyfunction]
#[pyo3(signature = (lab, method, step_nm, threads=None))]
pub fn fit_colour<'py>(
    py: Python<'py>,
    lab: In2<'py>,
    method: &str,
    step_nm: f64,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let (targets, _) = rows(&lab, Some(3), "lab")?;
    finite(&targets, "lab", "finite CIELAB")?;
    let opts = FitOptions {
        method: method_of(method)?,
        step_nm,
        ..FitOptions::default()
    };
    opts.validate().map_err(|e| Bad::new("step_nm", e))?;
    let fits = py.detach(|| {
        on_threads(threads, || {
            targets
                .par_chunks_exact(3)
                .map(|t| {
                    let target = Lab {
                        l: t[0],
                        a: t[1],
                        b: t[2],
                    };
                    skin_fit::fit_colour(target, &opts).map_err(|e| Bad::new("lab", e))
                })
                .collect::<Checked<Vec<_>>>()
        })
    })??;
    let d = PyDict::new(py);
    d.set_item("params", params_block(py, fits.iter().map(|f| &f.skin))?)?;
    d.set_item(
        "lab",
        block(
            py,
            fits.iter()
                .flat_map(|f| [f.lab.l, f.lab.a, f.lab.b])
                .collect(),
            3,
        )?,
    )?;
    d.set_item(
        "delta_e",
        out1(py, fits.iter().map(|f| f.delta_e).collect()),
    )?;
    d.set_item(
        "in_gamut",
        fits.iter().map(|f| f.in_gamut).collect::<Vec<_>>(),
    )?;
    Ok(d)
}
