//! `skin export FORMAT`: the skin written for another renderer or simulator (`crate::export`), to
//! `--out` atomically or to stdout; its notes (units, conventions, measured errors) go to stderr.

use crate::args::SkinArgs;
use anyhow::Context;
use clap::Args;
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
