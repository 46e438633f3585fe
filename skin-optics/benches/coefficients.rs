//! Criterion bench: all layer coefficients ([DJ06] eqs 1–6) over 400–700 nm at 1 nm (301 λ).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use skin_optics::{Preset, SkinParams, WavelengthGrid};
use std::hint::black_box;

fn coefficients(c: &mut Criterion) {
    let grid = WavelengthGrid::new(400.0, 700.0, 1.0).expect("valid grid");
    let mut g = c.benchmark_group("skin-optics/coefficients");
    g.throughput(Throughput::Elements(grid.len() as u64));
    for preset in Preset::ALL {
        let skin = SkinParams::preset(preset);
        g.bench_with_input(
            BenchmarkId::new("400-700nm-1nm", preset.name()),
            &skin,
            |b, skin| {
                b.iter(|| {
                    let mut sum = 0.0;
                    for lambda in black_box(&grid).iter() {
                        let k = black_box(skin).coefficients(lambda);
                        sum += k.epidermis.sigma_a
                            + k.epidermis.sigma_s_prime
                            + k.dermis.sigma_a
                            + k.dermis.sigma_s_prime;
                    }
                    sum
                });
            },
        );
    }
    g.finish();
}

criterion_group!(benches, coefficients);
criterion_main!(benches);
