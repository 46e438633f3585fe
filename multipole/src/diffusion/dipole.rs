//! The dipole: diffuse reflectance of a semi-infinite medium ([JMLH01]; docs/physics.md §3).
//!
//! Real source at depth z_r = ℓ, virtual source at z_v = −(ℓ + 2 z_b) (z into the medium).

use crate::diffusion::boundary::a_coefficient;
use crate::diffusion::medium::{Medium, pole_energy_within, pole_kernel, pole_transform};
use crate::error::{MultipoleError, check_range};
use std::f64::consts::PI;

/// A semi-infinite medium under a face of relative index η (= n_medium / n_outside).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dipole {
    medium: Medium,
    a_boundary: f64,
    z_r: f64,
    z_v: f64,
}

impl Dipole {
    /// Dipole for `medium` below a face of relative index `eta` in [0.2, 5].
    pub fn new(medium: Medium, eta: f64) -> Result<Self, MultipoleError> {
        check_range("η (relative index)", eta, 0.2, 5.0, "[0.2, 5]")?;
        Ok(Self::with_a(medium, a_coefficient(eta)))
    }

    /// Dipole with an explicit boundary coefficient A ≥ 1 (e.g. A = 1 for an index-matched face).
    pub(crate) fn with_a(medium: Medium, a_boundary: f64) -> Self {
        let l = medium.mean_free_path_mm();
        let z_b = medium.extrapolation_mm(a_boundary);
        Self {
            medium,
            a_boundary,
            z_r: l,
            z_v: -(l + 2.0 * z_b),
        }
    }

    /// The medium's coefficients.
    #[must_use]
    pub fn medium(&self) -> &Medium {
        &self.medium
    }

    /// Boundary coefficient A of the face, dimensionless.
    #[must_use]
    pub fn a_boundary(&self) -> f64 {
        self.a_boundary
    }

    /// Depth of the real source z_r = ℓ, mm.
    #[must_use]
    pub fn z_r(&self) -> f64 {
        self.z_r
    }

    /// Signed depth of the virtual source z_v = −(ℓ + 2 z_b), mm.
    #[must_use]
    pub fn z_v(&self) -> f64 {
        self.z_v
    }

    /// Radial diffuse reflectance R(r) at distance `r_mm`, mm⁻² ([JMLH01] eq. 4):
    /// α'/(4π) [z_r (1 + σtr d_r) e^(−σtr d_r)/d_r³ − z_v (1 + σtr d_v) e^(−σtr d_v)/d_v³].
    #[must_use]
    pub fn reflectance_mm2(&self, r_mm: f64) -> f64 {
        let s = self.medium.sigma_tr();
        self.medium.albedo_prime() / (4.0 * PI)
            * (pole_kernel(self.z_r, r_mm, s) - pole_kernel(self.z_v, r_mm, s))
    }

    /// Total diffuse reflectance, closed form, dimensionless (docs/physics.md §3):
    /// (α'/2)(1 + e^(−(4/3) A √(3(1−α')))) e^(−√(3(1−α'))).
    #[must_use]
    pub fn total_reflectance(&self) -> f64 {
        let ap = self.medium.albedo_prime();
        let k = (3.0 * (1.0 - ap)).sqrt();
        0.5 * ap * (1.0 + (-(4.0 / 3.0) * self.a_boundary * k).exp()) * (-k).exp()
    }

    /// Reflectance within radius `r_mm`, ∫₀^r 2πr' R(r') dr', dimensionless (closed form).
    #[must_use]
    pub fn reflectance_within(&self, r_mm: f64) -> f64 {
        let s = self.medium.sigma_tr();
        0.5 * self.medium.albedo_prime()
            * (pole_energy_within(self.z_r, r_mm, s) - pole_energy_within(self.z_v, r_mm, s))
    }

    /// Radius holding the fraction `frac` in (0, 1) of the total reflectance, mm (Newton on the
    /// closed-form cumulative energy, whose derivative is 2πr R(r), safeguarded by bisection; 1e-9 relative).
    #[must_use]
    pub fn radius_for_energy(&self, frac: f64) -> f64 {
        let target = frac.clamp(0.0, 1.0 - 1e-12) * self.reflectance_within(f64::INFINITY);
        let mut hi = self.medium.mean_free_path_mm();
        // The cumulative energy rises monotonically to the total; 2000 mm bounds any tissue.
        while self.reflectance_within(hi) < target && hi < 2000.0 {
            hi *= 2.0;
        }
        let mut lo = 0.0;
        let mut r = 0.5 * hi;
        for _ in 0..100 {
            let g = self.reflectance_within(r) - target;
            if g < 0.0 {
                lo = r
            } else {
                hi = r
            }
            let slope = 2.0 * PI * r * self.reflectance_mm2(r);
            let newton = r - g / slope;
            let next = if slope > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            let done = (next - r).abs() <= 1e-9 * r || hi - lo <= 1e-9 * hi;
            r = next;
            if done {
                break;
            }
        }
        r
    }

    /// Order-0 Hankel transform R̂(q) at spatial frequency `q` (rad/mm), dimensionless
    /// (docs/physics.md §5): (α'/2)(e^(−z_r s) + e^(−|z_v| s)), s = √(σtr² + q²). R̂(0) = the closed-form total.
    #[must_use]
    pub fn transform(&self, q: f64) -> f64 {
        let st = self.medium.sigma_tr();
        let s = (st * st + q * q).sqrt();
        0.5 * self.medium.albedo_prime()
            * (pole_transform(self.z_r, s) - pole_transform(self.z_v, s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn dipole(sa: f64, ss: f64) -> Dipole {
        Dipole::new(Medium::new(sa, ss).unwrap(), 1.4).unwrap()
    }

    #[test]
    fn closed_form_totals_match_physics_md() {
        // docs/physics.md §3 check values, η = 1.4.
        for (sa, expect) in [(0.01, 0.61410), (0.1, 0.29767), (1.0, 0.07382)] {
            let d = dipole(sa, 1.0);
            assert_relative_eq!(d.total_reflectance(), expect, max_relative = 1e-4);
            // The transform at q = 0 reproduces the closed form exactly.
            assert_relative_eq!(
                d.transform(0.0),
                d.total_reflectance(),
                max_relative = 1e-12
            );
            assert_relative_eq!(
                d.reflectance_within(f64::INFINITY),
                d.total_reflectance(),
                max_relative = 1e-12
            );
        }
    }

    #[test]
    fn integral_of_profile_matches_closed_form_total() {
        // Trapezoid of 2π r² R(r) in ln r from 1e-5 mm to the 99.9999% radius: within 0.5%
        // (the truncated tails and the trapezoid error are each far below that).
        for sa in [0.01, 0.1, 1.0] {
            let d = dipole(sa, 1.0);
            let r_hi = d.radius_for_energy(0.999_999);
            let n = 4000;
            let (a, b) = ((1e-5f64).ln(), r_hi.ln());
            let h = (b - a) / n as f64;
            let f = |t: f64| {
                let r = t.exp();
                2.0 * PI * r * r * d.reflectance_mm2(r)
            };
            let mut sum = 0.5 * (f(a) + f(b));
            for i in 1..n {
                sum += f(a + i as f64 * h);
            }
            sum *= h;
            let rel = (sum - d.total_reflectance()).abs() / d.total_reflectance();
            assert!(
                rel < 0.005,
                "σa = {sa}: ∫ = {sum}, closed form {}",
                d.total_reflectance()
            );
        }
    }

    #[test]
    fn energy_radius_inverts_cumulative() {
        let d = dipole(0.1, 1.0);
        let r = d.radius_for_energy(0.99);
        assert_relative_eq!(
            d.reflectance_within(r) / d.total_reflectance(),
            0.99,
            max_relative = 1e-8
        );
    }

    #[test]
    fn rejects_bad_eta() {
        let m = Medium::new(0.1, 1.0).unwrap();
        assert!(Dipole::new(m, f64::NAN).is_err());
        assert!(Dipole::new(m, 0.0).is_err());
    }
}
