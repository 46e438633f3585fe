//! `skin export`: every text format parses back with a real parser and holds the fitted values; the
//! MCML input read back and traced by our Monte Carlo gives `skin spectrum`'s exact totals; the
//! Burley and Gaussian fits hold their reported errors against a finer reference; doubling every
//! length doubles every exported radius; bad input ends in a one-line error.

use multipole::Method;
use multipole::exact::montecarlo::{McOptions, run};
use serde_json::Value;
use skin_export::burley::BurleyFit;
use skin_export::gaussians::GaussianFit;
use skin_export::rgb::{RgbProfile, shape_error};
use skin_export::spectral::SpectralSkin;
use skin_export::volume::VolumeFit;
use skin_export::{
    ColourSpace, ExportOptions, Format, Surface, export_rgb, export_spectral, mcml, rgb_profile,
};
use skin_optics::{Preset, SkinParams, WavelengthGrid};
use std::sync::OnceLock;

/// Test knobs: a 20-nm grid and 1,000-escape shapes keep the reference to about a second.
fn opts() -> ExportOptions {
    ExportOptions {
        grid: WavelengthGrid::new(400.0, 700.0, 20.0).unwrap(),
        escapes: 1_000,
        volume_photons: 4_000,
        photons: 30_000,
        ..ExportOptions::default()
    }
}

fn skin() -> SkinParams {
    SkinParams::preset(Preset::Light)
}

fn rgb() -> &'static RgbProfile {
    static RGB: OnceLock<RgbProfile> = OnceLock::new();
    RGB.get_or_init(|| rgb_profile(&skin(), &opts()).unwrap())
}

fn json(text: &str) -> Value {
    serde_json::from_str(text).unwrap()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    ((a - b) / b).abs() <= rel
}

/// The `value` attribute of MaterialX input `name`, as numbers.
fn mtlx_input(doc: &roxmltree::Document, name: &str) -> Vec<f64> {
    let node = doc
        .descendants()
        .find(|n| n.has_tag_name("input") && n.attribute("name") == Some(name))
        .unwrap_or_else(|| panic!("no input {name}"));
    node.attribute("value")
        .unwrap()
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect()
}

#[test]
fn materialx_parses_and_holds_the_medium_fit() {
    let o = opts();
    let surface = Surface::of(&skin());
    let fit = VolumeFit::fit(rgb(), 0.9, surface.eta, o.volume_photons).unwrap();
    // Values are written with 6 decimals: relative 1e-5 for numbers of order 1e-2 and above.
    for format in [Format::OpenPbr, Format::StandardSurface] {
        let e = export_rgb(format, rgb(), surface, &o).unwrap();
        let doc = roxmltree::Document::parse(&e.text).unwrap();
        assert_eq!(
            doc.root_element().attribute("colorspace"),
            Some("lin_rec709")
        );
        let colour = mtlx_input(&doc, "subsurface_color");
        let (radius, scale) = match format {
            Format::OpenPbr => (
                mtlx_input(&doc, "subsurface_radius")[0],
                mtlx_input(&doc, "subsurface_radius_scale"),
            ),
            _ => (
                mtlx_input(&doc, "subsurface_scale")[0],
                mtlx_input(&doc, "subsurface_radius"),
            ),
        };
        for c in 0..3 {
            assert!(close(colour[c], fit.colour[c], 1e-5), "{format} {colour:?}");
            assert!(
                close(radius * scale[c], fit.mean_free_path_mm[c], 1e-4),
                "{format}"
            );
        }
        let ior = match format {
            Format::OpenPbr => "specular_ior",
            _ => "specular_IOR",
        };
        assert_eq!(mtlx_input(&doc, ior), vec![1.4]);
    }
    // ACEScg is declared and changes the colours by the AP1 matrix.
    let aces = ExportOptions {
        colour_space: ColourSpace::AcesCg,
        ..o
    };
    let rgb_aces = rgb_profile(&skin(), &aces).unwrap();
    let want = ColourSpace::AcesCg.from_rec709(rgb().totals());
    for (got, want) in rgb_aces.totals().iter().zip(want) {
        assert!(close(*got, want, 1e-9));
    }
    // The medium is fitted in linear Rec.709: an ACEScg profile is refused, and the ACEScg
    // document is written from the Rec.709 one.
    assert!(export_rgb(Format::OpenPbr, &rgb_aces, surface, &aces).is_err());
    let e = export_rgb(Format::OpenPbr, rgb(), surface, &aces).unwrap();
    let doc = roxmltree::Document::parse(&e.text).unwrap();
    assert_eq!(doc.root_element().attribute("colorspace"), Some("acescg"));
}

/// A 3×3 matrix product.
fn matmul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// The inverse of a 3×3 matrix by its adjugate.
fn inverse(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    let det: f64 = (0..3).map(|j| m[0][j] * c(0, j)).sum();
    std::array::from_fn(|i| std::array::from_fn(|j| c(j, i) / det))
}

fn apply(m: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| m[i][k] * v[k]).sum())
}

/// RGB → XYZ of primaries and white given as CIE xy chromaticities (the white has Y = 1).
fn rgb_to_xyz(primaries: [[f64; 2]; 3], white: [f64; 2]) -> [[f64; 3]; 3] {
    let xyz = |[x, y]: [f64; 2]| [x / y, 1.0, (1.0 - x - y) / y];
    let cols = primaries.map(xyz);
    let p: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| cols[j][i]));
    let s = apply(inverse(p), xyz(white));
    std::array::from_fn(|i| std::array::from_fn(|j| p[i][j] * s[j]))
}

/// ACEScg → linear Rec.709 from the published definitions: AP1 primaries and the ACES white
/// (SMPTE ST 2065-1 / Academy S-2014-004), Rec.709 primaries and D65 (ITU-R BT.709), and the
/// Bradford chromatic adaptation from the ACES white to D65.
fn acescg_to_rec709() -> [[f64; 3]; 3] {
    let ap1 = rgb_to_xyz(
        [[0.713, 0.293], [0.165, 0.830], [0.128, 0.044]],
        [0.32168, 0.33767],
    );
    let rec709 = rgb_to_xyz([[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]], [0.3127, 0.3290]);
    let bradford = [
        [0.8951, 0.2664, -0.1614],
        [-0.7502, 1.7135, 0.0367],
        [0.0389, -0.0685, 1.0296],
    ];
    let white = |[x, y]: [f64; 2]| apply(bradford, [x / y, 1.0, (1.0 - x - y) / y]);
    let (src, dst) = (white([0.32168, 0.33767]), white([0.3127, 0.3290]));
    let scale = [
        [dst[0] / src[0], 0.0, 0.0],
        [0.0, dst[1] / src[1], 0.0],
        [0.0, 0.0, dst[2] / src[2]],
    ];
    let cat = matmul(inverse(bradford), matmul(scale, bradford));
    matmul(inverse(rec709), matmul(cat, ap1))
}

#[test]
fn acescg_radii_transformed_as_materialx_does_equal_the_rec709_file() {
    let o = opts();
    let surface = Surface::of(&skin());
    let m = acescg_to_rec709();
    // MaterialX's own acescg → lin_rec709 matrix (its stdlib colour-transform node), to 4 decimals.
    assert!(
        (m[0][0] - 1.70505).abs() < 2e-4 && (m[1][1] - 1.14080).abs() < 2e-4,
        "{m:?}"
    );
    for format in [Format::OpenPbr, Format::StandardSurface] {
        let read = |space: ColourSpace| {
            let e = export_rgb(
                format,
                rgb(),
                surface,
                &ExportOptions {
                    colour_space: space,
                    ..o
                },
            )
            .unwrap();
            let doc = roxmltree::Document::parse(&e.text).unwrap();
            let (radius, scale) = match format {
                Format::OpenPbr => (
                    mtlx_input(&doc, "subsurface_radius")[0],
                    mtlx_input(&doc, "subsurface_radius_scale"),
                ),
                _ => (
                    mtlx_input(&doc, "subsurface_scale")[0],
                    mtlx_input(&doc, "subsurface_radius"),
                ),
            };
            let colour = mtlx_input(&doc, "subsurface_color");
            (
                [0, 1, 2].map(|c| radius * scale[c]),
                [colour[0], colour[1], colour[2]],
            )
        };
        let (rec_radii, rec_colour) = read(ColourSpace::LinRec709);
        let (aces_radii, aces_colour) = read(ColourSpace::AcesCg);
        // MaterialX transforms every color3 input of an acescg document, radii included.
        let (radii, colour) = (apply(m, aces_radii), apply(m, aces_colour));
        for c in 0..3 {
            assert!(
                close(radii[c], rec_radii[c], 5e-3),
                "{format} {radii:?} vs {rec_radii:?}"
            );
            assert!(close(colour[c], rec_colour[c], 5e-3), "{format} {colour:?}");
        }
    }
}

/// The number after `name="NAME" value="` in a Mitsuba medium, as numbers.
fn mitsuba_values(medium: roxmltree::Node, name: &str) -> Vec<f64> {
    medium
        .children()
        .find(|n| n.attribute("name") == Some(name))
        .unwrap_or_else(|| panic!("no {name}"))
        .attribute("value")
        .unwrap()
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect()
}

#[test]
fn mitsuba_rgb_scene_configured_in_our_monte_carlo_returns_our_rgb_totals() {
    let s = skin();
    let o = ExportOptions {
        mitsuba_variant: skin_export::mitsuba::Variant::Rgb,
        scene: true,
        ..opts()
    };
    let grid = skin_export::mitsuba::spectral_grid(10.0).unwrap();
    let spectral = SpectralSkin::new(&s, &grid).unwrap();
    let e = export_spectral(Format::Mitsuba, &spectral, &s, Surface::of(&s), &o).unwrap();
    let doc = roxmltree::Document::parse(&e.text).unwrap();
    assert!(doc.descendants().any(|n| n.has_tag_name("sensor")));
    assert!(doc.descendants().any(|n| n.has_tag_name("emitter")));
    let media: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("medium"))
        .collect();
    // The dermis block's top face: translate z + scale z of the second cube.
    let epidermis_mm = skin().epidermis_thickness_mm();
    // Reference: the RGB of `skin spectrum`'s exact spectrum (per incident photon) over 400–700 nm,
    // independent of the channel fit.
    let rows = skin_cli::spectrum::rows(&s, &o.grid, Method::Exact).unwrap();
    let xyz = skin_optics::color::reflectance_to_xyz(
        &skin_optics::GridSpectrum::new(
            o.grid,
            rows.iter().map(|r| r.diffuse_reflectance).collect(),
        )
        .unwrap(),
    );
    let want = xyz.to_linear_srgb().0;
    for (c, &want) in want.iter().enumerate() {
        let layers: Vec<multipole::Layer> = media
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let sigma_t = mitsuba_values(*m, "scale")[0] * mitsuba_values(*m, "sigma_t")[c];
                let albedo = mitsuba_values(*m, "albedo")[c];
                assert!(mitsuba_values(*m, "sigma_t").iter().all(|v| *v <= 1.0));
                let (sa, ss) = (sigma_t * (1.0 - albedo), sigma_t * albedo);
                if i == 0 {
                    multipole::Layer::slab(sa, ss, 0.9, 1.4, epidermis_mm).unwrap()
                } else {
                    multipole::Layer::slab(sa, ss, 0.9, 1.4, o.dermis_thickness_mm).unwrap()
                }
            })
            .collect();
        let stack = multipole::LayeredMedium::new(layers, 1.0, 1.0).unwrap();
        let result = run(
            &stack,
            &McOptions::new(o.photons, 32, 40 + c as u64).unwrap(),
        );
        // The scene's stated normalisation: pixel − F(0) = diffuse reflectance per incident photon.
        // Colour integration at 10 nm against 400–700 nm moves the reference by < 0.1%, below σ.
        let z = result.diffuse_reflectance.z_score(want);
        assert!(
            z.abs() < 3.0,
            "{c}: MC {:?} vs {}",
            result.diffuse_reflectance,
            want
        );
    }
}

#[test]
fn mcx_input_configured_in_our_monte_carlo_returns_the_stated_per_entering_total() {
    let s = skin();
    let o = opts();
    let one = SpectralSkin::new(&s, &WavelengthGrid::new(550.0, 550.0, 1.0).unwrap()).unwrap();
    let e = export_spectral(Format::Mcx, &one, &s, Surface::of(&s), &o).unwrap();
    assert!(e.notes.iter().any(|n| n.contains("per photon entering")));
    let v = json(&e.text);
    let unit = v["Domain"]["LengthUnit"].as_f64().unwrap();
    let dim: Vec<f64> = v["Domain"]["Dim"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d.as_f64().unwrap())
        .collect();
    let epi_voxels = v["Shapes"][1]["ZLayers"][0][1].as_f64().unwrap();
    // One detector at the entry point holding the whole top face and not reaching the bottom.
    let det = &v["Optode"]["Detector"][0];
    let r = det["R"].as_f64().unwrap();
    assert!(
        r >= dim[0] / 2.0 * std::f64::consts::SQRT_2 && r < dim[2],
        "{r}"
    );
    assert_eq!(det["Pos"][2].as_f64(), Some(0.0));
    let media = v["Domain"]["Media"].as_array().unwrap();
    let layer = |i: usize, d: f64| {
        let m = &media[i];
        multipole::Layer::slab(
            m["mua"].as_f64().unwrap(),
            m["mus"].as_f64().unwrap(),
            m["g"].as_f64().unwrap(),
            m["n"].as_f64().unwrap(),
            d,
        )
        .unwrap()
    };
    let stack = multipole::LayeredMedium::new(
        vec![
            layer(1, epi_voxels * unit),
            layer(2, (dim[2] - epi_voxels) * unit),
        ],
        media[0]["n"].as_f64().unwrap(),
        1.0,
    )
    .unwrap();
    let result = run(&stack, &McOptions::new(o.photons, 32, 11).unwrap());
    // MCX counts per photon entering: our incident-photon estimate over 1 − specular.
    let entering = 1.0 - result.specular_reflectance;
    let (mean, se) = (
        result.diffuse_reflectance.mean / entering,
        result.diffuse_reflectance.stderr / entering,
    );
    let total = one.rows[0].total;
    assert!(
        ((mean - total) / se).abs() < 3.0,
        "MC {mean} ± {se} vs {total}"
    );
}

#[test]
fn what_a_format_cannot_carry_is_refused() {
    let s = skin();
    let aces = ExportOptions {
        colour_space: ColourSpace::AcesCg,
        ..opts()
    };
    for format in [
        Format::Unreal,
        Format::Hdrp,
        Format::Mcx,
        Format::Mcml,
        Format::Mitsuba,
        Format::Blender,
        Format::BlenderJson,
    ] {
        let err = skin_export::export(&s, format, &aces).unwrap_err();
        assert!(
            matches!(err, skin_export::ExportError::ColourSpace { .. }),
            "{format}: {err}"
        );
        assert!(err.to_string().contains("lin_rec709"), "{err}");
    }
    let mono = ExportOptions {
        mitsuba_variant: skin_export::mitsuba::Variant::Mono,
        lambda_nm: 900.0,
        ..opts()
    };
    let err = skin_export::export(&s, Format::Mitsuba, &mono).unwrap_err();
    assert!(err.to_string().contains("[360, 830] nm"), "{err}");
    // The Cycles table was measured at η = 1.4 only.
    let other_eta = s.with_eta(1.33).unwrap();
    let err = skin_export::export(&other_eta, Format::BlenderJson, &opts()).unwrap_err();
    assert!(err.to_string().contains("1.4"), "{err}");
    let err = "blender-yaml".parse::<Format>().unwrap_err();
    assert!(err.to_string().contains("blender-json"), "{err}");
}

#[test]
fn blender_values_return_our_diffuse_reflectance_through_the_cycles_table() {
    use skin_export::blender::{Calibration, CyclesMethod, cycles_albedo, cycles_radius_mm};
    let s = skin();
    let values = json(
        &skin_export::export(&s, Format::BlenderJson, &opts())
            .unwrap()
            .text,
    );
    let script = skin_export::export(&s, Format::Blender, &opts())
        .unwrap()
        .text;
    // The script carries the same values (its VALUES block) and builds the material by name.
    let block = script
        .split("r\"\"\"")
        .nth(1)
        .unwrap()
        .split("\"\"\"")
        .next()
        .unwrap();
    let mut from_script = json(block);
    let mut plain = values.clone();
    from_script.as_object_mut().unwrap().remove("notes");
    plain.as_object_mut().unwrap().remove("notes");
    assert_eq!(from_script, plain);
    assert!(script.contains("def subsurface_material(") && script.contains("def volume_slab("));
    // Target: our diffuse reflectance per incident photon = total per entering × (1 − F(0)).
    let f0 = skin_export::Surface::of(&s).f0();
    let target: Vec<f64> = rgb().totals().iter().map(|t| t * (1.0 - f0)).collect();
    for (c, t) in target.iter().enumerate() {
        assert!(close(
            values["target_diffuse_reflectance"][c].as_f64().unwrap(),
            *t,
            1e-12
        ));
    }
    for method in CyclesMethod::ALL {
        let v = &values["principled"][method.identifier()];
        let cal = Calibration::committed(method).unwrap();
        let scale = v["subsurface_scale"].as_f64().unwrap();
        for c in 0..3 {
            let base = v["base_color"][c].as_f64().unwrap();
            // The measured curve at the written Base Color is the target (bisection to 1e-12).
            assert!(
                close(cal.reflectance(base), target[c], 1e-9),
                "{method} {c}"
            );
            // Radius × Scale is Cycles' conversion of a reduced mean free path d > 0 whose walk
            // albedo is Cycles' remap of that Base Color.
            let radius = v["subsurface_radius"][c].as_f64().unwrap() * scale;
            let d = radius / cycles_radius_mm(method, 1.0, base, 1.4);
            assert!(d > 0.0 && d < 10.0, "{method} {c}: d = {d} mm");
            assert!(
                (v["walk_single_scattering_albedo"][c].as_f64().unwrap()
                    - cycles_albedo(base, 0.0))
                .abs()
                    < 1e-12
            );
        }
    }
    // The volume's layers return our per-entering totals (adding-doubling, bisection).
    for c in 0..3 {
        let total = values["volume"]["per_entering_totals"][c].as_f64().unwrap();
        assert!(close(total, rgb().totals()[c], 1e-6), "{c}: {total}");
        let e = &values["volume"]["epidermis"];
        let a = e["color"][c].as_f64().unwrap();
        assert!(a > 0.9 && a < 1.0 && e["density"].as_f64().unwrap() > 1.0);
    }
}

#[test]
fn engine_json_parses_and_holds_the_burley_fit() {
    let o = opts();
    let surface = Surface::of(&skin());
    let fit = BurleyFit::fit(rgb()).unwrap();
    let e = json(&export_rgb(Format::Unreal, rgb(), surface, &o).unwrap().text);
    let p = &e["subsurface_profile"];
    let distance_cm = p["mean_free_path_distance"].as_f64().unwrap();
    let mfp = fit.mean_free_path_mm();
    for (c, key) in ["R", "G", "B"].iter().enumerate() {
        let mm = 10.0 * distance_cm * p["mean_free_path_color"][key].as_f64().unwrap();
        assert!(close(mm, mfp[c], 1e-12), "{key}");
        assert!(close(
            p["surface_albedo"][key].as_f64().unwrap(),
            fit.albedo[c],
            1e-12
        ));
    }
    let e = json(&export_rgb(Format::Hdrp, rgb(), surface, &o).unwrap().text);
    let p = &e["diffusion_profile"];
    let m = p["scatteringDistanceMultiplier"].as_f64().unwrap();
    for (c, key) in ["r", "g", "b"].iter().enumerate() {
        assert!(close(
            m * p["scatteringDistance"][key].as_f64().unwrap(),
            fit.d_mm[c],
            1e-12
        ));
    }
    assert_eq!(p["ior"].as_f64(), Some(1.4));
    let e = json(&export_rgb(Format::Burley, rgb(), surface, &o).unwrap().text);
    for c in 0..3 {
        assert!(close(e["d_mm"][c].as_f64().unwrap(), fit.d_mm[c], 1e-12));
    }
    let e = json(
        &export_rgb(Format::Gaussians, rgb(), surface, &o)
            .unwrap()
            .text,
    );
    let g = GaussianFit::fit(rgb(), 6).unwrap();
    for k in 0..6 {
        assert!(close(
            e["variance_mm2"][k].as_f64().unwrap(),
            g.variances_mm2[k],
            1e-12
        ));
    }
    let w0: f64 = (0..6)
        .map(|k| e["weights_rgb"][k][0].as_f64().unwrap())
        .sum();
    assert!(close(w0, rgb().totals()[0], 1e-12));
}

/// `[ a b c ... ]` after `"spectrum NAME"` in a pbrt file, as (λ, value) pairs.
fn pbrt_spectrum(text: &str, name: &str) -> Vec<(f64, f64)> {
    let key = format!("\"spectrum {name}\"");
    let start = text.find(&key).unwrap() + key.len();
    let open = start + text[start..].find('[').unwrap() + 1;
    let close = open + text[open..].find(']').unwrap();
    let v: Vec<f64> = text[open..close]
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect();
    v.chunks(2).map(|p| (p[0], p[1])).collect()
}

#[test]
fn spectral_formats_parse_and_hold_our_layers() {
    let o = opts();
    let s = skin();
    let spectral = SpectralSkin::new(&s, &o.grid).unwrap();
    let surface = Surface::of(&s);
    // Mitsuba: two media, the epidermis' σt and albedo per wavelength over 360–830 nm (written to
    // 7 digits); a spectrum that stops short of that range is refused.
    assert!(matches!(
        export_spectral(Format::Mitsuba, &spectral, &s, surface, &o),
        Err(skin_export::ExportError::OutOfRange { .. })
    ));
    let spectral =
        SpectralSkin::new(&s, &skin_export::mitsuba::spectral_grid(20.0).unwrap()).unwrap();
    let e = export_spectral(Format::Mitsuba, &spectral, &s, surface, &o).unwrap();
    let doc = roxmltree::Document::parse(&e.text).unwrap();
    let media: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("medium"))
        .collect();
    assert_eq!(media.len(), 2);
    let sigma_t = media[0]
        .children()
        .find(|n| n.attribute("name") == Some("sigma_t"))
        .unwrap()
        .attribute("value")
        .unwrap();
    for (pair, row) in sigma_t.split(',').zip(&spectral.rows) {
        let (nm, v) = pair.trim().split_once(':').unwrap();
        assert_eq!(nm.parse::<f64>().unwrap(), row.lambda_nm);
        assert!(close(
            v.parse().unwrap(),
            row.layers[0].sigma_t_per_mm(),
            1e-6
        ));
    }
    let spectral = SpectralSkin::new(&s, &o.grid).unwrap();
    // MCX: media in mm⁻¹.
    let one = SpectralSkin::new(&s, &WavelengthGrid::new(550.0, 550.0, 1.0).unwrap()).unwrap();
    let e = json(
        &export_spectral(Format::Mcx, &one, &s, surface, &o)
            .unwrap()
            .text,
    );
    let media = &e["Domain"]["Media"];
    assert_eq!(media.as_array().unwrap().len(), 3);
    for (i, l) in one.rows[0].layers.iter().enumerate() {
        assert!(close(
            media[i + 1]["mua"].as_f64().unwrap(),
            l.sigma_a_per_mm,
            1e-12
        ));
        assert!(close(
            media[i + 1]["mus"].as_f64().unwrap(),
            l.sigma_s_per_mm,
            1e-12
        ));
    }
    // pbrt: the single-layer equivalent returns our total at every wavelength.
    let e = export_spectral(Format::Pbrt, &spectral, &s, surface, &o).unwrap();
    let sa = pbrt_spectrum(&e.text, "sigma_a");
    let ss = pbrt_spectrum(&e.text, "sigma_s");
    assert_eq!(sa.len(), spectral.rows.len());
    for ((&(nm, a), &(_, b)), row) in sa.iter().zip(&ss).zip(&spectral.rows) {
        assert_eq!(nm, row.lambda_nm);
        let total = skin_export::volume::semi_infinite_total(a, b, 0.9, 1.4).unwrap();
        // 7 significant digits written: the total moves by ≤ 1e-6 relative.
        assert!(
            close(total, row.total, 1e-5),
            "{nm}: {total} vs {}",
            row.total
        );
    }
}

#[test]
fn mcml_round_trip_reproduces_skin_spectrum_totals() {
    let s = skin();
    let grid = WavelengthGrid::new(450.0, 650.0, 100.0).unwrap();
    let o = ExportOptions { grid, ..opts() };
    let spectral = SpectralSkin::new(&s, &grid).unwrap();
    let e = export_spectral(Format::Mcml, &spectral, &s, Surface::of(&s), &o).unwrap();
    let runs = mcml::parse(&e.text).unwrap();
    let expected = skin_cli::spectrum::rows(&s, &grid, Method::Exact).unwrap();
    assert_eq!(runs.len(), expected.len());
    for (i, (mci, row)) in runs.iter().zip(&expected).enumerate() {
        let stack = mci.to_stack().unwrap();
        let result = run(
            &stack,
            &McOptions::new(mci.photons, 32, 7 + i as u64).unwrap(),
        );
        // 3σ of the Monte Carlo's batch standard error. Adding-doubling's own error at its
        // default quadrature is ≤ 0.02% for light skin and the 20-mm dermis transmits < 1e-6:
        // both far below σ (≈ 0.3% of R at 30,000 photons).
        let z = result.diffuse_reflectance.z_score(row.diffuse_reflectance);
        assert!(
            z.abs() < 3.0,
            "{} nm: MC {:?} vs exact {}",
            row.lambda_nm,
            result.diffuse_reflectance,
            row.diffuse_reflectance
        );
        assert!(result.transmittance.mean < 1e-6);
    }
}

#[test]
fn burley_and_gaussian_fits_hold_their_reported_errors_against_a_finer_reference() {
    // The fits' errors are reported against the 1,000-escape reference; a 4,000-escape reference
    // differs from it by its shape noise: [multipole README] measures 2.9-5.3% per wavelength at
    // 4,000 escapes (noise ∝ 1/√N: ≤ 10.6% at 1,000), and each RGB channel mixes ≥ 8 shape anchors
    // 20 nm apart, which averages the noise to ≤ 10.6%/√2 ≈ 7.5% in the worst channel.
    let finer = rgb_profile(
        &skin(),
        &ExportOptions {
            escapes: 4_000,
            ..opts()
        },
    )
    .unwrap();
    let allowance = 0.075;
    let burley = BurleyFit::fit(rgb()).unwrap();
    let gauss = GaussianFit::fit(rgb(), 6).unwrap();
    for c in 0..3 {
        let reference = finer.channel(c).unwrap();
        let d = burley.d_mm[c];
        let e = shape_error(&reference, |r| {
            skin_export::burley::reflectance_per_mm2(r, d)
        });
        assert!(
            e <= burley.shape_error[c] + allowance,
            "Burley {c}: {e} vs {:?}",
            burley.shape_error
        );
        let e = shape_error(&reference, |r| gauss.eval(c, r));
        assert!(
            e <= gauss.shape_error[c] + allowance,
            "Gauss {c}: {e} vs {:?}",
            gauss.shape_error
        );
        // The Burley d follows the mean radius, which the finer reference moves by < 5%.
        let d_fine = finer.mean_radius_mm(c) / 2.5;
        assert!(close(d, d_fine, 0.05), "{d} vs {d_fine}");
    }
    // Gaussians converge: six terms fit better than four.
    let four = GaussianFit::fit(rgb(), 4).unwrap();
    assert!(gauss.shape_error.iter().sum::<f64>() < four.shape_error.iter().sum::<f64>());
}

#[test]
fn doubling_every_length_doubles_every_exported_radius() {
    let o = opts();
    let (a, b) = (rgb().clone(), rgb().with_lengths_scaled(2.0));
    let (fa, fb) = (BurleyFit::fit(&a).unwrap(), BurleyFit::fit(&b).unwrap());
    let (ga, gb) = (
        GaussianFit::fit(&a, 5).unwrap(),
        GaussianFit::fit(&b, 5).unwrap(),
    );
    let (va, vb) = (
        VolumeFit::fit(&a, 0.9, 1.4, 2_000).unwrap(),
        VolumeFit::fit(&b, 0.9, 1.4, 2_000).unwrap(),
    );
    // Radii follow the profile exactly (the search grids are relative to its length scale):
    // rounding only.
    for c in 0..3 {
        assert!(close(fb.d_mm[c], 2.0 * fa.d_mm[c], 1e-9));
        assert!(close(
            fb.mean_free_path_mm()[c],
            2.0 * fa.mean_free_path_mm()[c],
            1e-9
        ));
        assert!(close(
            vb.mean_free_path_mm[c],
            2.0 * va.mean_free_path_mm[c],
            1e-9
        ));
        assert_eq!(vb.colour[c], va.colour[c]);
    }
    for k in 0..5 {
        assert!(close(gb.variances_mm2[k], 4.0 * ga.variances_mm2[k], 1e-9));
    }
    let surface = Surface::of(&skin());
    let hdrp = |r: &RgbProfile| {
        json(&export_rgb(Format::Hdrp, r, surface, &o).unwrap().text)["diffusion_profile"]
            ["filterRadius_mm"]
            .as_f64()
            .unwrap()
    };
    assert!(close(hdrp(&b), 2.0 * hdrp(&a), 1e-9));
    // Spectral: MCML thicknesses double, coefficients halve; MCX's voxel doubles.
    let s = skin();
    let sa = SpectralSkin::new(&s, &WavelengthGrid::new(550.0, 550.0, 1.0).unwrap()).unwrap();
    let sb = sa.with_lengths_scaled(2.0);
    let mci = |sp: &SpectralSkin| {
        mcml::parse(
            &export_spectral(Format::Mcml, sp, &s, surface, &o)
                .unwrap()
                .text,
        )
        .unwrap()
    };
    let (ma, mb) = (mci(&sa), mci(&sb));
    assert!(close(mb[0].layers[0][4], 2.0 * ma[0].layers[0][4], 1e-6));
    assert!(close(mb[0].layers[1][1], 0.5 * ma[0].layers[1][1], 1e-6));
    let voxel = |sp: &SpectralSkin| {
        json(
            &export_spectral(Format::Mcx, sp, &s, surface, &o)
                .unwrap()
                .text,
        )["Domain"]["LengthUnit"]
            .as_f64()
            .unwrap()
    };
    assert!(close(voxel(&sb), 2.0 * voxel(&sa), 1e-12));
}

/// Run the `skin` binary; (exit success, stderr).
fn skin_cmd(args: &[&str]) -> (bool, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_skin"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn bad_input_ends_in_one_line_naming_the_problem() {
    let dir = std::env::temp_dir().join(format!("skin-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let blocker = dir.join("file");
    std::fs::write(&blocker, b"x").unwrap();
    let target = blocker.join("skin.mci");
    let target = target.to_str().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (&["export", "cycles"], "unknown export format 'cycles'"),
        (&["export", "mitsuba", "--variant", "gray"], "--variant"),
        (&["export", "mcml", "--from", "200"], "--from"),
        (&["export", "mcml", "--colour-space", "xyz"], "lin_rec709"),
        (&["export", "mcml", "--out", target], "not a folder"),
    ];
    for (args, needle) in cases {
        let (ok, stderr) = skin_cmd(args);
        assert!(!ok, "{args:?}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(
            stderr.starts_with("error:") && stderr.contains(needle),
            "{stderr}"
        );
    }
    // A file in a folder that cannot be created: one line, nothing left behind.
    let (ok, stderr) = skin_cmd(&["export", "mcx", "--out", "/proc/skin-export/x.json"]);
    assert!(
        !ok && stderr.lines().filter(|l| l.starts_with("error:")).count() == 1,
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The Python that has the engines: $SKIN_ENGINES_PYTHON, else python3.
fn engines_python() -> String {
    std::env::var("SKIN_ENGINES_PYTHON").unwrap_or_else(|_| "python3".into())
}

#[test]
fn materialx_documents_pass_materialx_own_checks_where_it_is_installed() {
    let python = engines_python();
    let importable = std::process::Command::new(&python)
        .args(["-c", "import MaterialX"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !importable {
        eprintln!(
            "skipped: {python} cannot import MaterialX (pip install materialx, or set SKIN_ENGINES_PYTHON)"
        );
        return;
    }
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../validation/engines/materialx_check.py"
    );
    let dir = std::env::temp_dir().join(format!("skin-mtlx-check-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for format in [Format::OpenPbr, Format::StandardSurface] {
        for space in [ColourSpace::LinRec709, ColourSpace::AcesCg] {
            let o = ExportOptions {
                colour_space: space,
                ..opts()
            };
            let path = dir.join(format!("{format}_{space}.mtlx"));
            std::fs::write(
                &path,
                skin_export::export(&skin(), format, &o).unwrap().text,
            )
            .unwrap();
            let out = std::process::Command::new(&python)
                .arg(script)
                .arg(&path)
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{format} {space}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            let stdout = String::from_utf8_lossy(&out.stdout);
            let v = json(stdout.lines().last().unwrap());
            // MaterialX's validate() and every input known to the node's nodedef with its type.
            assert_eq!(
                v["valid"],
                Value::Bool(true),
                "{format} {space}: {}",
                v["message"]
            );
            assert_eq!(
                v["unknown_inputs"],
                serde_json::json!([]),
                "{format} {space}"
            );
            assert_eq!(v["colorspace"], space.materialx_name());
        }
        // The textured document: its inputs bound to image nodes pass the same checks.
        let texture = skin_export::textured::ChromophoreTexture {
            width: 2,
            height: 1,
            melanin: vec![0.01, 0.1],
            eumelanin: vec![0.6, 0.6],
            hemoglobin: vec![0.01, 0.05],
            thin: None,
        };
        let topts = skin_export::textured::TexturedOptions {
            nodes: 2,
            checks: 0,
        };
        let textured = skin_export::textured::export_textured(
            format,
            &skin(),
            &texture,
            &opts(),
            &topts,
            &|_, _| {},
        )
        .unwrap();
        let path = dir.join(format!("{format}_textured.mtlx"));
        std::fs::write(&path, textured.text).unwrap();
        let out = std::process::Command::new(&python)
            .arg(script)
            .arg(&path)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        let v = json(stdout.lines().last().unwrap());
        assert_eq!(
            v["valid"],
            Value::Bool(true),
            "{format} textured: {}",
            v["message"]
        );
        assert_eq!(
            v["unknown_inputs"],
            serde_json::json!([]),
            "{format} textured"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The channels of a maps.exr: melanin, eumelanin, hemoglobin per texel (row-major), without
/// the channel `skip`.
fn write_maps_exr(path: &std::path::Path, w: usize, h: usize, texels: &[[f32; 3]], skip: &str) {
    let channels = ["melanin", "eumelanin", "hemoglobin"]
        .iter()
        .enumerate()
        .filter(|(_, name)| **name != skip)
        .map(|(c, name)| (*name, texels.iter().map(|t| t[c]).collect()))
        .collect();
    std::fs::write(path, render::testing::hetero::exr_bytes(w, h, channels)).unwrap();
}

/// `skin export openpbr --maps`: the document and its two images are written together, the
/// document references them, each image has the maps' size, and the texels of each of the two
/// skins hold that skin's colour from the scalar export (within the grid's interpolation, here
/// exact: the two skins are the grid's corner nodes). A missing channel is a one-line error that
/// writes nothing.
#[test]
fn maps_become_texture_images_beside_the_document() {
    let tmp = tempfile::tempdir().unwrap();
    let maps = tmp.path().join("maps.exr");
    let (a, b) = ([0.02f32, 0.6, 0.01], [0.2f32, 0.6, 0.05]);
    let texels: Vec<[f32; 3]> = (0..8).map(|k| if k % 2 == 0 { a } else { b }).collect();
    write_maps_exr(&maps, 4, 2, &texels, "");
    let out = tmp.path().join("mat").join("skin.mtlx");
    let mut args = vec!["export", "openpbr", "--maps", maps.to_str().unwrap()];
    args.extend(["--out", out.to_str().unwrap()]);
    args.extend(crate::common::QUICK_EXPORT);
    args.extend(["--texture-nodes", "3"]);
    let (ok, stderr) = skin_cmd(&args);
    assert!(ok, "{stderr}");
    let text = std::fs::read_to_string(&out).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let files: Vec<&str> = doc
        .descendants()
        .filter(|n| n.attribute("type") == Some("filename"))
        .filter_map(|n| n.attribute("value"))
        .collect();
    assert_eq!(
        files,
        ["subsurface_color.exr", "subsurface_radius_scale.exr"]
    );
    let colour = exr::prelude::read_first_rgba_layer_from_file(
        out.with_file_name(files[0]),
        |size, _| (size.0, vec![[0.0f32; 3]; size.0 * size.1]),
        |t: &mut (usize, Vec<[f32; 3]>), pos, (r, g, b, _): (f32, f32, f32, f32)| {
            t.1[pos.1 * t.0 + pos.0] = [r, g, b];
        },
    )
    .unwrap();
    let (width, pixels) = &colour.layer_data.channel_data.pixels;
    assert_eq!((*width, pixels.len()), (4, 8));
    let o = ExportOptions {
        grid: WavelengthGrid::new(400.0, 700.0, 20.0).unwrap(),
        escapes: 500,
        volume_photons: 2000,
        ..ExportOptions::default()
    };
    for (k, p) in texels.iter().enumerate() {
        let skin = SkinParams::preset(Preset::Light)
            .with_melanin(f64::from(p[0]))
            .unwrap()
            .with_eumelanin_blend(f64::from(p[1]))
            .unwrap()
            .with_hemoglobin(f64::from(p[2]))
            .unwrap();
        let fit = VolumeFit::fit(
            &rgb_profile(&skin, &o).unwrap(),
            multipole::DEFAULT_G,
            1.4,
            2000,
        )
        .unwrap();
        for c in 0..3 {
            assert!(
                close(f64::from(pixels[k][c]), fit.colour[c], 1e-5),
                "texel {k} channel {c}: {:?} vs {:?}",
                pixels[k],
                fit.colour
            );
        }
    }
    let missing = tmp.path().join("no_blood.exr");
    write_maps_exr(&missing, 4, 2, &texels, "hemoglobin");
    let out2 = tmp.path().join("other").join("skin.mtlx");
    let mut args = vec!["export", "unreal", "--maps", missing.to_str().unwrap()];
    args.extend(["--out", out2.to_str().unwrap()]);
    let (ok, stderr) = skin_cmd(&args);
    assert!(
        !ok && stderr.contains("no channel 'hemoglobin'"),
        "{stderr}"
    );
    assert!(!out2.exists() && !out2.with_file_name("base_color.exr").exists());
}
