//! Criterion benches of the chromophore maps: the inversion of one million texels on two cores
//! (target ≥ 10 M texels/s), the forward albedo of the maps, and one β_m slice with its seed grid.
//! The forward table comes from the disk cache (built on the first run, about 5000 exact colours).
//! Run: `cargo bench -p skin-fit --bench maps`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use skin_fit::maps::{Eumelanin, Inverter, MapsModel, MapsOptions};
use std::hint::black_box;

/// One million texels: skins spread over the table (u, v on a scrambled lattice, β_m 0.6) with
/// every tenth texel a non-skin colour (grey, green, near black).
fn texels(model: &MapsModel) -> Vec<[f32; 3]> {
    let n = 1_000_000;
    let skins = model
        .albedo(
            &(0..n)
                .map(|k| skin_fit::maps::melanin_of_u(((k * 7919) % 1000) as f64 / 999.0) as f32)
                .collect::<Vec<_>>(),
            0.6,
            &(0..n)
                .map(|k| {
                    skin_fit::maps::hemoglobin_of_v(((k * 104_729) % 997) as f64 / 996.0) as f32
                })
                .collect::<Vec<_>>(),
        )
        .expect("valid maps");
    skins
        .into_iter()
        .enumerate()
        .map(|(k, t)| match k % 30 {
            0 => [0.2, 0.2, 0.2],
            10 => [0.05, 0.4, 0.05],
            20 => [0.002, 0.002, 0.003],
            _ => t,
        })
        .collect()
}

fn bench_maps(c: &mut Criterion) {
    let opts = MapsOptions {
        eumelanin: Eumelanin::Fixed(0.6),
        cache_dir: skin_io::cache::cache_dir(),
        ..MapsOptions::default()
    };
    let model = MapsModel::load(&opts).expect("forward table");
    let texels = texels(&model);
    let mut g = c.benchmark_group("maps");
    g.sample_size(10);
    g.throughput(Throughput::Elements(texels.len() as u64));
    g.bench_function("invert_1M_texels", |b| {
        b.iter(|| model.fit(black_box(&texels), None, &opts, &|_| {}))
    });
    let fitted = model.fit(&texels, None, &opts, &|_| {}).expect("maps");
    g.bench_function("albedo_1M_texels", |b| {
        b.iter(|| model.albedo(black_box(&fitted.melanin), 0.6, &fitted.hemoglobin))
    });
    let fit_beta = MapsOptions {
        eumelanin: Eumelanin::Fit,
        ..opts.clone()
    };
    g.bench_function("invert_1M_texels_fit_eumelanin", |b| {
        b.iter(|| model.fit(black_box(&texels), None, &fit_beta, &|_| {}))
    });
    g.throughput(Throughput::Elements(1));
    g.bench_function("slice_and_seed_grid", |b| {
        b.iter(|| Inverter::new(model.table().slice(black_box(0.37))))
    });
    g.finish();
}

criterion_group!(benches, bench_maps);
criterion_main!(benches);
