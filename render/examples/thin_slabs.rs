//! Thin skin by default against the volumetric reference (BENCHMARKS.md, "Accuracy where users
//! look"; docs/accuracy_evidence.md §4): backlit slabs of each skin tone, 1, 2 and 4 mm thick (the
//! render study's thin-slab scene; `front`: lit from the camera's side instead), rendered by the BSSRDF alone (`--thin-walk 0`), by the default
//! (the walk with light sampled at its exits, `ThinExit::LightSampled`), by the walk leaving along
//! its refracted direction (`ThinExit::Refracted`) and by the volumetric reference. Per
//! configuration: the mean luminance over the frame with its standard error (variance pass), the
//! error against the reference, the process CPU seconds and the efficiency se·√CPU-s (lower is
//! better; its squared ratio is the speed-up at equal noise).
//!
//! `cargo run --release -p render --features studies --example thin_slabs -- SIDE SPP REF_SPP [TONES] [front]`

use render::fidelity::FidelityKnobs;
use render::integrator::{BodyIntegrator, IntegratorKind, PathSettings, ThinExit};
use render::material::SkinKnobs;
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let num = |i: usize, d: u32| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (side, spp, ref_spp) = (num(0, 16) as usize, num(1, 64), num(2, 64));
    if args.get(3).is_some_and(|s| s == "ear") {
        return ear(side, spp, ref_spp);
    }
    let tones: Vec<String> = args.get(3).map_or_else(
        || vec!["light".into(), "medium".into(), "dark".into()],
        |s| s.split(',').map(str::to_string).collect(),
    );
    // "front": the slabs lit from the camera's side by a sphere (the thin parts whose far face is
    // unlit keep the BSSRDF; this measures what that choice costs).
    let front = args.get(4).is_some_and(|s| s == "front");
    let light = if front {
        "type = \"sphere\"\ncenter_mm = [150, 0, 200]\nradius_mm = 60\nintensity = 3"
    } else {
        "type = \"quad\"\ncenter_mm = [0, 0, -60]\nlook_at_mm = [0, 0, 0]\nsize_mm = [200, 200]\nintensity = 5"
    };
    let dir = tempfile::tempdir()?;
    println!(
        "tone,mm,configuration,spp,mean_y,se,error_pct,error_sigma,cpu_s,se_sqrt_cpu,walked_pct"
    );
    for tone in &tones {
        for mm in [1.0f32, 2.0, 4.0] {
            let obj = dir.path().join(format!("thin{mm}.obj"));
            std::fs::write(&obj, render::volumetric::shapes::box_obj([60.0, 60.0, mm]))?;
            let toml = format!(
                "[camera]\nposition_mm = [0, 0, 300]\nlook_at_mm = [0, 0, 0]\nfov_deg = 5.7\n\
                 [environment]\nspectrum = \"d65\"\nintensity = 0.02\n\
                 [materials.skin]\ntype = \"skin\"\npreset = \"{tone}\"\nsurface = \"smooth\"\n\
                 [[meshes]]\nfile = \"{}\"\nmaterial = \"skin\"\n[[lights]]\n{light}\n",
                obj.display()
            );
            let load = |thin: Option<f64>| {
                let knobs = SkinKnobs {
                    fidelity: FidelityKnobs {
                        thin_walk_r99: thin,
                        ..FidelityKnobs::default()
                    },
                    ..SkinKnobs::default()
                };
                Scene::from_toml(&toml, "slab.toml", None, &knobs)
            };
            let default = load(None)?;
            let alone = load(Some(0.0))?;
            let reference = run(
                &default,
                &BodyIntegrator::build(&default, IntegratorKind::Volumetric),
                ThinExit::Refracted,
                side,
                ref_spp,
                2,
            )?;
            let rows = [
                (
                    "volumetric reference",
                    &default,
                    IntegratorKind::Volumetric,
                    ThinExit::Refracted,
                    ref_spp,
                ),
                (
                    "BSSRDF alone",
                    &alone,
                    IntegratorKind::Bssrdf,
                    ThinExit::LightSampled,
                    spp,
                ),
                (
                    "default (walk, light sampled at exits)",
                    &default,
                    IntegratorKind::Bssrdf,
                    ThinExit::LightSampled,
                    spp,
                ),
                (
                    "walk, refracted exits",
                    &default,
                    IntegratorKind::Bssrdf,
                    ThinExit::Refracted,
                    spp,
                ),
            ];
            for (label, scene, kind, exit, n) in rows {
                let body = BodyIntegrator::build(scene, kind);
                let r = if kind == IntegratorKind::Volumetric {
                    reference
                } else {
                    run(scene, &body, exit, side, n, 1)?
                };
                let walked = body.thin_parts().and_then(|t| t.part(0)).map_or(0.0, |p| {
                    let (t, w) = p.counts();
                    100.0 * w as f64 / t.max(1) as f64
                });
                let diff = r.y / reference.y - 1.0;
                let sigma = r.se.hypot(reference.se) / reference.y;
                println!(
                    "{tone},{mm},{label},{n},{:.5},{:.5},{:+.1},{:+.1},{:.2},{:.5},{walked:.1}",
                    r.y,
                    r.se,
                    100.0 * diff,
                    if kind == IntegratorKind::Volumetric {
                        0.0
                    } else {
                        diff / sigma
                    },
                    r.cpu,
                    r.se / r.y * r.cpu.sqrt()
                );
            }
        }
    }
    Ok(())
}

/// The built-in backlit ear (light skin, smooth surface, no albedo texture: the volumetric walk
/// has none), the camera closed in on the ear (9° field, aimed at it), so that the frame's mean is
/// the ear's region mean: the same four configurations.
fn ear(side: usize, spp: u32, ref_spp: u32) -> anyhow::Result<()> {
    let toml: String = render::builtin::EAR
        .lines()
        .filter(|l| !l.trim_start().starts_with("albedo_texture"))
        .map(|l| match l.trim() {
            "type = \"skin\"" => format!("{l}\nsurface = \"smooth\""),
            "look_at_mm = [-70, 35, -10]" => "look_at_mm = [-65, 57, 3]".to_string(),
            "fov_deg = 22" => "fov_deg = 9".to_string(),
            _ => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    let load = |thin: Option<f64>| {
        let knobs = SkinKnobs {
            fidelity: FidelityKnobs {
                thin_walk_r99: thin,
                ..FidelityKnobs::default()
            },
            ..SkinKnobs::default()
        };
        Scene::from_toml(&toml, "ear.toml", None, &knobs)
    };
    println!("configuration,spp,mean_y,se,cpu_s,se_sqrt_cpu,walked_pct");
    let default = load(None)?;
    // The reference is optional (REF_SPP 0): its heavy tail (a small light found only by refracted
    // exits) needs thousands of samples per pixel; the walk everywhere (k = 10) is the low-noise
    // comparison, checked against it within its noise.
    if ref_spp > 0 {
        let vol = BodyIntegrator::build(&default, IntegratorKind::Volumetric);
        let r = run(&default, &vol, ThinExit::Refracted, side, ref_spp, 2)?;
        println!(
            "volumetric reference,{ref_spp},{:.5},{:.5},{:.2},{:.5},0",
            r.y,
            r.se,
            r.cpu,
            r.se / r.y * r.cpu.sqrt()
        );
    }
    for (label, k, exit) in [
        ("BSSRDF alone (k 0)", Some(0.0), ThinExit::LightSampled),
        (
            "default (k 1, light sampled at exits)",
            None,
            ThinExit::LightSampled,
        ),
        ("k 1, refracted exits", None, ThinExit::Refracted),
        ("k 2", Some(2.0), ThinExit::LightSampled),
        ("k 3", Some(3.0), ThinExit::LightSampled),
        ("k 10 (walk everywhere)", Some(10.0), ThinExit::LightSampled),
    ] {
        let scene = load(k)?;
        let body = BodyIntegrator::build(&scene, IntegratorKind::Bssrdf);
        let r = run(&scene, &body, exit, side, spp, 1)?;
        let walked = body
            .thin_parts()
            .and_then(|t| (0..2).find_map(|i| t.part(i)))
            .map_or(0.0, |p| {
                let (t, w) = p.counts();
                100.0 * w as f64 / t.max(1) as f64
            });
        println!(
            "{label},{spp},{:.5},{:.5},{:.2},{:.5},{walked:.1}",
            r.y,
            r.se,
            r.cpu,
            r.se / r.y * r.cpu.sqrt()
        );
    }
    Ok(())
}

/// Mean luminance over a render, its standard error and the CPU seconds it took.
#[derive(Clone, Copy)]
struct Run {
    y: f64,
    se: f64,
    cpu: f64,
}

fn run(
    scene: &Scene,
    body: &BodyIntegrator,
    thin_exit: ThinExit,
    side: usize,
    spp: u32,
    seed: u64,
) -> anyhow::Result<Run> {
    let opts = RenderOptions {
        width: side,
        height: side,
        spp,
        seed,
        noise: None,
        path: PathSettings {
            thin_exit,
            ..PathSettings::default()
        },
        ..Default::default()
    };
    let t0 = cpu_time::ProcessTime::now();
    let (film, _) = render_with(scene, body, &opts.validate()?, None)?;
    let cpu = t0.elapsed().as_secs_f64();
    let n = (side * side) as f64;
    let (mut sum, mut var) = (0.0, 0.0);
    for y in 0..side {
        for x in 0..side {
            sum += f64::from(film.xyz(x, y)[1]);
            var += film.variance(x, y);
        }
    }
    Ok(Run {
        y: sum / n,
        se: var.sqrt() / n,
        cpu,
    })
}
