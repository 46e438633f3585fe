//! A homogeneous scattering medium in the diffusion approximation: σa, σs' and the derived symbols
//! of docs/physics.md §2 ([JMLH01] §2, [DJ05] §2).

use crate::error::{MultipoleError, check_range};

/// Largest coefficient accepted, mm⁻¹ (far beyond any tissue; keeps exponentials finite).
pub const MAX_COEFFICIENT_PER_MM: f64 = 1.0e6;

/// Validated absorption and reduced scattering coefficients of one layer, mm⁻¹.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium {
    sigma_a: f64,
    sigma_s_prime: f64,
}

impl Medium {
    /// Medium from σa ≥ 0 and σs' ≥ 0 (mm⁻¹), with σt' = σa + σs' > 0 and both ≤ 1e6 mm⁻¹.
    pub fn new(sigma_a: f64, sigma_s_prime: f64) -> Result<Self, MultipoleError> {
        check_range(
            "σa (mm⁻¹)",
            sigma_a,
            0.0,
            MAX_COEFFICIENT_PER_MM,
            "[0, 1e6]",
        )?;
        check_range(
            "σs' (mm⁻¹)",
            sigma_s_prime,
            0.0,
            MAX_COEFFICIENT_PER_MM,
            "[0, 1e6]",
        )?;
        if sigma_a + sigma_s_prime <= 0.0 {
            return Err(MultipoleError::OutOfRange {
                name: "σt' = σa + σs' (mm⁻¹)",
                value: 0.0,
                range: "(0, 2e6]",
            });
        }
        Ok(Self {
            sigma_a,
            sigma_s_prime,
        })
    }

    /// From a layer's coefficients as `skin_optics` computes them.
    pub fn from_coefficients(c: &skin_optics::LayerCoefficients) -> Result<Self, MultipoleError> {
        Self::new(c.sigma_a, c.sigma_s_prime)
    }

    /// Absorption coefficient σa, mm⁻¹.
    #[must_use]
    pub fn sigma_a(&self) -> f64 {
        self.sigma_a
    }

    /// Reduced scattering coefficient σs', mm⁻¹.
    #[must_use]
    pub fn sigma_s_prime(&self) -> f64 {
        self.sigma_s_prime
    }

    /// Reduced extinction σt' = σa + σs', mm⁻¹.
    #[must_use]
    pub fn sigma_t_prime(&self) -> f64 {
        self.sigma_a + self.sigma_s_prime
    }

    /// Reduced albedo α' = σs'/σt', dimensionless.
    #[must_use]
    pub fn albedo_prime(&self) -> f64 {
        self.sigma_s_prime / self.sigma_t_prime()
    }

    /// Reduced mean free path ℓ = 1/σt', mm (depth of the real source in [JMLH01]).
    #[must_use]
    pub fn mean_free_path_mm(&self) -> f64 {
        1.0 / self.sigma_t_prime()
    }

    /// Diffusion coefficient D = 1/(3σt'), mm.
    #[must_use]
    pub fn diffusion_mm(&self) -> f64 {
        1.0 / (3.0 * self.sigma_t_prime())
    }

    /// Effective transport coefficient σtr = √(3 σa σt'), mm⁻¹.
    #[must_use]
    pub fn sigma_tr(&self) -> f64 {
        (3.0 * self.sigma_a * self.sigma_t_prime()).sqrt()
    }

    /// Extrapolation distance z_b = 2AD for boundary coefficient A, mm ([DJ05] eq. 6).
    #[must_use]
    pub fn extrapolation_mm(&self, a_boundary: f64) -> f64 {
        2.0 * a_boundary * self.diffusion_mm()
    }
}

/// The spatial kernel of one pole: z (1 + σtr ρ) e^(−σtr ρ) / ρ³ with ρ = √(r² + z²), mm⁻²
/// (−∂/∂z of e^(−σtr ρ)/ρ; [JMLH01] eq. 4). Signed with z; 0 when z = 0 and r > 0.
#[inline]
#[must_use]
pub fn pole_kernel(z: f64, r: f64, sigma_tr: f64) -> f64 {
    let rho2 = r * r + z * z;
    if rho2 == 0.0 {
        return 0.0;
    }
    let rho = rho2.sqrt();
    z * (1.0 + sigma_tr * rho) * (-sigma_tr * rho).exp() / (rho2 * rho)
}

/// The energy a pole kernel puts within radius r: ∫₀^r 2πr' kernel dr' / (2π)
/// = sgn(z) [e^(−σtr|z|) − |z| e^(−σtr ρ)/ρ], dimensionless (closed form: the integrand is
/// d/dr' of −|z| e^(−σtr ρ)/ρ).
#[must_use]
pub fn pole_energy_within(z: f64, r: f64, sigma_tr: f64) -> f64 {
    if z == 0.0 {
        return 0.0;
    }
    let za = z.abs();
    let rho = (r * r + z * z).sqrt();
    z.signum() * ((-sigma_tr * za).exp() - za * (-sigma_tr * rho).exp() / rho)
}

/// The 2D Fourier (order-0 Hankel) transform of the normalised pole kernel,
/// ∫ 2πr kernel(z, r) J0(qr) dr / (2π) = sgn(z) e^(−|z| s), s = √(σtr² + q²) ([DJ05] §5; docs/physics.md §5).
/// `sgn(0)` is +1: a source on the face transmits half its light as a delta.
#[inline]
#[must_use]
pub fn pole_transform(z: f64, s: f64) -> f64 {
    let e = (-z.abs() * s).exp();
    if z >= 0.0 { e } else { -e }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn derived_symbols() {
        let m = Medium::new(0.1, 1.0).unwrap();
        assert_relative_eq!(m.sigma_t_prime(), 1.1);
        assert_relative_eq!(m.albedo_prime(), 1.0 / 1.1);
        assert_relative_eq!(m.sigma_tr(), (3.0f64 * 0.1 * 1.1).sqrt());
        assert_relative_eq!(m.extrapolation_mm(1.0), 2.0 / 3.3);
    }

    #[test]
    fn rejects_bad_coefficients() {
        assert!(Medium::new(-0.1, 1.0).is_err());
        assert!(Medium::new(f64::NAN, 1.0).is_err());
        assert!(Medium::new(0.0, 0.0).is_err());
        let e = Medium::new(0.1, -2.0).unwrap_err().to_string();
        assert!(e.contains("σs'") && e.contains("-2"), "{e}");
    }

    #[test]
    fn kernel_energy_matches_quadrature() {
        // ∫ 2πr kernel dr / 2π from the closed form vs a fine midpoint rule in log r.
        let (z, s, rmax) = (0.3, 0.8, 5.0f64);
        let n = 200_000;
        let (a, b) = ((1e-6f64).ln(), rmax.ln());
        let h = (b - a) / n as f64;
        let mut sum = 0.0;
        for i in 0..n {
            let r = (a + (i as f64 + 0.5) * h).exp();
            sum += r * r * pole_kernel(z, r, s) * h;
        }
        assert_relative_eq!(sum, pole_energy_within(z, rmax, s), max_relative = 1e-6);
        // Whole plane: e^(−σtr z) = the transform at q = 0.
        assert_relative_eq!(
            pole_energy_within(z, 1e9, s),
            pole_transform(z, s),
            max_relative = 1e-9
        );
    }
}
