//! Adding-doubling totals for a full 31-wavelength skin set (400–700 nm) on one thread.
//! Run: `cargo bench -p multipole --bench adding_doubling`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use multipole::exact::adding_doubling::{AddingDoublingOptions, DEFAULT_G, skin_totals_spectrum};
use skin_optics::{Preset, SkinParams, WavelengthGrid};

fn spectral_set(c: &mut Criterion) {
    let grid = WavelengthGrid::visible();
    let mut group = c.benchmark_group("multipole/adding_doubling_31");
    group.sample_size(20);
    for (name, preset) in [("light", Preset::Light), ("dark", Preset::Dark)] {
        let skin = SkinParams::preset(preset);
        for points in [8, 16, 24, 32] {
            let opts = AddingDoublingOptions::new(points, DEFAULT_G).expect("valid knob");
            group.bench_function(format!("{name}/points_{points}"), |b| {
                b.iter(|| {
                    skin_totals_spectrum(black_box(&skin), black_box(&grid), black_box(&opts))
                        .expect("valid skin")
                });
            });
        }
    }
    group.finish();
}

criterion_group!(benches, spectral_set);
criterion_main!(benches);
