//! Criterion benches of the Torrance–Sparrow lobe: eval, sample, pdf, albedo lookup, construction.
//! Each iteration processes a batch of 1024 precomputed direction pairs (or uniforms), so the
//! reported time is per batch; divide by 1024 for the per-call cost.

use brdf::TorranceSparrow;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::hint::black_box;

const BATCH: usize = 1024;

fn random_dir(rng: &mut Xoshiro256PlusPlus) -> Vec3 {
    let c: f32 = rng.random();
    let phi = std::f32::consts::TAU * rng.random::<f32>();
    let s = (1.0 - c * c).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), c)
}

/// One batch: the sum of `f` over the (opaque to the optimiser) direction pairs.
fn over_pairs(pairs: &[(Vec3, Vec3)], f: impl Fn(Vec3, Vec3) -> f32) -> f32 {
    let mut acc = 0.0f32;
    for &(wo, wi) in black_box(pairs) {
        acc += f(wo, wi);
    }
    acc
}

fn bench(c: &mut Criterion) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    let pairs: Vec<(Vec3, Vec3)> = (0..BATCH)
        .map(|_| (random_dir(&mut rng), random_dir(&mut rng)))
        .collect();
    let us: Vec<[f32; 2]> = (0..BATCH).map(|_| [rng.random(), rng.random()]).collect();
    let cosines: Vec<f32> = (0..BATCH).map(|_| rng.random()).collect();

    let mut group = c.benchmark_group("brdf");
    group.throughput(Throughput::Elements(BATCH as u64));
    for m in [0.1f32, 0.3] {
        let ts = TorranceSparrow::new(m, 0.25, 1.4).expect("valid parameters");
        group.bench_function(BenchmarkId::new("eval", format!("m{m}")), |b| {
            b.iter(|| black_box(over_pairs(&pairs, |wo, wi| ts.eval(wo, wi))));
        });
        group.bench_function(BenchmarkId::new("sample", format!("m{m}")), |b| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for (&(wo, _), &u) in black_box(&pairs).iter().zip(black_box(&us)) {
                    if let Some(s) = ts.sample(wo, u) {
                        acc += s.value / s.pdf;
                    }
                }
                black_box(acc)
            });
        });
        group.bench_function(BenchmarkId::new("pdf", format!("m{m}")), |b| {
            b.iter(|| black_box(over_pairs(&pairs, |wo, wi| ts.pdf(wo, wi))));
        });
    }
    let ts = TorranceSparrow::new(0.3, 0.25, 1.4).expect("valid parameters");
    group.bench_function("directional_albedo/table", |b| {
        b.iter(|| {
            let mut acc = 0.0f32;
            for &c in black_box(&cosines) {
                acc += ts.directional_albedo(c);
            }
            black_box(acc)
        });
    });
    group.finish();

    let mut group = c.benchmark_group("brdf");
    group.sample_size(10);
    // Each iteration nudges m by one ulp so the table cache misses: this is the full build.
    let mut m = 0.3f32;
    group.bench_function("new/m0.3/build", |b| {
        b.iter(|| {
            m = f32::from_bits(m.to_bits() + 1);
            TorranceSparrow::new(black_box(m), 0.25, 1.4).expect("valid parameters")
        });
    });
    group.bench_function("new/m0.3/cached", |b| {
        b.iter(|| TorranceSparrow::new(black_box(0.3), 0.25, 1.4).expect("valid parameters"));
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
