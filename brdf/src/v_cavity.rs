//! Torrance–Sparrow V-cavity geometric attenuation ([TS67]; docs/physics.md §7).
//!
//! The surface is modelled as symmetric V-grooves, each made of a facet with normal h and its mirror
//! image about the macro-normal. Light to or from direction v is blocked by the opposite facet; the
//! unblocked fraction of the facet is G₁(v, h) = min(1, 2 (n·h)(n·v) / (v·h)), and the bidirectional
//! term is G(ωo, ωi) = min(1, G₁(ωo, h), G₁(ωi, h)), the formula of docs/physics.md §7 (with
//! ωi·h = ωo·h for the half-vector h). G is symmetric in ωo and ωi, so the BRDF is reciprocal.

use crate::real::Real;

/// One-direction V-cavity term G₁(v, h) = min(1, 2 cosθh cosθv / (v·h)), dimensionless; 0 when h
/// faces away from v (`v_dot_h` ≤ 0).
pub(crate) fn g1<T: Real>(cos_theta_h: T, cos_theta_v: T, v_dot_h: T) -> T {
    if v_dot_h > T::ZERO {
        (T::TWO * cos_theta_h * cos_theta_v / v_dot_h).min(T::ONE)
    } else {
        T::ZERO
    }
}

/// Bidirectional V-cavity term G(ωo, ωi) = min(1, G₁(ωo), G₁(ωi)), dimensionless, for the half-vector
/// cosine `cos_theta_h`, the two direction cosines and the common `o_dot_h` = ωo·h = ωi·h.
pub(crate) fn g<T: Real>(cos_theta_h: T, cos_theta_o: T, cos_theta_i: T, o_dot_h: T) -> T {
    g1(cos_theta_h, cos_theta_o, o_dot_h).min(g1(cos_theta_h, cos_theta_i, o_dot_h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unshadowed_at_normal_incidence_and_symmetric() {
        // h = n and ωo = ωi = n: G₁ = 2, clipped to 1.
        assert_eq!(g(1.0f64, 1.0, 1.0, 1.0), 1.0);
        // Symmetry in the two directions.
        assert_eq!(g(0.9f64, 0.2, 0.7, 0.5), g(0.9f64, 0.7, 0.2, 0.5));
        // Grazing: G₁ → 2 cosθh cosθv/(v·h) → 0 as cosθv → 0.
        assert_eq!(g1(0.9f64, 0.0, 0.5), 0.0);
        assert!((g1(0.9f64, 0.1, 0.5) - 0.36).abs() < 1e-12);
        assert_eq!(g1(0.9f64, 0.1, -0.5), 0.0);
    }
}
