//! The four physical parameters of skin ([DJ06]) and the constants the seed fixes, validated.
//!
//! Each `with_*` setter's doc and error name the parameter's range.

use crate::error::{OpticsError, check_positive, check_range};
use crate::physiology::Physiology;
use std::fmt;
use std::str::FromStr;

/// Named skin presets. `Light` is the seed's Figure 1 set; `Medium` and `Dark` are this project's
/// (docs/physics.md §1), to be refined by fitting measured skin colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Preset {
    /// C_m = 0.002, β_m = 0.5, C_h = 0.01, ρ_s = 0.25 ([DJ06] Figure 1).
    Light,
    /// C_m = 0.05, β_m = 0.6, C_h = 0.02, ρ_s = 0.25.
    Medium,
    /// C_m = 0.30, β_m = 0.9, C_h = 0.04, ρ_s = 0.25.
    Dark,
}

impl Preset {
    /// All presets, light to dark.
    pub const ALL: [Preset; 3] = [Preset::Light, Preset::Medium, Preset::Dark];

    /// Lower-case name used on the command line and in scene files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Preset::Light => "light",
            Preset::Medium => "medium",
            Preset::Dark => "dark",
        }
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Error for an unknown preset name (the name as given, cut by [`crate::echo::text`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown skin preset '{0}' (valid: light or paper, medium, dark)")]
pub struct UnknownPreset(pub String);

impl FromStr for Preset {
    type Err = UnknownPreset;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "light" | "paper" => Ok(Preset::Light),
            "medium" => Ok(Preset::Medium),
            "dark" => Ok(Preset::Dark),
            _ => Err(UnknownPreset(crate::echo::text(s))),
        }
    }
}

/// Validated skin parameters: valid by construction, so hot paths never re-check.
///
/// The four model parameters of [DJ06] plus the constants the seed fixes (blood oxygenation γ,
/// epidermis thickness, index of refraction) and a documented dermis scattering scale
/// (1 = the seed's single scattering law in both layers; some public ports use 0.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkinParams {
    melanin: f64,
    eumelanin_blend: f64,
    hemoglobin: f64,
    oiliness: f64,
    oxygenation: f64,
    epidermis_thickness_mm: f64,
    eta: f64,
    dermis_scattering_scale: f64,
    physiology: Physiology,
}

impl SkinParams {
    /// Default blood oxygenation ratio γ ([DJ06] seed: ≈ 0.7).
    pub const DEFAULT_OXYGENATION: f64 = 0.7;
    /// Default epidermis thickness, mm ([DJ06]: fixed at 0.25 mm).
    pub const DEFAULT_EPIDERMIS_THICKNESS_MM: f64 = 0.25;
    /// Default index of refraction of skin ([DJ06], [DJ05]: 1.4).
    pub const DEFAULT_ETA: f64 = 1.4;

    /// Skin from melanin fraction C_m, eumelanin blend β_m, hemoglobin fraction C_h and oiliness ρ_s,
    /// each in [0, 1] (the physical ranges are C_m 0–0.5, C_h 0.001–0.1); other constants at their defaults.
    pub fn new(
        melanin: f64,
        eumelanin_blend: f64,
        hemoglobin: f64,
        oiliness: f64,
    ) -> Result<Self, OpticsError> {
        Ok(Self {
            melanin: check_range("melanin fraction C_m", melanin, 0.0, 1.0, "[0, 1]")?,
            eumelanin_blend: check_range(
                "eumelanin blend β_m",
                eumelanin_blend,
                0.0,
                1.0,
                "[0, 1]",
            )?,
            hemoglobin: check_range("hemoglobin fraction C_h", hemoglobin, 0.0, 1.0, "[0, 1]")?,
            oiliness: check_range("oiliness ρ_s", oiliness, 0.0, 1.0, "[0, 1]")?,
            oxygenation: Self::DEFAULT_OXYGENATION,
            epidermis_thickness_mm: Self::DEFAULT_EPIDERMIS_THICKNESS_MM,
            eta: Self::DEFAULT_ETA,
            dermis_scattering_scale: 1.0,
            physiology: Physiology::SEED,
        })
    }

    /// A named preset (docs/physics.md §1).
    #[must_use]
    pub fn preset(preset: Preset) -> Self {
        let (cm, bm, ch) = match preset {
            Preset::Light => (0.002, 0.5, 0.01),
            Preset::Medium => (0.05, 0.6, 0.02),
            Preset::Dark => (0.30, 0.9, 0.04),
        };
        // The preset values are constants inside the valid ranges.
        Self::new(cm, bm, ch, 0.25).expect("preset values are valid")
    }

    /// Same skin with blood oxygenation γ in [0, 1].
    pub fn with_oxygenation(mut self, gamma: f64) -> Result<Self, OpticsError> {
        self.oxygenation = check_range("blood oxygenation γ", gamma, 0.0, 1.0, "[0, 1]")?;
        Ok(self)
    }

    /// Same skin with epidermis thickness in mm, in (0, 10] mm.
    pub fn with_epidermis_thickness_mm(mut self, d_mm: f64) -> Result<Self, OpticsError> {
        self.epidermis_thickness_mm =
            check_positive("epidermis thickness (mm)", d_mm, 10.0, "(0, 10] mm")?;
        Ok(self)
    }

    /// Same skin with index of refraction η in [1, 3].
    pub fn with_eta(mut self, eta: f64) -> Result<Self, OpticsError> {
        self.eta = check_range("index of refraction η", eta, 1.0, 3.0, "[1, 3]")?;
        Ok(self)
    }

    /// Same skin with the dermis reduced scattering scaled by `scale` in (0, 4] (1 = the seed).
    pub fn with_dermis_scattering_scale(mut self, scale: f64) -> Result<Self, OpticsError> {
        self.dermis_scattering_scale =
            check_positive("dermis scattering scale", scale, 4.0, "(0, 4]")?;
        Ok(self)
    }

    /// Same skin with oiliness ρ_s in [0, 1].
    pub fn with_oiliness(mut self, rho_s: f64) -> Result<Self, OpticsError> {
        self.oiliness = check_range("oiliness ρ_s", rho_s, 0.0, 1.0, "[0, 1]")?;
        Ok(self)
    }

    /// Same skin with melanin fraction C_m in [0, 1].
    pub fn with_melanin(mut self, c_m: f64) -> Result<Self, OpticsError> {
        self.melanin = check_range("melanin fraction C_m", c_m, 0.0, 1.0, "[0, 1]")?;
        Ok(self)
    }

    /// Same skin with eumelanin blend β_m in [0, 1].
    pub fn with_eumelanin_blend(mut self, beta_m: f64) -> Result<Self, OpticsError> {
        self.eumelanin_blend = check_range("eumelanin blend β_m", beta_m, 0.0, 1.0, "[0, 1]")?;
        Ok(self)
    }

    /// Same skin with hemoglobin fraction C_h in [0, 1].
    pub fn with_hemoglobin(mut self, c_h: f64) -> Result<Self, OpticsError> {
        self.hemoglobin = check_range("hemoglobin fraction C_h", c_h, 0.0, 1.0, "[0, 1]")?;
        Ok(self)
    }

    /// Same skin with the extended physiology of docs/physics.md §13 (validated by its builders).
    #[must_use]
    pub fn with_physiology(mut self, physiology: Physiology) -> Self {
        self.physiology = physiology;
        self
    }

    /// The extended physiology ([`Physiology::SEED`] unless set: the seed's model).
    #[must_use]
    pub fn physiology(&self) -> Physiology {
        self.physiology
    }

    /// Melanin volume fraction C_m of the epidermis, in [0, 1].
    #[must_use]
    pub fn melanin(&self) -> f64 {
        self.melanin
    }
    /// Eumelanin share β_m of the melanin (1 − β_m is pheomelanin), in [0, 1].
    #[must_use]
    pub fn eumelanin_blend(&self) -> f64 {
        self.eumelanin_blend
    }
    /// Hemoglobin (whole blood) volume fraction C_h of the dermis, in [0, 1].
    #[must_use]
    pub fn hemoglobin(&self) -> f64 {
        self.hemoglobin
    }
    /// Oiliness ρ_s: linear scale of the Torrance–Sparrow surface lobe, in [0, 1].
    #[must_use]
    pub fn oiliness(&self) -> f64 {
        self.oiliness
    }
    /// Blood oxygenation ratio γ, in [0, 1].
    #[must_use]
    pub fn oxygenation(&self) -> f64 {
        self.oxygenation
    }
    /// Epidermis thickness, mm.
    #[must_use]
    pub fn epidermis_thickness_mm(&self) -> f64 {
        self.epidermis_thickness_mm
    }
    /// Index of refraction of skin (both layers), dimensionless.
    #[must_use]
    pub fn eta(&self) -> f64 {
        self.eta
    }
    /// Scale applied to the dermis reduced scattering (1 = the seed's law).
    #[must_use]
    pub fn dermis_scattering_scale(&self) -> f64 {
        self.dermis_scattering_scale
    }
}

impl Default for SkinParams {
    /// The seed's Figure 1 skin (the `light` preset).
    fn default() -> Self {
        Self::preset(Preset::Light)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The error's variant, parameter name and value.
    fn parts(e: OpticsError) -> (&'static str, &'static str, f64) {
        match e {
            OpticsError::NonFinite { name, value, .. } => ("NonFinite", name, value),
            OpticsError::OutOfRange { name, value, .. } => ("OutOfRange", name, value),
            other => panic!("unexpected {other:?}"),
        }
    }

    fn check_field(
        name: &'static str,
        build: impl Fn(f64) -> Result<SkinParams, OpticsError>,
        out_of_range: &[f64],
    ) {
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (kind, n, _) = parts(build(v).unwrap_err());
            assert_eq!((kind, n), ("NonFinite", name), "{name} = {v}");
        }
        for &v in out_of_range {
            let (kind, n, value) = parts(build(v).unwrap_err());
            assert_eq!((kind, n, value), ("OutOfRange", name, v), "{name} = {v}");
        }
    }

    #[test]
    fn every_invalid_field_is_rejected_with_its_name() {
        let bad_fraction = [-1e-12, -0.5, 1.000_001, 1.5];
        check_field(
            "melanin fraction C_m",
            |v| SkinParams::new(v, 0.5, 0.01, 0.25),
            &bad_fraction,
        );
        check_field(
            "eumelanin blend β_m",
            |v| SkinParams::new(0.1, v, 0.01, 0.25),
            &bad_fraction,
        );
        check_field(
            "hemoglobin fraction C_h",
            |v| SkinParams::new(0.1, 0.5, v, 0.25),
            &bad_fraction,
        );
        check_field(
            "oiliness ρ_s",
            |v| SkinParams::new(0.1, 0.5, 0.01, v),
            &bad_fraction,
        );
        let skin = SkinParams::default();
        check_field("oiliness ρ_s", |v| skin.with_oiliness(v), &bad_fraction);
        check_field(
            "blood oxygenation γ",
            |v| skin.with_oxygenation(v),
            &bad_fraction,
        );
        check_field(
            "epidermis thickness (mm)",
            |v| skin.with_epidermis_thickness_mm(v),
            &[0.0, -0.0, -0.25, 10.5],
        );
        check_field(
            "index of refraction η",
            |v| skin.with_eta(v),
            &[0.999, 0.0, 3.01],
        );
        check_field(
            "dermis scattering scale",
            |v| skin.with_dermis_scattering_scale(v),
            &[0.0, -1.0, 4.5],
        );
    }

    #[test]
    fn error_message_names_field_value_and_range() {
        let e = SkinParams::new(1.5, 0.5, 0.01, 0.25).unwrap_err();
        assert_eq!(e.to_string(), "melanin fraction C_m = 1.5 outside [0, 1]");
        let e = SkinParams::new(f64::NAN, 0.5, 0.01, 0.25).unwrap_err();
        assert_eq!(
            e.to_string(),
            "melanin fraction C_m = NaN is not a finite number (valid range [0, 1])"
        );
    }

    #[test]
    fn boundary_values_are_accepted() {
        let s = SkinParams::new(0.0, 1.0, 0.0, 1.0).unwrap();
        assert_eq!(
            (
                s.melanin(),
                s.eumelanin_blend(),
                s.hemoglobin(),
                s.oiliness()
            ),
            (0.0, 1.0, 0.0, 1.0)
        );
        let s = s
            .with_eta(1.0)
            .unwrap()
            .with_eta(3.0)
            .unwrap()
            .with_epidermis_thickness_mm(10.0)
            .unwrap()
            .with_oxygenation(1.0)
            .unwrap()
            .with_dermis_scattering_scale(4.0)
            .unwrap();
        assert_eq!(
            (
                s.eta(),
                s.epidermis_thickness_mm(),
                s.oxygenation(),
                s.dermis_scattering_scale()
            ),
            (3.0, 10.0, 1.0, 4.0)
        );
    }

    #[test]
    fn defaults_are_the_seed_constants() {
        let s = SkinParams::new(0.1, 0.5, 0.01, 0.25).unwrap();
        assert_eq!(s.oxygenation(), 0.7);
        assert_eq!(s.epidermis_thickness_mm(), 0.25);
        assert_eq!(s.eta(), 1.4);
        assert_eq!(s.dermis_scattering_scale(), 1.0);
    }

    #[test]
    fn presets_match_documented_values() {
        let get = |p| {
            let s = SkinParams::preset(p);
            (
                s.melanin(),
                s.eumelanin_blend(),
                s.hemoglobin(),
                s.oiliness(),
            )
        };
        assert_eq!(get(Preset::Light), (0.002, 0.5, 0.01, 0.25));
        assert_eq!(get(Preset::Medium), (0.05, 0.6, 0.02, 0.25));
        assert_eq!(get(Preset::Dark), (0.30, 0.9, 0.04, 0.25));
        assert_eq!(SkinParams::default(), SkinParams::preset(Preset::Light));
    }

    #[test]
    fn preset_names_round_trip() {
        for p in Preset::ALL {
            assert_eq!(p.name().parse::<Preset>().unwrap(), p);
            assert_eq!(p.to_string(), p.name());
        }
        assert_eq!("DARK".parse::<Preset>().unwrap(), Preset::Dark);
        assert_eq!("paper".parse::<Preset>().unwrap(), Preset::Light);
        let e = "tan".parse::<Preset>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown skin preset 'tan' (valid: light or paper, medium, dark)"
        );
    }
}
