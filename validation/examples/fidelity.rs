//! Render time and error of the automatic fidelity against `--fidelity full`, on the far view
//! (`builtin:three-heads-far`, fifteen heads about 40 px tall) and the close-up (`builtin:ear`).
//!
//! Three questions, one table (OUT/fidelity.csv, chart OUT/fidelity.png, each render's PNG):
//! - **Where the time goes** at a fixed sample count: full fidelity, auto, auto with a narrower
//!   level-of-detail band, the level of detail forced on at every skin hit (`collapsed`), and no
//!   subsurface at all (`--no-subsurface`, the Lambertian stand-in: the floor the level of detail
//!   cannot go below).
//! - **Time to the same noise**, what a default render (a per-pixel noise target) costs: full,
//!   auto, narrow and collapsed rendered to the same noise target, their CPU time compared.
//! - **Error** of each against a full-fidelity reference at four times the samples (seed 1):
//!   relative RMS over the image's cells (5 × 3 for the far view, one head each; the whole frame
//!   for the ear) of the mean skin luminance Y; the per-pixel relative RMS over skin pixels; and
//!   χ² per skin pixel, (a − b)² / (σa² + σb²) from each render's own variance of the mean: 1 when
//!   the two differ by noise alone, above 1 by the share of a bias (shadow-edge bleeding the
//!   stand-in does not have would show here, where the cell mean averages it out).
//!
//! Time: process CPU time of the render (`cpu-time`), so it holds on a loaded machine. Each
//! configuration has its own seed, so no two renders share their noise.
//!
//! OUT/lod_ratios.csv: for each skin of the far view, the 99% energy radius at 450, 550 and 650 nm
//! (blue, green, red), the largest over the table's rows and the luminance-weighted one (what the
//! level of detail uses, docs/physics.md §16.3), and the
//! ratio of the pixel footprint at the skin's mean camera distance to each.
//!
//! The default scene's uniform heads (`builtin:three-heads-uniform`, three cells, one head each) at SPP_DEFAULT: full,
//! auto, and auto with the 500,000-photon shape table (SPP_DEFAULT 0 skips it).
//!
//! `cargo run --release -p render --features studies --example fidelity -- [OUT] [SPP_FAR] [SPP_EAR] [NOISE] [MAX_SPP]
//! [SPP_DEFAULT]` (default out/fidelity, 64, 16, 0.1, 4096, 8; MAX_SPP 0 skips the renders to the
//! noise target)

use render::fidelity::{Fidelity, FidelityKnobs, LodBand, LodSetting};
use render::film::Film;
use render::integrator::PathSettings;
use render::material::Material;
use render::material::SkinKnobs;
use render::passes::Passes;
use render::renderer::{RenderOptions, render};
use render::scene::Scene;
use skin_plot::{LineChart, Panel, Series, save_png};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

const WIDTH: usize = 768;
const HEIGHT: usize = 384;

/// One configuration to render.
struct Config {
    label: &'static str,
    opts: SkinKnobs,
    seed: u64,
    spp: u32,
    noise: Option<f64>,
    max_spp: u32,
}

impl Config {
    /// `spp` samples in every pixel (no noise target).
    fn fixed(label: &'static str, opts: SkinKnobs, seed: u64, spp: u32) -> Self {
        Self {
            label,
            opts,
            seed,
            spp,
            noise: None,
            max_spp: spp,
        }
    }
}

/// One rendered configuration.
struct Run {
    label: &'static str,
    spp: u32,
    noise: Option<f64>,
    mean_spp: f64,
    luminance: Vec<f64>,
    variance: Vec<f64>,
    cpu_s: f64,
    load_s: f64,
}

fn knobs(fidelity: Fidelity, lod: LodSetting, no_subsurface: bool) -> SkinKnobs {
    SkinKnobs {
        fidelity: FidelityKnobs {
            fidelity: Some(fidelity),
            lod,
            // The footprint the shape photons are chosen from.
            image_height: Some(HEIGHT as u32),
            ..FidelityKnobs::default()
        },
        no_subsurface,
        ..SkinKnobs::default()
    }
}

fn band(full_below: f32, diffuse_above: f32) -> LodSetting {
    LodSetting::Band(LodBand {
        full_below,
        diffuse_above,
    })
}

fn render_one(spec: &str, c: &Config, out: &Path) -> Run {
    let t0 = Instant::now();
    let scene = Scene::load(spec, &c.opts).expect("built-in scenes load");
    let load_s = t0.elapsed().as_secs_f64();
    let settings = RenderOptions {
        width: WIDTH,
        height: HEIGHT,
        spp: c.noise.map_or(c.spp, |_| c.max_spp),
        seed: c.seed,
        noise: c.noise,
        time_limit: None,
        path: PathSettings {
            pixel_angle_rad: scene.camera.pixel_angle_rad(HEIGHT),
            ..PathSettings::default()
        },
        ..Default::default()
    }
    .validate()
    .expect("valid settings");
    let cpu = cpu_time::ProcessTime::now();
    let (film, stats) = render(&scene, &settings).expect("render");
    let cpu_s = cpu.elapsed().as_secs_f64();
    let name = spec.trim_start_matches("builtin:");
    film.write_png(
        &out.join(format!("{name}-{}.png", c.label)),
        scene.exposure_stops,
    )
    .expect("write png");
    eprintln!(
        "{spec} {}: load {load_s:.2} s, render {cpu_s:.1} CPU-s, mean {:.1} spp",
        c.label, stats.mean_spp
    );
    Run {
        label: c.label,
        spp: c.spp,
        noise: c.noise,
        mean_spp: stats.mean_spp,
        luminance: per_pixel(&film, |f, x, y| f64::from(f.xyz(x, y)[1])),
        variance: per_pixel(&film, Film::variance),
        cpu_s,
        load_s,
    }
}

fn per_pixel(film: &Film, f: impl Fn(&Film, usize, usize) -> f64) -> Vec<f64> {
    (0..HEIGHT)
        .flat_map(|y| (0..WIDTH).map(move |x| (x, y)))
        .map(|(x, y)| f(film, x, y))
        .collect()
}

/// How `run` differs from `reference` over the skin pixels.
struct Errors {
    /// Relative RMS over the cells of the mean skin luminance.
    cell: f64,
    /// Per-pixel relative RMS.
    pixel: f64,
    /// Mean of (a − b)² / (σa² + σb²).
    chi2: f64,
    /// RMS relative noise of the run's own skin pixels (σ of the mean / mean).
    noise: f64,
}

fn errors(run: &Run, reference: &Run, skin: &[bool], nx: usize, ny: usize) -> Errors {
    let mut cells = vec![(0.0, 0.0, 0usize); nx * ny];
    let (mut sq, mut sum_ref, mut chi2, mut noise2, mut n) = (0.0, 0.0, 0.0, 0.0, 0usize);
    for (i, _) in skin.iter().enumerate().filter(|(_, s)| **s) {
        let (a, b) = (run.luminance[i], reference.luminance[i]);
        let c = &mut cells[((i / WIDTH) * ny / HEIGHT) * nx + (i % WIDTH) * nx / WIDTH];
        c.0 += a;
        c.1 += b;
        c.2 += 1;
        sq += (a - b).powi(2);
        sum_ref += b;
        let var = run.variance[i] + reference.variance[i];
        if var > 0.0 {
            chi2 += (a - b).powi(2) / var;
        }
        if a > 0.0 {
            noise2 += run.variance[i] / (a * a);
        }
        n += 1;
    }
    let rel: Vec<f64> = cells
        .iter()
        .filter(|c| c.2 > 0 && c.1 > 0.0)
        .map(|c| c.0 / c.1 - 1.0)
        .collect();
    let n = n.max(1) as f64;
    Errors {
        cell: (rel.iter().map(|r| r * r).sum::<f64>() / rel.len().max(1) as f64).sqrt(),
        pixel: (sq / n).sqrt() / (sum_ref / n),
        chi2: chi2 / n,
        noise: (noise2 / n).sqrt(),
    }
}

/// The far view's configurations: the reference, where the time goes at `spp`, and time to the
/// noise target `noise` with at most `max_spp` samples a pixel (0: not rendered to the target).
fn far_configs(spp: u32, noise: f64, max_spp: u32) -> Vec<Config> {
    let full = || knobs(Fidelity::Full, LodSetting::ByFidelity, false);
    let auto = || knobs(Fidelity::Auto, LodSetting::ByFidelity, false);
    let narrow = || knobs(Fidelity::Auto, band(0.25, 1.0), false);
    // A band far below any footprint: every skin hit takes the diffuse body.
    let collapsed = || knobs(Fidelity::Auto, band(1e-4, 2e-4), false);
    let fixed = |label, opts, seed| Config {
        label,
        opts,
        seed,
        spp,
        noise: None,
        max_spp,
    };
    let target = |label, opts, seed| Config {
        label,
        opts,
        seed,
        spp,
        noise: Some(noise),
        max_spp,
    };
    let mut configs = vec![
        Config {
            spp: 4 * spp,
            ..fixed("full-reference", full(), 1)
        },
        fixed("full", full(), 2),
        fixed("auto", auto(), 3),
        fixed("auto-band-0.25-1", narrow(), 4),
        fixed("collapsed", collapsed(), 5),
        fixed(
            "no-subsurface",
            knobs(Fidelity::Auto, LodSetting::Off, true),
            6,
        ),
    ];
    if max_spp > 0 {
        configs.extend([
            target("full-to-noise", full(), 7),
            target("auto-to-noise", auto(), 8),
            target("collapsed-to-noise", collapsed(), 10),
        ]);
    }
    configs
}

/// The close-up's configurations (all at `spp`, the reference at four times as many).
fn ear_configs(spp: u32) -> Vec<Config> {
    let full = knobs(Fidelity::Full, LodSetting::ByFidelity, false);
    let config = Config::fixed;
    vec![
        config("full-reference", full, 1, 4 * spp),
        config("full", full, 2, spp),
        config(
            "auto",
            knobs(Fidelity::Auto, LodSetting::ByFidelity, false),
            3,
            spp,
        ),
        config(
            "auto-band-0.25-1",
            knobs(Fidelity::Auto, band(0.25, 1.0), false),
            4,
            spp,
        ),
    ]
}

/// The default scene's configurations (all at `spp`, the reference at four times as many): full,
/// auto, and auto with the full fidelity's 500,000-photon shape table instead of the one the
/// footprint picks, so the table's share of auto's error shows alone.
fn default_configs(spp: u32) -> Vec<Config> {
    let full = knobs(Fidelity::Full, LodSetting::ByFidelity, false);
    let auto = knobs(Fidelity::Auto, LodSetting::ByFidelity, false);
    let mut photons_500k = knobs(Fidelity::Auto, LodSetting::ByFidelity, false);
    photons_500k.fidelity.shape_photons = Some(500_000);
    let config = Config::fixed;
    vec![
        config("full-reference", full, 1, 4 * spp),
        config("full", full, 2, spp),
        config("auto", auto, 3, spp),
        config("auto-photons-500k", photons_500k, 4, spp),
    ]
}

/// OUT/lod_ratios.csv: per skin of `spec`, the 99% radius per colour and the pixel footprint over it.
fn lod_ratios(spec: &str, out: &Path) -> String {
    let full = knobs(Fidelity::Full, LodSetting::ByFidelity, false);
    let scene = Scene::load(spec, &full).expect("built-in scenes load");
    // The mean camera distance of the skin the camera sees.
    let passes = Passes::first_hit(&scene, WIDTH, HEIGHT);
    let depths: Vec<f32> = (passes.skin.iter().zip(&passes.depth))
        .filter(|(s, _)| **s > 0.5)
        .map(|(_, d)| *d)
        .collect();
    let distance_mm = depths.iter().sum::<f32>() / depths.len().max(1) as f32;
    let footprint_mm = scene.camera.pixel_angle_rad(HEIGHT) * distance_mm;
    let mut csv = String::from(
        "material,footprint_mm,r99_450_mm,r99_550_mm,r99_650_mm,r99_largest_mm,r99_luminance_mm,\
         ratio_450,ratio_550,ratio_650,ratio_largest,ratio_luminance\n",
    );
    for (name, m) in scene.material_names.iter().zip(&scene.materials) {
        let Material::Skin(skin) = m else { continue };
        let Some(ss) = &skin.subsurface else { continue };
        // The inverse CDF at 0.99 of a row is its 99% energy radius.
        let r: Vec<f32> = [450.0, 550.0, 650.0]
            .iter()
            .map(|&nm| ss.table.sample_radius(nm, 0.99))
            .chain(std::iter::once(ss.table.largest_radius_for_energy_mm(0.99)))
            .chain(std::iter::once(
                ss.table.luminance_radius_for_energy_mm(0.99),
            ))
            .collect();
        let _ = write!(csv, "{name},{footprint_mm:.3}");
        for x in &r {
            let _ = write!(csv, ",{x:.3}");
        }
        for x in &r {
            let _ = write!(csv, ",{:.2}", footprint_mm / x);
        }
        csv.push('\n');
    }
    skin_io::atomic::write_bytes(&out.join("lod_ratios.csv"), csv.as_bytes()).expect("write csv");
    csv
}

fn main() {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().unwrap_or_else(|| "out/fidelity".into()));
    let mut next = |default: f64| {
        args.next()
            .map_or(default, |s| s.parse().expect("a number"))
    };
    let (spp_far, spp_ear, noise) = (next(64.0) as u32, next(16.0) as u32, next(0.1));
    let max_spp = next(4096.0) as u32;
    let spp_default = next(8.0) as u32;
    std::fs::create_dir_all(&out).expect("create OUT");
    print!("{}", lod_ratios("builtin:three-heads-far", &out));
    let mut csv = String::from(
        "scene,config,spp,noise_target,mean_spp,load_s,render_cpu_s,speedup,cell_rel_rms,\
         pixel_rel_rms,chi2,skin_noise,cpu_s_to_skin_noise,speedup_to_skin_noise,pixel_noise,\
         cpu_s_to_pixel_noise,speedup_to_pixel_noise,skin_pixels\n",
    );
    let mut chart = LineChart::new(
        "Automatic fidelity against --fidelity full",
        "render CPU time, s",
        "relative RMS of mean skin luminance per cell",
    );
    let mut worst: f64 = 0.0;
    for (spec, nx, ny, configs) in [
        (
            "builtin:three-heads-far",
            5,
            3,
            far_configs(spp_far, noise, max_spp),
        ),
        ("builtin:ear", 1, 1, ear_configs(spp_ear)),
        (
            "builtin:three-heads-uniform",
            3,
            1,
            default_configs(spp_default),
        ),
    ]
    .into_iter()
    .filter(|(_, _, _, c)| c.iter().all(|c| c.spp > 0))
    {
        let runs: Vec<Run> = configs.iter().map(|c| render_one(spec, c, &out)).collect();
        let scene = Scene::load(spec, &configs[0].opts).expect("built-in scenes load");
        let skin: Vec<bool> = Passes::first_hit(&scene, WIDTH, HEIGHT)
            .skin
            .iter()
            .map(|&s| s > 0.5)
            .collect();
        let skin_pixels = skin.iter().filter(|&&s| s).count();
        let (mut fixed, mut targeted) = (Vec::new(), Vec::new());
        // CPU time at which uniform sampling at the run's cost per sample brings the skin pixels'
        // RMS relative noise to the target: noise² falls as 1/samples, time grows with them.
        let to_noise = |run: &Run, e: &Errors| run.cpu_s * (e.noise / noise).powi(2);
        let full = runs[1..].iter().find(|r| r.label == "full");
        let full_errors = full.map(|r| errors(r, &runs[0], &skin, nx, ny));
        let full_to_noise = full.zip(full_errors.as_ref()).map(|(r, e)| to_noise(r, e));
        // The same from the measured difference to the reference: full at n samples against the
        // reference at 4n has pixel_rel² = σ² + σ²/4, so the reference's own share is
        // pixel_rel²(full) / 5; what is left of a run's pixel_rel² is its noise (and any bias).
        let reference_noise2 = full_errors.as_ref().map_or(0.0, |e| e.pixel.powi(2) / 5.0);
        let pixel_noise = |e: &Errors| (e.pixel.powi(2) - reference_noise2).max(0.0).sqrt();
        let to_pixel_noise = |run: &Run, e: &Errors| run.cpu_s * (pixel_noise(e) / noise).powi(2);
        let full_to_pixel_noise = full
            .zip(full_errors.as_ref())
            .map(|(r, e)| to_pixel_noise(r, e));
        for run in &runs[1..] {
            let e = errors(run, &runs[0], &skin, nx, ny);
            let t_noise = to_noise(run, &e);
            // Speed-up against full fidelity under the same stop rule.
            let base = runs[1..]
                .iter()
                .find(|r| r.label.starts_with("full") && r.noise == run.noise)
                .map_or(run.cpu_s, |r| r.cpu_s);
            let _ = writeln!(
                csv,
                "{spec},{},{},{},{:.1},{:.3},{:.2},{:.3},{:.5},{:.5},{:.3},{:.5},{:.1},{:.2},{:.5},{:.1},{:.2},\
                 {skin_pixels}",
                run.label,
                run.spp,
                run.noise.map_or("none".into(), |n| n.to_string()),
                run.mean_spp,
                run.load_s,
                run.cpu_s,
                base / run.cpu_s,
                e.cell,
                e.pixel,
                e.chi2,
                e.noise,
                t_noise,
                full_to_noise.map_or(1.0, |t| t / t_noise),
                pixel_noise(&e),
                to_pixel_noise(run, &e),
                full_to_pixel_noise.map_or(1.0, |t| t / to_pixel_noise(run, &e)),
            );
            if run.label != "no-subsurface" {
                let points = if run.noise.is_some() {
                    &mut targeted
                } else {
                    &mut fixed
                };
                points.push((run.cpu_s, e.cell));
                worst = worst.max(e.cell);
            }
        }
        let name = spec.trim_start_matches("builtin:");
        chart = chart.with_series(Series::scatter(format!("{name}, fixed spp"), fixed));
        if !targeted.is_empty() {
            chart = chart.with_series(Series::scatter(format!("{name}, to noise"), targeted));
        }
    }
    // From 0, with headroom above the worst point for the legend (upper right), so no point sits
    // on the frame or under the legend.
    chart = chart.with_y_range(0.0, 1.7 * worst.max(1e-3));
    skin_io::atomic::write_bytes(&out.join("fidelity.csv"), csv.as_bytes()).expect("write csv");
    save_png(&out.join("fidelity.png"), &[Panel::Line(chart)], 900, 500).expect("write chart");
    print!("{csv}");
}
