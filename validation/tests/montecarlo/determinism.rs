//! The same seed gives the same bits on any thread count; independent seeds agree statistically.

use super::photons;
use skin_optics::{Preset, SkinParams, Wavelength};
use validation::montecarlo::{DEFAULT_G, LayeredMedium, McOptions, run};

fn light_550() -> LayeredMedium {
    LayeredMedium::skin(
        &SkinParams::preset(Preset::Light),
        Wavelength::new(550.0).unwrap(),
        DEFAULT_G,
    )
    .unwrap()
}

#[test]
fn same_seed_same_bits_on_one_and_two_threads() {
    let stack = light_550();
    let opts = McOptions::new(photons(20_000), 16, 42).unwrap();
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let one = pool(1).install(|| run(&stack, &opts));
    let two = pool(2).install(|| run(&stack, &opts));
    assert_eq!(
        one.diffuse_reflectance.mean.to_bits(),
        two.diffuse_reflectance.mean.to_bits()
    );
    assert_eq!(
        one.diffuse_reflectance.stderr.to_bits(),
        two.diffuse_reflectance.stderr.to_bits()
    );
    assert_eq!(one.absorbed.mean.to_bits(), two.absorbed.mean.to_bits());
    assert_eq!(one, two);
    // A different seed gives a different history (the seed is really used).
    let other = run(&stack, &McOptions::new(photons(20_000), 16, 43).unwrap());
    assert_ne!(one.diffuse_reflectance.mean, other.diffuse_reflectance.mean);
}

#[test]
fn independent_streams_agree_on_a_two_layer_case() {
    // Two seeds are two independent xoshiro256** streams; their difference must be noise (4σ,
    // two-sided), so no seed gives a degenerate stream. This is not a bias check (a biased
    // generator agrees with itself): the totals are checked against [XT] in `reference.rs` and
    // against adding-doubling in `properties::physiology`. A generator can bias them: MCML 1.2
    // with its `ran3` replaced by xoshiro256** reflects 0.28% less and absorbs 0.87% more in light
    // skin's epidermis at 650 nm than with `ran3` (9σ; validation/data/mcml/README.md).
    let stack = LayeredMedium::skin(
        &SkinParams::preset(Preset::Medium),
        Wavelength::new(500.0).unwrap(),
        DEFAULT_G,
    )
    .unwrap();
    let a = run(&stack, &McOptions::new(photons(80_000), 20, 1).unwrap());
    let b = run(
        &stack,
        &McOptions::new(photons(80_000), 20, 0x9e37_79b9_7f4a_7c15).unwrap(),
    );
    let (ra, rb) = (a.diffuse_reflectance, b.diffuse_reflectance);
    let sigma = ra.stderr.hypot(rb.stderr);
    let z = (ra.mean - rb.mean) / sigma;
    assert!(z.abs() < 4.0, "{ra:?} vs {rb:?}: z = {z}");
}
