//! A validated, loaded scene: camera, lights, environment, materials (with their spectral tables
//! built once here), textures and the triangle geometry with its BVH.
//!
//! Scene files are parsed by `scene_file` and validated here; every error names the file, the key
//! and what was expected, and a missing mesh or texture names its path.

use crate::bssrdf::{Directional, EnergySplit, ProfileTable, Subsurface, TableOptions};
use crate::builtin;
use crate::camera::Camera;
use crate::error::RenderError;
use crate::geometry::{Geometry, SurfaceHit};
use crate::light::{EmissionShape, Environment, Light};
use crate::material::{DiffuseMaterial, Material, SkinMaterial, TextureRef};
use crate::mesh::{Placement, TriangleMesh};
use crate::scene_file::{
    EnvironmentDesc, LightDesc, MaterialDesc, MeshDesc, SceneDesc, ShapeKind, SpectrumKind,
};
use crate::spectrum::{SpectrumTable, linear_srgb_to_spectrum};
use crate::texture::{Texture, luminance};
use glam::Vec3;
use rayon::prelude::*;
use skin_optics::{Preset, SkinParams, Wavelength};
use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Choices made when a scene is loaded.
#[derive(Debug, Clone, Copy)]
pub struct SceneOptions {
    /// How skin reflectance is computed (default exact: adding-doubling totals, Monte Carlo shapes).
    pub method: multipole::Method,
    /// Shade skin's body with the Lambertian stand-in instead of the BSSRDF (for comparisons;
    /// default false: subsurface scattering on).
    pub no_subsurface: bool,
    /// Escaping photons per Monte Carlo profile shape (`Method::Exact`), or `None` (the default)
    /// for the shapes of the universal table (`multipole::skin::ExactShape::Table`: no run-time
    /// photons, built once per machine and cached).
    pub shape_escapes: Option<u64>,
}

impl Default for SceneOptions {
    fn default() -> Self {
        Self {
            method: multipole::Method::default(),
            no_subsurface: false,
            shape_escapes: None,
        }
    }
}

/// What a ray hit first: a surface or an area light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Hit {
    /// A triangle.
    Surface(SurfaceHit),
    /// The emitting surface of light `index` at distance `t`, mm.
    Light {
        /// Index into [`Scene::lights`].
        index: usize,
        /// Distance, mm.
        t: f32,
    },
}

/// A scene ready to render.
pub struct Scene {
    /// Where it came from (file path or `builtin:NAME`).
    pub name: String,
    /// The camera.
    pub camera: Camera,
    /// Light sources.
    pub lights: Vec<Light>,
    /// Light from far away, if any.
    pub environment: Option<Environment>,
    /// Materials, indexed by the geometry's material ids.
    pub materials: Vec<Material>,
    /// Material names, same order.
    pub material_names: Vec<String>,
    /// Textures used by materials.
    pub textures: Vec<Texture>,
    /// All triangles and the BVH.
    pub geometry: Geometry,
    /// PNG exposure, stops.
    pub exposure_stops: f32,
}

/// Wavelength step of the skin reflectance tables computed at load, nm (interpolated to 5 nm).
pub const SKIN_TABLE_STEP_NM: f64 = 10.0;

impl Scene {
    /// Load a scene file, or a built-in scene named `builtin:NAME` (see [`builtin::SCENES`]).
    pub fn load(spec: &str, opts: &SceneOptions) -> Result<Scene, RenderError> {
        if let Some(name) = spec.strip_prefix(builtin::PREFIX) {
            let text = builtin::scene(name).ok_or_else(|| RenderError::MissingFile {
                what: "scene",
                path: PathBuf::from(spec),
                source: std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!(
                        "no built-in scene '{name}' (valid: {})",
                        builtin::SCENES.join(", ")
                    ),
                ),
            })?;
            return Scene::from_toml(text, spec, None, opts);
        }
        let path = Path::new(spec);
        let text = std::fs::read_to_string(path).map_err(|source| RenderError::MissingFile {
            what: "scene",
            path: path.to_path_buf(),
            source,
        })?;
        Scene::from_toml(&text, spec, path.parent(), opts)
    }

    /// Parse and load scene text; `file` names it in errors, relative paths resolve against `base_dir`.
    pub fn from_toml(
        text: &str,
        file: &str,
        base_dir: Option<&Path>,
        opts: &SceneOptions,
    ) -> Result<Scene, RenderError> {
        let desc: SceneDesc = toml::from_str(text).map_err(|e| RenderError::SceneSyntax {
            file: file.to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        Loader {
            file,
            base_dir,
            opts,
        }
        .load(desc)
    }

    /// First thing hit along (`o`, unit `d`) within (`tmin`, `tmax`): triangles and area lights.
    #[must_use]
    pub fn intersect(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        let surface = self.geometry.intersect(o, d, tmin, tmax);
        let mut best_t = surface.map_or(tmax, |s| s.t);
        let mut best = surface.map(Hit::Surface);
        for (index, light) in self.lights.iter().enumerate() {
            if let Some(t) = light.intersect(o, d)
                && t > tmin
                && t < best_t
            {
                best_t = t;
                best = Some(Hit::Light { index, t });
            }
        }
        best
    }
}

struct Loader<'a> {
    file: &'a str,
    base_dir: Option<&'a Path>,
    opts: &'a SceneOptions,
}

impl Loader<'_> {
    fn err(&self, key: impl Into<String>, message: impl Into<String>) -> RenderError {
        RenderError::value(self.file, key, message)
    }

    fn vec3(&self, key: &str, v: [f32; 3]) -> Result<Vec3, RenderError> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(Vec3::from(v))
        } else {
            Err(self.err(key, format!("expected three finite numbers, got {v:?}")))
        }
    }

    fn positive(&self, key: &str, v: f32) -> Result<f32, RenderError> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(key, format!("expected a finite number > 0, got {v}")))
        }
    }

    fn non_negative(&self, key: &str, v: f32) -> Result<f32, RenderError> {
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(self.err(key, format!("expected a finite number ≥ 0, got {v}")))
        }
    }

    /// Bytes of a referenced file (or built-in asset) and its resolved path.
    fn read(
        &self,
        what: &'static str,
        spec: &str,
    ) -> Result<(Cow<'static, [u8]>, PathBuf), RenderError> {
        if let Some(name) = spec.strip_prefix(builtin::PREFIX) {
            return builtin::asset(name)
                .map(|b| (Cow::Borrowed(b), PathBuf::from(spec)))
                .ok_or_else(|| RenderError::MissingFile {
                    what,
                    path: PathBuf::from(spec),
                    source: std::io::Error::new(
                        std::io::ErrorKind::NotFound,
                        "no such built-in asset",
                    ),
                });
        }
        let path = match self.base_dir {
            Some(dir) => dir.join(spec),
            None => PathBuf::from(spec),
        };
        std::fs::read(&path)
            .map(|b| (Cow::Owned(b), path.clone()))
            .map_err(|source| RenderError::MissingFile { what, path, source })
    }

    fn emission(
        &self,
        key: &str,
        kind: Option<SpectrumKind>,
        temperature_k: Option<f64>,
        intensity: f32,
    ) -> Result<SpectrumTable, RenderError> {
        let intensity = self.non_negative(&format!("{key}.intensity"), intensity)?;
        let shape = match kind.unwrap_or(SpectrumKind::D65) {
            SpectrumKind::D65 => EmissionShape::D65,
            SpectrumKind::Constant => EmissionShape::Constant,
            SpectrumKind::Blackbody => match temperature_k {
                Some(t) if t.is_finite() && (500.0..=100_000.0).contains(&t) => {
                    EmissionShape::Blackbody { kelvin: t }
                }
                Some(t) => {
                    return Err(self.err(
                        format!("{key}.temperature_k"),
                        format!("{t} outside [500, 100000] K"),
                    ));
                }
                None => {
                    return Err(self.err(
                        format!("{key}.temperature_k"),
                        "required with spectrum = \"blackbody\"",
                    ));
                }
            },
        };
        Ok(shape.table(intensity))
    }

    fn load(&self, desc: SceneDesc) -> Result<Scene, RenderError> {
        let c = &desc.camera;
        let camera = Camera::new(
            self.vec3("camera.position_mm", c.position_mm)?,
            self.vec3("camera.look_at_mm", c.look_at_mm)?,
            self.vec3("camera.up", c.up)?,
            c.fov_deg,
            c.aperture_mm,
            c.focus_distance_mm,
        )
        .map_err(|e| match e {
            RenderError::Setting { name, value, range } => {
                self.err(name, format!("expected {range}, got {value}"))
            }
            other => other,
        })?;
        if !desc.film.exposure_stops.is_finite() {
            return Err(self.err("film.exposure_stops", "expected a finite number"));
        }

        let mut textures = Vec::new();
        let mut texture_ids: HashMap<String, usize> = HashMap::new();
        let mut material_names = Vec::new();
        let mut materials = Vec::new();
        for (name, m) in &desc.materials {
            let key = format!("materials.{name}");
            let mut texture = |spec: &Option<String>| -> Result<Option<TextureRef>, RenderError> {
                let Some(spec) = spec else { return Ok(None) };
                let index = match texture_ids.get(spec) {
                    Some(&i) => i,
                    None => {
                        let (bytes, path) = self.read("texture", spec)?;
                        textures.push(Texture::from_srgb_bytes(&bytes, &path)?);
                        texture_ids.insert(spec.clone(), textures.len() - 1);
                        textures.len() - 1
                    }
                };
                let mean_luminance = luminance(textures[index].mean()).max(1e-6);
                Ok(Some(TextureRef {
                    index,
                    mean_luminance,
                }))
            };
            let material = match m {
                MaterialDesc::Skin {
                    preset,
                    melanin,
                    eumelanin,
                    hemoglobin,
                    oil,
                    roughness,
                    albedo_texture,
                } => {
                    let params =
                        self.skin_params(&key, preset, [*melanin, *eumelanin, *hemoglobin, *oil])?;
                    let m_rough = roughness.unwrap_or(brdf::DEFAULT_ROUGHNESS);
                    let surface = brdf::TorranceSparrow::new(
                        m_rough,
                        params.oiliness() as f32,
                        params.eta() as f32,
                    )
                    .map_err(|e| self.err(format!("{key}.roughness"), e.to_string()))?;
                    let tex = texture(albedo_texture)?;
                    let rd = self.skin_table(&key, &params)?;
                    let skin = SkinMaterial::new(params, surface, rd, tex);
                    if self.opts.no_subsurface {
                        Material::Skin(skin)
                    } else {
                        let ss = self.subsurface(&key, &skin)?;
                        Material::Skin(skin.with_subsurface(ss))
                    }
                }
                MaterialDesc::Diffuse {
                    albedo,
                    albedo_srgb,
                    albedo_spectrum,
                    albedo_texture,
                } => {
                    let set = [
                        albedo.is_some(),
                        albedo_srgb.is_some(),
                        albedo_spectrum.is_some(),
                    ];
                    let table = match (albedo, albedo_srgb, albedo_spectrum) {
                        _ if set.iter().filter(|&&s| s).count() > 1 => {
                            return Err(self.err(
                                &key,
                                "give only one of albedo, albedo_srgb, albedo_spectrum",
                            ));
                        }
                        (Some(a), _, _) => {
                            SpectrumTable::constant(self.unit(&format!("{key}.albedo"), *a)?)
                        }
                        (_, Some(rgb), _) => {
                            let mut lin = [0.0; 3];
                            for (i, &c) in rgb.iter().enumerate() {
                                let c = self.unit(&format!("{key}.albedo_srgb"), c)?;
                                lin[i] = skin_optics::color::srgb_decode(f64::from(c)) as f32;
                            }
                            linear_srgb_to_spectrum(lin)
                        }
                        (_, _, Some(samples)) => {
                            self.sampled_albedo(&format!("{key}.albedo_spectrum"), samples)?
                        }
                        _ if albedo_texture.is_some() => SpectrumTable::constant(1.0),
                        _ => {
                            return Err(self.err(
                                &key,
                                "expected one of albedo, albedo_srgb, albedo_spectrum",
                            ));
                        }
                    };
                    Material::Diffuse(DiffuseMaterial {
                        albedo: table,
                        albedo_texture: texture(albedo_texture)?,
                    })
                }
            };
            material_names.push(name.clone());
            materials.push(material);
        }

        let mut meshes = Vec::new();
        let mut cache: HashMap<String, TriangleMesh> = HashMap::new();
        for (i, m) in desc.meshes.iter().enumerate() {
            let key = format!("meshes[{i}]");
            let material = material_names
                .iter()
                .position(|n| *n == m.material)
                .ok_or_else(|| {
                    self.err(
                        format!("{key}.material"),
                        format!(
                            "no material named '{}' (defined: {})",
                            m.material,
                            material_names.join(", ")
                        ),
                    )
                })?;
            let mut mesh = self.mesh(&key, m, &mut cache)?;
            if let Material::Skin(SkinMaterial {
                albedo_texture: Some(_),
                ..
            })
            | Material::Diffuse(DiffuseMaterial {
                albedo_texture: Some(_),
                ..
            }) = &materials[material]
                && mesh.uvs.is_none()
            {
                return Err(self.err(
                    &key,
                    "the material has a texture but the mesh has no texture coordinates",
                ));
            }
            let placement = Placement {
                units_mm: self.positive(&format!("{key}.units_mm"), m.units_mm)?,
                scale: self.positive(&format!("{key}.scale"), m.scale)?,
                rotate_deg: self.vec3(&format!("{key}.rotate_deg"), m.rotate_deg)?,
                translate_mm: self.vec3(&format!("{key}.translate_mm"), m.translate_mm)?,
            };
            mesh.transform(&placement.to_affine());
            if m.flip_v
                && let Some(uvs) = &mut mesh.uvs
            {
                uvs.iter_mut().for_each(|uv| uv.y = 1.0 - uv.y);
            }
            meshes.push((mesh, material as u32));
        }

        let lights = desc
            .lights
            .iter()
            .enumerate()
            .map(|(i, l)| self.light(&format!("lights[{i}]"), l))
            .collect::<Result<Vec<_>, _>>()?;
        let environment = desc
            .environment
            .as_ref()
            .map(|e| self.environment(e))
            .transpose()?;

        Ok(Scene {
            name: self.file.to_string(),
            camera,
            lights,
            environment,
            materials,
            material_names,
            textures,
            geometry: Geometry::new(meshes),
            exposure_stops: desc.film.exposure_stops,
        })
    }

    fn unit(&self, key: &str, v: f32) -> Result<f32, RenderError> {
        if v.is_finite() && (0.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err(self.err(key, format!("expected a value in [0, 1], got {v}")))
        }
    }

    fn sampled_albedo(&self, key: &str, s: &[[f64; 2]]) -> Result<SpectrumTable, RenderError> {
        if s.is_empty() || s.windows(2).any(|w| w[1][0] <= w[0][0]) {
            return Err(self.err(key, "expected [nm, value] pairs with increasing nm"));
        }
        for p in s {
            self.unit(key, p[1] as f32)?;
        }
        Ok(SpectrumTable::from_fn(|nm| {
            let i = s.partition_point(|p| p[0] <= nm);
            if i == 0 {
                s[0][1]
            } else if i == s.len() {
                s[s.len() - 1][1]
            } else {
                let (a, b) = (s[i - 1], s[i]);
                a[1] + (nm - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
            }
        }))
    }

    /// The preset with explicit fractions replacing its values; an invalid one is reported by its key.
    fn skin_params(
        &self,
        key: &str,
        preset: &Option<String>,
        overrides: [Option<f64>; 4],
    ) -> Result<SkinParams, RenderError> {
        let base = match preset {
            Some(p) => SkinParams::preset(
                p.parse::<Preset>()
                    .map_err(|e| self.err(format!("{key}.preset"), e.to_string()))?,
            ),
            None => SkinParams::preset(Preset::Light),
        };
        let names = ["melanin", "eumelanin", "hemoglobin", "oil"];
        let values = |o: [Option<f64>; 4]| {
            [
                o[0].unwrap_or(base.melanin()),
                o[1].unwrap_or(base.eumelanin_blend()),
                o[2].unwrap_or(base.hemoglobin()),
                o[3].unwrap_or(base.oiliness()),
            ]
        };
        // Check each override alone first, so the error names the offending key.
        for (i, name) in names.iter().enumerate() {
            if overrides[i].is_some() {
                let mut one = [None; 4];
                one[i] = overrides[i];
                let v = values(one);
                SkinParams::new(v[0], v[1], v[2], v[3])
                    .map_err(|e| self.err(format!("{key}.{name}"), e.to_string()))?;
            }
        }
        let v = values(overrides);
        SkinParams::new(v[0], v[1], v[2], v[3]).map_err(|e| self.err(key, e.to_string()))
    }

    /// R_d(λ) of a skin from the multipole model at 10-nm steps over 380–780 nm.
    /// The BSSRDF of a skin: its radial profiles at 10-nm steps (`bssrdf::ProfileTable`) and the
    /// directional term with the surface lobe's energy split.
    fn subsurface(&self, key: &str, skin: &SkinMaterial) -> Result<Subsurface, RenderError> {
        let mut opts = TableOptions::default();
        if let Some(escapes) = self.opts.shape_escapes {
            opts.profile.exact_shape = multipole::skin::ExactShape::MonteCarlo { escapes };
        }
        let table = ProfileTable::build(&skin.params, self.opts.method, &opts)
            .map_err(|e| self.err(key, format!("skin profiles: {e}")))?;
        let directional = Directional::new(skin.surface.clone(), EnergySplit::default());
        Ok(Subsurface::new(std::sync::Arc::new(table), directional))
    }

    fn skin_table(&self, key: &str, params: &SkinParams) -> Result<SpectrumTable, RenderError> {
        let n = ((780.0 - 380.0) / SKIN_TABLE_STEP_NM) as usize + 1;
        let rd = (0..n)
            .into_par_iter()
            .map(|i| {
                let nm = 380.0 + SKIN_TABLE_STEP_NM * i as f64;
                let lambda = Wavelength::new(nm).map_err(|e| self.err(key, e.to_string()))?;
                multipole::skin::total_reflectance(params, lambda, self.opts.method)
                    .map_err(|e| self.err(key, format!("skin reflectance at {nm} nm: {e}")))
            })
            .collect::<Result<Vec<f64>, _>>()?;
        if let Some(bad) = rd
            .iter()
            .find(|r| !(r.is_finite() && (0.0..=1.0).contains(*r)))
        {
            return Err(self.err(key, format!("skin reflectance {bad} outside [0, 1]")));
        }
        Ok(SpectrumTable::from_fn(|nm| {
            let x = ((nm - 380.0) / SKIN_TABLE_STEP_NM).clamp(0.0, (n - 1) as f64);
            let i = (x as usize).min(n - 2);
            rd[i] + (x - i as f64) * (rd[i + 1] - rd[i])
        }))
    }

    fn mesh(
        &self,
        key: &str,
        m: &MeshDesc,
        cache: &mut HashMap<String, TriangleMesh>,
    ) -> Result<TriangleMesh, RenderError> {
        match (&m.file, m.shape) {
            (Some(_), Some(_)) | (None, None) => {
                Err(self.err(key, "expected exactly one of `file` and `shape`"))
            }
            (None, Some(ShapeKind::Sphere)) => Ok(TriangleMesh::sphere(4)),
            (None, Some(ShapeKind::Quad)) => Ok(TriangleMesh::quad()),
            (Some(file), None) => {
                if let Some(mesh) = cache.get(file) {
                    return Ok(mesh.clone());
                }
                let (bytes, path) = self.read("mesh", file)?;
                let lower = file.to_ascii_lowercase();
                let mesh = if lower.ends_with(".glb") {
                    TriangleMesh::from_glb(&bytes, &path)?
                } else if lower.ends_with(".obj") {
                    TriangleMesh::from_obj(&bytes, &path)?
                } else {
                    return Err(self.err(
                        format!("{key}.file"),
                        format!("expected a .glb or .obj file, got {file}"),
                    ));
                };
                cache.insert(file.clone(), mesh.clone());
                Ok(mesh)
            }
        }
    }

    fn light(&self, key: &str, l: &LightDesc) -> Result<Light, RenderError> {
        Ok(match l {
            LightDesc::Point {
                position_mm,
                spectrum,
                temperature_k,
                intensity,
            } => Light::Point {
                position_mm: self.vec3(&format!("{key}.position_mm"), *position_mm)?,
                intensity: self.emission(key, *spectrum, *temperature_k, *intensity)?,
            },
            LightDesc::Spot {
                position_mm,
                look_at_mm,
                inner_deg,
                outer_deg,
                spectrum,
                temperature_k,
                intensity,
            } => {
                let p = self.vec3(&format!("{key}.position_mm"), *position_mm)?;
                let dir = self.vec3(&format!("{key}.look_at_mm"), *look_at_mm)? - p;
                if dir.length() <= 0.0 {
                    return Err(
                        self.err(format!("{key}.look_at_mm"), "must differ from position_mm")
                    );
                }
                if !(*inner_deg >= 0.0 && inner_deg <= outer_deg && *outer_deg < 180.0) {
                    return Err(self.err(
                        format!("{key}.outer_deg"),
                        format!(
                            "expected 0 ≤ inner_deg ≤ outer_deg < 180, got {inner_deg}, {outer_deg}"
                        ),
                    ));
                }
                Light::Spot {
                    position_mm: p,
                    direction: dir.normalize(),
                    cos_inner: inner_deg.to_radians().cos(),
                    cos_outer: outer_deg.to_radians().cos(),
                    intensity: self.emission(key, *spectrum, *temperature_k, *intensity)?,
                }
            }
            LightDesc::Distant {
                direction,
                spectrum,
                temperature_k,
                intensity,
            } => {
                let d = self.vec3(&format!("{key}.direction"), *direction)?;
                if d.length() <= 0.0 {
                    return Err(self.err(format!("{key}.direction"), "expected a non-zero vector"));
                }
                Light::Distant {
                    to_light: d.normalize(),
                    irradiance: self.emission(key, *spectrum, *temperature_k, *intensity)?,
                }
            }
            LightDesc::Sphere {
                center_mm,
                radius_mm,
                spectrum,
                temperature_k,
                intensity,
            } => Light::Sphere {
                center_mm: self.vec3(&format!("{key}.center_mm"), *center_mm)?,
                radius_mm: self.positive(&format!("{key}.radius_mm"), *radius_mm)?,
                radiance: self.emission(key, *spectrum, *temperature_k, *intensity)?,
            },
            LightDesc::Quad {
                center_mm,
                look_at_mm,
                size_mm,
                spectrum,
                temperature_k,
                intensity,
            } => {
                let c = self.vec3(&format!("{key}.center_mm"), *center_mm)?;
                let n = self.vec3(&format!("{key}.look_at_mm"), *look_at_mm)? - c;
                if n.length() <= 0.0 {
                    return Err(self.err(format!("{key}.look_at_mm"), "must differ from center_mm"));
                }
                let n = n.normalize();
                let w = self.positive(&format!("{key}.size_mm"), size_mm[0])?;
                let h = self.positive(&format!("{key}.size_mm"), size_mm[1])?;
                let hint = if n.y.abs() > 0.99 { Vec3::X } else { Vec3::Y };
                let right = hint.cross(n).normalize();
                let up = n.cross(right);
                // edge_u × edge_v = w h (right × up) = w h n: the emitting side faces look_at.
                let (eu, ev) = (right * w, up * h);
                Light::Quad {
                    corner_mm: c - eu * 0.5 - ev * 0.5,
                    edge_u_mm: eu,
                    edge_v_mm: ev,
                    radiance: self.emission(key, *spectrum, *temperature_k, *intensity)?,
                }
            }
        })
    }

    fn environment(&self, e: &EnvironmentDesc) -> Result<Environment, RenderError> {
        match &e.exr {
            Some(file) => {
                let scale = self.non_negative("environment.intensity", e.intensity)?;
                let (bytes, path) = self.read("environment map", file)?;
                Ok(Environment::LatLong {
                    map: Texture::from_exr_bytes(&bytes, &path)?,
                    scale,
                })
            }
            None => Ok(Environment::Constant(self.emission(
                "environment",
                e.spectrum,
                e.temperature_k,
                e.intensity,
            )?)),
        }
    }
}
