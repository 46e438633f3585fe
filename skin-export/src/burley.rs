//! Christensen–Burley normalized diffusion ([CB15]): R(r) = A (e^{−r/d} + e^{−r/3d}) / (8π d r), of
//! total A and mean radial distance 2.5 d; fitted per channel to our total and mean radius
//! (docs/physics.md §14). Unreal's Subsurface Profile and Unity HDRP's diffusion profiles use this
//! model; Unreal takes a mean free path ℓ = d · s(A) with the perpendicular-incidence factor of [CB15].

use crate::error::ExportError;
use crate::rgb::{RgbProfile, shape_error, total_error};
use std::f64::consts::PI;

/// Mean radial distance of the profile in units of d: ∫ r · ¼(e^{−r/d} + e^{−r/3d})/d dr = (1 + 9)/4.
pub const MEAN_RADIUS_PER_D: f64 = 2.5;

/// R(r) of unit albedo, mm⁻², for shape `d_mm`.
#[must_use]
pub fn reflectance_per_mm2(r_mm: f64, d_mm: f64) -> f64 {
    ((-r_mm / d_mm).exp() + (-r_mm / (3.0 * d_mm)).exp()) / (8.0 * PI * d_mm * r_mm)
}

/// Energy inside radius r of the unit-albedo profile: 1 − ¼e^{−r/d} − ¾e^{−r/3d}.
#[must_use]
pub fn energy_within(r_mm: f64, d_mm: f64) -> f64 {
    1.0 - 0.25 * (-r_mm / d_mm).exp() - 0.75 * (-r_mm / (3.0 * d_mm)).exp()
}

/// The radius holding `fraction` in (0, 1) of the energy, mm (bisection to 1e-12 relative).
#[must_use]
pub fn radius_for_energy(fraction: f64, d_mm: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, d_mm);
    while energy_within(hi, d_mm) < fraction {
        hi *= 2.0;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if energy_within(mid, d_mm) < fraction {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// [CB15]'s scaling s(A) = 1.85 − A + 7|A − 0.8|³ for a beam perpendicular to the surface, with the
/// profile parameterised by the mean free path ℓ: d = ℓ / s.
#[must_use]
pub fn perpendicular_scaling(albedo: f64) -> f64 {
    1.85 - albedo + 7.0 * (albedo - 0.8).abs().powi(3)
}

/// A Burley fit per channel and its measured errors against the reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BurleyFit {
    /// Albedo A per channel: our total reflectance (per unit flux entering).
    pub albedo: [f64; 3],
    /// Shape parameter d per channel, mm.
    pub d_mm: [f64; 3],
    /// |A − R_ref| / R_ref per channel (0 by construction up to rounding).
    pub total_error: [f64; 3],
    /// Energy-weighted shape error per channel ([`shape_error`]).
    pub shape_error: [f64; 3],
}

impl BurleyFit {
    /// d per channel = mean radial distance / 2.5, A = the channel's total.
    pub fn fit(rgb: &RgbProfile) -> Result<Self, ExportError> {
        let mut fit = Self {
            albedo: rgb.totals(),
            d_mm: [0.0; 3],
            total_error: [0.0; 3],
            shape_error: [0.0; 3],
        };
        for c in 0..3 {
            let d = rgb.mean_radius_mm(c) / MEAN_RADIUS_PER_D;
            if !(d.is_finite() && d > 0.0) {
                return Err(ExportError::Fit(format!(
                    "channel {c}: no mean radius (d = {d} mm)"
                )));
            }
            let reference = rgb.channel(c)?;
            fit.d_mm[c] = d;
            fit.total_error[c] = total_error(rgb.totals()[c], fit.albedo[c]);
            fit.shape_error[c] = shape_error(&reference, |r| reflectance_per_mm2(r, d));
        }
        Ok(fit)
    }

    /// The mean free path per channel, mm, that gives this d under [`perpendicular_scaling`].
    #[must_use]
    pub fn mean_free_path_mm(&self) -> [f64; 3] {
        [0, 1, 2].map(|c| self.d_mm[c] * perpendicular_scaling(self.albedo[c]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb::RgbProfile;

    #[test]
    fn profile_has_unit_energy_and_mean_two_and_a_half_d() {
        let d = 0.7;
        let (mut e, mut m) = (0.0, 0.0);
        // Midpoint rule in ln r over 1e-6..1e3 mm (tails below 1e-9 of the energy).
        let n = 20_000;
        let (lo, hi): (f64, f64) = (1e-6, 1e3);
        let h = (hi / lo).ln() / n as f64;
        for i in 0..n {
            let r = lo * (h * (i as f64 + 0.5)).exp();
            let p = 2.0 * PI * r * r * reflectance_per_mm2(r, d) * h;
            e += p;
            m += r * p;
        }
        assert!((e - 1.0).abs() < 1e-6, "{e}");
        assert!((m / e - MEAN_RADIUS_PER_D * d).abs() < 1e-5, "{m}");
        assert!((energy_within(radius_for_energy(0.997, d), d) - 0.997).abs() < 1e-12);
    }

    #[test]
    fn fit_of_a_burley_profile_recovers_it() {
        let radii: Vec<f64> = (0..500).map(|i| 1e-4 * 1.035_f64.powi(i)).collect();
        let ds = [0.9, 0.4, 0.2];
        let values = ds.map(|d| radii.iter().map(|&r| reflectance_per_mm2(r, d)).collect());
        let rgb = RgbProfile::from_parts(radii, values, [0.6, 0.4, 0.3]);
        let fit = BurleyFit::fit(&rgb).unwrap();
        for (c, d) in ds.iter().enumerate() {
            // The table ends at 1.5e3 mm and starts at 1e-4 mm: the trapezoid mean is within 1e-3.
            assert!((fit.d_mm[c] / d - 1.0).abs() < 1e-3, "{:?}", fit.d_mm);
            assert!(fit.shape_error[c] < 5e-3, "{:?}", fit.shape_error);
        }
    }
}
