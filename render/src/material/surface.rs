//! The two surface models of skin (scene key `surface`): the seed's oily Torrance–Sparrow layer
//! ([TS67], [DJ06] §3; docs/physics.md §7) and a smooth dielectric of the skin's index (exact
//! unpolarised Fresnel reflection and refraction, `brdf::fresnel`), for validation against
//! closed forms. Both give the energy split T(θ) = 1 − (reflected fraction) through which light
//! enters the body.

use super::SkinMaterial;
use brdf::TorranceSparrow;
use brdf::fresnel::dielectric_reflectance_f32;
use glam::Vec3;
use std::str::FromStr;

/// Which surface a skin has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SurfaceKind {
    /// The oily Torrance–Sparrow lobe with the skin's ρ_s and roughness (the default).
    #[default]
    Oily,
    /// A smooth dielectric of the skin's index η: mirror reflection with weight F(θ), refraction
    /// with 1 − F(θ), no oil lobe.
    Smooth,
}

impl FromStr for SurfaceKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "oily" => Ok(Self::Oily),
            "smooth" => Ok(Self::Smooth),
            _ => Err(format!(
                "unknown surface '{}' (valid: oily, smooth)",
                skin_optics::echo::text(s)
            )),
        }
    }
}

/// A skin's surface at a shading point, local frame (+Z = normal).
#[derive(Debug, Clone, Copy)]
pub(super) enum Surface<'a> {
    Oily(&'a TorranceSparrow),
    Smooth { eta: f32 },
}

impl<'a> Surface<'a> {
    pub(super) fn of(skin: &'a SkinMaterial) -> Self {
        match skin.surface_kind {
            SurfaceKind::Oily => Self::Oily(&skin.surface),
            SurfaceKind::Smooth => Self::Smooth {
                eta: skin.surface.eta(),
            },
        }
    }

    /// Fraction of the light arriving at incidence cosine `cos` that the surface reflects.
    pub(super) fn albedo(&self, cos: f32) -> f32 {
        match self {
            Self::Oily(ts) => ts.directional_albedo(cos),
            Self::Smooth { eta } => dielectric_reflectance_f32(cos.clamp(0.0, 1.0), *eta),
        }
    }

    /// The fraction that enters where the surface reflects the fraction `albedo` ([`Self::albedo`]).
    pub(super) fn transmitted_of(albedo: f32) -> f32 {
        1.0 - albedo
    }

    /// The BRDF of the non-delta part, sr⁻¹ (0 for the smooth surface).
    pub(super) fn eval(&self, o: Vec3, i: Vec3) -> f32 {
        match self {
            Self::Oily(ts) => ts.eval(o, i),
            Self::Smooth { .. } => 0.0,
        }
    }

    /// Density of the non-delta part, sr⁻¹ (0 for the smooth surface).
    pub(super) fn pdf(&self, o: Vec3, i: Vec3) -> f32 {
        match self {
            Self::Oily(ts) => ts.pdf(o, i),
            Self::Smooth { .. } => 0.0,
        }
    }

    /// An incident direction sampled from the lobe (the mirror direction for the smooth surface).
    pub(super) fn sample(&self, o: Vec3, u: [f32; 2]) -> Option<Vec3> {
        match self {
            Self::Oily(ts) => ts.sample(o, u).map(|s| s.wi),
            Self::Smooth { .. } => Some(Vec3::new(-o.x, -o.y, o.z)),
        }
    }
}
