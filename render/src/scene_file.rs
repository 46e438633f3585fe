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
//!
//! [materials.face]
//! type = "skin"
//! preset = "light"         # light, medium, dark; melanin, eumelanin, hemoglobin, oil override it
//! albedo_texture = "builtin:Map-COL.jpg"
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

use serde::Deserialize;
use std::collections::BTreeMap;

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
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position, mm.
    pub position_mm: [f32; 3],
    /// Point looked at, mm.
    pub look_at_mm: [f32; 3],
    /// Up hint (default +Y).
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    pub fov_deg: f32,
    /// Lens aperture diameter, mm (0 = pinhole).
    #[serde(default)]
    pub aperture_mm: f32,
    /// Distance of the plane in focus, mm (default: the look-at distance).
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
    #[serde(default)]
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
    pub temperature_k: Option<f64>,
    /// Lat-long linear-sRGB OpenEXR map.
    pub exr: Option<String>,
    /// Luminance of a constant environment, or the map's multiplier.
    pub intensity: f32,
}

/// `[materials.NAME]`.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum MaterialDesc {
    /// Skin: a preset with optional explicit fractions.
    Skin {
        /// light, medium or dark (default light).
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
        roughness: Option<f32>,
        /// sRGB albedo texture (JPEG/PNG).
        albedo_texture: Option<String>,
    },
    /// Lambertian.
    Diffuse {
        /// Constant albedo.
        albedo: Option<f32>,
        /// sRGB-encoded albedo colour.
        albedo_srgb: Option<[f32; 3]>,
        /// Albedo samples `[nm, value]`, linearly interpolated.
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
    #[serde(default = "one")]
    pub units_mm: f32,
    /// Extra uniform scale (default 1).
    #[serde(default = "one")]
    pub scale: f32,
    /// Rotation about X, Y, Z, degrees (applied in that order).
    #[serde(default)]
    pub rotate_deg: [f32; 3],
    /// Translation, mm.
    #[serde(default)]
    pub translate_mm: [f32; 3],
    /// Use v → 1 − v for texture lookups (OpenGL-style UVs, e.g. the head scan).
    #[serde(default)]
    pub flip_v: bool,
}

fn one() -> f32 {
    1.0
}

/// `[[lights]]`; every light has `spectrum` (default d65), `temperature_k` (blackbody) and `intensity`.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum LightDesc {
    /// Isotropic point light; intensity is radiant intensity (irradiance × mm²).
    Point {
        /// Position, mm.
        position_mm: [f32; 3],
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        temperature_k: Option<f64>,
        /// Luminous scale.
        intensity: f32,
    },
    /// Spot light.
    Spot {
        /// Position, mm.
        position_mm: [f32; 3],
        /// Point on the cone axis, mm.
        look_at_mm: [f32; 3],
        /// Full-intensity half angle, degrees.
        inner_deg: f32,
        /// Zero-intensity half angle, degrees.
        outer_deg: f32,
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        temperature_k: Option<f64>,
        /// Luminous scale (on the axis).
        intensity: f32,
    },
    /// Distant (directional) light; intensity is the irradiance on a surface facing it.
    Distant {
        /// Direction towards the light.
        direction: [f32; 3],
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        temperature_k: Option<f64>,
        /// Irradiance (luminance units).
        intensity: f32,
    },
    /// Spherical area light; intensity is its radiance.
    Sphere {
        /// Centre, mm.
        center_mm: [f32; 3],
        /// Radius, mm.
        radius_mm: f32,
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        temperature_k: Option<f64>,
        /// Radiance (luminance units).
        intensity: f32,
    },
    /// Rectangular area light facing `look_at_mm`; intensity is its radiance.
    Quad {
        /// Centre, mm.
        center_mm: [f32; 3],
        /// Point the emitting side faces, mm.
        look_at_mm: [f32; 3],
        /// Width and height, mm.
        size_mm: [f32; 2],
        /// Spectrum shape.
        spectrum: Option<SpectrumKind>,
        /// Blackbody temperature, K.
        temperature_k: Option<f64>,
        /// Radiance (luminance units).
        intensity: f32,
    },
}
