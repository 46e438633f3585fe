//! Emission spectra of lights: blackbody, constant or D65, each normalised to luminance Y = 1 and
//! multiplied by the light's intensity.

use crate::spectrum::{SpectrumTable, luminance_of};

/// Second radiation constant c₂ = hc/k, m·K (CODATA 2018).
const PLANCK_C2_M_K: f64 = 1.438_776_877e-2;

/// Largest luminance a light or the environment may be given (relative units, Y = 1 is "white
/// 1"). Far above any scene (the built-in ones use ≤ 1e5), and low enough that every emission
/// table stays finite in f32 (the most lopsided shape allowed, a 500 K blackbody normalised to
/// Y = 1, peaks at 6.1e3 at 780 nm) with four decades left for the path weights that multiply it.
pub const MAX_INTENSITY: f32 = 1e30;

/// Shape of an emission spectrum, before normalisation to unit luminance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EmissionShape {
    /// Planck blackbody at a temperature, K.
    Blackbody {
        /// Temperature, K.
        kelvin: f64,
    },
    /// Equal energy at every wavelength.
    Constant,
    /// CIE illuminant D65 (`skin_optics::color::d65`).
    D65,
}

impl EmissionShape {
    /// Relative spectral power at `nm` (arbitrary scale).
    #[must_use]
    pub fn relative_power(&self, nm: f64) -> f64 {
        match *self {
            // Planck's law up to constant factors: λ⁻⁵ / (exp(c₂ / λT) − 1).
            EmissionShape::Blackbody { kelvin } => {
                let lambda_m = nm * 1e-9;
                lambda_m.powi(-5) / (PLANCK_C2_M_K / (lambda_m * kelvin)).exp_m1()
            }
            EmissionShape::Constant => 1.0,
            EmissionShape::D65 => skin_optics::color::d65(nm),
        }
    }

    /// The spectrum with luminance `intensity` (Y of the tabulated spectrum = intensity).
    #[must_use]
    pub fn table(&self, intensity: f32) -> SpectrumTable {
        let y = luminance_of(|nm| self.relative_power(nm));
        SpectrumTable::from_fn(|nm| self.relative_power(nm) / y * f64::from(intensity))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn emission_is_normalised_to_luminance() {
        for shape in [
            EmissionShape::D65,
            EmissionShape::Constant,
            EmissionShape::Blackbody { kelvin: 3000.0 },
        ] {
            let t = shape.table(2.5);
            let y = luminance_of(|nm| {
                f64::from(t.at_nm(nm as f32))
                    * if (380.0..=780.0).contains(&nm) {
                        1.0
                    } else {
                        0.0
                    }
            });
            assert!((y - 2.5).abs() < 0.01, "{shape:?}: {y}");
        }
    }

    /// Every shape at the largest intensity allowed tabulates finite values, the reddest
    /// blackbody with four decades of f32 to spare.
    #[test]
    fn largest_intensity_gives_finite_tables() {
        for shape in [
            EmissionShape::D65,
            EmissionShape::Constant,
            EmissionShape::Blackbody { kelvin: 500.0 },
            EmissionShape::Blackbody { kelvin: 100_000.0 },
        ] {
            let t = shape.table(MAX_INTENSITY);
            let max = (380..=780)
                .step_by(5)
                .map(|nm| t.at_nm(nm as f32))
                .fold(0.0f32, f32::max);
            assert!(
                max.is_finite() && max < 1e-4 * f32::MAX,
                "{shape:?}: {max:e}"
            );
        }
    }

    #[test]
    fn blackbody_peaks_at_wien_wavelength() {
        // Wien: λ_max = 2.897771955e-3 m·K / T → 579.6 nm at 5000 K.
        let s = EmissionShape::Blackbody { kelvin: 5000.0 };
        let peak = (400..800)
            .max_by(|&a, &b| {
                s.relative_power(a as f64)
                    .total_cmp(&s.relative_power(b as f64))
            })
            .unwrap();
        assert!((peak - 580i32).abs() <= 1, "{peak}");
    }
}
