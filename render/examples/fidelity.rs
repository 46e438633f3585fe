//! Render time and error of the automatic fidelity against `--fidelity full`, on the far view
//! (`builtin:three-heads-far`, fifteen heads about 40 px tall) and the close-up (`builtin:ear`):
//! each scene at a fixed sample count with full fidelity (seed 1: the reference; seed 2: the
//! noise floor, what a second reference differs by), auto, and auto with a narrower level-of-detail
//! band. Error: relative RMS over the image's cells (5 × 3 for the far view, one head each; the
//! whole frame for the ear) of the mean skin luminance, and the per-pixel relative RMS over skin
//! pixels. Time: process CPU time of the render (`cpu-time`), so it holds on a loaded machine.
//! Writes OUT/fidelity.csv, OUT/fidelity.png (error against render time) and each render's PNG.
//!
//! Each configuration has its own seed, so no two renders share their noise; the full-fidelity
//! render with seed 2 gives the noise floor of the error.
//!
//! `cargo run --release -p render --example fidelity -- [OUT] [SPP_FAR] [SPP_EAR]` (default
//! out/fidelity, 96, 16)

use render::fidelity::{Fidelity, FidelityKnobs, LodBand, LodSetting};
use render::integrator::PathSettings;
use render::passes::Passes;
use render::plot::{LineChart, Panel, Series, save_png};
use render::renderer::{RenderOptions, render};
use render::scene::{Scene, SceneOptions};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

const WIDTH: usize = 768;
const HEIGHT: usize = 384;

/// One rendered configuration.
struct Run {
    label: &'static str,
    luminance: Vec<f64>,
    cpu_s: f64,
    load_s: f64,
}

fn knobs(fidelity: Fidelity, lod: LodSetting) -> SceneOptions {
    SceneOptions {
        fidelity: FidelityKnobs {
            fidelity: Some(fidelity),
            lod,
            ..FidelityKnobs::default()
        },
        ..SceneOptions::default()
    }
}

fn render_one(
    spec: &str,
    label: &'static str,
    opts: &SceneOptions,
    seed: u64,
    spp: u32,
    out: &std::path::Path,
) -> Run {
    let t0 = Instant::now();
    let scene = Scene::load(spec, opts).expect("built-in scenes load");
    let load_s = t0.elapsed().as_secs_f64();
    let settings = RenderOptions {
        width: WIDTH,
        height: HEIGHT,
        spp,
        seed,
        noise: None,
        time_limit: None,
        path: PathSettings {
            pixel_angle_rad: scene.camera.pixel_angle_rad(HEIGHT),
            ..PathSettings::default()
        },
        progress: false,
        ..Default::default()
    }
    .validate()
    .expect("valid settings");
    let cpu = cpu_time::ProcessTime::now();
    let (film, _) = render(&scene, &settings).expect("render");
    let cpu_s = cpu.elapsed().as_secs_f64();
    let name = spec.trim_start_matches("builtin:");
    film.write_png(
        &out.join(format!("{name}-{label}.png")),
        scene.exposure_stops,
    )
    .expect("write png");
    let luminance = (0..HEIGHT)
        .flat_map(|y| (0..WIDTH).map(move |x| (x, y)))
        .map(|(x, y)| f64::from(film.xyz(x, y)[1]))
        .collect();
    eprintln!("{spec} {label}: load {load_s:.2} s, render {cpu_s:.1} CPU-s");
    Run {
        label,
        luminance,
        cpu_s,
        load_s,
    }
}

/// (cell relative RMS of the mean skin luminance, per-pixel relative RMS over skin) of `run`
/// against `reference`, cells `nx` × `ny`.
fn errors(run: &Run, reference: &Run, skin: &[bool], nx: usize, ny: usize) -> (f64, f64) {
    let mut cells = vec![(0.0, 0.0, 0usize); nx * ny];
    let (mut sq, mut sum_ref, mut n) = (0.0, 0.0, 0usize);
    for (i, &is_skin) in skin.iter().enumerate() {
        if !is_skin {
            continue;
        }
        let (x, y) = (i % WIDTH, i / WIDTH);
        let c = &mut cells[(y * ny / HEIGHT) * nx + x * nx / WIDTH];
        c.0 += run.luminance[i];
        c.1 += reference.luminance[i];
        c.2 += 1;
        sq += (run.luminance[i] - reference.luminance[i]).powi(2);
        sum_ref += reference.luminance[i];
        n += 1;
    }
    let rel: Vec<f64> = cells
        .iter()
        .filter(|c| c.2 > 0 && c.1 > 0.0)
        .map(|c| c.0 / c.1 - 1.0)
        .collect();
    let cell_rms = (rel.iter().map(|r| r * r).sum::<f64>() / rel.len().max(1) as f64).sqrt();
    let pixel_rms = (sq / n.max(1) as f64).sqrt() / (sum_ref / n.max(1) as f64);
    (cell_rms, pixel_rms)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().unwrap_or_else(|| "out/fidelity".into()));
    let mut spp = |default: u32| {
        args.next()
            .map_or(default, |s| s.parse().expect("SPP is a number"))
    };
    let (spp_far, spp_ear) = (spp(96), spp(16));
    std::fs::create_dir_all(&out).expect("create OUT");
    let narrow = LodSetting::Band(LodBand {
        full_below: 0.25,
        diffuse_above: 1.0,
    });
    let mut csv = String::from(
        "scene,config,spp,load_s,render_cpu_s,speedup,cell_rel_rms,pixel_rel_rms,skin_pixels\n",
    );
    let mut chart = LineChart::new(
        "Automatic fidelity against --fidelity full",
        "render CPU time, s",
        "relative RMS of mean skin luminance per cell",
    );
    let mut worst: f64 = 0.0;
    for (spec, nx, ny, spp) in [
        ("builtin:three-heads-far", 5, 3, spp_far),
        ("builtin:ear", 1, 1, spp_ear),
    ] {
        let full = knobs(Fidelity::Full, LodSetting::ByFidelity);
        let runs = [
            render_one(spec, "full", &full, 1, spp, &out),
            render_one(spec, "full-seed2", &full, 2, spp, &out),
            render_one(spec, "auto", &SceneOptions::default(), 3, spp, &out),
            render_one(
                spec,
                "auto-band-0.25-1",
                &knobs(Fidelity::Auto, narrow),
                4,
                spp,
                &out,
            ),
        ];
        let scene = Scene::load(spec, &full).expect("built-in scenes load");
        let skin: Vec<bool> = Passes::first_hit(&scene, WIDTH, HEIGHT)
            .skin
            .iter()
            .map(|&s| s > 0.5)
            .collect();
        let skin_pixels = skin.iter().filter(|&&s| s).count();
        let mut points = Vec::new();
        for run in &runs {
            let (cell, pixel) = errors(run, &runs[0], &skin, nx, ny);
            let _ = writeln!(
                csv,
                "{spec},{},{spp},{:.3},{:.2},{:.3},{cell:.5},{pixel:.5},{skin_pixels}",
                run.label,
                run.load_s,
                run.cpu_s,
                runs[0].cpu_s / run.cpu_s
            );
            if run.label != "full" {
                points.push((run.cpu_s, cell));
                worst = worst.max(cell);
            }
        }
        chart = chart.with_series(Series::scatter(spec, points));
    }
    // From 0, with headroom, so no point sits on the frame.
    chart = chart.with_y_range(0.0, 1.2 * worst.max(1e-3));
    render::atomic::write_bytes(&out.join("fidelity.csv"), csv.as_bytes()).expect("write csv");
    save_png(&out.join("fidelity.png"), &[Panel::Line(chart)], 900, 500).expect("write chart");
    print!("{csv}");
}
