//! Colour of spectra and colours: CIE XYZ under D65, CIELAB, CIEDE2000 and the ITA°, from
//! `skin_optics::{color, lab}` (the one home of colour science).

use crate::arrays::{In1, In2, finite, out1, out2, rows, vec1};
use crate::error::{Bad, Checked};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use skin_optics::color::{Srgb, Xyz, reflectance_to_xyz};
use skin_optics::lab::Lab;
use skin_optics::{GridSpectrum, WavelengthGrid};

/// The uniform grid of `lambda` (nm, increasing, equal steps to 1e-6 nm).
fn grid_of(lambda: &[f64]) -> Checked<WavelengthGrid> {
    let bad = |m: String| Bad::new("wavelength_nm", m);
    finite(lambda, "wavelength_nm", "[250, 1000] nm")?;
    let (Some(&first), Some(&last)) = (lambda.first(), lambda.last()) else {
        return Err(bad("needs at least 2 wavelengths".into()));
    };
    if lambda.len() < 2 {
        return Err(bad("needs at least 2 wavelengths".into()));
    }
    let step = (last - first) / (lambda.len() - 1) as f64;
    if lambda
        .iter()
        .enumerate()
        .any(|(i, nm)| (nm - (first + step * i as f64)).abs() > 1e-6)
    {
        return Err(bad(
            "must be increasing in equal steps (a uniform grid)".into()
        ));
    }
    let grid = WavelengthGrid::new(first, last, step).map_err(|e| bad(e.to_string()))?;
    if grid.len() != lambda.len() {
        return Err(bad(format!(
            "{} wavelengths do not make a grid from {first} to {last} nm",
            lambda.len()
        )));
    }
    Ok(grid)
}

/// CIE 1931 XYZ under D65 (white reflector: Y = 1) of each row of reflectances on `lambda_nm`.
#[pyfunction]
pub fn xyz<'py>(
    py: Python<'py>,
    lambda_nm: In1<'py>,
    reflectance: In2<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let lambda = vec1(&lambda_nm);
    let grid = grid_of(&lambda)?;
    let (r, m) = rows(&reflectance, Some(lambda.len()), "reflectance")?;
    finite(&r, "reflectance", "[0, 1]")?;
    let out: Vec<f64> = py.detach(|| -> Checked<Vec<f64>> {
        let mut out = Vec::with_capacity(r.len() / m.max(1) * 3);
        for row in r.chunks_exact(m) {
            let s =
                GridSpectrum::new(grid, row.to_vec()).map_err(|e| Bad::new("reflectance", e))?;
            out.extend(reflectance_to_xyz(&s).0);
        }
        Ok(out)
    })?;
    out2(py, out, 3)
}

fn triples(a: &In2<'_>, name: &str) -> Checked<Vec<[f64; 3]>> {
    let (v, _) = rows(a, Some(3), name)?;
    finite(&v, name, "finite")?;
    Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

fn lab_of(t: [f64; 3]) -> Lab {
    Lab {
        l: t[0],
        a: t[1],
        b: t[2],
    }
}

/// CIELAB (D65 white) of XYZ triples (Y = 1 for white).
#[pyfunction]
pub fn lab_from_xyz<'py>(py: Python<'py>, xyz: In2<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let out = triples(&xyz, "xyz")?
        .into_iter()
        .flat_map(|t| {
            let l = Lab::from_xyz(Xyz(t));
            [l.l, l.a, l.b]
        })
        .collect();
    out2(py, out, 3)
}

/// CIELAB of `#RRGGBB` sRGB colours.
#[pyfunction]
pub fn lab_from_srgb(py: Python<'_>, srgb: Vec<String>) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let mut out = Vec::with_capacity(srgb.len() * 3);
    for s in &srgb {
        let c = Srgb::from_hex(s).ok_or_else(|| {
            Bad::new(
                "srgb",
                format!(
                    "'{}' is not an sRGB colour (expected #RRGGBB, six hex digits)",
                    skin_optics::echo::Text(s)
                ),
            )
        })?;
        let l = Lab::from_srgb(c);
        out.extend([l.l, l.a, l.b]);
    }
    out2(py, out, 3)
}

/// `#RRGGBB` of CIELAB triples (clipped to the sRGB gamut).
#[pyfunction]
pub fn srgb_from_lab(lab: In2<'_>) -> PyResult<Vec<String>> {
    Ok(triples(&lab, "lab")?
        .into_iter()
        .map(|t| lab_of(t).to_srgb().to_hex())
        .collect())
}

/// CIEDE2000 colour difference of paired CIELAB rows.
#[pyfunction]
pub fn delta_e_2000<'py>(
    py: Python<'py>,
    lab1: In2<'py>,
    lab2: In2<'py>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let a = triples(&lab1, "lab1")?;
    let b = triples(&lab2, "lab2")?;
    if a.len() != b.len() {
        return Err(Bad::new(
            "lab2",
            format!("{} colours for {} in lab1", b.len(), a.len()),
        )
        .into());
    }
    let out = a
        .iter()
        .zip(&b)
        .map(|(x, y)| skin_optics::lab::delta_e_2000(lab_of(*x), lab_of(*y)))
        .collect();
    Ok(out1(py, out))
}

/// Individual typology angle ITA° in degrees of CIELAB rows (`skin_optics::lab::Lab::ita_deg`).
#[pyfunction]
pub fn ita<'py>(py: Python<'py>, lab: In2<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let out = triples(&lab, "lab")?
        .into_iter()
        .map(|t| lab_of(t).ita_deg())
        .collect();
    Ok(out1(py, out))
}
