//! Thin skin by default against the volumetric reference (BENCHMARKS.md, "Accuracy where users
//! look"; docs/accuracy_evidence.md §4): backlit slabs of each skin tone, 1, 2 and 4 mm thick (the
//! render study's thin-slab scene; `front`: lit from the camera's side instead), rendered by the BSSRDF alone (`--thin-walk 0`), by the default
//! (the walk with light sampled at its exits, `ThinExit::LightSampled`), by the walk leaving along
//! its refracted direction (`ThinExit::Refracted`) and by the volumetric reference. Per
//! configuration: the mean luminance over the frame with its standard error (variance pass), the
//! error against the reference, the process CPU seconds and the efficiency se·√CPU-s (lower is
//! better; its squared ratio is the speed-up at equal noise).
//!
//! `ear` instead of the tones: the built-in ear close-up, split into its thin and thick regions;
//! `lamp`: a thick box under the ear's back light.
//!
//! `cargo run --release -p render --features studies --example thin_slabs -- SIDE SPP REF_SPP [TONES|ear|lamp] [front]`

use render::fidelity::FidelityKnobs;
use render::geometry::offset_origin;
use render::integrator::{BodyIntegrator, IntegratorKind, PathSettings, ThinExit};
use render::material::SkinKnobs;
use render::renderer::{RenderOptions, render_with};
use render::scene::{Hit, Scene};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let num = |i: usize, d: u32| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (side, spp, ref_spp) = (num(0, 16) as usize, num(1, 64), num(2, 64));
    if args.get(3).is_some_and(|s| s == "ear") {
        return ear(side, spp, ref_spp);
    }
    if args.get(3).is_some_and(|s| s == "lamp") {
        return thick_under_the_ears_lamp(side, spp, ref_spp);
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
            let load = |thin: Option<f64>| load_scene(&toml, "slab.toml", thin);
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
                    reference.clone()
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
/// has none), the camera closed in on the ear (9° field, aimed at it). Besides the frame's mean,
/// each configuration's mean over two regions split by the pixel centre's geometry: "thin", where
/// a probe along the inward normal meets the skin again within 10 mm (the ear's rim and helix),
/// and "thick", the rest (the head behind the ear, much of it lit directly by the back light).
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
    let load = |thin: Option<f64>| load_scene(&toml, "ear.toml", thin);
    let default = load(None)?;
    let thin_px = thin_pixels(&default, side);
    println!(
        "configuration,spp,mean_y,se,thin_px,thin_y,thin_se,thick_y,thick_se,cpu_s,walked_pct"
    );
    let print = |label: &str, n: u32, r: &Run, walked: f64| {
        let (thin, thick) = (r.region(&thin_px, true), r.region(&thin_px, false));
        println!(
            "{label},{n},{:.5},{:.5},{},{:.5},{:.5},{:.5},{:.5},{:.2},{walked:.1}",
            r.y,
            r.se,
            thin_px.iter().filter(|&&t| t).count(),
            thin.0,
            thin.1,
            thick.0,
            thick.1,
            r.cpu
        );
    };
    // The reference is optional (REF_SPP 0): its heavy tail (a small light found only by refracted
    // exits) needs thousands of samples per pixel.
    if ref_spp > 0 {
        let vol = BodyIntegrator::build(&default, IntegratorKind::Volumetric);
        let r = run(&default, &vol, ThinExit::Refracted, side, ref_spp, 2)?;
        print("volumetric reference", ref_spp, &r, 0.0);
    }
    for (label, k, exit) in [
        ("BSSRDF alone", Some(0.0), ThinExit::LightSampled),
        (
            "default (walk, light sampled at exits)",
            None,
            ThinExit::LightSampled,
        ),
        ("walk, refracted exits", None, ThinExit::Refracted),
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
        print(label, spp, &r, walked);
    }
    Ok(())
}

/// A 20-mm-thick box of the ear's light skin (smooth surface) under the ear's back light (the
/// 25-mm blackbody sphere, 60° off the normal, 230 mm away), seen at 45° from the other side: the
/// BSSRDF alone against the volumetric reference on thick, directly lit skin, the ear close-up's
/// thick region without its curvature.
fn thick_under_the_ears_lamp(side: usize, spp: u32, ref_spp: u32) -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let obj = dir.path().join("box.obj");
    std::fs::write(
        &obj,
        render::volumetric::shapes::box_obj([60.0, 60.0, 20.0]),
    )?;
    let toml = format!(
        "[camera]\nposition_mm = [212, 0, 222]\nlook_at_mm = [0, 0, 10]\nfov_deg = 5\n\
         [environment]\nspectrum = \"d65\"\nintensity = 0.005\n\
         [materials.skin]\ntype = \"skin\"\npreset = \"light\"\nsurface = \"smooth\"\n\
         [[meshes]]\nfile = \"{}\"\nmaterial = \"skin\"\n[[lights]]\ntype = \"sphere\"\n\
         center_mm = [-200, 0, 125]\nradius_mm = 25\nspectrum = \"blackbody\"\n\
         temperature_k = 5000\nintensity = 400\n",
        obj.display()
    );
    let scene = Scene::from_toml(&toml, "lamp.toml", None, &SkinKnobs::default())?;
    println!("configuration,spp,mean_y,se,cpu_s");
    for (label, kind, n, seed) in [
        ("BSSRDF", IntegratorKind::Bssrdf, spp, 1),
        (
            "volumetric reference",
            IntegratorKind::Volumetric,
            ref_spp,
            2,
        ),
    ] {
        let body = BodyIntegrator::build(&scene, kind);
        let r = run(&scene, &body, ThinExit::Refracted, side, n, seed)?;
        println!("{label},{n},{:.5},{:.5},{:.2}", r.y, r.se, r.cpu);
    }
    Ok(())
}

/// The scene `toml` (named `name` in errors) with the thin-part walk at `thin` r₉₉ (`None`: the
/// default).
fn load_scene(
    toml: &str,
    name: &str,
    thin: Option<f64>,
) -> Result<Scene, render::error::RenderError> {
    let knobs = SkinKnobs {
        fidelity: FidelityKnobs {
            thin_walk_r99: thin,
            ..FidelityKnobs::default()
        },
        ..SkinKnobs::default()
    };
    Scene::from_toml(toml, name, None, &knobs)
}

/// Per pixel (row-major), whether the camera ray through its centre hits skin whose inward
/// normal meets the skin again within 10 mm.
fn thin_pixels(scene: &Scene, side: usize) -> Vec<bool> {
    let mut thin = Vec::with_capacity(side * side);
    for y in 0..side {
        for x in 0..side {
            let (o, d) = render::testing::pixel_ray(scene, side, x, y);
            let t = match scene.intersect(o, d, 0.0, f32::INFINITY) {
                Some(Hit::Surface(si)) => {
                    let ng = if si.ng.dot(d) > 0.0 { -si.ng } else { si.ng };
                    scene
                        .geometry
                        .intersect(offset_origin(si.p, ng, -ng), -ng, 0.0, 10.0)
                        .is_some_and(|f| f.material == si.material)
                }
                _ => false,
            };
            thin.push(t);
        }
    }
    thin
}

/// Mean luminance over a render, its standard error and the CPU seconds it took, with each
/// pixel's luminance and variance of its mean.
#[derive(Clone)]
struct Run {
    y: f64,
    se: f64,
    cpu: f64,
    pixels: Vec<(f64, f64)>,
}

impl Run {
    /// (mean, standard error) over the pixels whose `mask` entry is `inside`.
    fn region(&self, mask: &[bool], inside: bool) -> (f64, f64) {
        let (mut n, mut sum, mut var) = (0.0, 0.0, 0.0);
        for (&(y, v), &m) in self.pixels.iter().zip(mask) {
            if m == inside {
                n += 1.0;
                sum += y;
                var += v;
            }
        }
        (sum / f64::max(n, 1.0), var.sqrt() / f64::max(n, 1.0))
    }
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
    let mut pixels = Vec::with_capacity(side * side);
    for y in 0..side {
        for x in 0..side {
            pixels.push((f64::from(film.xyz(x, y)[1]), film.variance(x, y)));
        }
    }
    let sum: f64 = pixels.iter().map(|p| p.0).sum();
    let var: f64 = pixels.iter().map(|p| p.1).sum();
    Ok(Run {
        y: sum / n,
        se: var.sqrt() / n,
        cpu,
        pixels,
    })
}
