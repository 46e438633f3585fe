//! The subsurface total at oblique incidence (docs/physics.md §8.1): light that enters skin
//! obliquely is refracted into a shallower beam, so more of it finds its way out again. The
//! gain a(μ, λ) = R_d(μ, λ) / R_d(1, λ), R_d(μ) the diffuse reflectance per unit flux entering
//! from a collimated beam at incidence cosine μ (outside), comes from adding-doubling's reflection
//! operator (`multipole::exact::adding_doubling::reflectance_by_angle`, §10) at the skin's own
//! parameters and g, tabulated every [`SKIN_TABLE_STEP_NM`] nm at the quadrature's angles.

use crate::fidelity::SKIN_TABLE_STEP_NM;
use crate::fidelity::wavelengths::{FROM_NM, TO_NM};
use multipole::MultipoleError;
use multipole::exact::adding_doubling::{
    AddingDoublingOptions, DEFAULT_QUADRATURE_POINTS, reflectance_by_angle,
};
use rayon::prelude::*;
use skin_optics::{SkinParams, Wavelength};

/// How the separable BSSRDF's angular factor treats the incidence (the knob of §8.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Incidence {
    /// R_tot at normal incidence for every angle, T(θ) alone ([JMLH01], pbrt): a flat slab seen or
    /// lit obliquely renders up to 5% dark (docs/physics.md §8.1).
    Normal,
    /// T(θ) a(θ, λ) with the adding-doubling gain a (default): a flat slab under a uniform sky
    /// renders its exact albedo at every angle.
    #[default]
    AddingDoubling,
}

/// a(μ, λ) of one skin: rows every [`SKIN_TABLE_STEP_NM`] nm from 380 nm, columns at the
/// outside cosines of the adding-doubling quadrature (ascending, the last 1).
#[derive(Debug, Clone, PartialEq)]
pub struct IncidenceGain {
    mu: Vec<f32>,
    rows: Vec<Vec<f32>>,
}

impl IncidenceGain {
    /// The gain of `params` at HG anisotropy `g`, one adding-doubling solve per tabulated
    /// wavelength (in parallel).
    pub fn build(params: &SkinParams, g: f64) -> Result<Self, MultipoleError> {
        let n = ((TO_NM - FROM_NM) / SKIN_TABLE_STEP_NM) as usize + 1;
        let options = AddingDoublingOptions::new(DEFAULT_QUADRATURE_POINTS, g)?;
        let solved = (0..n)
            .into_par_iter()
            .map(|i| {
                let nm = FROM_NM + SKIN_TABLE_STEP_NM * i as f64;
                let medium = multipole::LayeredMedium::skin(params, Wavelength::new(nm)?, g)?;
                Ok(reflectance_by_angle(&medium, &options)?)
            })
            .collect::<Result<Vec<_>, MultipoleError>>()?;
        let mu = solved[0].iter().map(|r| r.mu_outside as f32).collect();
        let rows = solved
            .iter()
            .map(|angles| {
                let normal = angles.last().map_or(0.0, |r| r.per_entering());
                angles
                    .iter()
                    .map(|r| {
                        let a = r.per_entering() / normal;
                        if a.is_finite() { a as f32 } else { 1.0 }
                    })
                    .collect()
            })
            .collect();
        Ok(Self { mu, rows })
    }

    /// Tabulated wavelengths.
    #[must_use]
    pub fn wavelengths(&self) -> usize {
        self.rows.len()
    }

    /// The wavelength of row `i`, nm.
    #[must_use]
    pub fn row_nm(i: usize) -> f32 {
        (FROM_NM + SKIN_TABLE_STEP_NM * i as f64) as f32
    }

    /// a(μ) of row `i`, linear in μ between the quadrature's angles and held at the grazing-most
    /// one below it (where T(θ) → 0 anyway).
    #[must_use]
    pub fn row_gain(&self, i: usize, mu: f32) -> f32 {
        let row = &self.rows[i.min(self.rows.len() - 1)];
        let k = self.mu.partition_point(|&m| m < mu);
        if k == 0 {
            return row[0];
        }
        if k >= self.mu.len() {
            return row[self.mu.len() - 1];
        }
        let (m0, m1) = (self.mu[k - 1], self.mu[k]);
        let t = (mu - m0) / (m1 - m0);
        row[k - 1] + t * (row[k] - row[k - 1])
    }

    /// The row index and weight of the next row for wavelength `nm` (linear in λ).
    #[must_use]
    pub fn rows_at(&self, nm: f32) -> (usize, f32) {
        let x = ((f64::from(nm) - FROM_NM) / SKIN_TABLE_STEP_NM)
            .clamp(0.0, (self.rows.len() - 1) as f64);
        let i = (x as usize).min(self.rows.len().saturating_sub(2));
        (i, (x - i as f64) as f32)
    }

    /// a(μ, λ) at outside incidence cosine `mu` and wavelength `nm` (1 at μ = 1).
    #[must_use]
    pub fn gain(&self, mu: f32, nm: f32) -> f32 {
        let (i, t) = self.rows_at(nm);
        if self.rows.len() < 2 {
            return self.row_gain(0, mu);
        }
        let (a, b) = (self.row_gain(i, mu), self.row_gain(i + 1, mu));
        a + t * (b - a)
    }
}
