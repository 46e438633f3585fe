//! The per-path spectral lookups of a skin hit: drawing the path's four wavelengths (with their
//! places on the shared table grids), a 5-nm spectrum at them, and the BSSRDF's angular factor
//! T(θ) a(θ, λ) and S_ω with the adding-doubling incidence gain (light skin, g = 0.9).

use criterion::{Criterion, criterion_group, criterion_main};
use render::bssrdf::{Directional, EnergySplit, IncidenceGain};
use render::media::SkinMedia;
use render::spectrum::{SampledWavelengths, SpectrumTable, WavelengthSampling};
use skin_optics::{Preset, SkinParams};
use std::hint::black_box;
use std::sync::Arc;

/// Wavelength sets at 256 stratified CDF values.
fn wavelength_sets() -> Vec<SampledWavelengths> {
    (0..256)
        .map(|i| SampledWavelengths::sample((i as f32 + 0.5) / 256.0, WavelengthSampling::Visible))
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("render/spectral");
    g.bench_function("wavelengths_sample", |b| {
        let mut u = 0.0f32;
        b.iter(|| {
            u = (u + 0.618_034).fract();
            black_box(SampledWavelengths::sample(
                black_box(u),
                WavelengthSampling::Visible,
            ))
        })
    });
    let sets = wavelength_sets();
    let table = SpectrumTable::from_fn(|nm| 0.5 + 0.001 * (nm - 380.0));
    g.bench_function("spectrum_table_eval", |b| {
        let mut k = 0;
        b.iter(|| {
            k = (k + 1) % sets.len();
            black_box(table.eval(black_box(&sets[k])))
        })
    });
    let params = SkinParams::preset(Preset::Light);
    let media = SkinMedia::new(&params, multipole::DEFAULT_G).expect("light skin's layers");
    let gain = IncidenceGain::build(media.every_10nm(), multipole::DEFAULT_G).expect("gain");
    let surface = brdf::TorranceSparrow::new(0.3, params.oiliness() as f32, params.eta() as f32)
        .expect("the lobe");
    let directional =
        Directional::new(surface, EnergySplit::default()).with_incidence(Arc::new(gain));
    g.bench_function("directional_factors", |b| {
        let (mut k, mut mu) = (0, 0.0f32);
        b.iter(|| {
            k = (k + 1) % sets.len();
            mu = (mu + 0.618_034).fract();
            black_box(directional.factors(black_box(mu), &sets[k]))
        })
    });
    g.bench_function("directional_s_omegas", |b| {
        let (mut k, mut mu) = (0, 0.0f32);
        b.iter(|| {
            k = (k + 1) % sets.len();
            mu = (mu + 0.618_034).fract();
            black_box(directional.s_omegas(black_box(mu), &sets[k]))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
