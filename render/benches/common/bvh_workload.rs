//! The BVH workload shared by the criterion bench (`benches/bvh.rs`) and the CPU-time example
//! (`examples/bvh_throughput.rs`): the bundled head in mm, coherent primary rays and incoherent
//! random rays, all deterministic.

// Each of the two targets compiles this module on its own and reads only part of `Query`.
#![allow(dead_code)]

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use render::accel::{Accel, ray};
use render::mesh::{Placement, TriangleMesh};
use std::path::Path;

/// The bundled head's triangles (17,684), scaled to mm.
pub fn head_triangles() -> Vec<[Vec3; 3]> {
    let mut m = TriangleMesh::from_glb(
        include_bytes!("../../assets/LeePerrySmith.glb"),
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

/// Primary rays: an n² pinhole grid from 600 mm in front of the face (about half hit the head).
pub fn primary_rays(n: usize) -> Vec<(Vec3, Vec3)> {
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

/// `count` incoherent rays: random origins in the head's box (enlarged), random directions (seed 1).
pub fn random_rays(count: usize) -> Vec<(Vec3, Vec3)> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    (0..count)
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

/// A ray query the tracer makes: its bench group name, its name in prose, the word for a positive
/// answer, and the query itself.
pub struct Query {
    /// Criterion group name.
    pub name: &'static str,
    /// Name in the example's report.
    pub label: &'static str,
    /// What a positive answer is called ("hit", "blocked").
    pub outcome: &'static str,
    /// Whether the query answers yes for ray (`o`, unit `d`).
    pub run: fn(&Accel, Vec3, Vec3) -> bool,
}

/// Closest hit (unbounded) and occlusion (to 1000 mm).
pub const QUERIES: [Query; 2] = [
    Query {
        name: "closest_hit",
        label: "closest hit",
        outcome: "hit",
        run: |a, o, d| a.closest(&ray(o, d, 0.0, f32::INFINITY)).is_some(),
    },
    Query {
        name: "occluded",
        label: "occlusion",
        outcome: "blocked",
        run: |a, o, d| a.occluded(&ray(o, d, 0.0, 1000.0)),
    },
];
