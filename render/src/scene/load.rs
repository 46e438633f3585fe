//! Loading a scene file: the camera, meshes and their placement, lights and the environment, with
//! every value checked and every error naming the file and key.

use super::Scene;
use crate::builtin;
use crate::camera::Camera;
use crate::error::RenderError;
use crate::geometry::{Geometry, MAX_COORD_MM, unit_vector, within_scene};
use crate::light::{
    DistantLight, EmissionShape, Environment, Light, MAX_INTENSITY, PointLight, QuadLight,
    SphereLight, SpotLight,
};
use crate::material::{DiffuseMaterial, Material, SkinKnobs, SkinMaterial};
use crate::mesh::{Placement, TriangleMesh};
use crate::scene_file::{EnvironmentDesc, LightDesc, MeshDesc, SceneDesc, ShapeKind, SpectrumKind};
use crate::spectrum::SpectrumTable;
use crate::texture::Texture;
use glam::Vec3;
use skin_io::input::{self, InputKind};
use skin_optics::echo::Num;
use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// One scene file being loaded: where it is, and the choices made for its materials.
pub(super) struct Loader<'a> {
    pub(super) file: &'a str,
    pub(super) base_dir: Option<&'a Path>,
    pub(super) opts: &'a SkinKnobs,
}

impl Loader<'_> {
    pub(super) fn err(&self, key: impl Into<String>, message: impl Into<String>) -> RenderError {
        RenderError::value(self.file, key, message)
    }

    fn vec3(&self, key: &str, v: [f32; 3]) -> Result<Vec3, RenderError> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(Vec3::from(v))
        } else {
            Err(self.err(key, format!("expected three finite numbers, got {v:?}")))
        }
    }

    /// `v` if `ok(v)`, else an error naming `key`, what was `expected` and the value.
    fn checked<T: Copy>(
        &self,
        key: &str,
        v: T,
        ok: bool,
        expected: &str,
        shown: f32,
    ) -> Result<T, RenderError> {
        if ok {
            Ok(v)
        } else {
            Err(self.err(
                key,
                format!("expected {expected}, got {}", Num(f64::from(shown))),
            ))
        }
    }

    /// A light's position: finite and within ±[`MAX_COORD_MM`], like the geometry, so distances
    /// and their squares stay finite in f32.
    fn point(&self, key: &str, v: [f32; 3]) -> Result<Vec3, RenderError> {
        let p = self.vec3(key, v)?;
        let range = format!("a point within ±{MAX_COORD_MM:e} mm");
        self.checked(key, p, within_scene(p), &range, p.abs().max_element())
    }

    /// A light's size in (0, [`MAX_COORD_MM`]] mm: its area and solid angle stay finite in f32.
    fn length(&self, key: &str, v: f32) -> Result<f32, RenderError> {
        let ok = v.is_finite() && v > 0.0 && v <= MAX_COORD_MM;
        self.checked(
            key,
            v,
            ok,
            &format!("a length in (0, {MAX_COORD_MM:e}] mm"),
            v,
        )
    }

    /// A light's intensity in [0, [`MAX_INTENSITY`]].
    fn intensity(&self, key: &str, v: f32) -> Result<f32, RenderError> {
        let ok = v.is_finite() && (0.0..=MAX_INTENSITY).contains(&v);
        self.checked(
            key,
            v,
            ok,
            &format!("an intensity in [0, {MAX_INTENSITY:e}]"),
            v,
        )
    }

    fn positive(&self, key: &str, v: f32) -> Result<f32, RenderError> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(key, format!("expected a finite number > 0, got {v}")))
        }
    }

    /// Bytes of a referenced file (or built-in asset) and its resolved path, read through the
    /// guarded reader of `kind` (extension, regular file, size cap).
    pub(super) fn read(
        &self,
        kind: InputKind,
        spec: &str,
    ) -> Result<(Cow<'static, [u8]>, PathBuf), RenderError> {
        let what = kind.what;
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
        let bytes = kind.read(&path)?;
        Ok((Cow::Owned(bytes), path))
    }

    fn emission(
        &self,
        key: &str,
        kind: Option<SpectrumKind>,
        temperature_k: Option<f64>,
        intensity: f32,
    ) -> Result<SpectrumTable, RenderError> {
        let intensity = self.intensity(&format!("{key}.intensity"), intensity)?;
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

    pub(super) fn load(&self, desc: SceneDesc) -> Result<Scene, RenderError> {
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

        let knobs = SkinKnobs {
            fidelity: self
                .opts
                .fidelity
                .over(&self.fidelity(desc.fidelity.as_ref())?),
            ..*self.opts
        };
        // Material ids follow the file's table in name order, as `materials` builds them.
        let material_names: Vec<String> = desc.materials.keys().cloned().collect();
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
            let placement = Placement {
                units_mm: self.positive(&format!("{key}.units_mm"), m.units_mm)?,
                scale: self.positive(&format!("{key}.scale"), m.scale)?,
                rotate_deg: self.vec3(&format!("{key}.rotate_deg"), m.rotate_deg)?,
                translate_mm: self.vec3(&format!("{key}.translate_mm"), m.translate_mm)?,
            };
            mesh.transform(&placement.to_affine());
            // The BVH builder needs finite bounds well inside f32 range: check after placement,
            // where units_mm × scale and translate_mm may push an in-range model out of it.
            if let Some(p) = mesh.positions.iter().find(|&&p| !within_scene(p)) {
                return Err(self.err(
                    &key,
                    format!(
                        "a vertex lands at [{}, {}, {}] mm after units_mm, scale, rotate_deg and \
                         translate_mm; every coordinate must lie within ±{MAX_COORD_MM:e} mm",
                        Num(p.x.into()),
                        Num(p.y.into()),
                        Num(p.z.into())
                    ),
                ));
            }
            if m.flip_v
                && let Some(uvs) = &mut mesh.uvs
            {
                uvs.iter_mut().for_each(|uv| uv.y = 1.0 - uv.y);
            }
            meshes.push((mesh, material as u32));
        }
        let footprints = smallest_footprints_mm(
            &camera,
            knobs.fidelity.image_height,
            &meshes,
            material_names.len(),
        );
        let (materials, material_names, textures) =
            self.materials(&desc.materials, &knobs, &footprints)?;
        for (i, (mesh, material)) in meshes.iter().enumerate() {
            if let Material::Skin(SkinMaterial {
                albedo_texture: Some(_),
                ..
            })
            | Material::Skin(SkinMaterial { maps: Some(_), .. })
            | Material::Diffuse(DiffuseMaterial {
                albedo_texture: Some(_),
                ..
            }) = &materials[*material as usize]
                && mesh.uvs.is_none()
            {
                return Err(self.err(
                    format!("meshes[{i}]"),
                    "the material has a texture but the mesh has no texture coordinates",
                ));
            }
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
                let (bytes, path) = self.read(input::MESH, file)?;
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
            } => Light::Point(PointLight {
                position_mm: self.point(&format!("{key}.position_mm"), *position_mm)?,
                intensity: self.emission(key, *spectrum, *temperature_k, *intensity)?,
            }),
            LightDesc::Spot {
                position_mm,
                look_at_mm,
                inner_deg,
                outer_deg,
                spectrum,
                temperature_k,
                intensity,
            } => {
                let p = self.point(&format!("{key}.position_mm"), *position_mm)?;
                let to = self.point(&format!("{key}.look_at_mm"), *look_at_mm)? - p;
                let Some(dir) = unit_vector(to) else {
                    return Err(
                        self.err(format!("{key}.look_at_mm"), "must differ from position_mm")
                    );
                };
                if !(*inner_deg >= 0.0 && inner_deg <= outer_deg && *outer_deg < 180.0) {
                    return Err(self.err(
                        format!("{key}.outer_deg"),
                        format!(
                            "expected 0 ≤ inner_deg ≤ outer_deg < 180, got {inner_deg}, {outer_deg}"
                        ),
                    ));
                }
                Light::Spot(SpotLight {
                    position_mm: p,
                    direction: dir,
                    cos_inner: inner_deg.to_radians().cos(),
                    cos_outer: outer_deg.to_radians().cos(),
                    intensity: self.emission(key, *spectrum, *temperature_k, *intensity)?,
                })
            }
            LightDesc::Distant {
                direction,
                spectrum,
                temperature_k,
                intensity,
            } => {
                // Any finite non-zero vector is a direction: `unit_vector` normalises even those
                // whose squared length overflows f32.
                let d = self.vec3(&format!("{key}.direction"), *direction)?;
                let Some(to_light) = unit_vector(d) else {
                    return Err(self.err(format!("{key}.direction"), "expected a non-zero vector"));
                };
                Light::Distant(DistantLight {
                    to_light,
                    irradiance: self.emission(key, *spectrum, *temperature_k, *intensity)?,
                })
            }
            LightDesc::Sphere {
                center_mm,
                radius_mm,
                spectrum,
                temperature_k,
                intensity,
            } => Light::Sphere(SphereLight {
                center_mm: self.point(&format!("{key}.center_mm"), *center_mm)?,
                radius_mm: self.length(&format!("{key}.radius_mm"), *radius_mm)?,
                radiance: self.emission(key, *spectrum, *temperature_k, *intensity)?,
            }),
            LightDesc::Quad {
                center_mm,
                look_at_mm,
                size_mm,
                spectrum,
                temperature_k,
                intensity,
            } => {
                let c = self.point(&format!("{key}.center_mm"), *center_mm)?;
                let to = self.point(&format!("{key}.look_at_mm"), *look_at_mm)? - c;
                let Some(n) = unit_vector(to) else {
                    return Err(self.err(format!("{key}.look_at_mm"), "must differ from center_mm"));
                };
                let w = self.length(&format!("{key}.size_mm"), size_mm[0])?;
                let h = self.length(&format!("{key}.size_mm"), size_mm[1])?;
                let hint = if n.y.abs() > 0.99 { Vec3::X } else { Vec3::Y };
                let right = hint.cross(n).normalize();
                let up = n.cross(right);
                // edge_u × edge_v = w h (right × up) = w h n: the emitting side faces look_at.
                let (eu, ev) = (right * w, up * h);
                Light::Quad(QuadLight::new(
                    c - eu * 0.5 - ev * 0.5,
                    eu,
                    ev,
                    self.emission(key, *spectrum, *temperature_k, *intensity)?,
                ))
            }
        })
    }

    fn environment(&self, e: &EnvironmentDesc) -> Result<Environment, RenderError> {
        let intensity = match (e.intensity, e.spectral_radiance) {
            (Some(_), Some(_)) => {
                return Err(self.err(
                    "environment.spectral_radiance",
                    "give either intensity or spectral_radiance, not both",
                ));
            }
            (None, Some(x)) => {
                if e.exr.is_some() || e.spectrum.is_some() || e.temperature_k.is_some() {
                    return Err(self.err(
                        "environment.spectral_radiance",
                        "a constant spectral radiance takes no exr, spectrum or temperature_k",
                    ));
                }
                let x = self.intensity("environment.spectral_radiance", x)?;
                return Ok(Environment::Constant(SpectrumTable::constant(x)));
            }
            (Some(i), None) => i,
            (None, None) => {
                return Err(self.err(
                    "environment.intensity",
                    "expected intensity (or spectral_radiance)",
                ));
            }
        };
        match &e.exr {
            Some(file) => {
                let scale = self.intensity("environment.intensity", intensity)?;
                let (bytes, path) = self.read(input::ENVIRONMENT, file)?;
                Ok(Environment::LatLong {
                    map: Texture::from_exr_bytes(&bytes, &path)?,
                    scale,
                })
            }
            None => Ok(Environment::Constant(self.emission(
                "environment",
                e.spectrum,
                e.temperature_k,
                intensity,
            )?)),
        }
    }
}

/// Per material, the smallest pixel footprint on its meshes, mm: the pixel angle at `image_height`
/// times the distance from the camera to the nearest point of the bounding box of the material's
/// placed meshes (0 with the camera inside it), a lower bound on every camera hit's footprint
/// (`crate::fidelity::photons`). `None` without an image height or a mesh.
fn smallest_footprints_mm(
    camera: &Camera,
    image_height: Option<u32>,
    meshes: &[(TriangleMesh, u32)],
    materials: usize,
) -> Vec<Option<f32>> {
    let Some(height) = image_height else {
        return vec![None; materials];
    };
    let angle = camera.pixel_angle_rad(height as usize);
    let eye = camera.position_mm();
    let mut bounds: Vec<Option<(Vec3, Vec3)>> = vec![None; materials];
    for (mesh, material) in meshes {
        let Some(b) = bounds.get_mut(*material as usize) else {
            continue;
        };
        for &p in &mesh.positions {
            *b = Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))));
        }
    }
    bounds
        .into_iter()
        .map(|b| b.map(|(lo, hi)| angle * (eye.clamp(lo, hi) - eye).length()))
        .collect()
}
