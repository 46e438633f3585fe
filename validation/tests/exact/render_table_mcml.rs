//! The profile the renderer actually uses, against MCML 1.2 ([WJZ95]; the committed runs of
//! `validation/data/mcml/`, see `montecarlo::mcml`): `render::bssrdf::ProfileTable` built with
//! `TableOptions::default()` (`Method::Exact`: adding-doubling totals, shapes from the shape table,
//! re-tabulated in f32), evaluated at a wavelength off the `RENDER_SHAPE_STEP_NM` grid.
//!
//! Error = Σ_i |E_table,i − E_MCML,i| / R_d,MCML over MCML's 0.01 mm annuli (the last one: all
//! energy beyond 9.99 mm), E_table,i = (1 − F_r(0)) ∫ 2πr R(r) dr (the table is per unit flux
//! entering; midpoint rule on 16 sub-intervals, exact enough for its piecewise-linear 2πr R).
//!
//! # Tolerance
//! The renderer's stated accuracy is an energy-weighted error ≤ 10% (the shape table alone measures
//! 1.0–2.5% against 10⁶-photon Monte Carlo, BENCHMARKS.md `## Exact profile table`). MCML's noise n_i
//! adds at most Σ|n_i| (triangle inequality), whose mean is Σ √(2/π) σ_i and whose standard
//! deviation is √(Σ (1 − 2/π) σ_i²); the bound is 10% + that mean + 4 of those deviations (σ_i:
//! MCML's stated per-annulus errors). The diffusion profile (`Method::Multipole`) misses by 25–32%
//! (light) and ≥ 60% (dark), and is checked to fail the same bound.

use super::super::montecarlo::mcml::reference;
use multipole::skin::{Method, profile};
use multipole::{Profile, ProfileOptions};
use render::bssrdf::{ProfileTable, RENDER_SHAPE_STEP_NM, TableOptions};
use skin_optics::{Preset, SkinParams, Wavelength};
use validation::mcml::ReferenceData;

/// The renderer's shape error bound at its default table settings.
const STATED_ERROR: f64 = 0.10;

/// ∫ 2πr f(r) dr over [a, b] (mm), midpoint rule on 16 sub-intervals.
fn energy(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let h = (b - a) / 16.0;
    (0..16)
        .map(|k| {
            let r = a + (k as f64 + 0.5) * h;
            2.0 * std::f64::consts::PI * r * f(r) * h
        })
        .sum()
}

/// Energy-weighted error of `f` (R(r) per unit flux entering, zero beyond `r_max_mm`) against
/// `mcml`, and the error bound from the stated accuracy plus MCML's noise.
fn error_and_bound(f: &dyn Fn(f64) -> f64, r_max_mm: f64, mcml: &ReferenceData) -> (f64, f64) {
    let enter = 1.0 - mcml.specular;
    let n = mcml.rd_r_per_mm2.len();
    let dr = mcml.dr_mm;
    let (mut err, mut noise_mean, mut noise_var) = (0.0, 0.0, 0.0);
    for (i, e) in mcml.rd_r_per_mm2.iter().enumerate() {
        let a = i as f64 * dr;
        let b = if i + 1 == n { r_max_mm.max(a) } else { a + dr };
        let area = mcml.annulus_area_mm2(i);
        err += (enter * energy(f, a, b) - e.mean * area).abs();
        noise_mean += (2.0 / std::f64::consts::PI).sqrt() * e.stderr * area;
        noise_var += (1.0 - 2.0 / std::f64::consts::PI) * (e.stderr * area).powi(2);
    }
    let rd = mcml.diffuse_reflectance.mean;
    (
        err / rd,
        STATED_ERROR + (noise_mean + 4.0 * noise_var.sqrt()) / rd,
    )
}

fn check(preset: Preset, nm: f64, case: &str) {
    let opts = TableOptions::default();
    let shape_rows = (nm - opts.from_nm) / RENDER_SHAPE_STEP_NM;
    assert!(
        (shape_rows - shape_rows.round()).abs() > 0.25,
        "{nm} nm is not between two shape rows"
    );
    let skin = SkinParams::preset(preset);
    let mcml = reference(case);
    let table = ProfileTable::build(&skin, Method::Exact, &opts).unwrap();
    let r_max = f64::from(table.r_max_mm(nm as f32));
    let (err, bound) = error_and_bound(
        &|r| f64::from(table.eval(nm as f32, r as f32)),
        r_max,
        &mcml,
    );
    eprintln!(
        "{case}: renderer table error {:.2}% (bound {:.2}%)",
        100.0 * err,
        100.0 * bound
    );
    assert!(
        err <= bound,
        "{case}: renderer table error {:.2}% > {:.2}%",
        100.0 * err,
        100.0 * bound
    );
    let diffusion: Profile = profile(
        &skin,
        Wavelength::new(nm).unwrap(),
        Method::Multipole,
        &ProfileOptions::default(),
    )
    .unwrap();
    let (err_diffusion, _) = error_and_bound(&|r| diffusion.eval(r), diffusion.r_max_mm(), &mcml);
    assert!(
        err_diffusion > bound,
        "{case}: diffusion's error {:.1}% should exceed the bound {:.1}%",
        100.0 * err_diffusion,
        100.0 * bound
    );
}

// One test per case: test name, preset, wavelength (nm), committed MCML case.
release_cases! {
    check, "builds a renderer table: run with --release";
    render_table_light_550_nm_matches_mcml: Preset::Light, 550.0, "light-550";
    render_table_dark_450_nm_matches_mcml: Preset::Dark, 450.0, "dark-450";
}
