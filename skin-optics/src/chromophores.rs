//! Absorption and reduced scattering of skin's chromophores, mm⁻¹ ([DJ06] eqs 1–6).
//!
//! The only home of these laws in the workspace: everyone else calls them.

use crate::params::SkinParams;
use crate::table::UniformTable;
use crate::units::Wavelength;
use std::sync::OnceLock;

/// Hemoglobin concentration of whole blood, g/L ([Prahl]: 150 g/L).
pub const BLOOD_HEMOGLOBIN_G_PER_L: f64 = 150.0;
/// Molar mass of hemoglobin, g/mol ([Prahl]: 64 500 g/mol).
pub const HEMOGLOBIN_G_PER_MOL: f64 = 64_500.0;

/// Eumelanin absorption σa_em = 6.6·10¹⁰ λ^−3.33, mm⁻¹ ([DJ06] eq. 2).
#[must_use]
pub fn eumelanin_sigma_a(lambda: Wavelength) -> f64 {
    6.6e10 * lambda.nm().powf(-3.33)
}

/// Pheomelanin absorption σa_pm = 2.9·10¹⁴ λ^−4.75, mm⁻¹ ([DJ06] eq. 3; the seed's "2.9 × 10^1 4").
#[must_use]
pub fn pheomelanin_sigma_a(lambda: Wavelength) -> f64 {
    2.9e14 * lambda.nm().powf(-4.75)
}

/// Baseline skin absorption σa_base = 0.0244 + 8.53 e^−(λ−154)/66.2, mm⁻¹ ([DJ06] eq. 4).
#[must_use]
pub fn baseline_sigma_a(lambda: Wavelength) -> f64 {
    0.0244 + 8.53 * (-(lambda.nm() - 154.0) / 66.2).exp()
}

fn hemoglobin_table() -> &'static UniformTable {
    static TABLE: OnceLock<UniformTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        UniformTable::parse(include_str!("../data/hemoglobin_molar_extinction.csv"))
    })
}

/// Whole-blood absorption, mm⁻¹, from a decadic molar extinction ε in cm⁻¹/M ([Prahl]):
/// σa = ln(10) · ε · 150 g/L / 64 500 g/mol / 10.
#[must_use]
pub fn blood_sigma_a_from_molar_extinction(epsilon_per_cm_per_molar: f64) -> f64 {
    // Prahl's recipe uses 2.303 for ln 10; keep it so the check values match the published table.
    2.303 * epsilon_per_cm_per_molar * BLOOD_HEMOGLOBIN_G_PER_L / HEMOGLOBIN_G_PER_MOL / 10.0
}

/// Molar extinction of oxy-hemoglobin, cm⁻¹/M decadic, linearly interpolated in Prahl's 2-nm table.
#[must_use]
pub fn oxyhemoglobin_molar_extinction(lambda: Wavelength) -> f64 {
    hemoglobin_table().lerp(0, lambda.nm())
}

/// Molar extinction of deoxy-hemoglobin, cm⁻¹/M decadic, linearly interpolated in Prahl's 2-nm table.
#[must_use]
pub fn deoxyhemoglobin_molar_extinction(lambda: Wavelength) -> f64 {
    hemoglobin_table().lerp(1, lambda.nm())
}

/// Absorption of fully oxygenated whole blood σa_oxy, mm⁻¹ ([Prahl], used in [DJ06] eq. 5).
#[must_use]
pub fn oxyhemoglobin_sigma_a(lambda: Wavelength) -> f64 {
    blood_sigma_a_from_molar_extinction(oxyhemoglobin_molar_extinction(lambda))
}

/// Absorption of fully deoxygenated whole blood σa_deoxy, mm⁻¹ ([Prahl], used in [DJ06] eq. 5).
#[must_use]
pub fn deoxyhemoglobin_sigma_a(lambda: Wavelength) -> f64 {
    blood_sigma_a_from_molar_extinction(deoxyhemoglobin_molar_extinction(lambda))
}

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

/// Reduced scattering σs' = 14.74 λ^−0.22 + 2.2·10¹¹ λ^−4 (Mie + Rayleigh), mm⁻¹ ([DJ06] eq. 6).
#[must_use]
pub fn reduced_scattering(lambda: Wavelength) -> f64 {
    let l = lambda.nm();
    14.74 * l.powf(-0.22) + 2.2e11 * l.powi(-4)
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
