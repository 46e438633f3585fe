//! Spectral profiles reduced to RGB: each radius's reflectance spectrum integrated against the CIE 1931
//! observer under D65 (`skin_optics::color::reflectance_to_xyz`) and mapped to linear Rec.709 (and on to
//! the export's colour space), docs/physics.md §14. The reduction is linear in the spectrum, so the RGB
//! profile's integral is the RGB of the total-reflectance spectrum.

use crate::colour::ColourSpace;
use crate::error::ExportError;
use multipole::{Profile, SpectralProfiles};
use skin_optics::GridSpectrum;
use skin_optics::color::reflectance_to_xyz;
use std::f64::consts::PI;

/// Channel names, in order.
pub const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// Radial profiles of the three channels on one radius grid, per unit flux entering the skin.
#[derive(Debug, Clone, PartialEq)]
pub struct RgbProfile {
    radii_mm: Vec<f64>,
    values_per_mm2: [Vec<f64>; 3],
    totals: [f64; 3],
    space: ColourSpace,
}

impl RgbProfile {
    /// Reduce `set` (every profile on the same radii, as `Method::Exact` Monte Carlo shapes are) to
    /// RGB in `space`. Totals are the RGB of the spectrum of each row's own total.
    pub fn from_spectral(set: &SpectralProfiles, space: ColourSpace) -> Result<Self, ExportError> {
        let rows = set.profiles();
        // Exact rows share the Monte Carlo shape radii, each cut after its own 99.9% energy radius:
        // every table is a prefix of the longest, and R = 0 beyond a table's end.
        let longest = rows
            .iter()
            .max_by_key(|p| p.radii_mm().len())
            .expect("a grid has wavelengths");
        let radii = longest.radii_mm().to_vec();
        if rows
            .iter()
            .any(|p| p.radii_mm() != &radii[..p.radii_mm().len()])
        {
            return Err(ExportError::Fit(
                "spectral profiles on different radii (use the exact method's Monte Carlo shapes)"
                    .into(),
            ));
        }
        let value = |p: &Profile, i: usize| p.reflectance_per_mm2().get(i).copied().unwrap_or(0.0);
        let grid = *set.grid();
        let to_rgb = |values: Vec<f64>| -> Result<[f64; 3], ExportError> {
            let xyz = reflectance_to_xyz(&GridSpectrum::new(grid, values)?);
            Ok(space.from_rec709(xyz.to_linear_srgb().0))
        };
        let mut values: [Vec<f64>; 3] = Default::default();
        for i in 0..radii.len() {
            let rgb = to_rgb(rows.iter().map(|p| value(p, i)).collect())?;
            for c in 0..3 {
                // A saturated channel can dip below zero in a wide gamut; a profile cannot.
                values[c].push(rgb[c].max(0.0));
            }
        }
        let totals = to_rgb(rows.iter().map(Profile::total).collect())?;
        Ok(Self {
            radii_mm: radii,
            values_per_mm2: values,
            totals,
            space,
        })
    }

    /// A linear Rec.709 profile from its parts (radii increasing, mm; values mm⁻²; totals per channel).
    #[must_use]
    pub fn from_parts(radii_mm: Vec<f64>, values_per_mm2: [Vec<f64>; 3], totals: [f64; 3]) -> Self {
        Self {
            radii_mm,
            values_per_mm2,
            totals,
            space: ColourSpace::LinRec709,
        }
    }

    /// The colour space of the channels.
    #[must_use]
    pub fn space(&self) -> ColourSpace {
        self.space
    }

    /// The same skin with every length multiplied by `k`: R(r) → R(r/k)/k², totals unchanged
    /// (transport is scale-free when every coefficient is divided by k).
    #[must_use]
    pub fn with_lengths_scaled(&self, k: f64) -> Self {
        Self {
            radii_mm: self.radii_mm.iter().map(|r| r * k).collect(),
            values_per_mm2: self
                .values_per_mm2
                .clone()
                .map(|v| v.into_iter().map(|x| x / (k * k)).collect()),
            totals: self.totals,
            space: self.space,
        }
    }

    /// The radius grid, mm.
    #[must_use]
    pub fn radii_mm(&self) -> &[f64] {
        &self.radii_mm
    }

    /// Total reflectance per channel (per unit flux entering; the profile's integral).
    #[must_use]
    pub fn totals(&self) -> [f64; 3] {
        self.totals
    }

    /// Channel `c` as a profile table (mm, mm⁻²) with its total.
    pub fn channel(&self, c: usize) -> Result<Profile, ExportError> {
        Ok(Profile::from_table(
            self.radii_mm.clone(),
            self.values_per_mm2[c].clone(),
            self.totals[c],
        )?)
    }

    /// Mean radial distance of channel `c`, mm: ∫ r 2πr R dr / ∫ 2πr R dr on the table (trapezoid).
    #[must_use]
    pub fn mean_radius_mm(&self, c: usize) -> f64 {
        let (r, v) = (&self.radii_mm, &self.values_per_mm2[c]);
        let (mut num, mut den) = (0.0, 0.0);
        for i in 1..r.len() {
            let dr = r[i] - r[i - 1];
            let p = |j: usize| 2.0 * PI * r[j] * v[j];
            den += 0.5 * dr * (p(i) + p(i - 1));
            num += 0.5 * dr * (r[i] * p(i) + r[i - 1] * p(i - 1));
        }
        num / den
    }

    /// Mean of the three channels' mean radial distances, mm (the length scale of the fits' searches).
    #[must_use]
    pub fn length_scale_mm(&self) -> f64 {
        (0..3).map(|c| self.mean_radius_mm(c)).sum::<f64>() / 3.0
    }
}

/// Points of the error integrals per decade of radius.
const POINTS_PER_DECADE: usize = 200;

/// Energy-weighted shape error of a model against `reference`: ∫ |R̂_model − R̂_ref| 2πr dr with both
/// profiles normalised to unit energy (0 = same shape, 2 = disjoint), docs/physics.md §14.
/// `model_per_mm2` is the model's R(r) (any normalisation; normalised here over the same radii). The
/// integral runs in ln r from 1e-3 of the reference's first radius to 10× its last.
#[must_use]
pub fn shape_error(reference: &Profile, model_per_mm2: impl Fn(f64) -> f64) -> f64 {
    let radii = reference.radii_mm();
    let (lo, hi) = (radii[0] * 1e-3, radii[radii.len() - 1] * 10.0);
    let n = ((hi / lo).log10() * POINTS_PER_DECADE as f64).ceil() as usize + 1;
    let step = (hi / lo).ln() / (n - 1) as f64;
    let rs: Vec<f64> = (0..n).map(|i| lo * (step * i as f64).exp()).collect();
    // Energy per ln r: 2πr² R(r).
    let density = |f: &dyn Fn(f64) -> f64| -> Vec<f64> {
        rs.iter().map(|&r| 2.0 * PI * r * r * f(r)).collect()
    };
    let a = density(&|r| reference.eval(r));
    let b = density(&model_per_mm2);
    let integral = |v: &[f64]| {
        v.windows(2)
            .map(|w| 0.5 * (w[0] + w[1]) * step)
            .sum::<f64>()
    };
    let (ea, eb) = (integral(&a), integral(&b));
    if !(ea > 0.0 && eb > 0.0) {
        return 2.0;
    }
    let diff: Vec<f64> = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x / ea - y / eb).abs())
        .collect();
    integral(&diff)
}

/// Relative error of a model total against the reference total.
#[must_use]
pub fn total_error(reference: f64, model: f64) -> f64 {
    ((model - reference) / reference).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exponential(r0: f64) -> Profile {
        // 2πr R = e^{−r/r0}/r0: unit energy, mean radius r0.
        let radii: Vec<f64> = (0..400).map(|i| 1e-4 * 1.04_f64.powi(i)).collect();
        let values = radii
            .iter()
            .map(|&r| (-r / r0).exp() / (r0 * 2.0 * PI * r))
            .collect();
        Profile::from_table(radii, values, 1.0).unwrap()
    }

    #[test]
    fn shape_error_is_zero_for_the_same_shape_and_grows_with_mismatch() {
        let p = exponential(0.5);
        let same = shape_error(&p, |r| 3.0 * (-r / 0.5).exp() / r);
        // Log–log interpolation of a smooth table on 4% steps: error of order 1e-4.
        assert!(same < 2e-3, "{same}");
        // Exponentials of mean a = 0.5 and b = 1 cross at x* = ab ln(b/a)/(b − a) = ln 2, so
        // ∫|e^{-x/a}/a − e^{-x/b}/b| dx = 2(e^{-x*/b} − e^{-x*/a}) = 2(0.5 − 0.25) = 0.5.
        let other = shape_error(&p, |r| (-r).exp() / r);
        assert!((other - 0.5).abs() < 5e-3, "{other}");
    }

    #[test]
    fn scaling_lengths_keeps_totals_and_scales_the_mean_radius() {
        let radii: Vec<f64> = (0..300).map(|i| 1e-3 * 1.05_f64.powi(i)).collect();
        let v: Vec<f64> = radii.iter().map(|&r| (-r).exp() / r).collect();
        let p = RgbProfile::from_parts(radii, [v.clone(), v.clone(), v], [0.5, 0.4, 0.3]);
        let q = p.with_lengths_scaled(2.0);
        assert_eq!(q.totals(), p.totals());
        let ratio = q.mean_radius_mm(1) / p.mean_radius_mm(1);
        assert!((ratio - 2.0).abs() < 1e-12, "{ratio}");
    }
}
