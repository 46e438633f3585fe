//! The wavelengths of a skin's tables (docs/physics.md §16.2): the widest uniform step over
//! 380–780 nm whose linearly interpolated total reflectance R_tot(λ) keeps the skin's colour
//! (CIE 1931 XYZ under D65 → CIELAB, `skin_optics::color`/`lab`) within a CIEDE2000 target of the
//! same model tabulated every 1 nm, and its luminance Y within a relative target. Under uniform
//! light a flat patch of skin renders exactly this colour (the BSSRDF integrates to R_tot at each
//! wavelength), so the targets bound the rendered colour error of the interpolation. The
//! luminance bound is there because ΔE2000 weighs lightness by S_L, which lets a dark colour's Y
//! drift by percents inside ΔE 0.5: a brightness error a renderer's image comparison sees.

use crate::spectrum::{LAMBDA_MAX_NM, LAMBDA_MIN_NM};
use multipole::{Method, MultipoleError};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use skin_optics::color::Xyz;
use skin_optics::lab::Lab;
use skin_optics::spectrum::GridSpectrum;
use skin_optics::{SkinParams, Wavelength, WavelengthGrid, color};

/// Steps tried, nm, widest first: every step dividing the 400-nm range into whole intervals.
pub const STEPS_NM: [f64; 10] = [100.0, 80.0, 50.0, 40.0, 25.0, 20.0, 16.0, 10.0, 8.0, 5.0];
/// First wavelength of the tables, nm.
pub const FROM_NM: f64 = LAMBDA_MIN_NM as f64;
/// Last wavelength of the tables, nm.
pub const TO_NM: f64 = LAMBDA_MAX_NM as f64;

/// The chosen step and the colour error it costs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WavelengthChoice {
    /// Step between rows, nm.
    pub step_nm: f64,
    /// Rows of the table.
    pub nodes: usize,
    /// CIEDE2000 between the interpolated and the 1-nm colour (`None`: a fixed step, not measured).
    pub delta_e: Option<f64>,
    /// |Y / Y₁ₙₘ − 1| of the interpolated colour's luminance (`None`: a fixed step).
    pub luminance_error: Option<f64>,
}

impl WavelengthChoice {
    /// A fixed step of `step_nm`, its errors not measured.
    #[must_use]
    pub fn fixed(step_nm: f64) -> Self {
        Self {
            step_nm,
            nodes: nodes(step_nm),
            delta_e: None,
            luminance_error: None,
        }
    }
}

/// Rows of a table every `step_nm` from [`FROM_NM`] to [`TO_NM`].
fn nodes(step_nm: f64) -> usize {
    ((TO_NM - FROM_NM) / step_nm) as usize + 1
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

/// CIE XYZ (D65) of a reflectance sampled every `step_nm` from [`FROM_NM`] (linear between samples).
fn xyz(values: Vec<f64>, step_nm: f64) -> Option<Xyz> {
    let grid = WavelengthGrid::new(FROM_NM, TO_NM, step_nm).ok()?;
    let spectrum = GridSpectrum::new(grid, values).ok()?;
    Some(color::reflectance_to_xyz(&spectrum))
}

/// The colour of `totals_1nm` and of its samples every `step_nm` (a whole number of nm)
/// interpolated linearly.
fn colours_of_step(totals_1nm: &[f64], step_nm: f64) -> Option<(Xyz, Xyz)> {
    let stride = (step_nm as usize).max(1);
    let nodes: Vec<f64> = totals_1nm.iter().step_by(stride).copied().collect();
    Some((xyz(totals_1nm.to_vec(), 1.0)?, xyz(nodes, step_nm)?))
}

/// CIEDE2000 between `totals_1nm` and its samples every `step_nm` (a whole number of nm)
/// interpolated linearly.
#[must_use]
pub fn delta_e_of_step(totals_1nm: &[f64], step_nm: f64) -> f64 {
    colours_of_step(totals_1nm, step_nm).map_or(f64::INFINITY, |(a, b)| {
        Lab::from_xyz(a).delta_e_2000(Lab::from_xyz(b))
    })
}

/// |Y / Y₁ₙₘ − 1| between the luminance of `totals_1nm` and of its samples every `step_nm`
/// interpolated linearly.
#[must_use]
pub fn luminance_error_of_step(totals_1nm: &[f64], step_nm: f64) -> f64 {
    colours_of_step(totals_1nm, step_nm).map_or(f64::INFINITY, |(a, b)| {
        if a.0[1] > 0.0 {
            (b.0[1] / a.0[1] - 1.0).abs()
        } else {
            f64::INFINITY
        }
    })
}

/// The widest step of [`STEPS_NM`] within `max_delta_e` and `max_luminance_error`; the narrowest
/// (5 nm) when none is.
#[must_use]
pub fn choose_step(
    totals_1nm: &[f64],
    max_delta_e: f64,
    max_luminance_error: f64,
) -> WavelengthChoice {
    let choice = |step_nm: f64| WavelengthChoice {
        delta_e: Some(delta_e_of_step(totals_1nm, step_nm)),
        luminance_error: Some(luminance_error_of_step(totals_1nm, step_nm)),
        ..WavelengthChoice::fixed(step_nm)
    };
    STEPS_NM
        .iter()
        .map(|&s| choice(s))
        .find(|c| {
            c.delta_e.is_some_and(|d| d <= max_delta_e)
                && c.luminance_error.is_some_and(|y| y <= max_luminance_error)
        })
        .unwrap_or_else(|| choice(STEPS_NM[STEPS_NM.len() - 1]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::{ProfileTable, TableOptions};
    use skin_optics::Preset;

    /// For every preset and both methods the chosen step keeps the colour within ΔE2000 0.5 and
    /// the luminance within 0.1% of the 1-nm grid, measured independently on the table that is
    /// built with it: its totals read back at every nm (the renderer's interpolation) against the
    /// model's 1-nm totals.
    #[test]
    fn interpolated_wavelengths_stay_within_the_colour_target_for_every_preset() {
        let (max_de, max_y) = (0.5, 1e-3);
        for method in [Method::Exact, Method::Multipole] {
            for preset in Preset::ALL {
                let skin = SkinParams::preset(preset);
                let fine = totals_1nm(&skin, method, multipole::DEFAULT_G).unwrap();
                let c = choose_step(&fine, max_de, max_y);
                let (de, dy) = (c.delta_e.unwrap(), c.luminance_error.unwrap());
                assert!(de <= max_de && dy <= max_y, "{preset:?} {method}: {c:?}");
                // The luminance bound binds: the colour target alone allows a wider step that
                // misses it, for at least the presets the bound is there for.
                let by_colour = choose_step(&fine, max_de, f64::INFINITY);
                assert!(by_colour.step_nm >= c.step_nm);
                let opts = TableOptions {
                    step_nm: c.step_nm,
                    ..TableOptions::default()
                };
                let table = ProfileTable::build(&skin, method, &opts).unwrap();
                assert_eq!(table.wavelengths(), c.nodes);
                let read: Vec<f64> = (0..fine.len())
                    .map(|i| f64::from(table.total((FROM_NM + i as f64) as f32)))
                    .collect();
                // The table's rows are f32 (relative 6e-8): ΔE moves by far less than 0.01 and
                // Y by far less than 1e-6.
                let (a, b) = (xyz(read, 1.0).unwrap(), xyz(fine, 1.0).unwrap());
                let de = Lab::from_xyz(a).delta_e_2000(Lab::from_xyz(b));
                assert!(de <= max_de + 0.01, "{preset:?} {method}: table ΔE {de}");
                let dy = (a.0[1] / b.0[1] - 1.0).abs();
                assert!(dy <= max_y + 1e-6, "{preset:?} {method}: table ΔY {dy}");
            }
        }
    }

    /// The luminance the colour target alone lets through, per preset (printed for physics §16.2):
    /// the dark preset's widest ΔE-admissible step misses Y by more than the bound.
    #[test]
    fn the_colour_target_alone_lets_dark_skin_luminance_drift() {
        let skin = SkinParams::preset(Preset::Dark);
        let fine = totals_1nm(&skin, Method::Exact, multipole::DEFAULT_G).unwrap();
        let by_colour = choose_step(&fine, 0.5, f64::INFINITY);
        let dy = by_colour.luminance_error.unwrap();
        for s in STEPS_NM {
            eprintln!(
                "dark, step {s} nm: ΔE {:.3}, ΔY {:.3}%",
                delta_e_of_step(&fine, s),
                100.0 * luminance_error_of_step(&fine, s)
            );
        }
        assert!(dy > 1e-3, "{by_colour:?}");
    }
}
