//! `skin maps`: chromophore maps (C_m, β_m, C_h, the residual ΔE2000 and the in-gamut flag) from
//! an albedo texture, through [`skin_fit::maps`]; optional edits of the maps; the maps as one
//! EXR, PNG previews and the albedo the (edited) maps reproduce.

pub mod image_file;

use anyhow::{Context, bail};
use clap::Args;
use image_file::{LinearImage, SrgbEncoder};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use skin_fit::ModelChoice;
use skin_fit::maps::{
    DEFAULT_SMOOTHNESS, Edit, Eumelanin, Exposure, ExtendedFit, Maps, MapsModel, MapsOptions,
    Regions, apply_edits,
};
use skin_plot::{HeatMap, Panel};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The channels of `maps.exr`, in the order written (the EXR stores them sorted by name).
pub const CHANNELS: [&str; 5] = ["melanin", "eumelanin", "hemoglobin", "delta_e", "in_gamut"];

/// Longest side of a preview map, cells (each the mean of a block of texels).
pub const PREVIEW_CELLS: usize = 256;

/// Arguments of `skin maps`.
#[derive(Args, Debug, Clone)]
pub struct MapsArgs {
    /// The albedo texture: PNG or JPEG (sRGB-encoded, 8 or 16 bit) or OpenEXR (linear). A texel is
    /// the skin's diffuse albedo: diffuse reflectance with the specular excluded (the SCE of `skin
    /// fit`) under D65, CIE 1931 2°, as linear Rec.709 with a perfect white diffuser at 1 — the
    /// colour `skin spectrum` prints.
    #[arg(long, value_name = "FILE")]
    pub albedo: PathBuf,
    /// Texels to fit: an image of the same size, fitted where its luminance is at least 0.5; the
    /// other texels are copied through to albedo.png and flagged (in_gamut 0).
    #[arg(long, value_name = "FILE")]
    pub mask: Option<PathBuf>,
    /// Folder for maps.exr, albedo.png and the previews (created if missing).
    #[arg(long, value_name = "DIR", default_value = "out/maps")]
    pub out: PathBuf,
    /// Eumelanin blend β_m of the whole texture, [0, 1], instead of fitting it.
    #[arg(long, value_name = "B", value_parser = crate::args::Checked(crate::args::parse_fraction), conflicts_with = "fit_eumelanin")]
    pub eumelanin: Option<f64>,
    /// Fit β_m over the texels (the default), and report the range the data allow.
    #[arg(long)]
    pub fit_eumelanin: bool,
    /// β_m per square region of BLOCK texels a side, in [4, 4096], instead of one value: each
    /// region's β_m fitted on its texels with a smoothness prior between neighbouring regions
    /// (a β_m step of 0.1 costs as much as one sampled texel 1 ΔE2000 worse); the summary reports
    /// the range of the regions' β_m and how wide a range each region's texels allow.
    #[arg(long, value_name = "BLOCK", conflicts_with_all = ["eumelanin", "fit_eumelanin"], value_parser = clap::value_parser!(u32).range(4..=4096))]
    pub eumelanin_regions: Option<u32>,
    /// Gains on the linear texels before the fit, each in [0.125, 2]: G (all channels), R,G,B,
    /// `auto` (one gain fitted with β_m: the one whose maps reproduce a sample of the texels best;
    /// its range is reported) or `auto-rgb` (one per channel: exposure and white balance). For a
    /// photograph whose light level or colour balance is not a measured albedo's; 1 takes the
    /// texels as they are. Residuals are measured at the texture's own exposure; albedo.png is
    /// the fitted skins' albedo, so the texture after the gains.
    #[arg(long, value_name = "G|R,G,B|auto|auto-rgb", default_value = "1", allow_hyphen_values = true, value_parser = crate::args::Checked(parse_exposure))]
    pub exposure: Exposure,
    /// Parameters beyond C_m, β_m, C_h, as `skin fit --model`: `seed` (none), `full` (blood near
    /// the surface, epidermis thickness, γ, scattering scales, bilirubin) or `auto` (those that
    /// lower the sample's RMS capped ΔE2000 by more than 0.25). Each is one value per texture,
    /// fitted over the texels as β_m is (three colour numbers per texel go to C_m and C_h); each
    /// kept one adds a channel to maps.exr named as in `skin fit --json`.
    #[arg(long, value_name = "MODEL", default_value = "seed", value_parser = crate::args::Checked(parse_model))]
    pub model: ModelChoice,
    /// The extended parameters `--model full|auto` tries, comma-separated, named as in `skin fit
    /// --json` (epidermis_blood, epidermis_thickness_mm, oxygenation, mie_scale, rayleigh_scale,
    /// dermis_scattering_scale, bilirubin_g_per_l); default all of them.
    #[arg(long, value_name = "NAMES", value_delimiter = ',', value_parser = crate::args::Checked(parse_parameter))]
    pub parameters: Vec<skin_fit::Parameter>,
    /// Texels out of gamut are fitted again under a thin epidermis of this thickness, mm, in
    /// [0.04, 0.3] (lip vermilion), and keep that skin where it reproduces them at least 1
    /// ΔE2000 closer; `off`: one skin for every texel. maps.exr gets a channel
    /// `thin_epidermis` (1 where a texel has it; its header attribute `thin_epidermis_mm` holds
    /// the thickness).
    #[arg(long, value_name = "MM|off", default_value = "0.05", value_parser = crate::args::Checked(parse_thin_epidermis))]
    pub thin_epidermis: ThinEpidermisArg,
    /// The top of the thin-epidermis skin's blood fraction C_h, in (0.001, 1]: the default 0.25 is
    /// the plausible range of Aliaga et al. 2023's skin model (the vermilion's capillaries lie
    /// dense under its thin epithelium); 0.1 gives it the range of the texture's skin.
    #[arg(long, value_name = "C", default_value = "0.25", value_parser = crate::args::Checked(parse_thin_hemoglobin_max))]
    pub thin_hemoglobin_max: f64,
    /// Edit the maps before writing them, in order (repeatable): melanin*S, melanin+D,
    /// melanin-D (tanning, pallor), hemoglobin*S, hemoglobin+D, hemoglobin-D (flush; under
    /// --edit-mask if given), eumelanin=B. albedo.png is then the forward model of the edited maps.
    #[arg(long = "edit", value_name = "OP", value_parser = crate::args::Checked(parse_edit), allow_hyphen_values = true)]
    pub edits: Vec<Edit>,
    /// Weight of the hemoglobin edits per texel: an image of the same size whose luminance (0 to 1)
    /// blends each texel between its fitted and its edited C_h (e.g. a blush).
    #[arg(long, value_name = "FILE")]
    pub edit_mask: Option<PathBuf>,
    /// Build the forward table in memory instead of reading it from (or storing it in) the cache.
    #[arg(long)]
    pub no_cache: bool,
}

/// Parse one `--edit` (clap value parser).
pub fn parse_edit(s: &str) -> Result<Edit, String> {
    s.parse()
        .map_err(|e: skin_fit::maps::MapsError| e.to_string())
}

/// Parse `--model` (clap value parser).
pub fn parse_model(s: &str) -> Result<ModelChoice, String> {
    s.parse().map_err(|e: skin_fit::FitError| e.to_string())
}

/// Parse one name of `--parameters` (clap value parser).
pub fn parse_parameter(s: &str) -> Result<skin_fit::Parameter, String> {
    let candidates = skin_fit::Parameter::CANDIDATES;
    candidates
        .iter()
        .copied()
        .find(|p| p.name() == s.trim())
        .ok_or_else(|| {
            let known: Vec<&str> = candidates.iter().map(|p| p.name()).collect();
            format!(
                "'{}' is not an extended parameter (one of {})",
                skin_optics::echo::Text(s),
                known.join(", ")
            )
        })
}

/// Parse `--thin-hemoglobin-max` (clap value parser).
pub fn parse_thin_hemoglobin_max(s: &str) -> Result<f64, String> {
    let c = crate::args::parse_number(s, "(0.001, 1]")?;
    if c > skin_fit::maps::THIN_HEMOGLOBIN_RANGE[0] && c <= 1.0 {
        Ok(c)
    } else {
        Err(format!("{} outside (0.001, 1]", skin_optics::echo::Num(c)))
    }
}

/// `--thin-epidermis`: the thickness, mm, or `None` for `off`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThinEpidermisArg(pub Option<f64>);

/// Parse `--thin-epidermis` (clap value parser).
pub fn parse_thin_epidermis(s: &str) -> Result<ThinEpidermisArg, String> {
    if s.trim().eq_ignore_ascii_case("off") {
        return Ok(ThinEpidermisArg(None));
    }
    let t = crate::args::parse_number(s, "[0.04, 0.3] mm")?;
    let [lo, hi] = skin_fit::Parameter::EpidermisThickness.range();
    if !(lo..=hi).contains(&t) {
        return Err(format!(
            "{} mm outside [0.04, 0.3] mm (or off)",
            skin_optics::echo::Num(t)
        ));
    }
    Ok(ThinEpidermisArg(Some(t)))
}

/// Parse `--exposure` (clap value parser).
pub fn parse_exposure(s: &str) -> Result<Exposure, String> {
    s.parse()
}

/// Luminance (Rec.709 Y) of the sRGB-encoded value of a linear texel, in [0, 1]: how a mask
/// painted in an image editor reads.
fn mask_value(t: [f32; 3]) -> f32 {
    let y = 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2];
    if y.is_nan() {
        return 0.0;
    }
    skin_optics::color::srgb_encode(f64::from(y.clamp(0.0, 1.0))) as f32
}

/// A mask or weight image of the texture's size.
fn read_same_size(path: &Path, flag: &str, texture: &LinearImage) -> anyhow::Result<Vec<f32>> {
    let img = image_file::read(path).with_context(|| format!("{flag} {}", path.display()))?;
    if (img.width, img.height) != (texture.width, texture.height) {
        bail!(
            "{flag} {} is {}×{}, the albedo texture {}×{} (they must match)",
            path.display(),
            img.width,
            img.height,
            texture.width,
            texture.height
        );
    }
    Ok(img.texels.into_iter().map(mask_value).collect())
}

/// Run `skin maps`.
pub fn run(args: &MapsArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    let texture = image_file::read(&args.albedo)
        .with_context(|| format!("--albedo {}", args.albedo.display()))?;
    let mask: Option<Vec<bool>> = args
        .mask
        .as_ref()
        .map(|p| read_same_size(p, "--mask", &texture))
        .transpose()?
        .map(|v| v.into_iter().map(|m| m >= 0.5).collect());
    let weight = args
        .edit_mask
        .as_ref()
        .map(|p| read_same_size(p, "--edit-mask", &texture))
        .transpose()?;
    let read_s = start.elapsed().as_secs_f64();

    let opts = MapsOptions {
        eumelanin: match (args.eumelanin, args.eumelanin_regions) {
            (Some(b), _) => Eumelanin::Fixed(b),
            (None, Some(block)) => Eumelanin::PerRegion(Regions {
                width: texture.width,
                block: block as usize,
                smoothness: DEFAULT_SMOOTHNESS,
            }),
            (None, None) => Eumelanin::Fit,
        },
        exposure: args.exposure,
        thin_epidermis_mm: args.thin_epidermis.0,
        thin_hemoglobin_max: args.thin_hemoglobin_max,
        cache_dir: if args.no_cache {
            None
        } else {
            skin_io::cache::cache_dir()
        },
        cache_max_bytes: skin_io::cache::max_bytes()?,
        ..MapsOptions::default()
    };
    let t = Instant::now();
    let mut opts = opts;
    let mut model = MapsModel::load(&opts).context("forward table")?;
    let extended = if args.model == ModelChoice::Seed {
        None
    } else {
        let spinner = ProgressBar::new_spinner();
        spinner.enable_steady_tick(std::time::Duration::from_millis(200));
        let fit = model.fit_extended(
            &texture.texels,
            mask.as_deref(),
            &opts,
            args.model,
            if args.parameters.is_empty() {
                &skin_fit::Parameter::CANDIDATES
            } else {
                &args.parameters
            },
            &|name| spinner.set_message(format!("fitting {name} over the texture")),
        )?;
        spinner.finish_and_clear();
        opts.base = fit.base;
        model = MapsModel::load(&opts).context("forward table of the extended skin")?;
        Some(fit)
    };
    let table_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let n = texture.texels.len();
    let bar = ProgressBar::new(n as u64);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {percent:>3}% {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message("fitting texels");
    let mut maps = model.fit(&texture.texels, mask.as_deref(), &opts, &|k| {
        bar.inc(k as u64);
    })?;
    bar.finish_and_clear();
    let fit_s = t.elapsed().as_secs_f64();
    let fitted = maps.summary.clone();
    let beta = maps.eumelanin;
    apply_edits(&mut maps, &args.edits, weight.as_deref())?;

    let t = Instant::now();
    let mut albedo = model.albedo_of(&maps)?;
    // Texels not fitted are copied through at the same gain, so the image stays one exposure.
    let gain = fitted.exposure.map(|g| g as f32);
    for (a, (t, f)) in albedo
        .iter_mut()
        .zip(texture.texels.iter().zip(&maps.fitted))
    {
        if !f {
            *a = [t[0] * gain[0], t[1] * gain[1], t[2] * gain[2]];
        }
    }
    let extra: Vec<(&'static str, f32)> = extended
        .as_ref()
        .map(|e| {
            e.kept()
                .map(|v| (v.parameter.name(), v.value as f32))
                .collect()
        })
        .unwrap_or_default();
    write_outputs(&args.out, &texture, &maps, &albedo, &extra)?;
    let write_s = t.elapsed().as_secs_f64();

    let s = &fitted;
    let pct = |k: usize| 100.0 * k as f64 / s.fitted.max(1) as f64;
    eprintln!(
        "maps: {}×{} texels, {} fitted, {} in gamut (ΔE2000 ≤ 1: {:.1}%), {} bad values replaced",
        texture.width,
        texture.height,
        s.fitted,
        s.in_gamut,
        pct(s.in_gamut),
        s.invalid
    );
    eprintln!(
        "residual ΔE2000 over fitted texels: median {:.3}, p95 {:.3}, max {:.3}",
        s.median_de, s.p95_de, s.max_de
    );
    match (&s.regions, &s.eumelanin_spread) {
        (Some(r), _) => eprintln!(
            "eumelanin β_m per region of {b}×{b} texels ({} regions): median {:.2}, {:.2}-{:.2}; each region's texels allow a range of median width {:.2} (RMS capped ΔE2000 within {} of its best); smoothness {} ΔE² per unit β_m²",
            r.regions,
            r.median,
            r.min,
            r.max,
            r.median_allowed_width,
            opts.beta_tolerance_de,
            DEFAULT_SMOOTHNESS,
            b = args.eumelanin_regions.unwrap_or(0),
        ),
        (None, Some(r)) => eprintln!(
            "eumelanin β_m {:.3} (fitted; the texels allow {:.2}-{:.2}: RMS capped ΔE2000 within {} of the best {:.3})",
            beta, r.min, r.max, r.tolerance_de, r.best_rms_de
        ),
        (None, None) => eprintln!("eumelanin β_m {beta:.3} (given)"),
    }
    let [gr, gg, gb] = s.exposure;
    match (&s.exposure_spread, args.exposure) {
        (Some(r), _) => eprintln!(
            "exposure: gain {gr:.3} on every texel (fitted; the texels allow {:.3}-{:.3}: RMS capped ΔE2000 within {} of the best {:.3})",
            r.min, r.max, r.tolerance_de, r.best_rms_de
        ),
        (None, Exposure::WhiteBalance) => eprintln!(
            "exposure: gains R {gr:.3}, G {gg:.3}, B {gb:.3} on every texel (fitted with β_m)"
        ),
        (None, _) => {
            eprintln!("exposure: gains R {gr:.3}, G {gg:.3}, B {gb:.3} on every texel (given)")
        }
    }
    if let Some(e) = &extended {
        print_extended(args.model, e);
    }
    if let Some(t) = &maps.thin_epidermis {
        eprintln!(
            "thin epidermis ({} mm): {} texels ({:.1}%) fitted under it",
            t.epidermis_mm,
            s.thin_epidermis,
            pct(s.thin_epidermis)
        );
    }
    if !args.edits.is_empty() {
        let list: Vec<String> = args.edits.iter().map(ToString::to_string).collect();
        eprintln!(
            "edits: {} (albedo.png is the edited maps' forward model)",
            list.join(", ")
        );
    }
    eprintln!("forward table: {}", model.cache_outcome());
    eprintln!(
        "time: read {read_s:.2} s, table {table_s:.2} s, fit {fit_s:.2} s, write {write_s:.2} s, total {:.2} s",
        start.elapsed().as_secs_f64()
    );
    eprintln!(
        "wrote {}: maps.exr, albedo.png, melanin.png, hemoglobin.png, delta_e.png",
        args.out.display()
    );
    Ok(())
}

/// The summary lines of the extended parameters.
fn print_extended(model: ModelChoice, e: &ExtendedFit) {
    let list: Vec<String> = e
        .values
        .iter()
        .map(|v| {
            format!(
                "{} {:.4}{} (the texels allow {:.4}-{:.4})",
                v.parameter.name(),
                v.value,
                if v.kept { "" } else { ", not kept" },
                v.range.min,
                v.range.max
            )
        })
        .collect();
    eprintln!(
        "model {model}: one value per texture: {}",
        if list.is_empty() {
            "none".to_string()
        } else {
            list.join("; ")
        }
    );
    eprintln!(
        "  sample RMS capped ΔE2000: seed model {:.3}, with these {:.3}",
        e.seed_rms_de, e.rms_de
    );
}

/// Write maps.exr (with a constant channel per kept extended parameter in `extra`), albedo.png
/// and the previews as one group (all or none).
fn write_outputs(
    out: &Path,
    texture: &LinearImage,
    maps: &Maps,
    albedo: &[[f32; 3]],
    extra: &[(&'static str, f32)],
) -> anyhow::Result<()> {
    let (w, h) = (texture.width, texture.height);
    let n = w * h;
    let flag: Vec<f32> = maps
        .in_gamut
        .iter()
        .map(|g| f32::from(u8::from(*g)))
        .collect();
    let mut channels = vec![
        (CHANNELS[0], maps.melanin.clone()),
        (
            CHANNELS[1],
            maps.eumelanin_map
                .clone()
                .unwrap_or_else(|| vec![maps.eumelanin as f32; n]),
        ),
        (CHANNELS[2], maps.hemoglobin.clone()),
        (CHANNELS[3], maps.delta_e.clone()),
        (CHANNELS[4], flag),
    ];
    channels.extend(extra.iter().map(|(name, v)| (*name, vec![*v; n])));
    // The flag's thickness travels with it, so a renderer reads the texel's epidermis from the
    // file alone.
    let mut attributes = Vec::new();
    if let Some(t) = &maps.thin_epidermis {
        channels.push((
            render::material::maps::THIN_EPIDERMIS_CHANNEL,
            t.texels.iter().map(|f| f32::from(u8::from(*f))).collect(),
        ));
        attributes.push((
            render::material::maps::THIN_EPIDERMIS_ATTRIBUTE,
            t.epidermis_mm as f32,
        ));
    }
    let exr = render::texture::channels_exr_bytes_with(w, h, channels, &attributes)
        .map_err(anyhow::Error::msg)?;
    let encoder = SrgbEncoder::default();
    let rgb: Vec<u8> = albedo
        .par_iter()
        .with_min_len(1 << 14)
        .flat_map_iter(|t| t.map(|c| encoder.encode(c)))
        .collect();
    let albedo_png = image_file::png_bytes(w, h, &rgb)?;
    let preview = |values: &[f32], title: &str, label: &str, range: Option<(f64, f64)>| {
        preview_png(w, h, values, &maps.fitted, title, label, range)
    };
    // Both fractions span decades: their previews show log₁₀ (C_m 0 shows as −4).
    let log = |v: &[f32]| -> Vec<f32> { v.iter().map(|x| x.max(1e-4).log10()).collect() };
    let melanin = preview(
        &log(&maps.melanin),
        "Melanin: log₁₀ C_m",
        "log₁₀ C_m (volume fraction)",
        None,
    )?;
    let hemoglobin = preview(
        &log(&maps.hemoglobin),
        "Hemoglobin: log₁₀ C_h",
        "log₁₀ C_h (volume fraction)",
        None,
    )?;
    let delta_e = preview(
        &maps.delta_e,
        "Residual ΔE2000 (grey: not fitted)",
        "ΔE2000",
        Some((0.0, 5.0)),
    )?;
    let staged = [
        ("maps.exr", exr),
        ("albedo.png", albedo_png),
        ("melanin.png", melanin),
        ("hemoglobin.png", hemoglobin),
        ("delta_e.png", delta_e),
    ]
    .into_iter()
    .map(|(name, bytes)| skin_io::atomic::stage_bytes(&out.join(name), &bytes))
    .collect::<Result<Vec<_>, _>>()?;
    skin_io::atomic::commit(staged)?;
    Ok(())
}

/// A heat map of `values` (block means over fitted texels, grey where a block has none) with a
/// colour bar, as PNG bytes.
fn preview_png(
    w: usize,
    h: usize,
    values: &[f32],
    fitted: &[bool],
    title: &str,
    label: &str,
    range: Option<(f64, f64)>,
) -> anyhow::Result<Vec<u8>> {
    let block = w.max(h).div_ceil(PREVIEW_CELLS).max(1);
    let (nx, ny) = (w.div_ceil(block), h.div_ceil(block));
    let mut cells = vec![f64::NAN; nx * ny];
    for cy in 0..ny {
        for cx in 0..nx {
            let (mut sum, mut count) = (0.0, 0usize);
            for y in cy * block..((cy + 1) * block).min(h) {
                for x in cx * block..((cx + 1) * block).min(w) {
                    if fitted[y * w + x] {
                        sum += f64::from(values[y * w + x]);
                        count += 1;
                    }
                }
            }
            // Row 0 of a heat map is at the bottom; image rows run top down.
            if count > 0 {
                cells[(ny - 1 - cy) * nx + cx] = sum / count as f64;
            }
        }
    }
    let heat = HeatMap {
        title: title.into(),
        x_label: "x (texels)".into(),
        y_label: "y (texels from the bottom)".into(),
        value_label: label.into(),
        x_range: (0.0, w as f64),
        y_range: (0.0, h as f64),
        nx,
        ny,
        values: cells,
        value_range: range,
        ..HeatMap::default()
    };
    let width = 760u32;
    let height = ((f64::from(width - 110) * h as f64 / w as f64) as u32 + 110).clamp(200, 1400);
    let rgb = skin_plot::render_rgb(&[Panel::Heat(heat)], width, height)?;
    image_file::png_bytes(width as usize, height as usize, &rgb)
}
