//! Area lights, which rays can hit and BSDF sampling can find (MIS with light sampling): the
//! sphere and the one-sided parallelogram (quad).

use super::{LightSample, facing, selection};
use crate::sampling::{uniform_cone, uniform_cone_pdf};
use crate::spectrum::{SampledWavelengths, SpectrumTable};
use glam::{DVec3, Vec2, Vec3};

/// Spherical area light, emitting uniformly outwards.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereLight {
    /// Centre, mm.
    pub center_mm: Vec3,
    /// Radius, mm.
    pub radius_mm: f32,
    /// Emitted radiance spectrum.
    pub radiance: SpectrumTable,
}

impl SphereLight {
    /// 1 − cos θ_max of the visible cap seen from `p` (sin²θ_max / (1 + cos θ_max): no
    /// cancellation however small the cap), or None inside the light. Every cap a ray can hit is
    /// sampled: a far, bright light subtends little but can outshine the rest of the scene, and a
    /// cap left to BSDF sampling alone lights a pixel in a few of its paths at thousands of times
    /// the mean (the white speckles of a backlit scene's far backdrop).
    fn cone(&self, p: Vec3) -> Option<f32> {
        let d2 = f64::from((self.center_mm - p).length_squared());
        let sin2_max = f64::from(self.radius_mm).powi(2) / d2;
        let one_minus_cos = sin2_max / (1.0 + (1.0 - sin2_max).max(0.0).sqrt());
        (sin2_max < 1.0 && one_minus_cos > 0.0).then_some(one_minus_cos as f32)
    }

    /// A direction uniform in the cone of the visible cap ([pbrt] sphere sampling).
    #[must_use]
    pub fn sample(&self, p: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<LightSample> {
        let to_c = self.center_mm - p;
        let d2 = to_c.length_squared();
        let one_minus_cos_max = self.cone(p)?;
        let frame = brdf::Frame::from_normal(to_c / d2.sqrt());
        let wi = frame.to_world(uniform_cone(u, one_minus_cos_max));
        let t = self.intersect(p, wi).unwrap_or(d2.sqrt());
        Some(LightSample {
            wi,
            distance_mm: t,
            li: self.radiance.eval(wl),
            pdf: uniform_cone_pdf(one_minus_cos_max),
            is_delta: false,
        })
    }

    /// Selection proxy at `p` with normal `n`: L · solid angle, times the widened cosine.
    #[must_use]
    pub fn selection_weight(&self, p: Vec3, n: Vec3) -> f32 {
        let to = (self.center_mm - p).as_dvec3();
        let r = f64::from(self.radius_mm);
        let d = to.length().max(r);
        let l = f64::from(self.radiance.mean());
        selection(l * std::f64::consts::PI * (r / d).powi(2) * facing(n, to, d, r / d))
    }

    /// Nearest positive hit of the ray (`o`, unit `d`) with the sphere.
    #[must_use]
    pub fn intersect(&self, o: Vec3, d: Vec3) -> Option<f32> {
        let oc = o - self.center_mm;
        let b = oc.dot(d);
        let disc = b * b - (oc.length_squared() - self.radius_mm * self.radius_mm);
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

    /// Solid-angle density of [`SphereLight::sample`] from `p`, sr⁻¹.
    #[must_use]
    pub fn pdf(&self, p: Vec3) -> f32 {
        self.cone(p).map_or(0.0, uniform_cone_pdf)
    }
}

/// Parallelogram area light `corner + s·edge_u + t·edge_v`, emitting on the side of
/// `edge_u × edge_v`.
#[derive(Debug, Clone, PartialEq)]
pub struct QuadLight {
    /// One corner, mm.
    pub corner_mm: Vec3,
    /// First edge, mm.
    pub edge_u_mm: Vec3,
    /// Second edge, mm.
    pub edge_v_mm: Vec3,
    /// Emitted radiance spectrum.
    pub radiance: SpectrumTable,
    /// What every query derives from the edges, found once.
    shape: QuadShape,
}

/// A quad's normal, area and centre, which sampling, intersection and light selection read at
/// every shading point and ray (f32 for the rays, f64 for the selection proxy).
#[derive(Debug, Clone, PartialEq)]
struct QuadShape {
    /// edge_u × edge_v, mm², and its length (the area), mm².
    n: Vec3,
    area: f32,
    /// |edge_u|², |edge_v|², mm².
    uu: f32,
    vv: f32,
    /// The unit normal, the area (mm²), the corner and the centre (mm) and half the diagonal
    /// (mm), in f64.
    unit_n64: DVec3,
    area64: f64,
    corner64: DVec3,
    centre64: DVec3,
    half_diagonal64: f64,
}

impl QuadLight {
    /// The quad `corner_mm + s·edge_u_mm + t·edge_v_mm` (s, t in [0, 1]) emitting `radiance` on
    /// the side of `edge_u_mm × edge_v_mm`.
    #[must_use]
    pub fn new(corner_mm: Vec3, edge_u_mm: Vec3, edge_v_mm: Vec3, radiance: SpectrumTable) -> Self {
        let n = edge_u_mm.cross(edge_v_mm);
        let (eu, ev) = (edge_u_mm.as_dvec3(), edge_v_mm.as_dvec3());
        let corner64 = corner_mm.as_dvec3();
        let n64 = eu.cross(ev);
        let area64 = n64.length();
        Self {
            corner_mm,
            edge_u_mm,
            edge_v_mm,
            radiance,
            shape: QuadShape {
                n,
                area: n.length(),
                uu: edge_u_mm.length_squared(),
                vv: edge_v_mm.length_squared(),
                unit_n64: n64 / area64,
                area64,
                corner64,
                centre64: corner64 + (eu + ev) * 0.5,
                half_diagonal64: 0.5 * (eu + ev).length(),
            },
        }
    }

    /// A point uniform in area, converted to solid angle (None from behind).
    #[must_use]
    pub fn sample(&self, p: Vec3, u: Vec2, wl: &SampledWavelengths) -> Option<LightSample> {
        let q = self.corner_mm + self.edge_u_mm * u.x + self.edge_v_mm * u.y;
        let (n, area) = (self.shape.n, self.shape.area);
        let d = q - p;
        let r2 = d.length_squared();
        let wi = d / r2.sqrt();
        let cos_l = -wi.dot(n / area);
        (cos_l > 0.0).then(|| LightSample {
            wi,
            distance_mm: r2.sqrt(),
            li: self.radiance.eval(wl),
            pdf: r2 / (cos_l * area),
            is_delta: false,
        })
    }

    /// Selection proxy at `p` with normal `n`: L · (projected) solid angle of the quad, times the
    /// widened cosine; 0 behind the emitting side.
    #[must_use]
    pub fn selection_weight(&self, p: Vec3, n: Vec3) -> f32 {
        let s = &self.shape;
        let (nl, area) = (s.unit_n64, s.area64);
        let p = p.as_dvec3();
        if (p - s.corner64).dot(nl) <= 0.0 {
            return 0.0;
        }
        let to = s.centre64 - p;
        let d2 = to.length_squared().max(area);
        let d = d2.sqrt();
        let cos_l = (-to.dot(nl) / d).max(0.05);
        let half_diagonal = s.half_diagonal64;
        let l = f64::from(self.radiance.mean());
        selection(l * area * cos_l / d2 * facing(n, to, d, half_diagonal / d))
    }

    /// Distance at which the ray (`o`, unit `d`) hits the emitting side, if it does.
    #[must_use]
    pub fn intersect(&self, o: Vec3, d: Vec3) -> Option<f32> {
        let (eu, ev) = (self.edge_u_mm, self.edge_v_mm);
        let n = self.shape.n;
        let denom = d.dot(n);
        if denom >= 0.0 {
            return None; // back side does not emit, and is not drawn
        }
        let t = (self.corner_mm - o).dot(n) / denom;
        if t <= 0.0 {
            return None;
        }
        let rel = o + d * t - self.corner_mm;
        let (uu, vv) = (self.shape.uu, self.shape.vv);
        let s = rel.dot(eu) / uu;
        let w = rel.dot(ev) / vv;
        ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&w)).then_some(t)
    }

    /// Solid-angle density of [`QuadLight::sample`] for direction `wi` hitting at distance `t`, sr⁻¹.
    #[must_use]
    pub fn pdf(&self, wi: Vec3, t: f32) -> f32 {
        let (n, area) = (self.shape.n, self.shape.area);
        let cos_l = -wi.dot(n / area);
        if cos_l <= 0.0 {
            0.0
        } else {
            t * t / (cos_l * area)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_sample_pdf_matches_pdf_function() {
        let wl = SampledWavelengths::sample_visible(0.3);
        let q = QuadLight::new(
            Vec3::new(-1.0, -1.0, 5.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            SpectrumTable::constant(1.0),
        );
        let s = q.sample(Vec3::ZERO, Vec2::new(0.3, 0.8), &wl).unwrap();
        let t = q.intersect(Vec3::ZERO, s.wi).unwrap();
        assert!((t - s.distance_mm).abs() < 1e-4);
        assert!((q.pdf(s.wi, t) - s.pdf).abs() < 1e-4 * s.pdf);
    }

    /// A sphere light of radius 25 mm seen from 0.1 to 10 m (the backlit ear's light from its
    /// backdrop, 1.6–1.9 m away, subtends 1 − cos θ_max ≈ 10⁻⁴): every one is sampled, every sampled
    /// direction hits the sphere, and the density is 1 / (2π (1 − cos θ_max)) with 1 − cos θ_max
    /// from the f64 closed form 1 − √(1 − (R/d)²) (f32 rounding of the cap: 10⁻⁴ relative at most,
    /// tolerance 10⁻³). A light left unsampled puts its whole light in the rare BSDF hits.
    #[test]
    fn far_sphere_lights_are_sampled_with_their_cone_density() {
        let wl = SampledWavelengths::sample_visible(0.3);
        let light = SphereLight {
            center_mm: Vec3::new(-110.0, 60.0, -220.0),
            radius_mm: 25.0,
            radiance: SpectrumTable::constant(400.0),
        };
        for d_mm in [100.0f32, 1600.0, 1900.0, 10_000.0] {
            let p = light.center_mm + Vec3::new(0.6, -0.48, 0.64) * d_mm;
            let r = f64::from(light.radius_mm) / f64::from(d_mm);
            let one_minus_cos = 1.0 - (1.0 - r * r).sqrt();
            let expected = 1.0 / (std::f64::consts::TAU * one_minus_cos);
            for (a, b) in [(0.0, 0.0), (0.5, 0.25), (0.999, 0.7), (0.2, 0.9)] {
                let s = light
                    .sample(p, Vec2::new(a, b), &wl)
                    .unwrap_or_else(|| panic!("no sample at {d_mm} mm"));
                assert!(
                    (f64::from(s.pdf) / expected - 1.0).abs() < 1e-3,
                    "{d_mm} mm: pdf {} against {expected}",
                    s.pdf
                );
                assert!((f64::from(light.pdf(p)) / expected - 1.0).abs() < 1e-3);
                assert!(
                    light.intersect(p, s.wi).is_some(),
                    "{d_mm} mm: sample {:?} misses",
                    s.wi
                );
            }
        }
    }
}
