//! Intersecting the BSSRDF's probe segments (`crate::bssrdf`, [KHPC13]): the BSSRDF samples a
//! segment, this integrator step finds the entry point's material along it, and the BSSRDF turns
//! what was found into an exit and its weight.

use crate::accel::{TriHit, ray};
use crate::bssrdf::{
    Exit, MAX_PROBE_HITS, ProbeAxes, ProbeFrame, ProbeSample, ProfileTable, RadiusWavelength,
    Subsurface,
};
use crate::geometry::Geometry;
use crate::spectrum::SampledWavelengths;
use glam::Vec3;

/// Sample where light that leaves at `p_o` (outward frame `frame`, on material `material`)
/// entered, from four uniforms, choosing probe axes by `axes` and the radius's wavelength by
/// `radius`: probe `ss`'s segment (in a defensive mixture with `wide`'s radii where given,
/// [`Subsurface::sample_probe`]) through `geometry`, keep every hit on the material, pick one
/// uniformly. `flipped` tells that the entry frame faces against the mesh's vertex normals;
/// `rays` counts probe rays. None when the probe found nothing usable (a tangent probe missing
/// is expected and unbiased, `crate::bssrdf` module doc).
#[must_use]
#[allow(clippy::too_many_arguments)] // the probe's frame, its choices and the random state
pub fn sample_exit(
    geometry: &Geometry,
    ss: &Subsurface,
    wide: Option<&ProfileTable>,
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
    let probe = ss.sample_probe(wide, frame, p_o, axes, radius, wl, [u[0], u[1], u[2]])?;
    let at = (p_o, frame, axes);
    let pr = probe.segment;
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
        if pr.axis != 0 || crosses_arc(geometry, material, &probe, p_o, frame.n, rays) {
            return None;
        }
        return Some(ss.local_exit(&probe, at));
    }
    let pick = ((u[3] * m as f32) as usize).min(m - 1);
    let (t, triangle, bary) = hits[pick];
    let s = geometry.surface(&TriHit { t, triangle, bary });
    ss.exit_at(&probe, at, s, m, flipped)
}

/// Whether `material` crosses the arc of a normal probe that found nothing
/// ([`ProbeSample::arc_chords`]): then the probes find that energy elsewhere. Counts its rays.
fn crosses_arc(
    geometry: &Geometry,
    material: u32,
    probe: &ProbeSample<'_>,
    p_o: Vec3,
    n: Vec3,
    rays: &mut u64,
) -> bool {
    probe.arc_chords(p_o, n).any(|(origin, dir, len)| {
        *rays += 1;
        let mut found = false;
        geometry
            .accel()
            .for_each_hit(&ray(origin, dir, 0.0, len), |h| {
                found |= geometry.material_of(h.triangle) == material;
            });
        found
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bssrdf::{Directional, EnergySplit, ProfileTable, TableOptions};
    use crate::mesh::TriangleMesh;
    use crate::spectrum::SampledWavelengths;
    use glam::Affine3A;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;
    use skin_optics::{Preset, SkinParams, Wavelength};
    use std::sync::Arc;

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

    /// pbrt's axis choice (normal ½).
    const AXES: ProbeAxes = ProbeAxes::PBRT;

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
            if let Some(e) = sample_exit(
                &geo,
                &ss,
                None,
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
            if let Some(e) = sample_exit(
                geo,
                ss,
                None,
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
