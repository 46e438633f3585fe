//! Absorption spectra of skin's chromophores and the reduced scattering law, mm⁻¹ ([DJ06] eqs 2–4
//! and 6, and the blood table of eq. 5); `coefficients` mixes them into the layers.
//!
//! The only home of these laws in the workspace: everyone else calls them.
//!
//! Each equation's hand-computed check is its own test, spelled out with its printed constants, so
//! that a failure names the equation and a reader can redo the arithmetic.

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

/// Absorption, mm⁻¹, of a chromophore at `g_per_l` (g/L) with molar mass `g_per_mol` from its decadic
/// molar extinction ε in cm⁻¹/M ([Prahl]): σa = ln(10) · ε · c / M / 10.
#[must_use]
pub fn sigma_a_from_molar_extinction(
    epsilon_per_cm_per_molar: f64,
    g_per_l: f64,
    g_per_mol: f64,
) -> f64 {
    // Prahl's recipe uses 2.303 for ln 10; keep it so the check values match the published table.
    2.303 * epsilon_per_cm_per_molar * g_per_l / g_per_mol / 10.0
}

/// Whole-blood absorption, mm⁻¹, from a decadic molar extinction ε in cm⁻¹/M ([Prahl]):
/// σa = ln(10) · ε · 150 g/L / 64 500 g/mol / 10.
#[must_use]
pub fn blood_sigma_a_from_molar_extinction(epsilon_per_cm_per_molar: f64) -> f64 {
    sigma_a_from_molar_extinction(
        epsilon_per_cm_per_molar,
        BLOOD_HEMOGLOBIN_G_PER_L,
        HEMOGLOBIN_G_PER_MOL,
    )
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

/// Reduced scattering σs' = 14.74 λ^−0.22 + 2.2·10¹¹ λ^−4 (Mie + Rayleigh), mm⁻¹ ([DJ06] eq. 6).
#[must_use]
pub fn reduced_scattering(lambda: Wavelength) -> f64 {
    let l = lambda.nm();
    14.74 * l.powf(-0.22) + 2.2e11 * l.powi(-4)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::{rel, wl};

    // Hand-computed from the printed formulas (double precision, independent of this code):
    // e.g. eq. 2 at 400 nm: 6.6e10 · 400^−3.33 = 6.6e10 · e^(−3.33 · ln 400) = 142.78551898613...
    #[test]
    fn eumelanin_eq2_matches_hand_values() {
        assert!(rel(eumelanin_sigma_a(wl(400.0)), 142.785_518_986_134_4) < 1e-9);
        assert!(rel(eumelanin_sigma_a(wl(600.0)), 37.008_396_787_617_47) < 1e-9);
    }

    #[test]
    fn pheomelanin_eq3_matches_hand_values() {
        assert!(rel(pheomelanin_sigma_a(wl(400.0)), 126.652_287_788_074_02) < 1e-9);
        assert!(rel(pheomelanin_sigma_a(wl(600.0)), 18.457_783_964_937_395) < 1e-9);
    }

    #[test]
    fn baseline_eq4_matches_hand_values() {
        // 0.0244 + 8.53 e^(−246/66.2) and 0.0244 + 8.53 e^(−546/66.2).
        assert!(rel(baseline_sigma_a(wl(400.0)), 0.231_941_756_567_145_05) < 1e-9);
        assert!(rel(baseline_sigma_a(wl(700.0)), 0.026_633_590_770_620_816) < 1e-9);
    }

    #[test]
    fn reduced_scattering_eq6_matches_hand_values() {
        assert!(rel(reduced_scattering(wl(500.0)), 7.275_987_018_393_602) < 1e-9);
        assert!(rel(reduced_scattering(wl(700.0)), 4.404_280_371_335_495) < 1e-9);
    }

    /// docs/physics.md §1 check table (5 significant digits, so 1e-4 relative).
    #[test]
    fn physics_check_table() {
        let table = [
            (400.0, 142.79, 126.65, 0.2319, 12.539),
            (500.0, 67.916, 43.882, 0.07022, 7.276),
            (600.0, 37.008, 18.458, 0.03452, 5.306),
            (700.0, 22.150, 8.875, 0.02663, 4.404),
        ];
        for (nm, em, pm, base, s) in table {
            let l = wl(nm);
            assert!(rel(eumelanin_sigma_a(l), em) < 1e-4, "em {nm}");
            assert!(rel(pheomelanin_sigma_a(l), pm) < 1e-4, "pm {nm}");
            assert!(rel(baseline_sigma_a(l), base) < 2e-4, "base {nm}");
            assert!(rel(reduced_scattering(l), s) < 1e-4, "s' {nm}");
        }
    }

    #[test]
    fn blood_check_value_oxy_414() {
        // docs/physics.md §1 check value: ε(414) = 524 280 cm⁻¹/M gives 280.7946 mm⁻¹ with Prahl's
        // 2.303 for ln 10, 280.80 to the table's 5 digits.
        let v = oxyhemoglobin_sigma_a(wl(414.0));
        assert!((v - 280.80).abs() < 0.01, "{v}");
        assert!(rel(v, 2.303 * 524_280.0 * 150.0 / 64_500.0 / 10.0) < 1e-14);
    }

    #[test]
    fn hemoglobin_is_interpolated_linearly_between_table_rows() {
        // Rows 414 nm (524 280, 342 596) and 416 nm (521 880, 363 848) of Prahl's table.
        assert!(
            rel(
                oxyhemoglobin_molar_extinction(wl(415.0)),
                0.5 * (524_280.0 + 521_880.0)
            ) < 1e-14
        );
        assert!(
            rel(
                deoxyhemoglobin_molar_extinction(wl(414.5)),
                0.75 * 342_596.0 + 0.25 * 363_848.0
            ) < 1e-14
        );
        assert!(oxyhemoglobin_molar_extinction(wl(1000.0)) > 0.0);
        assert!(oxyhemoglobin_molar_extinction(wl(250.0)) > 0.0);
    }

    /// Wavelength of the largest value of `f` on [a, b] sampled every 0.5 nm.
    fn argmax(f: fn(Wavelength) -> f64, a: f64, b: f64) -> f64 {
        let n = ((b - a) / 0.5) as usize;
        (0..=n)
            .map(|i| a + 0.5 * i as f64)
            .max_by(|x, y| f(wl(*x)).total_cmp(&f(wl(*y))))
            .unwrap()
    }

    #[test]
    fn oxyhemoglobin_soret_peak_at_414nm() {
        let peak = argmax(oxyhemoglobin_sigma_a, 350.0, 500.0);
        assert!((peak - 414.0).abs() <= 2.0, "Soret peak at {peak} nm");
    }

    #[test]
    fn oxyhemoglobin_q_bands_near_542_and_577nm() {
        let alpha = argmax(oxyhemoglobin_sigma_a, 530.0, 560.0);
        let beta = argmax(oxyhemoglobin_sigma_a, 565.0, 590.0);
        assert!((alpha - 542.0).abs() <= 2.0, "Q band α at {alpha} nm");
        assert!((beta - 577.0).abs() <= 2.0, "Q band β at {beta} nm");
        // Both are true local maxima: the valley between them is lower than either.
        let valley = oxyhemoglobin_sigma_a(wl(560.0));
        assert!(valley < oxyhemoglobin_sigma_a(wl(alpha)));
        assert!(valley < oxyhemoglobin_sigma_a(wl(beta)));
    }

    #[test]
    fn deoxyhemoglobin_peak_431_to_433nm() {
        // Prahl's table has a flat top: 552 160 cm⁻¹/M at both 432 and 434 nm. The peak is that
        // plateau; its centre must lie in 431–433 nm.
        let max = deoxyhemoglobin_sigma_a(wl(argmax(deoxyhemoglobin_sigma_a, 350.0, 500.0)));
        let top: Vec<f64> = (0..=300)
            .map(|i| 350.0 + 0.5 * f64::from(i))
            .filter(|&nm| deoxyhemoglobin_sigma_a(wl(nm)) >= max * (1.0 - 1e-12))
            .collect();
        let (first, last) = (top[0], top[top.len() - 1]);
        assert_eq!((first, last), (432.0, 434.0));
        let centre = 0.5 * (first + last);
        assert!(
            (431.0..=433.0).contains(&centre),
            "deoxy peak at {centre} nm"
        );
    }
}
