//! The subsurface total at oblique incidence (docs/physics.md §8.1): light that enters skin
//! obliquely is refracted into a shallower beam, so more of it finds its way out again. The
//! gain a(μ, λ) = R_d(μ, λ) / R_d(1, λ), R_d(μ) the diffuse reflectance per unit flux entering
//! from a collimated beam at incidence cosine μ (outside), comes from adding-doubling's reflection
//! operator (`multipole::exact::adding_doubling::reflectance_by_angle`, §10) at the skin's own
//! parameters and g, tabulated every [`INCIDENCE_STEP_NM`] nm at the quadrature's angles.

use crate::spectrum::{
    GRID_10NM_NODES, GRID_10NM_STEP_NM, GridPosition, LAMBDA_MAX_NM, LAMBDA_MIN_NM,
    SampledWavelengths,
};
use multipole::exact::adding_doubling::{
    AddingDoublingOptions, DEFAULT_QUADRATURE_POINTS, reflectance_by_angle,
};
use multipole::{LayeredMedium, MultipoleError};
use rayon::prelude::*;

/// Wavelength step of the gain's rows, nm (the skin tables' 10 nm), interpolated linearly.
pub const INCIDENCE_STEP_NM: f64 = 10.0;

const FROM_NM: f64 = LAMBDA_MIN_NM as f64;
const TO_NM: f64 = LAMBDA_MAX_NM as f64;

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

/// a(μ, λ) of one skin: rows every [`INCIDENCE_STEP_NM`] nm from 380 nm, columns at the
/// outside cosines of the adding-doubling quadrature (ascending, the last 1).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IncidenceGain {
    mu: Vec<f32>,
    /// The rows one after the other, `mu.len()` values each.
    rows: Vec<f32>,
}

impl IncidenceGain {
    /// The gain of the skin layers `rows` (each wavelength, nm, from 380 nm every
    /// [`INCIDENCE_STEP_NM`] nm with its layered medium, as `media::SkinMedia::every_10nm` lists
    /// them) at HG anisotropy `g`: one adding-doubling solve per row, in parallel.
    pub fn build<'m>(
        rows: impl Iterator<Item = (f64, &'m LayeredMedium)>,
        g: f64,
    ) -> Result<Self, MultipoleError> {
        let options = AddingDoublingOptions::new(DEFAULT_QUADRATURE_POINTS, g)?;
        let rows: Vec<(f64, &LayeredMedium)> = rows.collect();
        let expected = ((TO_NM - FROM_NM) / INCIDENCE_STEP_NM) as usize + 1;
        if rows.len() != expected
            || rows
                .iter()
                .enumerate()
                .any(|(i, (nm, _))| (nm - (FROM_NM + INCIDENCE_STEP_NM * i as f64)).abs() > 1e-9)
        {
            return Err(MultipoleError::InvalidOption {
                name: "incidence gain rows",
                value: rows.len() as f64,
                range: "380–780 nm every 10 nm",
            });
        }
        let solved = rows
            .into_par_iter()
            .map(|(_, medium)| reflectance_by_angle(medium, &options))
            .collect::<Result<Vec<_>, _>>()?;
        let mu = solved[0].iter().map(|r| r.mu_outside as f32).collect();
        let rows = solved
            .iter()
            .flat_map(|angles| {
                let normal = angles.last().map_or(0.0, |r| r.per_entering());
                angles
                    .iter()
                    .map(|r| {
                        let a = r.per_entering() / normal;
                        if a.is_finite() { a as f32 } else { 1.0 }
                    })
                    .collect::<Vec<f32>>()
            })
            .collect();
        Ok(Self { mu, rows })
    }

    /// Whether the table is whole: at least one angle, ascending, and every row complete and
    /// finite (a table read back from the disk cache is checked with it).
    #[must_use]
    pub fn is_whole(&self) -> bool {
        !self.mu.is_empty()
            && self.mu.windows(2).all(|w| w[0] < w[1])
            && !self.rows.is_empty()
            && self.rows.len().is_multiple_of(self.mu.len())
            && self.rows.iter().all(|a| a.is_finite())
    }

    /// The outside incidence cosines of the columns, ascending.
    #[must_use]
    pub fn angles(&self) -> &[f32] {
        &self.mu
    }

    /// Tabulated wavelengths.
    #[must_use]
    pub fn wavelengths(&self) -> usize {
        self.rows.len() / self.mu.len().max(1)
    }

    /// The wavelength of row `i`, nm.
    #[must_use]
    pub fn row_nm(i: usize) -> f32 {
        (FROM_NM + INCIDENCE_STEP_NM * i as f64) as f32
    }

    /// Where `mu` falls among the quadrature's angles: the two columns and the weight of the
    /// second, found once for every row and wavelength read at that angle.
    #[must_use]
    pub fn column(&self, mu: f32) -> Column {
        let k = self.mu.partition_point(|&m| m < mu);
        if k == 0 {
            return Column {
                k0: 0,
                k1: 0,
                t: 0.0,
            };
        }
        if k >= self.mu.len() {
            let last = self.mu.len() - 1;
            return Column {
                k0: last,
                k1: last,
                t: 0.0,
            };
        }
        let (m0, m1) = (self.mu[k - 1], self.mu[k]);
        Column {
            k0: k - 1,
            k1: k,
            t: (mu - m0) / (m1 - m0),
        }
    }

    /// a of row `i` at the column `c` (linear between the quadrature's angles).
    #[must_use]
    pub fn row_gain_at(&self, i: usize, c: Column) -> f32 {
        let n = self.mu.len();
        let row = &self.rows[n * i.min(self.wavelengths() - 1)..];
        row[c.k0] + c.t * (row[c.k1] - row[c.k0])
    }

    /// a(μ) of row `i`, linear in μ between the quadrature's angles and held at the grazing-most
    /// one below it (where T(θ) → 0 anyway).
    #[must_use]
    pub fn row_gain(&self, i: usize, mu: f32) -> f32 {
        self.row_gain_at(i, self.column(mu))
    }

    /// The row index and weight of the next row for wavelength `nm` (linear in λ).
    #[must_use]
    pub fn rows_at(&self, nm: f32) -> (usize, f32) {
        if self.wavelengths() < 2 {
            return (0, 0.0);
        }
        let at = GridPosition::on_grid(nm, INCIDENCE_STEP_NM as f32, self.wavelengths());
        (at.index(), at.weight())
    }

    /// a(μ, λ) at outside incidence cosine `mu` and wavelength `nm` (1 at μ = 1).
    #[must_use]
    pub fn gain(&self, mu: f32, nm: f32) -> f32 {
        self.gain_at(self.column(mu), nm)
    }

    /// a(μ, λ) at the column `c` of μ and wavelength `nm`.
    #[must_use]
    pub fn gain_at(&self, c: Column, nm: f32) -> f32 {
        let (i, t) = self.rows_at(nm);
        if self.wavelengths() < 2 {
            return self.row_gain_at(0, c);
        }
        let (a, b) = (self.row_gain_at(i, c), self.row_gain_at(i + 1, c));
        a + t * (b - a)
    }

    /// [`Self::gain_at`] at the path's wavelength `k`, whose row was found once per path.
    #[must_use]
    #[inline]
    pub fn gain_lane(&self, c: Column, wl: &SampledWavelengths, k: usize) -> f32 {
        if !self.on_10nm_grid() {
            return self.gain_at(c, wl.nm(k));
        }
        let at = wl.on_10nm(k);
        let (a, b) = (
            self.row_gain_at(at.index(), c),
            self.row_gain_at(at.index() + 1, c),
        );
        a + at.weight() * (b - a)
    }

    /// Whether the rows are the path's 10-nm grid (always, as built: 380–780 nm every 10 nm).
    #[must_use]
    #[inline]
    pub fn on_10nm_grid(&self) -> bool {
        self.wavelengths() == GRID_10NM_NODES && INCIDENCE_STEP_NM as f32 == GRID_10NM_STEP_NM
    }
}

/// Where an incidence cosine falls among the gain's tabulated angles ([`IncidenceGain::column`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Column {
    k0: usize,
    k1: usize,
    t: f32,
}
