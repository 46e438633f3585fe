//! `skin export FORMAT`: the skin written for another renderer or simulator (`crate::export`), to
//! `--out` atomically or to stdout; its notes (units, conventions, measured errors) go to stderr.

use crate::args::SkinArgs;
use anyhow::Context;
use clap::Args;
use skin_export::textured::{ChromophoreTexture, TexturedOptions, ThinTexels, export_textured};
use skin_export::{ColourSpace, ExportOptions, Format, export};
use skin_io::atomic::write_bytes;
use skin_optics::{Wavelength, WavelengthGrid};
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `skin export`.
#[derive(Args, Debug, Clone)]
pub struct ExportArgs {
    /// Format: openpbr, standard-surface, unreal, hdrp, gaussians, burley, pbrt, mitsuba, mcml, mcx,
    /// blender (a bpy script), blender-json (its values).
    #[arg(value_name = "FORMAT")]
    pub format: String,
    /// The skin (preset and/or fractions).
    #[command(flatten)]
    pub skin: SkinArgs,
    /// Write the file here (atomically: whole or not at all); default: stdout.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// First wavelength, nm, [250, 1000].
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 400.0,
        allow_negative_numbers = true
    )]
    pub from: f64,
    /// Last wavelength, nm, [250, 1000], ≥ --from.
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 700.0,
        allow_negative_numbers = true
    )]
    pub to: f64,
    /// Wavelength step, nm, [0.01, 750].
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 10.0,
        allow_negative_numbers = true
    )]
    pub step: f64,
    /// Escaping photons of each exact profile's Monte Carlo shape, [100, 1e9] (reference accuracy).
    #[arg(long, value_name = "N", default_value_t = ExportOptions::default().escapes)]
    pub escapes: u64,
    /// Colour space of exported colours: lin_rec709 or acescg.
    #[arg(
        long = "colour-space",
        value_name = "NAME",
        default_value = "lin_rec709"
    )]
    pub colour_space: String,
    /// Length of one scene unit in mm (OpenPBR, Standard Surface, pbrt, Mitsuba, Blender), [1e-6, 1e6].
    #[arg(long = "unit-mm", value_name = "MM", default_value_t = 1.0)]
    pub unit_mm: f64,
    /// Photons per run written into MCML / MCX inputs, [1, 2e9].
    #[arg(long, value_name = "N", default_value_t = ExportOptions::default().photons)]
    pub photons: u64,
    /// Monte Carlo histories per channel for the OpenPBR / Standard Surface medium, Cycles' walk medium and pbrt's shape check.
    #[arg(long = "volume-photons", value_name = "N", default_value_t = ExportOptions::default().volume_photons)]
    pub volume_photons: u64,
    /// Gaussians written by `gaussians`, [1, 8] (4, 5 and 6 are always reported).
    #[arg(long, value_name = "N", default_value_t = ExportOptions::default().gaussian_terms)]
    pub terms: usize,
    /// The one wavelength of `mcx` and of `mitsuba --variant mono`, nm, [250, 1000] ([360, 830] for Mitsuba).
    #[arg(long, value_name = "NM", default_value_t = ExportOptions::default().lambda_nm, allow_negative_numbers = true)]
    pub lambda: f64,
    /// Mitsuba 3 variant family: spectral (360–830 nm spectra), rgb (σt scaled into [0, 1]) or mono (--lambda).
    #[arg(long, value_name = "NAME", default_value = "spectral")]
    pub variant: String,
    /// Write a complete scene (camera and uniform sky) that renders as is (mitsuba).
    #[arg(long)]
    pub scene: bool,
    /// Finite dermis thickness for MCML, MCX, Mitsuba and Blender's volume, mm, [1, 1000].
    #[arg(long = "dermis-mm", value_name = "MM", default_value_t = ExportOptions::default().dermis_thickness_mm)]
    pub dermis_mm: f64,
    /// Chromophore maps (maps.exr of `skin maps`: channels melanin, eumelanin, hemoglobin): write
    /// openpbr, standard-surface, unreal or hdrp with texture images, fitted per texel, beside
    /// --out (required); the other parameters come from the skin options.
    #[arg(long, value_name = "FILE", requires = "out")]
    pub maps: Option<PathBuf>,
    /// Grid nodes along C_m and C_h for the per-texel fit of --maps, [2, 33] (the interpolation
    /// error is measured and printed with the export).
    #[arg(long = "texture-nodes", value_name = "N", default_value_t = TexturedOptions::default().nodes)]
    pub texture_nodes: usize,
}

impl ExportArgs {
    /// The validated options (every range error names its flag).
    pub fn options(&self) -> anyhow::Result<ExportOptions> {
        Wavelength::new(self.from).context("--from")?;
        Wavelength::new(self.to).context("--to")?;
        if self.to < self.from {
            anyhow::bail!("--to {} nm is below --from {} nm", self.to, self.from);
        }
        let opts = ExportOptions {
            grid: WavelengthGrid::new(self.from, self.to, self.step)
                .context("--from/--to/--step")?,
            escapes: self.escapes,
            colour_space: self
                .colour_space
                .parse::<ColourSpace>()
                .map_err(anyhow::Error::msg)
                .context("--colour-space")?,
            scene_unit_mm: self.unit_mm,
            photons: self.photons,
            volume_photons: self.volume_photons,
            gaussian_terms: self.terms,
            lambda_nm: self.lambda,
            mitsuba_variant: self
                .variant
                .parse::<skin_export::mitsuba::Variant>()
                .map_err(anyhow::Error::msg)
                .context("--variant")?,
            scene: self.scene,
            dermis_thickness_mm: self.dermis_mm,
            ..ExportOptions::default()
        };
        opts.validate()?;
        Ok(opts)
    }
}

/// Run `skin export`.
pub fn run(args: &ExportArgs) -> anyhow::Result<()> {
    let format: Format = args.format.parse()?;
    let skin = args.skin.to_params()?;
    let opts = args.options()?;
    if let Some(path) = &args.out {
        // Fail before the long computation if the folder cannot take the file.
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
            && dir.exists()
            && !dir.is_dir()
        {
            anyhow::bail!(
                "--out {}: {} is not a folder",
                path.display(),
                dir.display()
            );
        }
    }
    if let (Some(maps), Some(out)) = (&args.maps, &args.out) {
        return run_textured(format, &skin, &opts, args, maps, out);
    }
    let exported = export(&skin, format, &opts)?;
    for note in &exported.notes {
        eprintln!("{note}");
    }
    match &args.out {
        Some(path) => {
            write_bytes(path, exported.text.as_bytes())
                .with_context(|| format!("--out {}", path.display()))?;
            eprintln!("wrote {}", path.display());
        }
        None => {
            let mut out = std::io::stdout().lock();
            out.write_all(exported.text.as_bytes())?;
            out.flush()?;
        }
    }
    Ok(())
}

/// `skin export FORMAT --maps FILE --out FILE`: the material and its texture images beside it,
/// written as one group (all or none).
fn run_textured(
    format: Format,
    skin: &skin_optics::SkinParams,
    opts: &ExportOptions,
    args: &ExportArgs,
    maps: &std::path::Path,
    out: &std::path::Path,
) -> anyhow::Result<()> {
    let bytes = skin_io::input::CHROMOPHORE_MAP
        .read(maps)
        .with_context(|| format!("--maps {}", maps.display()))?;
    let channels = render::material::maps::read_maps_exr(&bytes, maps).context("--maps")?;
    let [melanin, eumelanin, hemoglobin] = channels.parameters;
    let missing = |name: &str| anyhow::anyhow!("--maps {}: no channel '{name}'", maps.display());
    let melanin = melanin.ok_or_else(|| missing("melanin"))?;
    let eumelanin = eumelanin.ok_or_else(|| missing("eumelanin"))?;
    let hemoglobin = hemoglobin.ok_or_else(|| missing("hemoglobin"))?;
    let (width, height) = (melanin.width, melanin.height);
    let thin = match (channels.thin_epidermis, channels.thin_epidermis_mm) {
        (None, _) => None,
        (Some(_), None) => anyhow::bail!(
            "--maps {}: channel '{}' without its header attribute '{}' (the thin epidermis' \
             thickness, mm)",
            maps.display(),
            render::material::maps::THIN_EPIDERMIS_CHANNEL,
            render::material::maps::THIN_EPIDERMIS_ATTRIBUTE
        ),
        (Some(flags), Some(epidermis_mm)) => {
            if let Some(k) = flags.values.iter().position(|v| !(0.0..=1.0).contains(v)) {
                anyhow::bail!(
                    "--maps {}: {} at texel ({}, {}) is {}, outside [0, 1]",
                    maps.display(),
                    render::material::maps::THIN_EPIDERMIS_CHANNEL,
                    k % flags.width,
                    k / flags.width,
                    flags.values[k]
                );
            }
            Some(ThinTexels {
                epidermis_mm,
                texels: flags.values.iter().map(|&v| v >= 0.5).collect(),
            })
        }
    };
    let texture = ChromophoreTexture {
        width,
        height,
        melanin: melanin.values,
        eumelanin: eumelanin.values,
        hemoglobin: hemoglobin.values,
        thin,
    };
    let topts = TexturedOptions {
        nodes: args.texture_nodes,
        ..TexturedOptions::default()
    };
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message("skins fitted on the texture's grid");
    let exported = export_textured(format, skin, &texture, opts, &topts, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })
    .with_context(|| format!("--maps {}", maps.display()))?;
    bar.finish_and_clear();
    for note in &exported.notes {
        eprintln!("{note}");
    }
    let dir = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let mut staged = vec![skin_io::atomic::stage_bytes(out, exported.text.as_bytes())?];
    for image in &exported.images {
        let channel = |c: usize| image.rgb.iter().map(|t| t[c]).collect::<Vec<f32>>();
        let bytes = render::texture::channels_exr_bytes(
            width,
            height,
            vec![("R", channel(0)), ("G", channel(1)), ("B", channel(2))],
        )
        .map_err(anyhow::Error::msg)?;
        staged.push(skin_io::atomic::stage_bytes(
            &dir.join(image.file_name),
            &bytes,
        )?);
    }
    skin_io::atomic::commit(staged)?;
    let names: Vec<&str> = exported.images.iter().map(|i| i.file_name).collect();
    eprintln!(
        "wrote {} and {} in {}",
        out.display(),
        names.join(", "),
        dir.display()
    );
    Ok(())
}
