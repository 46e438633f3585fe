//! Agreement with independent exact-transport totals ([XT]: other Monte Carlo and adding-doubling
//! runs of the same model; index 1.4, g = 0.9, σs = σs'/(1 − g)).
//!
//! Tolerance: 4 standard errors of this run (a false-failure rate of 6e-5 per row for Gaussian batch
//! means) plus the reference's stated ±0.0008 (the skin rows) or its last printed digit (the
//! half-space rows). At these photon counts that is 1.1–3.4% of R_d in release builds (3.5–11% in
//! debug builds, which trace a tenth of the photons): a bias fails when it exceeds that, not below.

use super::photons;
use skin_optics::{Preset, SkinParams, Wavelength};
use validation::montecarlo::{Layer, LayeredMedium, McOptions, McResult, run};

fn check(r: &McResult, reference: f64, reference_uncertainty: f64, what: &str) {
    let rd = r.diffuse_reflectance;
    let tol = 4.0 * rd.stderr + reference_uncertainty;
    assert!(
        (rd.mean - reference).abs() < tol,
        "{what}: MC {:.5} ± {:.5} vs reference {reference} (tolerance {tol:.5})",
        rd.mean,
        rd.stderr
    );
    assert!((r.energy_total() - 1.0).abs() < 1e-10);
}

fn light_skin(nm: f64, n: u64, seed: u64) -> McResult {
    let stack = LayeredMedium::skin(
        &SkinParams::preset(Preset::Light),
        Wavelength::new(nm).unwrap(),
        0.9,
    )
    .unwrap();
    run(&stack, &McOptions::new(photons(n), 20, seed).unwrap())
}

#[test]
fn light_skin_450_nm() {
    check(
        &light_skin(450.0, 100_000, 450),
        0.4095,
        0.0008,
        "light 450 nm",
    );
}

#[test]
fn light_skin_550_nm() {
    check(
        &light_skin(550.0, 100_000, 550),
        0.4370,
        0.0008,
        "light 550 nm",
    );
}

#[test]
fn light_skin_650_nm() {
    check(
        &light_skin(650.0, 40_000, 650),
        0.6066,
        0.0008,
        "light 650 nm",
    );
}

fn half_space(sigma_a: f64, n: u64) -> McResult {
    let layer = Layer::from_reduced(sigma_a, 1.0, 0.9, 1.4, None).unwrap();
    let stack = LayeredMedium::new(vec![layer], 1.0, 1.0).unwrap();
    run(&stack, &McOptions::new(photons(n), 20, 17).unwrap())
}

#[test]
fn half_space_high_albedo() {
    let r = half_space(0.01, 30_000);
    assert!((r.specular_reflectance - 0.027_777_8).abs() < 1e-6);
    check(&r, 0.6040, 0.00005, "σa 0.01, σs' 1");
}

#[test]
fn half_space_low_albedo() {
    check(&half_space(0.5, 100_000), 0.0713, 0.00005, "σa 0.5, σs' 1");
}
