//! The wavelengths of a skin's tables (docs/physics.md §16.2): the widest uniform step over
//! 380–780 nm whose linearly interpolated total reflectance R_tot(λ) keeps the skin's colour
//! (CIE 1931 XYZ under D65 → CIELAB, `skin_optics::color`/`lab`) within a CIEDE2000 target of the
//! same model tabulated every 1 nm. Under uniform light a flat patch of skin renders exactly this
//! colour (the BSSRDF integrates to R_tot at each wavelength), so the target bounds the rendered
//! colour error of the interpolation.

use multipole::{Method, MultipoleError};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use skin_optics::lab::Lab;
use skin_optics::spectrum::GridSpectrum;
use skin_optics::{SkinParams, Wavelength, WavelengthGrid, color};

/// Steps tried, nm, widest first: every step dividing the 400-nm range into whole intervals.
pub const STEPS_NM: [f64; 10] = [100.0, 80.0, 50.0, 40.0, 25.0, 20.0, 16.0, 10.0, 8.0, 5.0];
/// First wavelength of the tables, nm.
pub const FROM_NM: f64 = 380.0;
/// Last wavelength of the tables, nm.
pub const TO_NM: f64 = 780.0;

/// The chosen step and the colour error it costs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WavelengthChoice {
    /// Step between rows, nm.
    pub step_nm: f64,
    /// Rows of the table.
    pub nodes: usize,
    /// CIEDE2000 between the interpolated and the 1-nm colour (`None`: a fixed step, not measured).
    pub delta_e: Option<f64>,
}

/// R_tot of `skin` with `method` at every nm from [`FROM_NM`] to [`TO_NM`] (in parallel).
pub fn totals_1nm(
    skin: &SkinParams,
    method: Method,
    phase_g: f64,
) -> Result<Vec<f64>, MultipoleError> {
    (0..=(TO_NM - FROM_NM) as usize)
        .into_par_iter()
        .map(|i| {
            let lambda = Wavelength::new(FROM_NM + i as f64).map_err(|_| {
                MultipoleError::Profile("table wavelength outside the model's range")
            })?;
            multipole::skin::total_reflectance_at_g(skin, lambda, method, phase_g)
        })
        .collect()
}

/// CIELAB (D65) of a reflectance sampled every `step_nm` from [`FROM_NM`] (linear between samples).
fn lab(values: Vec<f64>, step_nm: f64) -> Option<Lab> {
    let grid = WavelengthGrid::new(FROM_NM, TO_NM, step_nm).ok()?;
    let spectrum = GridSpectrum::new(grid, values).ok()?;
    Some(Lab::from_xyz(color::reflectance_to_xyz(&spectrum)))
}

/// CIEDE2000 between `totals_1nm` and its samples every `step_nm` (a whole number of nm)
/// interpolated linearly.
#[must_use]
pub fn delta_e_of_step(totals_1nm: &[f64], step_nm: f64) -> f64 {
    let stride = step_nm as usize;
    let nodes: Vec<f64> = totals_1nm.iter().step_by(stride.max(1)).copied().collect();
    match (lab(totals_1nm.to_vec(), 1.0), lab(nodes, step_nm)) {
        (Some(a), Some(b)) => a.delta_e_2000(b),
        _ => f64::INFINITY,
    }
}

/// The widest step of [`STEPS_NM`] within `max_delta_e`; the narrowest (5 nm) when none is.
#[must_use]
pub fn choose_step(totals_1nm: &[f64], max_delta_e: f64) -> WavelengthChoice {
    let choice = |step_nm: f64| WavelengthChoice {
        step_nm,
        nodes: ((TO_NM - FROM_NM) / step_nm) as usize + 1,
        delta_e: Some(delta_e_of_step(totals_1nm, step_nm)),
    };
    STEPS_NM
        .iter()
        .map(|&s| choice(s))
        .find(|c| c.delta_e.is_some_and(|d| d <= max_delta_e))
        .unwrap_or_else(|| choice(STEPS_NM[STEPS_NM.len() - 1]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::{ProfileTable, TableOptions};
    use skin_optics::Preset;

    /// For every preset and both methods the chosen step keeps the colour within ΔE2000 0.5 of
    /// the 1-nm grid, measured independently on the table that is built with it: its totals read
    /// back at every nm (the renderer's interpolation) against the model's 1-nm totals.
    #[test]
    fn interpolated_wavelengths_stay_within_the_colour_target_for_every_preset() {
        for method in [Method::Exact, Method::Multipole] {
            for preset in Preset::ALL {
                let skin = SkinParams::preset(preset);
                let fine = totals_1nm(&skin, method, multipole::DEFAULT_G).unwrap();
                let c = choose_step(&fine, 0.5);
                let de = c.delta_e.unwrap();
                assert!(de <= 0.5, "{preset:?} {method}: {c:?}");
                let opts = TableOptions {
                    step_nm: c.step_nm,
                    ..TableOptions::default()
                };
                let table = ProfileTable::build(&skin, method, &opts).unwrap();
                assert_eq!(table.wavelengths(), c.nodes);
                let read: Vec<f64> = (0..fine.len())
                    .map(|i| f64::from(table.total((FROM_NM + i as f64) as f32)))
                    .collect();
                // The table's rows are f32 (relative 6e-8): ΔE moves by far less than 0.01.
                let de = lab(read, 1.0)
                    .unwrap()
                    .delta_e_2000(lab(fine, 1.0).unwrap());
                assert!(de <= 0.5 + 0.01, "{preset:?} {method}: table ΔE {de}");
            }
        }
    }
}
