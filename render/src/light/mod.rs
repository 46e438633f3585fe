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
pub use emission::{EmissionShape, MAX_INTENSITY};
pub use environment::Environment;

use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{DVec3, Vec2, Vec3};

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
fn facing(n: Vec3, to: DVec3, d: f64, spread: f64) -> f64 {
    (n.as_dvec3().dot(to) / d + spread.min(1.0)).clamp(0.0, 1.0)
}

/// Range a positive selection weight is clamped to. The proxies are computed in f64 (a light of
/// intensity 1e30 at 1 µm, or an area light filling the sky, overflows f32), then clamped so that
/// the sum over up to 1e20 lights stays finite and the smallest share, 1e-36, is still a normal
/// f32: no light that can contribute gets probability 0 or disables light sampling. Clamping
/// only flattens the proxy; any positive proxy keeps the estimator unbiased.
const SELECTION_WEIGHT_RANGE: (f64, f64) = (1e-18, 1e18);

/// A proxy computed in f64 as the f32 selection weight: 0 stays 0 (the light cannot contribute),
/// anything positive is clamped into [`SELECTION_WEIGHT_RANGE`].
fn selection(w: f64) -> f32 {
    if w > 0.0 {
        w.clamp(SELECTION_WEIGHT_RANGE.0, SELECTION_WEIGHT_RANGE.1) as f32
    } else {
        0.0
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::MAX_COORD_MM;
    use crate::spectrum::SpectrumTable;

    /// The largest values a scene may give (lengths [`MAX_COORD_MM`], intensity [`MAX_INTENSITY`],
    /// a point light 1 nm away) give finite positive weights, whose sum stays finite: light
    /// sampling is never switched off by one extreme light. In f32 these proxies were inf or NaN.
    #[test]
    fn extreme_but_valid_lights_keep_finite_selection_weights() {
        let hot = SpectrumTable::constant(MAX_INTENSITY);
        let (p, n) = (Vec3::ZERO, Vec3::Z);
        let lights = [
            Light::Quad(QuadLight::new(
                Vec3::new(-0.5, -0.5, 0.0) * MAX_COORD_MM - Vec3::Z,
                Vec3::X * MAX_COORD_MM,
                Vec3::Y * MAX_COORD_MM,
                hot.clone(),
            )),
            Light::Sphere(SphereLight {
                center_mm: Vec3::Z * MAX_COORD_MM,
                radius_mm: MAX_COORD_MM,
                radiance: hot.clone(),
            }),
            Light::Point(PointLight {
                position_mm: p + Vec3::Z * 1e-6,
                intensity: hot.clone(),
            }),
            Light::Distant(DistantLight {
                to_light: Vec3::Z,
                irradiance: hot.clone(),
            }),
            // And the dimmest: far, tiny and faint still gets a positive share.
            Light::Sphere(SphereLight {
                center_mm: Vec3::Z * MAX_COORD_MM,
                radius_mm: 1e-6,
                radiance: SpectrumTable::constant(1e-30),
            }),
        ];
        let env = Environment::Constant(hot);
        let mut weights: Vec<f32> = lights.iter().map(|l| l.selection_weight(p, n)).collect();
        weights.push(env.selection_weight());
        let total: f32 = weights.iter().sum();
        assert!(total.is_finite() && total > 0.0, "{weights:?}");
        assert!(
            weights.iter().all(|w| w.is_finite() && *w > 0.0),
            "{weights:?}"
        );
        assert!(weights.iter().all(|w| w / total > 0.0), "{weights:?}");
        // A light that cannot reach p keeps weight 0: behind the one-sided quad.
        let Light::Quad(q) = &lights[0] else {
            unreachable!()
        };
        assert_eq!(q.selection_weight(Vec3::NEG_Z * 2.0, n), 0.0);
    }
}
