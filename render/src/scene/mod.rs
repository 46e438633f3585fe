//! A loaded scene ready to render: camera, lights, environment, materials (with their spectral
//! tables built once at load), textures and the triangle geometry with its BVH.
//!
//! Loading lives in `load` (the file, meshes, lights, environment) and `materials` (the materials'
//! keys); every error names the file, the key and what was expected, and a missing mesh or
//! texture names its path.

mod fitted_maps;
mod load;
mod maps;
mod materials;

use crate::builtin;
use crate::camera::Camera;
use crate::error::RenderError;
use crate::fidelity::SkinChoices;
use crate::geometry::{Geometry, SurfaceHit};
use crate::light::{Environment, Light};
use crate::material::{Material, SkinKnobs};
use crate::scene_file::SceneDesc;
use crate::texture::Texture;
use glam::Vec3;
use load::Loader;
use std::path::{Path, PathBuf};

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

impl Scene {
    /// Load a scene file, or a built-in scene named `builtin:NAME` (see [`builtin::SCENES`]).
    pub fn load(spec: &str, opts: &SkinKnobs) -> Result<Scene, RenderError> {
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
        let text = skin_io::input::SCENE.read_text(path)?;
        Scene::from_toml(&text, spec, path.parent(), opts)
    }

    /// Parse and load scene text; `file` names it in errors, relative paths resolve against `base_dir`.
    pub fn from_toml(
        text: &str,
        file: &str,
        base_dir: Option<&Path>,
        opts: &SkinKnobs,
    ) -> Result<Scene, RenderError> {
        let desc: SceneDesc =
            crate::scene_file::parse(text).map_err(|message| RenderError::SceneSyntax {
                file: file.to_string(),
                message,
            })?;
        Loader {
            file,
            base_dir,
            opts,
        }
        .load(desc)
    }

    /// Each skin material with a BSSRDF, by name, with what the fidelity chose for its tables.
    #[must_use]
    pub fn skin_choices(&self) -> Vec<(&str, &SkinChoices)> {
        self.material_names
            .iter()
            .zip(&self.materials)
            .filter_map(|(name, m)| match m {
                Material::Skin(s) => s.choices.as_deref().map(|c| (name.as_str(), c)),
                Material::Diffuse(_) => None,
            })
            .collect()
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
