//! Rays per on-CPU second of the BVH on the head mesh, one thread: closest hit and occlusion for
//! coherent primary rays and incoherent random rays. Reads the thread's own CPU time
//! (`cpu-time`), so the figure holds on a loaded machine.
//!
//! `cargo run --release -p render --example bvh_throughput`

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use render::accel::{Accel, ray};
use render::mesh::{Placement, TriangleMesh};
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

/// On-CPU time of this thread, seconds.
fn cpu_seconds() -> f64 {
    cpu_time::ThreadTime::now().as_duration().as_secs_f64()
}

fn main() {
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
    let tris: Vec<[Vec3; 3]> = m
        .indices
        .iter()
        .map(|t| t.map(|i| m.positions[i as usize]))
        .collect();

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
    let eye = Vec3::new(0.0, 30.0, 600.0);
    let primary: Vec<(Vec3, Vec3)> = (0..n * n)
        .map(|i| {
            let (x, y) = (
                (i % n) as f32 / n as f32 - 0.5,
                (i / n) as f32 / n as f32 - 0.5,
            );
            (
                eye,
                (Vec3::new(x * 400.0, 30.0 - y * 400.0, 0.0) - eye).normalize(),
            )
        })
        .collect();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    let random: Vec<(Vec3, Vec3)> = (0..n * n)
        .map(|_| {
            let o = (Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - Vec3::ONE)
                * Vec3::new(250.0, 250.0, 150.0);
            let d = loop {
                let v = Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - Vec3::ONE;
                if (0.01..1.0).contains(&v.length_squared()) {
                    break v.normalize();
                }
            };
            (o, d)
        })
        .collect();
    for (name, rays) in [("primary", &primary), ("random", &random)] {
        let (c0, w0) = (cpu_seconds(), Instant::now());
        let hits = rays
            .iter()
            .filter(|(o, d)| accel.closest(&ray(*o, *d, 0.0, f32::INFINITY)).is_some())
            .count();
        let (cpu, wall) = (cpu_seconds() - c0, w0.elapsed().as_secs_f64());
        println!(
            "closest hit, {name}: {:.2} M rays per CPU-second ({:.2} M/s wall), {:.0}% hit",
            rays.len() as f64 / cpu / 1e6,
            rays.len() as f64 / wall / 1e6,
            100.0 * hits as f64 / rays.len() as f64
        );
        let (c0, w0) = (cpu_seconds(), Instant::now());
        let blocked = rays
            .iter()
            .filter(|(o, d)| accel.occluded(&ray(*o, *d, 0.0, 1000.0)))
            .count();
        let (cpu, wall) = (cpu_seconds() - c0, w0.elapsed().as_secs_f64());
        println!(
            "occlusion, {name}: {:.2} M rays per CPU-second ({:.2} M/s wall), {:.0}% blocked",
            rays.len() as f64 / cpu / 1e6,
            rays.len() as f64 / wall / 1e6,
            100.0 * blocked as f64 / rays.len() as f64
        );
    }
}
