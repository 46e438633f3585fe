//! A loaded scene ready to render: camera, lights, environment, materials (with their spectral
//! tables built once at load), textures and the triangle geometry with its BVH.
//!
//! Loading lives in `load` (the file, meshes, lights, environment) and `materials` (the materials'
//! keys); every error names the file, the key and what was expected, and a missing mesh or
//! texture names its path.

mod load;
mod materials;

use crate::builtin;
use crate::camera::Camera;
use crate::error::RenderError;
use crate::geometry::{Geometry, SurfaceHit};
use crate::light::{Environment, Light};
use crate::material::Material;
use crate::scene_file::SceneDesc;
use crate::texture::Texture;
use glam::Vec3;
use load::Loader;
use std::path::{Path, PathBuf};

/// The choices made when a scene is loaded (today, the knobs of its skin materials).
pub use crate::material::SkinKnobs as SceneOptions;

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
    /// The skin media of the volumetric reference integrator (None = skin by its BSSRDF).
    pub volumetric: Option<crate::volumetric::Volumetric>,
    /// The volumetric walk at thin parts of skin (`crate::fidelity::transport`; None = off).
    pub thin_parts: Option<crate::fidelity::transport::ThinParts>,
}

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
        let text = skin_io::input::SCENE.read_text(path)?;
        Scene::from_toml(&text, spec, path.parent(), opts)
    }

    /// Parse and load scene text; `file` names it in errors, relative paths resolve against `base_dir`.
    pub fn from_toml(
        text: &str,
        file: &str,
        base_dir: Option<&Path>,
        opts: &SceneOptions,
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

    /// Render skin with the volumetric random walk instead of its BSSRDF from now on.
    pub fn use_volumetric(&mut self) -> Result<(), crate::volumetric::VolumetricError> {
        self.volumetric = Some(crate::volumetric::Volumetric::build(self)?);
        Ok(())
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
