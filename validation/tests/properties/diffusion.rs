//! `multipole` against physics limits and against the Monte Carlo in the high-albedo regime.

use crate::montecarlo::photons;
use multipole::Method;
use multipole::diffusion::boundary::observable_reflectance;
use multipole::diffusion::{
    dipole::Dipole,
    medium::Medium,
    slab::{Poles, Slab},
};
use proptest::prelude::*;
use skin_optics::{SkinParams, Wavelength};
use validation::montecarlo::{Layer, LayeredMedium, McOptions, run};

#[test]
fn high_albedo_half_space_matches_the_dipole() {
    // Reduced albedo 0.99 (σa 0.01, σs' 0.99 mm⁻¹), η 1.4, g 0.9: diffusion's home ground. The
    // dipole's own bias here is about 1.2% ([XT]: 0.6040 exact against 0.597 for the dipole at
    // σs' = 1), so the bound is 1.5% for the model plus 4 standard errors of this run (20,000
    // photons in release, a tenth in debug builds).
    let (sigma_a, sigma_s_prime, eta) = (0.01, 0.99, 1.4);
    let dipole = Dipole::new(Medium::new(sigma_a, sigma_s_prime).unwrap(), eta).unwrap();
    let expected = observable_reflectance(dipole.total_reflectance(), eta);
    let layer = Layer::from_reduced(sigma_a, sigma_s_prime, 0.9, eta, None).unwrap();
    let stack = LayeredMedium::new(vec![layer], 1.0, 1.0).unwrap();
    let r = run(&stack, &McOptions::new(photons(20_000), 10, 99).unwrap());
    let rel = (r.diffuse_reflectance.mean - expected) / expected;
    let tol = 0.015 + 4.0 * r.diffuse_reflectance.stderr / expected;
    assert!(
        rel.abs() < tol,
        "MC {:?} vs dipole {expected}: {rel:+.4} (tolerance {tol:.4})",
        r.diffuse_reflectance
    );
}

#[test]
fn thick_slab_tends_to_the_dipole() {
    // Limit: a slab 200 transport mean free paths thick reflects like the half-space.
    let m = Medium::new(0.05, 1.0).unwrap();
    let slab = Slab::new(m, 200.0, 1.4, 1.0).unwrap();
    let dipole = Dipole::new(m, 1.4).unwrap();
    let (a, b) = (
        slab.total_reflectance(Poles::Exact),
        dipole.total_reflectance(),
    );
    assert!((a - b).abs() < 1e-9, "slab {a} vs dipole {b}");
}

/// A skin inside the paper's physical ranges: C_m in [0, 0.5], β_m in [0, 1], C_h in [0.001, 0.1].
fn skin() -> impl Strategy<Value = SkinParams> {
    (0.0..0.5f64, 0.0..1.0f64, 0.001..0.1f64)
        .prop_map(|(cm, bm, ch)| SkinParams::new(cm, bm, ch, 0.25).expect("valid ranges"))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn diffusion_reflectance_is_a_fraction(skin in skin(), nm in 400.0..700.0f64) {
        let lambda = Wavelength::new(nm).unwrap();
        for method in [Method::Multipole, Method::Exact] {
            let r = multipole::skin::total_reflectance(&skin, lambda, method).unwrap();
            prop_assert!(r > 0.0 && r <= 1.0, "{method} R = {r}");
            let obs = multipole::skin::diffuse_reflectance(&skin, lambda, method).unwrap();
            prop_assert!(obs <= r && obs > 0.0);
        }
    }

    #[test]
    fn monte_carlo_skin_conserves_energy(skin in skin(), nm in 400.0..700.0f64, seed in any::<u64>()) {
        let stack = LayeredMedium::skin(&skin, Wavelength::new(nm).unwrap(), 0.9).unwrap();
        let r = run(&stack, &McOptions::new(100, 2, seed).unwrap());
        prop_assert!((r.energy_total() - 1.0).abs() < 1e-10);
        prop_assert_eq!(r.transmittance.mean, 0.0);
    }
}
