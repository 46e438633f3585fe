//! `skin fit`: the skin parameters (C_m, β_m, C_h) that match an sRGB colour or a measured reflectance
//! spectrum, from `skin_fit`; prints the fit (with the forward model used), its colour, residual,
//! CIELAB and ITA°, or JSON.

use crate::args::{Checked, parse_number};
use anyhow::Context;
use clap::{ArgGroup, Args};
use multipole::Method;
use skin_fit::{
    BetaRange, FitOptions, Geometry, MeasuredOptions, MeasuredSpectrum, ModelChoice, fit_colour,
    fit_measured, fit_measured_colour, fit_spectrum,
};
use skin_optics::SkinParams;
use skin_optics::WavelengthGrid;
use skin_optics::color::{Srgb, Xyz};
use skin_optics::echo::{Num, Text};
use skin_optics::lab::Lab;
use std::path::{Path, PathBuf};

mod measured;

/// Arguments of `skin fit`.
#[derive(Args, Debug, Clone)]
#[command(group(ArgGroup::new("target").required(true).args(["srgb", "lab", "spectrum"])))]
pub struct FitArgs {
    /// Target colour, sRGB hex '#RRGGBB' (e.g. picked from a photograph), read as the skin's diffuse
    /// colour under D65.
    #[arg(long, value_name = "HEX", value_parser = Checked(parse_hex), allow_hyphen_values = true)]
    pub srgb: Option<Hex>,
    /// Target colour as CIELAB (D65, CIE 1931 2°) 'L,a,b', L* in [0, 100], a* and b* in
    /// [-200, 200]: e.g. a published mean skin colour, as the instrument (--geometry) measured it.
    #[arg(long, value_name = "L,a,b", value_parser = Checked(parse_lab), allow_hyphen_values = true)]
    pub lab: Option<Lab>,
    /// Measured diffuse reflectance, CSV with header `lambda_nm,reflectance` (optional third column
    /// `weight`), wavelengths increasing within 400-700 nm, '#' comment lines allowed.
    #[arg(long, value_name = "FILE.csv")]
    pub spectrum: Option<PathBuf>,
    /// Forward model: `exact` (adding-doubling totals, right for every skin tone; searched with a
    /// cheap 8-point exact model, then corrected to the full one) or `multipole` (the paper's
    /// diffusion: reproduces Donner & Jensen 2006 and is faster, but dark skin comes out too bright,
    /// so its melanin is fitted too high).
    #[arg(long, value_name = "METHOD", default_value = "exact", value_parser = Checked(parse_method), allow_hyphen_values = true)]
    pub method: Method,
    /// Instrument geometry of the target: `sce` (d/8, specular component excluded: the model's
    /// diffuse reflectance as is) or `sci` (d/8, specular included: adds the oily layer's surface
    /// reflection at 8°, with ρ_s fitted), for a spectrum and a colour alike.
    #[arg(long, value_name = "GEOMETRY", default_value = "sce", value_parser = parse_geometry)]
    pub geometry: Geometry,
    /// Parameters to fit: `seed` (C_m, β_m, C_h, plus ρ_s under sci), `full` (also blood near the
    /// surface, epidermis thickness, γ, scattering scales, bilirubin) or `auto` (the seed's plus
    /// what the information criterion accepts at --noise). For a colour (three coordinates) the
    /// criterion uses the colour noise that --noise implies; more parameters than coordinates
    /// leave their values undetermined, so read a colour fit as "the model reaches this colour".
    #[arg(long, value_name = "MODEL", default_value = "seed", value_parser = parse_model)]
    pub model: ModelChoice,
    /// Noise σ of one measured reflectance, for `--model auto`'s criterion, in (0, 1).
    #[arg(long, value_name = "SIGMA", default_value_t = 0.005)]
    pub noise: f64,
    /// Convergence tolerance of a spectrum fit's refinement, in χ² units at --noise, in [0, 1]
    /// (0: refine to the optimiser's precision).
    #[arg(long = "chi2-tolerance", value_name = "CHI2", default_value_t = skin_fit::CHI2_TOLERANCE)]
    pub chi2_tolerance: f64,
    /// Wavelength step of the model spectrum behind a colour, nm, in [0.01, 100].
    #[arg(long = "step-nm", value_name = "NM", default_value_t = 10.0, value_parser = Checked(parse_step), allow_hyphen_values = true)]
    pub step_nm: f64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// A parsed `#RRGGBB` colour with its original spelling.
#[derive(Debug, Clone, PartialEq)]
pub struct Hex {
    /// The colour.
    pub srgb: Srgb,
    /// Normalised `#rrggbb`.
    pub text: String,
}

fn parse_hex(s: &str) -> Result<Hex, String> {
    let srgb = Srgb::from_hex(s).ok_or_else(|| {
        format!(
            "'{}' is not an sRGB colour (expected #RRGGBB, six hex digits)",
            Text(s)
        )
    })?;
    Ok(Hex {
        text: srgb.to_hex(),
        srgb,
    })
}

fn parse_lab(s: &str) -> Result<Lab, String> {
    s.parse::<Lab>().map_err(|e| e.to_string())
}

fn parse_method(s: &str) -> Result<Method, String> {
    s.parse::<Method>().map_err(|e| e.to_string())
}

fn parse_geometry(s: &str) -> Result<Geometry, String> {
    s.parse::<Geometry>().map_err(|e| e.to_string())
}

fn parse_model(s: &str) -> Result<ModelChoice, String> {
    s.parse::<ModelChoice>().map_err(|e| e.to_string())
}

fn parse_step(s: &str) -> Result<f64, String> {
    let v = parse_number(s, "[0.01, 100] nm")?;
    // The lower bound is the finest wavelength grid the colour model accepts.
    if !(WavelengthGrid::MIN_STEP_NM..=100.0).contains(&v) {
        return Err(format!("{} outside [0.01, 100] nm", Num(v)));
    }
    Ok(v)
}

fn hex_of(xyz: Xyz) -> String {
    xyz.to_linear_srgb().to_srgb().to_hex()
}

pub(crate) fn lab_json(lab: Lab) -> serde_json::Value {
    serde_json::json!({
        "l": lab.l, "a": lab.a, "b": lab.b,
        "ita_deg": lab.ita_deg(), "ita_category": lab.ita_category().name(),
    })
}

pub(crate) fn colour_line(label: &str, hex: &str, lab: Lab) -> String {
    format!(
        "{label:<9}{hex}  L*a*b* ({:.2}, {:.2}, {:.2})  ITA° {:.1} ({})",
        lab.l,
        lab.a,
        lab.b,
        lab.ita_deg(),
        lab.ita_category()
    )
}

pub(crate) fn skin_line(skin: &SkinParams, method: Method) -> String {
    format!(
        "{:<9}C_m = {:.4}  β_m = {:.3}  C_h = {:.4}  (method {method})",
        "skin",
        skin.melanin(),
        skin.eumelanin_blend(),
        skin.hemoglobin()
    )
}

fn beta_line(range: Option<BetaRange>, unit: &str, prior: f64) -> Option<String> {
    range.map(|r| {
        format!(
            "{:<9}allowed range [{:.1}, {:.1}] (residual within {} {unit} of the best; ties resolved towards β_m = {prior})",
            "β_m", r.min, r.max, r.tolerance
        )
    })
}

fn beta_json(range: Option<BetaRange>) -> serde_json::Value {
    range.map_or(serde_json::Value::Null, |r| {
        serde_json::json!({ "min": r.min, "max": r.max, "tolerance": r.tolerance, "samples": r.samples })
    })
}

pub(crate) fn params_json(skin: &SkinParams) -> serde_json::Value {
    serde_json::json!({
        "melanin": skin.melanin(),
        "eumelanin_blend": skin.eumelanin_blend(),
        "hemoglobin": skin.hemoglobin(),
    })
}

/// What both kinds of fit report alike: the skin found, its colour, the β_m range and the effort.
struct Found<'a> {
    method: Method,
    skin: &'a SkinParams,
    fitted_hex: &'a str,
    lab: Lab,
    beta_range: Option<BetaRange>,
    beta_prior: f64,
    evaluations: usize,
    full_evaluations: usize,
}

/// The [`Found`] of a colour or a spectrum fit (the two result types share these fields).
macro_rules! found {
    ($fit:expr, $hex:expr, $opts:expr) => {
        Found {
            method: $opts.method,
            skin: &$fit.skin,
            fitted_hex: $hex,
            lab: $fit.lab,
            beta_range: $fit.beta_range,
            beta_prior: $opts.beta_prior,
            evaluations: $fit.evaluations,
            full_evaluations: $fit.full_evaluations,
        }
    };
}

impl Found<'_> {
    /// One JSON object: the shared keys merged with the kind's `own` keys (objects under the same
    /// key, such as `fitted`, are merged too).
    fn json(&self, own: serde_json::Value) -> serde_json::Value {
        let mut out = serde_json::json!({
            "method": self.method.to_string(),
            "parameters": params_json(self.skin),
            "fitted": { "srgb": self.fitted_hex, "lab": lab_json(self.lab) },
            "beta_range": beta_json(self.beta_range),
            "beta_prior": self.beta_prior,
            "evaluations": self.evaluations,
            "full_evaluations": self.full_evaluations,
        });
        if let (Some(o), serde_json::Value::Object(own)) = (out.as_object_mut(), own) {
            for (k, v) in own {
                match (o.get_mut(&k), v) {
                    (Some(serde_json::Value::Object(a)), serde_json::Value::Object(b)) => {
                        a.extend(b);
                    }
                    (_, v) => {
                        o.insert(k, v);
                    }
                }
            }
        }
        out
    }

    /// The text lines after the target's: skin, fitted colour, `residual`, β_m range in `unit`.
    fn print(&self, residual: &str, unit: &str) {
        println!("{}", skin_line(self.skin, self.method));
        println!("{}", colour_line("fitted", self.fitted_hex, self.lab));
        println!("{:<9}{residual}", "residual");
        if let Some(l) = beta_line(self.beta_range, unit, self.beta_prior) {
            println!("{l}");
        }
    }
}

/// The instrument and model options the command line asks for.
fn measured_options(args: &FitArgs, fit: FitOptions) -> MeasuredOptions {
    MeasuredOptions {
        geometry: args.geometry,
        model: args.model,
        noise: args.noise,
        chi2_tolerance: args.chi2_tolerance,
        fit,
        ..MeasuredOptions::default()
    }
}

/// Run `skin fit`.
pub fn run(args: &FitArgs) -> anyhow::Result<()> {
    let opts = FitOptions {
        method: args.method,
        step_nm: args.step_nm,
        ..FitOptions::default()
    };
    let colour = match (&args.srgb, args.lab) {
        (Some(hex), _) => Some((Lab::from_srgb(hex.srgb), hex.text.clone())),
        (None, Some(lab)) => Some((lab, lab.to_srgb().to_hex())),
        (None, None) => None,
    };
    if let Some((target, text)) = colour {
        if args.geometry != Geometry::Sce || args.model != ModelChoice::Seed {
            let fit = fit_measured_colour(target, &measured_options(args, opts))?;
            return measured::report_colour(args, &text, &fit, &opts);
        }
        let fit = fit_colour(target, &opts)?;
        let fitted_hex = hex_of(fit.xyz);
        let found = found!(fit, &fitted_hex, opts);
        if args.json {
            let out = found.json(serde_json::json!({
                "target": { "srgb": text, "lab": lab_json(target) },
                "residual": { "delta_e_2000": fit.delta_e },
                "in_gamut": fit.in_gamut,
                "gamut_threshold_delta_e_2000": opts.gamut_threshold_de,
            }));
            println!("{out}");
        } else {
            println!("{}", colour_line("target", &text, target));
            found.print(&format!("ΔE2000 = {:.3}", fit.delta_e), "ΔE2000");
        }
        if !fit.in_gamut {
            anyhow::bail!(
                "{} is out of gamut: no skin has this colour; the nearest skin (above) is ΔE2000 {:.1} away (threshold {})",
                text,
                fit.delta_e,
                opts.gamut_threshold_de
            );
        }
        return Ok(());
    }
    let Some(path) = &args.spectrum else {
        // clap's ArgGroup requires one of the two.
        anyhow::bail!("give --srgb '#RRGGBB', --lab L,a,b or --spectrum FILE.csv");
    };
    let text = skin_io::input::SPECTRUM.read_text(path)?;
    let measured =
        MeasuredSpectrum::parse_csv(&text).with_context(|| path.display().to_string())?;
    if args.geometry != Geometry::Sce || args.model != ModelChoice::Seed {
        let fit = fit_measured(&measured, &measured_options(args, opts))?;
        return measured::report(args, path, &measured, &fit, &opts);
    }
    let fit = fit_spectrum(&measured, &opts)?;
    let fitted_hex = fit.lab.to_srgb().to_hex();
    let found = found!(fit, &fitted_hex, opts);
    if args.json {
        let out = found.json(serde_json::json!({
            "target": { "spectrum": path.display().to_string(), "points": measured.len() },
            "fitted": { "lambda_nm": measured.lambda_nm(), "reflectance": fit.model },
            "residual": { "rms_reflectance": fit.rms },
            "within_tolerance": fit.within_tolerance,
            "max_rms_reflectance": opts.max_rms,
        }));
        println!("{out}");
    } else {
        println!(
            "{:<9}{} ({} wavelengths, {}-{} nm)",
            "target",
            path.display(),
            measured.len(),
            measured.lambda_nm()[0],
            measured.lambda_nm()[measured.len() - 1]
        );
        found.print(&format!("RMS reflectance = {:.5}", fit.rms), "RMS");
    }
    within_tolerance(path, fit.rms, opts.max_rms)
}

/// Fail when a spectrum fit's RMS exceeds the tolerance: no skin reproduces the spectrum.
pub(crate) fn within_tolerance(path: &Path, rms: f64, max_rms: f64) -> anyhow::Result<()> {
    if rms > max_rms {
        anyhow::bail!(
            "{}: no skin reproduces this spectrum; the nearest skin (above) has RMS reflectance error {rms:.3} (threshold {max_rms})",
            path.display()
        );
    }
    Ok(())
}
