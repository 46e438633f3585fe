//! Speed of the volumetric reference (BENCHMARKS.md, "Volumetric reference"): camera paths per
//! CPU-second on a homogeneous 10-mm sphere of light skin's dermis (one layer: the epidermis given
//! the dermis' coefficients) under a uniform sky, at one wavelength and over the spectrum; and the
//! cost of the epidermis test (distance to the head mesh) against a BVH ray cast.
//!
//! `cargo run --release -p render --features studies --example volumetric_speed [SKIN_SPP]`: with
//! SKIN_SPP, only the two-layer skin sphere of the Mitsuba comparison, at that many samples per pixel
//! on one thread (for profiles).

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::SkinKnobs;
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;
use render::volumetric::{SkinVolume, Volumetric};

fn main() -> anyhow::Result<()> {
    let sphere = "[camera]\nposition_mm = [0, 0, 60]\nlook_at_mm = [0, 0, 0]\nfov_deg = 20\n\
                  [environment]\nspectral_radiance = 1\n\
                  [materials.skin]\ntype = \"skin\"\npreset = \"light\"\nsurface = \"smooth\"\n\
                  [[meshes]]\nshape = \"sphere\"\nmaterial = \"skin\"\nunits_mm = 10\n";
    let scene = Scene::from_toml(sphere, "sphere.toml", None, &SkinKnobs::default())?;
    // The Mitsuba comparison's skin (mitsuba_side_by_side): two layers, isotropic phase.
    let skin_sphere = sphere
        .replace(
            "preset = \"light\"",
            "melanin = 0.05\neumelanin = 0.7\nhemoglobin = 0.02\nphase_g = 0",
        )
        .replace("fov_deg = 20", "fov_deg = 24");
    let skin_scene = Scene::from_toml(&skin_sphere, "skin.toml", None, &SkinKnobs::default())?;
    {
        let body = BodyIntegrator::build(&skin_scene, IntegratorKind::Volumetric);
        let only: Option<u32> = std::env::args().nth(1).map(|s| s.parse()).transpose()?;
        let opts = RenderOptions {
            width: 64,
            height: 64,
            spp: only.unwrap_or(8),
            seed: 1,
            wavelength_nm: Some(550.0),
            threads: only.map(|_| 1),
            ..Default::default()
        };
        let settings = opts.validate()?;
        let t0 = cpu_time::ProcessTime::now();
        let (_, stats) = render_with(&skin_scene, &body, &settings, None)?;
        let cpu = t0.elapsed().as_secs_f64();
        let paths = f64::from(64 * 64 * settings.spp);
        println!(
            "skin sphere (C_m 0.05, β_m 0.7, C_h 0.02, g 0), 550 nm: {:.0} camera paths per CPU-s, {:.2} µs each ({:.1} rays per path; {cpu:.2} CPU s)",
            paths / cpu,
            cpu / paths * 1e6,
            stats.rays as f64 / paths
        );
        if only.is_some() {
            return Ok(());
        }
    }
    let two_layer = Volumetric::build(&scene);
    // Homogeneous: both layers the dermis.
    let mut homogeneous = two_layer.clone();
    if let Some(Some(m)) = homogeneous.media.first_mut() {
        m.epidermis = m.dermis.clone();
    }
    let side = 64;
    for (label, nm) in [("550 nm", Some(550.0)), ("spectral", None)] {
        for (what, vol) in [
            ("homogeneous", homogeneous.clone()),
            ("two-layer", two_layer.clone()),
        ] {
            let body = BodyIntegrator::Volumetric(vol);
            let opts = RenderOptions {
                width: side,
                height: side,
                spp: 8,
                seed: 1,
                wavelength_nm: nm,
                ..Default::default()
            };
            let t0 = cpu_time::ProcessTime::now();
            let (_, stats) = render_with(&scene, &body, &opts.validate()?, None)?;
            let cpu = t0.elapsed().as_secs_f64();
            let paths = (side * side * 8) as f64;
            println!(
                "{what} sphere, {label}: {:.0} camera paths per CPU-s ({:.3} M rays per CPU-s; {cpu:.2} CPU s, {:.2} s wall)",
                paths / cpu,
                stats.rays as f64 / cpu / 1e6,
                stats.elapsed.as_secs_f64()
            );
        }
    }
    distance_cost()?;
    Ok(())
}

/// CPU ns per epidermis test on the head, beside one closest-hit ray cast.
fn distance_cost() -> anyhow::Result<()> {
    let head = Scene::load("builtin:ear", &SkinKnobs::default())?;
    let BodyIntegrator::Volumetric(Volumetric { media }) =
        BodyIntegrator::build(&head, IntegratorKind::Volumetric)
    else {
        anyhow::bail!("no media");
    };
    let skin: &SkinVolume = media
        .iter()
        .flatten()
        .next()
        .ok_or_else(|| anyhow::anyhow!("no skin"))?;
    let tris = head.geometry.triangles_of(0);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(1);
    // Points near the surface: a triangle's centroid moved by up to ±1 mm along its normal.
    let points: Vec<Vec3> = (0..1_000_000)
        .map(|_| {
            let t = tris[rng.random_range(0..tris.len())];
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            (t[0] + t[1] + t[2]) / 3.0 + n * rng.random_range(-1.0..1.0)
        })
        .collect();
    let t0 = cpu_time::ProcessTime::now();
    let inside = points
        .iter()
        .filter(|&&p| skin.epidermis_region.within(p.as_dvec3()))
        .count();
    let dt = t0.elapsed().as_secs_f64();
    let t1 = cpu_time::ProcessTime::now();
    let mut hits = 0usize;
    for p in &points {
        let d = Vec3::new(rng.random(), rng.random(), rng.random()) - 0.5;
        hits += usize::from(
            head.geometry
                .intersect(*p, d.normalize_or(Vec3::Z), 1e-3, f32::INFINITY)
                .is_some(),
        );
    }
    let dr = t1.elapsed().as_secs_f64();
    let (cells, entries) = skin.epidermis_region.size();
    println!(
        "epidermis test on the head ({} triangles, grid {cells} cells, {entries} entries): {:.0} ns per query ({inside} of 10⁶ within d_epi); closest-hit ray: {:.0} ns ({hits} hits)",
        tris.len(),
        dt * 1e9 / points.len() as f64,
        dr * 1e9 / points.len() as f64
    );
    Ok(())
}
