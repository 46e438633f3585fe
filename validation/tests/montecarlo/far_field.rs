//! The Monte Carlo's radial distribution far from the source against diffusion, where diffusion is
//! accurate: a matched, isotropically scattering half-space at reduced albedo α' = 0.999
//! (σa = 0.001, σs = σs' = 1 mm⁻¹, g = 0, n = 1 on both sides), annuli 20–40 and 40–80 mm, i.e.
//! 20–80 transport mean free paths ℓ from the entry point and up to 4.4 diffusion lengths 1/σtr.
//!
//! # Reference
//! The dipole (docs/physics.md §3, `multipole::Dipole`, A = 1 for the matched face): the energy
//! escaping in each annulus from its closed-form R_within, independent of the Monte Carlo.
//!
//! # Tolerance: 4σ + 1.5%
//! - 4σ of the Monte Carlo annulus energy (its batch standard error; 6e-5 false alarms per check).
//! - 1.5% for diffusion itself. Far from the source the exact transport field is a diffusion field
//!   whose dipole moment is set by the Milne problem: for a conservative, isotropically
//!   scattering half-space the effective source-plus-extrapolation depth of a normally incident
//!   beam is H(1)/√3 ℓ = 1.6788 ℓ (Chandrasekhar, *Radiative Transfer*, 1950: H(1) = 2.9078 for
//!   ω = 1, the Milne solution's emergent intensity ∝ H(μ)), against the dipole's ℓ + 2ℓ/3 =
//!   1.6667 ℓ: +0.73% in amplitude. The near-field corrections fall with r (measured with 3·10⁶
//!   photons, `(MC − dipole)/dipole` per geometric annulus: −3.3% at 10–14 mm, −1.6% at 14–20 mm,
//!   −0.2 ± 0.3%, +0.8 ± 0.5%, 0.0 ± 0.7% at 20–30, 30–43, 43–61 mm). 1.5% covers both from 20 mm.
//!
//! Power: at 10⁶ photons σ is 0.51% (20–40 mm) and 0.93% (40–80 mm) of the annulus energy, so
//! the bounds are 3.5% and 5.2% (measured, seed 2024: −0.95% and +0.13%); a radial tally scaled by
//! 2% in radius moves the 20–40 mm energy by about 4%, a wrong annulus area or a lost far-field
//! photon by more.

use validation::montecarlo::{Layer, LayeredMedium, McOptions, RadialGrid, run};

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "10⁶ photons of 300 scatterings: run with --release"
)]
fn far_field_matches_the_dipole_at_high_albedo() {
    let (sigma_a, sigma_s) = (0.001, 1.0);
    let stack = LayeredMedium::new(
        vec![Layer::semi_infinite(sigma_a, sigma_s, 0.0, 1.0).unwrap()],
        1.0,
        1.0,
    )
    .unwrap();
    // A disc to 20 mm, then annuli 20–40 and 40–80 mm.
    let grid = RadialGrid::geometric(20.0, 80.0, 3).unwrap();
    let mc = run(
        &stack,
        &McOptions::new(1_000_000, 32, 2024).unwrap().with_grid(grid),
    );
    let dipole = multipole::diffusion::dipole::Dipole::new(
        multipole::diffusion::medium::Medium::new(sigma_a, sigma_s).unwrap(),
        1.0,
    )
    .unwrap();
    for i in 1..grid.bins() {
        let (a, b) = (grid.inner_mm(i), grid.outer_mm(i));
        let area = grid.annulus_area_mm2(i);
        let got = mc.radial.reflectance_per_mm2[i] * area;
        let sigma = mc.radial.stderr[i] * area;
        let want = dipole.reflectance_within(b) - dipole.reflectance_within(a);
        assert!(
            (got - want).abs() <= 4.0 * sigma + 0.015 * want,
            "{a:.0}–{b:.0} mm: Monte Carlo {got:.6} ± {sigma:.6} vs dipole {want:.6}"
        );
    }
}
