#![doc = include_str!("../README.md")]

pub mod blender;
pub mod burley;
pub mod colour;
pub mod engines;
pub mod error;
pub mod gaussians;
pub mod materialx;
pub mod mcml;
pub mod mcx;
pub mod mitsuba;
pub mod pbrt;
pub mod rgb;
pub mod spectral;
pub mod textured;
pub mod volume;

pub use colour::ColourSpace;
pub use error::ExportError;

use error::check;
use multipole::skin::{DEFAULT_SHAPE_ESCAPES, ExactShape};
use multipole::{Method, ProfileOptions, SpectralProfiles};
use rgb::RgbProfile;
use skin_optics::{SkinParams, WavelengthGrid};
use spectral::SpectralSkin;
use std::fmt;
use std::str::FromStr;

/// An export format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// MaterialX `.mtlx` of OpenPBR Surface.
    OpenPbr,
    /// MaterialX `.mtlx` of Autodesk Standard Surface.
    StandardSurface,
    /// Unreal Engine Subsurface Profile fields, JSON.
    Unreal,
    /// Unity HDRP diffusion profile fields, JSON.
    Hdrp,
    /// Sum-of-Gaussians profile per RGB, JSON.
    Gaussians,
    /// Christensen–Burley normalized diffusion per RGB, JSON.
    Burley,
    /// pbrt-v4 `subsurface` material.
    Pbrt,
    /// Mitsuba 3 scene XML with two volumetric layers.
    Mitsuba,
    /// MCML 1.2 `.mci` input, one run per wavelength.
    Mcml,
    /// MCX / pmcx JSON input at one wavelength.
    Mcx,
    /// Blender Cycles: a Python script that builds the calibrated Principled BSDF and the
    /// volumetric slab.
    Blender,
    /// Blender Cycles: the same values as JSON.
    BlenderJson,
}

impl Format {
    /// Every format, in the order of the documentation.
    pub const ALL: [Format; 12] = [
        Format::OpenPbr,
        Format::StandardSurface,
        Format::Unreal,
        Format::Hdrp,
        Format::Gaussians,
        Format::Burley,
        Format::Pbrt,
        Format::Mitsuba,
        Format::Mcml,
        Format::Mcx,
        Format::Blender,
        Format::BlenderJson,
    ];

    /// The command-line name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Format::OpenPbr => "openpbr",
            Format::StandardSurface => "standard-surface",
            Format::Unreal => "unreal",
            Format::Hdrp => "hdrp",
            Format::Gaussians => "gaussians",
            Format::Burley => "burley",
            Format::Pbrt => "pbrt",
            Format::Mitsuba => "mitsuba",
            Format::Mcml => "mcml",
            Format::Mcx => "mcx",
            Format::Blender => "blender",
            Format::BlenderJson => "blender-json",
        }
    }

    /// What running the file in its engine here measured (`skin-validate engines`, BENCHMARKS.md
    /// "Engines", where the commands, versions and machine are), or why it was not run.
    #[must_use]
    pub fn measured_in_engine(self) -> &'static str {
        match self {
            Format::OpenPbr | Format::StandardSurface => {
                "MaterialX 1.39.5: validate() clean, only nodedef inputs with their types; acescg radii through MaterialX's own colour transform equal the lin_rec709 file's (≤ 0.001%); no MaterialX renderer runs here, so the totals and shape are the model-side errors above"
            }
            Format::Mitsuba => {
                "Mitsuba 3.9.1, slab under a uniform sky at normal view: rgb and mono variants within 1.1σ of F(0) + our diffuse reflectance (≤ 1.1%, σ 0.7–5%), light, medium and dark skin"
            }
            Format::Mcx => {
                "pmcxcl 0.7.5 (MCX on CPU OpenCL), 550 nm, 100,000 photons, light, medium and dark skin: detected weights per photon within 0.5σ of our per-entering total (≤ 0.3%)"
            }
            Format::Mcml => {
                "MCML 1.2 (the exported runs): within 1.8 binomial σ of skin spectrum's diffuse_reflectance"
            }
            Format::Blender | Format::BlenderJson => {
                "Blender 5.0.1 Cycles (CPU, 256 spp), light, medium and dark skin: Principled BSDF subsurface part on a slab at normal view within 2.2% of our diffuse reflectance (both methods); over a 20 mm sphere under a white sky, against our volumetric walk on the same sphere, Random Walk (Skin) within 2.7% for light skin, +5.6 to −4.7% for medium and −9 to −15% for dark, as Cycles' homogeneous walk does not follow layered skin's angular response (the 3% target is not met for medium and dark); volume_slab() within 1.0% of F(0) + our diffuse reflectance (1,024 spp) for every skin and channel but light skin's red, −3.0% (Cycles' 1,024-bounce limit)"
            }
            Format::Unreal | Format::Hdrp => {
                "cannot run here (no Unreal or Unity on this machine): the errors above are model-side, Burley's profile against ours"
            }
            Format::Burley | Format::Gaussians | Format::Pbrt => {
                "no engine run here: the errors above are model-side, the format's profile model against ours"
            }
        }
    }

    /// Whether the format is fitted to RGB profiles (otherwise it is spectral).
    #[must_use]
    pub fn is_rgb(self) -> bool {
        !matches!(
            self,
            Format::Pbrt | Format::Mitsuba | Format::Mcml | Format::Mcx
        )
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Format {
    type Err = ExportError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let key = s.trim().to_ascii_lowercase();
        Format::ALL
            .into_iter()
            .find(|f| f.name() == key)
            .ok_or_else(|| ExportError::UnknownFormat(s.to_string()))
    }
}

/// The knobs of an export.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExportOptions {
    /// Wavelengths of the spectral profiles and of the spectral formats.
    pub grid: WavelengthGrid,
    /// Escaping photons of each exact profile's Monte Carlo shape (accuracy knob of the reference).
    pub escapes: u64,
    /// Wavelength step between traced shapes, nm (rows between are mixed).
    pub shape_step_nm: f64,
    /// Colour space of exported colours.
    pub colour_space: ColourSpace,
    /// Length of one scene unit, mm (OpenPBR, Standard Surface, pbrt, Mitsuba, Blender).
    pub scene_unit_mm: f64,
    /// Photons per run written into MCML / MCX inputs.
    pub photons: u64,
    /// Monte Carlo histories per channel of the OpenPBR / Standard Surface medium fit.
    pub volume_photons: u64,
    /// Gaussians written by the `gaussians` format (4, 5 and 6 are always measured).
    pub gaussian_terms: usize,
    /// The one wavelength of the MCX input and of Mitsuba's mono variant, nm.
    pub lambda_nm: f64,
    /// Which Mitsuba 3 variant family the scene is written for.
    pub mitsuba_variant: mitsuba::Variant,
    /// Write a complete scene (camera, sky) where the format has one (Mitsuba).
    pub scene: bool,
    /// Thickness given to the dermis where the program needs a finite layer (MCML, MCX, Mitsuba, Blender), mm.
    pub dermis_thickness_mm: f64,
}

impl Default for ExportOptions {
    fn default() -> Self {
        Self {
            grid: WavelengthGrid::visible(),
            escapes: DEFAULT_SHAPE_ESCAPES,
            shape_step_nm: 20.0,
            colour_space: ColourSpace::LinRec709,
            scene_unit_mm: 1.0,
            photons: 1_000_000,
            volume_photons: 20_000,
            gaussian_terms: 6,
            lambda_nm: 550.0,
            mitsuba_variant: mitsuba::Variant::Spectral,
            scene: false,
            dermis_thickness_mm: 20.0,
        }
    }
}

impl ExportOptions {
    /// Check every knob against its range.
    pub fn validate(&self) -> Result<(), ExportError> {
        check("escapes", self.escapes as f64, 100.0, 1e9, "[100, 1e9]")?;
        check(
            "shape step (nm)",
            self.shape_step_nm,
            0.01,
            750.0,
            "[0.01, 750] nm",
        )?;
        check(
            "scene unit (mm)",
            self.scene_unit_mm,
            1e-6,
            1e6,
            "[1e-6, 1e6] mm",
        )?;
        check(
            "photons",
            self.photons as f64,
            1.0,
            2e9,
            "[1, 2e9] (MCML reads a C long)",
        )?;
        check(
            "volume photons",
            self.volume_photons as f64,
            100.0,
            1e9,
            "[100, 1e9]",
        )?;
        check(
            "Gaussian terms",
            self.gaussian_terms as f64,
            gaussians::TERMS_RANGE.0 as f64,
            gaussians::TERMS_RANGE.1 as f64,
            "[1, 8]",
        )?;
        check(
            "wavelength (nm)",
            self.lambda_nm,
            250.0,
            1000.0,
            "[250, 1000] nm",
        )?;
        check(
            "dermis thickness (mm)",
            self.dermis_thickness_mm,
            1.0,
            1000.0,
            "[1, 1000] mm",
        )?;
        Ok(())
    }

    /// Refuse what `format` cannot carry: a colour space other than linear Rec.709 where the
    /// engine has no colour-space tag (or no colours), and wavelengths outside what it samples.
    pub fn check_format(&self, format: Format) -> Result<(), ExportError> {
        let carries_acescg = match format {
            Format::OpenPbr | Format::StandardSurface | Format::Gaussians | Format::Burley => true,
            Format::Unreal | Format::Hdrp | Format::Pbrt | Format::Mcml | Format::Mcx => false,
            Format::Mitsuba | Format::Blender | Format::BlenderJson => false,
        };
        if self.colour_space != ColourSpace::LinRec709 && !carries_acescg {
            return Err(ExportError::ColourSpace {
                format: format.name(),
                space: self.colour_space.materialx_name(),
                valid: if matches!(format, Format::Blender | Format::BlenderJson) {
                    "lin_rec709 (Blender's default scene-linear working space, where the values are fitted)"
                } else if format.is_rgb() {
                    "lin_rec709 (the engine's working space; the file has no colour-space tag)"
                } else {
                    "lin_rec709 (the format is spectral: it holds no colours)"
                },
            });
        }
        if format == Format::Mitsuba && self.mitsuba_variant == mitsuba::Variant::Mono {
            check(
                "Mitsuba mono wavelength (nm)",
                self.lambda_nm,
                mitsuba::SPECTRAL_RANGE_NM.0,
                mitsuba::SPECTRAL_RANGE_NM.1,
                "[360, 830] nm (Mitsuba's spectral range)",
            )?;
        }
        Ok(())
    }
}

/// The surface parameters every format carries: index, oiliness and the lobe's Beckmann roughness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// Refractive index η of the skin.
    pub eta: f64,
    /// Oiliness ρ_s, the scale of the surface lobe.
    pub oiliness: f64,
    /// Beckmann RMS slope m of the lobe ([DJ06]: 0.3).
    pub beckmann_m: f64,
}

impl Surface {
    /// The surface of `skin`.
    #[must_use]
    pub fn of(skin: &SkinParams) -> Self {
        Self {
            eta: skin.eta(),
            oiliness: skin.oiliness(),
            // The f32 constant widened, rounded back to the decimal it was written as.
            beckmann_m: (f64::from(brdf::DEFAULT_ROUGHNESS) * 1e6).round() / 1e6,
        }
    }

    /// GGX α ≈ Beckmann m (the slopes' RMS agree, [WMLT07]); engines take roughness r with α = r².
    #[must_use]
    pub fn ggx_roughness(&self) -> f64 {
        self.beckmann_m.sqrt()
    }

    /// Normal-incidence Fresnel reflectance ((η − 1)/(η + 1))².
    #[must_use]
    pub fn f0(&self) -> f64 {
        ((self.eta - 1.0) / (self.eta + 1.0)).powi(2)
    }
}

/// An exported file and the notes (units, conventions, measured errors) printed with it.
#[derive(Debug, Clone, PartialEq)]
pub struct Export {
    /// The format.
    pub format: Format,
    /// The file's text (notes included as comments where the format has them).
    pub text: String,
    /// One line each: what the file holds, its units and conventions, its measured error.
    pub notes: Vec<String>,
}

/// The skin's exact spectral profiles reduced to RGB with the knobs of `opts`.
pub fn rgb_profile(skin: &SkinParams, opts: &ExportOptions) -> Result<RgbProfile, ExportError> {
    let profile_opts = ProfileOptions {
        exact_shape: ExactShape::MonteCarlo {
            escapes: opts.escapes,
        },
        shape_step_nm: opts.shape_step_nm,
        ..ProfileOptions::default()
    };
    let set = SpectralProfiles::new(skin, &opts.grid, Method::Exact, &profile_opts)?;
    RgbProfile::from_spectral(&set, opts.colour_space)
}

/// Export `skin` in `format`.
pub fn export(
    skin: &SkinParams,
    format: Format,
    opts: &ExportOptions,
) -> Result<Export, ExportError> {
    opts.validate()?;
    let surface = Surface::of(skin);
    let mut header = vec![header_note(skin, format, opts)];
    opts.check_format(format)?;
    let mut out = if format.is_rgb() {
        // MaterialX documents are fitted in linear Rec.709 and carry their colour space themselves.
        let rgb_opts = match format {
            Format::OpenPbr | Format::StandardSurface => ExportOptions {
                colour_space: ColourSpace::LinRec709,
                ..*opts
            },
            _ => *opts,
        };
        let rgb = rgb_profile(skin, &rgb_opts)?;
        if matches!(format, Format::Blender | Format::BlenderJson) {
            let (text, notes) = blender::write(format, skin, &rgb, surface, opts)?;
            Export {
                format,
                text,
                notes,
            }
        } else {
            export_rgb(format, &rgb, surface, opts)?
        }
    } else if format == Format::Mcx
        || (format == Format::Mitsuba && opts.mitsuba_variant == mitsuba::Variant::Mono)
    {
        let grid = WavelengthGrid::new(opts.lambda_nm, opts.lambda_nm, 1.0)?;
        export_spectral(
            format,
            &SpectralSkin::new(skin, &grid)?,
            skin,
            surface,
            opts,
        )?
    } else if format == Format::Mitsuba {
        let grid = mitsuba::spectral_grid(opts.grid.step_nm())?;
        export_spectral(
            format,
            &SpectralSkin::new(skin, &grid)?,
            skin,
            surface,
            opts,
        )?
    } else {
        export_spectral(
            format,
            &SpectralSkin::new(skin, &opts.grid)?,
            skin,
            surface,
            opts,
        )?
    };
    header.append(&mut out.notes);
    if !format.is_rgb() {
        header.push(
            "colour space: none (spectral: per-wavelength coefficients, no colours)".to_string(),
        );
    }
    header.push(format!(
        "measured in the engine: {}",
        format.measured_in_engine()
    ));
    out.notes = header;
    out.text = materialise_notes(format, &out.notes, &out.text);
    Ok(out)
}

/// Write an RGB-reduced format from the RGB profiles (its `text` carries no notes yet).
pub fn export_rgb(
    format: Format,
    rgb: &RgbProfile,
    surface: Surface,
    opts: &ExportOptions,
) -> Result<Export, ExportError> {
    let (text, notes) = match format {
        Format::OpenPbr | Format::StandardSurface => {
            if rgb.space() != ColourSpace::LinRec709 {
                return Err(ExportError::Fit(format!(
                    "{format}: the medium is fitted to linear Rec.709 profiles (got {})",
                    rgb.space()
                )));
            }
            let fit = volume::VolumeFit::fit(
                rgb,
                multipole::DEFAULT_G,
                surface.eta,
                opts.volume_photons,
            )?;
            materialx::write(format, &fit, surface, opts)
        }
        Format::Unreal | Format::Hdrp | Format::Burley => {
            let fit = burley::BurleyFit::fit(rgb)?;
            engines::write(format, &fit, surface, opts)
        }
        Format::Gaussians => {
            let fits = [4, 5, 6]
                .into_iter()
                .chain(std::iter::once(opts.gaussian_terms))
                .map(|n| gaussians::GaussianFit::fit(rgb, n))
                .collect::<Result<Vec<_>, _>>()?;
            engines::write_gaussians(&fits, opts)
        }
        _ => {
            return Err(ExportError::Fit(format!(
                "{format}: not an RGB profile format (use `export`)"
            )));
        }
    };
    Ok(Export {
        format,
        text,
        notes,
    })
}

/// Write a spectral format from the per-wavelength layers (its `text` carries no notes yet).
pub fn export_spectral(
    format: Format,
    spectral: &SpectralSkin,
    skin: &SkinParams,
    surface: Surface,
    opts: &ExportOptions,
) -> Result<Export, ExportError> {
    let (text, notes) = match format {
        Format::Pbrt => pbrt::write(spectral, skin, surface, opts)?,
        Format::Mitsuba => mitsuba::write(spectral, skin, surface, opts)?,
        Format::Mcml => mcml::write(spectral, opts)?,
        Format::Mcx => mcx::write(spectral, opts)?,
        _ => unreachable!("RGB formats go through export_rgb"),
    };
    Ok(Export {
        format,
        text,
        notes,
    })
}

/// The first note of every export: the skin, and the reference its fit was made against.
pub(crate) fn header_note(skin: &SkinParams, format: Format, opts: &ExportOptions) -> String {
    format!(
        "skin export {format}: C_m = {}, β_m = {}, C_h = {}, ρ_s = {}, η = {}, epidermis {} mm; reference: exact profiles over {}–{} nm step {} nm (adding-doubling totals, Monte Carlo shapes of {} escapes every {} nm), docs/physics.md §14",
        skin.melanin(),
        skin.eumelanin_blend(),
        skin.hemoglobin(),
        skin.oiliness(),
        skin.eta(),
        skin.epidermis_thickness_mm(),
        opts.grid.start_nm(),
        opts.grid.nm(opts.grid.len() - 1),
        opts.grid.step_nm(),
        opts.escapes,
        opts.shape_step_nm,
    )
}

/// Put the notes into the file as comments (XML, pbrt, MCML) or a `notes` array (JSON).
pub(crate) fn materialise_notes(format: Format, notes: &[String], text: &str) -> String {
    match format {
        Format::OpenPbr | Format::StandardSurface | Format::Mitsuba => {
            let (decl, rest) = text.split_once('\n').unwrap_or((text, ""));
            let comments: String = notes
                .iter()
                .map(|n| format!("<!-- {} -->\n", n.replace("--", "‒")))
                .collect();
            format!("{decl}\n{comments}{rest}")
        }
        Format::Pbrt | Format::Blender => {
            let comments: String = notes.iter().map(|n| format!("# {n}\n")).collect();
            format!("{comments}{text}")
        }
        Format::Mcml => {
            // MCML reads lines of at most 254 bytes: the notes are wrapped.
            let comments: String = notes
                .iter()
                .flat_map(|n| mcml::wrap(&mcml::ascii(n), mcml::COMMENT_WIDTH))
                .map(|l| format!("# {l}\n"))
                .collect();
            format!("{comments}{}", mcml::ascii(text))
        }
        Format::Unreal
        | Format::Hdrp
        | Format::Gaussians
        | Format::Burley
        | Format::Mcx
        | Format::BlenderJson => {
            let mut value: serde_json::Value =
                serde_json::from_str(text).expect("the JSON writers produce valid JSON");
            value["notes"] = serde_json::json!(notes);
            serde_json::to_string_pretty(&value).expect("a JSON value serialises") + "\n"
        }
    }
}

/// `[r, g, b]` as percentages `r/g/b %` with `digits` decimals.
#[must_use]
pub fn percent3(v: [f64; 3], digits: usize) -> String {
    format!(
        "{:.*}/{:.*}/{:.*} %",
        digits,
        100.0 * v[0],
        digits,
        100.0 * v[1],
        digits,
        100.0 * v[2]
    )
}
