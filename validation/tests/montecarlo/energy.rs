//! Exact energy accounting for random valid stacks (proptest).

use proptest::prelude::*;
use validation::montecarlo::{Layer, LayeredMedium, McOptions, run};

/// One physically valid layer: σa in [0, 50], σs in [0, 200] mm⁻¹, g in [−0.5, 0.95], n in
/// [1, 1.6], thickness in [0.01, 2] mm (semi-infinite layers get σa ≥ 0.05 to keep histories short).
fn layer(last: bool) -> impl Strategy<Value = Layer> {
    (
        0.0..50.0f64,
        0.0..200.0f64,
        -0.5..0.95f64,
        1.0..1.6f64,
        0.01..2.0f64,
        any::<bool>(),
    )
        .prop_map(move |(a, s, g, n, d, semi)| {
            if last && semi {
                Layer::semi_infinite(a.max(0.05), s, g, n).expect("valid ranges")
            } else {
                Layer::slab(a, s, g, n, d).expect("valid ranges")
            }
        })
}

/// A stack of one to three layers with ambient indices in [1, 1.6].
fn stack() -> impl Strategy<Value = LayeredMedium> {
    (1usize..=3)
        .prop_flat_map(|k| {
            (
                proptest::collection::vec(layer(false), k - 1),
                layer(true),
                1.0..1.6f64,
                1.0..1.6f64,
            )
        })
        .prop_map(|(mut layers, last, up, down)| {
            layers.push(last);
            LayeredMedium::new(layers, up, down).expect("only the last layer may be semi-infinite")
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn reflected_transmitted_absorbed_sum_to_one(stack in stack(), seed in any::<u64>()) {
        let r = run(&stack, &McOptions::new(400, 4, seed).unwrap());
        prop_assert!((r.energy_total() - 1.0).abs() < 1e-10, "total {}", r.energy_total());
        for v in [r.diffuse_reflectance.mean, r.transmittance.mean, r.specular_reflectance] {
            prop_assert!((0.0..=1.0).contains(&v), "{v}");
        }
        if stack.is_semi_infinite() {
            prop_assert_eq!(r.transmittance.mean, 0.0);
        }
        let deposited: f64 = r.absorbed_by_layer.iter().sum();
        prop_assert!((deposited + r.roulette_balance - r.absorbed.mean).abs() < 1e-12);
    }
}
