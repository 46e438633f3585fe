//! Our layered Monte Carlo against MCML 1.2 ([WJZ95] Wang, Jacques & Zheng 1995: the original C
//! program, an independent implementation with its own generator), on the same layers: the radial
//! profile R_d(r) and the totals R_d, A (per layer too) and T_t.
//!
//! Reference: `validation/data/mcml/CASE.csv`, MCML run on `CASE.mci` (20 runs × 10⁵ photons;
//! input, command and build in `validation/data/mcml/README.md`), binned by MCML: annuli of 0.01 mm
//! from r = 0, the last (9.99 mm on) holding every photon escaping beyond the grid, each divided by
//! its area (`validation::mcml::mcml_binned` bins our runs the same way).
//!
//! # Tolerance
//! Both codes score the same estimator (implicit capture, roulette at 10⁻⁴ with survival 1/10,
//! all-or-none Fresnel), so with no bias their difference has mean 0. Each side's standard error is
//! a batch estimate: sd(batch values)/√batches, over MCML's 20 runs and over our `RUNS` independent
//! runs (seeds `SEED + k`). Annuli are compared in groups (radii 0.01, 0.02, …, 7, 9.99 mm, merged
//! outwards until each holds ≥ 200 of our escaping photons, so every group's batch values are near
//! normal); for ours the group's batch values are summed before the variance, for MCML (only
//! per-annulus errors are stored) the annuli's errors add in quadrature, which overstates its
//! variance since one photon escapes in one annulus only (negative covariances): conservative.
//! z = (ours − MCML)/√(σ_ours² + σ_MCML²). With estimated variances z follows Student's t with
//! about `RUNS` − 1 = 39 degrees of freedom (Welch–Satterthwaite: our variance, from 10× fewer
//! photons, dominates). Per case at most 26 comparisons (≤ 20 groups, R_d, A, T_t, A per layer);
//! for a false alarm in 1 of 1000 case runs each must pass |z| ≤ t₃₉(1 − 0.001/(2·26)) = 4.64
//! (Bonferroni). MCML prints R_d(r) to 5 and A_l to 4 significant digits: the rounding (≤ 5·10⁻⁵ and
//! 5·10⁻⁴ relative) is added to the A_l bound and is negligible for R_d(r).
//! Power: R_d's standard error here is 0.2–0.3% of R_d, so a bias of 1.5% in a total, or of 5% in a
//! group holding a tenth of R_d, fails.

use super::photons;
use rayon::prelude::*;
use validation::mcml::{self, DR_MM, NR, ReferenceData, mcml_binned};
use validation::montecarlo::{Estimate, McOptions, RadialGrid, run};

/// Independent runs of ours (batches of the standard errors).
const RUNS: u64 = 40;
/// Bound on |z| for every comparison (derivation above).
const Z_MAX: f64 = 4.64;
/// Least of our escaping photons (≈ weight sum) per compared group.
const MIN_ESCAPES: f64 = 200.0;
/// Outer edges (annulus index, exclusive) of the groups before merging; the last is MCML's
/// overflow annulus alone.
const EDGES: [usize; 19] = [
    1, 2, 3, 5, 7, 10, 15, 20, 30, 50, 70, 100, 150, 200, 300, 500, 700, 999, 1000,
];

/// The committed MCML data of case `name`.
pub(crate) fn reference(name: &str) -> ReferenceData {
    let text = match name {
        "light-450" => include_str!("../../data/mcml/light-450.csv"),
        "light-550" => include_str!("../../data/mcml/light-550.csv"),
        "light-650" => include_str!("../../data/mcml/light-650.csv"),
        "dark-450" => include_str!("../../data/mcml/dark-450.csv"),
        "dark-650" => include_str!("../../data/mcml/dark-650.csv"),
        "half-space" => include_str!("../../data/mcml/half-space.csv"),
        _ => panic!("no MCML data for {name}"),
    };
    ReferenceData::parse(text).unwrap()
}

/// Group ranges (annulus index ranges) holding ≥ `MIN_ESCAPES` of `photons` of ours by MCML's profile.
fn groups(reference: &ReferenceData, photons: f64) -> Vec<std::ops::Range<usize>> {
    let energy = |a: usize, b: usize| -> f64 {
        (a..b)
            .map(|i| reference.rd_r_per_mm2[i].mean * reference.annulus_area_mm2(i))
            .sum()
    };
    let mut out: Vec<std::ops::Range<usize>> = Vec::new();
    let mut start = 0;
    for &end in &EDGES {
        if energy(start, end) * photons >= MIN_ESCAPES {
            out.push(start..end);
            start = end;
        }
    }
    // A short remainder joins the last full group.
    if let Some(last) = out.last_mut() {
        last.end = NR;
    }
    out
}

/// Compare `RUNS` runs of ours (`photons` in all, seeds from `seed`) with MCML's case `name`.
fn check(name: &str, photons_total: u64, seed: u64) {
    let case = mcml::case(name).unwrap();
    let reference = reference(name);
    assert_eq!(reference.dr_mm, DR_MM);
    assert_eq!(reference.rd_r_per_mm2.len(), NR);
    let per_run = (photons_total / RUNS).max(100);
    let groups = groups(&reference, (per_run * RUNS) as f64);
    let results: Vec<_> = (0..RUNS)
        .into_par_iter()
        .map(|k| {
            let opts = McOptions::new(per_run, 2, seed + k)
                .unwrap()
                .with_grid(RadialGrid::new(DR_MM, NR).unwrap());
            run(&case.stack, &opts)
        })
        .collect();
    let mut report = Vec::new();
    // z of ours against MCML; `slack` (MCML's rounding) is forgiven before dividing.
    let mut compare = |what: String, ours: Estimate, theirs: Estimate, slack: f64| {
        let d = ours.mean - theirs.mean;
        let z = (d.abs() - slack).max(0.0).copysign(d) / ours.stderr.hypot(theirs.stderr);
        report.push((what, ours, theirs, z));
    };
    let ours_of = |f: &dyn Fn(&validation::montecarlo::McResult) -> f64| {
        Estimate::from_batches(results.iter().map(f))
    };
    compare(
        "R_d".into(),
        ours_of(&|r| r.diffuse_reflectance.mean),
        reference.diffuse_reflectance,
        0.0,
    );
    compare(
        "A".into(),
        ours_of(&|r| r.absorbed.mean),
        reference.absorbed,
        0.0,
    );
    for (l, theirs) in reference.absorbed_by_layer.iter().enumerate() {
        compare(
            format!("A layer {l}"),
            ours_of(&|r| r.absorbed_by_layer[l]),
            *theirs,
            5e-4 * theirs.mean,
        );
    }
    let binned: Vec<Vec<f64>> = results.iter().map(|r| mcml_binned(r).unwrap()).collect();
    for g in &groups {
        let energy = |v: &[f64]| -> f64 {
            g.clone()
                .map(|i| v[i] * reference.annulus_area_mm2(i))
                .sum()
        };
        let ours = Estimate::from_batches(binned.iter().map(|b| energy(b)));
        let mean: Vec<f64> = reference.rd_r_per_mm2.iter().map(|e| e.mean).collect();
        let var: f64 = g
            .clone()
            .map(|i| (reference.rd_r_per_mm2[i].stderr * reference.annulus_area_mm2(i)).powi(2))
            .sum();
        let theirs = Estimate {
            mean: energy(&mean),
            stderr: var.sqrt(),
        };
        let (a, b) = (g.start as f64 * DR_MM, g.end as f64 * DR_MM);
        compare(format!("E[{a:.2}, {b:.2}) mm"), ours, theirs, 0.0);
    }
    // Both transmit almost nothing through 100 mm: no z (both errors may be 0), a bound instead.
    let t_ours = ours_of(&|r| r.transmittance.mean).mean;
    assert!(
        t_ours < 1e-6 && reference.transmittance.mean < 1e-6,
        "{name}: T_t ours {t_ours:e}, MCML {:e}",
        reference.transmittance.mean
    );
    assert!(groups.len() >= 8, "{name}: only {} groups", groups.len());
    assert!(report.len() <= 26);
    let worst = report.iter().map(|r| r.3.abs()).fold(0.0, f64::max);
    let chi2: f64 = report.iter().map(|r| r.3 * r.3).sum::<f64>() / report.len() as f64;
    let table: String = report
        .iter()
        .map(|(w, o, t, z)| {
            format!(
                "  {w:<22} ours {:.5e} ± {:.1e}  MCML {:.5e} ± {:.1e}  z {z:+.2}\n",
                o.mean, o.stderr, t.mean, t.stderr
            )
        })
        .collect();
    eprintln!(
        "{name}: {} comparisons, max |z| {worst:.2}, mean z² {chi2:.2}\n{table}",
        report.len()
    );
    assert!(
        worst <= Z_MAX,
        "{name}: |z| {worst:.2} > {Z_MAX}\n{table}"
    );
}

#[test]
fn light_skin_450_nm_matches_mcml() {
    check("light-450", photons(160_000), 0x4D43_0450);
}

#[test]
fn light_skin_550_nm_matches_mcml() {
    check("light-550", photons(160_000), 0x4D43_0550);
}

#[test]
fn light_skin_650_nm_matches_mcml() {
    check("light-650", photons(120_000), 0x4D43_0650);
}

#[test]
fn dark_skin_450_nm_matches_mcml() {
    check("dark-450", photons(200_000), 0x4D44_0450);
}

#[test]
fn dark_skin_650_nm_matches_mcml() {
    check("dark-650", photons(160_000), 0x4D44_0650);
}

#[test]
fn half_space_matches_mcml() {
    check("half-space", photons(80_000), 0x4D48_0001);
}
