//! Skin parameters as one row of numbers per evaluation point, and the named presets.

use crate::error::{Bad, Checked};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use skin_optics::measured::named_skin;
use skin_optics::{Extension, Preset, SkinParams, Wavelength};

/// The Python keyword of each column of a parameter row, in order.
pub const COLUMNS: [&str; 10] = [
    "melanin",
    "eumelanin",
    "hemoglobin",
    "oil",
    "oxygenation",
    "epidermis_thickness_mm",
    "epidermis_blood",
    "bilirubin_g_per_l",
    "mie_scale",
    "rayleigh_scale",
];

/// Columns per parameter row.
pub const WIDTH: usize = COLUMNS.len();

/// The extensions in the order of the last four columns.
const EXTENSIONS: [Extension; 4] = [
    Extension::EpidermisBlood,
    Extension::Bilirubin,
    Extension::MieScale,
    Extension::RayleighScale,
];

/// The row of `skin`.
pub fn row_of(skin: &SkinParams) -> [f64; WIDTH] {
    let p = skin.physiology();
    [
        skin.melanin(),
        skin.eumelanin_blend(),
        skin.hemoglobin(),
        skin.oiliness(),
        skin.oxygenation(),
        skin.epidermis_thickness_mm(),
        p.get(EXTENSIONS[0]),
        p.get(EXTENSIONS[1]),
        p.get(EXTENSIONS[2]),
        p.get(EXTENSIONS[3]),
    ]
}

/// The validated skin of one row; a bad value's error names its keyword and range.
pub fn skin_of(row: &[f64]) -> Checked<SkinParams> {
    let named = |i: usize| move |e: skin_optics::OpticsError| Bad::new(COLUMNS[i], e);
    let mut skin = SkinParams::new(0.0, 0.0, 0.0, 0.0)
        .map_err(named(0))?
        .with_melanin(row[0])
        .map_err(named(0))?
        .with_eumelanin_blend(row[1])
        .map_err(named(1))?
        .with_hemoglobin(row[2])
        .map_err(named(2))?
        .with_oiliness(row[3])
        .map_err(named(3))?
        .with_oxygenation(row[4])
        .map_err(named(4))?
        .with_epidermis_thickness_mm(row[5])
        .map_err(named(5))?;
    let mut physiology = skin.physiology();
    for (k, e) in EXTENSIONS.into_iter().enumerate() {
        physiology = physiology.with(e, row[6 + k]).map_err(named(6 + k))?;
    }
    skin = skin.with_physiology(physiology);
    Ok(skin)
}

/// A wavelength in nm, [250, 1000]; the error names `wavelength_nm`.
pub fn wavelength(nm: f64) -> Checked<Wavelength> {
    Wavelength::new(nm).map_err(|e| Bad::new("wavelength_nm", e))
}

/// The keyword of each column of a parameter row.
#[pyfunction]
pub fn skin_columns() -> Vec<&'static str> {
    COLUMNS.to_vec()
}

/// The parameter row of a named skin (`None`: the default, the paper's light skin).
#[pyfunction]
#[pyo3(signature = (name=None))]
pub fn preset_row(name: Option<&str>) -> PyResult<Vec<f64>> {
    let skin = match name {
        None => SkinParams::preset(Preset::Light),
        Some(n) => named_skin(n).map_err(|e| Bad::new("preset", e))?,
    };
    Ok(row_of(&skin).to_vec())
}

/// Every named skin: name, source, colour (exact model, 10-nm step) and parameters.
#[pyfunction]
pub fn presets(py: Python<'_>) -> PyResult<Vec<Bound<'_, PyDict>>> {
    let rows = py
        .detach(skin_fit::named_skins)
        .map_err(|e| Bad::new("presets", e))?;
    rows.into_iter()
        .map(
            |skin_fit::NamedSkin {
                 name,
                 source,
                 skin,
                 lab,
             }| {
                let d = PyDict::new(py);
                d.set_item("name", name)?;
                d.set_item("source", source)?;
                d.set_item("srgb", lab.to_srgb().to_hex())?;
                d.set_item("lab", (lab.l, lab.a, lab.b))?;
                d.set_item("ita_deg", lab.ita_deg())?;
                d.set_item("ita_category", lab.ita_category().name())?;
                for (k, v) in COLUMNS.iter().zip(row_of(&skin)) {
                    d.set_item(*k, v)?;
                }
                Ok(d)
            },
        )
        .collect()
}
