//! The parameters a spectrum fit may free, each with the physiological range it explores
//! (docs/physics.md §13), and the model choices `seed`, `full` and `auto`.

use super::{EUMELANIN_RANGE, FitError, HEMOGLOBIN_RANGE, MELANIN_RANGE};
use skin_optics::{Extension, OpticsError, SkinParams};
use std::fmt;
use std::str::FromStr;

/// One fitted parameter of the skin.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Parameter {
    /// Melanin fraction C_m of the epidermis ([DJ06] eq. 1).
    Melanin,
    /// Eumelanin blend β_m ([DJ06] eq. 1).
    EumelaninBlend,
    /// Hemoglobin fraction C_h of the dermis ([DJ06] eq. 5).
    Hemoglobin,
    /// Oiliness ρ_s, seen only by the SCI geometry.
    Oiliness,
    /// Blood oxygenation γ ([DJ06] eq. 5).
    Oxygenation,
    /// Epidermis thickness, mm.
    EpidermisThickness,
    /// Scale of the dermis reduced scattering.
    DermisScattering,
    /// One of the extensions of `skin_optics::physiology`.
    Extended(Extension),
}

impl Parameter {
    /// The seed's three fitted chromophores.
    pub const SEED: [Parameter; 3] = [
        Parameter::Melanin,
        Parameter::EumelaninBlend,
        Parameter::Hemoglobin,
    ];

    /// Candidates beyond the seed, in the order `auto` tries them and reports them.
    pub const CANDIDATES: [Parameter; 7] = [
        Parameter::Extended(Extension::EpidermisBlood),
        Parameter::EpidermisThickness,
        Parameter::Oxygenation,
        Parameter::Extended(Extension::MieScale),
        Parameter::Extended(Extension::RayleighScale),
        Parameter::DermisScattering,
        Parameter::Extended(Extension::Bilirubin),
    ];

    /// Name used in reports and JSON.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Parameter::Melanin => "melanin",
            Parameter::EumelaninBlend => "eumelanin_blend",
            Parameter::Hemoglobin => "hemoglobin",
            Parameter::Oiliness => "oiliness",
            Parameter::Oxygenation => "oxygenation",
            Parameter::EpidermisThickness => "epidermis_thickness_mm",
            Parameter::DermisScattering => "dermis_scattering_scale",
            Parameter::Extended(e) => e.name(),
        }
    }

    /// The range `[lo, hi]` a fit explores (docs/physics.md §13 gives each source): the seed's
    /// physical ranges for the chromophores; ρ_s [0, 1]; γ [0.4, 1] (venous to arterial blood);
    /// epidermis 0.04–0.3 mm (the viable epidermis is about 0.05–0.1 mm thick [SM03], [DJ06]'s
    /// 0.25 mm lumps the papillary dermis in; 0.04 mm is still a few cell layers); dermis
    /// scattering scale [0.5, 2] (as the extended scattering scales).
    #[must_use]
    pub fn range(self) -> [f64; 2] {
        match self {
            Parameter::Melanin => MELANIN_RANGE,
            Parameter::EumelaninBlend => EUMELANIN_RANGE,
            Parameter::Hemoglobin => HEMOGLOBIN_RANGE,
            Parameter::Oiliness => [0.0, 1.0],
            Parameter::Oxygenation => [0.4, 1.0],
            Parameter::EpidermisThickness => [0.04, 0.3],
            Parameter::DermisScattering => [0.5, 2.0],
            Parameter::Extended(e) => e.physiological_range(),
        }
    }

    /// The parameter's value in `skin`.
    #[must_use]
    pub fn get(self, skin: &SkinParams) -> f64 {
        match self {
            Parameter::Melanin => skin.melanin(),
            Parameter::EumelaninBlend => skin.eumelanin_blend(),
            Parameter::Hemoglobin => skin.hemoglobin(),
            Parameter::Oiliness => skin.oiliness(),
            Parameter::Oxygenation => skin.oxygenation(),
            Parameter::EpidermisThickness => skin.epidermis_thickness_mm(),
            Parameter::DermisScattering => skin.dermis_scattering_scale(),
            Parameter::Extended(e) => skin.physiology().get(e),
        }
    }

    /// `skin` with this parameter set to `value` (validated by `SkinParams`).
    pub fn set(self, skin: SkinParams, value: f64) -> Result<SkinParams, OpticsError> {
        match self {
            Parameter::Melanin => skin.with_melanin(value),
            Parameter::EumelaninBlend => skin.with_eumelanin_blend(value),
            Parameter::Hemoglobin => skin.with_hemoglobin(value),
            Parameter::Oiliness => skin.with_oiliness(value),
            Parameter::Oxygenation => skin.with_oxygenation(value),
            Parameter::EpidermisThickness => skin.with_epidermis_thickness_mm(value),
            Parameter::DermisScattering => skin.with_dermis_scattering_scale(value),
            Parameter::Extended(e) => Ok(skin.with_physiology(skin.physiology().with(e, value)?)),
        }
    }
}

impl fmt::Display for Parameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Which parameters a spectrum fit frees.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ModelChoice {
    /// The seed's C_m, β_m, C_h (plus ρ_s for SCI data): today's fit.
    #[default]
    Seed,
    /// The seed's parameters and every candidate.
    Full,
    /// The seed's, plus the candidates the information criterion accepts (module `select`).
    Auto,
}

impl fmt::Display for ModelChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ModelChoice::Seed => "seed",
            ModelChoice::Full => "full",
            ModelChoice::Auto => "auto",
        })
    }
}

impl FromStr for ModelChoice {
    type Err = FitError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "seed" => Ok(ModelChoice::Seed),
            "full" => Ok(ModelChoice::Full),
            "auto" => Ok(ModelChoice::Auto),
            _ => Err(FitError::Unknown {
                what: "model",
                found: s.to_string(),
                valid: "seed, full, auto",
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_parameter_round_trips_through_the_skin_and_its_range_holds_the_default() {
        let base = SkinParams::default();
        let all = Parameter::SEED
            .iter()
            .chain(&Parameter::CANDIDATES)
            .chain(&[Parameter::Oiliness]);
        for &p in all {
            let [lo, hi] = p.range();
            let mid = 0.5 * (lo + hi);
            let s = p.set(base, mid).unwrap();
            assert_eq!(p.get(&s), mid, "{p}");
            assert!(p.set(base, f64::NAN).is_err(), "{p}");
            // The seed's value of every candidate lies inside its range, so a fit can stay there.
            if Parameter::CANDIDATES.contains(&p) {
                let v = p.get(&base);
                assert!(lo <= v && v <= hi, "{p}: {v} outside [{lo}, {hi}]");
            }
        }
    }

    #[test]
    fn model_names_round_trip() {
        for m in [ModelChoice::Seed, ModelChoice::Full, ModelChoice::Auto] {
            assert_eq!(m.to_string().parse::<ModelChoice>().unwrap(), m);
        }
        let e = "tiny".parse::<ModelChoice>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown model 'tiny' (valid: seed, full, auto)"
        );
    }
}
