//! `skin render`: load a scene (the built-in three-head scene by default), path trace it, and write
//! OUT/render.exr (linear sRGB, f32, with the passes of `render::passes`) and OUT/render.png (sRGB, exposure + filmic tone curve).

use crate::args::{Checked, parse_number, parse_whole};
use ::render::fidelity::explain::{diffusion_warning, explain_table};
use ::render::fidelity::{Fidelity, FidelityKnobs, LodBand, LodSetting};
use ::render::integrator::{BodyIntegrator, IntegratorKind};
use ::render::material::SkinKnobs;
use ::render::renderer::{Progress, RenderOptions, SettingError, render_with};
use ::render::scene::Scene;
use ::render::volumetric::majorant::Majorant;
use ::render::volumetric::walk::Absorption;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use skin_optics::echo::Num;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Arguments of `skin render`.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// Scene file (TOML), or a built-in scene: builtin:three-heads (default, per-texel skin),
    /// builtin:three-heads-uniform, builtin:ear, builtin:three-heads-far, builtin:face-maps,
    /// builtin:face.
    #[arg(long, value_name = "FILE", default_value = "builtin:three-heads")]
    pub scene: String,
    /// Output folder for render.exr and render.png.
    #[arg(long, value_name = "DIR", default_value = "out")]
    pub out: PathBuf,
    /// Samples (paths) per pixel: the most any pixel takes (all take it with --noise 0).
    #[arg(long, value_name = "N", default_value_t = 4096, value_parser = Checked(parse_spp), allow_hyphen_values = true)]
    pub spp: u32,
    /// Per-pixel relative noise target (0.02 = 2%, relative to the pixel's luminance, or to 15%
    /// of the 95th percentile in the dark): a pixel stops sampling once its noise estimated from
    /// its own samples is below it. 0 = off: every pixel takes --spp samples.
    #[arg(long, value_name = "REL", default_value_t = 0.02, value_parser = Checked(parse_noise), allow_hyphen_values = true)]
    pub noise: f64,
    /// How each pixel's noise is estimated for --noise and the printed figure: calibrated (the
    /// sample variance scaled per 16×16 block by the two half-sequences' agreement; default),
    /// half-difference (the two half-sequences' means alone: few degrees of freedom, so pixels
    /// stop on a low estimate) or sample-variance (an overstatement for Sobol points).
    #[arg(long, value_name = "E", value_enum, default_value_t = ErrorEstimateArg::Calibrated)]
    pub error_estimate: ErrorEstimateArg,
    /// z of the one-sided upper confidence bound of a pixel's estimated noise that must be within
    /// --noise before it stops, in [0, 10] (default 1.645: 95%; 0 = the estimate itself).
    #[arg(long, value_name = "Z", default_value_t = ::render::renderer::STOP_CONFIDENCE_Z, value_parser = Checked(parse_confidence), allow_hyphen_values = true)]
    pub noise_confidence: f64,
    /// Image width, pixels.
    #[arg(long, value_name = "W", default_value_t = 768, value_parser = Checked(parse_pixels), allow_hyphen_values = true)]
    pub width: u32,
    /// Image height, pixels.
    #[arg(long, value_name = "H", default_value_t = 384, value_parser = Checked(parse_pixels), allow_hyphen_values = true)]
    pub height: u32,
    /// Wall-clock budget in seconds, in [0, 1e9]: no pass starts that would end past it (0 = no limit).
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0, value_parser = Checked(parse_time_limit), allow_hyphen_values = true)]
    pub time_limit: f64,
    /// Seed of all random numbers (same seed and spp give the same image on any thread count).
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N", value_parser = Checked(parse_small_count), allow_hyphen_values = true)]
    pub threads: Option<u32>,
    /// Skin reflectance method (the BSSRDF's radial profiles and the totals): exact (adding-doubling
    /// totals, layered Monte Carlo profile shapes) or multipole (the paper's diffusion).
    #[arg(long, value_name = "M", default_value_t = multipole::Method::default())]
    pub method: multipole::Method,
    /// Trace a layered Monte Carlo shape per tabulated wavelength with this many escaping photons,
    /// in [100, 1e9] (shape noise ∝ 1/√N; 1000 with shapes every 20 nm: at most 6–9%
    /// energy-weighted shape error), instead of the default shapes from the universal table
    /// (exact transport, 1–3% against a 10⁶-photon Monte Carlo, no run-time photons). With
    /// --fidelity auto the count is scaled down where the pixel footprint cannot see the shape.
    #[arg(long, value_name = "N",
          value_parser = Checked(parse_escapes), allow_hyphen_values = true)]
    pub shape_escapes: Option<u64>,
    /// Shade skin's body with a Lambertian term of its total diffuse reflectance instead of the
    /// BSSRDF (no light transport under the skin; for comparisons and timing).
    #[arg(long)]
    pub no_subsurface: bool,
    /// PNG exposure in stops, added to the scene's own.
    #[arg(
        long,
        value_name = "STOPS",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub exposure: f32,
    /// Maximum scattering events per path, in [1, 1024].
    #[arg(long, value_name = "N", default_value_t = 16,
          value_parser = Checked(parse_small_count), allow_hyphen_values = true)]
    pub max_depth: u32,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// How much model each skin gets: auto (each choice from the scene: profile extent, table
    /// radii, wavelengths, shape photons, level of detail) or full (every knob at its reference value, the BSSRDF
    /// at every hit). Each choice can be set alone with the flags below.
    /// (Default: the scene's `[fidelity]` key, else auto.)
    #[arg(long, value_name = "F")]
    pub fidelity: Option<Fidelity>,
    /// Energy left beyond each profile row, a fraction in (0, 0.1] (auto: 0.001).
    #[arg(long, value_name = "FRACTION", value_parser = Checked(parse_fraction), allow_hyphen_values = true)]
    pub energy_tolerance: Option<f64>,
    /// Energy-weighted interpolation error target of the profile tables' radius grid, in (0, 0.1]
    /// (auto: 0.002).
    #[arg(long, value_name = "FRACTION", value_parser = Checked(parse_fraction), allow_hyphen_values = true)]
    pub radial_error: Option<f64>,
    /// Wavelength step of the skin tables, nm: one of 5, 8, 10, 16, 20, 25, 40, 50, 80, 100
    /// (auto: the widest within ΔE2000 0.5 of a 1-nm grid; full: 10).
    #[arg(long, value_name = "NM", value_parser = Checked(parse_step), allow_hyphen_values = true)]
    pub wavelength_step: Option<f64>,
    /// Level of detail by pixel footprint: off, or LO,HI (pixel footprint / the profile's 99%
    /// radius: BSSRDF below LO, diffuse above HI, blended between; auto: 1,4).
    #[arg(long, value_name = "off|LO,HI", value_parser = Checked(parse_lod))]
    pub lod: Option<LodSetting>,
    /// Volumetric walk instead of the BSSRDF at thin parts (where the BSSRDF would omit a share
    /// `render::fidelity::THIN_OMISSION_SHARE` of the light, judged from the slab's exact transmission and both faces' light) seen at pixel
    /// footprints below this many of the skin's largest 99% energy radii, in [0, 10] (0: never;
    /// auto: 1, full: 0).
    #[arg(long, value_name = "R99S", value_parser = Checked(parse_thin_walk), allow_hyphen_values = true)]
    pub thin_walk: Option<f64>,
    /// Photons of the universal shape table, in [1e4, 1e9] (auto: the fewest whose measured shape
    /// error the smallest pixel footprint on the skin cannot see; full: 500000).
    #[arg(long, value_name = "N", value_parser = Checked(parse_shape_photons), allow_hyphen_values = true)]
    pub shape_photons: Option<u64>,
    /// Neither read nor write the disk cache of skin tables.
    #[arg(long)]
    pub no_cache: bool,
    /// Print what was chosen for each skin material and why (wavelengths, extent, table size,
    /// shapes, level of detail, BSSRDF or volumetric, cache).
    #[arg(long)]
    pub explain: bool,
    /// How skin's body is rendered: bssrdf (the separable BSSRDF, fast) or volumetric (an
    /// unbiased random walk through the two layers inside each closed skin mesh: the reference).
    #[arg(long, value_name = "KIND", value_enum, default_value_t = Integrator::Bssrdf)]
    pub integrator: Integrator,
    /// Majorant of the volumetric walk in skin with chromophore maps: local (per 2-mm cell over
    /// the surface, the largest σt its points can read) or global (the maps' darkest texel
    /// everywhere); both are unbiased, local is faster.
    #[arg(long, value_name = "KIND", value_enum, default_value_t = MajorantArg::Local)]
    pub majorant: MajorantArg,
    /// Absorption at the volumetric walk's collisions in skin with chromophore maps: excess (a
    /// collision weighs σs/σt at the local majorant cell's least σa, and the excess over it is
    /// ratio-tracked; the texel is read at few collisions) or implicit (every collision weighs
    /// σs/σt at its own texel); both are unbiased, excess is faster.
    #[arg(long, value_name = "RULE", value_enum, default_value_t = AbsorptionArg::Excess)]
    pub walk_absorption: AbsorptionArg,
    /// Render one wavelength, nm, in [380, 780]: the EXR holds the spectral radiance there as a
    /// grey (R = G = B), in the scene's emission units.
    #[arg(long, value_name = "NM", value_parser = Checked(parse_wavelength), allow_hyphen_values = true)]
    pub wavelength: Option<f32>,
}

/// The integrator of skin's body (`--integrator`).
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Integrator {
    /// The separable BSSRDF (`render::bssrdf`).
    Bssrdf,
    /// The volumetric random walk (`render::volumetric`).
    Volumetric,
}

/// The volumetric walk's majorant with maps (`--majorant`).
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum MajorantArg {
    /// Per cell of a grid over the surface.
    Local,
    /// The maps' darkest texel everywhere.
    Global,
}

/// The volumetric walk's absorption rule with maps (`--walk-absorption`).
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum AbsorptionArg {
    /// σs/σt(x) in the weight at every collision.
    Implicit,
    /// The cell's least σa in the weight, the excess ratio-tracked.
    Excess,
}

fn parse_wavelength(s: &str) -> Result<f32, String> {
    let v = parse_number(s, "[380, 780] nm")?;
    if !(380.0..=780.0).contains(&v) {
        return Err(format!("{} outside [380, 780] nm", Num(v)));
    }
    Ok(v as f32)
}

/// Run `skin render`.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    if !args.exposure.is_finite() {
        anyhow::bail!(
            "--exposure = {} is not a finite number of stops",
            args.exposure
        );
    }
    // Validated before the scene loads, so a bad flag fails fast.
    let mut options = RenderOptions {
        width: args.width as usize,
        height: args.height as usize,
        spp: args.spp,
        noise: (args.noise > 0.0).then_some(args.noise),
        error_estimate: Some(args.error_estimate.into()),
        stop_confidence_z: args.noise_confidence,
        time_limit: (args.time_limit > 0.0).then(|| Duration::from_secs_f64(args.time_limit)),
        seed: args.seed,
        threads: args.threads.map(|t| t as usize),
        path: ::render::integrator::PathSettings {
            max_depth: args.max_depth,
            ..Default::default()
        },
        integrator: match args.integrator {
            Integrator::Bssrdf => IntegratorKind::Bssrdf,
            Integrator::Volumetric => IntegratorKind::Volumetric,
        },
        wavelength_nm: args.wavelength,
        ..Default::default()
    };
    options.clone().validate().map_err(flag_error)?;
    let fidelity = FidelityKnobs {
        fidelity: args.fidelity,
        energy_tolerance: args.energy_tolerance,
        radial_error: args.radial_error,
        wavelength_step_nm: args.wavelength_step,
        lod: args.lod.unwrap_or_default(),
        thin_walk_r99: args.thin_walk,
        shape_photons: args.shape_photons,
        image_height: Some(args.height),
        smallest_footprint_mm: None,
        cache: !args.no_cache,
    };
    fidelity
        .resolve()
        .map_err(|e| anyhow::anyhow!("{e} (--fidelity and its overrides)"))?;
    // Checked before any work, so an unwritable --out does not waste the scene load and render.
    std::fs::create_dir_all(&args.out)
        .and_then(|()| tempfile::tempfile_in(&args.out))
        .map_err(|e| {
            anyhow::anyhow!("--out {}: not a writable folder ({e})", args.out.display())
        })?;
    let t0 = Instant::now();
    if args.integrator == Integrator::Volumetric && args.no_subsurface {
        anyhow::bail!("--integrator volumetric renders the subsurface: drop --no-subsurface");
    }
    let scene = Scene::load(
        &args.scene,
        &SkinKnobs {
            method: args.method,
            no_subsurface: args.no_subsurface,
            shape_escapes: args.shape_escapes,
            fidelity,
            ..SkinKnobs::default()
        },
    )?;
    let mut body = BodyIntegrator::build(&scene, options.integrator);
    if let BodyIntegrator::Volumetric(walk) = &mut body {
        let majorant = match args.majorant {
            MajorantArg::Local => Majorant::Local,
            MajorantArg::Global => Majorant::Global,
        };
        let absorption = match args.walk_absorption {
            AbsorptionArg::Implicit => Absorption::Implicit,
            AbsorptionArg::Excess => Absorption::Excess,
        };
        for medium in walk.media.iter_mut().flatten() {
            medium.majorant = majorant;
            medium.absorption = absorption;
        }
    }
    let load = t0.elapsed();
    let skins = scene.skin_choices();
    if args.explain {
        print!("{}", explain_table(&skins));
    }
    if let Some(warning) = diffusion_warning(&skins) {
        eprintln!("{warning}");
    }
    // The level of detail needs the pixel footprint: the camera's pixel angle at this height.
    options.path.pixel_angle_rad = scene.camera.pixel_angle_rad(options.height);
    let settings = options.validate().map_err(flag_error)?;
    eprintln!(
        "scene {}: {} triangles, {} lights, {} materials, loaded in {:.2} s",
        scene.name,
        scene.geometry.triangle_count(),
        scene.lights.len(),
        scene.materials.len(),
        load.as_secs_f64()
    );
    let (film, stats) = render_with_bar(&scene, &body, &settings, !args.quiet)?;
    if film.dropped_samples() > 0 {
        eprintln!(
            "dropped {} non-finite samples (not averaged into any pixel)",
            film.dropped_samples()
        );
    }
    let exr = args.out.join("render.exr");
    let png = args.out.join("render.png");
    let passes = ::render::passes::Passes::first_hit(&scene, settings.width, settings.height);
    // Both or neither: a failure of either leaves the previous pair (or nothing) in place.
    skin_io::atomic::commit(vec![
        passes.stage_exr(&film, &exr)?,
        film.stage_png(&png, scene.exposure_stops + args.exposure)?,
    ])?;
    println!(
        "rendered {}×{} at {:.1} spp (mean; at most {}) in {:.1} s ({} threads): {:.2} M rays/s, {:.3} s per sample per pixel",
        settings.width,
        settings.height,
        stats.mean_spp,
        stats.spp,
        stats.elapsed.as_secs_f64(),
        rayon_threads(settings.threads),
        stats.rays_per_second() / 1e6,
        stats.seconds_per_spp()
    );
    println!(
        "estimated noise {:.2}% over the lit pixels; {} of {} pixels reached the target; skin covers {:.1}% of the frame",
        100.0 * stats.noise,
        stats.converged,
        settings.width * settings.height,
        100.0 * passes.skin.iter().sum::<f32>() / passes.skin.len().max(1) as f32
    );
    if args.explain
        && let Some(thin) = body.thin_parts()
    {
        print!("{}", thin.report(&scene.material_names));
    }
    println!(
        "total {:.1} s; wrote {} and {}",
        t0.elapsed().as_secs_f64(),
        exr.display(),
        png.display()
    );
    Ok(())
}

/// Render with a progress bar on stderr (hidden when `show` is false or stderr is not a
/// terminal): passes, noise, converged pixels and ray rate.
fn render_with_bar(
    scene: &Scene,
    body: &BodyIntegrator,
    settings: &::render::renderer::RenderSettings,
    show: bool,
) -> Result<(::render::film::Film, ::render::renderer::RenderStats), ::render::error::RenderError> {
    let bar = if show {
        let b = ProgressBar::new((settings.width * settings.height) as u64);
        b.set_style(
            ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {percent:>3}% {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let noise_target = settings.noise.is_some();
    let mut on_pass = |p: &Progress| {
        if noise_target {
            bar.set_position(p.converged as u64);
        } else {
            bar.set_position(p.pixels as u64 * u64::from(p.done) / u64::from(p.spp));
        }
        bar.set_message(format!(
            "{}/{} spp, noise {:.2}%, {}/{} px converged, {:.2} Mrays/s",
            p.done,
            p.spp,
            100.0 * p.noise,
            p.converged,
            p.pixels,
            p.rays_per_second / 1e6
        ));
        if p.time_limit_reached {
            bar.println(format!("time limit reached after {} passes", p.done));
        }
    };
    let out = render_with(scene, body, settings, Some(&mut on_pass));
    bar.finish_and_clear();
    out
}

/// A settings error in the words of the command line: the flag that sets the option.
fn flag_error(e: SettingError) -> anyhow::Error {
    let flag = match e.name {
        "width" => "--width",
        "height" => "--height",
        "spp" => "--spp",
        "noise" => "--noise",
        "error_estimate" => "--error-estimate",
        "threads" => "--threads",
        "path.max_depth" => "--max-depth",
        "wavelength_nm" => "--wavelength",
        other => other,
    };
    anyhow::anyhow!("{flag} = {} outside {}", e.value, e.range)
}

/// The longest `--time-limit`, seconds (about 32 years): far inside what `Duration` holds.
const MAX_TIME_LIMIT_S: f64 = 1e9;

fn parse_time_limit(s: &str) -> Result<f64, String> {
    let v = parse_number(s, "[0, 1e9] seconds")?;
    if !(0.0..=MAX_TIME_LIMIT_S).contains(&v) {
        return Err(format!(
            "{} outside [0, 1e9] seconds (0 = no limit)",
            Num(v)
        ));
    }
    Ok(v)
}

fn parse_noise(s: &str) -> Result<f64, String> {
    let v = parse_number(s, "[0, 1)")?;
    if !(0.0..1.0).contains(&v) {
        return Err(format!("{} outside [0, 1) (0 = off)", Num(v)));
    }
    Ok(v)
}

fn parse_confidence(s: &str) -> Result<f64, String> {
    let v = parse_number(s, "[0, 10]")?;
    if !(0.0..=10.0).contains(&v) {
        return Err(format!("{} outside [0, 10]", Num(v)));
    }
    Ok(v)
}

fn parse_pixels(s: &str) -> Result<u32, String> {
    parse_whole(s, 1, 16384, "[1, 16384] pixels").map(|v| v as u32)
}

fn parse_spp(s: &str) -> Result<u32, String> {
    parse_whole(s, 1, u64::from(u32::MAX), "[1, 4294967295]").map(|v| v as u32)
}

fn parse_small_count(s: &str) -> Result<u32, String> {
    parse_whole(s, 1, 1024, "[1, 1024]").map(|v| v as u32)
}

fn parse_escapes(s: &str) -> Result<u64, String> {
    parse_whole(s, 100, 1_000_000_000, "[100, 1e9]")
}

fn parse_shape_photons(s: &str) -> Result<u64, String> {
    parse_whole(s, 10_000, 1_000_000_000, "[1e4, 1e9]")
}

fn parse_fraction(s: &str) -> Result<f64, String> {
    let v = parse_number(s, "(0, 0.1]")?;
    if !(v > 0.0 && v <= 0.1) {
        return Err(format!("{} outside (0, 0.1]", Num(v)));
    }
    Ok(v)
}

fn parse_step(s: &str) -> Result<f64, String> {
    let v = parse_number(s, "nm")?;
    if !::render::fidelity::wavelengths::STEPS_NM.contains(&v) {
        return Err(format!(
            "{} nm is not one of 5, 8, 10, 16, 20, 25, 40, 50, 80, 100",
            Num(v)
        ));
    }
    Ok(v)
}

fn parse_thin_walk(s: &str) -> Result<f64, String> {
    let v = parse_number(s, "[0, 10] r99")?;
    if !(0.0..=10.0).contains(&v) {
        return Err(format!("{} outside [0, 10] r99", Num(v)));
    }
    Ok(v)
}

fn parse_lod(s: &str) -> Result<LodSetting, String> {
    if s.trim().eq_ignore_ascii_case("off") {
        return Ok(LodSetting::Off);
    }
    let parts: Vec<&str> = s.split(',').collect();
    let [lo, hi] = parts[..] else {
        return Err("expected off or LO,HI (two numbers)".into());
    };
    let band = LodBand {
        full_below: parse_number(lo, "a number > 0")? as f32,
        diffuse_above: parse_number(hi, "a number > LO")? as f32,
    };
    band.checked()
        .map(LodSetting::Band)
        .map_err(|e| e.range.to_string())
}

fn rayon_threads(requested: Option<usize>) -> usize {
    requested.unwrap_or_else(rayon::current_num_threads)
}

/// `--error-estimate`: the command line's names for [`::render::adaptive::ErrorEstimate`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ErrorEstimateArg {
    /// σ̂²/n from the sample variance.
    SampleVariance,
    /// (Ȳ_A − Ȳ_B)²/4 from the means of the even and the odd samples.
    HalfDifference,
    /// The sample variance calibrated per 16 × 16 block by the half difference.
    Calibrated,
}

impl From<ErrorEstimateArg> for ::render::adaptive::ErrorEstimate {
    fn from(a: ErrorEstimateArg) -> Self {
        match a {
            ErrorEstimateArg::SampleVariance => Self::SampleVariance,
            ErrorEstimateArg::HalfDifference => Self::HalfDifference,
            ErrorEstimateArg::Calibrated => Self::Calibrated,
        }
    }
}
