//! A full spectral set of profiles for one skin: 31 wavelengths (400–700 nm), two layers, 256 radial
//! samples to the 99.9% radius, on ONE thread (a 1-thread rayon pool), plus single profiles.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use multipole::ProfileOptions;
use multipole::diffusion::slab::Poles;
use multipole::diffusion::spatial::DiffusionOptions;
use multipole::skin::{Method, SpectralProfiles, profile};
use skin_optics::{Preset, SkinParams, Wavelength, WavelengthGrid};
use std::hint::black_box;

fn spectral_profiles(c: &mut Criterion) {
    let grid = WavelengthGrid::visible();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("1-thread pool");
    let mut g = c.benchmark_group("multipole/spectral_profiles");
    for preset in [Preset::Light, Preset::Dark] {
        let skin = SkinParams::preset(preset);
        let opts = ProfileOptions::default();
        // Warm the shared Hankel table outside the measurement.
        SpectralProfiles::new(&skin, &grid, Method::Multipole, &opts).expect("profiles");
        g.bench_with_input(
            BenchmarkId::new("31x256_1thread", preset.name()),
            &skin,
            |b, skin| {
                b.iter(|| {
                    pool.install(|| {
                        SpectralProfiles::new(black_box(skin), &grid, Method::Multipole, &opts)
                    })
                })
            },
        );
    }
    g.finish();

    let mut g = c.benchmark_group("multipole/profile");
    let skin = SkinParams::preset(Preset::Light);
    for nm in [450.0, 650.0] {
        let lambda = Wavelength::new(nm).expect("valid wavelength");
        for (name, poles) in [("exact", Poles::Exact), ("count5", Poles::Count(5))] {
            let opts = ProfileOptions::with_diffusion(DiffusionOptions {
                poles,
                ..DiffusionOptions::default()
            });
            g.bench_with_input(
                BenchmarkId::new(format!("{name}_{nm}nm"), 256),
                &lambda,
                |b, &l| b.iter(|| profile(black_box(&skin), l, Method::Multipole, &opts)),
            );
        }
    }
    g.finish();
}

criterion_group!(benches, spectral_profiles);
criterion_main!(benches);
