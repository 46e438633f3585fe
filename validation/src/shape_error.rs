//! Energy-weighted error of a radial profile against a Monte Carlo run: Σ_annuli |E_model − E_mc| /
//! R_mc on the run's annuli, E = ∫ 2πr R dr per annulus (the model per incident photon: its
//! per-entering profile × (1 − F_r(0))). The run's own noise adds about Σ √(2/π) σ_annulus E / R_mc.

use multipole::Profile;
use multipole::exact::montecarlo::McResult;

/// ∫ 2πr R(r) dr over [a, b] (mm), exact in the profile's own model between its nodes
/// (`Profile::energy_within_mm`): a quadrature of `eval` would miss peaks narrower than its step
/// (dark skin reflects most of its light within 0.005 mm, inside the first 0.02 mm annulus).
#[must_use]
pub fn annulus_energy(p: &Profile, a: f64, b: f64) -> f64 {
    p.energy_within_mm(b) - p.energy_within_mm(a)
}

/// (energy-weighted error, expected contribution of the run's noise) of `p` against `mc`.
#[must_use]
pub fn energy_error(p: &Profile, mc: &McResult) -> (f64, f64) {
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
