//! Image noise against CPU time for a scene (`skin-validate noise-chart`): renders at fixed sample
//! counts with two seeds, the two-seed metric of `render::noise` over the lit pixels (and over
//! the skin and non-skin pixels apart, by the first-hit skin mask), for each sampling variant, so
//! each variance-reduction step is seen as noise at equal CPU time.
//!
//! CPU time (user + system of the whole process while a render runs) is the x axis, not wall
//! time: on a shared machine the wall clock depends on the other processes, the CPU time much less.
//! For an unbiased estimator noise ∝ 1/√t, so noise · √(CPU s) is the efficiency figure (lower is
//! better) and the ratio of two variants' figures squared is their speed-up at equal noise.

use cpu_time::ProcessTime;
use render::bssrdf::{ProbeAxes, RadiusWavelength};
use render::integrator::{ExitLights, PathSettings};
use render::noise::relative_noise_where;
use render::passes::Passes;
use render::renderer::{RenderOptions, render};
use render::sampler::SamplerKind;
use render::scene::Scene;
use render::spectrum::{WavelengthSampling, xyz_to_linear_srgb};
use skin_plot::{LineChart, Panel, Series, SeriesStyle, save_png};
use std::fmt::Write as _;
use std::path::Path;

/// One sampling configuration of the path tracer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variant {
    /// Legend and CSV name.
    pub name: &'static str,
    /// The path tracer's knobs.
    pub path: PathSettings,
}

/// The steps in the order they were added, each on top of the one before (the first is the
/// renderer before any of them), then two other normal-probe probabilities on top of the fourth,
/// then the splitting candidates on top of the seventh, then the radius wavelength's choice on
/// top of the tenth (two probes per skin hit), then four light-splitting budgets at the exit
/// points on top of the seventeenth (by luminance, uniform share 0.1): the twenty-fifth (budget 8)
/// is today's default.
#[must_use]
pub fn variants() -> Vec<Variant> {
    let chosen = |samples, stratified| ExitLights::Choose {
        samples,
        stratified,
    };
    let before = PathSettings {
        sampler: SamplerKind::Independent,
        wavelengths: WavelengthSampling::Uniform,
        probe_axes: ProbeAxes::PBRT,
        exit_lights: chosen(1, false),
        split_subsurface: false,
        subsurface_probes: 1,
        radius_wavelength: RadiusWavelength::HERO,
        ..PathSettings::default()
    };
    let sobol = PathSettings {
        sampler: SamplerKind::Sobol,
        ..before
    };
    let visible = PathSettings {
        wavelengths: WavelengthSampling::Visible,
        ..sobol
    };
    let split = PathSettings {
        split_subsurface: true,
        ..visible
    };
    let normal = PathSettings {
        probe_axes: ProbeAxes::DEFAULT,
        ..split
    };
    let two_lights = PathSettings {
        exit_lights: chosen(2, false),
        ..normal
    };
    let pair = PathSettings {
        sampler: SamplerKind::SobolPair,
        ..two_lights
    };
    let two_probes = PathSettings {
        subsurface_probes: 2,
        ..pair
    };
    let share = |s: f32| PathSettings {
        radius_wavelength: RadiusWavelength::new(s).unwrap_or_default(),
        ..two_probes
    };
    [
        ("before (independent + uniform λ)", before),
        ("+ Sobol", sobol),
        ("+ visible λ", visible),
        ("+ exit light at every skin hit", split),
        ("+ normal probes 0.95", normal),
        ("+ 2 light samples per exit", two_lights),
        ("+ two Sobol half-sequences", pair),
        (
            "normal probes 0.8",
            PathSettings {
                probe_axes: ProbeAxes::new(0.8).unwrap_or_default(),
                ..split
            },
        ),
        (
            "normal probes 0.9",
            PathSettings {
                probe_axes: ProbeAxes::new(0.9).unwrap_or_default(),
                ..split
            },
        ),
        (
            "+ 2 probes per skin hit",
            PathSettings {
                subsurface_probes: 2,
                ..pair
            },
        ),
        (
            "2 probes, 1 light sample each",
            PathSettings {
                subsurface_probes: 2,
                exit_lights: chosen(1, false),
                ..pair
            },
        ),
        (
            "4 light samples per exit",
            PathSettings {
                exit_lights: chosen(4, false),
                ..pair
            },
        ),
        (
            "direct light only (depth 1)",
            PathSettings {
                max_depth: 1,
                ..pair
            },
        ),
        (
            "2 probes, stratified exit light choice",
            PathSettings {
                subsurface_probes: 2,
                exit_lights: chosen(2, true),
                ..pair
            },
        ),
        (
            "3 probes, 2 stratified light samples",
            PathSettings {
                subsurface_probes: 3,
                exit_lights: chosen(2, true),
                ..pair
            },
        ),
        (
            "3 probes",
            PathSettings {
                subsurface_probes: 3,
                ..pair
            },
        ),
        ("+ radius wavelength by luminance", share(0.1)),
        ("radius wavelength, uniform share 0.5", share(0.5)),
        ("radius wavelength, uniform share 0.25", share(0.25)),
        ("radius wavelength, uniform share 0.02", share(0.02)),
        (
            "luminance radius, 3 probes",
            PathSettings {
                subsurface_probes: 3,
                ..share(0.1)
            },
        ),
        (
            "luminance radius, 1 probe",
            PathSettings {
                subsurface_probes: 1,
                ..share(0.1)
            },
        ),
        (
            "luminance radius, stratified exit light choice",
            PathSettings {
                exit_lights: chosen(2, true),
                ..share(0.1)
            },
        ),
    ]
    .into_iter()
    .chain(
        [
            ("luminance radius, lights split (budget 4)", 4.0),
            ("+ lights split at each exit (budget 8)", 8.0),
            ("luminance radius, lights split (budget 16)", 16.0),
            (
                "luminance radius, every light at each exit",
                render::renderer::MAX_SPLIT_BUDGET,
            ),
        ]
        .map(|(name, budget)| {
            (
                name,
                PathSettings {
                    exit_lights: ExitLights::Split { budget },
                    ..share(0.1)
                },
            )
        }),
    )
    .map(|(name, path)| Variant { name, path })
    .collect()
}

/// The noise of one fixed-spp measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Samples per pixel.
    pub spp: u32,
    /// CPU seconds of one render (mean of the two seeds).
    pub cpu_s: f64,
    /// Wall seconds of one render (mean of the two seeds).
    pub wall_s: f64,
    /// RMS relative noise over the lit pixels.
    pub noise: f64,
    /// The same over lit skin pixels.
    pub noise_skin: f64,
    /// The same over lit non-skin pixels.
    pub noise_other: f64,
    /// The same metric on the linear sRGB red and blue channels over the skin pixels lit in
    /// that channel (the colour speckle the luminance figure does not see).
    pub noise_skin_rb: [f64; 2],
}

impl Point {
    /// noise · √(CPU s): lower is more efficient.
    #[must_use]
    pub fn efficiency(&self) -> f64 {
        self.noise * self.cpu_s.sqrt()
    }
}

/// The two-seed metric over the lit pixels where `keep` holds (NaN when none).
fn masked_noise(a: &[f64], b: &[f64], keep: impl Fn(usize) -> bool) -> f64 {
    relative_noise_where(a, b, keep).map_or(f64::NAN, |r| r.relative_noise)
}

/// Render `scene` at `spp` with seeds 1 and 2 and measure the noise; `skin` is the skin mask.
pub fn measure(
    scene: &Scene,
    (width, height): (usize, usize),
    spp: u32,
    threads: Option<usize>,
    path: PathSettings,
    skin: &[f32],
) -> anyhow::Result<Point> {
    let mut lum = Vec::new();
    let mut red_blue: Vec<[Vec<f64>; 2]> = Vec::new();
    let (mut cpu, mut wall) = (0.0, 0.0);
    for seed in [1, 2] {
        let settings = RenderOptions {
            width,
            height,
            spp,
            seed,
            threads,
            path,
            ..Default::default()
        }
        .validate()?;
        let t = ProcessTime::now();
        let (film, stats) = render(scene, &settings)?;
        cpu += t.elapsed().as_secs_f64();
        wall += stats.elapsed.as_secs_f64();
        lum.push(
            (0..width * height)
                .map(|i| f64::from(film.xyz(i % width, i / width)[1]))
                .collect::<Vec<f64>>(),
        );
        red_blue.push([0, 2].map(|c| {
            (0..width * height)
                .map(|i| f64::from(xyz_to_linear_srgb(film.xyz(i % width, i / width))[c]))
                .collect()
        }));
    }
    let skin_channel = |c: usize| masked_noise(&red_blue[0][c], &red_blue[1][c], |i| skin[i] > 0.5);
    Ok(Point {
        spp,
        cpu_s: 0.5 * cpu,
        wall_s: 0.5 * wall,
        noise: masked_noise(&lum[0], &lum[1], |_| true),
        noise_skin: masked_noise(&lum[0], &lum[1], |i| skin[i] > 0.5),
        noise_other: masked_noise(&lum[0], &lum[1], |i| skin[i] <= 0.5),
        noise_skin_rb: [skin_channel(0), skin_channel(1)],
    })
}

/// Where the noise comes from, for one variant at `spp`: the whole scene, each light alone (the
/// environment counted as a light), and, when `no_subsurface` (the same scene loaded with skin
/// as its Lambertian stand-in) is given, the scene without subsurface transport. Rows are
/// (what, point).
pub fn breakdown(
    scene: &mut Scene,
    no_subsurface: Option<&Scene>,
    size: (usize, usize),
    spp: u32,
    threads: Option<usize>,
    path: PathSettings,
) -> anyhow::Result<Vec<(String, Point)>> {
    let skin = Passes::first_hit(scene, size.0, size.1).skin;
    let mut rows = vec![(
        "all lights".to_string(),
        measure(scene, size, spp, threads, path, &skin)?,
    )];
    if let Some(lambert) = no_subsurface {
        rows.push((
            "no subsurface".to_string(),
            measure(lambert, size, spp, threads, path, &skin)?,
        ));
    }
    // Each light alone: the scene's lights are moved out and put back one at a time.
    let lights = std::mem::take(&mut scene.lights);
    let environment = scene.environment.take();
    let mut alone = Ok(());
    for (k, light) in lights.iter().enumerate() {
        scene.lights = vec![light.clone()];
        match measure(scene, size, spp, threads, path, &skin) {
            Ok(p) => rows.push((format!("light {k} alone"), p)),
            Err(e) => {
                alone = Err(e);
                break;
            }
        }
    }
    scene.lights.clear();
    scene.environment = environment;
    if alone.is_ok() && scene.environment.is_some() {
        match measure(scene, size, spp, threads, path, &skin) {
            Ok(p) => rows.push(("environment alone".to_string(), p)),
            Err(e) => alone = Err(e),
        }
    }
    scene.lights = lights;
    alone?;
    for (what, p) in &rows {
        log::info!(
            "{what:<20} {spp} spp: {:7.1} CPU s, noise {:6.2}% (skin {:.2}%, other {:.2}%), noise·√CPU-s {:.4}",
            p.cpu_s,
            100.0 * p.noise,
            100.0 * p.noise_skin,
            100.0 * p.noise_other,
            p.efficiency()
        );
    }
    Ok(rows)
}

/// Measure every variant at every sample count, write `noise_vs_time.csv` and
/// `noise_vs_time.png` into `out`, and return the rows (variant name, point).
pub fn run(
    scene: &Scene,
    size: (usize, usize),
    spps: &[u32],
    threads: Option<usize>,
    variants: &[Variant],
    out: &Path,
) -> anyhow::Result<Vec<(&'static str, Point)>> {
    std::fs::create_dir_all(out)?;
    let skin = Passes::first_hit(scene, size.0, size.1).skin;
    let mut rows = Vec::new();
    for v in variants {
        for &spp in spps {
            let p = measure(scene, size, spp, threads, v.path, &skin)?;
            log::info!(
                "{:<34} {spp:>5} spp: {:7.1} CPU s, noise {:6.2}% (skin {:.2}%, other {:.2}%; skin red {:.2}%, blue {:.2}%), noise·√CPU-s {:.4}",
                v.name,
                p.cpu_s,
                100.0 * p.noise,
                100.0 * p.noise_skin,
                100.0 * p.noise_other,
                100.0 * p.noise_skin_rb[0],
                100.0 * p.noise_skin_rb[1],
                p.efficiency()
            );
            rows.push((v.name, p));
        }
    }
    write_csv(&out.join("noise_vs_time.csv"), &rows)?;
    let mut chart = LineChart::new(
        format!("noise against CPU time, {}×{}", size.0, size.1),
        "CPU time of one render, s",
        "RMS relative noise over lit pixels, %",
    )
    .log_x()
    .log_y();
    for v in variants {
        let pts = rows
            .iter()
            .filter(|(n, _)| *n == v.name)
            .map(|(_, p)| (p.cpu_s, 100.0 * p.noise))
            .collect();
        chart = chart.with_series(Series::line(v.name, pts).with_style(SeriesStyle::LinePoints));
    }
    let png = out.join("noise_vs_time.png");
    save_png(&png, &[Panel::Line(chart)], 900, 600)?;
    Ok(rows)
}

fn write_csv(path: &Path, rows: &[(&'static str, Point)]) -> anyhow::Result<()> {
    let mut s = String::from(
        "variant,spp,cpu_s,wall_s,noise,noise_skin,noise_other,noise_sqrt_cpu_s,noise_skin_red,noise_skin_blue\n",
    );
    for (name, p) in rows {
        writeln!(
            s,
            "\"{}\",{},{:.3},{:.3},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
            // Quoted (RFC 4180): the names hold commas.
            name.replace('"', "\"\""),
            p.spp,
            p.cpu_s,
            p.wall_s,
            p.noise,
            p.noise_skin,
            p.noise_other,
            p.efficiency(),
            p.noise_skin_rb[0],
            p.noise_skin_rb[1]
        )?;
    }
    skin_io::atomic::write_bytes(path, s.as_bytes())?;
    Ok(())
}
