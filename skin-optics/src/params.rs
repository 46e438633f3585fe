//! The four physical parameters of skin ([DJ06]) and the constants the seed fixes, validated.

use crate::error::{OpticsError, check_range};
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

/// Error for an unknown preset name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown skin preset '{0}' (valid: light, medium, dark)")]
pub struct UnknownPreset(pub String);

impl FromStr for Preset {
    type Err = UnknownPreset;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "light" => Ok(Preset::Light),
            "medium" => Ok(Preset::Medium),
            "dark" => Ok(Preset::Dark),
            _ => Err(UnknownPreset(s.to_string())),
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
        let d = check_range("epidermis thickness (mm)", d_mm, 0.0, 10.0, "(0, 10] mm")?;
        if d <= 0.0 {
            return Err(OpticsError::OutOfRange {
                name: "epidermis thickness (mm)",
                value: d_mm,
                range: "(0, 10] mm",
            });
        }
        self.epidermis_thickness_mm = d;
        Ok(self)
    }

    /// Same skin with index of refraction η in [1, 3].
    pub fn with_eta(mut self, eta: f64) -> Result<Self, OpticsError> {
        self.eta = check_range("index of refraction η", eta, 1.0, 3.0, "[1, 3]")?;
        Ok(self)
    }

    /// Same skin with the dermis reduced scattering scaled by `scale` in (0, 4] (1 = the seed).
    pub fn with_dermis_scattering_scale(mut self, scale: f64) -> Result<Self, OpticsError> {
        let s = check_range("dermis scattering scale", scale, 0.0, 4.0, "(0, 4]")?;
        if s <= 0.0 {
            return Err(OpticsError::OutOfRange {
                name: "dermis scattering scale",
                value: scale,
                range: "(0, 4]",
            });
        }
        self.dermis_scattering_scale = s;
        Ok(self)
    }

    /// Same skin with oiliness ρ_s in [0, 1].
    pub fn with_oiliness(mut self, rho_s: f64) -> Result<Self, OpticsError> {
        self.oiliness = check_range("oiliness ρ_s", rho_s, 0.0, 1.0, "[0, 1]")?;
        Ok(self)
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
