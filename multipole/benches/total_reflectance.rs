//! Total diffuse reflectance (q = 0 of the stacked spectrum): one wavelength and a 31-λ spectrum.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use multipole::diffusion::{
    medium::Medium,
    slab::{Poles, Slab},
};
use multipole::skin::{Method, diffuse_reflectance, total_reflectance};
use skin_optics::{Preset, SkinParams, Wavelength, WavelengthGrid};
use std::hint::black_box;

fn totals(c: &mut Criterion) {
    let mut g = c.benchmark_group("multipole/total_reflectance");
    let skin = SkinParams::preset(Preset::Medium);
    let lambda = Wavelength::new(550.0).expect("valid wavelength");
    g.bench_function("skin_1lambda", |b| {
        b.iter(|| total_reflectance(black_box(&skin), lambda, Method::Multipole))
    });
    g.bench_function("skin_1lambda_exact", |b| {
        b.iter(|| total_reflectance(black_box(&skin), lambda, Method::Exact))
    });
    let grid = WavelengthGrid::visible();
    for method in [Method::Multipole, Method::Exact] {
        let id = match method {
            Method::Multipole => "skin_31lambda_observable".to_string(),
            other => format!("skin_31lambda_observable_{other}"),
        };
        g.bench_function(id, |b| {
            b.iter(|| {
                grid.iter()
                    .map(|l| diffuse_reflectance(black_box(&skin), l, method).unwrap_or(0.0))
                    .sum::<f64>()
            })
        });
    }
    let slab = Slab::new(Medium::new(0.1, 2.0).expect("medium"), 1.0, 1.4, 1.0).expect("slab");
    for (name, poles) in [
        ("exact", Poles::Exact),
        ("count5", Poles::Count(5)),
        ("count50", Poles::Count(50)),
    ] {
        g.bench_with_input(BenchmarkId::new("slab_transform", name), &poles, |b, &p| {
            b.iter(|| black_box(&slab).transform(black_box(3.0), p))
        });
    }
    g.finish();
}

criterion_group!(benches, totals);
criterion_main!(benches);
