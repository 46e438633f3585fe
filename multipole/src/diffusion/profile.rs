//! The radial profile table: R(r) on a geometric radius grid, its total, energy radii, and the CDF of
//! 2πr R(r) for importance sampling r (docs/physics.md §8). The renderer and validation both use it.
//!
//! Between nodes, the sampling density p(r) = 2πr R(r) is linear in r (so the CDF is piecewise
//! quadratic and inverted exactly, by [`crate::sampling`]); below the first radius it rises linearly
//! from p(0) = 0. [`Profile::sample_radius`] and [`Profile::pdf_radius`] are exactly consistent;
//! [`Profile::eval`] interpolates R log–log between nodes and is 0 beyond the last radius.

use crate::error::MultipoleError;
use crate::sampling;
use std::f64::consts::PI;

/// Radial diffuse reflectance table of one material at one wavelength.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    radii_mm: Vec<f64>,
    reflectance_per_mm2: Vec<f64>,
    total: f64,
    /// The sampling density p = 2πr R(r) at each node, mm⁻¹.
    density: Vec<f64>,
    /// Cumulative ∫₀^{r_i} 2πr R dr at each node (trapezoid in the linear-p model).
    cdf: Vec<f64>,
    clamped: usize,
}

impl Profile {
    /// Profile from increasing radii (mm, > 0), R(r) values (mm⁻², finite, ≥ 0) and the model's total
    /// reflectance (dimensionless, finite, ≥ 0; e.g. exact from q = 0). At least two radii.
    pub fn from_table(
        radii_mm: Vec<f64>,
        reflectance_per_mm2: Vec<f64>,
        total: f64,
    ) -> Result<Self, MultipoleError> {
        if radii_mm.len() < 2 || radii_mm.len() != reflectance_per_mm2.len() {
            return Err(MultipoleError::Profile(
                "need ≥ 2 radii and one value per radius",
            ));
        }
        if radii_mm[0] <= 0.0
            || radii_mm
                .windows(2)
                .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
            || radii_mm.iter().any(|r| !r.is_finite())
        {
            return Err(MultipoleError::Profile(
                "radii must be finite, positive and increasing",
            ));
        }
        if reflectance_per_mm2
            .iter()
            .any(|v| !v.is_finite() || *v < 0.0)
        {
            return Err(MultipoleError::Profile(
                "R(r) must be finite and non-negative",
            ));
        }
        if !total.is_finite() || total < 0.0 {
            return Err(MultipoleError::Profile(
                "total must be finite and non-negative",
            ));
        }
        let density: Vec<f64> = radii_mm
            .iter()
            .zip(&reflectance_per_mm2)
            .map(|(r, v)| 2.0 * PI * r * v)
            .collect();
        let cdf = sampling::cumulative(&radii_mm, &density);
        Ok(Self {
            radii_mm,
            reflectance_per_mm2,
            total,
            density,
            cdf,
            clamped: 0,
        })
    }

    pub(crate) fn with_clamped(mut self, clamped: usize) -> Self {
        self.clamped = clamped;
        self
    }

    /// Radii of the table, mm (geometric from about 1e-3 mm to the outer radius).
    #[must_use]
    pub fn radii_mm(&self) -> &[f64] {
        &self.radii_mm
    }

    /// R(r) at each radius, mm⁻².
    #[must_use]
    pub fn reflectance_per_mm2(&self) -> &[f64] {
        &self.reflectance_per_mm2
    }

    /// The model's total diffuse reflectance ∫ 2πr R(r) dr over the whole plane (exact, from q = 0).
    #[must_use]
    pub fn total(&self) -> f64 {
        self.total
    }

    /// ∫ 2πr R(r) dr over the table [0, r_max] (the normalisation of the sampling pdf).
    #[must_use]
    pub fn table_integral(&self) -> f64 {
        *self.cdf.last().unwrap_or(&0.0)
    }

    /// Outer radius of the table, mm.
    #[must_use]
    pub fn r_max_mm(&self) -> f64 {
        *self.radii_mm.last().unwrap_or(&0.0)
    }

    /// Number of radii where a slightly negative numerical value was clamped to 0 (0 when the inverse
    /// transform is converged; reported so tests and charts can see it).
    #[must_use]
    pub fn clamped_samples(&self) -> usize {
        self.clamped
    }

    /// Radius holding the fraction `frac` of the model's total reflectance, mm; capped at r_max
    /// when the table holds less than that.
    #[must_use]
    pub fn radius_for_energy(&self, frac: f64) -> f64 {
        self.radius_for_cumulative(frac.clamp(0.0, 1.0) * self.total)
    }

    /// ∫₀^r 2πr' R(r') dr' in the model of the sampling pdf (p = 2πrR linear between nodes, from 0
    /// at r = 0 to the first node), dimensionless; the table's integral beyond r_max.
    #[must_use]
    pub fn energy_within_mm(&self, r_mm: f64) -> f64 {
        sampling::cumulative_at(&self.radii_mm, &self.density, &self.cdf, r_mm)
    }

    /// Radius holding 99% of the total reflectance, mm.
    #[must_use]
    pub fn radius_99_mm(&self) -> f64 {
        self.radius_for_energy(0.99)
    }

    /// Invert the cumulative energy: the radius where ∫₀^r 2πr' R dr' = `target`.
    fn radius_for_cumulative(&self, target: f64) -> f64 {
        sampling::invert(&self.radii_mm, &self.density, &self.cdf, target)
    }

    /// A radius drawn with pdf ∝ 2πr R(r) on [0, r_max], from a uniform `u` in [0, 1), mm.
    #[must_use]
    pub fn sample_radius(&self, u: f64) -> f64 {
        self.radius_for_cumulative(u.clamp(0.0, 1.0) * self.table_integral())
    }

    /// The pdf of [`Profile::sample_radius`] at `r_mm`, per mm (0 outside [0, r_max]).
    #[must_use]
    pub fn pdf_radius(&self, r_mm: f64) -> f64 {
        let norm = self.table_integral();
        if norm <= 0.0 {
            return 0.0;
        }
        sampling::density(&self.radii_mm, &self.density, r_mm) / norm
    }

    /// R(r) at `r_mm`, mm⁻²: log–log interpolation between nodes (linear where a value is 0),
    /// R(r₀) below the first radius, 0 beyond the last.
    #[must_use]
    pub fn eval(&self, r_mm: f64) -> f64 {
        let (rs, vs) = (&self.radii_mm, &self.reflectance_per_mm2);
        if r_mm.is_nan() || r_mm < 0.0 || r_mm > self.r_max_mm() {
            return 0.0;
        }
        if r_mm <= rs[0] {
            return vs[0];
        }
        let i = rs.partition_point(|&r| r < r_mm).max(1);
        let (r0, r1, v0, v1) = (rs[i - 1], rs[i], vs[i - 1], vs[i]);
        if v0 > 0.0 && v1 > 0.0 {
            let t = (r_mm / r0).ln() / (r1 / r0).ln();
            (v0.ln() + t * (v1.ln() - v0.ln())).exp()
        } else {
            let t = (r_mm - r0) / (r1 - r0);
            v0 + t * (v1 - v0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::{dipole::Dipole, medium::Medium};
    use approx::assert_relative_eq;

    fn dipole_profile() -> (Dipole, Profile) {
        let d = Dipole::new(Medium::new(0.1, 1.0).unwrap(), 1.4).unwrap();
        let r_max = d.radius_for_energy(0.999);
        let n = 512;
        let radii: Vec<f64> = (0..n)
            .map(|i| 1e-3 * (r_max / 1e-3f64).powf(i as f64 / (n - 1) as f64))
            .collect();
        let vals = radii.iter().map(|&r| d.reflectance_mm2(r)).collect();
        (
            d,
            Profile::from_table(radii, vals, d.total_reflectance()).unwrap(),
        )
    }

    #[test]
    fn table_integral_and_energy_radius_match_the_closed_form() {
        let (d, p) = dipole_profile();
        // The table holds 99.9% of the dipole's energy (trapezoid: within 0.1%).
        assert_relative_eq!(
            p.table_integral(),
            0.999 * d.total_reflectance(),
            max_relative = 1e-3
        );
        let r99 = p.radius_99_mm();
        assert_relative_eq!(r99, d.radius_for_energy(0.99), max_relative = 5e-3);
    }

    #[test]
    fn sampling_inverts_the_cdf_and_matches_the_pdf() {
        let (_, p) = dipole_profile();
        // Numerically differentiate the sampler: dr/du = 1 / pdf(r).
        for u in [0.01, 0.2, 0.5, 0.9, 0.99] {
            let (r0, r1) = (p.sample_radius(u), p.sample_radius(u + 1e-6));
            let pdf = p.pdf_radius(0.5 * (r0 + r1));
            assert_relative_eq!((r1 - r0) / 1e-6, 1.0 / pdf, max_relative = 1e-3);
        }
        // The pdf integrates to 1 (trapezoid on a fine grid).
        let n = 200_000;
        let h = p.r_max_mm() / n as f64;
        let s: f64 = (0..n).map(|i| p.pdf_radius((i as f64 + 0.5) * h) * h).sum();
        assert_relative_eq!(s, 1.0, max_relative = 1e-4);
        assert_eq!(p.pdf_radius(p.r_max_mm() * 1.01), 0.0);
        assert_eq!(p.sample_radius(1.0), p.r_max_mm());
    }

    #[test]
    fn energy_within_is_the_integral_of_the_sampling_pdf() {
        let (_, p) = dipole_profile();
        // The cumulative is the sampler's inverse: energy within sample_radius(u) = u × integral
        // (to rounding of the quadratic solve), 0 at 0 and the table's integral at r_max.
        for u in [0.001, 0.05, 0.5, 0.95] {
            let r = p.sample_radius(u);
            assert_relative_eq!(
                p.energy_within_mm(r),
                u * p.table_integral(),
                max_relative = 1e-9
            );
        }
        assert_eq!(p.energy_within_mm(0.0), 0.0);
        assert_eq!(p.energy_within_mm(p.r_max_mm() * 2.0), p.table_integral());
    }

    #[test]
    fn eval_interpolates_between_nodes() {
        let (d, p) = dipole_profile();
        for r in [0.0005, 0.01, 0.3, 2.0] {
            assert_relative_eq!(
                p.eval(r),
                d.reflectance_mm2(r.max(1e-3)),
                max_relative = 1e-3
            );
        }
        assert_eq!(p.eval(p.r_max_mm() * 2.0), 0.0);
    }

    #[test]
    fn rejects_bad_tables() {
        assert!(Profile::from_table(vec![1.0, 0.5], vec![1.0, 1.0], 0.5).is_err());
        assert!(Profile::from_table(vec![0.5, 1.0], vec![1.0, -1.0], 0.5).is_err());
        assert!(Profile::from_table(vec![0.5, 1.0], vec![1.0, f64::NAN], 0.5).is_err());
        assert!(Profile::from_table(vec![0.5, 1.0], vec![1.0, 1.0], f64::NAN).is_err());
    }
}
