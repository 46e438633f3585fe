//! Which pixels do not reach the noise target: a scene rendered with the adaptive stop at a fixed
//! most samples per pixel (no time limit, so the answer does not depend on the machine's load),
//! and every pixel that took them all counted by where its camera ray lands: the image's third
//! (the three heads), skin or not, a thin-epidermis texel or not, and whether the pixel is dark
//! (below 15% of the 95th-percentile luminance, where the target is absolute). Writes the counts
//! as CSV to stdout and `stop_map.png` (the image, pixels that did not stop in red) to OUT.
//!
//! `cargo run --release -p render --features studies --example stop_map -- [SCENE] [SPP] [OUT]`
//! (default `builtin:three-heads-maps`, 52 — the maps scene's mean in 60 s on the quiet machine —
//! and `out/stop_map`); environment `THIN_WALK=0` turns the thin-part walk off.

use render::fidelity::FidelityKnobs;
use render::integrator::BodyIntegrator;
use render::material::{Material, SkinKnobs};
use render::renderer::{RenderOptions, render_with};
use render::scene::{Hit, Scene};
use std::collections::BTreeMap;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene_name = args
        .first()
        .cloned()
        .unwrap_or_else(|| "builtin:three-heads-maps".into());
    let spp: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(52);
    let out = std::path::PathBuf::from(args.get(2).map_or("out/stop_map", String::as_str));
    std::fs::create_dir_all(&out)?;
    let (width, height) = (768usize, 384usize);
    let fidelity = FidelityKnobs {
        image_height: Some(height as u32),
        thin_walk_r99: std::env::var("THIN_WALK").ok().and_then(|s| s.parse().ok()),
        ..FidelityKnobs::default()
    };
    let scene = Scene::load(
        &scene_name,
        &SkinKnobs {
            fidelity,
            ..SkinKnobs::default()
        },
    )?;
    let mut options = RenderOptions {
        width,
        height,
        spp,
        noise: Some(0.02),
        time_limit: None,
        seed: 1,
        ..Default::default()
    };
    options.path.pixel_angle_rad = scene.camera.pixel_angle_rad(height);
    let settings = options.validate()?;
    let body = BodyIntegrator::build(&scene, settings.integrator);
    let t0 = std::time::Instant::now();
    let (film, stats) = render_with(&scene, &body, &settings, None)?;
    eprintln!(
        "{scene_name}: {:.1} mean spp, {} of {} pixels stopped, {:.1} s",
        stats.mean_spp,
        stats.converged,
        width * height,
        t0.elapsed().as_secs_f64()
    );
    let luminance: Vec<f32> = (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| film.xyz(x, y)[1])
        .collect();
    let mut sorted = luminance.clone();
    sorted.sort_by(f32::total_cmp);
    let dark_below = 0.15 * sorted[(0.95 * (sorted.len() - 1) as f64) as usize];
    let aspect = width as f32 / height as f32;
    let mut counts: BTreeMap<(usize, &str, &str, &str), (usize, usize)> = BTreeMap::new();
    let mut png = film.to_srgb8(0.0);
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            let ndc = glam::Vec2::new(
                (x as f32 + 0.5) / width as f32,
                (y as f32 + 0.5) / height as f32,
            );
            let (o, d) = scene
                .camera
                .generate_ray(ndc, aspect, glam::Vec2::splat(0.5));
            let (kind, thin) = match scene.intersect(o, d, 0.0, f32::INFINITY) {
                Some(Hit::Surface(s)) => match &scene.materials[s.material as usize] {
                    Material::Skin(m) => {
                        let thin = m
                            .maps
                            .as_ref()
                            .and_then(|maps| maps.maps.thin())
                            .is_some_and(|t| t.is_thin(s.uv));
                        ("skin", if thin { "thin epidermis" } else { "-" })
                    }
                    _ => ("other", "-"),
                },
                _ => ("background", "-"),
            };
            let dark = if luminance[i] < dark_below {
                "dark"
            } else {
                "lit"
            };
            let stuck = film.samples(x, y) >= spp;
            let e = counts.entry((3 * x / width, kind, thin, dark)).or_default();
            e.0 += 1;
            if stuck {
                e.1 += 1;
                png[3 * i..3 * i + 3].copy_from_slice(&[255, 0, 0]);
            }
        }
    }
    println!("third,surface,epidermis,luminance,pixels,not_stopped");
    for ((third, kind, thin, dark), (n, stuck)) in &counts {
        println!("{third},{kind},{thin},{dark},{n},{stuck}");
    }
    image::save_buffer(
        out.join("stop_map.png"),
        &png,
        width as u32,
        height as u32,
        image::ColorType::Rgb8,
    )?;
    Ok(())
}
