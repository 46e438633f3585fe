//! numpy arrays in (any real dtype, any strides: copied into owned row-major vectors) and out.

use crate::error::{Bad, Checked};
use numpy::ndarray::Array2;
use numpy::{AllowTypeChange, IntoPyArray, PyArray1, PyArray2, PyArrayLike1, PyArrayLike2};
use pyo3::prelude::*;

/// A 1-D array-like of reals as `f64`.
pub type In1<'py> = PyArrayLike1<'py, f64, AllowTypeChange>;
/// A 2-D array-like of reals as `f64`.
pub type In2<'py> = PyArrayLike2<'py, f64, AllowTypeChange>;

/// The values of a 1-D array, copied (works for any strides).
pub fn vec1(a: &In1<'_>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// The rows of a 2-D array with `cols` columns, copied row-major; `name` for the error.
pub fn rows(a: &In2<'_>, cols: Option<usize>, name: &str) -> Checked<(Vec<f64>, usize)> {
    let v = a.as_array();
    let (_, m) = v.dim();
    if let Some(c) = cols
        && m != c
    {
        return Err(Bad::new(
            name,
            format!("last axis has {m} values, expected {c}"),
        ));
    }
    Ok((v.iter().copied().collect(), m))
}

/// A flat vector as a 1-D float64 array (no copy).
pub fn out1(py: Python<'_>, v: Vec<f64>) -> Bound<'_, PyArray1<f64>> {
    v.into_pyarray(py)
}

/// A row-major vector of `rows × cols` values as a 2-D float64 array (no copy).
pub fn out2(py: Python<'_>, v: Vec<f64>, cols: usize) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let rows = v.len().checked_div(cols).unwrap_or(0);
    Array2::from_shape_vec((rows, cols), v)
        .map(|a| a.into_pyarray(py))
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))
}

/// Whether every value of `v` is finite; else the error naming `name`.
pub fn finite(v: &[f64], name: &str, range: &str) -> Checked<()> {
    match v.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(Bad::new(
            name,
            format!("{x} is not a finite number (valid range {range})"),
        )),
        None => Ok(()),
    }
}
