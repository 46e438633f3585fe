//! Lanes change the order of draws, never the statistics.

use super::*;
use crate::exact::montecarlo::tally::McResult;
use crate::exact::montecarlo::{Layer, batch_streams};

/// Run `batches` × `per_batch` photons through `trace_lanes::<K>` with the module's batch streams.
fn run_lanes<const K: usize>(stack: &LayeredMedium, seed: u64, per_batch: u64) -> McResult {
    let medium = Medium::new(stack);
    let specular = medium.specular(stack.n_above());
    let grid = RadialGrid::default();
    let tallies: Vec<BatchTally> = batch_streams(seed, 16)
        .into_iter()
        .map(|mut rng| {
            let mut t = BatchTally::new(stack.layers().len(), grid.bins());
            trace_lanes::<K>(&medium, grid, 1.0 - specular, per_batch, &mut rng, &mut t);
            t
        })
        .collect();
    McResult::from_batches(&tallies, specular, grid)
}

#[test]
fn lanes_agree_with_one_photon_at_a_time() {
    // Two layers with a mismatch below (Fresnel both ways, transmission, absorption in each).
    let stack = LayeredMedium::new(
        vec![
            Layer::slab(1.0, 20.0, 0.8, 1.4, 0.2).unwrap(),
            Layer::slab(0.05, 10.0, 0.9, 1.4, 1.0).unwrap(),
        ],
        1.0,
        1.2,
    )
    .unwrap();
    for seed in [3, 11] {
        let one = run_lanes::<1>(&stack, seed, 500);
        let many = run_lanes::<LANES>(&stack, seed, 500);
        for r in [&one, &many] {
            assert_eq!(r.photons, 8000);
            assert!(
                (r.energy_total() - 1.0).abs() < 1e-12,
                "{}",
                r.energy_total()
            );
        }
        for (a, b) in [
            (one.diffuse_reflectance, many.diffuse_reflectance),
            (one.transmittance, many.transmittance),
            (one.absorbed, many.absorbed),
        ] {
            let se = (a.stderr * a.stderr + b.stderr * b.stderr).sqrt();
            // Independent runs: the difference has standard error `se`; 4 of them is a 6e-5 chance.
            assert!(
                (a.mean - b.mean).abs() < 4.0 * se,
                "seed {seed}: {a:?} vs {b:?}"
            );
        }
        // Different draws, so not the same bits.
        assert_ne!(one.diffuse_reflectance.mean, many.diffuse_reflectance.mean);
    }
}

#[test]
fn same_bits_on_one_and_two_threads() {
    let stack = LayeredMedium::new(
        vec![Layer::from_reduced(0.1, 1.0, 0.9, 1.4, None).unwrap()],
        1.0,
        1.0,
    )
    .unwrap();
    let opts = crate::exact::montecarlo::McOptions::new(2000, 8, 5).unwrap();
    let on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| crate::exact::montecarlo::run(&stack, &opts))
    };
    let (a, b) = (on(1), on(2));
    assert_eq!(a, b);
    assert!((a.energy_total() - 1.0).abs() < 1e-12);
}
