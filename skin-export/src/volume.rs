//! The homogeneous semi-infinite medium behind OpenPBR's and Standard Surface's subsurface
//! parameters ([OpenPBR] §subsurface): extinction μt = 1/ℓ from the mean free path ℓ
//! (`subsurface_radius` × scale), single-scattering albedo α chosen so that the medium under its
//! dielectric face returns the fraction C (`subsurface_color`) of the light that enters it, HG phase
//! function of anisotropy g. Transport in it is solved exactly: totals by adding-doubling, the radial
//! profile by the layered Monte Carlo, both from `multipole` (docs/physics.md §10, §11, §14).
//!
//! The fit per channel: C = our total (per unit flux entering); α by bisection on the adding-doubling
//! total; ℓ so that the medium's mean radial distance equals ours. Its profile shape is then measured
//! against ours. The spec also quotes van de Hulst's index-matched inversion α(C); a renderer that uses
//! it under a dielectric face returns another total, which is measured too.

use crate::error::{ExportError, check};
use crate::rgb::{RgbProfile, shape_error, total_error};
use multipole::exact::adding_doubling::{AddingDoublingOptions, solve};
use multipole::exact::montecarlo::{McOptions, RadialGrid, run};
use multipole::{Layer, LayeredMedium, MultipoleError, Profile};

/// Generator seed of the medium's Monte Carlo profiles (fixed: an export is a pure function).
pub const VOLUME_SEED: u64 = 0x0BE1_7A11;
/// Batches of those runs.
const BATCHES: u32 = 16;

/// One semi-infinite layer (σa, σs in mm⁻¹, HG g, index η) under air, on air (the exit side is
/// never reached).
fn semi_infinite_medium(
    sigma_a_per_mm: f64,
    sigma_s_per_mm: f64,
    g: f64,
    eta: f64,
) -> Result<LayeredMedium, ExportError> {
    Ok(LayeredMedium::new(
        vec![Layer::semi_infinite(
            sigma_a_per_mm,
            sigma_s_per_mm,
            g,
            eta,
        )?],
        1.0,
        1.0,
    )?)
}

/// Total reflectance per unit flux entering a semi-infinite layer (σa, σs in mm⁻¹, HG g, index η
/// under air), by adding-doubling at its default quadrature.
pub fn semi_infinite_total(
    sigma_a_per_mm: f64,
    sigma_s_per_mm: f64,
    g: f64,
    eta: f64,
) -> Result<f64, ExportError> {
    let medium = semi_infinite_medium(sigma_a_per_mm, sigma_s_per_mm, g, eta)?;
    let t = solve(&medium, &AddingDoublingOptions::default()).map_err(MultipoleError::from)?;
    Ok(t.diffuse_reflectance / (1.0 - t.specular_reflectance))
}

/// The x in [lo, hi] (both > 0) where the decreasing `f(x)` equals `target`: bisection on ln x to a
/// relative width of 1e-10 (≤ 80 evaluations).
pub fn solve_decreasing(
    target: f64,
    lo: f64,
    hi: f64,
    f: impl Fn(f64) -> Result<f64, ExportError>,
) -> Result<f64, ExportError> {
    let (f_lo, f_hi) = (f(lo)?, f(hi)?);
    if !(f_hi <= target && target <= f_lo) {
        return Err(ExportError::Fit(format!(
            "total {target} outside what the medium can return ([{f_hi:.4}, {f_lo:.4}])"
        )));
    }
    let (mut a, mut b) = (lo.ln(), hi.ln());
    while b - a > 1e-10 {
        let m = 0.5 * (a + b);
        if f(m.exp())? > target {
            a = m;
        } else {
            b = m;
        }
    }
    Ok((0.5 * (a + b)).exp())
}

/// Radial profile (per unit flux entering, mm⁻²) and mean radial distance (mm) of a semi-infinite
/// layer under air, from `photons` Monte Carlo histories on a geometric grid scaled to its transport
/// mean free path.
pub fn semi_infinite_profile(
    sigma_a_per_mm: f64,
    sigma_s_per_mm: f64,
    g: f64,
    eta: f64,
    photons: u64,
) -> Result<(Profile, f64), ExportError> {
    let transport_mfp = 1.0 / (sigma_a_per_mm + sigma_s_per_mm * (1.0 - g));
    let grid = RadialGrid::geometric(
        (2e-3 * transport_mfp).max(1e-6),
        (500.0 * transport_mfp).min(1000.0),
        96,
    )?;
    let stack = semi_infinite_medium(sigma_a_per_mm, sigma_s_per_mm, g, eta)?;
    let result = run(
        &stack,
        &McOptions::new(photons, BATCHES, VOLUME_SEED)?.with_grid(grid),
    );
    let entering = 1.0 - result.specular_reflectance;
    let radii: Vec<f64> = (0..grid.bins()).map(|i| grid.r_mid_mm(i)).collect();
    let values: Vec<f64> = result
        .radial
        .reflectance_per_mm2
        .iter()
        .map(|v| v / entering)
        .collect();
    let (mut num, mut den) = (0.0, 0.0);
    for (i, v) in values.iter().enumerate() {
        let w = v * grid.annulus_area_mm2(i);
        num += w * radii[i];
        den += w;
    }
    let profile = Profile::from_table(radii, values, result.diffuse_reflectance.mean / entering)?;
    Ok((profile, num / den))
}

/// van de Hulst's single-scattering albedo for a multiple-scattering albedo C and anisotropy g (the
/// index-matched inversion quoted by [OpenPBR]).
#[must_use]
pub fn van_de_hulst_albedo(c: f64, g: f64) -> f64 {
    let s = 4.09712 + 4.20863 * c - (9.59217 + 41.6808 * c + 17.7126 * c * c).sqrt();
    (1.0 - s * s) / (1.0 - g * s * s)
}

/// The OpenPBR / Standard Surface medium fitted per channel, with its measured errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeFit {
    /// `subsurface_color` C per channel: our total per unit flux entering.
    pub colour: [f64; 3],
    /// Mean free path ℓ = 1/μt per channel, mm.
    pub mean_free_path_mm: [f64; 3],
    /// Single-scattering albedo α per channel that returns C.
    pub single_scattering_albedo: [f64; 3],
    /// HG anisotropy g.
    pub g: f64,
    /// Refractive index of the face.
    pub eta: f64,
    /// |total(α) − C| / C per channel (bisection tolerance).
    pub total_error: [f64; 3],
    /// The same with van de Hulst's α(C) instead.
    pub van_de_hulst_total_error: [f64; 3],
    /// Energy-weighted shape error of the medium's profile per channel.
    pub shape_error: [f64; 3],
}

impl VolumeFit {
    /// Fit the medium (anisotropy `g`, index `eta`) to `rgb`, tracing `photons` per channel.
    pub fn fit(rgb: &RgbProfile, g: f64, eta: f64, photons: u64) -> Result<Self, ExportError> {
        check("anisotropy g", g, 0.0, 0.99, "[0, 0.99]")?;
        let mut fit = Self {
            colour: rgb.totals(),
            mean_free_path_mm: [0.0; 3],
            single_scattering_albedo: [0.0; 3],
            g,
            eta,
            total_error: [0.0; 3],
            van_de_hulst_total_error: [0.0; 3],
            shape_error: [0.0; 3],
        };
        for c in 0..3 {
            let target = fit.colour[c];
            // μt = 1 mm⁻¹: σa = 1 − α, σs = α; the total falls as 1 − α grows.
            let total = |one_minus_alpha: f64| {
                semi_infinite_total(one_minus_alpha, 1.0 - one_minus_alpha, g, eta)
            };
            let u = solve_decreasing(target, 1e-9, 0.999_999, total)?;
            let alpha = 1.0 - u;
            let (profile, mean_at_unit_mfp) = semi_infinite_profile(u, alpha, g, eta, photons)?;
            let mfp = rgb.mean_radius_mm(c) / mean_at_unit_mfp;
            let vdh = van_de_hulst_albedo(target, g).clamp(0.0, 1.0 - 1e-12);
            fit.single_scattering_albedo[c] = alpha;
            fit.mean_free_path_mm[c] = mfp;
            fit.total_error[c] = total_error(target, total(u)?);
            fit.van_de_hulst_total_error[c] = total_error(target, total(1.0 - vdh)?);
            fit.shape_error[c] =
                shape_error(&rgb.channel(c)?, |r| profile.eval(r / mfp) / (mfp * mfp));
        }
        Ok(fit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn van_de_hulst_inverts_its_forward_formula() {
        // Forward: C = (1 − s)(1 − 0.139 s)/(1 + 1.17 s), s = √((1 − α)/(1 − αg)).
        for &(alpha, g) in &[(0.99, 0.0), (0.999, 0.9), (0.9, 0.5)] {
            let s = ((1.0_f64 - alpha) / (1.0 - alpha * g)).sqrt();
            let c = (1.0 - s) * (1.0 - 0.139 * s) / (1.0 + 1.17 * s);
            // The published inversion is a fit to 3e-3 in α near these values.
            assert!(
                (van_de_hulst_albedo(c, g) - alpha).abs() < 3e-3,
                "{alpha} {g}"
            );
        }
    }

    #[test]
    fn bisection_reproduces_the_total() {
        let target = 0.4;
        let u = solve_decreasing(target, 1e-9, 0.999_999, |u| {
            semi_infinite_total(u, 1.0 - u, 0.9, 1.4)
        })
        .unwrap();
        let got = semi_infinite_total(u, 1.0 - u, 0.9, 1.4).unwrap();
        assert!((got - target).abs() < 1e-8, "{got}");
        assert!(
            solve_decreasing(1.5, 1e-9, 0.5, |u| semi_infinite_total(
                u,
                1.0 - u,
                0.9,
                1.4
            ))
            .is_err()
        );
    }
}
