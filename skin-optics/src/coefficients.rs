//! Both layers' absorption and reduced scattering from a skin's parameters, mm⁻¹: the chromophores'
//! spectra (`chromophores`) mixed by [DJ06] eqs 1 and 5, and eq. 6 scattering, or the extended laws
//! of docs/physics.md §13 (`physiology`) when an extension is on.

use crate::chromophores::{
    baseline_sigma_a, deoxyhemoglobin_sigma_a, eumelanin_sigma_a, oxyhemoglobin_sigma_a,
    pheomelanin_sigma_a, reduced_scattering,
};
use crate::params::SkinParams;
use crate::physiology;
use crate::units::Wavelength;

/// Epidermis absorption σa_epi = C_m(β_m σa_em + (1−β_m) σa_pm) + (1−C_m) σa_base, mm⁻¹ ([DJ06] eq. 1).
#[must_use]
pub fn epidermis_sigma_a(skin: &SkinParams, lambda: Wavelength) -> f64 {
    let cm = skin.melanin();
    let bm = skin.eumelanin_blend();
    cm * (bm * eumelanin_sigma_a(lambda) + (1.0 - bm) * pheomelanin_sigma_a(lambda))
        + (1.0 - cm) * baseline_sigma_a(lambda)
}

/// Dermis absorption σa_derm = C_h(γ σa_oxy + (1−γ) σa_deoxy) + (1−C_h) σa_base, mm⁻¹ ([DJ06] eq. 5).
#[must_use]
pub fn dermis_sigma_a(skin: &SkinParams, lambda: Wavelength) -> f64 {
    let ch = skin.hemoglobin();
    let g = skin.oxygenation();
    ch * (g * oxyhemoglobin_sigma_a(lambda) + (1.0 - g) * deoxyhemoglobin_sigma_a(lambda))
        + (1.0 - ch) * baseline_sigma_a(lambda)
}

/// Absorption and reduced scattering of one homogeneous layer, mm⁻¹.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerCoefficients {
    /// Absorption coefficient σa, mm⁻¹.
    pub sigma_a: f64,
    /// Reduced scattering coefficient σs' = σs (1 − g), mm⁻¹.
    pub sigma_s_prime: f64,
}

/// The two layers of [DJ06] skin at one wavelength.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkinCoefficients {
    /// Wavelength these coefficients belong to.
    pub lambda: Wavelength,
    /// Epidermis: eq. 1 absorption, eq. 6 scattering.
    pub epidermis: LayerCoefficients,
    /// Dermis: eq. 5 absorption, eq. 6 scattering times the dermis scattering scale.
    pub dermis: LayerCoefficients,
}

impl SkinParams {
    /// Both layers' coefficients at one wavelength ([DJ06] eqs 1–6), mm⁻¹.
    #[must_use]
    pub fn coefficients(&self, lambda: Wavelength) -> SkinCoefficients {
        if !self.physiology().is_seed() {
            return self.extended_coefficients(lambda);
        }
        let s = reduced_scattering(lambda);
        SkinCoefficients {
            lambda,
            epidermis: LayerCoefficients {
                sigma_a: epidermis_sigma_a(self, lambda),
                sigma_s_prime: s,
            },
            dermis: LayerCoefficients {
                sigma_a: dermis_sigma_a(self, lambda),
                sigma_s_prime: s * self.dermis_scattering_scale(),
            },
        }
    }
}

impl SkinParams {
    /// [`SkinParams::coefficients`] with the extensions of docs/physics.md §13 (module
    /// `physiology`): blood in the epidermis, bilirubin in the dermis, scaled scattering terms.
    fn extended_coefficients(&self, lambda: Wavelength) -> SkinCoefficients {
        let x = self.physiology();
        let bm = self.eumelanin_blend();
        let melanin = bm * eumelanin_sigma_a(lambda) + (1.0 - bm) * pheomelanin_sigma_a(lambda);
        let s = physiology::reduced_scattering(&x, lambda);
        SkinCoefficients {
            lambda,
            epidermis: LayerCoefficients {
                sigma_a: physiology::epidermis_sigma_a(
                    melanin,
                    self.melanin(),
                    &x,
                    self.oxygenation(),
                    lambda,
                ),
                sigma_s_prime: s,
            },
            dermis: LayerCoefficients {
                sigma_a: dermis_sigma_a(self, lambda)
                    + physiology::dermis_extra_sigma_a(&x, lambda),
                sigma_s_prime: s * self.dermis_scattering_scale(),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{rel, wl};
    use proptest::prelude::*;

    #[test]
    fn no_melanin_gives_baseline_epidermis() {
        let skin = SkinParams::new(0.0, 0.37, 0.05, 0.25).unwrap();
        for nm in [250.0, 400.0, 555.5, 1000.0] {
            assert_eq!(epidermis_sigma_a(&skin, wl(nm)), baseline_sigma_a(wl(nm)));
        }
    }

    #[test]
    fn no_blood_gives_baseline_dermis() {
        let skin = SkinParams::new(0.2, 0.5, 0.0, 0.25).unwrap();
        for nm in [250.0, 414.0, 577.0, 1000.0] {
            assert_eq!(dermis_sigma_a(&skin, wl(nm)), baseline_sigma_a(wl(nm)));
        }
    }

    #[test]
    fn full_eumelanin_blend_ignores_pheomelanin() {
        let l = wl(450.0);
        let pure = SkinParams::new(1.0, 1.0, 0.01, 0.25).unwrap();
        assert!(rel(epidermis_sigma_a(&pure, l), eumelanin_sigma_a(l)) < 1e-15);
        let mixed = SkinParams::new(0.3, 1.0, 0.01, 0.25).unwrap();
        let expect = 0.3 * eumelanin_sigma_a(l) + 0.7 * baseline_sigma_a(l);
        assert!(rel(epidermis_sigma_a(&mixed, l), expect) < 1e-14);
        let pheo = SkinParams::new(1.0, 0.0, 0.01, 0.25).unwrap();
        assert!(rel(epidermis_sigma_a(&pheo, l), pheomelanin_sigma_a(l)) < 1e-15);
    }

    #[test]
    fn dermis_eq5_mixes_oxy_and_deoxy_by_gamma() {
        let l = wl(560.0);
        let skin = SkinParams::new(0.01, 0.5, 0.04, 0.25).unwrap();
        // Default γ = 0.7.
        let expect = 0.04 * (0.7 * oxyhemoglobin_sigma_a(l) + 0.3 * deoxyhemoglobin_sigma_a(l))
            + 0.96 * baseline_sigma_a(l);
        assert!(rel(dermis_sigma_a(&skin, l), expect) < 1e-14);
        let venous = skin.with_oxygenation(0.0).unwrap();
        let expect = 0.04 * deoxyhemoglobin_sigma_a(l) + 0.96 * baseline_sigma_a(l);
        assert!(rel(dermis_sigma_a(&venous, l), expect) < 1e-14);
    }

    #[test]
    fn coefficients_bundle_the_layer_laws() {
        let skin = SkinParams::preset(crate::Preset::Medium)
            .with_dermis_scattering_scale(0.5)
            .unwrap();
        let l = wl(633.0);
        let c = skin.coefficients(l);
        assert_eq!(c.lambda, l);
        assert_eq!(c.epidermis.sigma_a, epidermis_sigma_a(&skin, l));
        assert_eq!(c.dermis.sigma_a, dermis_sigma_a(&skin, l));
        assert_eq!(c.epidermis.sigma_s_prime, reduced_scattering(l));
        assert_eq!(c.dermis.sigma_s_prime, 0.5 * reduced_scattering(l));
    }

    /// The extended laws with every extension off reduce to eqs 1–6 exactly: `coefficients` takes
    /// the seed path then, and the extended path would give the same bits.
    #[test]
    fn extended_path_with_everything_off_is_bit_identical() {
        for preset in crate::Preset::ALL {
            let skin = SkinParams::preset(preset)
                .with_oxygenation(0.83)
                .unwrap()
                .with_dermis_scattering_scale(0.5)
                .unwrap();
            for i in 0..=60 {
                let l = wl(400.0 + 5.0 * f64::from(i));
                assert_eq!(
                    skin.extended_coefficients(l),
                    skin.coefficients(l),
                    "{preset} {l:?}"
                );
            }
        }
    }

    proptest! {
        #[test]
        fn all_coefficients_finite_and_positive(
            cm in 0.0..=1.0f64, bm in 0.0..=1.0f64, ch in 0.0..=1.0f64, rho in 0.0..=1.0f64,
            gamma in 0.0..=1.0f64, d in 1e-3..=10.0f64, eta in 1.0..=3.0f64, scale in 1e-3..=4.0f64,
            nm in 250.0..=1000.0f64,
        ) {
            let skin = SkinParams::new(cm, bm, ch, rho).unwrap()
                .with_oxygenation(gamma).unwrap()
                .with_epidermis_thickness_mm(d).unwrap()
                .with_eta(eta).unwrap()
                .with_dermis_scattering_scale(scale).unwrap();
            let c = skin.coefficients(wl(nm));
            for v in [c.epidermis.sigma_a, c.epidermis.sigma_s_prime, c.dermis.sigma_a, c.dermis.sigma_s_prime] {
                prop_assert!(v.is_finite() && v > 0.0, "{v} at {nm} nm");
            }
        }
    }
}
