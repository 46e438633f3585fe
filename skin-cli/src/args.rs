//! Arguments shared by several subcommands (skin parameters, method), and the value parser every
//! flag goes through.

use clap::Args;
use clap::builder::TypedValueParser;
use skin_optics::echo::{Num, Text};
use skin_optics::measured::named_skin;
use skin_optics::{OpticsError, Preset, SkinParams};
use std::ffi::OsStr;

/// A clap value parser from a plain `fn(&str) -> Result<T, String>` whose error names the flag and
/// states its range (the function's message), echoing the value cut to a few dozen characters.
/// Flags using it also take `allow_hyphen_values`, so `-1` or `-inf` reach the range check instead
/// of being read as another flag.
#[derive(Clone, Copy)]
pub struct Checked<T>(pub fn(&str) -> Result<T, String>);

impl<T: Clone + Send + Sync + 'static> TypedValueParser for Checked<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<T, clap::Error> {
        let text = value.to_string_lossy();
        (self.0)(&text).map_err(|message| {
            let flag = arg.map_or_else(|| "value".to_string(), ToString::to_string);
            clap::Error::raw(
                clap::error::ErrorKind::ValueValidation,
                format!("invalid value '{}' for '{flag}': {message}\n", Text(&text)),
            )
            .with_cmd(cmd)
        })
    }
}

/// Parse a number, or say it is not one and give the valid `range`.
pub fn parse_number(s: &str, range: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .map_err(|_| format!("'{}' is not a number (valid range {range})", Text(s)))
}

/// Parse a number in [`lo`, `hi`]; `range` is how the help spells the interval.
pub fn parse_in(s: &str, lo: f64, hi: f64, range: &str) -> Result<f64, String> {
    let v = parse_number(s, range)?;
    if !(lo..=hi).contains(&v) {
        return Err(format!("{} outside {range}", Num(v)));
    }
    Ok(v)
}

/// Parse a whole number in [`lo`, `hi`]; `range` is how the help spells the interval.
pub fn parse_whole(s: &str, lo: u64, hi: u64, range: &str) -> Result<u64, String> {
    let v = parse_number(s, range)?;
    if !((lo as f64..=hi as f64).contains(&v) && v.fract() == 0.0) {
        return Err(format!("{} outside {range} (a whole number)", Num(v)));
    }
    Ok(v as u64)
}

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
    let skin = named_skin(s).map_err(|e| e.to_string())?;
    Ok(NamedSkin {
        name: s.to_string(),
        skin,
    })
}

/// Parse a volume fraction in [0, 1] (clap value parser: bad values exit with code 2).
pub fn parse_fraction(s: &str) -> Result<f64, String> {
    let v = parse_number(s, "[0, 1]")?;
    if !v.is_finite() || !(0.0..=1.0).contains(&v) {
        return Err(format!("{} outside [0, 1]", Num(v)));
    }
    Ok(v)
}

/// The skin being described: a preset and/or explicit fractions (explicit values win).
#[derive(Args, Debug, Clone, Default)]
pub struct SkinArgs {
    /// Named skin preset: paper (= light, the paper's Figure 1), medium, dark, or a measured one
    /// (`skin presets` lists them, e.g. ca-forehead, ita-tan). Explicit fractions override it.
    #[arg(long, value_name = "NAME", value_parser = Checked(parse_preset))]
    pub preset: Option<NamedSkin>,
    /// Melanin volume fraction C_m of the epidermis, [0, 1] (physical: 0-0.5).
    #[arg(long, value_name = "C_M", value_parser = Checked(parse_fraction), allow_hyphen_values = true)]
    pub melanin: Option<f64>,
    /// Eumelanin share β_m of the melanin, [0, 1] (the rest is pheomelanin).
    #[arg(long, value_name = "BETA_M", value_parser = Checked(parse_fraction), allow_hyphen_values = true)]
    pub eumelanin: Option<f64>,
    /// Hemoglobin (blood) volume fraction C_h of the dermis, [0, 1] (physical: 0.001-0.1).
    #[arg(long, value_name = "C_H", value_parser = Checked(parse_fraction), allow_hyphen_values = true)]
    pub hemoglobin: Option<f64>,
    /// Oiliness ρ_s, the scale of the surface reflection lobe, [0, 1].
    #[arg(long, value_name = "RHO_S", value_parser = Checked(parse_fraction), allow_hyphen_values = true)]
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct Cli {
        #[command(flatten)]
        skin: SkinArgs,
    }

    fn error_of(args: &[&str]) -> String {
        let mut all = vec!["skin"];
        all.extend_from_slice(args);
        Cli::try_parse_from(all).unwrap_err().to_string()
    }

    #[test]
    fn melanin_minus_inf_gets_the_flag_range() {
        let e = error_of(&["--melanin", "-inf"]);
        assert!(e.contains("--melanin") && e.contains("[0, 1]"), "{e}");
        let e = error_of(&["--oil", "-1"]);
        assert!(e.contains("--oil") && e.contains("outside [0, 1]"), "{e}");
    }

    #[test]
    fn melanin_1e308_is_echoed_in_scientific_notation() {
        let e = error_of(&["--melanin", "1e308"]);
        assert!(e.contains("1e308 outside [0, 1]") && e.len() < 200, "{e}");
    }

    #[test]
    fn a_ten_megabyte_preset_is_echoed_cut() {
        let long = "a".repeat(10 << 20);
        let e = error_of(&["--preset", &long]);
        assert!(e.len() < 400 && e.contains("--preset"), "{e}");
    }

    #[test]
    fn whole_numbers_state_their_range() {
        assert_eq!(parse_whole("12", 1, 16, "[1, 16]"), Ok(12));
        let e = parse_whole("-1", 1, 16, "[1, 16]").unwrap_err();
        assert_eq!(e, "-1 outside [1, 16] (a whole number)");
        assert!(parse_whole("2.5", 1, 16, "[1, 16]").is_err());
        assert!(
            parse_whole("-inf", 1, 16, "[1, 16]")
                .unwrap_err()
                .contains("[1, 16]")
        );
    }
}
