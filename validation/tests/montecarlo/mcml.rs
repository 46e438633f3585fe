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
//! runs (seeds `seed + k`). Annuli are compared in groups (radii 0.01, 0.02, …, 7, 9.99 mm, merged
//! outwards until each holds ≥ 200 of our escaping photons, so every group's batch values are near
//! normal); for ours the group's batch values are summed before the variance, for MCML (only
//! per-annulus errors are stored) the annuli's errors add in quadrature, which overstates its
//! variance since one photon escapes in one annulus only (negative covariances): conservative.
//! z = (ours − MCML)/√(σ_ours² + σ_MCML²). With estimated variances z follows Student's t; ours
//! has fewer photons than MCML's 2·10⁶ in every case, so its variance is the larger and the
//! Welch–Satterthwaite degrees of freedom are at least `RUNS` − 1 = 39. Per case at most 23
//! comparisons (≤ 19 groups, R_d, A, A per layer; T_t, ≈ 0 for both, is a bound); for a false alarm
//! in 1 of 1000 case runs each must pass |z| ≤ t₃₉(1 − 0.001/(2·23)) = 4.60, rounded up to 4.64
//! (the 26-comparison value). MCML prints R_d(r) to 5 and A_l to 4 significant digits: the rounding
//! (≤ 5·10⁻⁵ and 5·10⁻⁴ relative) is forgiven in the A_l comparison and negligible for R_d(r);
//! A_l also forgives a measured difference of the codes, traced to MCML's `ran3` (`LAYER_DISCREPANCY`).
//! Power: R_d's combined standard error is 0.2% (light) to 0.4% (dark) of R_d, so a bias of 1–2% in
//! a total, or of 5–10% in a group holding a tenth of R_d, fails.

use validation::mcml::{self, DR_MM, NR, ReferenceData};

/// Independent runs of ours (batches of the standard errors).
const RUNS: u64 = 40;
/// Bound on |z| for every comparison (derivation above).
const Z_MAX: f64 = 4.64;
/// Relative difference in absorption per layer forgiven (besides MCML's rounding): in light skin
/// our epidermis absorbs up to 0.9% more than the committed MCML runs (+0.24%, +0.72%, +0.88% at
/// 450, 550, 650 nm, z = 2.6, 7.4, 9.9 with 10⁶ photons of ours, `cargo run --release -p
/// validation --features studies --example mcml_agreement`). The cause is MCML's `ran3`
/// generator: MCML with only its generator replaced by xoshiro256**
/// (`validation/data/mcml/random_num_xoshiro.c`, README there) absorbs 0.87% more in the epidermis at 650 nm (0.09633 ± 0.00007 against 0.09550 ±
/// 0.00006 for the same build with `ran3`), ours 0.0964, and its R_d moves from 0.6093 to 0.6076,
/// onto ours (0.6075) and adding-doubling's (0.6077). The reference data are `ran3`'s, so the
/// allowance stays, scoped to per-layer absorption; dark skin and the half-space agree within
/// their errors.
const LAYER_DISCREPANCY: f64 = 0.01;
/// Least of our escaping photons (≈ weight sum) per compared group.
const MIN_ESCAPES: f64 = 200.0;

/// The committed MCML data of case `name`.
pub(crate) fn reference(name: &str) -> ReferenceData {
    let text = match name {
        "light-450" => include_str!("../../data/mcml/light-450.csv"),
        "light-550" => include_str!("../../data/mcml/light-550.csv"),
        "light-650" => include_str!("../../data/mcml/light-650.csv"),
        "dark-450" => include_str!("../../data/mcml/dark-450.csv"),
        "dark-650" => include_str!("../../data/mcml/dark-650.csv"),
        "half-space" => include_str!("../../data/mcml/half-space.csv"),
        "cm50-400" => include_str!("../../data/mcml/cm50-400.csv"),
        "cm50-450" => include_str!("../../data/mcml/cm50-450.csv"),
        "cm25-400" => include_str!("../../data/mcml/cm25-400.csv"),
        "cm25-500" => include_str!("../../data/mcml/cm25-500.csv"),
        _ => panic!("no MCML data for {name}"),
    };
    ReferenceData::parse(text).unwrap()
}

/// Compare `RUNS` runs of ours (`photons` in all, seeds from `seed`) with MCML's case `name`.
fn check(name: &str, photons: u64, seed: u64) {
    let case = mcml::case(name).unwrap();
    let reference = reference(name);
    assert_eq!(reference.dr_mm, DR_MM);
    assert_eq!(reference.rd_r_per_mm2.len(), NR);
    let per_run = (photons / RUNS).max(100);
    let c = mcml::compare(
        &case,
        &reference,
        RUNS,
        per_run,
        seed,
        MIN_ESCAPES,
        LAYER_DISCREPANCY + 5e-4,
    )
    .unwrap();
    // Both transmit almost nothing through 100 mm: no z (both errors may be 0), a bound instead.
    assert!(
        c.our_transmittance < 1e-6 && reference.transmittance.mean < 1e-6,
        "{name}: T_t ours {:e}, MCML {:e}",
        c.our_transmittance,
        reference.transmittance.mean
    );
    // The profile is compared at ≥ 7 radii (dark skin at 450 nm, most of its R_d within 0.03 mm,
    // gives the fewest groups).
    assert!(
        c.groups.len() >= 7,
        "{name}: only {} groups",
        c.groups.len()
    );
    assert!(c.rows.len() <= 26, "{name}: {} comparisons", c.rows.len());
    eprintln!(
        "{name}: {} comparisons, max |z| {:.2}, mean z² {:.2}\n{}",
        c.rows.len(),
        c.max_abs_z(),
        c.mean_z2(),
        c.table()
    );
    assert!(
        c.max_abs_z() <= Z_MAX,
        "{name}: |z| {:.2} > {Z_MAX}\n{}",
        c.max_abs_z(),
        c.table()
    );
}

// One test per committed MCML case: test name, case, our photon count, seed.
release_cases! {
    check, "10⁵–10⁶ photons: run with --release";
    light_skin_450_nm_matches_mcml: "light-450", 160_000, 0x4D43_0450;
    light_skin_550_nm_matches_mcml: "light-550", 160_000, 0x4D43_0550;
    light_skin_650_nm_matches_mcml: "light-650", 120_000, 0x4D43_0650;
    dark_skin_450_nm_matches_mcml: "dark-450", 4_000_000, 0x4D44_0450;
    dark_skin_650_nm_matches_mcml: "dark-650", 800_000, 0x4D44_0650;
    half_space_matches_mcml: "half-space", 80_000, 0x4D48_0001;
}
