//! JSON for the real-time engines and profile models: Unreal's Subsurface Profile and Unity HDRP's
//! diffusion profile (both Christensen–Burley, [CB15]), the Burley fit itself, and sums of Gaussians
//! ([dEL07]); docs/physics.md §14.

use crate::burley::{self, BurleyFit};
use crate::gaussians::GaussianFit;
use crate::{ExportOptions, Format, Surface, percent3};
use serde_json::{Value, json};

/// Centimetres per millimetre (Unreal's unit).
const CM_PER_MM: f64 = 0.1;
/// Energy fraction HDRP's filter radius holds (its `SampleBurleyDiffusionProfile(0.997, …)`).
pub const HDRP_FILTER_ENERGY: f64 = 0.997;
/// Unreal's `Specular` input maps to F0 = 0.08 × Specular.
const UNREAL_F0_PER_SPECULAR: f64 = 0.08;

fn colour(v: [f64; 3]) -> Value {
    json!({ "R": v[0], "G": v[1], "B": v[2], "A": 1.0 })
}

fn normalised(v: [f64; 3]) -> ([f64; 3], f64) {
    let m = v.iter().copied().fold(0.0, f64::max);
    (v.map(|x| x / m), m)
}

fn error_note(fit: &BurleyFit) -> String {
    format!(
        "error against our exact RGB profiles: total {}, shape {} (energy-weighted, Burley normalized diffusion)",
        percent3(fit.total_error, 4),
        percent3(fit.shape_error, 1)
    )
}

/// The Unreal, HDRP or Burley JSON of `fit` and its notes.
#[must_use]
pub fn write(
    format: Format,
    fit: &BurleyFit,
    surface: Surface,
    opts: &ExportOptions,
) -> (String, Vec<String>) {
    let space = opts.colour_space.materialx_name();
    let (value, units) = match format {
        Format::Unreal => {
            let (mfp_colour, mfp_mm) = normalised(fit.mean_free_path_mm());
            (
                json!({
                    "subsurface_profile": {
                        "surface_albedo": colour(fit.albedo),
                        "mean_free_path_color": colour(mfp_colour),
                        "mean_free_path_distance": mfp_mm * CM_PER_MM,
                        "world_unit_scale": 0.1,
                        "enable_burley": true,
                        "enable_mean_free_path": true,
                        "ior": surface.eta,
                    },
                    "material": {
                        "roughness": surface.ggx_roughness(),
                        "specular": surface.oiliness * surface.f0() / UNREAL_F0_PER_SPECULAR,
                    },
                }),
                format!(
                    "units: mean_free_path_distance in cm (Unreal units), × mean_free_path_color per channel; world_unit_scale left at the engine default 0.1; colours linear {space}; conventions: Burley with mean free path ℓ = d · (1.85 − A + 7|A − 0.8|³) [CB15], material specular = ρ_s F0(η)/0.08, roughness √m"
                ),
            )
        }
        Format::Hdrp => {
            let (scatter_colour, d_max) = normalised(fit.d_mm);
            (
                json!({
                    "diffusion_profile": {
                        "scatteringDistance": { "r": scatter_colour[0], "g": scatter_colour[1], "b": scatter_colour[2], "a": 1.0 },
                        "scatteringDistanceMultiplier": d_max,
                        "worldScale": 1.0,
                        "ior": surface.eta,
                        "filterRadius_mm": burley::radius_for_energy(HDRP_FILTER_ENERGY, d_max),
                    },
                    "material": {
                        "baseColor": { "r": fit.albedo[0], "g": fit.albedo[1], "b": fit.albedo[2] },
                        "smoothness": 1.0 - surface.ggx_roughness(),
                    },
                }),
                format!(
                    "units: scattering colour × multiplier = Burley d per channel in mm (HDRP's shape parameter 1/d), worldScale 1 (1 unit = 1 m); filterRadius_mm = radius holding 99.7% of the widest channel's energy, as HDRP computes it; base colour = albedo A (linear {space}); smoothness = 1 − √m"
                ),
            )
        }
        _ => (
            json!({
                "model": "Christensen-Burley normalized diffusion: R(r) = A (exp(-r/d) + exp(-r/(3d))) / (8 pi d r)",
                "colour_space": space,
                "albedo": fit.albedo,
                "d_mm": fit.d_mm,
                "mean_free_path_mm": fit.mean_free_path_mm(),
                "total_error": fit.total_error,
                "shape_error": fit.shape_error,
            }),
            format!(
                "units: d and mean free path in mm; albedo linear {space}; conventions: d = our mean radial distance / 2.5, A = our total per unit flux entering"
            ),
        ),
    };
    let text = serde_json::to_string_pretty(&value).expect("a JSON value serialises");
    (text, vec![units, error_note(fit)])
}

/// The sum-of-Gaussians JSON: the last of `fits` is written, all are reported.
#[must_use]
pub fn write_gaussians(fits: &[GaussianFit], opts: &ExportOptions) -> (String, Vec<String>) {
    let chosen = fits.last().expect("at least one fit");
    let value = json!({
        "model": "sum of Gaussians: R(r) = sum_k w_k exp(-r^2 / (2 v_k)) / (2 pi v_k)",
        "colour_space": opts.colour_space.materialx_name(),
        "variance_mm2": chosen.variances_mm2,
        "weights_rgb": chosen.weights,
        "shape_error": chosen.shape_error,
    });
    let mut notes = vec![format!(
        "units: variances in mm², weights per channel linear {} summing to our total per unit flux entering (total error 0 by construction)",
        opts.colour_space.materialx_name()
    )];
    for fit in &fits[..fits.len() - 1] {
        notes.push(format!(
            "{} Gaussians: energy-weighted shape error {}",
            fit.variances_mm2.len(),
            percent3(fit.shape_error, 1)
        ));
    }
    notes.push(format!(
        "written: {} Gaussians, shape error {}",
        chosen.variances_mm2.len(),
        percent3(chosen.shape_error, 1)
    ));
    (
        serde_json::to_string_pretty(&value).expect("a JSON value serialises"),
        notes,
    )
}
