//! Cases with exact answers: clear slabs, Fresnel multiple reflection, no-absorption slabs.
//!
//! Each case builds its layers and calls the transport in full (as the Monte Carlo's own unit tests
//! do), so that a reader sees the whole physical setup beside the closed form it must meet.

use super::photons;
use brdf::fresnel::normal_incidence_reflectance;
use validation::montecarlo::{Layer, LayeredMedium, McOptions, McResult, run};

/// `layer` alone between index 1 above and `n_below` below, traced with `photons` in `batches`.
fn one_slab(layer: Layer, n_below: f64, photons: u64, batches: u32, seed: u64) -> McResult {
    let stack = LayeredMedium::new(vec![layer], 1.0, n_below).unwrap();
    run(&stack, &McOptions::new(photons, batches, seed).unwrap())
}

#[test]
fn absorbing_clear_slab_transmits_beer_lambert() {
    // σs = 0, matched indices: the beam goes straight, T = e^(−σa d) (binomial noise).
    let (sigma_a, d) = (1.0, 0.7);
    let r = one_slab(
        Layer::slab(sigma_a, 0.0, 0.0, 1.0, d).unwrap(),
        1.0,
        photons(200_000),
        20,
        7,
    );
    let exact = (-sigma_a * d).exp();
    let z = r.transmittance.z_score(exact);
    assert!(
        z.abs() < 4.0,
        "T {:?} vs e^-σd {exact}: z = {z}",
        r.transmittance
    );
    assert_eq!(r.diffuse_reflectance.mean, 0.0);
    assert!((r.energy_total() - 1.0).abs() < 1e-12);
}

#[test]
fn glass_slab_reflects_two_r_over_one_plus_r() {
    // A clear, non-absorbing slab of index 1.5 in air: incoherent multiple reflection gives
    // R = 2 R₁ / (1 + R₁) at normal incidence, R₁ = F_r(0).
    let r = one_slab(
        Layer::slab(0.0, 0.0, 0.0, 1.5, 1.0).unwrap(),
        1.0,
        photons(200_000),
        20,
        3,
    );
    let r1 = normal_incidence_reflectance(1.5);
    let exact_r = 2.0 * r1 / (1.0 + r1);
    assert!((r.specular_reflectance - r1).abs() < 1e-15);
    let z = r.diffuse_reflectance.z_score(exact_r - r1);
    assert!(
        z.abs() < 4.0,
        "R_d {:?} vs {}: z = {z}",
        r.diffuse_reflectance,
        exact_r - r1
    );
    assert!((r.transmittance.mean + r.diffuse_reflectance.mean + r1 - 1.0).abs() < 1e-12);
}

#[test]
fn non_absorbing_matched_slab_loses_no_energy() {
    // No absorption and matched indices: every photon leaves by the top or the bottom, with its
    // full weight (roulette never fires because the weight never falls).
    let stack = LayeredMedium::new(
        vec![
            Layer::slab(0.0, 5.0, 0.8, 1.0, 0.5).unwrap(),
            Layer::slab(0.0, 20.0, 0.0, 1.0, 1.0).unwrap(),
        ],
        1.0,
        1.0,
    )
    .unwrap();
    let r = run(&stack, &McOptions::new(photons(20_000), 8, 11).unwrap());
    assert_eq!(r.specular_reflectance, 0.0);
    assert_eq!(r.roulette_balance, 0.0);
    assert_eq!(r.absorbed.mean, 0.0);
    let sum = r.diffuse_reflectance.mean + r.transmittance.mean;
    assert!((sum - 1.0).abs() < 1e-12, "R_d + T = {sum}");
    // The radial tally holds all of R_d.
    let radial: f64 = (0..r.radial.grid.bins())
        .map(|i| r.radial.reflectance_per_mm2[i] * r.radial.grid.annulus_area_mm2(i))
        .sum::<f64>()
        + r.radial.beyond_grid;
    assert!(
        (radial - r.diffuse_reflectance.mean).abs() < 1e-9,
        "{radial}"
    );
}

#[test]
fn non_absorbing_mismatched_slab_loses_no_energy() {
    let r = one_slab(
        Layer::slab(0.0, 10.0, 0.9, 1.4, 1.0).unwrap(),
        1.33,
        photons(20_000),
        8,
        5,
    );
    let sum = r.specular_reflectance + r.diffuse_reflectance.mean + r.transmittance.mean;
    assert!((sum - 1.0).abs() < 1e-12, "R_spec + R_d + T = {sum}");
}

#[test]
fn van_de_hulst_slab() {
    // Albedo 0.9, g 0.75, optical thickness 2, matched indices: van de Hulst's tables give
    // R = 0.09739, T = 0.66096 ([WJZ95] Table 2 uses this case to check MCML).
    let r = one_slab(
        Layer::slab(1.0, 9.0, 0.75, 1.0, 0.2).unwrap(),
        1.0,
        photons(200_000),
        20,
        21,
    );
    let zr = r.diffuse_reflectance.z_score(0.09739);
    let zt = r.transmittance.z_score(0.66096);
    assert!(
        zr.abs() < 4.0 && zt.abs() < 4.0,
        "R {:?} (z {zr}), T {:?} (z {zt})",
        r.diffuse_reflectance,
        r.transmittance
    );
}
