//! `skin-validate`: Monte Carlo reference runs (`mc`) and the diffusion-versus-exact comparison charts.

use anyhow::Context;
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use skin_cli::args::{Checked, SkinArgs, parse_whole};
use skin_optics::Wavelength;
use skin_optics::echo::{Num, Text};
use std::path::PathBuf;
use std::time::Instant;
use validation::montecarlo::{self, LayeredMedium, McOptions, McResult};

/// Monte Carlo ground truth for layered skin, and charts of where diffusion fails.
///
/// Without a subcommand: run the comparison (multipole versus Monte Carlo) and write PNG charts,
/// the CSV behind each and a markdown summary into --out.
#[derive(Parser, Debug)]
#[command(name = "skin-validate", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Fewer wavelengths, grid points and photons: the whole comparison in under two minutes.
    #[arg(long)]
    quick: bool,
    /// Output folder for the comparison's charts, CSV and summary.
    #[arg(long, value_name = "DIR", default_value = "out/validation")]
    out: PathBuf,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// One Monte Carlo run for a skin at one wavelength; prints one CSV line with its header.
    Mc(McArgs),
    /// Only the exact-versus-multipole study (totals over C_m, light/dark profiles) into --out.
    Exact(ExactArgs),
    /// Per-pixel relative luminance noise of one render, from two renders with different seeds:
    /// sqrt(mean((L₁ − L₂)² / (2 L̄²))) over pixels with L̄ ≥ 15% of the 95th percentile.
    Noise(NoiseArgs),
    /// Noise against CPU time of a scene at fixed sample counts (two seeds each), for every
    /// sampling variant from the renderer before variance reduction to now: CSV and PNG into --out.
    NoiseChart(NoiseChartArgs),
    /// Fit the measured ISSA spectra (explore or held-out subjects) with the seed model and a
    /// chosen one; residual bands and fitted parameters as CSV and PNG into --out.
    Measured(MeasuredArgs),
    /// Fit the mean colour of each group/site of the measured ISSA spectra as a colour target with
    /// each model (SCI): the ΔE2000 per model as CSV and a summary into --out.
    MeanColours(MeanColourArgs),
    /// Fit the ISSA group/site medians (SCI, model auto) and write the measured-preset table.
    Presets(PresetArgs),
    /// Error against cost (build CPU-s, evaluation ms) for every knob of the exact profile's shape
    /// table, against Monte Carlo references; CSV and PNG into --out.
    TableKnobs(TableKnobArgs),
    /// The BSSRDF against the volumetric reference in image space: per-pixel error maps, region
    /// means by shape and skin tone, error against render time (PNG, CSV, render.md) into --out.
    Render(RenderStudyArgs),
    /// Each installed engine (MaterialX, Mitsuba 3, MCX, Blender Cycles) on the exported files against our exact
    /// numbers: CSV and PNG into --out; an engine that is not installed is skipped with a note.
    Engines(EnginesArgs),
}

#[derive(Args, Debug)]
struct EnginesArgs {
    /// Python interpreter with the engines installed (default: $SKIN_ENGINES_PYTHON, else python3).
    #[arg(long, value_name = "PATH")]
    python: Option<PathBuf>,
    /// Folder of the driver scripts.
    #[arg(long, value_name = "DIR", default_value = validation::engines::SCRIPTS)]
    scripts: PathBuf,
    /// Samples per pixel of the Mitsuba renders (16 × 16 pixels), [1, 65536].
    #[arg(long, value_name = "N", default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=65_536))]
    spp: u32,
    /// Samples per pixel of the Cycles renders, [1, 65536].
    #[arg(long = "cycles-spp", value_name = "N", default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=65_536))]
    cycles_spp: u32,
    /// Samples per pixel of our volumetric sphere (48 × 48 pixels), the Cycles sphere's
    /// reference, [1, 65536].
    #[arg(long = "sphere-spp", value_name = "N", default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=65_536))]
    sphere_spp: u32,
    /// Photons of each MCX run, [1000, 1e9].
    #[arg(long = "mcx-photons", value_name = "N", default_value_t = 100_000, value_parser = clap::value_parser!(u64).range(1_000..=1_000_000_000))]
    mcx_photons: u64,
    /// Library to preload into the MCX driver (e.g. /usr/lib/x86_64-linux-gnu/libstdc++.so.6 when
    /// pocl's kernel build cannot find 'stdint.h').
    #[arg(long = "mcx-ld-preload", value_name = "PATH")]
    mcx_ld_preload: Option<PathBuf>,
    /// Run only this engine (its Python module: MaterialX, mitsuba, pmcxcl, bpy); repeatable.
    #[arg(long = "engine", value_name = "MODULE", value_parser = ["MaterialX", "mitsuba", "pmcxcl", "bpy"])]
    engine: Vec<String>,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/engines")]
    out: PathBuf,
}

fn run_engines(args: &EnginesArgs) -> anyhow::Result<()> {
    let python = args
        .python
        .clone()
        .or_else(|| std::env::var_os("SKIN_ENGINES_PYTHON").map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from("python3"));
    let opts = validation::engines::EngineOptions {
        python,
        scripts: args.scripts.clone(),
        out: args.out.clone(),
        spp: args.spp,
        cycles_spp: args.cycles_spp,
        sphere_spp: args.sphere_spp,
        mcx_photons: args.mcx_photons,
        mcx_preload: args.mcx_ld_preload.clone(),
        only: args.engine.clone(),
    };
    let (rows, notes) = validation::engines::run_engines(&opts)?;
    for r in &rows {
        println!(
            "{:<16} {:<6} {:<4} ours {:.5} engine {:.5} ± {:.5}  {:+.2}%  ({})",
            r.engine,
            r.preset,
            r.channel,
            r.ours,
            r.engine_value,
            r.engine_stderr,
            100.0 * r.rel_error(),
            r.quantity
        );
    }
    for n in notes {
        eprintln!("{n}");
    }
    eprintln!("wrote {}", args.out.join("engines.csv").display());
    Ok(())
}

#[derive(Args, Debug)]
struct TableKnobArgs {
    /// Photons per Monte Carlo reference (nine: light, medium, dark at 450, 550, 650 nm), [1e4, 1e9].
    #[arg(long, value_name = "N", default_value_t = 1_000_000, value_parser = Checked(parse_reference_photons))]
    photons: u64,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/table_knobs")]
    out: PathBuf,
}

#[derive(Args, Debug)]
struct RenderStudyArgs {
    /// Smaller images and sample counts (minutes on two cores).
    #[arg(long)]
    quick: bool,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/render-study")]
    out: PathBuf,
    /// Only the cases whose label "name (tone)" contains this text (repeatable; skips the
    /// error-against-time chart), e.g. "backlit ear", "sphere r=10 mm (light)".
    #[arg(long, value_name = "TEXT")]
    only: Vec<String>,
    /// Volumetric spp of the cases whose label contains TEXT, as TEXT=N with N in [1, 65536]
    /// (repeatable, first match wins), e.g. "backlit ear=256".
    #[arg(long, value_name = "TEXT=N", value_parser = Checked(parse_case_spp))]
    reference_spp: Vec<(String, u32)>,
    /// Folder where volumetric references are kept and reused by later runs (same scene, size,
    /// spp and seed; empty it when the volumetric walk changes).
    #[arg(long, value_name = "DIR")]
    reference_cache: Option<PathBuf>,
    /// Worker threads of every render, [1, 1024] (default: all cores).
    #[arg(long, value_name = "N", value_parser = Checked(parse_threads))]
    threads: Option<u32>,
    /// Only the error-against-time charts (thin slab, ear, sphere; BSSRDF, default configuration,
    /// volumetric), no case table; with --only, the chart cases whose label contains the text.
    #[arg(long)]
    charts: bool,
    /// Render the BSSRDF with the planar profile, without its curvature term (the former form,
    /// for before/after comparisons; docs/physics.md §8.2).
    #[arg(long)]
    planar: bool,
}

fn parse_case_spp(s: &str) -> Result<(String, u32), String> {
    let (text, n) = s
        .rsplit_once('=')
        .ok_or_else(|| format!("`{s}`: expected TEXT=N"))?;
    let n = parse_whole(n, 1, 65_536, "[1, 65536]")?;
    Ok((
        text.to_string(),
        u32::try_from(n).map_err(|e| e.to_string())?,
    ))
}

fn parse_reference_photons(s: &str) -> Result<u64, String> {
    parse_whole(s, 10_000, 1_000_000_000, "[1e4, 1e9]")
}

#[derive(Args, Debug)]
struct NoiseArgs {
    /// First render (RGB OpenEXR).
    a: PathBuf,
    /// Second render of the same scene with another seed (RGB OpenEXR).
    b: PathBuf,
    /// Also the metric over the lit pixels that see skin, by the `mask.skin` pass of the first
    /// render (an EXR written by `skin render`): prints both lines.
    #[arg(long)]
    skin: bool,
}

#[derive(Args, Debug)]
struct NoiseChartArgs {
    /// Scene file or built-in scene.
    #[arg(long, value_name = "FILE", default_value = "builtin:three-heads")]
    scene: String,
    /// Image width, pixels.
    #[arg(long, default_value_t = 768)]
    width: usize,
    /// Image height, pixels.
    #[arg(long, default_value_t = 384)]
    height: usize,
    /// Sample counts per pixel, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "4,16,64")]
    spp: Vec<u32>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Only these variants (indices into the list, comma-separated; default all).
    #[arg(long, value_delimiter = ',')]
    variants: Vec<usize>,
    /// Instead of the chart: where the noise comes from (each light alone, without subsurface)
    /// for the last variant at the first sample count.
    #[arg(long)]
    breakdown: bool,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/noise-chart")]
    out: PathBuf,
}

#[derive(Args, Debug)]
struct PresetArgs {
    /// Noise σ of one reflectance for the criterion, (0, 1).
    #[arg(long, default_value_t = 0.005)]
    noise: f64,
    /// Output table.
    #[arg(
        long,
        value_name = "FILE.csv",
        default_value = "skin-optics/data/measured_presets.csv"
    )]
    out: PathBuf,
}

#[derive(Args, Debug)]
struct MeasuredArgs {
    /// Which subjects: `heldout` (report these) or `explore`.
    #[arg(long, default_value = "heldout", value_parser = ["heldout", "explore"])]
    set: String,
    /// Instrument geometry: `sci` (what ISSA measured) or `sce`.
    #[arg(long, default_value = "sci", value_parser = parse_geometry)]
    geometry: skin_fit::Geometry,
    /// Model compared with the seed: `seed`, `full` or `auto`.
    #[arg(long, default_value = "auto", value_parser = parse_model)]
    model: skin_fit::ModelChoice,
    /// Forward model: `exact` or `multipole`.
    #[arg(long, default_value = "exact", value_parser = parse_method)]
    method: multipole::Method,
    /// Noise σ of one reflectance for the criterion, (0, 1).
    #[arg(long, default_value_t = 0.005)]
    noise: f64,
    /// Convergence tolerance of the refinement, χ² units at --noise, [0, 1] (0: to the optimiser's
    /// precision).
    #[arg(long, default_value_t = skin_fit::CHI2_TOLERANCE)]
    chi2_tolerance: f64,
    /// Fit at most this many records, spread evenly over the subset.
    #[arg(long)]
    limit: Option<usize>,
    /// Starts of the `full` refinement, [1, 4] (fewer: faster, may stop in a worse valley).
    #[arg(long, default_value_t = skin_fit::FULL_STARTS_MAX)]
    full_starts: usize,
    /// Extra `full` starts refined after short trials rank them, [0, 3] (3: every start refined,
    /// no trials).
    #[arg(long, default_value_t = skin_fit::FULL_REFINED_STARTS)]
    full_refined_starts: usize,
    /// Candidates per `auto` round trial-fitted after the score test ranks them, [0, 7] (0: every
    /// candidate, the exhaustive selection).
    #[arg(long, default_value_t = skin_fit::SCREENED_TRIALS)]
    screened_trials: usize,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/measured")]
    out: PathBuf,
}

#[derive(Args, Debug)]
struct MeanColourArgs {
    /// Which subjects: `heldout` (report these) or `explore`.
    #[arg(long, default_value = "heldout", value_parser = ["heldout", "explore"])]
    set: String,
    /// Models to fit, comma-separated (`seed`, `full`, `auto`).
    #[arg(long, value_delimiter = ',', default_value = "seed,auto,full", value_parser = parse_model)]
    models: Vec<skin_fit::ModelChoice>,
    /// Noise σ of one reflectance, (0, 1): the criterion's colour noise follows from it.
    #[arg(long, default_value_t = 0.005)]
    noise: f64,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "out/measured")]
    out: PathBuf,
}

/// The subset a `--set` value names (clap has checked it is one of the two).
fn subset_of(set: &str) -> validation::measured_report::Subset {
    use validation::measured_report::Subset;
    if set == "explore" {
        Subset::Explore
    } else {
        Subset::Heldout
    }
}

fn run_mean_colours(args: &MeanColourArgs) -> anyhow::Result<()> {
    let subset = subset_of(&args.set);
    let opts = skin_fit::MeasuredOptions {
        geometry: skin_fit::Geometry::Sci,
        noise: args.noise,
        fit: skin_fit::FitOptions {
            beta_scan: 0,
            ..skin_fit::FitOptions::default()
        },
        ..skin_fit::MeasuredOptions::default()
    };
    validation::mean_colours::run_mean_colours(subset, &args.models, &opts, &args.out)
}

fn parse_geometry(s: &str) -> Result<skin_fit::Geometry, String> {
    s.parse().map_err(|e: skin_fit::FitError| e.to_string())
}

fn parse_model(s: &str) -> Result<skin_fit::ModelChoice, String> {
    s.parse().map_err(|e: skin_fit::FitError| e.to_string())
}

fn parse_method(s: &str) -> Result<multipole::Method, String> {
    s.parse()
        .map_err(|e: multipole::MultipoleError| e.to_string())
}

fn run_measured(args: &MeasuredArgs) -> anyhow::Result<()> {
    let subset = subset_of(&args.set);
    let opts = skin_fit::MeasuredOptions {
        geometry: args.geometry,
        model: args.model,
        noise: args.noise,
        chi2_tolerance: args.chi2_tolerance,
        full_starts: args.full_starts,
        screened_trials: args.screened_trials,
        full_refined_starts: args.full_refined_starts,
        fit: skin_fit::FitOptions {
            method: args.method,
            beta_scan: 0,
            ..skin_fit::FitOptions::default()
        },
        ..skin_fit::MeasuredOptions::default()
    };
    validation::measured_report::run_measured(subset, args.limit, &opts, &args.out)
}

#[derive(Args, Debug)]
struct ExactArgs {
    /// Fewer wavelengths and photons (well under two minutes).
    #[arg(long)]
    quick: bool,
    /// Output folder for the charts, CSV and summary.
    #[arg(long, value_name = "DIR", default_value = "out/validation")]
    out: PathBuf,
}

/// Parse a wavelength in nm, [250, 1000].
fn parse_lambda(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{}' is not a number (valid range [250, 1000] nm)", Text(s)))?;
    Wavelength::new(v)
        .map(|w| w.nm())
        .map_err(|e| e.to_string())
}

/// Parse a Henyey–Greenstein anisotropy, [-0.999, 0.999].
fn parse_g(s: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|_| {
        format!(
            "'{}' is not a number (valid range [-0.999, 0.999])",
            Text(s)
        )
    })?;
    if v.is_finite() && (-0.999..=0.999).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{} outside [-0.999, 0.999]", Num(v)))
    }
}

/// Parse a photon count, [1, 1e12] (accepts `1e6`).
fn parse_photons(s: &str) -> Result<u64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{}' is not a number (valid range [1, 1e12])", Text(s)))?;
    if v.is_finite() && (1.0..=1e12).contains(&v) && v.fract() == 0.0 {
        Ok(v as u64)
    } else {
        Err(format!("{} outside [1, 1e12] (a whole number)", Num(v)))
    }
}

/// Parse a batch count, [2, 1e6].
fn parse_batches(s: &str) -> Result<u32, String> {
    parse_whole(s, 2, 1_000_000, "[2, 1e6]").map(|v| v as u32)
}

/// Parse a thread count, [1, 1024].
fn parse_threads(s: &str) -> Result<u32, String> {
    parse_whole(s, 1, 1024, "[1, 1024]").map(|v| v as u32)
}

#[derive(Args, Debug)]
struct McArgs {
    #[command(flatten)]
    skin: SkinArgs,
    /// Wavelength in nm, [250, 1000].
    #[arg(long, value_name = "NM", value_parser = Checked(parse_lambda), default_value = "550", allow_hyphen_values = true)]
    lambda: f64,
    /// Photon histories (the accuracy knob: the standard error falls as 1/√N).
    #[arg(long, value_name = "N", value_parser = Checked(parse_photons), default_value = "1000000", allow_hyphen_values = true)]
    photons: u64,
    /// Henyey–Greenstein anisotropy g; σs = σs' / (1 − g).
    #[arg(long, value_name = "G", value_parser = Checked(parse_g), default_value = "0.9", allow_hyphen_values = true)]
    g: f64,
    /// Generator seed: the same seed gives the same result on any number of threads.
    #[arg(long, value_name = "S", default_value_t = 1)]
    seed: u64,
    /// Independent batches for the standard errors, [2, 1e6].
    #[arg(long, value_name = "B", default_value_t = 32, value_parser = Checked(parse_batches), allow_hyphen_values = true)]
    batches: u32,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "T", value_parser = Checked(parse_threads), allow_hyphen_values = true)]
    threads: Option<u32>,
    /// Also write the radial profile R_d(r) as CSV (r_mm,reflectance_per_mm2,stderr).
    #[arg(long, value_name = "FILE.csv")]
    profile: Option<PathBuf>,
}

fn main() {
    skin_io::atomic::remove_temporaries_on_interrupt(|n| {
        eprintln!("interrupted: removed {n} temporary file(s); nothing half-written is left");
    });
    skin_cli::init_logging();
    let cli = Cli::parse();
    let result = match &cli.command {
        Some(Command::Mc(args)) => run_mc(args),
        Some(Command::Exact(args)) => {
            validation::compare::run_exact(args.quick, &args.out).map(|md| println!("{md}"))
        }
        Some(Command::Noise(args)) => run_noise(args),
        Some(Command::NoiseChart(args)) => run_noise_chart(args),
        Some(Command::Measured(args)) => run_measured(args),
        Some(Command::MeanColours(args)) => run_mean_colours(args),
        Some(Command::Presets(args)) => {
            validation::presets::run_presets(args.noise, &args.out).map(|lines| print!("{lines}"))
        }
        Some(Command::TableKnobs(args)) => {
            validation::compare::table_knobs::run_table_knobs(args.photons, &args.out)
        }
        Some(Command::Render(args)) => {
            use validation::compare::render_study::{RenderStudy, run_render};
            let study = if args.quick {
                RenderStudy::QUICK
            } else {
                RenderStudy::FULL
            };
            let run = validation::compare::render_study::StudyRun {
                only: args.only.clone(),
                reference_spp_for: args.reference_spp.clone(),
                reference_cache: args.reference_cache.clone(),
                threads: args.threads.map(|t| t as usize),
                charts_only: args.charts,
                curvature: if args.planar {
                    render::bssrdf::Curvature::Planar
                } else {
                    render::bssrdf::Curvature::FirstOrder
                },
            };
            run_render(study, &run, &args.out).map(|md| println!("{md}"))
        }
        Some(Command::Engines(args)) => run_engines(args),
        None => validation::compare::run_comparison(cli.quick, &cli.out).map(|md| println!("{md}")),
    };
    if let Err(e) = result {
        eprintln!("skin-validate: {}", skin_cli::one_line(&e));
        std::process::exit(1);
    }
}

/// Progress bar on stderr for `total` photons.
fn photon_bar(total: u64) -> ProgressBar {
    let bar = ProgressBar::new(total);
    if let Ok(style) = ProgressStyle::with_template(
        "{elapsed_precise} [{bar:30}] {human_pos}/{human_len} photons ({per_sec}, eta {eta})",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

fn run_mc(args: &McArgs) -> anyhow::Result<()> {
    let skin = args.skin.to_params()?;
    let lambda = Wavelength::new(args.lambda)?;
    let stack = LayeredMedium::skin(&skin, lambda, args.g)?;
    let opts = McOptions::new(args.photons, args.batches, args.seed)?;
    let bar = photon_bar(opts.total_photons());
    let start = Instant::now();
    let trace = || montecarlo::run_with_progress(&stack, &opts, |n| bar.inc(n));
    let result = match args.threads {
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t as usize)
            .build()
            .context("building the thread pool")?
            .install(trace),
        None => trace(),
    };
    let seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    println!(
        "diffuse_reflectance,diffuse_reflectance_stderr,specular_reflectance,transmittance,absorbed,photons,seconds"
    );
    println!(
        "{:.6},{:.6},{:.6},{:.6},{:.6},{},{:.3}",
        result.diffuse_reflectance.mean,
        result.diffuse_reflectance.stderr,
        result.specular_reflectance,
        result.transmittance.mean,
        result.absorbed.mean,
        result.photons,
        seconds
    );
    if let Some(path) = &args.profile {
        write_profile(path, &result)?;
    }
    Ok(())
}

fn run_noise(args: &NoiseArgs) -> anyhow::Result<()> {
    let print = |what: &str, r: &render::noise::NoiseReport| {
        println!(
            "relative noise {:.4} ({:.2}%) over {} of {} pixels ({what}: luminance ≥ {:.4e})",
            r.relative_noise,
            100.0 * r.relative_noise,
            r.lit_pixels,
            r.pixels,
            r.threshold
        );
    };
    if args.skin {
        let (lit, skin) = render::noise::compare_exr_with_skin(&args.a, &args.b)?;
        print("lit", &lit);
        print("lit skin", &skin);
    } else {
        print("lit", &render::noise::compare_exr(&args.a, &args.b)?);
    }
    Ok(())
}

fn run_noise_chart(args: &NoiseChartArgs) -> anyhow::Result<()> {
    use render::material::SkinKnobs;
    use render::scene::Scene;
    use validation::noise_chart;
    let all = noise_chart::variants();
    let chosen: Vec<_> = if args.variants.is_empty() {
        all.clone()
    } else {
        args.variants
            .iter()
            .map(|&i| {
                all.get(i).copied().ok_or_else(|| {
                    anyhow::anyhow!("--variants {i}: outside [0, {}]", all.len() - 1)
                })
            })
            .collect::<anyhow::Result<_>>()?
    };
    let Some(&last) = chosen.last() else {
        anyhow::bail!("--variants: none chosen");
    };
    let size = (args.width, args.height);
    let mut scene = Scene::load(&args.scene, &SkinKnobs::default())?;
    if args.breakdown {
        let lambert = Scene::load(
            &args.scene,
            &SkinKnobs {
                no_subsurface: true,
                ..SkinKnobs::default()
            },
        )?;
        let spp = args.spp.first().copied().unwrap_or(16);
        noise_chart::breakdown(
            &mut scene,
            Some(&lambert),
            size,
            spp,
            args.threads,
            last.path,
        )?;
        return Ok(());
    }
    noise_chart::run(&scene, size, &args.spp, args.threads, &chosen, &args.out)?;
    println!("wrote {}", args.out.join("noise_vs_time.png").display());
    Ok(())
}

fn write_profile(path: &std::path::Path, result: &McResult) -> anyhow::Result<()> {
    let p = &result.radial;
    let mut csv = String::from("r_mm,reflectance_per_mm2,stderr\n");
    for i in 0..p.grid.bins() {
        csv.push_str(&format!(
            "{:.6},{:.6e},{:.3e}\n",
            p.grid.r_mid_mm(i),
            p.reflectance_per_mm2[i],
            p.stderr[i]
        ));
    }
    skin_io::atomic::write_bytes(path, csv.as_bytes())
        .with_context(|| format!("writing the profile {}", path.display()))
}
