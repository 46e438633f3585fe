//! Subsurface scattering for skin: the separable BSSRDF built from the multipole profiles
//! (docs/physics.md §8, [JMLH01], [DJ05], [DJ06]) and exit-point sampling with probe rays ([KHPC13]).
//!
//! - [`table`]: per material and wavelength, 2πr R(r) on a geometric grid with its CDF (f32).
//! - [`sampling`]: axis choice, probe segments and the one-sample MIS density over the axes.
//! - [`separable`]: S = T(θ_o) R(r) S_ω(ω_i), the energy split with the specular layer, the texture.
//!
//! [`Subsurface::sample_exit`] ties them together for the path tracer: it probes the scene's BVH,
//! keeps every hit on the entry point's material along the segment, picks one uniformly (and
//! multiplies by the hit count) and returns the spatial weight R(r) · N / pdf per wavelength, with
//! spectral MIS (one-sample balance heuristic over the path's wavelengths, [Wilkie et al. 2014],
//! pbrt-v4): each wavelength's density is computed with its own profile, the radius's wavelength is
//! chosen mostly by the lanes' shares of the luminance ([`RadiusWavelength`]) and the weight
//! divides by the mixture of the lanes' densities with those probabilities.
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
//! return R_tot F(2R) (F the profile's energy fraction within a radius). A fallback on every miss
//! added R_tot (1 − F(R)) and counted the band R < r < 2R twice (light skin at R = 2 mm: 5–6%
//! brighter in X and Y). So on a miss the fallback first traces the quarter circle of radius r
//! from the planar point down to p_o − r n (in the plane of n and the probe's azimuth, as
//! [`ARC_SEGMENTS`] chords, same end points): when it crosses the material, skin lies at distance r
//! and the probes account for that energy; the fallback fires only when it does not. On the
//! sphere that is exactly r > 2R (total R_tot; `render/tests/subsurface.rs`), on a flat patch
//! every miss (its total stays R_tot). Thin geometry needs nothing special: the normal probe
//! crosses it and finds the far side, so backlit ears transmit (red) light.

pub mod sampling;
pub mod separable;
pub mod table;

pub use sampling::{ProbeAxes, ProbeFrame, RadiusWavelength, pdf_exit, probe};
pub use separable::{Directional, EnergySplit, texture_modulation};
pub use table::{ProfileTable, RENDER_SHAPE_ESCAPES, RENDER_SHAPE_STEP_NM, RowsAt, TableOptions};

use crate::accel::ray;
use crate::geometry::{Geometry, SurfaceHit};
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

/// The subsurface model of one skin material.
#[derive(Debug, Clone)]
pub struct Subsurface {
    /// Radial profiles per wavelength.
    pub table: Arc<ProfileTable>,
    /// T(θ) and S_ω.
    pub directional: Directional,
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
}

impl Subsurface {
    /// The model for a profile table and the directional term.
    #[must_use]
    pub fn new(table: Arc<ProfileTable>, directional: Directional) -> Self {
        Self { table, directional }
    }

    /// The table resolved at each active lane's wavelength (`None` for a terminated lane).
    fn lanes(&self, wl: &SampledWavelengths) -> Lanes<'_> {
        std::array::from_fn(|k| (wl.pdf()[k] > 0.0).then(|| self.table.at(wl.nm(k))))
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

    /// Σ_j c_j pdf_area_j(r_mm): the mixture of the lanes' planar densities, mm⁻² (spectral MIS).
    fn mixture(&self, lanes: &Lanes<'_>, c: &[f32; N_WAVELENGTHS], r_mm: f32) -> f32 {
        let r = self.table.eval_each(lanes, r_mm);
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

    /// Sample where light that leaves at `p_o` (outward frame `frame`, on material `material`)
    /// entered, from four uniforms, choosing probe axes by `axes` and the radius's wavelength by
    /// `radius`; `flipped` tells that the entry frame faces against the mesh's
    /// vertex normals (a viewer inside the mesh), so exit normals are flipped alike; `rays` counts
    /// probe rays. None when the probe found nothing
    /// usable (a tangent probe missing is expected and unbiased, see the module doc).
    #[must_use]
    #[allow(clippy::too_many_arguments)] // the probe needs all of them; a struct would only rename them
    pub fn sample_exit(
        &self,
        geometry: &Geometry,
        material: u32,
        p_o: Vec3,
        frame: &ProbeFrame,
        axes: &ProbeAxes,
        radius: RadiusWavelength,
        flipped: bool,
        wl: &SampledWavelengths,
        u: [f32; 4],
        rays: &mut u64,
    ) -> Option<Exit> {
        let (axis, u_lane) = axes.choose(u[0]);
        let lanes = self.lanes(wl);
        let c = Self::lane_probabilities(wl, &lanes, radius);
        // The uniform choice keeps the hero (lane 0), which is already uniform over the lanes.
        let lane = if radius == RadiusWavelength::HERO {
            0
        } else {
            RadiusWavelength::choose(&c, u_lane)
        };
        let hero = wl.nm(lane);
        let r_max = self.table.r_max_mm(hero);
        let r = self.table.sample_radius(hero, u[1]);
        if r_max.is_nan() || r_max <= 0.0 {
            return None;
        }
        let pr = probe(frame, p_o, axis, r, r_max, u[2]);
        *rays += 1;
        let mut hits = [(0.0f32, 0u32, glam::Vec2::ZERO); MAX_PROBE_HITS];
        let mut n = 0usize;
        geometry
            .accel()
            .for_each_hit(&ray(pr.origin, pr.dir, 0.0, pr.length), |h| {
                if n < MAX_PROBE_HITS && geometry.material_of(h.triangle) == material {
                    hits[n] = (h.t, h.triangle, h.bary);
                    n += 1;
                }
            });
        // The triangle test is not watertight at shared edges: merge hits at nearly equal t.
        let hits = &mut hits[..n];
        hits.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let eps = 1e-5 * (1.0 + p_o.abs().max_element());
        let mut m = 0usize;
        for i in 0..hits.len() {
            if m == 0 || hits[i].0 - hits[m - 1].0 > eps {
                hits[m] = hits[i];
                m += 1;
            }
        }
        if m == 0 {
            if axis != 0 {
                return None;
            }
            let planar = pr.origin + pr.dir * (0.5 * pr.length) - p_o;
            if self.skin_at_distance(geometry, material, p_o, frame.n, planar, rays) {
                return None;
            }
            return Some(self.local_fallback(p_o, frame, axes, &lanes, &c, r));
        }
        let pick = ((u[3] * m as f32) as usize).min(m - 1);
        let (t, triangle, bary) = hits[pick];
        let s = geometry.surface(&crate::accel::TriHit { t, triangle, bary });
        // Outward normals: the vertex normals' side, flipped when the entry frame was.
        let (ng, ns) = if flipped {
            (-s.ng, -s.ns)
        } else {
            (s.ng, s.ns)
        };
        let dist = (s.p - p_o).length();
        let pdf = pdf_exit(axes, frame, p_o, s.p, ng, |ra| self.mixture(&lanes, &c, ra));
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        let weight = self.weight(&lanes, dist, m as f32 / pdf);
        Some(Exit {
            p: s.p,
            ng,
            ns,
            hit: Some(s),
            weight,
        })
    }

    /// Whether material `material` crosses the quarter circle from `p_o + planar` down to
    /// `p_o − |planar| n` (around `p_o`, as [`ARC_SEGMENTS`] chords): skin at distance |planar| from
    /// `p_o` in the probe's azimuth, whose energy the probes find. Counts its rays in `rays`.
    fn skin_at_distance(
        &self,
        geometry: &Geometry,
        material: u32,
        p_o: Vec3,
        n: Vec3,
        planar: Vec3,
        rays: &mut u64,
    ) -> bool {
        let r = planar.length();
        if r.is_nan() || r <= 0.0 {
            return false;
        }
        let t = planar / r;
        let point = |k: usize| {
            let beta = std::f32::consts::FRAC_PI_2 * k as f32 / ARC_SEGMENTS as f32;
            p_o + (t * beta.cos() - n * beta.sin()) * r
        };
        (0..ARC_SEGMENTS).any(|k| {
            let (a, b) = (point(k), point(k + 1));
            let len = (b - a).length();
            *rays += 1;
            let mut found = false;
            geometry
                .accel()
                .for_each_hit(&ray(a, (b - a) / len, 0.0, len), |h| {
                    found |= geometry.material_of(h.triangle) == material;
                });
            found
        })
    }

    /// The normal probe found no surface: the planar energy of (r, φ) leaves at the entry point.
    fn local_fallback(
        &self,
        p_o: Vec3,
        frame: &ProbeFrame,
        axes: &ProbeAxes,
        lanes: &Lanes<'_>,
        c: &[f32; N_WAVELENGTHS],
        r: f32,
    ) -> Exit {
        let pdf = axes.p_normal() * self.mixture(lanes, c, r);
        let weight = if pdf > 0.0 {
            self.weight(lanes, r, 1.0 / pdf)
        } else {
            SampledSpectrum::zero()
        };
        Exit {
            p: p_o,
            ng: frame.n,
            ns: frame.n,
            hit: None,
            weight,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::TriangleMesh;
    use glam::Affine3A;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;
    use skin_optics::{Preset, SkinParams, Wavelength};

    /// A 400 mm × 400 mm flat slab of skin at z = 0 (material 0), facing +Z.
    fn slab() -> Geometry {
        let mut q = TriangleMesh::quad();
        q.transform(&Affine3A::from_scale(Vec3::splat(200.0)));
        Geometry::new(vec![(q, 0)])
    }

    fn subsurface(preset: Preset) -> Subsurface {
        let skin = SkinParams::preset(preset);
        let table = ProfileTable::build(
            &skin,
            multipole::Method::default(),
            &TableOptions::default(),
        )
        .unwrap();
        let ts =
            brdf::TorranceSparrow::new(0.3, skin.oiliness() as f32, skin.eta() as f32).unwrap();
        Subsurface::new(
            Arc::new(table),
            Directional::new(ts, EnergySplit::default()),
        )
    }

    const FRAME: ProbeFrame = ProbeFrame {
        x: Vec3::X,
        y: Vec3::Y,
        n: Vec3::Z,
    };

    /// The default axis choice (normal ½).
    const AXES: ProbeAxes = ProbeAxes::DEFAULT;

    /// Radius-wavelength choices every unbiasedness check runs with: each lane alike, the
    /// renderer's, and a nearly pure luminance choice (the rarest lanes chosen 0.5% of the time).
    const RADIUS_CHOICES: [RadiusWavelength; 3] = [
        RadiusWavelength::HERO,
        RadiusWavelength::RENDER,
        match RadiusWavelength::new(0.02) {
            Some(r) => r,
            None => RadiusWavelength::HERO,
        },
    ];

    /// χ² of the sampled exit distance on a flat slab against the multipole profile's own radial
    /// density 2πr R(r) / R_table (20 equiprobable bins from `multipole::Profile::sample_radius`,
    /// 19 degrees of freedom: 45.3 is the p = 0.0005 critical value). Also: normal probes on a
    /// plane always find it (no fallback).
    #[test]
    fn sampled_radius_follows_the_profile_chi2() {
        let ss = subsurface(Preset::Light);
        let geo = slab();
        // An anchor of the tables' Monte Carlo shapes (380 + 12 × 20 nm), where the row is the shape
        // itself, not a mix of two.
        let nm = 620.0f32;
        let wl = SampledWavelengths::sample_visible((nm - 380.0) / 400.0);
        assert!((wl.nm(0) - nm).abs() < 1e-3);
        let reference = multipole::skin::profile(
            &SkinParams::preset(Preset::Light),
            Wavelength::new(f64::from(nm)).unwrap(),
            multipole::Method::default(),
            &TableOptions::default().profile,
        )
        .unwrap();
        let k = 20;
        let edges: Vec<f64> = (1..k)
            .map(|i| reference.sample_radius(i as f64 / k as f64))
            .collect();
        let mut counts = vec![0u32; k];
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
        let (mut hits, mut rays) = (0u32, 0u64);
        for _ in 0..120_000 {
            let u = [rng.random(), rng.random(), rng.random(), rng.random()];
            if let Some(e) = ss.sample_exit(
                &geo,
                0,
                Vec3::ZERO,
                &FRAME,
                &AXES,
                RadiusWavelength::HERO,
                false,
                &wl,
                u,
                &mut rays,
            ) {
                assert!(e.hit.is_some(), "fallback on an infinite plane");
                let r = f64::from(e.p.length());
                counts[edges.partition_point(|&x| x < r)] += 1;
                hits += 1;
            }
        }
        // About half the probes (the normal axis) hit.
        assert!(
            (f64::from(hits) / 120_000.0 - 0.5).abs() < 0.01,
            "{hits} hits"
        );
        let expect = f64::from(hits) / k as f64;
        let chi2: f64 = counts
            .iter()
            .map(|&c| (f64::from(c) - expect).powi(2) / expect)
            .sum();
        assert!(chi2 < 45.3, "χ² = {chi2:.1}, counts {counts:?}");
    }

    /// Mean spatial weight per physical wavelength over `n` probes from the origin, cycling the
    /// hero through the four rotations of one stratified set (one-sample spectral MIS is unbiased
    /// over the hero's choice, as in the renderer where the hero is uniform): (nm, mean, std error).
    fn mean_weights(
        ss: &Subsurface,
        geo: &Geometry,
        u0: f32,
        n: u32,
        seed: u64,
        radius: RadiusWavelength,
    ) -> Vec<(f32, f64, f64)> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let base = SampledWavelengths::sample_visible(u0);
        let mut acc: Vec<(f32, f64, f64)> =
            base.all_nm().iter().map(|&nm| (nm, 0.0, 0.0)).collect();
        let mut rays = 0;
        for s in 0..n {
            let wl = SampledWavelengths::sample_visible((u0 + (s % 4) as f32 * 0.25).fract());
            let u = [rng.random(), rng.random(), rng.random(), rng.random()];
            if let Some(e) = ss.sample_exit(
                geo,
                0,
                Vec3::ZERO,
                &FRAME,
                &AXES,
                radius,
                false,
                &wl,
                u,
                &mut rays,
            ) {
                for c in 0..4 {
                    let slot = acc
                        .iter_mut()
                        .min_by(|a, b| (a.0 - wl.nm(c)).abs().total_cmp(&(b.0 - wl.nm(c)).abs()));
                    let w = f64::from(e.weight.0[c]);
                    let slot = slot.unwrap(); // acc has four entries
                    slot.1 += w;
                    slot.2 += w * w;
                }
            }
        }
        acc.iter()
            .map(|&(nm, s, s2)| {
                let mean = s / f64::from(n);
                (
                    nm,
                    mean,
                    ((s2 / f64::from(n) - mean * mean) / f64::from(n)).sqrt(),
                )
            })
            .collect()
    }

    /// Under every radius-wavelength choice, each lane's mean spatial weight over 40,000 probes
    /// is its R_tot within 4 standard errors (plus 0.1% for the table's f32 rounding).
    fn assert_mean_weights_are_totals(
        ss: &Subsurface,
        geo: &Geometry,
        u0: f32,
        seed: u64,
        label: &str,
    ) {
        for radius in RADIUS_CHOICES {
            for (nm, mean, se) in mean_weights(ss, geo, u0, 40_000, seed, radius) {
                let want = f64::from(ss.table.total(nm));
                assert!(
                    (mean - want).abs() < 4.0 * se + 1e-3 * want,
                    "{label} {radius:?} {nm} nm: {mean:.4} ± {se:.4} vs R_tot {want:.4}"
                );
            }
        }
    }

    /// The spatial weight's mean over probes is R_tot at each of the four wavelengths (spectral MIS
    /// unbiased for the non-hero wavelengths too), within 4 standard errors.
    #[test]
    fn spatial_weight_integrates_to_the_total_per_wavelength() {
        let geo = slab();
        for preset in [Preset::Light, Preset::Dark] {
            let ss = subsurface(preset);
            assert_mean_weights_are_totals(&ss, &geo, 0.37, 5, &format!("{preset:?}"));
        }
    }

    /// An isolated small patch: normal probes mostly miss, and the local fallback returns the
    /// planar energy, so the total is still R_tot at every wavelength (nothing silently lost).
    #[test]
    fn missing_surface_energy_is_returned_locally() {
        let ss = subsurface(Preset::Light);
        let mut q = TriangleMesh::quad();
        q.transform(&Affine3A::from_scale(Vec3::splat(0.05)));
        let geo = Geometry::new(vec![(q, 0)]);
        assert_mean_weights_are_totals(&ss, &geo, 0.6, 9, "patch");
    }
}
