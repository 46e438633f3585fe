//! Chromophore maps of an albedo texture (`skin_fit::maps`): per-texel C_m and C_h, one β_m.

use crate::arrays::{In2, out1, rows};
use crate::error::{Bad, on_threads};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLike1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use skin_fit::maps::{
    DEFAULT_SMOOTHNESS, Eumelanin, Exposure, FittedRange, MapsError, MapsModel, MapsOptions,
    Regions,
};
use skin_fit::{ModelChoice, Parameter};

/// A 1-D array-like of flags.
type InMask<'py> = PyArrayLike1<'py, bool, AllowTypeChange>;

/// A maps error as the bad input it names.
fn bad(e: MapsError) -> Bad {
    match e {
        MapsError::Length { what, .. } => Bad::new(what, e),
        MapsError::Option { name, .. } if name.starts_with("eumelanin regions") => {
            Bad::new("eumelanin_regions", e)
        }
        MapsError::Option { name, .. } => Bad::new(name, e),
        other => Bad::new("albedo_rgb", other),
    }
}

/// A fitted range as a dict (`min`, `max`, `tolerance_de`, `rms_de`), or None.
fn range_dict<'py>(
    py: Python<'py>,
    r: Option<FittedRange>,
) -> PyResult<Option<Bound<'py, PyDict>>> {
    r.map(|r| {
        let d = PyDict::new(py);
        d.set_item("min", r.min)?;
        d.set_item("max", r.max)?;
        d.set_item("tolerance_de", r.tolerance_de)?;
        d.set_item("rms_de", r.best_rms_de)?;
        Ok(d)
    })
    .transpose()
}

/// The exposure of `skin maps --exposure`: `"auto"`, `"auto-rgb"` or `"gains"` with `gains`.
fn exposure_of(kind: &str, gains: [f64; 3]) -> Result<Exposure, Bad> {
    match kind {
        "auto" => Ok(Exposure::Auto),
        "auto-rgb" => Ok(Exposure::WhiteBalance),
        "gains" => Ok(Exposure::Fixed(gains)),
        other => Err(Bad::new(
            "exposure",
            format!("'{other}' is not a gain, three gains, 'auto' or 'auto-rgb'"),
        )),
    }
}

/// Fit the maps of `texels` (N × 3 linear Rec.709 diffuse albedo, rows of `width` texels), only
/// where `mask` (N,) is true if given, with β_m `eumelanin`, fitted per texture (`None`) or per
/// square region of `eumelanin_regions` texels a side, under the exposure `exposure` (`"gains"`
/// with `gains`, `"auto"`, `"auto-rgb"`) and the skin model `model` (`seed`, `full`, `auto`)
/// over the extended `parameters` (their `skin fit --json` names; `None`: all of them); texels
/// out of gamut fitted again under a thin epidermis if `thin_epidermis` (`thin_epidermis_mm`,
/// `None`: the default), whose C_h reaches `thin_hemoglobin_max` (`None`: the default 0.25).
/// Returns flat (N,) maps and the summary.
#[pyfunction]
#[pyo3(signature = (texels, width, mask, eumelanin, eumelanin_regions, exposure, gains, model, parameters, thin_epidermis, thin_epidermis_mm, thin_hemoglobin_max, cache, threads=None))]
#[allow(clippy::too_many_arguments)]
pub fn maps<'py>(
    py: Python<'py>,
    texels: In2<'py>,
    width: usize,
    mask: Option<InMask<'py>>,
    eumelanin: Option<f64>,
    eumelanin_regions: Option<usize>,
    exposure: &str,
    gains: [f64; 3],
    model: &str,
    parameters: Option<Vec<String>>,
    thin_epidermis: bool,
    thin_epidermis_mm: Option<f64>,
    thin_hemoglobin_max: Option<f64>,
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
    if eumelanin.is_some() && eumelanin_regions.is_some() {
        return Err(Bad::new(
            "eumelanin_regions",
            "a block size fits β_m per region: give it or eumelanin, not both",
        )
        .into());
    }
    let choice: ModelChoice = model
        .parse()
        .map_err(|e: skin_fit::FitError| Bad::new("model", e))?;
    let candidates: Vec<Parameter> = match parameters {
        None => Parameter::CANDIDATES.to_vec(),
        Some(names) => names
            .iter()
            .map(|n| {
                Parameter::CANDIDATES
                    .iter()
                    .copied()
                    .find(|p| p.name() == n.trim())
                    .ok_or_else(|| {
                        let known: Vec<&str> =
                            Parameter::CANDIDATES.iter().map(|p| p.name()).collect();
                        Bad::new(
                            "parameters",
                            format!("'{n}' is not one of {}", known.join(", ")),
                        )
                    })
            })
            .collect::<Result<_, _>>()?,
    };
    let mut opts = MapsOptions {
        eumelanin: match (eumelanin, eumelanin_regions) {
            (Some(b), _) => Eumelanin::Fixed(b),
            (None, Some(block)) => Eumelanin::PerRegion(Regions {
                width,
                block,
                smoothness: DEFAULT_SMOOTHNESS,
            }),
            (None, None) => Eumelanin::Fit,
        },
        exposure: exposure_of(exposure, gains)?,
        thin_epidermis_mm: thin_epidermis
            .then_some(thin_epidermis_mm.unwrap_or(skin_fit::maps::THIN_EPIDERMIS_MM)),
        thin_hemoglobin_max: thin_hemoglobin_max
            .unwrap_or(skin_fit::maps::THIN_HEMOGLOBIN_RANGE[1]),
        cache_dir: if cache {
            skin_io::cache::cache_dir()
        } else {
            None
        },
        ..MapsOptions::default()
    };
    opts.validate().map_err(bad)?;
    let (maps, extended) = py.detach(|| {
        on_threads(threads, || {
            let mut table = MapsModel::load(&opts).map_err(bad)?;
            let extended = if choice == ModelChoice::Seed {
                None
            } else {
                let fit = table
                    .fit_extended(
                        &texels,
                        mask.as_deref(),
                        &opts,
                        choice,
                        &candidates,
                        &|_| {},
                    )
                    .map_err(bad)?;
                opts.base = fit.base;
                table = MapsModel::load(&opts).map_err(bad)?;
                Some(fit)
            };
            let maps = table
                .fit(&texels, mask.as_deref(), &opts, &|_| {})
                .map_err(bad)?;
            Ok::<_, Bad>((maps, extended))
        })
    })??;
    let wide = |x: &[f32]| -> Vec<f64> { x.iter().map(|&c| f64::from(c)).collect() };
    let d = PyDict::new(py);
    d.set_item("melanin", out1(py, wide(&maps.melanin)))?;
    d.set_item("hemoglobin", out1(py, wide(&maps.hemoglobin)))?;
    d.set_item("delta_e", out1(py, wide(&maps.delta_e)))?;
    d.set_item("in_gamut", maps.in_gamut.into_pyarray(py))?;
    d.set_item("fitted", maps.fitted.into_pyarray(py))?;
    let thin = maps
        .thin_epidermis
        .as_ref()
        .map_or_else(|| vec![false; maps.melanin.len()], |t| t.texels.clone());
    d.set_item("thin_epidermis", thin.into_pyarray(py))?;
    if let Some(b) = &maps.eumelanin_map {
        d.set_item("eumelanin_map", out1(py, wide(b)))?;
    }
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
    summary.set_item("exposure", s.exposure.to_vec())?;
    summary.set_item("exposure_range", range_dict(py, s.exposure_spread)?)?;
    let regions = s
        .regions
        .as_ref()
        .map(|r| {
            let rd = PyDict::new(py);
            rd.set_item("block", eumelanin_regions)?;
            rd.set_item("regions", r.regions)?;
            rd.set_item("min", r.min)?;
            rd.set_item("median", r.median)?;
            rd.set_item("max", r.max)?;
            rd.set_item("median_allowed_width", r.median_allowed_width)?;
            Ok::<_, PyErr>(rd)
        })
        .transpose()?;
    summary.set_item("regions", regions)?;
    summary.set_item("model", choice.to_string())?;
    summary.set_item("thin_epidermis", s.thin_epidermis)?;
    let extended = extended
        .map(|e| {
            let ed = PyDict::new(py);
            ed.set_item("seed_rms_de", e.seed_rms_de)?;
            ed.set_item("rms_de", e.rms_de)?;
            let values = PyDict::new(py);
            for v in &e.values {
                let vd = PyDict::new(py);
                vd.set_item("value", v.value)?;
                vd.set_item("kept", v.kept)?;
                vd.set_item("range", range_dict(py, Some(v.range))?)?;
                values.set_item(v.parameter.name(), vd)?;
            }
            ed.set_item("values", values)?;
            Ok::<_, PyErr>(ed)
        })
        .transpose()?;
    summary.set_item("extended", extended)?;
    d.set_item("summary", summary)?;
    Ok(d)
}
