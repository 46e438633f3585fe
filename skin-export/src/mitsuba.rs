//! A Mitsuba 3 scene ([Mitsuba3]): the two-layer skin as volumes for `volpath`: a dielectric block
//! (air over index η) filled with the epidermis medium, holding an index-matched (`null`) block of
//! dermis medium below the epidermis' thickness; media `homogeneous` with spectral `albedo` and
//! `sigma_t` inline per wavelength and an HG phase function (docs/physics.md §14).

use crate::error::ExportError;
use crate::spectral::{LayerOptics, SpectralSkin};
use crate::{ExportOptions, Surface};
use std::fmt::Write;

/// Lateral half-width of the skin block, mm (far beyond any profile's 99.9% radius).
pub const HALF_WIDTH_MM: f64 = 100.0;

/// The scene XML and its notes.
pub fn write(
    spectral: &SpectralSkin,
    surface: Surface,
    opts: &ExportOptions,
) -> Result<(String, Vec<String>), ExportError> {
    let spectrum = |layer: usize, f: &dyn Fn(&LayerOptics) -> f64| -> String {
        spectral
            .rows
            .iter()
            .map(|r| format!("{}:{:.6e}", r.lambda_nm, f(&r.layers[layer])))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let first = &spectral.rows[0].layers;
    let epidermis_mm = first[0].thickness_mm.unwrap_or(0.0);
    let unit = opts.scene_unit_mm;
    let (w, total, epi) = (
        HALF_WIDTH_MM / unit,
        (epidermis_mm + opts.dermis_thickness_mm) / unit,
        epidermis_mm / unit,
    );
    let mut x = String::new();
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="utf-8"?>"#);
    let _ = writeln!(x, r#"<scene version="3.0.0">"#);
    let _ = writeln!(
        x,
        r#"    <integrator type="volpath"><integer name="max_depth" value="-1"/></integrator>"#
    );
    for (i, id) in ["epidermis", "dermis"].iter().enumerate() {
        let _ = writeln!(x, r#"    <medium type="homogeneous" id="{id}">"#);
        let _ = writeln!(
            x,
            r#"        <spectrum name="albedo" value="{}"/>"#,
            spectrum(i, &LayerOptics::albedo)
        );
        let _ = writeln!(
            x,
            r#"        <spectrum name="sigma_t" value="{}"/>"#,
            spectrum(i, &LayerOptics::sigma_t_per_mm)
        );
        let _ = writeln!(x, r#"        <float name="scale" value="{unit}"/>"#);
        let _ = writeln!(
            x,
            r#"        <phase type="hg"><float name="g" value="{}"/></phase>"#,
            first[i].g
        );
        let _ = writeln!(x, "    </medium>");
    }
    // The cube spans [−1, 1]³: scale by the half extents, translate the top face to z = 0.
    let block = |x: &mut String, id: &str, half_z: f64, centre_z: f64, half_w: f64| {
        let _ = writeln!(x, r#"    <shape type="cube" id="{id}">"#);
        let _ = writeln!(
            x,
            r#"        <transform name="to_world"><scale x="{half_w}" y="{half_w}" z="{half_z}"/><translate z="{centre_z}"/></transform>"#
        );
    };
    block(&mut x, "skin_epidermis", total / 2.0, -total / 2.0, w);
    let _ = writeln!(
        x,
        r#"        <bsdf type="dielectric"><float name="int_ior" value="{}"/><float name="ext_ior" value="{}"/></bsdf>"#,
        surface.eta, spectral.n_above
    );
    let _ = writeln!(x, r#"        <ref name="interior" id="epidermis"/>"#);
    let _ = writeln!(x, "    </shape>");
    // The dermis block sits inside the epidermis block, its top at −d, inset by 0.1% so that no two
    // faces coincide.
    let inset = 1e-3 * total;
    let dermis_half = (total - epi - inset) / 2.0;
    block(
        &mut x,
        "skin_dermis",
        dermis_half,
        -epi - dermis_half,
        w - inset,
    );
    let _ = writeln!(x, r#"        <bsdf type="null"/>"#);
    let _ = writeln!(x, r#"        <ref name="interior" id="dermis"/>"#);
    let _ = writeln!(x, r#"        <ref name="exterior" id="epidermis"/>"#);
    let _ = writeln!(x, "    </shape>");
    let _ = writeln!(x, "</scene>");
    let notes = vec![
        format!(
            "units: scene unit = {unit} mm (media \"scale\" = {unit}: sigma_t is given per mm); epidermis {epidermis_mm} mm, dermis {} mm thick (finite for the renderer), block {} mm wide",
            opts.dermis_thickness_mm,
            2.0 * HALF_WIDTH_MM
        ),
        "conventions: albedo = σs/σt (single scattering), sigma_t = σa + σs (not reduced), HG g; smooth dielectric face (the oily lobe is not written); add a sensor and emitter to render".to_string(),
        "accuracy: nothing lost by construction: the layers are ours, so volpath solves our transport exactly (only the finite dermis and block differ from the semi-infinite model)".to_string(),
    ];
    Ok((x, notes))
}
