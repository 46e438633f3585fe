//! MaterialX documents of OpenPBR Surface ([OpenPBR]) and Autodesk Standard Surface ([ASS]): the
//! subsurface medium of [`VolumeFit`] and the dielectric specular face (docs/physics.md §14.4).
//!
//! MaterialX colour-manages every `color3` input from the document's `colorspace` to the renderer's
//! working space, the radii (`subsurface_radius_scale`, Standard Surface's `subsurface_radius`)
//! included. The medium is therefore fitted once, in linear Rec.709, and every `color3` (colours
//! and radii alike) is written as its image in the document's space: MaterialX's transform back to
//! lin_rec709 then returns the fitted mean free paths, whatever space the file is declared in.

use crate::volume::VolumeFit;
use crate::{ExportOptions, Format, Surface, percent3};
use std::fmt::Write;

/// `a, b, c` with 6 significant decimals, as MaterialX writes a color3.
fn triple(v: [f64; 3]) -> String {
    format!("{:.6}, {:.6}, {:.6}", v[0], v[1], v[2])
}

/// The document for `format` (OpenPBR or Standard Surface) of a medium fitted in linear Rec.709,
/// its colours and radii written in `opts.colour_space`, and its notes.
#[must_use]
pub fn write(
    format: Format,
    fit: &VolumeFit,
    surface: Surface,
    opts: &ExportOptions,
) -> (String, Vec<String>) {
    let to_space = |v: [f64; 3]| opts.colour_space.from_rec709(v);
    let mfp_units = to_space(fit.mean_free_path_mm.map(|l| l / opts.scene_unit_mm));
    let radius = mfp_units.iter().copied().fold(0.0, f64::max);
    let scale = mfp_units.map(|l| l / radius);
    let space = opts.colour_space.materialx_name();
    let mut x = String::new();
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(x, r#"<materialx version="1.39" colorspace="{space}">"#);
    let input = |x: &mut String, name: &str, ty: &str, value: String| {
        let _ = writeln!(
            x,
            r#"    <input name="{name}" type="{ty}" value="{value}" />"#
        );
    };
    let (node, shader) = match format {
        Format::OpenPbr => ("open_pbr_surface", "skin_openpbr"),
        _ => ("standard_surface", "skin_standard_surface"),
    };
    let _ = writeln!(x, r#"  <{node} name="{shader}" type="surfaceshader">"#);
    let colour = triple(to_space(fit.colour));
    let roughness = format!("{:.6}", surface.ggx_roughness());
    let ior = format!("{:.6}", surface.eta);
    let weight = format!("{:.6}", surface.oiliness);
    let g = format!("{:.6}", fit.g);
    match format {
        Format::OpenPbr => {
            input(&mut x, "base_weight", "float", "1".into());
            input(&mut x, "base_color", "color3", colour.clone());
            input(&mut x, "subsurface_weight", "float", "1".into());
            input(&mut x, "subsurface_color", "color3", colour);
            input(&mut x, "subsurface_radius", "float", format!("{radius:.6}"));
            input(&mut x, "subsurface_radius_scale", "color3", triple(scale));
            input(&mut x, "subsurface_scatter_anisotropy", "float", g);
            input(&mut x, "specular_weight", "float", weight);
            input(&mut x, "specular_roughness", "float", roughness);
            input(&mut x, "specular_ior", "float", ior);
        }
        _ => {
            input(&mut x, "base", "float", "1".into());
            input(&mut x, "base_color", "color3", colour.clone());
            input(&mut x, "subsurface", "float", "1".into());
            input(&mut x, "subsurface_color", "color3", colour);
            input(&mut x, "subsurface_radius", "color3", triple(scale));
            input(&mut x, "subsurface_scale", "float", format!("{radius:.6}"));
            input(&mut x, "subsurface_anisotropy", "float", g);
            input(&mut x, "specular", "float", weight);
            input(&mut x, "specular_roughness", "float", roughness);
            input(&mut x, "specular_IOR", "float", ior);
        }
    }
    let _ = writeln!(x, "  </{node}>");
    let _ = writeln!(
        x,
        r#"  <surfacematerial name="skin" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="{shader}" />
  </surfacematerial>
</materialx>"#
    );
    let notes = vec![
        format!(
            "units: mean free paths (radius × scale) in scene units of {} mm: {:.5}/{:.5}/{:.5} mm (R/G/B, linear Rec.709 channels); colour space {space}: every color3 (colours and the radius colour) is the {space} image of the linear Rec.709 fit, so MaterialX's colour management to a lin_rec709 working space returns these mean free paths",
            opts.scene_unit_mm,
            fit.mean_free_path_mm[0],
            fit.mean_free_path_mm[1],
            fit.mean_free_path_mm[2]
        ),
        format!(
            "engine model: {}'s subsurface (MaterialX 1.39 nodedef {}); normalisation: subsurface_color is a fraction of the flux entering through the specular face (per entering photon)",
            if format == Format::OpenPbr {
                "OpenPBR Surface 1.1"
            } else {
                "Autodesk Standard Surface 1.0.1"
            },
            if format == Format::OpenPbr {
                "ND_open_pbr_surface_surfaceshader"
            } else {
                "ND_standard_surface_surfaceshader"
            },
        ),
        format!(
            "conventions: subsurface colour = multiple-scattering albedo C, our total per unit flux entering; mean free path = 1/μt of a semi-infinite HG medium (g = {}) under a dielectric of index {} whose single-scattering albedo ({:.6}/{:.6}/{:.6}) returns C and whose mean exit radius equals ours; specular weight = ρ_s, roughness √m with GGX α = m (Beckmann m = {})",
            fit.g,
            fit.eta,
            fit.single_scattering_albedo[0],
            fit.single_scattering_albedo[1],
            fit.single_scattering_albedo[2],
            surface.beckmann_m
        ),
        format!(
            "error against our exact RGB profiles: total {} (exact transport of that medium), shape {} (energy-weighted, medium traced with {} photons per channel); a renderer inverting C by van de Hulst's index-matched formula instead returns totals off by {}",
            percent3(fit.total_error, 4),
            percent3(fit.shape_error, 1),
            opts.volume_photons,
            percent3(fit.van_de_hulst_total_error, 1)
        ),
    ];
    (x, notes)
}

/// The document for `format` (OpenPBR or Standard Surface) whose subsurface colour and radius
/// colour come from the images `colour_file` and `radius_file` (declared in `space`), with the
/// scalar `radius` in scene units; the surface is `surface`'s.
#[must_use]
pub fn write_textured(
    format: Format,
    surface: Surface,
    space: &str,
    radius: f64,
    colour_file: &str,
    radius_file: &str,
) -> String {
    let mut x = String::new();
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(x, r#"<materialx version="1.39" colorspace="{space}">"#);
    for (name, file) in [
        ("subsurface_color_image", colour_file),
        ("radius_image", radius_file),
    ] {
        let _ = writeln!(
            x,
            r#"  <image name="{name}" type="color3">
    <input name="file" type="filename" value="{file}" colorspace="{space}" />
  </image>"#
        );
    }
    let value = |x: &mut String, name: &str, ty: &str, value: String| {
        let _ = writeln!(
            x,
            r#"    <input name="{name}" type="{ty}" value="{value}" />"#
        );
    };
    let image = |x: &mut String, name: &str, node: &str| {
        let _ = writeln!(
            x,
            r#"    <input name="{name}" type="color3" nodename="{node}" />"#
        );
    };
    let (node, shader) = match format {
        Format::OpenPbr => ("open_pbr_surface", "skin_openpbr"),
        _ => ("standard_surface", "skin_standard_surface"),
    };
    let _ = writeln!(x, r#"  <{node} name="{shader}" type="surfaceshader">"#);
    let roughness = format!("{:.6}", surface.ggx_roughness());
    let ior = format!("{:.6}", surface.eta);
    let weight = format!("{:.6}", surface.oiliness);
    let g = format!("{:.6}", multipole::DEFAULT_G);
    match format {
        Format::OpenPbr => {
            value(&mut x, "base_weight", "float", "1".into());
            image(&mut x, "base_color", "subsurface_color_image");
            value(&mut x, "subsurface_weight", "float", "1".into());
            image(&mut x, "subsurface_color", "subsurface_color_image");
            value(&mut x, "subsurface_radius", "float", format!("{radius:.6}"));
            image(&mut x, "subsurface_radius_scale", "radius_image");
            value(&mut x, "subsurface_scatter_anisotropy", "float", g);
            value(&mut x, "specular_weight", "float", weight);
            value(&mut x, "specular_roughness", "float", roughness);
            value(&mut x, "specular_ior", "float", ior);
        }
        _ => {
            value(&mut x, "base", "float", "1".into());
            image(&mut x, "base_color", "subsurface_color_image");
            value(&mut x, "subsurface", "float", "1".into());
            image(&mut x, "subsurface_color", "subsurface_color_image");
            image(&mut x, "subsurface_radius", "radius_image");
            value(&mut x, "subsurface_scale", "float", format!("{radius:.6}"));
            value(&mut x, "subsurface_anisotropy", "float", g);
            value(&mut x, "specular", "float", weight);
            value(&mut x, "specular_roughness", "float", roughness);
            value(&mut x, "specular_IOR", "float", ior);
        }
    }
    let _ = writeln!(x, "  </{node}>");
    let _ = writeln!(
        x,
        r#"  <surfacematerial name="skin" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="{shader}" />
  </surfacematerial>
</materialx>"#
    );
    x
}
