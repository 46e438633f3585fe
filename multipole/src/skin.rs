//! Two-layer skin ([DJ06]): an epidermis slab of the given thickness (index `skin.eta()` above it,
//! matched below) over a semi-infinite dermis (dipole with A = 1), stacked in the frequency domain.

use crate::boundary::observable_reflectance;
use crate::dipole::Dipole;
use crate::error::MultipoleError;
use crate::medium::Medium;
use crate::slab::{Poles, Slab};
use crate::stack::{Layer, Stack};
use skin_optics::{SkinParams, Wavelength};
use std::fmt;
use std::str::FromStr;

/// How the skin's diffuse reflectance is computed. More accurate methods may be added beside the paper's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Method {
    /// Donner & Jensen's multipole diffusion with frequency-domain layer stacking ([DJ05], [DJ06]).
    #[default]
    Multipole,
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Method::Multipole => f.write_str("multipole"),
        }
    }
}

impl FromStr for Method {
    type Err = MultipoleError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "multipole" => Ok(Method::Multipole),
            _ => Err(MultipoleError::UnknownMethod(s.to_string())),
        }
    }
}

/// The layer stack of `skin` at `lambda`: epidermis slab (η_top = skin η, η_bottom = 1 so A = 1)
/// over a semi-infinite dermis (A = 1: index matched to the epidermis).
pub fn stack(skin: &SkinParams, lambda: Wavelength) -> Result<Stack, MultipoleError> {
    let c = skin.coefficients(lambda);
    let epidermis = Slab::new(
        Medium::from_coefficients(&c.epidermis)?,
        skin.epidermis_thickness_mm(),
        skin.eta(),
        1.0,
    )?;
    let dermis = Dipole::new(Medium::from_coefficients(&c.dermis)?, 1.0)?;
    Stack::new(vec![Layer::Slab(epidermis), Layer::SemiInfinite(dermis)])
}

/// The model's total diffuse reflectance R_d per unit flux *entering* the skin, dimensionless, in (0, 1).
pub fn total_reflectance(
    skin: &SkinParams,
    lambda: Wavelength,
    method: Method,
) -> Result<f64, MultipoleError> {
    match method {
        Method::Multipole => Ok(stack(skin, lambda)?.total_reflectance(Poles::Exact)),
    }
}

/// The observable: diffuse reflectance per unit *incident* flux at normal incidence, specular
/// excluded, (1 − F_r(0)) R_d, dimensionless (what a spectrophotometer or a Monte Carlo reports).
pub fn diffuse_reflectance(
    skin: &SkinParams,
    lambda: Wavelength,
    method: Method,
) -> Result<f64, MultipoleError> {
    Ok(observable_reflectance(
        total_reflectance(skin, lambda, method)?,
        skin.eta(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_optics::Preset;

    #[test]
    fn method_parses_and_prints() {
        assert_eq!("multipole".parse::<Method>().unwrap(), Method::Multipole);
        assert_eq!(Method::default().to_string(), "multipole");
        let e = "mcml".parse::<Method>().unwrap_err().to_string();
        assert!(e.contains("mcml") && e.contains("multipole"), "{e}");
    }

    #[test]
    fn every_preset_total_in_unit_interval_and_darker_is_darker() {
        for nm in (400..=700).step_by(10) {
            let lambda = Wavelength::new(nm as f64).unwrap();
            let mut last = f64::INFINITY;
            for p in [Preset::Light, Preset::Medium, Preset::Dark] {
                let skin = SkinParams::preset(p);
                let r = total_reflectance(&skin, lambda, Method::Multipole).unwrap();
                let obs = diffuse_reflectance(&skin, lambda, Method::Multipole).unwrap();
                assert!(r > 0.0 && r < 1.0, "{p:?} {nm} nm: {r}");
                assert!((obs / r - (1.0 - 0.027_777_777_8)).abs() < 1e-9);
                assert!(
                    r < last,
                    "{p:?} at {nm} nm is not darker than the lighter preset"
                );
                last = r;
            }
        }
    }
}
