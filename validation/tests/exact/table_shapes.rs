//! The exact profile's default shape (the universal white-Monte-Carlo table, `ExactShape::Table`)
//! against a run-time layered Monte Carlo of the same skin, for random skins over the whole
//! parameter box (C_m ∈ [0, 0.5], β_m ∈ [0, 1], C_h ∈ [0.001, 0.1], epidermis 0.05–0.5 mm,
//! 400–700 nm), with a fixed proptest seed.
//!
//! Bound: energy-weighted error (`validation::shape_error`) ≤ 5% + 2 × the reference's own noise
//! term. The table's error against 10⁶-photon references is 0.7–2.3% for the presets (BENCHMARKS.md,
//! `## Exact profile table`); the reference here (≈ 30,000 escapes, ≤ 2·10⁶ photons) adds its
//! noise, of expected size `noise`, so a correct table stays well inside. Diffusion shapes miss by
//! 25–220%, so a fallback to them fails; so does a table read at the wrong depth or absorption.
//!
//! Each profile's total is the adding-doubling total (checked exactly: the table only shapes it).

use multipole::ProfileOptions;
use multipole::skin::{ExactShape, Method, ShapeTableOptions, exact_profile, total_reflectance};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use skin_optics::{SkinParams, Wavelength};
use validation::montecarlo::{DEFAULT_G, LayeredMedium, McOptions, RadialGrid, run};
use validation::shape_error::energy_error;

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 5,
        rng_seed: RngSeed::Fixed(0x7AB1E),
        ..ProptestConfig::default()
    })]

    #[test]
    #[cfg_attr(debug_assertions, ignore = "up to 2·10⁶ photons per case: run with --release")]
    fn table_shapes_match_the_run_time_monte_carlo(
        c_m in 0.0..=0.5f64, beta_m in 0.0..=1.0f64, c_h in 0.001..=0.1f64, nm in 400.0..=700.0f64,
        d_mm in 0.05..=0.5f64,
    ) {
        let skin = SkinParams::new(c_m, beta_m, c_h, 0.25)
            .and_then(|s| s.with_epidermis_thickness_mm(d_mm))
            .expect("valid skin");
        let lambda = Wavelength::new(nm).expect("visible");
        let shape = ExactShape::Table(ShapeTableOptions::default());
        let p = exact_profile(&skin, lambda, shape, &ProfileOptions::default()).expect("profile");
        let total = total_reflectance(&skin, lambda, Method::Exact).expect("total");
        prop_assert_eq!(p.total(), total);
        // The table is cut at the first node past 99.9% of the total, like the multipole tables.
        let held = p.table_integral() / total;
        prop_assert!((0.999 - 1e-9..=1.0 + 1e-9).contains(&held), "holds {}", held);
        let observable = multipole::skin::diffuse_reflectance(&skin, lambda, Method::Exact).expect("R");
        let photons = ((30_000.0 / observable) as u64).clamp(100_000, 2_000_000);
        let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G).expect("stack");
        let grid = RadialGrid::new(0.02, 300).expect("grid");
        let mc = run(&stack, &McOptions::new(photons, 16, 99).expect("options").with_grid(grid));
        let (err, noise) = energy_error(&p, &mc);
        prop_assert!(
            err <= 0.05 + 2.0 * noise,
            "C_m {} β_m {} C_h {} d {} mm {} nm: error {:.2}% (reference noise {:.2}%, {} photons)",
            c_m, beta_m, c_h, d_mm, nm, 100.0 * err, 100.0 * noise, photons
        );
    }
}
