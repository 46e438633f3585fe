//! The azimuthal lobe of the subsurface reflectance (docs/physics.md §8.3): light entering
//! obliquely keeps part of its horizontal direction through the first, forward-peaked
//! scatterings, so more of it leaves forward (away from the light) than back toward it. The
//! separable form has no azimuth; its product with
//!
//! M(μ_i, μ_o, φ, λ) = 1 + 2 A₁(λ) s_i s_o cos φ,   s = √(1 − μ²),
//!
//! φ the angle between the incident light's and the leaving light's horizontal directions of
//! travel (0 forward), has the first harmonic of the layered Monte Carlo
//! (`multipole::exact::montecarlo::azimuthal_harmonics`) while keeping the separable form's
//! azimuthal mean: ∫ M dφ = 2π, so every total, the sky's radiance and the walk's normal-incidence
//! results are unchanged. The s_i s_o factor is the regularity of the first harmonic at the pole
//! (and what the Monte Carlo shows at every incidence); M is symmetric in (μ_i, μ_o), so S stays
//! reciprocal. A₁ is fitted per tabulated wavelength to the Monte Carlo's first harmonic divided
//! by the separable form (smooth-surface Fresnel split) by least squares. The second harmonic is
//! left out: light skin's is below 0.005 (under 1% of M at grazing angles), and at the default
//! photons its estimate is noise of ±0.01.

use super::separable::Directional;
use crate::spectrum::{N_WAVELENGTHS, SampledSpectrum, SampledWavelengths};
use multipole::exact::montecarlo::{ObliqueOptions, azimuthal_harmonics};
use multipole::{LayeredMedium, MultipoleError};
use rayon::prelude::*;

/// Whether the BSSRDF carries the azimuthal lobe (the knob of docs/physics.md §8.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Azimuth {
    /// No azimuth: the separable form alone ([JMLH01]; default); on thick skin under a lamp
    /// opposite the camera at 60° it renders about 5% dark, beside the camera about 5% bright.
    #[default]
    Separable,
    /// The separable form times M with the Monte Carlo's first harmonic: light skin under that
    /// lamp within 1.5%, for 0.56 CPU-s per skin at load and 3% more CPU per sample.
    Harmonics,
}

/// Settings of the lobe's Monte Carlo: photons per incidence, collision cap, wavelength rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AzimuthOptions {
    /// Photons per incidence (six incidences per row).
    pub photons: u64,
    /// Interactions followed per photon (later orders keep no azimuth).
    pub max_collisions: u32,
}

impl Default for AzimuthOptions {
    /// 20,000 photons, 64 interactions: A₁ within 0.002 of 10⁵ photons with 2,000 interactions
    /// (light skin), M within 0.4% of it (docs/physics.md §8.3).
    fn default() -> Self {
        Self {
            photons: 20_000,
            max_collisions: 64,
        }
    }
}

/// Wavelengths of the lobe's rows, nm: every [`AZIMUTH_STEP_NM`] over the renderer's range (A_m
/// is smooth in λ, 0.046 to 0.029 from 400 to 700 nm for light skin; linear between rows).
pub const AZIMUTH_ROWS_NM: [f64; 5] = [380.0, 480.0, 580.0, 680.0, 780.0];

/// Step of [`AZIMUTH_ROWS_NM`], nm.
pub const AZIMUTH_STEP_NM: f64 = 100.0;

/// Incidences (exit bins) of the fit, even in μ².
const BINS: usize = 6;

/// A₁(λ) of one skin.
#[derive(Debug, Clone, PartialEq)]
pub struct AzimuthalLobe {
    /// A₁ at [`AZIMUTH_ROWS_NM`].
    a: Vec<f32>,
}

impl AzimuthalLobe {
    /// The lobe of the skin whose layered medium at a wavelength (nm) `medium_at` gives, beside
    /// the BSSRDF's angular factor `fresnel` (the Fresnel split with the skin's incidence gain)
    /// and total R_tot(λ) `r_tot`: the Monte Carlo per row and incidence, in parallel.
    pub fn build<'m>(
        medium_at: impl Fn(f64) -> &'m LayeredMedium + Sync,
        fresnel: &Directional,
        r_tot: impl Fn(f32) -> f32 + Sync,
        options: AzimuthOptions,
    ) -> Result<Self, MultipoleError> {
        let at =
            |seed: u64| ObliqueOptions::new(options.photons, options.max_collisions, 2, BINS, seed);
        let opts = at(11)?;
        let a = AZIMUTH_ROWS_NM
            .par_iter()
            .map(|&nm| {
                let medium = medium_at(nm);
                let runs = (0..BINS)
                    .map(|j| azimuthal_harmonics(medium, opts.bin_mu(j), &at(11 + j as u64)?))
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(fit_row(&runs, &opts, fresnel, r_tot(nm as f32), nm as f32))
            })
            .collect::<Result<Vec<_>, MultipoleError>>()?;
        Ok(Self { a })
    }

    /// A lobe of given A₁ per row ([`AZIMUTH_ROWS_NM`]), for tests.
    #[must_use]
    pub fn from_rows(a: Vec<f32>) -> Self {
        Self { a }
    }

    /// A₁ at `nm` (linear between rows, held beyond the first and last).
    #[must_use]
    pub fn coefficient(&self, nm: f32) -> f32 {
        let last = self.a.len() - 1;
        let x = ((f64::from(nm) - AZIMUTH_ROWS_NM[0]) / AZIMUTH_STEP_NM).clamp(0.0, last as f64);
        let i = (x as usize).min(last.saturating_sub(1));
        let t = (x - i as f64) as f32;
        let (p, q) = (self.a[i], self.a[(i + 1).min(last)]);
        p + t * (q - p)
    }

    /// M at incidence cosine `mu_i`, exit cosine `mu_o` and cos φ `cos_phi` (φ between the
    /// directions of travel, 0 forward), at `nm`; never negative.
    #[must_use]
    pub fn modulation(&self, mu_i: f32, mu_o: f32, cos_phi: f32, nm: f32) -> f32 {
        let t = 2.0 * sin_product(mu_i, mu_o) * cos_phi.clamp(-1.0, 1.0);
        (1.0 + self.coefficient(nm) * t).max(0.0)
    }

    /// [`Self::modulation`] at each of the path's wavelengths (the angles' terms found once).
    #[must_use]
    pub fn modulations(
        &self,
        mu_i: f32,
        mu_o: f32,
        cos_phi: f32,
        wl: &SampledWavelengths,
    ) -> SampledSpectrum {
        let t = 2.0 * sin_product(mu_i, mu_o) * cos_phi.clamp(-1.0, 1.0);
        SampledSpectrum(std::array::from_fn::<_, N_WAVELENGTHS, _>(|k| {
            (1.0 + self.coefficient(wl.nm(k)) * t).max(0.0)
        }))
    }
}

/// s_i s_o = √((1 − μ_i²)(1 − μ_o²)).
fn sin_product(mu_i: f32, mu_o: f32) -> f32 {
    let (a, b) = (mu_i.clamp(0.0, 1.0), mu_o.clamp(0.0, 1.0));
    ((1.0 - a * a) * (1.0 - b * b)).max(0.0).sqrt()
}

/// A₁ of one row: c₁ = F₁ / f_sep at every (incidence, exit bin), fitted by c₁ = A₁ s_i s_o
/// (one-parameter least squares, every cell alike: weights from the cells' own estimated
/// variances favour the cells whose few photons happened to agree).
fn fit_row(
    runs: &[multipole::exact::montecarlo::Harmonics],
    opts: &ObliqueOptions,
    fresnel: &Directional,
    r_tot: f32,
    nm: f32,
) -> f32 {
    let c = fresnel.normalisation_at(nm);
    let gain = |mu: f32| fresnel.incidence().map_or(1.0, |g| g.gain(mu, nm));
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (j, h) in runs.iter().enumerate() {
        let mu_i = opts.bin_mu(j) as f32;
        for k in 0..opts.bins() {
            let mu_o = opts.bin_mu(k) as f32;
            // The separable form per unit flux entering at μ_i (Fresnel split).
            let f_sep = f64::from(
                gain(mu_i) * r_tot * fresnel.factor(mu_o, nm) / (c * std::f32::consts::PI),
            );
            if f_sep <= 0.0 {
                continue;
            }
            let x = f64::from(sin_product(mu_i, mu_o));
            num += x * h.f[1][k] / f_sep;
            den += x * x;
        }
    }
    if den > 0.0 { (num / den) as f32 } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ M dφ = 2π at any angles (the lobe moves light in azimuth only), M is symmetric in
    /// (μ_i, μ_o), and M = 1 at normal incidence or exit. Midpoint rule in φ (exact for
    /// trigonometric polynomials of degree < nodes), 1e-6 for f32.
    #[test]
    fn the_lobe_keeps_the_azimuthal_mean_and_is_reciprocal() {
        let lobe = AzimuthalLobe::from_rows(vec![0.05; AZIMUTH_ROWS_NM.len()]);
        for (mu_i, mu_o) in [(0.2, 0.7), (0.5, 0.5), (0.9, 0.3)] {
            let n = 64;
            let mean: f32 = (0..n)
                .map(|i| {
                    let phi = (i as f32 + 0.5) / n as f32 * std::f32::consts::TAU;
                    lobe.modulation(mu_i, mu_o, phi.cos(), 550.0)
                })
                .sum::<f32>()
                / n as f32;
            assert!((mean - 1.0).abs() < 1e-6, "{mu_i} {mu_o}: {mean}");
            for c in [-1.0, -0.3, 0.4, 1.0] {
                let (a, b) = (
                    lobe.modulation(mu_i, mu_o, c, 550.0),
                    lobe.modulation(mu_o, mu_i, c, 550.0),
                );
                assert_eq!(a, b);
            }
        }
        assert_eq!(lobe.modulation(1.0, 0.3, 1.0, 550.0), 1.0);
        assert_eq!(lobe.modulation(0.3, 1.0, -1.0, 550.0), 1.0);
    }
}
