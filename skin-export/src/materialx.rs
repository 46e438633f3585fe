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
    let x = document(
        format,
        surface,
        space,
        fit.g,
        radius,
        &Colour3::Value(to_space(fit.colour)),
        &Colour3::Value(scale),
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

/// A `color3` input: a value, or an image file declared in the document's colour space.
#[derive(Debug, Clone, PartialEq)]
pub enum Colour3 {
    /// The same value at every point.
    Value([f64; 3]),
    /// An image file, read through an `image` node.
    Image(String),
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
    document(
        format,
        surface,
        space,
        multipole::DEFAULT_G,
        radius,
        &Colour3::Image(colour_file.to_string()),
        &Colour3::Image(radius_file.to_string()),
    )
}

/// The MaterialX document of `format` in colour space `space`: the surface shader with the
/// subsurface colour `colour` (also the base colour), the radius `radius` (scene units) times the
/// radius colour `radius_colour`, anisotropy `g`, and `surface`'s specular face.
fn document(
    format: Format,
    surface: Surface,
    space: &str,
    g: f64,
    radius: f64,
    colour: &Colour3,
    radius_colour: &Colour3,
) -> String {
    let mut x = String::new();
    let _ = writeln!(x, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(x, r#"<materialx version="1.39" colorspace="{space}">"#);
    let images = [
        ("subsurface_color_image", colour),
        ("radius_image", radius_colour),
    ];
    for (node, c) in &images {
        if let Colour3::Image(file) = c {
            let _ = writeln!(
                x,
                r#"  <image name="{node}" type="color3">
    <input name="file" type="filename" value="{file}" colorspace="{space}" />
  </image>"#
            );
        }
    }
    let scalar = |x: &mut String, name: &str, value: String| {
        let _ = writeln!(
            x,
            r#"    <input name="{name}" type="float" value="{value}" />"#
        );
    };
    let colour3 = |x: &mut String, name: &str, which: usize| {
        let (node, c) = images[which];
        let _ = match c {
            Colour3::Value(v) => writeln!(
                x,
                r#"    <input name="{name}" type="color3" value="{}" />"#,
                triple(*v)
            ),
            Colour3::Image(_) => writeln!(
                x,
                r#"    <input name="{name}" type="color3" nodename="{node}" />"#
            ),
        };
    };
    let (node, shader) = match format {
        Format::OpenPbr => ("open_pbr_surface", "skin_openpbr"),
        _ => ("standard_surface", "skin_standard_surface"),
    };
    let _ = writeln!(x, r#"  <{node} name="{shader}" type="surfaceshader">"#);
    let roughness = format!("{:.6}", surface.ggx_roughness());
    let ior = format!("{:.6}", surface.eta);
    let weight = format!("{:.6}", surface.oiliness);
    let g = format!("{g:.6}");
    match format {
        Format::OpenPbr => {
            scalar(&mut x, "base_weight", "1".into());
            colour3(&mut x, "base_color", 0);
            scalar(&mut x, "subsurface_weight", "1".into());
            colour3(&mut x, "subsurface_color", 0);
            scalar(&mut x, "subsurface_radius", format!("{radius:.6}"));
            colour3(&mut x, "subsurface_radius_scale", 1);
            scalar(&mut x, "subsurface_scatter_anisotropy", g);
            scalar(&mut x, "specular_weight", weight);
            scalar(&mut x, "specular_roughness", roughness);
            scalar(&mut x, "specular_ior", ior);
        }
        _ => {
            scalar(&mut x, "base", "1".into());
            colour3(&mut x, "base_color", 0);
            scalar(&mut x, "subsurface", "1".into());
            colour3(&mut x, "subsurface_color", 0);
            colour3(&mut x, "subsurface_radius", 1);
            scalar(&mut x, "subsurface_scale", format!("{radius:.6}"));
            scalar(&mut x, "subsurface_anisotropy", g);
            scalar(&mut x, "specular", weight);
            scalar(&mut x, "specular_roughness", roughness);
            scalar(&mut x, "specular_IOR", ior);
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
