//! The profile target of `Method::Exact` (docs/physics.md §9): the default profile (Monte Carlo
//! shape, exact total) against an independent Monte Carlo run, energy-weighted error within 10%.
//!
//! Error = Σ_annuli |E_model − E_mc| / R_mc on the reference's uniform 0.02 mm annuli to 6 mm,
//! E = ∫ 2πr R dr per annulus (model per incident photon: its per-entering profile × (1 − F_r(0))).
//! The reference's own noise adds about Σ √(2/π) σ_annulus / R_mc, which is printed on failure; the
//! diffusion shapes miss by 25–30% (light) and 60–75% (dark), so a fallback to them fails.

use multipole::skin::{Method, profile};
use multipole::{Profile, ProfileOptions};
use skin_optics::{Preset, SkinParams, Wavelength};
use validation::montecarlo::{DEFAULT_G, LayeredMedium, McOptions, McResult, RadialGrid, run};

/// ∫ 2πr R(r) dr over [a, b] (mm) by the midpoint rule on 16 sub-intervals.
fn annulus_energy(p: &Profile, a: f64, b: f64) -> f64 {
    let h = (b - a) / 16.0;
    (0..16)
        .map(|k| {
            let r = a + (k as f64 + 0.5) * h;
            2.0 * std::f64::consts::PI * r * p.eval(r) * h
        })
        .sum()
}

fn energy_error(p: &Profile, mc: &McResult) -> (f64, f64) {
    let g = mc.radial.grid;
    let enter = 1.0 - mc.specular_reflectance;
    let tot = mc.diffuse_reflectance.mean;
    let (mut err, mut noise) = (0.0, 0.0);
    for i in 0..g.bins() {
        let area = g.annulus_area_mm2(i);
        let model = enter * annulus_energy(p, g.inner_mm(i), g.outer_mm(i));
        err += (model - mc.radial.reflectance_per_mm2[i] * area).abs();
        noise += (2.0 / std::f64::consts::PI).sqrt() * mc.radial.stderr[i] * area;
    }
    (err / tot, noise / tot)
}

fn check(preset: Preset, nm: f64, photons: u64) {
    let skin = SkinParams::preset(preset);
    let lambda = Wavelength::new(nm).unwrap();
    let model = profile(&skin, lambda, Method::Exact, &ProfileOptions::default()).unwrap();
    let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G).unwrap();
    let grid = RadialGrid::new(0.02, 300).unwrap();
    let mc = run(
        &stack,
        &McOptions::new(photons, 16, 4242).unwrap().with_grid(grid),
    );
    let (err, noise) = energy_error(&model, &mc);
    assert!(
        err < 0.10,
        "{preset:?} {nm} nm: energy-weighted error {:.1}% (reference noise ≈ {:.1}%)",
        100.0 * err,
        100.0 * noise
    );
}

#[test]
#[cfg_attr(debug_assertions, ignore = "10⁵–10⁶ photons: run with --release")]
fn exact_profile_shape_matches_monte_carlo_light_550_nm() {
    check(Preset::Light, 550.0, 100_000);
}

#[test]
#[cfg_attr(debug_assertions, ignore = "10⁵–10⁶ photons: run with --release")]
fn exact_profile_shape_matches_monte_carlo_dark_450_nm() {
    // 0.86% of the photons come back: 10⁶ photons give ≈ 8,600 escapes in the reference.
    check(Preset::Dark, 450.0, 1_000_000);
}
