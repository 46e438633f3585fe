use super::*;
use std::sync::OnceLock;

/// A small table (40,000 photons, so the tests stay cheap) shared by the tests below.
fn table() -> &'static ShapeTable {
    static T: OnceLock<ShapeTable> = OnceLock::new();
    T.get_or_init(|| {
        let opts = ShapeTableOptions {
            photons: 40_000,
            ..ShapeTableOptions::default()
        };
        ShapeTable::build(0.9, 1.4, &opts, 2, |_| {}).expect("valid knobs")
    })
}

/// Reflectance per entering photon: Σ annuli mean × area (scattering lengths).
fn total(t: &ShapeTable, a1: f64, a2: f64, tau: f64) -> f64 {
    let shape = t.shape(a1, a2, tau).expect("covered");
    shape
        .iter()
        .enumerate()
        .map(|(i, v)| v * t.r_axis.annulus_area(i))
        .sum()
}

#[test]
#[cfg_attr(debug_assertions, ignore = "40,000 white photons: run with --release")]
fn reweighted_white_histories_reproduce_the_half_space_references() {
    // [validation]'s exact references (observable, per incident photon, ±0.0008): half-space
    // σs' 1 mm⁻¹, g 0.9 (σs 10), n 1.4, σa 0.01 → 0.6040 and σa 0.5 → 0.0713. Equal absorption
    // in both layers is a half-space at any depth of the ladder. Per entering photon: ÷ (1 − F(0)),
    // F(0) = (0.4/2.4)². Tolerance 2%: 4 standard errors of 40,000 histories (binomial-like
    // spread of the weights, ≤ 0.5% relative) plus the references' ±0.13–1.1%.
    let enter = 1.0 - (0.4f64 / 2.4).powi(2);
    for (sigma_a, reference) in [(0.01, 0.6040), (0.5, 0.0713)] {
        let alpha = sigma_a / 10.0;
        for tau in [2.0, 30.0] {
            let r = total(table(), alpha, alpha, tau) * enter;
            assert!(
                (r / reference - 1.0).abs() < 0.02,
                "σa {sigma_a}, depth {tau}: {r:.5} vs {reference}"
            );
        }
    }
}

#[test]
#[cfg_attr(debug_assertions, ignore = "40,000 white photons: run with --release")]
fn absorption_below_the_depth_only_dims_what_reaches_it() {
    let t = table();
    // A thicker top layer over a more absorbing bottom reflects more (less light reaches the
    // absorber); over a less absorbing one, less. Same histories, so no noise in the comparison.
    let (top, absorbing, clear) = (0.01, 0.2, 0.001);
    assert!(total(t, top, absorbing, 20.0) > total(t, top, absorbing, 4.0));
    assert!(total(t, top, clear, 20.0) < total(t, top, clear, 4.0));
    // An opaque top layer: the bottom does not matter.
    let a = total(t, 3.0, 0.001, 16.0);
    let b = total(t, 3.0, 1.0, 16.0);
    assert!((a / b - 1.0).abs() < 1e-6, "{a} vs {b}");
}

#[test]
fn outside_the_table_is_none_and_bad_knobs_are_errors() {
    let t = ShapeTable::empty(0.9, 1.4, ShapeTableOptions::default());
    assert!(t.shape(0.01, 0.01, TABLE_TAU_MIN * 0.5).is_none());
    assert!(t.shape(0.01, 0.01, TABLE_TAU_MAX * 2.0).is_none());
    assert!(t.shape(TABLE_MIN_ALPHA * 0.5, 0.01, 10.0).is_none());
    assert!(t.shape(0.01, f64::NAN, 10.0).is_none());
    let bad = ShapeTableOptions {
        photons: 10,
        ..ShapeTableOptions::default()
    };
    let e = ShapeTable::build(0.9, 1.4, &bad, 1, |_| {}).unwrap_err();
    assert!(e.to_string().contains("table photons"), "{e}");
    assert!(ShapeTable::build(1.0, 1.4, &ShapeTableOptions::default(), 1, |_| {}).is_err());
}

#[test]
#[cfg_attr(debug_assertions, ignore = "40,000 white photons: run with --release")]
fn profile_carries_the_given_total_and_same_bits_on_any_thread_count() {
    let t = table();
    let p = t.profile(60.0, 0.5, 0.05, 0.25, 0.3).unwrap().unwrap();
    assert_eq!(p.total(), 0.3);
    assert!((0.999..=1.0).contains(&(p.table_integral() / 0.3 + 1e-12)));
    // Fixed-point sums: one thread gives the same table as two.
    let opts = ShapeTableOptions {
        photons: 10_000,
        ..ShapeTableOptions::default()
    };
    let one = ShapeTable::build(0.9, 1.4, &opts, 1, |_| {}).unwrap();
    let two = ShapeTable::build(0.9, 1.4, &opts, 2, |_| {}).unwrap();
    assert!(one == two);
}
