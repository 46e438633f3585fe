//! Physiology beyond the seed's four parameters (docs/physics.md §13): blood close to the surface,
//! bilirubin, and the amplitude and Mie/Rayleigh balance of the scattering law.
//!
//! Every extension is off by default ([`Physiology::SEED`]); with all of them off,
//! `SkinParams::coefficients` runs the seed's eqs 1–6 unchanged, bit for bit. Each parameter has a
//! *valid* range (what the builders accept; the typed error names it) and a narrower
//! *physiological* range, the one a fit may explore ([`Extension::physiological_range`]), with the
//! source that bounds it.

use crate::chromophores::{
    baseline_sigma_a, deoxyhemoglobin_sigma_a, oxyhemoglobin_sigma_a, sigma_a_from_molar_extinction,
};
use crate::error::{OpticsError, check_range};
use crate::table::UniformTable;
use crate::units::Wavelength;
use std::sync::OnceLock;

/// Molar mass of bilirubin, g/mol (C₃₃H₃₆N₄O₆: 584.7 g/mol).
pub const BILIRUBIN_G_PER_MOL: f64 = 584.66;

/// The extended physiological parameters, each at its seed value unless set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Physiology {
    epidermis_blood: f64,
    bilirubin_g_per_l: f64,
    mie_scale: f64,
    rayleigh_scale: f64,
}

/// One extended parameter, for fits and reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Extension {
    /// Whole-blood volume fraction in the epidermis layer (the model's top 0.25 mm, which holds the
    /// papillary dermis and its capillary loops).
    EpidermisBlood,
    /// Bilirubin concentration in the dermis, g/L.
    Bilirubin,
    /// Scale of the Mie term of the reduced scattering (both layers).
    MieScale,
    /// Scale of the Rayleigh term of the reduced scattering (both layers).
    RayleighScale,
}

impl Extension {
    /// All extensions, in report order.
    pub const ALL: [Extension; 4] = [
        Extension::EpidermisBlood,
        Extension::Bilirubin,
        Extension::MieScale,
        Extension::RayleighScale,
    ];

    /// Short name used in reports and on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Extension::EpidermisBlood => "epidermis_blood",
            Extension::Bilirubin => "bilirubin_g_per_l",
            Extension::MieScale => "mie_scale",
            Extension::RayleighScale => "rayleigh_scale",
        }
    }

    /// Physiological range `[lo, hi]` a fit may explore (docs/physics.md §13 gives each source):
    /// * epidermis blood [0, 0.05]: the papillary dermis holds about 4 % blood and the upper
    ///   vascular plexus up to 30 % in thin sheets ([MM02] Table 1); averaged over the model's
    ///   0.25-mm top layer that is at most a few per cent;
    /// * bilirubin [0, 0.25] g/L: normal serum 0.002–0.012 g/L, severe (neonatal) jaundice
    ///   up to about 0.25 g/L ([AF90]);
    /// * Mie and Rayleigh scales [0.5, 2]: a factor of two either way around the seed's law, which
    ///   spans the measured skin μs' of [Sal06] (epidermis 7.11, dermis 4.65 mm⁻¹ at 500 nm against
    ///   the law's 7.28) and the spread of skin values reviewed in [Jac13].
    #[must_use]
    pub fn physiological_range(self) -> [f64; 2] {
        match self {
            Extension::EpidermisBlood => [0.0, 0.05],
            Extension::Bilirubin => [0.0, 0.25],
            Extension::MieScale | Extension::RayleighScale => [0.5, 2.0],
        }
    }

    /// The value that switches the extension off (the seed's model).
    #[must_use]
    pub fn off_value(self) -> f64 {
        match self {
            Extension::EpidermisBlood | Extension::Bilirubin => 0.0,
            Extension::MieScale | Extension::RayleighScale => 1.0,
        }
    }
}

impl Physiology {
    /// Every extension off: the seed's model.
    pub const SEED: Physiology = Physiology {
        epidermis_blood: 0.0,
        bilirubin_g_per_l: 0.0,
        mie_scale: 1.0,
        rayleigh_scale: 1.0,
    };

    /// The value of one extension.
    #[must_use]
    pub fn get(&self, e: Extension) -> f64 {
        match e {
            Extension::EpidermisBlood => self.epidermis_blood,
            Extension::Bilirubin => self.bilirubin_g_per_l,
            Extension::MieScale => self.mie_scale,
            Extension::RayleighScale => self.rayleigh_scale,
        }
    }

    /// The same physiology with one extension set; valid ranges: blood fraction [0, 1],
    /// bilirubin [0, 10] g/L, scattering scales (0, 10].
    pub fn with(mut self, e: Extension, value: f64) -> Result<Self, OpticsError> {
        match e {
            Extension::EpidermisBlood => {
                self.epidermis_blood =
                    check_range("epidermis blood fraction", value, 0.0, 1.0, "[0, 1]")?;
            }
            Extension::Bilirubin => {
                self.bilirubin_g_per_l =
                    check_range("bilirubin (g/L)", value, 0.0, 10.0, "[0, 10] g/L")?;
            }
            Extension::MieScale => self.mie_scale = positive_scale("Mie scattering scale", value)?,
            Extension::RayleighScale => {
                self.rayleigh_scale = positive_scale("Rayleigh scattering scale", value)?;
            }
        }
        Ok(self)
    }

    /// Whether every extension is off.
    #[must_use]
    pub fn is_seed(&self) -> bool {
        *self == Self::SEED
    }

    /// The extensions that are on (differ from their off value), in report order.
    #[must_use]
    pub fn active(&self) -> Vec<Extension> {
        Extension::ALL
            .into_iter()
            .filter(|&e| self.get(e) != e.off_value())
            .collect()
    }
}

impl Default for Physiology {
    fn default() -> Self {
        Self::SEED
    }
}

fn positive_scale(name: &'static str, value: f64) -> Result<f64, OpticsError> {
    let v = check_range(name, value, 0.0, 10.0, "(0, 10]")?;
    if v <= 0.0 {
        return Err(OpticsError::OutOfRange {
            name,
            value,
            range: "(0, 10]",
        });
    }
    Ok(v)
}

fn bilirubin_table() -> &'static UniformTable {
    static TABLE: OnceLock<UniformTable> = OnceLock::new();
    TABLE
        .get_or_init(|| UniformTable::parse(include_str!("../data/bilirubin_molar_extinction.csv")))
}

/// Molar extinction of bilirubin, cm⁻¹/M decadic, linearly interpolated in the 2-nm table
/// ([AF90] scaling of Li's spectrum, via PhotochemCAD); 0 above 700 nm, where it does not absorb.
#[must_use]
pub fn bilirubin_molar_extinction(lambda: Wavelength) -> f64 {
    bilirubin_table().lerp(0, lambda.nm())
}

/// Absorption of bilirubin at `g_per_l` (g/L), mm⁻¹: ln 10 · ε · c / M / 10.
#[must_use]
pub fn bilirubin_sigma_a(lambda: Wavelength, g_per_l: f64) -> f64 {
    sigma_a_from_molar_extinction(
        bilirubin_molar_extinction(lambda),
        g_per_l,
        BILIRUBIN_G_PER_MOL,
    )
}

/// Whole blood at oxygenation γ, mm⁻¹: γ σa_oxy + (1 − γ) σa_deoxy ([DJ06] eq. 5's blood term).
#[must_use]
pub fn blood_sigma_a(lambda: Wavelength, gamma: f64) -> f64 {
    gamma * oxyhemoglobin_sigma_a(lambda) + (1.0 - gamma) * deoxyhemoglobin_sigma_a(lambda)
}

/// Extended epidermis absorption, mm⁻¹: [DJ06] eq. 1 with a blood fraction C_eb taking its share
/// of the baseline's volume, C_m σa_mel + C_eb σa_blood(γ) + (1 − C_m − C_eb) σa_base (docs/physics.md §13).
#[must_use]
pub(crate) fn epidermis_sigma_a(
    melanin_sigma_a: f64,
    melanin: f64,
    physiology: &Physiology,
    gamma: f64,
    lambda: Wavelength,
) -> f64 {
    let cb = physiology.epidermis_blood;
    melanin * melanin_sigma_a
        + cb * blood_sigma_a(lambda, gamma)
        + (1.0 - melanin - cb).max(0.0) * baseline_sigma_a(lambda)
}

/// Bilirubin's absorption added to the dermis, mm⁻¹ (0 when off).
#[must_use]
pub(crate) fn dermis_extra_sigma_a(physiology: &Physiology, lambda: Wavelength) -> f64 {
    if physiology.bilirubin_g_per_l > 0.0 {
        bilirubin_sigma_a(lambda, physiology.bilirubin_g_per_l)
    } else {
        0.0
    }
}

/// Extended reduced scattering, mm⁻¹: [DJ06] eq. 6 with its Mie and Rayleigh terms scaled,
/// s_M · 14.74 λ^−0.22 + s_R · 2.2·10¹¹ λ^−4.
#[must_use]
pub(crate) fn reduced_scattering(physiology: &Physiology, lambda: Wavelength) -> f64 {
    let l = lambda.nm();
    physiology.mie_scale * (14.74 * l.powf(-0.22))
        + physiology.rayleigh_scale * (2.2e11 * l.powi(-4))
}

#[cfg(test)]
mod tests;
