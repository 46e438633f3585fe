//! Light sources: point, spot, distant, sphere and quad area lights, and the environment
//! (constant or lat-long EXR). Each kind is its own type (`delta`, `area`, `environment`);
//! [`Light`] dispatches to them. Emission spectra (`emission`) are normalised to luminance Y = 1
//! and multiplied by the light's intensity.
//!
//! Units: positions in mm; area lights and the environment give radiance; a point or spot light
//! gives radiant intensity (radiance · mm²: irradiance = I / d² with d in mm); a distant light gives
//! the irradiance on a surface facing it. All in the relative units where Y = 1 is "white 1".

mod area;
mod delta;
mod emission;
mod environment;

pub use area::{QuadLight, SphereLight};
pub use delta::{DistantLight, PointLight, SpotLight};
pub use emission::EmissionShape;
pub use environment::Environment;

use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

/// A light sample seen from a shading point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point to the light.
    pub wi: Vec3,
    /// Distance to the sampled point, mm (∞ for distant lights and the environment).
    pub distance_mm: f32,
    /// Incident radiance (area lights) or irradiance-equivalent (delta lights) per wavelength.
    pub li: SampledSpectrum,
    /// Solid-angle density of `wi`, sr⁻¹ (1 for delta lights).
    pub pdf: f32,
    /// True for point, spot and distant lights (no MIS: BSDF sampling cannot hit them).
    pub is_delta: bool,
}

/// A light source placed in the scene.
#[derive(Debug, Clone, PartialEq)]
pub enum Light {
    /// Isotropic point light.
    Point(PointLight),
    /// Spot light with a smooth falloff between the inner and outer cone.
    Spot(SpotLight),
    /// Light from a single direction (the sun).
    Distant(DistantLight),
    /// Spherical area light.
    Sphere(SphereLight),
    /// One-sided parallelogram area light.
    Quad(QuadLight),
}

/// cos towards a light in direction `to` (length `d`) of angular radius with sine `spread`, seen
/// with normal `n`, clamped to [0, 1].
fn facing(n: Vec3, to: Vec3, d: f32, spread: f32) -> f32 {
    (n.dot(to) / d + spread.min(1.0)).clamp(0.0, 1.0)
}

impl Light {
    /// Sample incident light at `p` with `u` ∈ [0, 1)².
    #[must_use]
    pub fn sample(&self, p: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<LightSample> {
        match self {
            Light::Point(l) => l.sample(p, wl),
            Light::Spot(l) => l.sample(p, wl),
            Light::Distant(l) => l.sample(wl),
            Light::Sphere(l) => l.sample(p, u, wl),
            Light::Quad(l) => l.sample(p, u, wl),
        }
    }

    /// Rough irradiance this light delivers at `p` on a surface with normal `n` (luminance units),
    /// used only to choose which light to sample there: intensity / d² for point and spot, E for
    /// distant, L · solid angle for area lights, times the cosine towards the light widened by the
    /// light's angular radius (0 when the light is entirely below the surface or behind a one-sided
    /// quad). Any proxy that is positive wherever the light can contribute keeps the estimator
    /// unbiased; a good one lowers the noise.
    #[must_use]
    pub fn selection_weight(&self, p: Vec3, n: Vec3) -> f32 {
        match self {
            Light::Point(l) => l.selection_weight(p, n),
            Light::Spot(l) => l.selection_weight(p, n),
            Light::Distant(l) => l.selection_weight(n),
            Light::Sphere(l) => l.selection_weight(p, n),
            Light::Quad(l) => l.selection_weight(p, n),
        }
    }

    /// Distance at which the ray (`o`, unit `d`) hits this light's emitting surface, if any.
    #[must_use]
    pub fn intersect(&self, o: Vec3, d: Vec3) -> Option<f32> {
        match self {
            Light::Sphere(l) => l.intersect(o, d),
            Light::Quad(l) => l.intersect(o, d),
            Light::Point(_) | Light::Spot(_) | Light::Distant(_) => None,
        }
    }

    /// Emitted radiance seen along a ray that hit this light (area lights only).
    #[must_use]
    pub fn radiance(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Light::Sphere(l) => l.radiance.eval(wl),
            Light::Quad(l) => l.radiance.eval(wl),
            Light::Point(_) | Light::Spot(_) | Light::Distant(_) => SampledSpectrum::zero(),
        }
    }

    /// Solid-angle density with which [`Light::sample`] from `p` picks direction `wi` that hits
    /// the light at distance `t` (for MIS of BSDF-sampled hits).
    #[must_use]
    pub fn pdf(&self, p: Vec3, wi: Vec3, t: f32) -> f32 {
        match self {
            Light::Sphere(l) => l.pdf(p),
            Light::Quad(l) => l.pdf(wi, t),
            Light::Point(_) | Light::Spot(_) | Light::Distant(_) => 0.0,
        }
    }
}
