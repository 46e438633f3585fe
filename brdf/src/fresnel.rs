//! Exact unpolarised Fresnel reflectance of a smooth dielectric interface, and its angular moments.
//!
//! The only home of dielectric Fresnel in the workspace (docs/physics.md §7): the microfacet lobe
//! uses it ([TS67]); `multipole` uses it for the observable reflectance, the faces of adding-doubling
//! and the Monte Carlo's interfaces; `render` for the BSSRDF's directional term.
//! Written once, generic over the float width: f64 for the physics crates, f32 for the per-ray lobe.

use crate::real::Real;

/// Unpolarised Fresnel reflectance for light arriving with `cos_theta_i` (cosine to the normal on the
/// incident side, clamped to [0, 1]) at an interface of relative index `eta` = n_transmitted / n_incident.
/// Returns 1 under total internal reflection (possible when `eta` < 1).
#[must_use]
pub fn dielectric_reflectance(cos_theta_i: f64, eta: f64) -> f64 {
    reflectance(cos_theta_i, eta)
}

/// [`dielectric_reflectance`] in f32, for the per-ray lobe evaluation (same formula, same code).
#[must_use]
pub fn dielectric_reflectance_f32(cos_theta_i: f32, eta: f32) -> f32 {
    reflectance(cos_theta_i, eta)
}

/// The Fresnel equations for unpolarised light, written once for both float widths.
fn reflectance<T: Real>(cos_theta_i: T, eta: T) -> T {
    let c = cos_theta_i.clamp(T::ZERO, T::ONE);
    let sin2_t = (T::ONE - c * c) / (eta * eta);
    if sin2_t >= T::ONE {
        return T::ONE;
    }
    let ct = (T::ONE - sin2_t).sqrt();
    let r_par = (eta * c - ct) / (eta * c + ct);
    let r_perp = (c - eta * ct) / (c + eta * ct);
    (r_par * r_par + r_perp * r_perp) / T::TWO
}

/// Fresnel reflectance at normal incidence, ((η − 1)/(η + 1))² (0.0278 for η = 1.4).
#[must_use]
pub fn normal_incidence_reflectance(eta: f64) -> f64 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}

/// The n-th Fresnel moment ∫₀¹ F_r(μ, η) μⁿ dμ (μ = cos θ on the incident side, η = n_t / n_i).
///
/// 2·moment(1, η) is the hemispherical (cosine-weighted) reflectance for diffuse light; with η = 1.4
/// it is the external one, ≈ 0.078, so the BSSRDF's S_ω normalisation is c = 1 − 2·moment(1, 1.4)
/// (pbrt-v3 writes this as 1 − 2 F̄₁(1/η) in its own index convention). Composite Simpson,
/// split at the critical angle where F_r has a kink; accurate to about 1e-6 (the square-root kink at the critical angle limits Simpson).
#[must_use]
pub fn fresnel_moment(n: i32, eta: f64) -> f64 {
    let f = |mu: f64| dielectric_reflectance(mu, eta) * mu.powi(n);
    // Below the critical cosine everything is reflected (eta < 1); integrate each smooth piece.
    let mu_c = if eta < 1.0 {
        (1.0 - eta * eta).sqrt()
    } else {
        0.0
    };
    simpson(f, 0.0, mu_c, 512) + simpson(f, mu_c, 1.0, 4096)
}

fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    if b <= a {
        return 0.0;
    }
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for i in 1..n {
        let x = a + h * i as f64;
        s += if i % 2 == 1 { 4.0 } else { 2.0 } * f(x);
    }
    s * h / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn normal_incidence_matches_closed_form() {
        assert_relative_eq!(
            dielectric_reflectance(1.0, 1.4),
            0.027_777_777_8,
            epsilon = 1e-9
        );
        assert_relative_eq!(
            normal_incidence_reflectance(1.4),
            0.027_777_777_8,
            epsilon = 1e-9
        );
    }

    #[test]
    fn f32_matches_f64() {
        for k in 0..=100 {
            let c = k as f32 / 100.0;
            for eta in [1.0f32, 1.4, 1.0 / 1.4, 3.0] {
                let a = f64::from(dielectric_reflectance_f32(c, eta));
                let b = dielectric_reflectance(f64::from(c), f64::from(eta));
                // f32 rounding, amplified by the square-root kink just above a critical angle (η < 1).
                let tol = if eta < 1.0 { 1e-5 } else { 1e-6 };
                assert!((a - b).abs() < tol, "cos = {c}, η = {eta}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn grazing_is_total_and_tir_beyond_critical_angle() {
        assert_relative_eq!(dielectric_reflectance(0.0, 1.4), 1.0, epsilon = 1e-12);
        // Inside skin (η = 1/1.4) the critical cosine is √(1 − 1/1.96) = 0.6999.
        assert_eq!(dielectric_reflectance(0.69, 1.0 / 1.4), 1.0);
        assert!(dielectric_reflectance(0.71, 1.0 / 1.4) < 1.0);
    }

    #[test]
    fn brewster_angle_zeroes_p_polarisation() {
        // At Brewster's angle tanθ = η the reflectance is half the s-term only: (cos-based check).
        let theta_b = 1.4f64.atan();
        let c = theta_b.cos();
        let ct = (1.0 - (1.0 - c * c) / 1.96).sqrt();
        let r_perp = (c - 1.4 * ct) / (c + 1.4 * ct);
        assert_relative_eq!(
            dielectric_reflectance(c, 1.4),
            0.5 * r_perp * r_perp,
            epsilon = 1e-12
        );
    }

    /// The first moment at η = 1.4 (light arriving from air) against an independent rule: 400-point
    /// Gauss–Legendre (`crate::quadrature`, exact to degree 799; F_r is analytic on [0, 1] for η > 1, so
    /// its error is below 1e-12) gives 0.038 405 77 (8 digits, rounding 3e-9). Simpson with 4096
    /// panels is within 1e-14 of it here (no kink for η > 1); 1e-8 covers the rounding.
    #[test]
    fn first_moment_matches_gauss_legendre() {
        let exact: f64 = crate::quadrature::gauss_legendre(400, 0.0, 1.0)
            .into_iter()
            .map(|(mu, w)| w * dielectric_reflectance(mu, 1.4) * mu)
            .sum();
        assert!((exact - 0.038_405_77).abs() < 1e-8, "{exact}");
        assert!((fresnel_moment(1, 1.4) - exact).abs() < 1e-8);
    }

    /// pbrt-v3's polynomial fit (`FresnelMoment1` in pbrt-v3's `core/bssrdf.cpp`, [pbrt], called with η = 1/1.4 in
    /// its convention) gives 0.45966 − 1.73965η + 3.37668η² − 3.904945η³ + 2.49277η⁴ − 0.68441η⁵ =
    /// 0.038 397 0 at η = 1/1.4. The fit's residual against the exact moment is 8.8e-6 here; 1.5e-5
    /// keeps a margin over that residual and fails on 0.0392 (8e-4 away).
    #[test]
    fn first_moment_matches_pbrt_fit() {
        assert!((fresnel_moment(1, 1.4) - 0.038_397_0).abs() < 1.5e-5);
    }

    /// Reciprocity of the interface for diffuse light (Stokes): the hemispherical transmittance from
    /// inside is η⁻² times the one from outside, 1 − 2·m1(1/η) = (1 − 2·m1(η)) / η². Simpson at the
    /// critical-angle square-root kink overestimates m1(1/1.4) by 3.6e-7 (against Gauss–Legendre
    /// after the substitution t = √(μ − μ_c)), 1.5e-6 relative here, so 5e-6 relative.
    #[test]
    fn diffuse_transmittance_is_reciprocal() {
        let inside = 1.0 - 2.0 * fresnel_moment(1, 1.0 / 1.4);
        let outside = 1.0 - 2.0 * fresnel_moment(1, 1.4);
        assert_relative_eq!(inside * 1.96, outside, max_relative = 5e-6);
    }
}
