//! Photon rate of the layered Monte Carlo on its half-space speed case: one semi-infinite layer
//! with σa = 0.01, σs' = 1 mm⁻¹ (σs = 10 mm⁻¹), g = 0.9, n = 1.4 under air (about 1,600 scatterings
//! per photon: long histories, the hardest case for the photon loop).
//!
//! `cargo run --release -p multipole --features studies --example mc_half_space [PHOTONS] [THREADS] [SIGMA_A]`
//! (defaults 100000, 1, 0.01 mm⁻¹; σs' stays 1 mm⁻¹). Prints R_d (exact-transport reference
//! values, BENCHMARKS.md `## Exact method`: 0.6040 for σa 0.01, 0.0713 for σa 0.5), energy, scatterings per photon, and the
//! wall-clock rate; for the CPU-time rate run the built binary under `/usr/bin/time -f "%U user"`
//! and divide the photons by the user seconds (the setup is microseconds).

use multipole::exact::montecarlo::{Layer, LayeredMedium, McOptions, run};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let photons: u64 = args.next().map_or(Ok(100_000), |s| s.parse())?;
    let threads: usize = args.next().map_or(Ok(1), |s| s.parse())?;
    let sigma_a: f64 = args.next().map_or(Ok(0.01), |s| s.parse())?;
    let half = Layer::from_reduced(sigma_a, 1.0, 0.9, 1.4, None)?;
    let stack = LayeredMedium::new(vec![half], 1.0, 1.0)?;
    let opts = McOptions::new(photons, 32, 1)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let start = Instant::now();
    let r = pool.install(|| run(&stack, &opts));
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "photons,threads,diffuse_reflectance,stderr,energy_total,scatterings_per_photon,seconds,photons_per_second"
    );
    println!(
        "{},{threads},{:.5},{:.5},{:.15},{:.1},{seconds:.3},{:.0}",
        r.photons,
        r.diffuse_reflectance.mean,
        r.diffuse_reflectance.stderr,
        r.energy_total(),
        r.interactions_per_photon,
        r.photons as f64 / seconds,
    );
    Ok(())
}
