//! The curvature term's cost and noise on the default three-head scene (docs/physics.md §8.2):
//! renders `builtin:three-heads-uniform` at fixed samples with `Curvature::Planar` and the default
//! `Curvature::FirstOrder`, seeds 1 and 2 each, one thread, interleaved so both see the same
//! machine load; prints each variant's CPU seconds (the two renders), the two-seed relative
//! luminance noise over the lit pixels (`render::noise`) and noise · √CPU-s (lower is better).
//!
//! `cargo run --release -p render --features studies --example curvature_cost -- [WIDTH] [SPP] [ROUNDS]`
use render::bssrdf::Curvature;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::SkinKnobs;
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let width: usize = args.get(1).map_or(192, |s| s.parse().unwrap());
    let spp: u32 = args.get(2).map_or(8, |s| s.parse().unwrap());
    let rounds: usize = args.get(3).map_or(2, |s| s.parse().unwrap());
    let height = width / 2;
    let variants = [Curvature::Planar, Curvature::FirstOrder];
    let loaded: Vec<(Scene, BodyIntegrator)> = variants
        .iter()
        .map(|&curvature| {
            let knobs = SkinKnobs {
                curvature,
                ..SkinKnobs::default()
            };
            let scene = Scene::load("builtin:three-heads-uniform", &knobs).unwrap();
            let body = BodyIntegrator::build(&scene, IntegratorKind::Bssrdf);
            (scene, body)
        })
        .collect();
    let mut cpu = [0.0f64; 2];
    let mut images: [Vec<Vec<f64>>; 2] = [Vec::new(), Vec::new()];
    for round in 0..rounds {
        for (v, (scene, body)) in loaded.iter().enumerate() {
            for seed in [1u64, 2] {
                let mut opts = RenderOptions {
                    width,
                    height,
                    spp,
                    seed,
                    threads: Some(1),
                    ..Default::default()
                };
                opts.path.pixel_angle_rad = scene.camera.pixel_angle_rad(height);
                let settings = opts.validate().unwrap();
                let t0 = cpu_time::ProcessTime::now();
                let (film, _) = render_with(scene, body, &settings, None).unwrap();
                cpu[v] += t0.elapsed().as_secs_f64();
                if round == 0 {
                    images[v].push(
                        (0..width * height)
                            .map(|i| f64::from(film.xyz(i % width, i / width)[1]))
                            .collect(),
                    );
                }
            }
        }
    }
    for (v, curvature) in variants.iter().enumerate() {
        let noise = render::noise::relative_noise(&images[v][0], &images[v][1]).unwrap();
        let per_round = cpu[v] / rounds as f64;
        println!(
            "{curvature:?}: {width}×{height}, {spp} spp, CPU {per_round:.2} s (two renders, mean of \
             {rounds} rounds), noise {:.3}% over {} lit pixels, noise·√(CPU-s of one render) {:.4}",
            100.0 * noise.relative_noise,
            noise.lit_pixels,
            noise.relative_noise * (per_round / 2.0).sqrt()
        );
    }
}
