//! BVH on the head mesh (17,684 triangles, mm): build time, closest-hit and occlusion rays per
//! second, for coherent primary rays and incoherent random rays, on one and on two threads.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use rayon::prelude::*;
use render::accel::{Accel, ray};
use render::mesh::{Placement, TriangleMesh};
use std::hint::black_box;
use std::path::Path;

fn head_triangles() -> Vec<[Vec3; 3]> {
    let mut m = TriangleMesh::from_glb(
        include_bytes!("../assets/LeePerrySmith.glb"),
        Path::new("LeePerrySmith.glb"),
    )
    .expect("bundled head loads");
    m.transform(
        &Placement {
            units_mm: 45.0,
            ..Default::default()
        }
        .to_affine(),
    );
    m.indices
        .iter()
        .map(|t| t.map(|i| m.positions[i as usize]))
        .collect()
}

/// Primary rays: a 256² pinhole grid from 600 mm in front of the face (about half hit the head).
fn primary_rays() -> Vec<(Vec3, Vec3)> {
    let n = 256;
    let eye = Vec3::new(0.0, 30.0, 600.0);
    (0..n * n)
        .map(|i| {
            let (x, y) = (
                (i % n) as f32 / n as f32 - 0.5,
                (i / n) as f32 / n as f32 - 0.5,
            );
            let target = Vec3::new(x * 400.0, 30.0 - y * 400.0, 0.0);
            (eye, (target - eye).normalize())
        })
        .collect()
}

/// Incoherent rays: random origins in the head's box (enlarged), random directions.
fn random_rays() -> Vec<(Vec3, Vec3)> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    (0..65_536)
        .map(|_| {
            let o = Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - Vec3::ONE;
            let o = o * Vec3::new(250.0, 250.0, 150.0);
            let d = loop {
                let v = Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - Vec3::ONE;
                if (0.01..1.0).contains(&v.length_squared()) {
                    break v.normalize();
                }
            };
            (o, d)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let tris = head_triangles();
    let mut g = c.benchmark_group("render/bvh_build");
    g.throughput(Throughput::Elements(tris.len() as u64));
    g.bench_function("head", |b| {
        b.iter(|| black_box(Accel::build(black_box(&tris))))
    });
    g.finish();

    let accel = Accel::build(&tris);
    for (name, rays) in [("primary", primary_rays()), ("random", random_rays())] {
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let mut g = c.benchmark_group(format!("render/closest_hit/{name}"));
            g.throughput(Throughput::Elements(rays.len() as u64));
            g.bench_with_input(
                BenchmarkId::from_parameter(format!("{threads}threads")),
                &rays,
                |b, rays| {
                    b.iter(|| {
                        pool.install(|| {
                            rays.par_chunks(1024)
                                .map(|ch| {
                                    ch.iter()
                                        .filter(|(o, d)| {
                                            accel
                                                .closest(&ray(*o, *d, 0.0, f32::INFINITY))
                                                .is_some()
                                        })
                                        .count()
                                })
                                .sum::<usize>()
                        })
                    })
                },
            );
            g.finish();
            let mut g = c.benchmark_group(format!("render/occluded/{name}"));
            g.throughput(Throughput::Elements(rays.len() as u64));
            g.bench_with_input(
                BenchmarkId::from_parameter(format!("{threads}threads")),
                &rays,
                |b, rays| {
                    b.iter(|| {
                        pool.install(|| {
                            rays.par_chunks(1024)
                                .map(|ch| {
                                    ch.iter()
                                        .filter(|(o, d)| accel.occluded(&ray(*o, *d, 0.0, 1000.0)))
                                        .count()
                                })
                                .sum::<usize>()
                        })
                    })
                },
            );
            g.finish();
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
