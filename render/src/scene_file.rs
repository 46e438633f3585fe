//! The scene file format: TOML mapped onto these serde structs (`deny_unknown_fields`), then turned
//! into validated types by `scene`. Lengths are in millimetres; keys carry their unit.
//!
//! ```toml
//! [camera]
//! position_mm = [0, 0, 900]
//! look_at_mm = [0, 0, 0]
//! fov_deg = 30
//!
//! [environment]            # optional; absent = black
//! spectrum = "d65"         # "d65", "constant" or "blackbody" (+ temperature_k); or exr = "sky.exr"
//! intensity = 0.05         # luminance Y of the emitted radiance
//! # spectral_radiance = 1  # instead: the same spectral radiance at every wavelength (validation)
//!
//! [materials.face]
//! type = "skin"
//! preset = "light"         # light (= paper), medium, dark, or a measured preset (`skin presets`:
//!                          # ca-forehead, ..., ita-tan); melanin, eumelanin, hemoglobin, oil override it
//! albedo_texture = "builtin:Map-COL.jpg"
//! phase_g = 0.9            # HG anisotropy of both layers, [0, 0.99] (default 0.9)
//! surface = "oily"         # "oily" (Torrance–Sparrow lobe, default) or "smooth" (dielectric, η = 1.4)
//!
//! [materials.wall]
//! type = "diffuse"
//! albedo = 0.05            # or albedo_srgb = [r, g, b], or albedo_spectrum = [[nm, value], ...]
//!
//! [[meshes]]
//! file = "builtin:LeePerrySmith.glb"   # .glb or .obj, relative to the scene file; or shape = "sphere" / "quad"
//! material = "face"
//! units_mm = 45            # millimetres per model unit
//! translate_mm = [0, 0, 0]
//!
//! [[lights]]
//! type = "sphere"          # point, spot, distant, sphere, quad
//! center_mm = [500, 400, 800]
//! radius_mm = 100
//! spectrum = "blackbody"
//! temperature_k = 5500
//! intensity = 20
//! ```
//!
//! The light variants repeat the same field shape (a documented key with its serde checker) because
//! each kind of light has its own keys; the checkers are shared.

use serde::Deserialize;
use serde::de::{Deserializer, Error as _};
use skin_optics::echo::Num;
use std::collections::BTreeMap;

/// Longest parser message kept, characters (the parser may quote a whole offending value).
const MAX_MESSAGE_CHARS: usize = 200;

/// Parse scene text into its description; a syntax or schema error comes back on one line,
/// `line L, column C: message`.
pub fn parse(text: &str) -> Result<SceneDesc, String> {
    toml::from_str(text).map_err(|e: toml::de::Error| {
        let mut message: String = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
        if let Some((cut, _)) = message.char_indices().nth(MAX_MESSAGE_CHARS) {
            message.truncate(cut);
            message.push('…');
        }
        match e.span() {
            Some(span) => {
                let before = &text[..span.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
                format!("line {line}, column {column}: {message}")
            }
            None => message,
        }
    })
}

/// A number as f32: finite and within f32's range (TOML reads f64; 1e39 would become ∞).
fn to_f32<E: serde::de::Error>(x: f64) -> Result<f32, E> {
    if x.is_finite() && x.abs() <= f64::from(f32::MAX) {
        Ok(x as f32)
    } else {
        Err(E::custom(format!(
            "expected a finite number within ±3.4e38, got {}",
            Num(x)
        )))
    }
}

/// Exactly `N` finite numbers (extra or missing elements are an error, not ignored).
fn finite_array<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f32; N], D::Error> {
    let v: Vec<f64> = Vec::deserialize(d)?;
    if v.len() != N {
        return Err(D::Error::custom(format!(
            "expected an array of {N} numbers, got {} elements",
            v.len()
        )));
    }
    let mut out = [0.0; N];
    for (o, &x) in out.iter_mut().zip(&v) {
        *o = to_f32(x)?;
    }
    Ok(out)
}

fn vec3<'de, D: Deserializer<'de>>(d: D) -> Result<[f32; 3], D::Error> {
    finite_array::<D, 3>(d)
}

fn vec2<'de, D: Deserializer<'de>>(d: D) -> Result<[f32; 2], D::Error> {
    finite_array::<D, 2>(d)
}

fn opt_vec3<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f32; 3]>, D::Error> {
    vec3(d).map(Some)
}

fn finite<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    to_f32(f64::deserialize(d)?)
}

fn opt_finite<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f32>, D::Error> {
    finite(d).map(Some)
}

fn opt_finite_f64<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    let x = f64::deserialize(d)?;
    if x.is_finite() {
        Ok(Some(x))
    } else {
        Err(D::Error::custom(format!(
            "expected a finite number, got {x}"
        )))
    }
}

/// `[nm, value]` pairs, each exactly two finite numbers.
fn pairs<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<[f64; 2]>>, D::Error> {
    let rows: Vec<Vec<f64>> = Vec::deserialize(d)?;
    rows.iter()
        .enumerate()
        .map(|(i, r)| match r[..] {
            [nm, v] if nm.is_finite() && v.is_finite() => Ok([nm, v]),
            [_, _] => Err(D::Error::custom(format!(
                "element {i}: expected finite [nm, value], got [{}, {}]",
                Num(r[0]),
                Num(r[1])
            ))),
            _ => Err(D::Error::custom(format!(
                "element {i}: expected [nm, value], got {} numbers",
                r.len()
            ))),
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// The camera.
    pub camera: CameraDesc,
    /// Film settings.
    #[serde(default)]
    pub film: FilmDesc,
    /// Light arriving from far away (absent = black).
    pub environment: Option<EnvironmentDesc>,
    /// Named materials.
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialDesc>,
    /// Meshes.
    #[serde(default)]
    pub meshes: Vec<MeshDesc>,
    /// Lights.
    #[serde(default)]
    pub lights: Vec<LightDesc>,
    /// The fidelity of the skin materials (each key overridden by its command-line flag).
    pub fidelity: Option<FidelityDesc>,
}

/// `[fidelity]`: the scene's own choices (`render::fidelity`; docs/physics.md §16).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FidelityDesc {
    /// "auto" or "full".
    pub fidelity: Option<String>,
    /// Energy left beyond each profile row, a fraction in (0, 0.1].
    pub energy_tolerance: Option<f64>,
    /// Interpolation error target of the radius grid, in (0, 0.1].
    pub radial_error: Option<f64>,
    /// Wavelength step of the skin tables, nm.
    pub wavelength_step_nm: Option<f64>,
    /// Level of detail: "off", or the band [LO, HI] in pixel footprints per r99.
    pub lod: Option<LodDesc>,
    /// Local thickness, in r99, below which a hit takes the volumetric walk, in [0, 10] (0: never).
    pub thin_walk: Option<f64>,
    /// Photons of the universal shape table, in [1e4, 1e9] (auto: from the pixel footprint).
    pub shape_photons: Option<u64>,
}

/// `fidelity.lod`: "off" or [LO, HI].
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum LodDesc {
    /// "off".
    Word(String),
    /// [LO, HI].
    Band([f32; 2]),
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position, mm.
    #[serde(deserialize_with = "vec3")]
    pub position_mm: [f32; 3],
    /// Point looked at, mm.
    #[serde(deserialize_with = "vec3")]
    pub look_at_mm: [f32; 3],
    /// Up hint (default +Y).
    #[serde(default = "default_up", deserialize_with = "vec3")]
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    #[serde(deserialize_with = "finite")]
    pub fov_deg: f32,
    /// Lens aperture diameter, mm (0 = pinhole).
    #[serde(default, deserialize_with = "finite")]
    pub aperture_mm: f32,
    /// Distance of the plane in focus, mm (default: the look-at distance).
    #[serde(default, deserialize_with = "opt_finite")]
    pub focus_distance_mm: Option<f32>,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

/// `[film]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FilmDesc {
    /// Exposure of the PNG, stops (the EXR is unscaled).
    #[serde(default, deserialize_with = "finite")]
    pub exposure_stops: f32,
}

/// The shape of an emission spectrum.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum SpectrumKind {
    /// CIE D65.
    D65,
    /// Equal energy.
    Constant,
    /// Planck blackbody at `temperature_k`.
    Blackbody,
}

/// `[environment]`: a constant spectrum or a lat-long EXR map, times `intensity`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    /// Spectrum of a constant environment (ignored with `exr`; default d65).
    pub spectrum: Option<SpectrumKind>,
    /// Blackbody temperature, K.
    #[serde(default, deserialize_with = "opt_finite_f64")]
    pub temperature_k: Option<f64>,
    /// Lat-long linear-sRGB OpenEXR map.
    pub exr: Option<String>,
    /// Luminance of a constant environment, or the map's multiplier (required unless
    /// `spectral_radiance` is given).
    #[serde(default, deserialize_with = "opt_finite")]
    pub intensity: Option<f32>,
    /// A constant environment of this spectral radiance at every wavelength, in the scene's
    /// emission units (instead of `spectrum` and `intensity`; ≥ 0).
    #[serde(default, deserialize_with = "opt_finite")]
    pub spectral_radiance: Option<f32>,
}

/// `[materials.NAME]`.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
// Parsed once per material and dropped after loading: boxing the skin's keys would only add a
// level to every pattern that reads them.
#[allow(clippy::large_enum_variant)]
pub enum MaterialDesc {
    /// Skin: a preset with optional explicit fractions.
    Skin {
        /// A seed preset (light = paper, medium, dark) or a measured one (`skin presets`); default light.
        preset: Option<String>,
        /// Melanin fraction C_m, [0, 1].
        melanin: Option<f64>,
        /// Eumelanin blend β_m, [0, 1].
        eumelanin: Option<f64>,
        /// Hemoglobin fraction C_h, [0, 1].
        hemoglobin: Option<f64>,
        /// Oiliness ρ_s, [0, 1].
        oil: Option<f64>,
        /// Beckmann roughness m of the surface (default 0.3).
        #[serde(default, deserialize_with = "opt_finite")]
        roughness: Option<f32>,
        /// sRGB albedo texture (JPEG/PNG).
        albedo_texture: Option<String>,
        /// Henyey–Greenstein anisotropy g of both layers, [0, 0.99] (default 0.9).
        #[serde(default, deserialize_with = "opt_finite_f64")]
        phase_g: Option<f64>,
        /// Surface model: "oily" (default) or "smooth".
        surface: Option<String>,
        /// Chromophore maps over the mesh's texture coordinates: the `maps.exr` of `skin maps`
        /// (channels `melanin`, `eumelanin`, `hemoglobin`; others ignored).
        maps: Option<String>,
        /// Chromophore maps fitted to `albedo_texture` at load, as `skin maps --exposure VALUE`
        /// fits them (`1`: the texture is the skin's albedo; `auto`, `auto-rgb`, `G` or `R,G,B`:
        /// gains for a photograph), kept in the disk cache; instead of `maps`.
        fit_maps: Option<String>,
        /// C_m per texel: a single-channel EXR or a grey 8/16-bit PNG holding the value (instead
        /// of the `melanin` channel of `maps`).
        melanin_map: Option<String>,
        /// β_m per texel (as `melanin_map`).
        eumelanin_map: Option<String>,
        /// C_h per texel (as `melanin_map`).
        hemoglobin_map: Option<String>,
        /// Scale s of the load-time edit C_m' = C_m + m (s C_m + o − C_m) (default 1).
        #[serde(default, deserialize_with = "opt_finite_f64")]
        melanin_scale: Option<f64>,
        /// Offset o of the melanin edit (default 0).
        #[serde(default, deserialize_with = "opt_finite_f64")]
        melanin_offset: Option<f64>,
        /// ITA° of the maps' typical skin (docs/physics.md §19), [−90, 90]: the melanin offset
        /// that brings it there is solved at load, instead of `melanin_offset`.
        #[serde(default, deserialize_with = "opt_finite_f64")]
        melanin_ita_deg: Option<f64>,
        /// Scale of the hemoglobin edit (default 1).
        #[serde(default, deserialize_with = "opt_finite_f64")]
        hemoglobin_scale: Option<f64>,
        /// Offset of the hemoglobin edit (default 0).
        #[serde(default, deserialize_with = "opt_finite_f64")]
        hemoglobin_offset: Option<f64>,
        /// Mask m in [0, 1] weighting the edits per texel (as `melanin_map`; default 1 everywhere).
        edit_mask: Option<String>,
        /// How the BSSRDF combines the profiles of a path's two ends in different skin: "exit",
        /// "entry", "mean" or "geometric" (default; docs/physics.md §19.3).
        profile_blend: Option<String>,
        /// Target of the profile grid's measured interpolation error, (0, 1) (default 0.02).
        #[serde(default, deserialize_with = "opt_finite")]
        map_profile_error: Option<f32>,
        /// Target of the incidence gain grid's measured interpolation error, (0, 1) (default
        /// 0.005; docs/physics.md §19.3).
        #[serde(default, deserialize_with = "opt_finite")]
        map_incidence_error: Option<f32>,
        /// Whether texels flagged in the maps' `thin_epidermis` channel (or fitted so by
        /// `fit_maps`) take the thin epidermis (default true; false: every texel keeps its
        /// chromophores under the material's epidermis).
        thin_epidermis: Option<bool>,
        /// The thin epidermis' thickness, mm, (0, 10] (default: maps.exr's `thin_epidermis_mm`
        /// attribute; with `fit_maps`, the fit's, 0.05 mm by default).
        #[serde(default, deserialize_with = "opt_finite_f64")]
        thin_epidermis_mm: Option<f64>,
    },
    /// Lambertian.
    Diffuse {
        /// Constant albedo.
        #[serde(default, deserialize_with = "opt_finite")]
        albedo: Option<f32>,
        /// sRGB-encoded albedo colour.
        #[serde(default, deserialize_with = "opt_vec3")]
        albedo_srgb: Option<[f32; 3]>,
        /// Albedo samples `[nm, value]`, linearly interpolated.
        #[serde(default, deserialize_with = "pairs")]
        albedo_spectrum: Option<Vec<[f64; 2]>>,
        /// sRGB albedo texture multiplying the albedo.
        albedo_texture: Option<String>,
    },
}

/// Procedural shapes.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    /// Unit-radius sphere (icosphere, 5120 triangles).
    Sphere,
    /// The square [−1, 1]² in the XY plane facing +Z.
    Quad,
}

/// `[[meshes]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshDesc {
    /// Mesh file (.glb or .obj), relative to the scene file, or `builtin:NAME`.
    pub file: Option<String>,
    /// A procedural shape instead of a file.
    pub shape: Option<ShapeKind>,
    /// Material name.
    pub material: String,
    /// Millimetres per model unit (default 1).
    #[serde(default = "one", deserialize_with = "finite")]
    pub units_mm: f32,
    /// Extra uniform scale (default 1).
    #[serde(default = "one", deserialize_with = "finite")]
    pub scale: f32,
    /// Rotation about X, Y, Z, degrees (applied in that order).
    #[serde(default, deserialize_with = "vec3")]
    pub rotate_deg: [f32; 3],
    /// Translation, mm.
    #[serde(default, deserialize_with = "vec3")]
    pub translate_mm: [f32; 3],
    /// Use v → 1 − v for texture lookups (OpenGL-style UVs, e.g. the head scan).
    #[serde(default)]
    pub flip_v: bool,
}

fn one() -> f32 {
    1.0
}

/// `[[lights]]`; every light has `spectrum` (default d65), `temperature_k` (blackbody) and `intensity`
/// in [0, 1e30] (`light::MAX_INTENSITY`; the environment's too). Positions lie within ±1e9 mm and
/// sizes (`radius_mm`, `size_mm`) in (0, 1e9] mm, as the geometry's coordinates.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum LightDesc {
    /// Isotropic point light; intensity is radiant intensity (irradiance × mm²).
    Point {
        /// Position, mm.
        #[serde(deserialize_with = "vec3")]
        position_mm: [f32; 3],
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        #[serde(default, deserialize_with = "opt_finite_f64")]
        temperature_k: Option<f64>,
        /// Luminous scale.
        #[serde(deserialize_with = "finite")]
        intensity: f32,
    },
    /// Spot light.
    Spot {
        /// Position, mm.
        #[serde(deserialize_with = "vec3")]
        position_mm: [f32; 3],
        /// Point on the cone axis, mm.
        #[serde(deserialize_with = "vec3")]
        look_at_mm: [f32; 3],
        /// Full-intensity half angle, degrees.
        #[serde(deserialize_with = "finite")]
        inner_deg: f32,
        /// Zero-intensity half angle, degrees.
        #[serde(deserialize_with = "finite")]
        outer_deg: f32,
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        #[serde(default, deserialize_with = "opt_finite_f64")]
        temperature_k: Option<f64>,
        /// Luminous scale (on the axis).
        #[serde(deserialize_with = "finite")]
        intensity: f32,
    },
    /// Distant (directional) light; intensity is the irradiance on a surface facing it.
    Distant {
        /// Direction towards the light.
        #[serde(deserialize_with = "vec3")]
        direction: [f32; 3],
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        #[serde(default, deserialize_with = "opt_finite_f64")]
        temperature_k: Option<f64>,
        /// Irradiance (luminance units).
        #[serde(deserialize_with = "finite")]
        intensity: f32,
    },
    /// Spherical area light; intensity is its radiance.
    Sphere {
        /// Centre, mm.
        #[serde(deserialize_with = "vec3")]
        center_mm: [f32; 3],
        /// Radius, mm.
        #[serde(deserialize_with = "finite")]
        radius_mm: f32,
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        #[serde(default, deserialize_with = "opt_finite_f64")]
        temperature_k: Option<f64>,
        /// Radiance (luminance units).
        #[serde(deserialize_with = "finite")]
        intensity: f32,
    },
    /// Rectangular area light facing `look_at_mm`; intensity is its radiance.
    Quad {
        /// Centre, mm.
        #[serde(deserialize_with = "vec3")]
        center_mm: [f32; 3],
        /// Point the emitting side faces, mm.
        #[serde(deserialize_with = "vec3")]
        look_at_mm: [f32; 3],
        /// Width and height, mm.
        #[serde(deserialize_with = "vec2")]
        size_mm: [f32; 2],
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        #[serde(default, deserialize_with = "opt_finite_f64")]
        temperature_k: Option<f64>,
        /// Radiance (luminance units).
        #[serde(deserialize_with = "finite")]
        intensity: f32,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERA: &str =
        "[camera]\nposition_mm = [0, 0, 300]\nlook_at_mm = [0, 0, 0]\nfov_deg = 30\n";

    fn error_of(extra: &str) -> String {
        parse(&format!("{CAMERA}{extra}")).unwrap_err()
    }

    #[test]
    fn scene_built_here_parses() {
        let d = parse(CAMERA).unwrap();
        assert_eq!(d.camera.position_mm, [0.0, 0.0, 300.0]);
    }

    #[test]
    fn extra_elements_in_coordinate_arrays_are_refused() {
        let e = parse("[camera]\nposition_mm = [0, 0, 300, 77, \"junk\"]\nlook_at_mm = [0, 0, 0]\nfov_deg = 30\n")
            .unwrap_err();
        assert!(e.starts_with("line 2"), "{e}");
        let e = parse(
            "[camera]\nposition_mm = [0, 0, 300, 77]\nlook_at_mm = [0, 0, 0]\nfov_deg = 30\n",
        )
        .unwrap_err();
        assert!(
            e.contains("expected an array of 3 numbers, got 4 elements"),
            "{e}"
        );
        let e = error_of(
            "[[lights]]\ntype = \"quad\"\ncenter_mm = [0, 0, 0]\nlook_at_mm = [0, 0, 1]\nsize_mm = [1]\nintensity = 1\n",
        );
        assert!(e.contains("expected an array of 2 numbers, got 1"), "{e}");
    }

    #[test]
    fn albedo_spectrum_with_inf_or_nan_wavelengths_is_refused() {
        for bad in ["inf", "-inf", "nan"] {
            let e = error_of(&format!(
                "[materials.w]\ntype = \"diffuse\"\nalbedo_spectrum = [[400, 0.5], [{bad}, 0.5], [700, 0.5]]\n"
            ));
            assert!(
                e.contains("element 1: expected finite [nm, value]"),
                "{bad}: {e}"
            );
        }
        let e = error_of("[materials.w]\ntype = \"diffuse\"\nalbedo_spectrum = [[400, 0.5, 3]]\n");
        assert!(e.contains("got 3 numbers"), "{e}");
    }

    #[test]
    fn numbers_beyond_f32_are_refused_not_read_as_infinity() {
        let e =
            error_of("[[lights]]\ntype = \"point\"\nposition_mm = [0, 1e39, 0]\nintensity = 1\n");
        assert!(e.contains("got 1e39"), "{e}");
        let e =
            error_of("[[lights]]\ntype = \"point\"\nposition_mm = [0, 0, 0]\nintensity = inf\n");
        assert!(e.contains("expected a finite number"), "{e}");
    }

    #[test]
    fn toml_errors_are_one_line() {
        let e = parse("[camera]\nposition_mm = [0, 0\n").unwrap_err();
        assert!(!e.contains('\n') && e.starts_with("line "), "{e}");
        let e = error_of("[film]\nexposure_stops = \"bright\"\n");
        assert!(!e.contains('\n') && e.starts_with("line 6"), "{e}");
        // A long offending value is cut.
        let e = error_of(&format!(
            "[materials.s]\ntype = \"skin\"\npreset = {}\n",
            "9".repeat(100_000)
        ));
        assert!(e.len() < 300, "{} chars", e.len());
    }
}
