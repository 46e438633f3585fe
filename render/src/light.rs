//! Light sources: point, spot, distant, sphere and quad area lights, and the environment
//! (constant or lat-long EXR). Emission spectra are blackbody, constant or D65, each normalised to
//! luminance Y = 1 and multiplied by the light's intensity.
//!
//! Units: positions in mm; area lights and the environment give radiance; a point or spot light
//! gives radiant intensity (radiance · mm²: irradiance = I / d² with d in mm); a distant light gives
//! the irradiance on a surface facing it. All in the relative units where Y = 1 is "white 1".

use crate::spectrum::{
    SampledSpectrum, SampledWavelengths, SpectrumTable, linear_srgb_at_nm, luminance_of,
};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI, TAU};

/// Second radiation constant c₂ = hc/k, m·K (CODATA 2018).
const PLANCK_C2_M_K: f64 = 1.438_776_877e-2;

/// Shape of an emission spectrum, before normalisation to unit luminance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EmissionShape {
    /// Planck blackbody at a temperature, K.
    Blackbody {
        /// Temperature, K.
        kelvin: f64,
    },
    /// Equal energy at every wavelength.
    Constant,
    /// CIE illuminant D65 (`skin_optics::color::d65`).
    D65,
}

impl EmissionShape {
    /// Relative spectral power at `nm` (arbitrary scale).
    #[must_use]
    pub fn relative_power(&self, nm: f64) -> f64 {
        match *self {
            // Planck's law up to constant factors: λ⁻⁵ / (exp(c₂ / λT) − 1).
            EmissionShape::Blackbody { kelvin } => {
                let lambda_m = nm * 1e-9;
                lambda_m.powi(-5) / (PLANCK_C2_M_K / (lambda_m * kelvin)).exp_m1()
            }
            EmissionShape::Constant => 1.0,
            EmissionShape::D65 => skin_optics::color::d65(nm),
        }
    }

    /// The spectrum with luminance `intensity` (Y of the tabulated spectrum = intensity).
    #[must_use]
    pub fn table(&self, intensity: f32) -> SpectrumTable {
        let y = luminance_of(|nm| self.relative_power(nm));
        SpectrumTable::from_fn(|nm| self.relative_power(nm) / y * f64::from(intensity))
    }
}

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
    Point {
        /// Position, mm.
        position_mm: Vec3,
        /// Radiant intensity spectrum.
        intensity: SpectrumTable,
    },
    /// Spot light with a smooth falloff between the inner and outer cone.
    Spot {
        /// Position, mm.
        position_mm: Vec3,
        /// Unit direction of the cone axis.
        direction: Vec3,
        /// cos of the inner (full-intensity) half angle.
        cos_inner: f32,
        /// cos of the outer (zero-intensity) half angle.
        cos_outer: f32,
        /// Radiant intensity spectrum on the axis.
        intensity: SpectrumTable,
    },
    /// Light from a single direction (the sun), irradiance on a surface facing it.
    Distant {
        /// Unit direction towards the light.
        to_light: Vec3,
        /// Irradiance spectrum.
        irradiance: SpectrumTable,
    },
    /// Spherical area light, emitting uniformly outwards.
    Sphere {
        /// Centre, mm.
        center_mm: Vec3,
        /// Radius, mm.
        radius_mm: f32,
        /// Emitted radiance spectrum.
        radiance: SpectrumTable,
    },
    /// Parallelogram area light `corner + s·edge_u + t·edge_v`, emitting on the side of
    /// `edge_u × edge_v`.
    Quad {
        /// One corner, mm.
        corner_mm: Vec3,
        /// First edge, mm.
        edge_u_mm: Vec3,
        /// Second edge, mm.
        edge_v_mm: Vec3,
        /// Emitted radiance spectrum.
        radiance: SpectrumTable,
    },
}

/// Smallest cos θ_max treated as a cone for sphere sampling (closer points sample the area).
const CONE_EPS: f32 = 1e-4;

impl Light {
    /// Sample incident light at `p` with `u` ∈ [0, 1)².
    #[must_use]
    pub fn sample(&self, p: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<LightSample> {
        match self {
            Light::Point {
                position_mm,
                intensity,
            } => {
                let d = *position_mm - p;
                let r2 = d.length_squared();
                Some(LightSample {
                    wi: d / r2.sqrt(),
                    distance_mm: r2.sqrt(),
                    li: intensity.eval(wl) / r2,
                    pdf: 1.0,
                    is_delta: true,
                })
            }
            Light::Spot {
                position_mm,
                direction,
                cos_inner,
                cos_outer,
                intensity,
            } => {
                let d = *position_mm - p;
                let r2 = d.length_squared();
                let wi = d / r2.sqrt();
                let cos = (-wi).dot(*direction);
                let x = ((cos - cos_outer) / (cos_inner - cos_outer).max(1e-6)).clamp(0.0, 1.0);
                let falloff = x * x * (3.0 - 2.0 * x);
                (falloff > 0.0).then(|| LightSample {
                    wi,
                    distance_mm: r2.sqrt(),
                    li: intensity.eval(wl) * (falloff / r2),
                    pdf: 1.0,
                    is_delta: true,
                })
            }
            Light::Distant {
                to_light,
                irradiance,
            } => Some(LightSample {
                wi: *to_light,
                distance_mm: f32::INFINITY,
                li: irradiance.eval(wl),
                pdf: 1.0,
                is_delta: true,
            }),
            Light::Sphere {
                center_mm,
                radius_mm,
                radiance,
            } => {
                let to_c = *center_mm - p;
                let d2 = to_c.length_squared();
                let sin2_max = radius_mm * radius_mm / d2;
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                if sin2_max >= 1.0 || 1.0 - cos_max < CONE_EPS {
                    return None; // inside the light or too far to matter
                }
                // Uniform direction in the cone of the visible cap ([pbrt] sphere sampling).
                let cos_t = 1.0 - u.x * (1.0 - cos_max);
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let phi = TAU * u.y;
                let frame = brdf::Frame::from_normal(to_c / d2.sqrt());
                let wi = frame.to_world(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t));
                let t = sphere_hit(p, wi, *center_mm, *radius_mm).unwrap_or(d2.sqrt());
                Some(LightSample {
                    wi,
                    distance_mm: t,
                    li: radiance.eval(wl),
                    pdf: 1.0 / (TAU * (1.0 - cos_max)),
                    is_delta: false,
                })
            }
            Light::Quad {
                corner_mm,
                edge_u_mm,
                edge_v_mm,
                radiance,
            } => {
                let q = *corner_mm + *edge_u_mm * u.x + *edge_v_mm * u.y;
                let n = edge_u_mm.cross(*edge_v_mm);
                let area = n.length();
                let d = q - p;
                let r2 = d.length_squared();
                let wi = d / r2.sqrt();
                let cos_l = -wi.dot(n / area);
                (cos_l > 0.0).then(|| LightSample {
                    wi,
                    distance_mm: r2.sqrt(),
                    li: radiance.eval(wl),
                    pdf: r2 / (cos_l * area),
                    is_delta: false,
                })
            }
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
        // cos towards a light of angular radius with sine `spread`, clamped to [0, 1].
        let facing =
            |to: Vec3, d: f32, spread: f32| (n.dot(to) / d + spread.min(1.0)).clamp(0.0, 1.0);
        match self {
            Light::Point {
                position_mm,
                intensity,
            }
            | Light::Spot {
                position_mm,
                intensity,
                ..
            } => {
                let to = *position_mm - p;
                let d2 = to.length_squared().max(1e-6);
                intensity.mean() / d2 * facing(to, d2.sqrt(), 0.0)
            }
            Light::Distant {
                irradiance,
                to_light,
            } => irradiance.mean() * facing(*to_light, 1.0, 0.0),
            Light::Sphere {
                center_mm,
                radius_mm,
                radiance,
            } => {
                let to = *center_mm - p;
                let r2 = radius_mm * radius_mm;
                let d2 = to.length_squared().max(r2);
                let d = d2.sqrt();
                radiance.mean() * PI * r2 / d2 * facing(to, d, radius_mm / d)
            }
            Light::Quad {
                corner_mm,
                edge_u_mm,
                edge_v_mm,
                radiance,
            } => {
                let nl = edge_u_mm.cross(*edge_v_mm);
                let area = nl.length();
                let nl = nl / area;
                if (p - *corner_mm).dot(nl) <= 0.0 {
                    return 0.0;
                }
                let c = *corner_mm + (*edge_u_mm + *edge_v_mm) * 0.5;
                let to = c - p;
                let d2 = to.length_squared().max(area);
                let d = d2.sqrt();
                let cos_l = (-to.dot(nl) / d).max(0.05);
                let half_diagonal = 0.5 * (*edge_u_mm + *edge_v_mm).length();
                radiance.mean() * area * cos_l / d2 * facing(to, d, half_diagonal / d)
            }
        }
    }

    /// Distance at which the ray (`o`, unit `d`) hits this light's emitting surface, if any.
    #[must_use]
    pub fn intersect(&self, o: Vec3, d: Vec3) -> Option<f32> {
        match self {
            Light::Sphere {
                center_mm,
                radius_mm,
                ..
            } => sphere_hit(o, d, *center_mm, *radius_mm),
            Light::Quad {
                corner_mm,
                edge_u_mm,
                edge_v_mm,
                ..
            } => {
                let n = edge_u_mm.cross(*edge_v_mm);
                let denom = d.dot(n);
                if denom >= 0.0 {
                    return None; // back side does not emit, and is not drawn
                }
                let t = (*corner_mm - o).dot(n) / denom;
                if t <= 0.0 {
                    return None;
                }
                let rel = o + d * t - *corner_mm;
                let (uu, vv) = (edge_u_mm.length_squared(), edge_v_mm.length_squared());
                let s = rel.dot(*edge_u_mm) / uu;
                let w = rel.dot(*edge_v_mm) / vv;
                ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&w)).then_some(t)
            }
            _ => None,
        }
    }

    /// Emitted radiance seen along a ray that hit this light (area lights only).
    #[must_use]
    pub fn radiance(&self, wl: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Light::Sphere { radiance, .. } | Light::Quad { radiance, .. } => radiance.eval(wl),
            _ => SampledSpectrum::zero(),
        }
    }

    /// Solid-angle density with which [`Light::sample`] from `p` picks direction `wi` that hits
    /// the light at distance `t` (for MIS of BSDF-sampled hits).
    #[must_use]
    pub fn pdf(&self, p: Vec3, wi: Vec3, t: f32) -> f32 {
        match self {
            Light::Sphere {
                center_mm,
                radius_mm,
                ..
            } => {
                let d2 = (*center_mm - p).length_squared();
                let sin2_max = radius_mm * radius_mm / d2;
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                if sin2_max >= 1.0 || 1.0 - cos_max < CONE_EPS {
                    0.0
                } else {
                    1.0 / (TAU * (1.0 - cos_max))
                }
            }
            Light::Quad {
                edge_u_mm,
                edge_v_mm,
                ..
            } => {
                let n = edge_u_mm.cross(*edge_v_mm);
                let area = n.length();
                let cos_l = -wi.dot(n / area);
                if cos_l <= 0.0 {
                    0.0
                } else {
                    t * t / (cos_l * area)
                }
            }
            _ => 0.0,
        }
    }
}

/// Nearest positive hit of a ray with a sphere.
fn sphere_hit(o: Vec3, d: Vec3, c: Vec3, r: f32) -> Option<f32> {
    let oc = o - c;
    let b = oc.dot(d);
    let disc = b * b - (oc.length_squared() - r * r);
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let t0 = -b - s;
    let t1 = -b + s;
    if t0 > 0.0 {
        Some(t0)
    } else if t1 > 0.0 {
        Some(t1)
    } else {
        None
    }
}

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
        match self {
            Environment::Constant(t) => PI * t.mean(),
            Environment::LatLong { map, scale } => {
                PI * scale * crate::texture::luminance(map.mean())
            }
        }
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

/// Cosine-weighted direction on the +Z hemisphere (Malley's method).
#[must_use]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = crate::camera::concentric_disk(u);
    Vec3::new(d.x, d.y, (1.0 - d.length_squared()).max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn emission_is_normalised_to_luminance() {
        for shape in [
            EmissionShape::D65,
            EmissionShape::Constant,
            EmissionShape::Blackbody { kelvin: 3000.0 },
        ] {
            let t = shape.table(2.5);
            let y = luminance_of(|nm| {
                f64::from(t.at_nm(nm as f32))
                    * if (380.0..=780.0).contains(&nm) {
                        1.0
                    } else {
                        0.0
                    }
            });
            assert!((y - 2.5).abs() < 0.01, "{shape:?}: {y}");
        }
    }

    #[test]
    fn blackbody_peaks_at_wien_wavelength() {
        // Wien: λ_max = 2.897771955e-3 m·K / T → 579.6 nm at 5000 K.
        let s = EmissionShape::Blackbody { kelvin: 5000.0 };
        let peak = (400..800)
            .max_by(|&a, &b| {
                s.relative_power(a as f64)
                    .total_cmp(&s.relative_power(b as f64))
            })
            .unwrap();
        assert!((peak - 580i32).abs() <= 1, "{peak}");
    }

    #[test]
    fn quad_sample_pdf_matches_pdf_function() {
        let wl = SampledWavelengths::sample_visible(0.3);
        let q = Light::Quad {
            corner_mm: Vec3::new(-1.0, -1.0, 5.0),
            edge_u_mm: Vec3::new(0.0, 2.0, 0.0),
            edge_v_mm: Vec3::new(2.0, 0.0, 0.0),
            radiance: SpectrumTable::constant(1.0),
        };
        let s = q.sample(Vec3::ZERO, Vec2::new(0.3, 0.8), &wl).unwrap();
        let t = q.intersect(Vec3::ZERO, s.wi).unwrap();
        assert!((t - s.distance_mm).abs() < 1e-4);
        assert!((q.pdf(Vec3::ZERO, s.wi, t) - s.pdf).abs() < 1e-4 * s.pdf);
    }
}
