//! `skin profile`: the radial diffuse reflectance profile R(r) of a skin at one wavelength, as CSV
//! (`r_mm,reflectance_per_mm2`), from `multipole::skin::profile`, or the whole spectral set
//! (`--from`/`--to`/`--step`: `lambda_nm,r_mm,reflectance_per_mm2`, from
//! `multipole::SpectralProfiles`); optionally a log–log chart of the profiles at 450, 550 and 650 nm.

use crate::args::{Checked, SkinArgs, parse_in, parse_whole};
use anyhow::Context;
use clap::Args;
use multipole::diffusion::spatial::DiffusionOptions;
use multipole::skin::{DEFAULT_SHAPE_ESCAPES, ExactShape, Method, ShapeTableOptions, profile};
use multipole::{Profile, ProfileOptions, SpectralProfiles};
use skin_optics::{Wavelength, WavelengthGrid};
use skin_plot::{LineChart, Panel, Series, palette_color, save_png};
use std::io::{BufWriter, Write};
use std::path::PathBuf;

/// Where the exact profile's radial shape comes from (`--shape`).
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapeChoice {
    /// The universal white Monte Carlo table, built once and cached.
    Table,
    /// A layered Monte Carlo run per wavelength (`--escapes`).
    MonteCarlo,
}

/// The surface the exact total is computed under (`--surface`, docs/physics.md §10.1).
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum SurfaceChoice {
    /// Fresnel faces: the model's smooth dielectric boundary.
    Smooth,
    /// The oily Torrance–Sparrow lobe (Beckmann slope `--roughness`, the skin's ρ_s) as the
    /// boundary, as the renderer's default surface.
    Oily,
}

/// Arguments of `skin profile`.
#[derive(Args, Debug, Clone)]
pub struct ProfileArgs {
    /// The skin (preset and/or fractions).
    #[command(flatten)]
    pub skin: SkinArgs,
    /// Wavelength, nm, in [250, 1000] (the model's data cover 400-700 nm best).
    #[arg(long, value_name = "NM", value_parser = Checked(parse_lambda), allow_hyphen_values = true,
          required_unless_present = "from", conflicts_with = "from")]
    pub lambda: Option<f64>,
    /// First wavelength of a spectral set, nm, in [250, 1000] (with --to): every row then starts
    /// with its `lambda_nm`.
    #[arg(long, value_name = "NM", value_parser = Checked(parse_lambda), allow_hyphen_values = true,
          requires = "to")]
    pub from: Option<f64>,
    /// Last wavelength of the spectral set, nm, in [250, 1000], ≥ --from.
    #[arg(long, value_name = "NM", value_parser = Checked(parse_lambda), allow_hyphen_values = true,
          requires = "from")]
    pub to: Option<f64>,
    /// Step of the spectral set, nm, in [0.01, 750] (default 10).
    #[arg(long, value_name = "NM", default_value_t = 10.0, value_parser = Checked(parse_step),
          allow_hyphen_values = true)]
    pub step: f64,
    /// Outer radius of the table, mm, in [0.002, 10000]; default: the radius holding 99.9% of the energy.
    #[arg(long = "r-max", value_name = "MM", value_parser = Checked(parse_r_max), allow_hyphen_values = true)]
    pub r_max: Option<f64>,
    /// Number of radii, geometric from 0.001 mm to the outer radius, in [2, 1000000].
    #[arg(long, value_name = "N", default_value_t = 256, value_parser = Checked(parse_samples), allow_hyphen_values = true)]
    pub samples: usize,
    /// Profile method: exact (the default: adding-doubling total, exact shape from the shape table)
    /// or multipole (the paper's diffusion, too bright for dark skin).
    #[arg(long, value_name = "METHOD", default_value_t = Method::default(), value_parser = Checked(parse_method), allow_hyphen_values = true)]
    pub method: Method,
    /// Shape of the exact profile: `table` (the default: the universal white Monte Carlo table,
    /// built once and cached) or `monte-carlo` (a layered Monte Carlo run per wavelength, --escapes).
    #[arg(long, value_name = "SHAPE", value_enum, default_value_t = ShapeChoice::Table)]
    pub shape: ShapeChoice,
    /// Escaping photons of the exact profile's Monte Carlo shape (`--shape monte-carlo`), in
    /// [100, 1e9] (the accuracy knob: noise ∝ 1/√N; the photons traced are N divided by the skin's
    /// reflectance).
    #[arg(long, value_name = "N", default_value_t = DEFAULT_SHAPE_ESCAPES, value_parser = Checked(parse_escapes), allow_hyphen_values = true)]
    pub escapes: u64,
    /// Surface of the exact total: `smooth` (the default: Fresnel faces, the model's) or `oily`
    /// (the oily lobe as the boundary, as the renderer's default surface; docs/physics.md §10.1).
    /// Diffusion keeps Fresnel's.
    #[arg(long, value_name = "SURFACE", value_enum, default_value_t = SurfaceChoice::Smooth)]
    pub surface: SurfaceChoice,
    /// Beckmann roughness m of the oily surface (`--surface oily`), (0, 1].
    #[arg(long, value_name = "M", default_value_t = brdf::DEFAULT_ROUGHNESS, allow_hyphen_values = true, value_parser = Checked(crate::brdf::parse_roughness))]
    pub roughness: f32,
    /// Print to stderr the treatment used and why (layer albedos, epidermis thickness in mean free
    /// paths, diffusion versus exact total, the exact profile's per-layer factors).
    #[arg(long)]
    pub explain: bool,
    /// Also draw the profiles at 450, 550 and 650 nm on log axes to this PNG file.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
}

fn parse_lambda(s: &str) -> Result<f64, String> {
    parse_in(s, 250.0, 1000.0, "[250, 1000] nm")
}

fn parse_step(s: &str) -> Result<f64, String> {
    parse_in(s, 0.01, 750.0, "[0.01, 750] nm")
}

fn parse_r_max(s: &str) -> Result<f64, String> {
    parse_in(s, 0.002, 1e4, "[0.002, 10000] mm")
}

fn parse_samples(s: &str) -> Result<usize, String> {
    parse_whole(s, 2, 1_000_000, "[2, 1000000]").map(|v| v as usize)
}

fn parse_escapes(s: &str) -> Result<u64, String> {
    parse_whole(s, 100, 1_000_000_000, "[100, 1e9]")
}

fn parse_method(s: &str) -> Result<Method, String> {
    s.parse::<Method>().map_err(|e| e.to_string())
}

/// `p` on `opts.radial_samples` geometric radii from 1e-3 mm to `opts.r_max_mm` (default: its own
/// outer radius), as the diffusion tables are laid out; a Monte Carlo shape has its own grid.
fn on_requested_radii(p: Profile, opts: &ProfileOptions) -> anyhow::Result<Profile> {
    let n = opts.diffusion.radial_samples;
    if p.radii_mm().len() == n
        && opts
            .diffusion
            .r_max_mm
            .is_none_or(|r| (r - p.r_max_mm()).abs() < 1e-12)
    {
        return Ok(p);
    }
    let (r0, r1) = (
        1e-3_f64,
        opts.diffusion
            .r_max_mm
            .unwrap_or_else(|| p.r_max_mm())
            .max(2e-3),
    );
    let radii: Vec<f64> = (0..n)
        .map(|i| r0 * (r1 / r0).powf(i as f64 / (n - 1) as f64))
        .collect();
    let values = radii.iter().map(|&r| p.eval(r)).collect();
    Ok(Profile::from_table(radii, values, p.total())?)
}

/// Run `skin profile`.
pub fn run(args: &ProfileArgs) -> anyhow::Result<()> {
    let skin = args.skin.to_params()?;
    let opts = ProfileOptions {
        diffusion: DiffusionOptions {
            radial_samples: args.samples,
            r_max_mm: args.r_max,
            ..DiffusionOptions::default()
        },
        exact_shape: match args.shape {
            ShapeChoice::MonteCarlo => ExactShape::MonteCarlo {
                escapes: args.escapes,
            },
            ShapeChoice::Table => ExactShape::Table(ShapeTableOptions::default()),
        },
        surface: match args.surface {
            SurfaceChoice::Smooth => multipole::Surface::Fresnel,
            SurfaceChoice::Oily => {
                multipole::Surface::lobe(f64::from(args.roughness), skin.oiliness())
                    .context("--roughness")?
            }
        },
        ..ProfileOptions::default()
    };
    let (Some(nm), None) = (args.lambda, args.from) else {
        return run_spectral(args, &skin, &opts);
    };
    let lambda = Wavelength::new(nm).context("--lambda")?;
    let prof = on_requested_radii(profile(&skin, lambda, args.method, &opts)?, &opts)?;
    if args.explain {
        eprintln!(
            "{}",
            multipole::skin::explain(&skin, lambda, args.method, Some(opts.exact_shape))
                .context("--explain")?
        );
    }
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    writeln!(out, "r_mm,reflectance_per_mm2")?;
    write_rows(&mut out, "", &prof)?;
    out.flush()?;
    eprintln!(
        "R_d = {:.5} (model, per unit flux entering), r99 = {:.4} mm, r_max = {:.4} mm, method {}",
        prof.total(),
        prof.radius_99_mm(),
        prof.r_max_mm(),
        args.method
    );
    plot(args, &skin, &opts)
}

/// One CSV row `{prefix}r,R(r)` per radius of `p`.
fn write_rows(out: &mut impl Write, prefix: &str, p: &Profile) -> std::io::Result<()> {
    for (r, v) in p.radii_mm().iter().zip(p.reflectance_per_mm2()) {
        writeln!(out, "{prefix}{r:.6e},{v:.6e}")?;
    }
    Ok(())
}

/// The spectral set `--from`..`--to` every `--step` nm: one CSV row per (λ, r).
fn run_spectral(
    args: &ProfileArgs,
    skin: &skin_optics::SkinParams,
    opts: &ProfileOptions,
) -> anyhow::Result<()> {
    let (Some(from), Some(to)) = (args.from, args.to) else {
        anyhow::bail!("give --lambda, or --from and --to");
    };
    let grid = WavelengthGrid::new(from, to, args.step).context("--from/--to/--step")?;
    let set = SpectralProfiles::new(skin, &grid, args.method, opts)?;
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    writeln!(out, "lambda_nm,r_mm,reflectance_per_mm2")?;
    for (i, p) in set.profiles().iter().enumerate() {
        let p = on_requested_radii(p.clone(), opts)?;
        let nm = grid.wavelength(i).nm();
        write_rows(&mut out, &format!("{nm},"), &p)?;
    }
    out.flush()?;
    eprintln!(
        "{} wavelengths {from}-{to} nm every {} nm, method {}",
        grid.len(),
        grid.step_nm(),
        args.method
    );
    plot(args, skin, opts)
}

/// `--plot`: the profiles at 450, 550 and 650 nm on log axes.
fn plot(
    args: &ProfileArgs,
    skin: &skin_optics::SkinParams,
    opts: &ProfileOptions,
) -> anyhow::Result<()> {
    if let Some(path) = &args.plot {
        let mut chart = LineChart::new("Diffuse reflectance profile R(r)", "r (mm)", "R(r) (mm⁻²)")
            .log_x()
            .log_y();
        for (i, nm) in [450.0, 550.0, 650.0].into_iter().enumerate() {
            let p = on_requested_radii(
                profile(skin, Wavelength::new(nm)?, args.method, opts)?,
                opts,
            )?;
            let points = p
                .radii_mm()
                .iter()
                .copied()
                .zip(p.reflectance_per_mm2().iter().copied())
                .collect();
            chart = chart
                .with_series(Series::line(format!("{nm} nm"), points).with_color(palette_color(i)));
        }
        save_png(path, &[Panel::Line(chart)], 900, 600)
            .with_context(|| format!("--plot {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
