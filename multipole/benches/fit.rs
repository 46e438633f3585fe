//! Criterion benches of the fit: one colour fit (target < 100 ms), its parts, and a spectrum fit.

use criterion::{Criterion, criterion_group, criterion_main};
use multipole::fit::{ColourModel, FitOptions, MeasuredSpectrum, fit_colour, fit_spectrum};
use multipole::skin::diffuse_reflectance;
use skin_optics::Wavelength;
use std::hint::black_box;

fn bench_fit(c: &mut Criterion) {
    let opts = FitOptions::default();
    let model = ColourModel::new(opts.step_nm, opts.method, opts.base).expect("valid model");
    let medium = model.skin(0.05, 0.6, 0.02).expect("valid skin");
    let target = model.lab(&medium).expect("model colour");

    let mut g = c.benchmark_group("multipole/fit");
    g.sample_size(20);
    g.bench_function("colour_model_eval/step_10nm", |b| {
        b.iter(|| model.lab(black_box(&medium)))
    });
    g.bench_function("colour/default", |b| {
        b.iter(|| fit_colour(black_box(target), &opts))
    });
    let no_sweep = FitOptions {
        beta_scan: 0,
        ..opts
    };
    g.bench_function("colour/no_beta_sweep", |b| {
        b.iter(|| fit_colour(black_box(target), &no_sweep))
    });

    let lambda: Vec<f64> = (0..31).map(|i| 400.0 + 10.0 * f64::from(i)).collect();
    let reflectance = lambda
        .iter()
        .map(|&nm| {
            diffuse_reflectance(&medium, Wavelength::new(nm).expect("visible"), opts.method)
                .expect("model reflectance")
        })
        .collect();
    let measured = MeasuredSpectrum::new(lambda, reflectance, None).expect("valid spectrum");
    g.bench_function("spectrum/31_points", |b| {
        b.iter(|| fit_spectrum(black_box(&measured), &opts))
    });
    g.finish();
}

criterion_group!(benches, bench_fit);
criterion_main!(benches);
