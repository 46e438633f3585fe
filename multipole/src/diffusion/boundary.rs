//! Boundary conditions of diffusion at a refractive face: the diffuse Fresnel reflectance fit F_dr(η),
//! the boundary coefficient A(η), and the observable conversion (1 − F_r(0)) R_d.
//!
//! η is always n_inside / n_outside across the face, seen from the scattering medium.

/// Diffuse (hemispherically averaged) Fresnel reflectance F_dr(η), dimensionless ([JMLH01] §2.4,
/// the polynomial fit of Egan & Hilgeman):
/// η ≥ 1: −1.440/η² + 0.710/η + 0.668 + 0.0636 η; η < 1: −0.4399 + 0.7099/η − 0.3319/η² + 0.0636/η³.
///
/// Note the fit gives F_dr(1) = 0.0016, not 0: [`a_coefficient`] treats η = 1 exactly.
#[must_use]
pub fn fresnel_diffuse_reflectance(eta: f64) -> f64 {
    if eta >= 1.0 {
        -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta
    } else {
        -0.4399 + 0.7099 / eta - 0.3319 / (eta * eta) + 0.0636 / (eta * eta * eta)
    }
}

/// Boundary coefficient A = (1 + F_dr)/(1 − F_dr), dimensionless ([JMLH01] eq. 5; A(1.4) = 3.2507).
///
/// An index-matched face (η = 1 exactly) returns A = 1: there is no internal reflection, and the
/// fit's residual F_dr(1) = 0.0016 would otherwise give a spurious 1.0032.
#[must_use]
pub fn a_coefficient(eta: f64) -> f64 {
    if eta == 1.0 {
        return 1.0;
    }
    let f = fresnel_diffuse_reflectance(eta);
    (1.0 + f) / (1.0 - f)
}

/// The observable diffuse reflectance per unit *incident* flux at normal incidence, specular excluded:
/// (1 − F_r(0)) R_d, from the model's R_d per unit flux *entering* ([DJ06]; docs/physics.md §1).
/// F_r(0) comes from the exact Fresnel law in `brdf::fresnel` (0.0278 at η = 1.4).
#[must_use]
pub fn observable_reflectance(model_total: f64, eta: f64) -> f64 {
    (1.0 - brdf::fresnel::normal_incidence_reflectance(eta)) * model_total
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn a_at_skin_index_matches_physics_md() {
        // docs/physics.md §2: A(1.4) = 3.2507.
        assert_relative_eq!(a_coefficient(1.4), 3.2507, max_relative = 2e-5);
    }

    #[test]
    fn matched_face_has_a_exactly_one() {
        assert_eq!(a_coefficient(1.0), 1.0);
        // The fit itself is slightly off at 1 (docs/physics.md §2: 0.0016).
        assert_relative_eq!(fresnel_diffuse_reflectance(1.0), 0.0016, epsilon = 1e-4);
    }

    #[test]
    fn fit_is_continuous_and_a_increases_with_mismatch() {
        // Both branches meet near η = 1 (within the fit's 0.0016 residual on the upper branch).
        assert!(
            (fresnel_diffuse_reflectance(1.0 - 1e-9) - fresnel_diffuse_reflectance(1.0)).abs()
                < 3e-3
        );
        assert!(a_coefficient(1.4) > a_coefficient(1.2));
        // Inside a lower-index medium (η < 1) there is no total internal reflection: A near 1.
        assert!(a_coefficient(1.0 / 1.4) > 0.9 && a_coefficient(1.0 / 1.4) < 1.3);
    }

    #[test]
    fn observable_uses_normal_incidence_fresnel() {
        assert_relative_eq!(
            observable_reflectance(1.0, 1.4),
            1.0 - 0.027_777_777_8,
            epsilon = 1e-9
        );
    }
}
