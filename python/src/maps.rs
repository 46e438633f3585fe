//! Chromophore maps of an albedo texture (`skin_fit::maps`): per-texel C_m and C_h, one β_m.

use crate::arrays::{In2, out1, rows};
use crate::error::{Bad, on_threads};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLike1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use skin_fit::maps::{Eumelanin, MapsError, MapsModel, MapsOptions};

/// A 1-D array-like of flags.
type InMask<'py> = PyArrayLike1<'py, bool, AllowTypeChange>;

/// A maps error as the bad input it names.
fn bad(e: MapsError) -> Bad {
    match e {
        MapsError::Length { what, .. } => Bad::new(what, e),
        MapsError::Option { name, .. } => Bad::new(name, e),
        other => Bad::new("albedo_rgb", other),
    }
}

/// Fit the maps of `texels` (N × 3 linear Rec.709 diffuse albedo), only where `mask` (N,) is true
/// if given, with β_m `eumelanin` or fitted (`None`). Returns flat (N,) maps and the summary.
#[pyfunction]
#[pyo3(signature = (texels, mask, eumelanin, cache, threads=None))]
pub fn maps<'py>(
    py: Python<'py>,
    texels: In2<'py>,
    mask: Option<InMask<'py>>,
    eumelanin: Option<f64>,
    cache: bool,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let (v, _) = rows(&texels, Some(3), "albedo_rgb")?;
    let texels: Vec<[f32; 3]> = v
        .chunks_exact(3)
        .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32])
        .collect();
    let mask: Option<Vec<bool>> = mask.map(|m| m.as_array().iter().copied().collect());
    if let Some(b) = eumelanin
        && !(b.is_finite() && (0.0..=1.0).contains(&b))
    {
        return Err(Bad::new("eumelanin", format!("{b} outside [0, 1] (or None: fitted)")).into());
    }
    let opts = MapsOptions {
        eumelanin: eumelanin.map_or(Eumelanin::Fit, Eumelanin::Fixed),
        cache_dir: if cache {
            skin_io::cache::cache_dir()
        } else {
            None
        },
        ..MapsOptions::default()
    };
    let maps = py.detach(|| {
        on_threads(threads, || {
            let model = MapsModel::load(&opts).map_err(bad)?;
            model
                .fit(&texels, mask.as_deref(), &opts, &|_| {})
                .map_err(bad)
        })
    })??;
    let wide = |x: &[f32]| -> Vec<f64> { x.iter().map(|&c| f64::from(c)).collect() };
    let d = PyDict::new(py);
    d.set_item("melanin", out1(py, wide(&maps.melanin)))?;
    d.set_item("hemoglobin", out1(py, wide(&maps.hemoglobin)))?;
    d.set_item("delta_e", out1(py, wide(&maps.delta_e)))?;
    d.set_item("in_gamut", maps.in_gamut.into_pyarray(py))?;
    d.set_item("fitted", maps.fitted.into_pyarray(py))?;
    let s = &maps.summary;
    let summary = PyDict::new(py);
    summary.set_item("eumelanin", maps.eumelanin)?;
    let spread = s.eumelanin_spread;
    summary.set_item("eumelanin_fitted", spread.is_some())?;
    summary.set_item("eumelanin_min", spread.map_or(maps.eumelanin, |x| x.min))?;
    summary.set_item("eumelanin_max", spread.map_or(maps.eumelanin, |x| x.max))?;
    summary.set_item("eumelanin_tolerance_de", spread.map(|x| x.tolerance_de))?;
    summary.set_item("eumelanin_rms_de", spread.map(|x| x.best_rms_de))?;
    summary.set_item("texels", texels.len())?;
    summary.set_item("fitted", s.fitted)?;
    summary.set_item("in_gamut", s.in_gamut)?;
    summary.set_item("invalid", s.invalid)?;
    summary.set_item("median_delta_e", s.median_de)?;
    summary.set_item("p95_delta_e", s.p95_de)?;
    summary.set_item("max_delta_e", s.max_de)?;
    summary.set_item("in_gamut_delta_e", skin_fit::maps::IN_GAMUT_DE)?;
    d.set_item("summary", summary)?;
    Ok(d)
}
