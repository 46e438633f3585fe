//! Our reference for the Cycles sphere: the same sphere of skin rendered by our volumetric walk
//! (`render::volumetric`, docs/physics.md §15) under the same uniform white sky, its subsurface
//! part read out over the same disc.
//!
//! A sphere under a uniform sky is not a flat slab seen at normal incidence: by reciprocity a pixel
//! is the sphere's albedo for light arriving from the camera at the pixel's incidence cosine μ, and
//! light that enters a finite convex body may leave it anywhere, so both the spread of μ over the
//! disc and the sphere's size (against the skin's diffusion length, millimetres in red) change the
//! mean. The walk through our two layers on the same sphere holds both.
//!
//! The surface is the smooth dielectric (η of the skin), so the specular part of a pixel is the
//! Fresnel reflectance F(μ) exactly (the sky is uniform and the sphere convex) and the subsurface
//! part is the pixel minus F(μ).

use brdf::fresnel::dielectric_reflectance;
use render::fidelity::FidelityKnobs;
use render::integrator::{BodyIntegrator, IntegratorKind};
use render::material::SkinKnobs;
use render::renderer::{RenderOptions, render_with};
use render::scene::Scene;
use skin_optics::{Preset, SkinParams};

/// Camera distance from the sphere's centre, in sphere radii: far enough that the perspective
/// rays are parallel within 0.12° (the pixel's μ is taken as the orthographic one).
const CAMERA_DISTANCE_RADII: f64 = 500.0;

/// The sphere, its read-out and the render's size.
#[derive(Debug, Clone, Copy)]
pub struct SphereView {
    /// Sphere radius, mm.
    pub radius_mm: f64,
    /// Pixels averaged: those whose centre lies within this fraction of the projected radius.
    pub mask: f64,
    /// Film side, pixels (the frame is the sphere's bounding square).
    pub pixels: usize,
    /// Samples per pixel.
    pub spp: u32,
}

/// Mean subsurface part (pixel − F(μ)) over the disc per linear Rec.709 channel and its standard
/// error over pixels, of the skin preset `preset` (light, medium, dark) as a smooth-faced sphere under a uniform D65 sky of luminance 1
/// (a white reflector renders as 1 in every channel), rendered by our volumetric walk.
pub fn volumetric_sphere(
    preset: &str,
    view: SphereView,
    threads: Option<usize>,
) -> anyhow::Result<([f64; 3], [f64; 3])> {
    let distance = CAMERA_DISTANCE_RADII * view.radius_mm;
    let fov_deg = 2.0 * (view.radius_mm / distance).atan().to_degrees();
    let toml = format!(
        "[camera]\nposition_mm = [0, 0, {distance}]\nlook_at_mm = [0, 0, 0]\nfov_deg = {fov_deg}\n\
         [environment]\nspectrum = \"d65\"\nintensity = 1\n\
         [materials.skin]\ntype = \"skin\"\npreset = \"{preset}\"\nsurface = \"smooth\"\n\
         [[meshes]]\nshape = \"sphere\"\nmaterial = \"skin\"\nunits_mm = {}\n",
        view.radius_mm
    );
    // The fidelity the command line resolves for this film (`skin render --height`).
    let knobs = SkinKnobs {
        fidelity: FidelityKnobs {
            image_height: Some(u32::try_from(view.pixels)?),
            ..FidelityKnobs::default()
        },
        ..SkinKnobs::default()
    };
    let scene = Scene::from_toml(&toml, "sphere.toml", None, &knobs)?;
    let body = BodyIntegrator::build(&scene, IntegratorKind::Volumetric);
    let mut options = RenderOptions {
        width: view.pixels,
        height: view.pixels,
        spp: view.spp,
        seed: 7,
        threads,
        integrator: IntegratorKind::Volumetric,
        ..Default::default()
    };
    // As `skin render` does: the level of detail follows the camera's pixel footprint.
    options.path.pixel_angle_rad = scene.camera.pixel_angle_rad(view.pixels);
    let settings = options.validate()?;
    let (film, _) = render_with(&scene, &body, &settings, None)?;
    let eta = scene_eta(preset)?;
    let n = view.pixels;
    let mut parts: Vec<[f64; 3]> = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let u = (x as f64 + 0.5) / n as f64 * 2.0 - 1.0;
            let v = (y as f64 + 0.5) / n as f64 * 2.0 - 1.0;
            let r2 = u * u + v * v;
            if r2 >= view.mask * view.mask {
                continue;
            }
            let f = dielectric_reflectance((1.0 - r2).sqrt(), eta);
            let rgb = film.linear_srgb(x, y);
            parts.push(rgb.map(|c| f64::from(c) - f));
        }
    }
    anyhow::ensure!(
        parts.len() > 1,
        "sphere: no pixel within the mask {}",
        view.mask
    );
    let k = parts.len() as f64;
    let mut mean = [0.0; 3];
    let mut se = [0.0; 3];
    for c in 0..3 {
        mean[c] = parts.iter().map(|p| p[c]).sum::<f64>() / k;
        let var = parts.iter().map(|p| (p[c] - mean[c]).powi(2)).sum::<f64>() / (k - 1.0);
        se[c] = (var / k).sqrt();
    }
    Ok((mean, se))
}

/// Index of refraction of the preset's skin (the smooth face's η).
fn scene_eta(preset: &str) -> anyhow::Result<f64> {
    let p: Preset = preset
        .parse()
        .map_err(|e| anyhow::anyhow!("sphere preset {preset}: {e}"))?;
    Ok(SkinParams::preset(p).eta())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Dark skin's light leaves within about a millimetre of where it entered, so its sphere, far
    /// larger, returns the same disc mean at any radius (a half-space's reflectance has no length
    /// scale): 20 and 40 mm agree within 4σ. A camera, field of view or mask that did not follow
    /// the radius would pair pixels with the wrong F(μ) (F is 0.04–0.2 over the disc against a
    /// subsurface part of 0.010–0.020) and fail this.
    #[test]
    fn dark_sphere_subsurface_part_does_not_depend_on_the_radius() {
        let view = |radius_mm| SphereView {
            radius_mm,
            mask: 0.95,
            pixels: 48,
            spp: 256,
        };
        let (a, sa) = volumetric_sphere("dark", view(20.0), None).unwrap();
        let (b, sb) = volumetric_sphere("dark", view(40.0), None).unwrap();
        for c in 0..3 {
            let tol = 4.0 * sa[c].hypot(sb[c]);
            assert!(
                (a[c] - b[c]).abs() < tol && a[c] > 0.0,
                "channel {c}: {} ± {} at 20 mm, {} ± {} at 40 mm (tolerance {tol})",
                a[c],
                sa[c],
                b[c],
                sb[c]
            );
        }
    }
}
