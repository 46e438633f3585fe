//! CPU and wall time of loading a scene as `skin render` does (the scene with its skin tables
//! through the disk cache, then the integrator's state), repeated: with a warm cache every load
//! after the first is a cached load. Reads the process's CPU time (`cpu-time`), so the figure
//! holds on a loaded machine; the wall time does not.
//!
//! `SKIN_CACHE_DIR=DIR cargo run --release -p render --features studies --example scene_load --
//! [SCENE] [HEIGHT] [REPEATS]` (default `builtin:three-heads`, 384 pixels, 2 loads).

use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::SkinKnobs;
use render::scene::Scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = args.first().map_or("builtin:three-heads", String::as_str);
    let height: u32 = args.get(1).map_or(Ok(384), |s| s.parse())?;
    let repeats: usize = args.get(2).map_or(Ok(2), |s| s.parse())?;
    let mut knobs = SkinKnobs::default();
    // As `skin render --height HEIGHT`: the pixel footprint picks the shape tables' photons.
    knobs.fidelity.image_height = Some(height);
    for i in 1..=repeats {
        let (cpu, wall) = (cpu_time::ProcessTime::now(), std::time::Instant::now());
        let loaded = Scene::load(scene, &knobs)?;
        let body = BodyIntegrator::build(&loaded, IntegratorKind::Bssrdf);
        println!(
            "load {i} of {scene}: {:.2} s wall, {:.2} CPU-s",
            wall.elapsed().as_secs_f64(),
            cpu.elapsed().as_secs_f64()
        );
        drop((body, loaded));
    }
    Ok(())
}
