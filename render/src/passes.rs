//! Render passes for compositing and denoising, written beside the beauty image in one OpenEXR:
//! `albedo.{R,G,B}`, `normal.{X,Y,Z}`, `depth.Z`, `mask.skin` and `variance.Y`, as Cycles and
//! Arnold name their AOVs, and `samples.count`, each pixel's sample count (Cycles' "Debug
//! Sample Count" pass), where an adaptive render spent its samples.
//!
//! The geometric passes come from one primary ray through each pixel's centre and the lens
//! centre, so they are noise-free and exact at the pixel centre (no anti-aliasing).

use crate::error::RenderError;
use crate::film::Film;
use crate::material::Material;
use crate::scene::{Hit, Scene};
use crate::spectrum::{linear_srgb_at_nm, xyz_to_linear_srgb};
use glam::Vec2;
use rayon::prelude::*;
use skin_io::atomic;
use std::path::Path;

/// Depth of a pixel that sees nothing, mm.
pub const NO_DEPTH: f32 = f32::INFINITY;

/// The first-hit passes of an image, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Passes {
    width: usize,
    height: usize,
    /// Directional-hemispherical albedo as linear sRGB (D65-weighted reflectance; 0 off surfaces).
    pub albedo: Vec<[f32; 3]>,
    /// Unit world shading normal (0 off surfaces).
    pub normal: Vec<[f32; 3]>,
    /// Distance from the camera along the ray, mm ([`NO_DEPTH`] where nothing is hit).
    pub depth: Vec<f32>,
    /// 1 where the pixel centre sees skin, else 0.
    pub skin: Vec<f32>,
}

/// Reflectance ρ(λ) as linear sRGB under D65 (ρ = 1 gives (1, 1, 1)).
fn reflectance_rgb(rho: impl Fn(f32) -> f32) -> [f32; 3] {
    let (mut xyz, mut norm) = ([0.0f64; 3], 0.0f64);
    for nm in (380..=780).step_by(5) {
        let nm = nm as f64;
        let bar = skin_optics::color::cie_xyz_bar(nm);
        let e = skin_optics::color::d65(nm);
        let r = f64::from(rho(nm as f32));
        for c in 0..3 {
            xyz[c] += r * e * bar[c];
        }
        norm += e * bar[1];
    }
    xyz_to_linear_srgb(xyz.map(|v| (v / norm) as f32))
}

/// The passes of one pixel.
#[derive(Debug, Clone, Copy)]
struct Pixel {
    albedo: [f32; 3],
    normal: [f32; 3],
    depth: f32,
    skin: f32,
}

/// The passes of the primary ray from `o` along `d`.
fn first_hit_pixel(scene: &Scene, o: glam::Vec3, d: glam::Vec3) -> Pixel {
    let mut out = Pixel {
        albedo: [0.0; 3],
        normal: [0.0; 3],
        depth: NO_DEPTH,
        skin: 0.0,
    };
    match scene.intersect(o, d, 0.0, f32::INFINITY) {
        Some(Hit::Surface(s)) => {
            out.depth = s.t;
            out.normal = s.ns.to_array();
            let (rgb, is_skin) = match &scene.materials[s.material as usize] {
                Material::Skin(crate::material::SkinMaterial {
                    maps: Some(maps), ..
                }) => {
                    let at = maps.corners(s.uv);
                    (reflectance_rgb(|nm| at.total(nm).min(1.0)), 1.0)
                }
                Material::Skin(m) => {
                    let f = m.texture_factor(s.uv, &scene.textures);
                    let t = &m.total_reflectance;
                    (reflectance_rgb(|nm| (t.at_nm(nm) * f).min(1.0)), 1.0)
                }
                Material::Diffuse(m) => {
                    let tex = m
                        .albedo_texture
                        .map(|t| scene.textures[t.index].lookup(s.uv));
                    let rho = |nm| {
                        let base = m.albedo.at_nm(nm);
                        let t = tex.map_or(1.0, |rgb| linear_srgb_at_nm(rgb, nm));
                        (base * t).clamp(0.0, 1.0)
                    };
                    (reflectance_rgb(rho), 0.0)
                }
            };
            out.albedo = rgb;
            out.skin = is_skin;
        }
        Some(Hit::Light { t, .. }) => out.depth = t,
        None => {}
    }
    out
}

impl Passes {
    /// Trace one primary ray per pixel of a `width × height` image of `scene` (the pixels in
    /// parallel).
    #[must_use]
    pub fn first_hit(scene: &Scene, width: usize, height: usize) -> Self {
        let n = width * height;
        let aspect = width as f32 / height as f32;
        let pixels: Vec<Pixel> = (0..n)
            .into_par_iter()
            .map(|i| {
                let ndc = Vec2::new(
                    ((i % width) as f32 + 0.5) / width as f32,
                    ((i / width) as f32 + 0.5) / height as f32,
                );
                let (o, d) = scene.camera.generate_ray(ndc, aspect, Vec2::splat(0.5));
                first_hit_pixel(scene, o, d)
            })
            .collect();
        Self {
            width,
            height,
            albedo: pixels.iter().map(|p| p.albedo).collect(),
            normal: pixels.iter().map(|p| p.normal).collect(),
            depth: pixels.iter().map(|p| p.depth).collect(),
            skin: pixels.iter().map(|p| p.skin).collect(),
        }
    }

    /// Write `film` (linear sRGB `R`, `G`, `B`), its `variance.Y`, its per-pixel sample counts
    /// `samples.count` (as f32: exact up to 2²⁴) and these passes as one 32-bit float OpenEXR.
    pub fn write_exr(&self, film: &Film, path: &Path) -> Result<(), RenderError> {
        Ok(atomic::commit(vec![self.stage_exr(film, path)?])?)
    }

    /// The EXR of [`Passes::write_exr`], staged beside `path` for [`atomic::commit`] (so it can
    /// be committed together with the PNG).
    pub fn stage_exr(&self, film: &Film, path: &Path) -> Result<atomic::Staged, RenderError> {
        use exr::prelude::*;
        let (w, h) = (self.width, self.height);
        let out_err = |message: String| RenderError::Output {
            path: path.to_path_buf(),
            message,
        };
        let beauty: Vec<[f32; 3]> = (0..h)
            .flat_map(|y| (0..w).map(move |x| film.linear_srgb(x, y)))
            .collect();
        let variance: Vec<f32> = (0..h)
            .flat_map(|y| (0..w).map(move |x| film.variance(x, y) as f32))
            .collect();
        let samples: Vec<f32> = (0..h)
            .flat_map(|y| (0..w).map(move |x| film.samples(x, y) as f32))
            .collect();
        let ch = |name: &str, data: Vec<f32>| AnyChannel::new(name, FlatSamples::F32(data));
        let split = |v: &[[f32; 3]], c: usize| v.iter().map(|p| p[c]).collect::<Vec<f32>>();
        let mut channels = Vec::new();
        for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
            channels.push(ch(name, split(&beauty, c)));
            channels.push(ch(&format!("albedo.{name}"), split(&self.albedo, c)));
        }
        for (c, name) in ["X", "Y", "Z"].into_iter().enumerate() {
            channels.push(ch(&format!("normal.{name}"), split(&self.normal, c)));
        }
        channels.push(ch("depth.Z", self.depth.clone()));
        channels.push(ch("mask.skin", self.skin.clone()));
        channels.push(ch("variance.Y", variance));
        channels.push(ch("samples.count", samples));
        let layer = Layer::new(
            (w, h),
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(channels.into()),
        );
        let image = Image::from_layer(layer);
        atomic::stage(path, |tmp| {
            image
                .write()
                .to_file(tmp)
                .map_err(|e| out_err(e.to_string()))
        })
        .map_err(|e: RenderError| match e {
            e @ (RenderError::Output { .. } | RenderError::Write(_)) => e,
            other => out_err(other.to_string()),
        })
    }
}
