//! Rays per on-CPU second of the BVH on the head mesh, one thread: closest hit and occlusion for
//! coherent primary rays and incoherent random rays. Reads the thread's own CPU time
//! (`cpu-time`), so the figure holds on a loaded machine.
//!
//! `cargo run --release -p render --example bvh_throughput`

#[path = "../benches/common/bvh_workload.rs"]
mod workload;

use render::accel::Accel;
use std::hint::black_box;
use std::time::Instant;
use workload::{QUERIES, head_triangles, primary_rays, random_rays};

/// On-CPU time of this thread, seconds.
fn cpu_seconds() -> f64 {
    cpu_time::ThreadTime::now().as_duration().as_secs_f64()
}

fn main() {
    let tris = head_triangles();

    let (c0, w0) = (cpu_seconds(), Instant::now());
    let builds = 20;
    for _ in 0..builds {
        black_box(Accel::build(black_box(&tris)));
    }
    println!(
        "build: {:.1} ms on-CPU per build ({:.1} ms wall), {} triangles",
        (cpu_seconds() - c0) / f64::from(builds) * 1e3,
        w0.elapsed().as_secs_f64() / f64::from(builds) * 1e3,
        tris.len()
    );
    let accel = Accel::build(&tris);

    let n = 512;
    let primary = primary_rays(n);
    let random = random_rays(n * n);
    for (name, rays) in [("primary", &primary), ("random", &random)] {
        for q in QUERIES {
            let (c0, w0) = (cpu_seconds(), Instant::now());
            let hits = rays.iter().filter(|(o, d)| (q.run)(&accel, *o, *d)).count();
            let (cpu, wall) = (cpu_seconds() - c0, w0.elapsed().as_secs_f64());
            println!(
                "{}, {name}: {:.2} M rays per CPU-second ({:.2} M/s wall), {:.0}% {}",
                q.label,
                rays.len() as f64 / cpu / 1e6,
                rays.len() as f64 / wall / 1e6,
                100.0 * hits as f64 / rays.len() as f64,
                q.outcome
            );
        }
    }
}
