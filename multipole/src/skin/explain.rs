//! Why a method is (or is not) trustworthy at one wavelength: the numbers behind the choice of
//! treatment, printed by `skin spectrum --explain` and `skin profile --explain` (docs/physics.md §9).

use super::{ExactShape, Method, layer_scales, shape_photons, total_reflectance};
use crate::diffusion::medium::Medium;
use crate::diffusion::slab::Poles;
use crate::error::MultipoleError;
use skin_optics::{SkinParams, Wavelength};
use std::fmt;

/// Relative difference |multipole / exact − 1| below which diffusion is called accurate (a 2%
/// target for total reflectance).
pub const DIFFUSION_OK: f64 = 0.02;

/// The per-wavelength diagnostic of [`explain`].
#[derive(Debug, Clone, PartialEq)]
pub struct Explanation {
    /// Wavelength, nm.
    pub lambda_nm: f64,
    /// The method asked for.
    pub method: Method,
    /// Epidermis reduced albedo α' = σs'/(σa + σs') (diffusion needs it close to 1).
    pub epidermis_albedo_prime: f64,
    /// Epidermis thickness in transport mean free paths, d (σa + σs') (diffusion needs many).
    pub epidermis_mean_free_paths: f64,
    /// Dermis reduced albedo α'.
    pub dermis_albedo_prime: f64,
    /// Total diffuse reflectance per unit flux entering by multipole diffusion ([DJ05]).
    pub multipole_total: f64,
    /// The same by adding-doubling (exact transport).
    pub exact_total: f64,
    /// `Method::Exact` profile only: factors (exact / diffusion at q = 0) on the epidermis R↓, T↓,
    /// R↑, T↑ and the dermis R, and the final correction to the exact two-layer total.
    pub profile_scales: Option<([f64; 5], f64)>,
    /// `Method::Exact` profile only: its shape.
    pub shape: Option<ExactShape>,
    /// Photons the Monte Carlo shape traces (with [`ExactShape::MonteCarlo`]).
    pub shape_photons: Option<u64>,
}

impl Explanation {
    /// multipole / exact − 1, dimensionless.
    #[must_use]
    pub fn diffusion_error(&self) -> f64 {
        self.multipole_total / self.exact_total - 1.0
    }
}

impl fmt::Display for Explanation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let err = self.diffusion_error();
        write!(
            f,
            "{} nm: epidermis α' {:.3}, {:.2} mean free paths; dermis α' {:.3}; R_d multipole {:.5}, exact {:.5} (diffusion {:+.1}%: {}). ",
            self.lambda_nm,
            self.epidermis_albedo_prime,
            self.epidermis_mean_free_paths,
            self.dermis_albedo_prime,
            self.multipole_total,
            self.exact_total,
            100.0 * err,
            if err.abs() < DIFFUSION_OK {
                "accurate here"
            } else {
                "wrong here"
            }
        )?;
        match self.method {
            Method::Multipole => write!(
                f,
                "Method multipole: diffusion for total and profile{}",
                if err.abs() < DIFFUSION_OK {
                    "."
                } else {
                    "; use --method exact for the right brightness."
                }
            ),
            Method::Exact => {
                write!(f, "Method exact: total by adding-doubling")?;
                match (self.shape, self.shape_photons) {
                    (Some(ExactShape::MonteCarlo { escapes }), Some(n)) => write!(
                        f,
                        "; profile shape = layered Monte Carlo ({n} photons for {escapes} escapes), scaled to the exact total"
                    )?,
                    (Some(ExactShape::RescaledTotal), _) => {
                        f.write_str("; profile = multipole shape scaled to the exact total")?;
                    }
                    (Some(ExactShape::Table(o)), _) => write!(
                        f,
                        "; profile shape = universal white Monte Carlo table ({} photons, exact transport; \
                         a layered Monte Carlo shape where the table does not cover the skin), scaled to the exact total",
                        o.photons
                    )?,
                    _ => {}
                }
                if let Some((s, c)) = self.profile_scales {
                    write!(
                        f,
                        "; diffusion layers rescaled to exact per-layer totals{}: epidermis R↓ ×{:.3}, T↓ ×{:.3}, R↑ ×{:.3}, T↑ ×{:.3}; dermis R ×{:.3}; then ×{:.3} to the exact total",
                        if self.shape == Some(ExactShape::PerLayer) {
                            " (the profile)"
                        } else {
                            " (not used: shown for how far diffusion is off per layer)"
                        },
                        s[0],
                        s[1],
                        s[2],
                        s[3],
                        s[4],
                        c
                    )?;
                }
                f.write_str(".")
            }
        }
    }
}

/// The diagnostic of `method` for `skin` at `lambda`; `profile` (the exact profile's shape, if a
/// profile is made) adds its treatment and diffusion's per-layer factors (`Method::Exact` only;
/// costs one more adding-doubling solve).
pub fn explain(
    skin: &SkinParams,
    lambda: Wavelength,
    method: Method,
    profile: Option<ExactShape>,
) -> Result<Explanation, MultipoleError> {
    let with_profile = profile.is_some();
    let c = skin.coefficients(lambda);
    let epi = Medium::from_coefficients(&c.epidermis)?;
    let derm = Medium::from_coefficients(&c.dermis)?;
    let multipole_total = total_reflectance(skin, lambda, Method::Multipole)?;
    let exact_total = total_reflectance(skin, lambda, Method::Exact)?;
    let profile_scales = if with_profile && method == Method::Exact {
        let (scales, totals) = layer_scales(skin, lambda)?;
        let scaled = super::stack(skin, lambda)?
            .with_scales(scales.clone())?
            .total_reflectance(Poles::Exact);
        let e = scales[0];
        Some((
            [e.r_down, e.t_down, e.r_up, e.t_up, scales[1].r_down],
            totals.total / scaled,
        ))
    } else {
        None
    };
    Ok(Explanation {
        lambda_nm: lambda.nm(),
        method,
        epidermis_albedo_prime: epi.albedo_prime(),
        epidermis_mean_free_paths: skin.epidermis_thickness_mm() * epi.sigma_t_prime(),
        dermis_albedo_prime: derm.albedo_prime(),
        multipole_total,
        exact_total,
        profile_scales,
        shape: profile.filter(|_| method == Method::Exact),
        shape_photons: match (method, profile) {
            (Method::Exact, Some(ExactShape::MonteCarlo { escapes })) => {
                Some(shape_photons(escapes, exact_total, skin.eta()))
            }
            _ => None,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_optics::Preset;

    #[test]
    fn light_skin_diffusion_is_close_and_dark_skin_is_not() {
        let lambda = Wavelength::new(550.0).unwrap();
        let at = |preset, method| {
            explain(
                &SkinParams::preset(preset),
                lambda,
                method,
                Some(ExactShape::default()),
            )
            .unwrap()
        };
        let light = at(Preset::Light, Method::Exact);
        // BENCHMARKS.md `## Exact method`: light skin within −2.2% to +3.1% over 400–700 nm.
        assert!(light.diffusion_error().abs() < 0.035, "{light}");
        assert!(light.epidermis_albedo_prime > 0.9, "{light}");
        let dark = at(Preset::Dark, Method::Multipole);
        // Dark skin: diffusion at least 60% too bright, low-albedo epidermis; no profile factors asked.
        assert!(dark.diffusion_error() > 0.6, "{dark}");
        assert!(dark.epidermis_albedo_prime < light.epidermis_albedo_prime);
        assert!(dark.profile_scales.is_none());
        for (e, words) in [
            (&dark, ["550 nm", "wrong here", "--method exact"]),
            (
                &light,
                ["adding-doubling", "dermis R ×", "white Monte Carlo table"],
            ),
        ] {
            let text = e.to_string();
            assert!(words.iter().all(|w| text.contains(w)), "{text}");
        }
        // The final correction of the per-layer profile is small (the scalars ignore angles only).
        let (_, corr) = light.profile_scales.unwrap();
        assert!((corr - 1.0).abs() < 0.02, "{corr}");
    }
}
