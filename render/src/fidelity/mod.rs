//! How much model each skin gets (docs/physics.md §16): the renderer chooses each knob of a skin's
//! tables and of its shading from what the scene needs, and reports every choice with its measured
//! error (`skin render --explain`).
//!
//! - [`wavelengths`]: the widest wavelength step whose interpolated reflectance keeps the skin's
//!   colour within a CIEDE2000 target and its luminance within a relative target of a 1-nm grid.
//! - [`lod`]: subsurface scattering blended into a Fresnel-weighted diffuse surface where a pixel
//!   covers much more than the profile's 99% radius.
//! - [`key`]: the disk-cache key of a skin's tables, the canonical bytes of everything they
//!   depend on.
//! - [`explain`]: what was chosen for each skin material and why; the diffusion warning.
//! - [`tables`]: a skin's tables with the choices applied, through the cache.
//! - [`photons`]: the Monte Carlo shape's photon count from the smallest pixel footprint on the
//!   skin and the measured error-vs-photons law.
//!
//! `Fidelity::Full` keeps every table knob at its fixed default (10-nm rows, 128 radii, each
//! profile's own 99.9% extent) and shades every skin hit with the full BSSRDF: the reference the
//! automatic choices are measured against. Each choice can be overridden alone
//! ([`FidelityKnobs`]).
//!
//! The name parsing of [`Fidelity`] (a `Display`/`FromStr` pair, one arm per name), the option
//! struct's field list and [`FidelityError`] (knob, value, valid range) have the shape of the same
//! items for the workspace's other enums and settings: each is kept with its type so that its
//! error names its own knob and valid values.

pub mod explain;
pub mod grid;
pub mod incidence;
pub mod key;
pub mod lod;
pub mod photons;
pub mod tables;
pub mod wavelengths;

pub use explain::{SkinChoices, TransportChoice};
pub use lod::{Lod, LodBand};
pub use wavelengths::WavelengthChoice;

use std::fmt;
use std::str::FromStr;
use thiserror::Error;

/// Factor of r₉₉: the pixel footprint below which a thin part (where the BSSRDF would omit at least
/// [`THIN_OMISSION_SHARE`] of the light, judged from the slab's exact transmission)
/// takes the volumetric walk under `Fidelity::Auto` (`--thin-walk K` sets another, 0 turns the walk
/// off; `Fidelity::Full` never walks).
pub const DEFAULT_THIN_WALK_R99: f64 = 1.0;

/// Share of the light the BSSRDF returns at a hit, R∞ E_near, that it may omit there (light
/// crossing from a lit far face, reflection a thin part lacks) before the hit takes the volumetric
/// walk (`crate::volumetric::thin`, docs/physics.md §16.6). The approximation's knob: its error on
/// backlit and front-lit slabs and on the ear is measured in docs/accuracy_evidence.md §4.
pub const THIN_OMISSION_SHARE: f32 = 0.05;
/// Wavelength step of the skin reflectance tables in `Fidelity::Full` and without a BSSRDF, nm
/// (interpolated to 5 nm).
pub const SKIN_TABLE_STEP_NM: f64 = 10.0;
/// Energy left beyond a profile row's end in `Fidelity::Auto`, a fraction of its total.
pub const DEFAULT_ENERGY_TOLERANCE: f64 = 1e-3;
/// Energy-weighted interpolation error target of the radius grid in `Fidelity::Auto`.
pub const DEFAULT_RADIAL_ERROR: f64 = 2e-3;
/// CIEDE2000 target of the wavelength choice in `Fidelity::Auto` (against a 1-nm grid).
pub const DEFAULT_MAX_DELTA_E: f64 = 0.5;
/// Relative luminance (CIE Y under D65) target of the wavelength choice in `Fidelity::Auto`
/// (against a 1-nm grid): below the 0.13% noise floor of the close-up's mean skin luminance
/// (BENCHMARKS.md, "Fidelity").
pub const DEFAULT_MAX_LUMINANCE_ERROR: f64 = 1e-3;

/// All automatic choices on (`Auto`, the default) or every knob at its fixed reference value
/// (`Full`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Fidelity {
    /// Each choice made from the scene (extent, radii, wavelengths, shape photons, level of
    /// detail).
    #[default]
    Auto,
    /// Every choice at its reference: full tables and the BSSRDF at every skin hit.
    Full,
}

/// A fidelity name that is neither `auto` nor `full`.
#[derive(Debug, Clone, Error)]
#[error("unknown fidelity '{0}' (valid: auto, full)")]
pub struct UnknownFidelity(pub String);

impl fmt::Display for Fidelity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Fidelity::Auto => "auto",
            Fidelity::Full => "full",
        })
    }
}

impl FromStr for Fidelity {
    type Err = UnknownFidelity;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(Fidelity::Auto),
            "full" => Ok(Fidelity::Full),
            _ => Err(UnknownFidelity(s.to_string())),
        }
    }
}

/// Level of detail asked for: by the fidelity, off, or a given band.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum LodSetting {
    /// `Auto`: [`LodBand::default`]; `Full`: off.
    #[default]
    ByFidelity,
    /// The BSSRDF at every skin hit.
    Off,
    /// This band.
    Band(LodBand),
}

/// The fidelity and its per-choice overrides (`None` / `ByFidelity`: chosen by `fidelity`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FidelityKnobs {
    /// All choices at once (`None`: the scene's `[fidelity]`, else auto).
    pub fidelity: Option<Fidelity>,
    /// Energy left beyond each profile row, a fraction of its total in (0, 0.1].
    pub energy_tolerance: Option<f64>,
    /// Interpolation error target of the radius grid, in (0, 0.1].
    pub radial_error: Option<f64>,
    /// Wavelength step of the tables, nm (dividing 400 nm).
    pub wavelength_step_nm: Option<f64>,
    /// Level of detail by pixel footprint.
    pub lod: LodSetting,
    /// Pixel footprint, in units of the skin's largest r₉₉, below which a thin part takes the
    /// volumetric walk, in [0, 10] (0: never).
    pub thin_walk_r99: Option<f64>,
    /// Photons of the universal shape table, in [1e4, 1e9] (auto: from the pixel footprint,
    /// `photons`; full: 500,000).
    pub shape_photons: Option<u64>,
    /// Image height the scene is rendered at, pixels (with the camera, the pixel footprint; `None`:
    /// unknown, so no choice from the footprint).
    pub image_height: Option<u32>,
    /// Smallest pixel footprint on this skin, mm (set per material by the scene loader from
    /// `image_height`, the camera and the skin's meshes).
    pub smallest_footprint_mm: Option<f32>,
    /// Read and write the disk cache of skin tables (default true; `--no-cache` clears it).
    pub cache: bool,
}

impl Default for FidelityKnobs {
    fn default() -> Self {
        Self {
            fidelity: None,
            energy_tolerance: None,
            radial_error: None,
            wavelength_step_nm: None,
            lod: LodSetting::ByFidelity,
            thin_walk_r99: None,
            shape_photons: None,
            image_height: None,
            smallest_footprint_mm: None,
            cache: true,
        }
    }
}

/// How the shape's photons are chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PhotonPolicy {
    /// The default table (500,000 photons) or the escapes asked for.
    Fixed,
    /// This many table photons (`--shape-photons`, `fidelity.shape_photons`).
    Override(u64),
    /// From this smallest pixel footprint, mm (`photons`).
    Footprint(f32),
}

/// How the wavelength step is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepChoice {
    /// This step, nm.
    Fixed(f64),
    /// The widest step within this CIEDE2000 and this relative luminance error of a 1-nm grid.
    Colour {
        /// ΔE2000 target.
        max_delta_e: f64,
        /// |Y / Y₁ₙₘ − 1| target.
        max_luminance_error: f64,
    },
}

/// [`FidelityKnobs`] with every choice resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resolved {
    /// Energy tolerance of the row ends (`None`: the profiles' own 99.9% extent).
    pub energy_tolerance: Option<f64>,
    /// Radius-grid error target (`None`: 128 radii).
    pub radial_error: Option<f64>,
    /// Wavelength step.
    pub step: StepChoice,
    /// The level-of-detail band, if on.
    pub lod: Option<LodBand>,
    /// The thin-part walk's largest pixel footprint in r₉₉, if on.
    pub thin_walk_r99: Option<f64>,
    /// How the shape photons are chosen.
    pub photons: PhotonPolicy,
}

/// A fidelity knob outside its range.
#[derive(Debug, Clone, Error)]
#[error("{name} = {value} outside {range}")]
pub struct FidelityError {
    /// The knob.
    pub name: &'static str,
    /// Its value.
    pub value: f64,
    /// Its valid range.
    pub range: &'static str,
}

impl FidelityKnobs {
    /// These knobs with each one left unset taken from `under` (a scene's own choices).
    #[must_use]
    pub fn over(self, under: &FidelityKnobs) -> Self {
        Self {
            fidelity: self.fidelity.or(under.fidelity),
            energy_tolerance: self.energy_tolerance.or(under.energy_tolerance),
            radial_error: self.radial_error.or(under.radial_error),
            wavelength_step_nm: self.wavelength_step_nm.or(under.wavelength_step_nm),
            lod: match self.lod {
                LodSetting::ByFidelity => under.lod,
                set => set,
            },
            thin_walk_r99: self.thin_walk_r99.or(under.thin_walk_r99),
            shape_photons: self.shape_photons.or(under.shape_photons),
            image_height: self.image_height.or(under.image_height),
            smallest_footprint_mm: self.smallest_footprint_mm.or(under.smallest_footprint_mm),
            cache: self.cache,
        }
    }

    /// Every choice resolved from the fidelity and the overrides, each checked against its range.
    pub fn resolve(&self) -> Result<Resolved, FidelityError> {
        let auto = self.fidelity.unwrap_or_default() == Fidelity::Auto;
        let fraction = |name, v: Option<f64>| match v {
            Some(x) if !(x > 0.0 && x <= 0.1) => Err(FidelityError {
                name,
                value: x,
                range: "(0, 0.1]",
            }),
            _ => Ok(v),
        };
        let energy_tolerance = fraction("fidelity.energy_tolerance", self.energy_tolerance)?
            .or(auto.then_some(DEFAULT_ENERGY_TOLERANCE));
        let radial_error = fraction("fidelity.radial_error", self.radial_error)?
            .or(auto.then_some(DEFAULT_RADIAL_ERROR));
        let step = match self.wavelength_step_nm {
            Some(s) if wavelengths::STEPS_NM.contains(&s) => StepChoice::Fixed(s),
            Some(s) => {
                return Err(FidelityError {
                    name: "fidelity.wavelength_step_nm",
                    value: s,
                    range: "{5, 8, 10, 16, 20, 25, 40, 50, 80, 100} nm (dividing 400 nm)",
                });
            }
            None if auto => StepChoice::Colour {
                max_delta_e: DEFAULT_MAX_DELTA_E,
                max_luminance_error: DEFAULT_MAX_LUMINANCE_ERROR,
            },
            None => StepChoice::Fixed(SKIN_TABLE_STEP_NM),
        };
        let lod = match self.lod {
            LodSetting::ByFidelity => auto.then(LodBand::default),
            LodSetting::Off => None,
            LodSetting::Band(b) => Some(b.checked()?),
        };
        let thin_walk_r99 = match self.thin_walk_r99 {
            Some(k) if !(0.0..=10.0).contains(&k) => {
                return Err(FidelityError {
                    name: "fidelity.thin_walk",
                    value: k,
                    range: "[0, 10] (r99; 0: never)",
                });
            }
            Some(k) => (k > 0.0).then_some(k),
            None => auto.then_some(DEFAULT_THIN_WALK_R99),
        };
        let photons = match (self.shape_photons, self.smallest_footprint_mm) {
            (Some(n), _) if !(1e4..=1e9).contains(&(n as f64)) => {
                return Err(FidelityError {
                    name: "fidelity.shape_photons",
                    value: n as f64,
                    range: "[1e4, 1e9]",
                });
            }
            (Some(n), _) => PhotonPolicy::Override(n),
            (None, Some(f)) if auto && f.is_finite() && f > 0.0 => PhotonPolicy::Footprint(f),
            (None, _) => PhotonPolicy::Fixed,
        };
        Ok(Resolved {
            energy_tolerance,
            radial_error,
            step,
            lod,
            thin_walk_r99,
            photons,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Full` is today's fixed tables without level of detail; `Auto` turns every choice on; an
    /// override wins over either, and a bad one names its knob.
    #[test]
    fn fidelity_resolves_each_choice() {
        let full = FidelityKnobs {
            fidelity: Some(Fidelity::Full),
            ..FidelityKnobs::default()
        }
        .resolve()
        .unwrap();
        assert_eq!(full.energy_tolerance, None);
        assert_eq!(full.radial_error, None);
        assert_eq!(full.step, StepChoice::Fixed(10.0));
        assert_eq!(full.lod, None);
        assert_eq!(full.thin_walk_r99, None);
        let seen = FidelityKnobs {
            smallest_footprint_mm: Some(6.0),
            ..FidelityKnobs::default()
        };
        assert_eq!(
            seen.resolve().unwrap().photons,
            PhotonPolicy::Footprint(6.0)
        );
        let seen_full = FidelityKnobs {
            fidelity: Some(Fidelity::Full),
            ..seen
        };
        assert_eq!(seen_full.resolve().unwrap().photons, PhotonPolicy::Fixed);
        let forced = FidelityKnobs {
            shape_photons: Some(200_000),
            ..seen
        };
        assert_eq!(
            forced.resolve().unwrap().photons,
            PhotonPolicy::Override(200_000)
        );
        let too_few = FidelityKnobs {
            shape_photons: Some(10),
            ..seen
        };
        assert_eq!(
            too_few.resolve().unwrap_err().name,
            "fidelity.shape_photons"
        );
        let auto = FidelityKnobs::default().resolve().unwrap();
        assert_eq!(auto.energy_tolerance, Some(DEFAULT_ENERGY_TOLERANCE));
        assert!(matches!(auto.step, StepChoice::Colour { .. }));
        assert_eq!(auto.lod, Some(LodBand::default()));
        assert_eq!(auto.thin_walk_r99, Some(DEFAULT_THIN_WALK_R99));
        let never = FidelityKnobs {
            thin_walk_r99: Some(0.0),
            ..FidelityKnobs::default()
        };
        assert_eq!(never.resolve().unwrap().thin_walk_r99, None);
        let over = FidelityKnobs {
            wavelength_step_nm: Some(20.0),
            lod: LodSetting::Off,
            ..FidelityKnobs::default()
        }
        .resolve()
        .unwrap();
        assert_eq!((over.step, over.lod), (StepChoice::Fixed(20.0), None));
        let bad = FidelityKnobs {
            energy_tolerance: Some(0.5),
            ..FidelityKnobs::default()
        }
        .resolve()
        .unwrap_err();
        assert_eq!(bad.name, "fidelity.energy_tolerance");
        assert!("Full".parse::<Fidelity>().is_ok() && "half".parse::<Fidelity>().is_err());
        // A flag wins over the scene's key; an unset flag takes it.
        let scene = FidelityKnobs {
            fidelity: Some(Fidelity::Full),
            wavelength_step_nm: Some(25.0),
            ..FidelityKnobs::default()
        };
        let flags = FidelityKnobs {
            wavelength_step_nm: Some(50.0),
            ..FidelityKnobs::default()
        };
        let merged = flags.over(&scene);
        assert_eq!(merged.fidelity, Some(Fidelity::Full));
        assert_eq!(merged.wavelength_step_nm, Some(50.0));
    }
}
