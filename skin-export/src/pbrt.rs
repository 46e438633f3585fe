//! A pbrt-v4 `subsurface` material ([pbrt]): spectral σa and σs inline as wavelength–value pairs, g,
//! eta and scale. pbrt's subsurface model is one homogeneous semi-infinite medium, so each wavelength
//! gets [`single_layer_equivalent`]: the dermis' scattering with the absorption that returns our exact
//! two-layer total; its shape error is measured at 450, 550 and 650 nm (docs/physics.md §14).

use crate::error::ExportError;
use crate::rgb::{shape_error, total_error};
use crate::spectral::{SpectralSkin, single_layer_equivalent};
use crate::volume::{semi_infinite_profile, semi_infinite_total};
use crate::{ExportOptions, Surface};
use multipole::skin::ExactShape;
use multipole::{Method, ProfileOptions};
use skin_optics::{SkinParams, WavelengthGrid};
use std::fmt::Write;

/// Wavelengths at which the single-layer equivalent's shape is measured, nm.
pub const SHAPE_CHECK_NM: [f64; 3] = [450.0, 550.0, 650.0];

/// The pbrt scene fragment and its notes.
pub fn write(
    spectral: &SpectralSkin,
    skin: &SkinParams,
    surface: Surface,
    opts: &ExportOptions,
) -> Result<(String, Vec<String>), ExportError> {
    let mut equivalents = Vec::with_capacity(spectral.rows.len());
    let mut worst_total: f64 = 0.0;
    for row in &spectral.rows {
        let eq = single_layer_equivalent(row)?;
        let total = semi_infinite_total(eq.sigma_a_per_mm, eq.sigma_s_per_mm, eq.g, eq.n)?;
        worst_total = worst_total.max(total_error(row.total, total));
        equivalents.push((row.lambda_nm, eq));
    }
    let pairs = |f: &dyn Fn(&crate::spectral::LayerOptics) -> f64| -> String {
        equivalents
            .iter()
            .map(|(nm, l)| format!("{nm} {:.6e}", f(l)))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let g = equivalents.first().map_or(0.0, |(_, l)| l.g);
    let mut x = String::new();
    let _ = writeln!(x, "MakeNamedMaterial \"skin\"");
    let _ = writeln!(x, "    \"string type\" \"subsurface\"");
    let _ = writeln!(
        x,
        "    \"spectrum sigma_a\" [ {} ]",
        pairs(&|l| l.sigma_a_per_mm)
    );
    let _ = writeln!(
        x,
        "    \"spectrum sigma_s\" [ {} ]",
        pairs(&|l| l.sigma_s_per_mm)
    );
    let _ = writeln!(x, "    \"float g\" {g}");
    let _ = writeln!(x, "    \"float eta\" {}", surface.eta);
    let _ = writeln!(x, "    \"float scale\" {}", opts.scene_unit_mm);
    let _ = writeln!(x, "    \"float roughness\" {}", surface.beckmann_m.powi(2));
    let _ = writeln!(x, "    \"bool remaproughness\" true");
    let shapes = shape_check(skin, opts)?;
    let notes = vec![
        format!(
            "units: σa and σs in mm⁻¹ (not reduced), \"scale\" = {} mm per scene unit, so pbrt's coefficients per scene unit are σ × scale",
            opts.scene_unit_mm
        ),
        format!(
            "conventions: pbrt's subsurface is one semi-infinite layer: per wavelength the dermis' σs and g with the σa that returns our exact two-layer total (adding-doubling); roughness m² so that pbrt's remapped α = √roughness = m (Beckmann m ≈ GGX α); the oiliness ρ_s = {} has no pbrt parameter",
            surface.oiliness
        ),
        format!(
            "error of the single-layer equivalent against our exact two-layer skin: total ≤ {:.1e} (relative, every wavelength); shape (energy-weighted) {} at {} nm ({} photons)",
            worst_total,
            shapes
                .iter()
                .map(|e| format!("{:.1}%", 100.0 * e))
                .collect::<Vec<_>>()
                .join(" / "),
            SHAPE_CHECK_NM.map(|n| n.to_string()).join("/"),
            opts.volume_photons
        ),
    ];
    Ok((x, notes))
}

/// Shape error of the single-layer equivalent against our exact profile at [`SHAPE_CHECK_NM`].
pub fn shape_check(skin: &SkinParams, opts: &ExportOptions) -> Result<Vec<f64>, ExportError> {
    let profile_opts = ProfileOptions {
        exact_shape: ExactShape::MonteCarlo {
            escapes: opts.escapes,
        },
        ..ProfileOptions::default()
    };
    SHAPE_CHECK_NM
        .iter()
        .map(|&nm| {
            let grid = WavelengthGrid::new(nm, nm, 1.0)?;
            let spectral = SpectralSkin::new(skin, &grid)?;
            let eq = single_layer_equivalent(&spectral.rows[0])?;
            let (model, _) = semi_infinite_profile(
                eq.sigma_a_per_mm,
                eq.sigma_s_per_mm,
                eq.g,
                eq.n,
                opts.volume_photons,
            )?;
            let reference =
                multipole::skin::profile(skin, grid.wavelength(0), Method::Exact, &profile_opts)?;
            Ok(shape_error(&reference, |r| model.eval(r)))
        })
        .collect()
}
