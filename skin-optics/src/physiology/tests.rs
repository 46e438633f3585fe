use super::*;
use crate::test_util::{rel, wl};
use crate::{Preset, SkinParams};

#[test]
fn bilirubin_peaks_at_the_scaled_55000_near_451nm() {
    // [AF90] scaling: 55 000 cm⁻¹/M at 450.8 nm. The 2-nm means of the noisy 0.25-nm samples
    // stay within 1 % of it over 448–456 nm (the band's flat top), and the maximum lies there.
    let (mut best, mut at) = (0.0, 0.0);
    for i in 0..=200 {
        let nm = 400.0 + 0.5 * f64::from(i);
        let e = bilirubin_molar_extinction(wl(nm));
        if e > best {
            (best, at) = (e, nm);
        }
    }
    assert!((448.0..=456.0).contains(&at), "peak at {at} nm");
    assert!(rel(best, 55_000.0) < 0.01, "peak {best}");
    assert!(rel(bilirubin_molar_extinction(wl(450.0)), 55_000.0) < 0.01);
    // No absorption worth the name in the red (the table's noise floor is ~100 cm⁻¹/M).
    assert!(bilirubin_molar_extinction(wl(650.0)) < 200.0);
    assert_eq!(bilirubin_molar_extinction(wl(800.0)), 0.0);
}

#[test]
fn bilirubin_absorption_follows_the_molar_recipe() {
    // 0.01 g/L at 450 nm: 2.303 · ε · 0.01 / 584.66 / 10 mm⁻¹.
    let e = bilirubin_molar_extinction(wl(450.0));
    let expect = 2.303 * e * 0.01 / 584.66 / 10.0;
    assert!(rel(bilirubin_sigma_a(wl(450.0), 0.01), expect) < 1e-14);
}

#[test]
fn epidermis_blood_takes_the_baseline_share() {
    let l = wl(414.0);
    let skin = SkinParams::preset(Preset::Medium);
    let x = Physiology::SEED
        .with(Extension::EpidermisBlood, 0.02)
        .unwrap();
    let plain = skin.coefficients(l).epidermis.sigma_a;
    let with = skin.with_physiology(x).coefficients(l).epidermis.sigma_a;
    let gamma = skin.oxygenation();
    let expect = plain + 0.02 * (blood_sigma_a(l, gamma) - baseline_sigma_a(l));
    assert!(rel(with, expect) < 1e-13, "{with} vs {expect}");
    // The Soret band: 2 % blood adds ~5.6 mm⁻¹ at 414 nm, more than the medium skin's melanin.
    assert!(with - plain > 5.0, "{}", with - plain);
}

#[test]
fn scattering_scales_multiply_their_own_term() {
    let l = wl(500.0);
    let mie = 14.74 * 500f64.powf(-0.22);
    let ray = 2.2e11 * 500f64.powi(-4);
    let x = Physiology::SEED
        .with(Extension::MieScale, 2.0)
        .unwrap()
        .with(Extension::RayleighScale, 0.5)
        .unwrap();
    let skin = SkinParams::default().with_physiology(x);
    let c = skin.coefficients(l);
    assert!(rel(c.epidermis.sigma_s_prime, 2.0 * mie + 0.5 * ray) < 1e-14);
    assert_eq!(c.dermis.sigma_s_prime, c.epidermis.sigma_s_prime);
}

#[test]
fn bilirubin_adds_to_the_dermis_only() {
    let l = wl(460.0);
    let skin = SkinParams::default();
    let x = Physiology::SEED.with(Extension::Bilirubin, 0.1).unwrap();
    let (a, b) = (
        skin.coefficients(l),
        skin.with_physiology(x).coefficients(l),
    );
    assert_eq!(a.epidermis, b.epidermis);
    assert!(
        rel(
            b.dermis.sigma_a - a.dermis.sigma_a,
            bilirubin_sigma_a(l, 0.1)
        ) < 1e-10
    );
}

#[test]
fn extensions_report_their_state_and_reject_bad_values() {
    assert!(Physiology::default().is_seed());
    assert!(Physiology::SEED.active().is_empty());
    let x = Physiology::SEED.with(Extension::MieScale, 1.2).unwrap();
    assert_eq!(x.active(), vec![Extension::MieScale]);
    assert_eq!(x.get(Extension::MieScale), 1.2);
    for e in Extension::ALL {
        assert_eq!(Physiology::SEED.get(e), e.off_value());
        let [lo, hi] = e.physiological_range();
        assert!(lo <= e.off_value() && e.off_value() <= hi, "{}", e.name());
        assert!(Physiology::SEED.with(e, f64::NAN).is_err());
        assert!(Physiology::SEED.with(e, -0.1).is_err());
        assert!(Physiology::SEED.with(e, 11.0).is_err());
    }
    let err = Physiology::SEED
        .with(Extension::RayleighScale, 0.0)
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "Rayleigh scattering scale = 0 outside (0, 10]"
    );
}
