//! Arguments shared by several subcommands (skin parameters, method).

use clap::Args;
use skin_optics::measured::find_measured;
use skin_optics::{OpticsError, Preset, SkinParams};

/// A named skin: one of the seed's presets (`paper` = `light`, the paper's Figure 1; `medium`,
/// `dark`) or a measured one (`skin presets` lists them: `ca-forehead`, …, `ita-tan`, …).
#[derive(Debug, Clone, PartialEq)]
pub struct NamedSkin {
    /// The name as given.
    pub name: String,
    /// Its skin.
    pub skin: SkinParams,
}

/// Parse a preset name (clap value parser).
pub fn parse_preset(s: &str) -> Result<NamedSkin, String> {
    let skin = match s.parse::<Preset>() {
        Ok(p) => SkinParams::preset(p),
        Err(e) => match find_measured(s) {
            Some(m) => m.skin,
            None => return Err(format!("{e}, or a measured preset (see `skin presets`)")),
        },
    };
    Ok(NamedSkin {
        name: s.to_string(),
        skin,
    })
}

/// Parse a volume fraction in [0, 1] (clap value parser: bad values exit with code 2).
pub fn parse_fraction(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number (valid range [0, 1])"))?;
    if !v.is_finite() || !(0.0..=1.0).contains(&v) {
        return Err(format!("{v} outside [0, 1]"));
    }
    Ok(v)
}

/// The skin being described: a preset and/or explicit fractions (explicit values win).
#[derive(Args, Debug, Clone, Default)]
pub struct SkinArgs {
    /// Named skin preset: paper (= light, the paper's Figure 1), medium, dark, or a measured one
    /// (`skin presets` lists them, e.g. ca-forehead, ita-tan). Explicit fractions override it.
    #[arg(long, value_name = "NAME", value_parser = parse_preset)]
    pub preset: Option<NamedSkin>,
    /// Melanin volume fraction C_m of the epidermis, [0, 1] (physical: 0-0.5).
    #[arg(long, value_name = "C_M", value_parser = parse_fraction, allow_negative_numbers = true)]
    pub melanin: Option<f64>,
    /// Eumelanin share β_m of the melanin, [0, 1] (the rest is pheomelanin).
    #[arg(long, value_name = "BETA_M", value_parser = parse_fraction, allow_negative_numbers = true)]
    pub eumelanin: Option<f64>,
    /// Hemoglobin (blood) volume fraction C_h of the dermis, [0, 1] (physical: 0.001-0.1).
    #[arg(long, value_name = "C_H", value_parser = parse_fraction, allow_negative_numbers = true)]
    pub hemoglobin: Option<f64>,
    /// Oiliness ρ_s, the scale of the surface reflection lobe, [0, 1].
    #[arg(long, value_name = "RHO_S", value_parser = parse_fraction, allow_negative_numbers = true)]
    pub oil: Option<f64>,
}

impl SkinArgs {
    /// The validated skin: the preset (light if none) with any explicit fraction replacing its value.
    pub fn to_params(&self) -> Result<SkinParams, OpticsError> {
        let base = self
            .preset
            .as_ref()
            .map_or_else(|| SkinParams::preset(Preset::Light), |p| p.skin);
        base.with_melanin(self.melanin.unwrap_or(base.melanin()))?
            .with_eumelanin_blend(self.eumelanin.unwrap_or(base.eumelanin_blend()))?
            .with_hemoglobin(self.hemoglobin.unwrap_or(base.hemoglobin()))?
            .with_oiliness(self.oil.unwrap_or(base.oiliness()))
    }
}
