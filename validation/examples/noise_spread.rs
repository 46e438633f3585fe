//! How unevenly the per-sample relative noise is spread over the lit pixels of a render: the bound
//! on what a fixed-budget allocation could gain on the RMS relative noise.
//!
//! With n_i samples at pixel i whose one-sample relative standard deviation is e_i, the mean
//! squared relative error over the lit pixels is mean(e_i²/n_i). Spending a fixed total N = Σ n_i
//! uniformly gives mean(e²)·P/N; spending n_i ∝ e_i (Lagrange, equal cost per sample) gives
//! mean(e)²·P/N; so the most any allocation gains in variance at equal samples is
//! E[e²]/E[e]². e_i comes from the film's variance pass (σ̂²/n, so e_i² = n · σ̂²/n / Ȳ_i²).
//!
//! `cargo run --release -p validation --features studies --example noise_spread -- [SPP] [SEED]`

use render::material::SkinKnobs;
use render::noise::lit_threshold;
use render::passes::Passes;
use render::renderer::{RenderOptions, render};
use render::scene::Scene;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let spp: u32 = args.get(1).map_or(Ok(32), |s| s.parse())?;
    let seed: u64 = args.get(2).map_or(Ok(1), |s| s.parse())?;
    let (w, h) = (768, 384);
    let scene = Scene::load("builtin:three-heads-uniform", &SkinKnobs::default())?;
    let skin = Passes::first_hit(&scene, w, h).skin;
    let settings = RenderOptions {
        width: w,
        height: h,
        spp,
        seed,
        threads: Some(1),
        path: render::integrator::PathSettings {
            pixel_angle_rad: scene.camera.pixel_angle_rad(h),
            ..Default::default()
        },
        ..Default::default()
    }
    .validate()?;
    let (film, _) = render(&scene, &settings)?;
    let y: Vec<f64> = (0..w * h)
        .map(|i| f64::from(film.xyz(i % w, i / w)[1]))
        .collect();
    let t = lit_threshold(&y);
    let n = f64::from(spp);
    for (label, keep) in [
        ("lit", Box::new(|_| true) as Box<dyn Fn(usize) -> bool>),
        ("lit skin", Box::new(|i| skin[i] > 0.5)),
        ("lit other", Box::new(|i| skin[i] <= 0.5)),
    ] {
        let e: Vec<f64> = (0..w * h)
            .filter(|&i| y[i] > 0.0 && y[i] >= t && keep(i))
            .map(|i| (n * film.variance(i % w, i / w)).sqrt() / y[i])
            .collect();
        let m = e.len() as f64;
        let e1 = e.iter().sum::<f64>() / m;
        let e2 = e.iter().map(|v| v * v).sum::<f64>() / m;
        let mut s = e.clone();
        s.sort_by(f64::total_cmp);
        let q = |p: f64| s[((m - 1.0) * p) as usize];
        println!(
            "{label:>9}: {} px, E[e] {e1:.3}, RMS e {:.3}, gain bound E[e²]/E[e]² {:.3}; \
             e quantiles 10% {:.3} 50% {:.3} 90% {:.3} 99% {:.3}",
            e.len(),
            e2.sqrt(),
            e2 / (e1 * e1),
            q(0.1),
            q(0.5),
            q(0.9),
            q(0.99)
        );
    }
    Ok(())
}
