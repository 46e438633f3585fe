//! BVH on the head mesh (17,684 triangles, mm): build time, closest-hit and occlusion rays per
//! second, for coherent primary rays and incoherent random rays, on one and on two threads.

#[path = "common/bvh_workload.rs"]
mod workload;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rayon::prelude::*;
use render::accel::Accel;
use std::hint::black_box;
use workload::{QUERIES, head_triangles, primary_rays, random_rays};

fn bench(c: &mut Criterion) {
    let tris = head_triangles();
    let mut g = c.benchmark_group("render/bvh_build");
    g.throughput(Throughput::Elements(tris.len() as u64));
    g.bench_function("head", |b| {
        b.iter(|| black_box(Accel::build(black_box(&tris))))
    });
    g.finish();

    let accel = Accel::build(&tris);
    for (name, rays) in [
        ("primary", primary_rays(256)),
        ("random", random_rays(65_536)),
    ] {
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            for q in QUERIES {
                let mut g = c.benchmark_group(format!("render/{}/{name}", q.name));
                g.throughput(Throughput::Elements(rays.len() as u64));
                g.bench_with_input(
                    BenchmarkId::from_parameter(format!("{threads}threads")),
                    &rays,
                    |b, rays| {
                        b.iter(|| {
                            pool.install(|| {
                                rays.par_chunks(1024)
                                    .map(|ch| {
                                        ch.iter().filter(|(o, d)| (q.run)(&accel, *o, *d)).count()
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
}

criterion_group!(benches, bench);
criterion_main!(benches);
