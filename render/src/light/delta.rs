//! Delta lights, which BSDF sampling can never hit (no MIS): the point light, the spot light and
//! the distant light.

use super::{LightSample, facing, selection};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, SpectrumTable};
use glam::Vec3;

/// Isotropic point light.
#[derive(Debug, Clone, PartialEq)]
pub struct PointLight {
    /// Position, mm.
    pub position_mm: Vec3,
    /// Radiant intensity spectrum.
    pub intensity: SpectrumTable,
}

impl PointLight {
    /// The light arriving at `p`: intensity / d².
    #[must_use]
    pub fn sample(&self, p: Vec3, wl: &SampledWavelengths) -> Option<LightSample> {
        let (wi, r2) = towards(self.position_mm, p);
        Some(delta(wi, r2.sqrt(), self.intensity.eval(wl) / r2))
    }

    /// Selection proxy at `p` with normal `n`: intensity / d² times the cosine.
    #[must_use]
    pub fn selection_weight(&self, p: Vec3, n: Vec3) -> f32 {
        inverse_square_weight(self.position_mm, &self.intensity, p, n)
    }
}

/// Spot light with a smooth falloff between the inner and outer cone.
#[derive(Debug, Clone, PartialEq)]
pub struct SpotLight {
    /// Position, mm.
    pub position_mm: Vec3,
    /// Unit direction of the cone axis.
    pub direction: Vec3,
    /// cos of the inner (full-intensity) half angle.
    pub cos_inner: f32,
    /// cos of the outer (zero-intensity) half angle.
    pub cos_outer: f32,
    /// Radiant intensity spectrum on the axis.
    pub intensity: SpectrumTable,
}

impl SpotLight {
    /// The light arriving at `p`: intensity / d² times the smoothstep falloff (None outside the cone).
    #[must_use]
    pub fn sample(&self, p: Vec3, wl: &SampledWavelengths) -> Option<LightSample> {
        let (wi, r2) = towards(self.position_mm, p);
        let cos = (-wi).dot(self.direction);
        let x =
            ((cos - self.cos_outer) / (self.cos_inner - self.cos_outer).max(1e-6)).clamp(0.0, 1.0);
        let falloff = x * x * (3.0 - 2.0 * x);
        (falloff > 0.0).then(|| delta(wi, r2.sqrt(), self.intensity.eval(wl) * (falloff / r2)))
    }

    /// Selection proxy at `p` with normal `n`: as a point light (the cone is ignored).
    #[must_use]
    pub fn selection_weight(&self, p: Vec3, n: Vec3) -> f32 {
        inverse_square_weight(self.position_mm, &self.intensity, p, n)
    }
}

/// Unit direction from `p` to `position_mm`, and the squared distance, mm².
fn towards(position_mm: Vec3, p: Vec3) -> (Vec3, f32) {
    let d = position_mm - p;
    let r2 = d.length_squared();
    (d / r2.sqrt(), r2)
}

/// A delta light's sample: `li` arriving from `wi`, emitted `distance_mm` away (pdf 1).
fn delta(wi: Vec3, distance_mm: f32, li: SampledSpectrum) -> LightSample {
    LightSample {
        wi,
        distance_mm,
        li,
        pdf: 1.0,
        is_delta: true,
    }
}

/// intensity / d² · cos towards a point light at `position_mm`.
fn inverse_square_weight(position_mm: Vec3, intensity: &SpectrumTable, p: Vec3, n: Vec3) -> f32 {
    let to = (position_mm - p).as_dvec3();
    let d2 = to.length_squared().max(1e-6);
    selection(f64::from(intensity.mean()) / d2 * facing(n, to, d2.sqrt(), 0.0))
}

/// Light from a single direction (the sun), irradiance on a surface facing it.
#[derive(Debug, Clone, PartialEq)]
pub struct DistantLight {
    /// Unit direction towards the light.
    pub to_light: Vec3,
    /// Irradiance spectrum.
    pub irradiance: SpectrumTable,
}

impl DistantLight {
    /// The irradiance from the light's direction.
    #[must_use]
    pub fn sample(&self, wl: &SampledWavelengths) -> Option<LightSample> {
        Some(delta(
            self.to_light,
            f32::INFINITY,
            self.irradiance.eval(wl),
        ))
    }

    /// Selection proxy with normal `n`: E times the cosine.
    #[must_use]
    pub fn selection_weight(&self, n: Vec3) -> f32 {
        selection(f64::from(self.irradiance.mean()) * facing(n, self.to_light.as_dvec3(), 1.0, 0.0))
    }
}
