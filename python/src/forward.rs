//! The forward model over flat arrays: coefficients, diffuse reflectance, profiles, Monte Carlo.

use crate::arrays::{In1, In2, out1, out2, rows, vec1};
use crate::error::{Bad, Checked, on_threads};
use crate::params::{WIDTH, skin_of, wavelength};
use multipole::exact::montecarlo::{self, McOptions, RadialGrid};
use multipole::skin::{ExactShape, ShapeTableOptions};
use multipole::{LayeredMedium, Method, ProfileOptions, Surface};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use skin_fit::Geometry;

/// The method named `name` (`exact` or `multipole`).
pub fn method_of(name: &str) -> Checked<Method> {
    name.parse::<Method>()
        .map_err(|_| Bad::new("method", format!("'{name}' is not one of exact, multipole")))
}

/// The instrument geometry named `name` (`sce` or `sci`).
pub fn geometry_of(name: &str) -> Checked<Geometry> {
    name.parse::<Geometry>()
        .map_err(|_| Bad::new("geometry", format!("'{name}' is not one of sce, sci")))
}

/// Wavelengths and parameter rows of equal count, copied.
fn points(lambda_nm: &In1<'_>, params: &In2<'_>) -> Checked<(Vec<f64>, Vec<f64>)> {
    let lambda = vec1(lambda_nm);
    let (p, _) = rows(params, Some(WIDTH), "params")?;
    if p.len() != lambda.len() * WIDTH {
        return Err(Bad::new(
            "wavelength_nm",
            format!(
                "{} wavelengths for {} parameter rows",
                lambda.len(),
                p.len() / WIDTH
            ),
        ));
    }
    Ok((lambda, p))
}

/// σa of the epidermis and dermis and σs' (mm⁻¹) per point: rows of 3 ([DJ06] eqs 1–6).
#[pyfunction]
pub fn coefficients<'py>(
    py: Python<'py>,
    lambda_nm: In1<'py>,
    params: In2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (lambda, p) = points(&lambda_nm, &params)?;
    let out = py.detach(|| -> Checked<Vec<f64>> {
        let mut out = Vec::with_capacity(lambda.len() * 3);
        for (nm, row) in lambda.iter().zip(p.chunks_exact(WIDTH)) {
            let c = skin_of(row)?.coefficients(wavelength(*nm)?);
            out.extend([
                c.epidermis.sigma_a,
                c.dermis.sigma_a,
                c.epidermis.sigma_s_prime,
            ]);
        }
        Ok(out)
    })?;
    out2(py, out, 3)
}

/// Diffuse reflectance per unit incident flux at each point (SCE: (1 − F_r(0)) R_d; SCI adds the
/// oily surface's albedo at 8°), computed in parallel.
#[pyfunction]
#[pyo3(signature = (lambda_nm, params, method, geometry, threads=None))]
pub fn diffuse_reflectance<'py>(
    py: Python<'py>,
    lambda_nm: In1<'py>,
    params: In2<'py>,
    method: &str,
    geometry: &str,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let method = method_of(method)?;
    let geometry = geometry_of(geometry)?;
    let (lambda, p) = points(&lambda_nm, &params)?;
    let out = py.detach(|| {
        on_threads(threads, || {
            lambda
                .par_iter()
                .zip(p.par_chunks_exact(WIDTH))
                .map(|(nm, row)| -> Checked<f64> {
                    let skin = skin_of(row)?;
                    let r = multipole::skin::diffuse_reflectance(&skin, wavelength(*nm)?, method)
                        .map_err(|e| Bad::new("params", e))?;
                    let s = geometry
                        .surface_reflectance(skin.oiliness(), skin.eta())
                        .map_err(|e| Bad::new("geometry", e))?;
                    Ok(r + s)
                })
                .collect::<Checked<Vec<f64>>>()
        })
    })??;
    Ok(out1(py, out))
}

/// The skin's surface as the boundary of exact transport: Fresnel faces without a roughness, the
/// oily lobe of Beckmann slope `roughness` and the skin's own ρ_s with one (docs/physics.md §10.1).
fn surface_of(roughness: Option<f64>, oiliness: f64) -> Checked<Surface> {
    roughness.map_or(Ok(Surface::Fresnel), |m| {
        Surface::lobe(m, oiliness).map_err(|e| Bad::new("roughness", e))
    })
}

/// R(r) in mm⁻² (per unit flux entering) of one skin at each wavelength (rows) and radius (columns).
#[pyfunction]
#[pyo3(signature = (r_mm, lambda_nm, params, method, shape, escapes, threads=None, roughness=None))]
#[allow(clippy::too_many_arguments)]
pub fn profile<'py>(
    py: Python<'py>,
    r_mm: In1<'py>,
    lambda_nm: In1<'py>,
    params: In1<'py>,
    method: &str,
    shape: &str,
    escapes: u64,
    threads: Option<usize>,
    roughness: Option<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let method = method_of(method)?;
    let exact_shape = match shape {
        "table" => ExactShape::Table(ShapeTableOptions::default()),
        "monte-carlo" | "monte_carlo" => ExactShape::MonteCarlo { escapes },
        _ => {
            return Err(Bad::new(
                "shape",
                format!("'{shape}' is not one of table, monte-carlo"),
            )
            .into());
        }
    };
    let radii = vec1(&r_mm);
    crate::arrays::finite(&radii, "r_mm", "[0, inf) mm")?;
    if let Some(r) = radii.iter().find(|r| **r < 0.0) {
        return Err(Bad::new("r_mm", format!("{r} outside [0, inf) mm")).into());
    }
    let lambda = vec1(&lambda_nm);
    let skin = skin_of(&vec1(&params))?;
    let opts = ProfileOptions {
        exact_shape,
        surface: surface_of(roughness, skin.oiliness())?,
        ..ProfileOptions::default()
    };
    opts.validate().map_err(|e| Bad::new("escapes", e))?;
    let out = py.detach(|| {
        on_threads(threads, || {
            lambda
                .par_iter()
                .map(|nm| -> Checked<Vec<f64>> {
                    let p = multipole::skin::profile(&skin, wavelength(*nm)?, method, &opts)
                        .map_err(|e| Bad::new("params", e))?;
                    Ok(radii.iter().map(|&r| p.eval(r)).collect())
                })
                .collect::<Checked<Vec<Vec<f64>>>>()
        })
    })??;
    out2(py, out.concat(), radii.len())
}

/// The layered Monte Carlo of one skin at one wavelength ([WJZ95]): totals with standard errors and
/// R(r) on `bins` uniform annuli out to `r_max_mm`, under Fresnel faces or the oily lobe's.
#[pyfunction]
#[pyo3(signature = (lambda_nm, params, photons, batches, seed, r_max_mm, bins, threads=None, roughness=None))]
#[allow(clippy::too_many_arguments)]
pub fn monte_carlo<'py>(
    py: Python<'py>,
    lambda_nm: f64,
    params: In1<'py>,
    photons: u64,
    batches: u32,
    seed: u64,
    r_max_mm: f64,
    bins: usize,
    threads: Option<usize>,
    roughness: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let skin = skin_of(&vec1(&params))?;
    let lambda = wavelength(lambda_nm)?;
    let medium = LayeredMedium::skin(&skin, lambda, multipole::DEFAULT_G)
        .map_err(|e| Bad::new("params", e))?
        .with_surface(surface_of(roughness, skin.oiliness())?);
    if !(r_max_mm.is_finite() && r_max_mm > 0.0) {
        return Err(Bad::new("r_max_mm", format!("{r_max_mm} outside (0, inf) mm")).into());
    }
    let grid =
        RadialGrid::new(r_max_mm / bins.max(1) as f64, bins).map_err(|e| Bad::new("bins", e))?;
    let opts = McOptions::new(photons, batches, seed)
        .map_err(|e| Bad::new("photons", e))?
        .with_grid(grid);
    let res = py.detach(|| on_threads(threads, || montecarlo::run(&medium, &opts)))?;
    let d = PyDict::new(py);
    d.set_item("photons", res.photons)?;
    d.set_item("diffuse_reflectance", res.diffuse_reflectance.mean)?;
    d.set_item("diffuse_reflectance_stderr", res.diffuse_reflectance.stderr)?;
    d.set_item("transmittance", res.transmittance.mean)?;
    d.set_item("transmittance_stderr", res.transmittance.stderr)?;
    d.set_item("absorbed", res.absorbed.mean)?;
    d.set_item("absorbed_stderr", res.absorbed.stderr)?;
    d.set_item("specular_reflectance", res.specular_reflectance)?;
    let g = res.radial.grid;
    d.set_item(
        "r_mm",
        out1(py, (0..g.bins()).map(|i| g.r_mid_mm(i)).collect()),
    )?;
    d.set_item(
        "reflectance_per_mm2",
        out1(py, res.radial.reflectance_per_mm2),
    )?;
    d.set_item("reflectance_stderr_per_mm2", out1(py, res.radial.stderr))?;
    d.set_item("beyond_grid", res.radial.beyond_grid)?;
    Ok(d)
}

/// Columns of a slab row of [`adding_doubling`].
const SLAB_COLUMNS: [&str; 7] = [
    "sigma_a_per_mm",
    "sigma_s_per_mm",
    "g",
    "n",
    "thickness_mm",
    "n_above",
    "n_below",
];

/// Exact totals ([Prahl95], [vdH80]) of one homogeneous layer per row (σa, σs in mm⁻¹, HG g,
/// index n, thickness in mm (inf: semi-infinite), indices above and below) for a normally incident
/// beam: rows of (diffuse reflectance, specular reflectance, transmittance).
#[pyfunction]
#[pyo3(signature = (slabs, quadrature_points, threads=None))]
pub fn adding_doubling<'py>(
    py: Python<'py>,
    slabs: In2<'py>,
    quadrature_points: usize,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    use multipole::Layer;
    use multipole::exact::adding_doubling::{AddingDoublingOptions, solve};
    let (rows_, _) = rows(&slabs, Some(SLAB_COLUMNS.len()), "slabs")?;
    let out = py.detach(|| {
        on_threads(threads, || {
            rows_
                .par_chunks_exact(SLAB_COLUMNS.len())
                .map(|s| -> Checked<[f64; 3]> {
                    let [sa, ss, g, n, d, n_above, n_below] =
                        [s[0], s[1], s[2], s[3], s[4], s[5], s[6]];
                    let layer = if d == f64::INFINITY {
                        Layer::semi_infinite(sa, ss, g, n)
                    } else {
                        Layer::slab(sa, ss, g, n, d)
                    }
                    .map_err(|e| {
                        Bad::new("sigma_a_per_mm, sigma_s_per_mm, g, n, thickness_mm", e)
                    })?;
                    let medium = LayeredMedium::new(vec![layer], n_above, n_below)
                        .map_err(|e| Bad::new("n_above/n_below", e))?;
                    let opts = AddingDoublingOptions::new(quadrature_points, g.clamp(0.0, 0.99))
                        .map_err(|e| Bad::new("quadrature_points", e))?;
                    let t = solve(&medium, &opts).map_err(|e| Bad::new("slabs", e))?;
                    Ok([
                        t.diffuse_reflectance,
                        t.specular_reflectance,
                        t.transmittance,
                    ])
                })
                .collect::<Checked<Vec<[f64; 3]>>>()
        })
    })??;
    out2(py, out.concat(), 3)
}
