//! Beckmann distribution of microfacet normals and its importance sampling ([TS67]; docs/physics.md §7).
//!
//! D(h) = exp(−tan²θh / m²) / (π m² cos⁴θh), with m the RMS slope of the surface. It is normalised
//! over projected microfacet area: ∫ D(h) cosθh dω_h = 1 over the upper hemisphere (the substitution
//! t = tan²θh turns the integral into ∫₀^∞ e^(−t/m²) dt / m² = 1). This is the normalisation of
//! [TS67]/pbrt; GPU variants without the 1/π ([KSK01]) are not interchangeable.
//!
//! Sampling draws h with density D(h) cosθh per solid angle of h: φh = 2π u₁ and, inverting the
//! radial CDF 1 − exp(−tan²θh/m²), tan²θh = −m² ln(1 − u₀).

use crate::real::Real;
use glam::Vec3;
use std::f32::consts::PI;

/// Beyond this exponent tan²θh/m² the factor e^(−x) is below 4e-44 (under f32's normal range) and D is
/// returned as exactly 0, which also keeps 0/0 out at cosθh → 0.
const MAX_EXPONENT: f32 = 100.0;

/// Beckmann D(h) in sr⁻¹ for a unit half-vector `h` in the local frame (+Z = normal) and RMS slope
/// `m`; 0 for h at or below the horizon. sin²θh is taken from h's x and y so that narrow lobes
/// (m ≈ 1e-3) keep full f32 precision near the normal.
#[must_use]
pub fn distribution(h: Vec3, m: f32) -> f32 {
    let cos2 = h.z * h.z;
    if h.z.is_nan() || h.z <= 0.0 || cos2 == 0.0 {
        return 0.0;
    }
    let tan2 = (h.x * h.x + h.y * h.y) / cos2;
    let m2 = m * m;
    let exponent = tan2 / m2;
    if exponent.is_nan() || exponent > MAX_EXPONENT {
        return 0.0;
    }
    (-exponent).exp() / (PI * m2 * cos2 * cos2)
}

/// tan²θh of the sampled half-vector for a uniform `u` in [0, 1): the inverse of the radial CDF
/// 1 − exp(−tan²θh/m²) of the density D cosθh.
pub(crate) fn tan2_theta_from_u<T: Real>(u: T, m: T) -> T {
    // ln(1 − u) through ln_1p keeps precision for small u (the lobe's peak).
    -(m * m) * (-u).ln_1p()
}

/// Half-vector `h` (unit, local frame, upper hemisphere) drawn with density D(h) cosθh per steradian
/// from two uniforms in [0, 1). See [`half_vector_pdf`].
#[must_use]
pub fn sample_half_vector(u: [f32; 2], m: f32) -> Vec3 {
    // u₀ = 1 would give tan²θ = ∞; the largest f32 below 1 maps to θh < 90° for every m ≤ 1.
    let u0 = u[0].clamp(0.0, 1.0 - f32::EPSILON / 2.0);
    let tan2 = tan2_theta_from_u(u0, m);
    let cos_theta = 1.0 / (1.0 + tan2).sqrt();
    let sin_theta = tan2.sqrt() * cos_theta;
    let (sin_phi, cos_phi) = (2.0 * PI * u[1]).sin_cos();
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// Density of [`sample_half_vector`] per steradian of h: D(h) cosθh.
#[must_use]
pub fn half_vector_pdf(h: Vec3, m: f32) -> f32 {
    distribution(h, m) * h.z.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ D cosθh dω over the hemisphere, by the midpoint rule in (θh, φ) (D is isotropic so φ gives 2π).
    fn projected_area(m: f32) -> f64 {
        let n = 20_000;
        let dtheta = std::f64::consts::FRAC_PI_2 / n as f64;
        (0..n)
            .map(|i| {
                let theta = (i as f64 + 0.5) * dtheta;
                let h = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
                f64::from(distribution(h, m)) * theta.cos() * theta.sin() * dtheta
            })
            .sum::<f64>()
            * 2.0
            * std::f64::consts::PI
    }

    #[test]
    fn normalised_over_projected_area() {
        for m in [0.05f32, 0.1, 0.3, 0.6, 1.0] {
            let a = projected_area(m);
            assert!((a - 1.0).abs() < 1e-3, "m = {m}: ∫ D cos = {a}");
        }
    }

    #[test]
    fn peak_value_is_one_over_pi_m2() {
        let m = 0.3f32;
        let d = distribution(Vec3::Z, m);
        assert!((d - 1.0 / (PI * m * m)).abs() < 1e-5 * d);
        assert_eq!(distribution(Vec3::X, m), 0.0);
        assert_eq!(distribution(-Vec3::Z, m), 0.0);
    }

    #[test]
    fn sampled_half_vectors_are_unit_and_above_horizon() {
        for m in [1e-3f32, 0.3, 1.0] {
            for u in [
                [0.0, 0.0],
                [0.5, 0.25],
                [1.0, 1.0],
                [1.0 - f32::EPSILON, 0.9],
            ] {
                let h = sample_half_vector(u, m);
                assert!((h.length() - 1.0).abs() < 1e-5, "{h}");
                assert!(h.z > 0.0, "{h}");
                assert!(half_vector_pdf(h, m).is_finite());
            }
        }
    }

    #[test]
    fn radial_cdf_inverts() {
        // P(tan²θ ≤ t) = 1 − exp(−t/m²): feed u, recover it.
        let m = 0.4f64;
        for u in [0.01, 0.3, 0.77, 0.999] {
            let t = tan2_theta_from_u(u, m);
            assert!((1.0 - (-t / (m * m)).exp() - u).abs() < 1e-12);
        }
    }
}
