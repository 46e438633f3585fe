//! The skin as a finite slab: a body `d` thick with the epidermis on both faces and the dermis
//! between, in air on both sides (docs/physics.md §16.6). This is what a thin part of a mesh (an
//! ear's rim, a backlit slab) is to the volumetric walk, whose epidermis is the shell within the
//! epidermis' thickness of the surface. Adding-doubling ([Prahl95], physics §10) gives its exact
//! totals at normal incidence: the diffuse reflectance R(d) and the transmittance T(d) per
//! incident photon, which tend to the half-space's R∞ and to 0 as d grows.

use crate::error::MultipoleError;
use crate::exact::adding_doubling::{self, AddingDoublingOptions, SlabTotals};
use crate::layered::{Layer, LayeredMedium};

/// The half-space skin `half_space` (an epidermis slab over a semi-infinite dermis, as
/// [`LayeredMedium::skin`] builds it) as a slab `thickness_mm` thick: epidermis, dermis
/// `thickness_mm − 2 d_epi`, epidermis, in air on both sides. A slab no thicker than twice the
/// epidermis is epidermis throughout; both faces take `half_space`'s surface. Errors name the thickness and its range (0, 1000] mm, or
/// a `half_space` that is not two layers with a semi-infinite dermis.
pub fn slab_of(
    half_space: &LayeredMedium,
    thickness_mm: f64,
) -> Result<LayeredMedium, MultipoleError> {
    let layers = half_space.layers();
    let (epi, dermis) = match layers {
        [e, d] if e.thickness_mm().is_some() && d.thickness_mm().is_none() => (e, d),
        _ => {
            return Err(MultipoleError::Layers(format!(
                "a thin slab needs an epidermis over a semi-infinite dermis, got {} layers",
                layers.len()
            )));
        }
    };
    if !(thickness_mm > 0.0 && thickness_mm <= crate::layered::MAX_THICKNESS_MM) {
        return Err(MultipoleError::OutOfRange {
            name: "thin slab thickness (mm)",
            value: thickness_mm,
            range: "(0, 1000] mm",
        });
    }
    let d_epi = epi.thickness_mm().unwrap_or(0.0);
    let with_thickness = |l: &Layer, d: f64| {
        Layer::from_reduced(l.sigma_a(), l.sigma_s_prime(), l.g(), l.n(), Some(d))
    };
    let stack = if thickness_mm <= 2.0 * d_epi {
        vec![with_thickness(epi, thickness_mm)?]
    } else {
        let e = with_thickness(epi, d_epi)?;
        vec![e, with_thickness(dermis, thickness_mm - 2.0 * d_epi)?, e]
    };
    Ok(
        LayeredMedium::new(stack, half_space.n_above(), half_space.n_above())?
            .with_surface(half_space.surface()),
    )
}

/// Exact totals of [`slab_of`]`(half_space, thickness_mm)` for a beam at normal incidence:
/// diffuse reflectance R(d), specular reflection and transmittance T(d), per incident photon.
pub fn slab_totals(
    half_space: &LayeredMedium,
    thickness_mm: f64,
    options: &AddingDoublingOptions,
) -> Result<SlabTotals, MultipoleError> {
    Ok(adding_doubling::solve(
        &slab_of(half_space, thickness_mm)?,
        options,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::montecarlo::{self, McOptions};
    use skin_optics::{Preset, SkinParams, Wavelength};

    fn skin(preset: Preset, nm: f64) -> LayeredMedium {
        LayeredMedium::skin(
            &SkinParams::preset(preset),
            Wavelength::new(nm).unwrap(),
            crate::DEFAULT_G,
        )
        .unwrap()
    }

    fn options() -> AddingDoublingOptions {
        AddingDoublingOptions::default()
    }

    /// Without scattering the slab is a clear absorber between two Fresnel faces: with
    /// τ = σa_e · 2 d_epi + σa_d (d − 2 d_epi) and F = F_r(0) = ((n − 1)/(n + 1))², the
    /// multiple reflections between the faces sum to T = (1 − F)² e^(−τ) / (1 − F² e^(−2τ)) and
    /// R = (1 − F)² F e^(−2τ) / (1 − F² e^(−2τ)) (the specular reflection of the top face apart).
    /// Adding-doubling's quadrature resolves the normal beam exactly, so the two agree to 1e-9.
    #[test]
    fn a_clear_slab_has_the_closed_form_totals() {
        let n = 1.4;
        let epi = Layer::from_reduced(0.5, 0.0, 0.9, n, Some(0.1)).unwrap();
        let dermis = Layer::from_reduced(0.2, 0.0, 0.9, n, None).unwrap();
        let half = LayeredMedium::new(vec![epi, dermis], 1.0, 1.0).unwrap();
        let f = ((n - 1.0) / (n + 1.0)).powi(2);
        for (d, tau) in [
            (0.15, 0.5 * 0.15),
            (2.0, 0.5 * 0.2 + 0.2 * 1.8),
            (9.0, 0.5 * 0.2 + 0.2 * 8.8),
        ] {
            let t = slab_totals(&half, d, &options()).unwrap();
            let e = f64::exp(-tau);
            let denom = 1.0 - f * f * e * e;
            let want_t = (1.0 - f).powi(2) * e / denom;
            let want_r = (1.0 - f).powi(2) * f * e * e / denom;
            assert!(
                (t.transmittance - want_t).abs() < 1e-9,
                "{d} mm: T {} vs {want_t}",
                t.transmittance
            );
            assert!(
                (t.diffuse_reflectance - want_r).abs() < 1e-9,
                "{d} mm: R {} vs {want_r}",
                t.diffuse_reflectance
            );
        }
    }

    /// Thick, the slab is the half-space: at 40 mm light skin at 650 nm (its most transparent
    /// band; the dermis' diffusion length 1/σ_tr ≈ 2.9 mm) transmits under 10⁻⁵ and reflects the
    /// half-space's R∞ within 10⁻⁵; at 2 mm it transmits more than a tenth, so the check can fail.
    #[test]
    fn a_thick_slab_is_the_half_space() {
        let half = skin(Preset::Light, 650.0);
        let r_inf = adding_doubling::solve(&half, &options())
            .unwrap()
            .diffuse_reflectance;
        let thick = slab_totals(&half, 40.0, &options()).unwrap();
        assert!((0.0..1e-5).contains(&thick.transmittance), "{thick:?}");
        assert!(
            (thick.diffuse_reflectance - r_inf).abs() < 1e-5,
            "{thick:?} vs {r_inf}"
        );
        let thin = slab_totals(&half, 2.0, &options()).unwrap();
        assert!(thin.transmittance > 0.1, "{thin:?}");
        assert!(thin.diffuse_reflectance < r_inf, "{thin:?} vs {r_inf}");
    }

    /// Against the layered Monte Carlo (an independent method, physics §11) on the same slabs,
    /// light and medium skin at 550 and 650 nm, 1 and 4 mm: R and T within 4 of the Monte Carlo's
    /// standard errors plus adding-doubling's quadrature error (2·10⁻⁴ absolute at its default 24 points,
    /// physics §10), two-sided.
    #[test]
    fn thin_slab_totals_match_the_layered_monte_carlo() {
        let mc = McOptions::new(40_000, 20, 11).unwrap();
        for (preset, nm, d) in [
            (Preset::Light, 650.0, 1.0),
            (Preset::Light, 550.0, 4.0),
            (Preset::Medium, 650.0, 4.0),
        ] {
            let half = skin(preset, nm);
            let ad = slab_totals(&half, d, &options()).unwrap();
            let run = montecarlo::run(&slab_of(&half, d).unwrap(), &mc);
            for (what, exact, est) in [
                ("R", ad.diffuse_reflectance, run.diffuse_reflectance),
                ("T", ad.transmittance, run.transmittance),
            ] {
                assert!(
                    (exact - est.mean).abs() <= 4.0 * est.stderr + 2e-4,
                    "{preset:?} {nm} nm {d} mm {what}: adding-doubling {exact} vs Monte Carlo {} ± {}",
                    est.mean,
                    est.stderr
                );
            }
        }
    }

    /// The same agreement under the oily surface on both faces (docs/physics.md §10.1; ρ_s 0 and
    /// 0.25 at m 0.3): adding-doubling's lobe faces against the Monte Carlo's, each photon meeting
    /// a face reflected with the lobe's ρ_dr at its outside angle. Each case's R must also differ from
    /// the Fresnel faces' by more than the tolerance, so the check can tell the two surfaces apart.
    #[test]
    fn oily_slab_totals_match_the_layered_monte_carlo() {
        let mc = McOptions::new(40_000, 20, 12).unwrap();
        for (preset, nm, d, rho_s) in [
            (Preset::Light, 650.0, 1.0, 0.0),
            (Preset::Medium, 550.0, 2.0, 0.25),
        ] {
            let half = skin(preset, nm);
            let fresnel = slab_totals(&half, d, &options()).unwrap();
            let half = half.with_surface(crate::layered::Surface::lobe(0.3, rho_s).unwrap());
            let ad = slab_totals(&half, d, &options()).unwrap();
            let run = montecarlo::run(&slab_of(&half, d).unwrap(), &mc);
            for (what, exact, est, other) in [
                (
                    "R",
                    ad.diffuse_reflectance,
                    run.diffuse_reflectance,
                    fresnel.diffuse_reflectance,
                ),
                (
                    "T",
                    ad.transmittance,
                    run.transmittance,
                    fresnel.transmittance,
                ),
            ] {
                let tol = 4.0 * est.stderr + 2e-4;
                assert!(
                    (exact - est.mean).abs() <= tol,
                    "{preset:?} {nm} nm {d} mm {what}: adding-doubling {exact} vs Monte Carlo {} ± {}",
                    est.mean,
                    est.stderr
                );
                assert!(
                    what == "T" || (other - est.mean).abs() > tol,
                    "{preset:?} {nm} nm {d} mm {what}: the Fresnel faces' {other} is as close"
                );
            }
        }
    }

    /// A thickness outside (0, 1000] mm and a medium that is not epidermis over dermis are
    /// errors naming what is wrong.
    #[test]
    fn bad_slabs_are_named_errors() {
        let half = skin(Preset::Light, 550.0);
        for d in [0.0, -1.0, f64::NAN, 2000.0] {
            let e = slab_of(&half, d).unwrap_err().to_string();
            assert!(e.contains("thin slab thickness"), "{d}: {e}");
        }
        let one = LayeredMedium::new(vec![half.layers()[0]], 1.0, 1.0).unwrap();
        assert!(slab_of(&one, 2.0).is_err());
    }
}
