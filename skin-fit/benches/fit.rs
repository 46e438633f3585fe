//! Criterion benches of the fit: one colour fit with each forward model (exact: the two-stage
//! default; multipole: the paper's diffusion, target < 100 ms), their parts, and spectrum fits.
//! Run: `cargo bench -p multipole --bench fit`.

use criterion::{Criterion, criterion_group, criterion_main};
use multipole::Method;
use multipole::skin::diffuse_reflectance;
use skin_fit::{ColourModel, FitOptions, MeasuredSpectrum, fit_colour, fit_spectrum};
use skin_optics::Wavelength;
use std::hint::black_box;

fn bench_fit(c: &mut Criterion) {
    let mut g = c.benchmark_group("multipole/fit");
    g.sample_size(10);
    for method in [Method::Exact, Method::Multipole] {
        let opts = FitOptions {
            method,
            ..FitOptions::default()
        };
        let model = ColourModel::new(opts.step_nm, opts.method, opts.base).expect("valid model");
        let medium = model.skin(0.05, 0.6, 0.02).expect("valid skin");
        let target = model.lab(&medium).expect("model colour");
        g.bench_function(format!("colour_model_eval/{method}_10nm"), |b| {
            b.iter(|| model.lab(black_box(&medium)))
        });
        g.bench_function(format!("colour/{method}"), |b| {
            b.iter(|| fit_colour(black_box(target), &opts))
        });
        let no_sweep = FitOptions {
            beta_scan: 0,
            ..opts
        };
        g.bench_function(format!("colour_no_beta_sweep/{method}"), |b| {
            b.iter(|| fit_colour(black_box(target), &no_sweep))
        });
        let lambda: Vec<f64> = (0..31).map(|i| 400.0 + 10.0 * f64::from(i)).collect();
        let reflectance = lambda
            .iter()
            .map(|&nm| {
                diffuse_reflectance(&medium, Wavelength::new(nm).expect("visible"), method)
                    .expect("model reflectance")
            })
            .collect();
        let measured = MeasuredSpectrum::new(lambda, reflectance, None).expect("valid spectrum");
        g.bench_function(format!("spectrum_31_points/{method}"), |b| {
            b.iter(|| fit_spectrum(black_box(&measured), &opts))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_fit);
criterion_main!(benches);
