//! Photon rate of the layered Monte Carlo on the three cases BENCHMARKS.md compares with the classic
//! MCML program ([WJZ95]):
//! light preset at 550 nm (g = 0.9), very dark skin (C_m 0.5, β_m 0.9, C_h 0.07) at 550 nm, and a
//! half-space with σa = 0.01, σs' = 1 mm⁻¹, g = 0.9, n = 1.4; on 1 and 2 rayon threads.
//! Throughput is in photons (criterion reports elements/s).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use skin_optics::{Preset, SkinParams, Wavelength};
use std::hint::black_box;
use validation::montecarlo::{DEFAULT_G, Layer, LayeredMedium, McOptions, run};

fn cases() -> Vec<(&'static str, LayeredMedium, u64)> {
    let l550 = Wavelength::new(550.0).expect("550 nm is in range");
    let light = SkinParams::preset(Preset::Light);
    let very_dark = SkinParams::new(0.5, 0.9, 0.07, 0.25).expect("valid fractions");
    let half = Layer::from_reduced(0.01, 1.0, 0.9, 1.4, None).expect("valid layer");
    vec![
        (
            "light_550nm",
            LayeredMedium::skin(&light, l550, DEFAULT_G).expect("valid"),
            4_000,
        ),
        (
            "very_dark_550nm",
            LayeredMedium::skin(&very_dark, l550, DEFAULT_G).expect("valid"),
            40_000,
        ),
        (
            "half_space_sa0.01",
            LayeredMedium::new(vec![half], 1.0, 1.0).expect("valid"),
            1_000,
        ),
    ]
}

fn photon_rate(c: &mut Criterion) {
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        let mut g = c.benchmark_group(format!("validation/mc_photons/{threads}_threads"));
        g.sample_size(10);
        for (name, stack, photons) in cases() {
            let opts = McOptions::new(photons, 16, 1).expect("valid options");
            g.throughput(Throughput::Elements(opts.total_photons()));
            g.bench_with_input(BenchmarkId::from_parameter(name), &stack, |b, s| {
                b.iter(|| pool.install(|| black_box(run(black_box(s), &opts))));
            });
        }
        g.finish();
    }
}

criterion_group!(benches, photon_rate);
criterion_main!(benches);
