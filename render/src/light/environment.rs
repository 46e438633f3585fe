//! Light from infinitely far away: a constant radiance or a lat-long (equirectangular) EXR map,
//! sampled by the cosine around the shading normal.

use super::{LightSample, selection};
use crate::sampling::cosine_hemisphere;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, SpectrumTable, linear_srgb_at_nm};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI, TAU};

/// Light arriving from infinitely far away along rays that leave the scene.
#[derive(Debug, Clone, PartialEq)]
pub enum Environment {
    /// The same radiance from every direction.
    Constant(SpectrumTable),
    /// A lat-long (equirectangular) linear-sRGB map times a scale; +Y is up, the map's centre
    /// column looks towards −Z.
    LatLong {
        /// The map.
        map: Texture,
        /// Radiance multiplier.
        scale: f32,
    },
}

impl Environment {
    /// Radiance arriving from direction `−d` (i.e. seen along a ray leaving in direction `d`).
    #[must_use]
    pub fn radiance(&self, d: Vec3, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Environment::Constant(t) => t.eval(wl),
            Environment::LatLong { map, scale } => {
                let u = 0.5 + d.x.atan2(-d.z) / TAU;
                let v = d.y.clamp(-1.0, 1.0).acos() / PI;
                let rgb = map.lookup(Vec2::new(u, v));
                SampledSpectrum(wl.all_nm().map(|nm| linear_srgb_at_nm(rgb, nm) * scale))
            }
        }
    }

    /// Rough irradiance from the environment (luminance units), for choosing what to sample.
    #[must_use]
    pub fn selection_weight(&self) -> f32 {
        let irradiance = match self {
            Environment::Constant(t) => f64::from(t.mean()),
            Environment::LatLong { map, scale } => {
                f64::from(*scale) * f64::from(crate::texture::luminance(map.mean()))
            }
        };
        selection(std::f64::consts::PI * irradiance)
    }

    /// Sample a direction around the shading normal `n` with density cos θ / π (the environment
    /// is sampled by the cosine, not by its brightness: good for constant and soft maps).
    #[must_use]
    pub fn sample(&self, n: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<LightSample> {
        let local = cosine_hemisphere(u);
        if local.z <= 0.0 {
            return None;
        }
        let wi = brdf::Frame::from_normal(n).to_world(local);
        Some(LightSample {
            wi,
            distance_mm: f32::INFINITY,
            li: self.radiance(wi, wl),
            pdf: local.z * FRAC_1_PI,
            is_delta: false,
        })
    }

    /// Density of [`Environment::sample`] at `wi` for shading normal `n`, sr⁻¹.
    #[must_use]
    pub fn pdf(&self, n: Vec3, wi: Vec3) -> f32 {
        n.dot(wi).max(0.0) * FRAC_1_PI
    }
}
