//! The totals target of `Method::Exact` over the whole parameter box: for random skins (C_m ∈ [0, 0.5],
//! β_m ∈ [0, 1], C_h ∈ [0.001, 0.1]) and wavelengths in 400–700 nm, adding-doubling's observable
//! diffuse reflectance is within 2% of the layered Monte Carlo, plus 3 of its standard errors.
//!
//! Photons are chosen per case for about 20,000 escaping photons (≈ 0.7% relative noise), at most
//! 4·10⁶ (very dark skin in the blue reflects < 0.5%). Diffusion misses by 22–260% for C_m ≥ 0.05,
//! so a method that fell back to it would fail.

use multipole::Method;
use proptest::prelude::*;
use skin_optics::{SkinParams, Wavelength};
use validation::montecarlo::{DEFAULT_G, LayeredMedium, McOptions, run};

proptest! {
    #![proptest_config(ProptestConfig { cases: 6, ..ProptestConfig::default() })]

    #[test]
    #[cfg_attr(debug_assertions, ignore = "up to 4·10⁶ photons per case: run with --release")]
    fn exact_totals_within_two_percent_of_monte_carlo(
        c_m in 0.0..=0.5f64, beta_m in 0.0..=1.0f64, c_h in 0.001..=0.1f64, nm in 400.0..=700.0f64,
        seed in 1u64..1000,
    ) {
        let skin = SkinParams::new(c_m, beta_m, c_h, 0.25).expect("valid skin");
        let lambda = Wavelength::new(nm).expect("visible");
        let exact = multipole::skin::diffuse_reflectance(&skin, lambda, Method::Exact).expect("solves");
        let photons = ((20_000.0 / exact) as u64).clamp(50_000, 4_000_000);
        let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G).expect("stack");
        let mc = run(&stack, &McOptions::new(photons, 16, seed).expect("options")).diffuse_reflectance;
        let tol = 0.02 * mc.mean + 3.0 * mc.stderr;
        prop_assert!(
            (exact - mc.mean).abs() < tol,
            "C_m {} β_m {} C_h {} {} nm: exact {:.5} vs MC {:.5} ± {:.5} ({} photons)",
            c_m, beta_m, c_h, nm, exact, mc.mean, mc.stderr, photons
        );
    }
}
