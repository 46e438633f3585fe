//! Subsurface scattering for skin: the separable BSSRDF built from the multipole profiles
//! (docs/physics.md §8, [JMLH01], [DJ05], [DJ06]) and exit-point sampling with probe rays ([KHPC13]).
//!
//! - [`table`]: per material and wavelength, 2πr R(r) on a geometric grid with its CDF (f32).
//! - [`extent`]: where a profile row ends (energy left beyond it below a tolerance) and how many
//!   radii the table needs for an interpolation error target.
//! - [`sampling`]: axis choice, probe segments and the one-sample MIS density over the axes.
//! - [`separable`]: S = T(θ_o) R(r) S_ω(ω_i), the energy split with the specular layer, the texture.
//! - [`incidence`]: the gain a(θ, λ) of the total at oblique incidence that multiplies T.
//! - [`curvature`]: the first-order term 1 + κ(λ) h of a curved surface that multiplies R(r).
//! - [`azimuth`]: the lobe M(μ_i, μ_o, φ) of light leaving forward, away from an oblique light,
//!   that multiplies S_ω.
//!
//! [`Subsurface`] ties them together for a path tracer in the manner of pbrt-v4's `SampleSp` →
//! intersect → `ProbeIntersectionToSample`: [`Subsurface::sample_probe`] says which segment to
//! intersect; the integrator keeps every hit on the entry point's material along it, picks one
//! uniformly, and [`Subsurface::exit_at`] returns the spatial weight R(r) · N / pdf per wavelength
//! (N the hit count), with spectral MIS (one-sample balance heuristic over the path's wavelengths,
//! [Wilkie et al. 2014], pbrt-v4): each wavelength's density is computed with its own profile, the
//! radius's wavelength is chosen mostly by the lanes' shares of the luminance
//! ([`RadiusWavelength`]) and the weight divides by the mixture of the lanes' densities with those
//! probabilities. This module traces no ray.
//!
//! # Where probes find no surface
//! On a flat surface only normal-axis probes find points (the tangent probes' MIS density there
//! is 0), so a tangent probe that misses loses nothing. A *normal-axis* probe that finds no surface
//! of the material means the planar profile's energy at (r, φ) has no surface to leave from (an
//! edge, a thin curved rim). That energy is not dropped: the sample leaves at the entry point
//! itself with the planar weight R(r) / (P_normal · pdf_area(r)) (the local diffuse fallback), so a
//! finite piece of skin still returns its total R_tot locally.
//!
//! The fallback returns only energy the probes cannot reach elsewhere. A missed normal probe says
//! the surface does not pass *under the planar point* (r, φ), not that no surface lies at distance
//! r: on a sphere of radius R smaller than the profile the normal probes miss beyond planar radius
//! R (the sphere's shadow on its tangent plane), yet the probes find the sphere's points out to
//! chord distance 2R, and over a sphere dA = 2πd dd (Archimedes' hat-box theorem), so they already
//! return R_tot F(2R) (F the profile's energy fraction within a radius); a fallback on every miss
//! would add R_tot (1 − F(R)) and count the band R < r < 2R twice. So on a miss the fallback first traces the quarter circle of radius r
//! from the planar point down to p_o − r n (in the plane of n and the probe's azimuth, as
//! [`ARC_SEGMENTS`] chords, same end points): when it crosses the material, skin lies at distance r
//! and the probes account for that energy; the fallback fires only when it does not. On the
//! sphere that is exactly r > 2R (total R_tot; `render/tests/subsurface.rs`), on a flat patch
//! every miss (its total stays R_tot). These totals are the planar model's; the curvature term
//! ([`curvature`]) multiplies each found exit by 1 + κ h on top. Thin geometry needs nothing special: the normal probe
//! crosses it and finds the far side, so backlit ears transmit (red) light.

pub mod azimuth;
pub mod curvature;
pub mod extent;
pub mod grid;
pub mod incidence;
pub mod incidence_grid;
pub mod sampling;
pub mod separable;
pub mod table;

pub use azimuth::{Azimuth, AzimuthOptions, AzimuthalLobe};
pub use curvature::{Curvature, CurvatureGain};
pub use grid::{Corners, ProfileGrid};
pub use incidence::{Incidence, IncidenceGain};
pub use incidence_grid::{AngularFactor, GainCorners, IncidenceGrid};
pub use sampling::{Probe, ProbeAxes, ProbeFrame, RadiusWavelength, pdf_exit, probe};
pub use separable::{Directional, EnergySplit, texture_modulation};
pub use table::{ProfileTable, RENDER_SHAPE_STEP_NM, RowPlace, RowsAt, TableOptions, TableRadius};

use crate::geometry::SurfaceHit;
use crate::spectrum::{N_WAVELENGTHS, SampledSpectrum, SampledWavelengths};
use glam::Vec3;
use std::sync::Arc;

/// Most hits kept along one probe segment (more are ignored: only very folded geometry has them).
pub const MAX_PROBE_HITS: usize = 32;

/// Chords of the quarter circle a missed normal probe traces before the local fallback (module
/// doc, "Where probes find no surface"). Its end points are exact, so a closed surface that
/// separates them is always found; the chords stray inside the arc by at most
/// r (1 − cos(π / 32)) ≈ 0.5% of r.
pub const ARC_SEGMENTS: usize = 8;

/// The profile table resolved at a path's wavelengths, one entry per lane.
type Lanes<'a> = [Option<RowsAt<'a>>; N_WAVELENGTHS];

/// Most of the radii the wide profile draws where a skin samples from a narrower one (the
/// `wide` table of [`Subsurface::sample_probe`]): light entering far from a strongly absorbing
/// exit otherwise comes with weights up to the two profiles' ratio (700× across the split slab
/// of `the_geometric_rule_is_reciprocal_on_the_split_slab`, whose far side reads 1.7σ from 0 with
/// no share, 2σ with 0.1 and 3σ with 0.25). The share itself is [`wide_share`].
pub const WIDE_SHARE: f32 = 0.5;

/// The share of the radii a wide profile of luminance-weighted total `wide_total` draws beside
/// an own profile of `own_total` under the geometric rule (docs/physics.md §19.3): light that
/// entered in the wide profile's skin follows √(R_own R_wide), of energy about
/// √(R̄_own R̄_wide), and the share is the part of it the own profile lacks,
/// 1 − √(R̄_own / R̄_wide), at most [`WIDE_SHARE`]. Where the two skins differ little the wide
/// profile has little to defend against and would only spend samples at radii the own profile
/// already covers.
#[must_use]
pub fn wide_share(own_total: f32, wide_total: f32) -> f32 {
    if wide_total > 0.0 && own_total >= 0.0 {
        (1.0 - (own_total / wide_total).sqrt()).clamp(0.0, WIDE_SHARE)
    } else {
        WIDE_SHARE
    }
}

/// The largest f32 below 1: a uniform rescaled from part of [0, 1) stays below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// The subsurface model of one skin material.
#[derive(Debug, Clone)]
pub struct Subsurface {
    /// Radial profiles per wavelength.
    pub table: Arc<ProfileTable>,
    /// T(θ) and S_ω.
    pub directional: Directional,
    /// The curvature term's κ(λ) (`None`: the planar profile, [`Curvature::Planar`]).
    pub curvature: Option<CurvatureGain>,
    /// The azimuthal lobe (`None`: the separable form alone, [`Azimuth::Separable`]).
    pub azimuth: Option<Arc<AzimuthalLobe>>,
}

/// Where a subsurface path leaves the skin toward the entry point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exit {
    /// Point, mm.
    pub p: Vec3,
    /// Outward geometric normal (same side convention as the entry's).
    pub ng: Vec3,
    /// Outward shading normal.
    pub ns: Vec3,
    /// The surface hit (None for the local fallback at the entry point).
    pub hit: Option<SurfaceHit>,
    /// Spatial weight per wavelength, R(r) · N / pdf (dimensionless: mm⁻² / mm⁻²).
    pub weight: SampledSpectrum,
    /// The spatial weight per unit of the profile R(r): N / pdf, times the curvature term where
    /// the model has one, per wavelength (mm²); a skin with maps multiplies its own R(r) by it.
    pub per_profile: SampledSpectrum,
    /// The distance r the weight's R(r) was read at, mm (the probe's radius for the local
    /// fallback).
    pub r_mm: f32,
}

/// A sampled probe: the segment to intersect, and the lanes' densities that weight what it finds.
#[derive(Debug, Clone, Copy)]
pub struct ProbeSample<'a> {
    /// The segment, its axis and its sampled radius.
    pub segment: Probe,
    lanes: Lanes<'a>,
    c: [f32; N_WAVELENGTHS],
    /// The wide profile, its lanes and lane probabilities, when it draws part of the radii.
    wide: Option<(&'a ProfileTable, Lanes<'a>, [f32; N_WAVELENGTHS])>,
    /// The share of the radii the wide profile draws ([`wide_share`]).
    share: f32,
    /// Each lane's curvature κ, mm⁻¹ (0 without the curvature term).
    kappa: [f32; N_WAVELENGTHS],
}

impl ProbeSample<'_> {
    /// The quarter circle of radius r from the probe's planar point down to p_o − r n (around the
    /// entry point `p_o` with outward normal `n`, in the plane of n and the probe's azimuth), as
    /// [`ARC_SEGMENTS`] chords (origin, unit direction, length in mm): skin crossing it lies at
    /// distance r in that azimuth, where the probes find its energy (module doc).
    pub fn arc_chords(&self, p_o: Vec3, n: Vec3) -> impl Iterator<Item = (Vec3, Vec3, f32)> {
        let pr = &self.segment;
        let planar = pr.origin + pr.dir * (0.5 * pr.length) - p_o;
        let r = planar.length();
        let chords = if r.is_nan() || r <= 0.0 {
            0
        } else {
            ARC_SEGMENTS
        };
        let t = planar / r;
        let point = move |k: usize| {
            let beta = std::f32::consts::FRAC_PI_2 * k as f32 / ARC_SEGMENTS as f32;
            p_o + (t * beta.cos() - n * beta.sin()) * r
        };
        (0..chords).map(move |k| {
            let (a, b) = (point(k), point(k + 1));
            let len = (b - a).length();
            (a, (b - a) / len, len)
        })
    }
}

impl Subsurface {
    /// The model for a profile table and the directional term.
    #[must_use]
    pub fn new(table: Arc<ProfileTable>, directional: Directional) -> Self {
        Self {
            table,
            directional,
            curvature: None,
            azimuth: None,
        }
    }

    /// The same model with the azimuthal lobe `lobe` (docs/physics.md §8.3).
    #[must_use]
    pub fn with_azimuth(mut self, lobe: Arc<AzimuthalLobe>) -> Self {
        self.azimuth = Some(lobe);
        self
    }

    /// The same model with the first-order curvature term of `gain` (docs/physics.md §8.2).
    #[must_use]
    pub fn with_curvature(mut self, gain: CurvatureGain) -> Self {
        self.curvature = Some(gain);
        self
    }

    /// The table resolved at each active lane's wavelength (`None` for a terminated lane).
    fn lanes(&self, wl: &SampledWavelengths) -> Lanes<'_> {
        std::array::from_fn(|k| (wl.pdf()[k] > 0.0).then(|| self.table.at_lane(wl, k)))
    }

    /// The lane probabilities of the radius wavelength under `radius` (luminance weight
    /// ȳ/p · R_tot per active lane).
    fn lane_probabilities(
        wl: &SampledWavelengths,
        lanes: &Lanes<'_>,
        radius: RadiusWavelength,
    ) -> [f32; N_WAVELENGTHS] {
        let y = wl.luminance_weights();
        radius.probabilities(std::array::from_fn(|k| {
            y[k].zip(lanes[k]).map(|(w, at)| w * at.total())
        }))
    }

    /// The planar density of radius `r_mm` under `probe`'s strategies, mm⁻²: the lanes' mixture
    /// of the table, mixed with the wide profile's where it draws part of the radii.
    fn density(&self, probe: &ProbeSample<'_>, r_mm: f32) -> f32 {
        let radius = TableRadius::new(r_mm);
        let own = Self::mixture(&self.table, &probe.lanes, &probe.c, radius);
        match &probe.wide {
            Some((wide, lanes, c)) if probe.share > 0.0 => {
                (1.0 - probe.share) * own + probe.share * Self::mixture(wide, lanes, c, radius)
            }
            _ => own,
        }
    }

    /// Σ_j c_j pdf_area_j(r): the mixture of `table`'s lanes' planar densities at `radius`, mm⁻²
    /// (spectral MIS).
    fn mixture(
        table: &ProfileTable,
        lanes: &Lanes<'_>,
        c: &[f32; N_WAVELENGTHS],
        radius: TableRadius,
    ) -> f32 {
        let r = table.eval_each_at(lanes, radius);
        (0..N_WAVELENGTHS)
            .filter_map(|k| {
                let total = lanes[k]?.total();
                (c[k] > 0.0 && total > 0.0).then(|| c[k] * r[k] / total)
            })
            .sum()
    }

    /// The spatial weight R_k(r_mm) · `scale` per active lane.
    fn weight(&self, lanes: &Lanes<'_>, r_mm: f32, scale: f32) -> SampledSpectrum {
        SampledSpectrum(self.table.eval_each(lanes, r_mm).map(|r| r * scale))
    }

    /// Sample the probe segment for light that leaves at `p_o` (outward frame `frame`), from
    /// three uniforms (axis and radius wavelength, radius, azimuth), choosing probe axes by `axes`
    /// and the radius's wavelength by `radius`; with `wide`, that wider profile draws the share
    /// [`wide_share`] of the radii: a defensive mixture ([Hes95], docs/physics.md §19.3), so that
    /// no weight exceeds 1 / share times what the wide profile alone would give. The
    /// integrator intersects the segment with the entry point's material and hands what it found
    /// to [`Subsurface::exit_at`]; a normal probe that found nothing goes to
    /// [`Subsurface::local_exit`] unless the material crosses [`ProbeSample::arc_chords`] (module
    /// doc). None when the radius's wavelength has no profile.
    #[must_use]
    #[allow(clippy::too_many_arguments)] // the probe's frame, its choices and the random state
    pub fn sample_probe<'a>(
        &'a self,
        wide: Option<&'a ProfileTable>,
        frame: &ProbeFrame,
        p_o: Vec3,
        axes: &ProbeAxes,
        radius: RadiusWavelength,
        wl: &SampledWavelengths,
        u: [f32; 3],
    ) -> Option<ProbeSample<'a>> {
        let (axis, u_lane) = axes.choose(u[0]);
        let lanes = self.lanes(wl);
        let c = Self::lane_probabilities(wl, &lanes, radius);
        let wide = wide.map(|t| {
            let lanes: Lanes<'_> =
                std::array::from_fn(|k| (wl.pdf()[k] > 0.0).then(|| t.at_lane(wl, k)));
            let c = Self::lane_probabilities(wl, &lanes, radius);
            (t, lanes, c)
        });
        // The wide profile's share of the radii, from the luminance-weighted totals at the
        // path's wavelengths (the radius uniform split in two keeps its stratification).
        let share = wide.as_ref().map_or(0.0, |(_, wide_lanes, _)| {
            let y = wl.luminance_weights();
            let (mut own_total, mut wide_total) = (0.0, 0.0);
            for k in 0..N_WAVELENGTHS {
                if let (Some(y), Some(o), Some(w)) = (y[k], lanes[k], wide_lanes[k]) {
                    own_total += y * o.total();
                    wide_total += y * w.total();
                }
            }
            wide_share(own_total, wide_total)
        });
        let own = 1.0 - share;
        let (table, strategy_c, u_radius) = match &wide {
            Some((t, _, wc)) if share > 0.0 && u[1] >= own => {
                (*t, wc, ((u[1] - own) / share).min(ONE_MINUS_EPSILON))
            }
            Some(_) if share > 0.0 => (&*self.table, &c, (u[1] / own).min(ONE_MINUS_EPSILON)),
            _ => (&*self.table, &c, u[1]),
        };
        // The uniform choice keeps the hero (lane 0), which is already uniform over the lanes.
        let lane = if radius == RadiusWavelength::HERO {
            0
        } else {
            RadiusWavelength::choose(strategy_c, u_lane)
        };
        let hero = wl.nm(lane);
        // The probe's sphere reaches as far as either strategy's radii.
        let r_max = match &wide {
            Some((t, ..)) if share > 0.0 => self.table.r_max_mm(hero).max(t.r_max_mm(hero)),
            _ => self.table.r_max_mm(hero),
        };
        let r = table.sample_radius(hero, u_radius);
        if r_max.is_nan() || r_max <= 0.0 {
            return None;
        }
        let kappa = self.curvature.as_ref().map_or([0.0; N_WAVELENGTHS], |g| {
            std::array::from_fn(|k| {
                if lanes[k].is_some() {
                    g.kappa_per_mm(wl.nm(k))
                } else {
                    0.0
                }
            })
        });
        Some(ProbeSample {
            segment: probe(frame, p_o, axis, r, r_max, u[2]),
            lanes,
            c,
            wide,
            share,
            kappa,
        })
    }

    /// The exit at `s`, one of `hits` distinct points of the material found along `probe`'s
    /// segment from `p_o` (frame `frame`, axes `axes`) and picked uniformly: the spatial weight
    /// R(r) · hits / pdf per wavelength, times the curvature term 1 + κ h where the model has
    /// one ([`curvature`]; h from the entry's normal and the exit's shading normal). `flipped` tells that the entry frame faces against the
    /// mesh's vertex normals (a viewer inside the mesh), so the exit normals are flipped alike.
    /// None when the point's density is 0 or not a number.
    #[must_use]
    pub fn exit_at(
        &self,
        probe: &ProbeSample<'_>,
        (p_o, frame, axes): (Vec3, &ProbeFrame, &ProbeAxes),
        s: SurfaceHit,
        hits: usize,
        flipped: bool,
    ) -> Option<Exit> {
        // Outward normals: the vertex normals' side, flipped when the entry frame was.
        let (ng, ns) = if flipped {
            (-s.ng, -s.ns)
        } else {
            (s.ng, s.ns)
        };
        let dist = (s.p - p_o).length();
        let pdf = pdf_exit(axes, frame, p_o, s.p, ng, |ra| self.density(probe, ra));
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        let mut per_profile = SampledSpectrum::splat(hits as f32 / pdf);
        if self.curvature.is_some()
            && let Some(h) = curvature::depth_below_tangent_mm(p_o, frame.n, s.p, ns)
        {
            for (w, &k) in per_profile.0.iter_mut().zip(&probe.kappa) {
                *w *= curvature::factor(k, h);
            }
        }
        Some(Exit {
            p: s.p,
            ng,
            ns,
            hit: Some(s),
            weight: self.weight(&probe.lanes, dist, 1.0) * per_profile,
            per_profile,
            r_mm: dist,
        })
    }

    /// The normal probe `probe` found no surface of the material and none lies on its arc: the
    /// planar energy of (r, φ) leaves at the entry point `p_o` (module doc).
    #[must_use]
    pub fn local_exit(
        &self,
        probe: &ProbeSample<'_>,
        (p_o, frame, axes): (Vec3, &ProbeFrame, &ProbeAxes),
    ) -> Exit {
        let r = probe.segment.r_mm;
        let pdf = axes.p_normal() * self.density(probe, r);
        let per_profile = SampledSpectrum::splat(if pdf > 0.0 { 1.0 / pdf } else { 0.0 });
        Exit {
            p: p_o,
            ng: frame.n,
            ns: frame.n,
            hit: None,
            weight: self.weight(&probe.lanes, r, 1.0) * per_profile,
            per_profile,
            r_mm: r,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The wide profile's share: none where it is the own profile, half where the own profile
    /// holds at most a quarter of its energy, the combined profile's energy the own profile lacks
    /// in between, and half where the totals give no answer.
    #[test]
    fn wide_share_follows_the_energy_the_own_profile_lacks() {
        assert_eq!(wide_share(0.4, 0.4), 0.0);
        assert_eq!(wide_share(0.5, 0.4), 0.0);
        assert!((wide_share(0.36, 0.64) - 0.25).abs() < 1e-6);
        assert_eq!(wide_share(0.1, 0.4), WIDE_SHARE);
        assert_eq!(wide_share(0.1, 0.0), WIDE_SHARE);
        assert_eq!(wide_share(f32::NAN, 0.4), WIDE_SHARE);
    }
}
