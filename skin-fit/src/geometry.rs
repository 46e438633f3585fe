//! The measuring instrument: a d/8 integrating-sphere spectrophotometer with the specular component
//! excluded (SCE) or included (SCI) (docs/physics.md §13).
//!
//! The sphere lights the sample diffusely and views it at 8° from the normal. By reciprocity that
//! equals collimated light at 8° collected over the hemisphere, so:
//! * **SCE** (the default, and what [`multipole::skin::diffuse_reflectance`] already is): the subsurface
//!   reflectance at (near-)normal incidence, the specular light trapped;
//! * **SCI**: SCE plus the surface reflection of the oily layer, the directional albedo of the
//!   Torrance–Sparrow lobe at θ = 8°, ρ_s · a(cos 8°), from `brdf`'s quadrature (Beckmann roughness
//!   [`brdf::DEFAULT_ROUGHNESS`], index η of the skin). It is wavelength independent (η is).
//!
//! Approximation: the subsurface term keeps its smooth-surface entry factor 1 − F_r(0) rather than
//! 1 − ρ_s a(cos 8°); for the default lobe the two differ by under 0.03 of R_d (≤ 0.015 in
//! reflectance at R = 0.6), as F_r(0) = 0.028 and ρ_s a ≤ 0.03.

use super::FitError;
use brdf::TorranceSparrow;
use std::fmt;
use std::str::FromStr;

/// Viewing angle of a d/8 instrument, degrees from the normal (CIE 15 geometry d:8°).
pub const VIEWING_ANGLE_DEG: f64 = 8.0;

/// Gauss–Legendre nodes per axis of the albedo quadrature (accurate to 1e-5, `brdf` module doc).
pub const ALBEDO_NODES: usize = 96;

/// What the instrument reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Geometry {
    /// d/8, specular component excluded: the model's diffuse reflectance as it is.
    #[default]
    Sce,
    /// d/8, specular component included: diffuse plus the lobe's albedo at 8°.
    Sci,
}

impl fmt::Display for Geometry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Geometry::Sce => "sce",
            Geometry::Sci => "sci",
        })
    }
}

impl FromStr for Geometry {
    type Err = FitError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "sce" => Ok(Geometry::Sce),
            "sci" => Ok(Geometry::Sci),
            _ => Err(FitError::Unknown {
                what: "geometry",
                found: s.to_string(),
                valid: "sce, sci",
            }),
        }
    }
}

/// Surface reflection at 8° per unit oiliness, a(cos 8°) for ρ_s = 1, dimensionless, for skin
/// index `eta` in [1, 3] (brdf's direct quadrature with [`ALBEDO_NODES`] nodes).
pub fn unit_surface_reflectance(eta: f64) -> Result<f64, FitError> {
    let lobe = TorranceSparrow::new(brdf::DEFAULT_ROUGHNESS, 1.0, eta as f32)?;
    Ok(lobe.directional_albedo_quadrature(VIEWING_ANGLE_DEG.to_radians().cos(), ALBEDO_NODES)?)
}

impl Geometry {
    /// Reflectance the instrument adds to the model's diffuse reflectance for oiliness `rho_s` and
    /// index `eta`: 0 for SCE, ρ_s a(cos 8°) for SCI.
    pub fn surface_reflectance(self, rho_s: f64, eta: f64) -> Result<f64, FitError> {
        match self {
            Geometry::Sce => Ok(0.0),
            Geometry::Sci => Ok(rho_s * unit_surface_reflectance(eta)?),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SCI adds exactly the lobe's albedo at 8°, from brdf's own quadrature, linear in ρ_s; the
    /// unit albedo lies near the smooth-surface Fresnel F(0) = 0.028 for η = 1.4 (a rough lobe
    /// reflects a little more at 8°, shadowing takes a little: within 20 %).
    #[test]
    fn sci_matches_the_brdf_albedo_quadrature() {
        let cos8 = 8f64.to_radians().cos();
        let lobe = TorranceSparrow::new(brdf::DEFAULT_ROUGHNESS, 0.25, 1.4).unwrap();
        let direct = lobe.directional_albedo_quadrature(cos8, 192).unwrap();
        let ours = Geometry::Sci.surface_reflectance(0.25, 1.4).unwrap();
        // 96 against 192 nodes: both within 1e-5 of converged (brdf module doc).
        assert!((ours - direct).abs() < 2e-5, "{ours} vs {direct}");
        // The table the renderer uses agrees to its stated 1e-4.
        assert!((ours - f64::from(lobe.directional_albedo(cos8 as f32))).abs() < 1e-4);
        let unit = unit_surface_reflectance(1.4).unwrap();
        assert!((unit - 0.028).abs() < 0.2 * 0.028, "{unit}");
        assert_eq!(Geometry::Sce.surface_reflectance(0.25, 1.4).unwrap(), 0.0);
    }

    #[test]
    fn geometry_names_round_trip() {
        for g in [Geometry::Sce, Geometry::Sci] {
            assert_eq!(g.to_string().parse::<Geometry>().unwrap(), g);
        }
        assert!("d/0".parse::<Geometry>().is_err());
        assert_eq!(Geometry::default(), Geometry::Sce);
    }
}
