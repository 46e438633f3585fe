//! End-to-end checks of subsurface scattering in the tracer: the flat slab renders to the
//! model's total diffuse reflectance with the documented energy split plus the specular term, a
//! closed sphere of skin in a white furnace never outshines the environment, and skin parameters
//! at the edges of their ranges render finite, non-negative images.

use render::bssrdf::{Directional, EnergySplit};
mod common;

use common::{mean_xyz, run, scene, xyz_of};
use skin_optics::color::d65;
use skin_optics::{Preset, SkinParams, Wavelength};

/// Seed of every render in this file.
const SEED: u64 = 7;

/// A 2 m wide slab of skin under a distant D65 light of irradiance E (luminance 1) at normal
/// incidence, seen head-on, has radiance E(λ) [f_s(n, n) + T(0°) R_tot(λ) T(0°) / (π c)]
/// (separable BSSRDF with the specular-lobe split, `render::bssrdf::separable`): within 2% per
/// XYZ channel, for the light and the dark presets.
#[test]
fn flat_slab_renders_to_the_total_diffuse_reflectance_plus_specular() {
    for preset in ["light", "dark"] {
        let s = scene(&format!(
            r#"
            [camera]
            position_mm = [0, 0, 500]
            look_at_mm = [0, 0, 0]
            fov_deg = 2
            [materials.skin]
            type = "skin"
            preset = "{preset}"
            [[meshes]]
            shape = "quad"
            material = "skin"
            scale = 1000
            [[lights]]
            type = "distant"
            direction = [0, 0, 1]
            spectrum = "d65"
            intensity = 1
            "#
        ));
        let film = run(&s, 32, 32, 48, SEED);
        let skin = SkinParams::preset(preset.parse::<Preset>().unwrap());
        let ts = brdf::TorranceSparrow::new(
            brdf::DEFAULT_ROUGHNESS,
            skin.oiliness() as f32,
            skin.eta() as f32,
        )
        .unwrap();
        let dir = Directional::new(ts.clone(), EnergySplit::default());
        let n = glam::Vec3::Z;
        let specular = f64::from(ts.eval(n, n));
        let split = f64::from(
            dir.transmittance(1.0).powi(2) / (std::f32::consts::PI * dir.normalisation()),
        );
        let d65_y = xyz_of(d65)[1];
        let want = xyz_of(|nm| {
            let rd = multipole::skin::total_reflectance(
                &skin,
                Wavelength::new(nm).unwrap(),
                multipole::Method::default(),
            )
            .unwrap();
            d65(nm) / d65_y * (specular + split * rd)
        });
        let got = mean_xyz(&film);
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= 0.02 * want[c],
                "{preset}: channel {c}: {got:?} vs {want:?}"
            );
        }
    }
}

/// A closed sphere of skin inside a uniform white environment of radiance 1: the rendered
/// radiance never exceeds the environment's (mean over the sphere within 1% MC noise, every
/// pixel within a loose per-pixel bound), for a large sphere and one smaller than the profiles'
/// reach (where the local fallback for missing surface is exercised).
#[test]
fn skin_sphere_in_a_white_furnace_never_exceeds_the_environment() {
    for radius in [100.0, 2.0] {
        let s = scene(&format!(
            r#"
            [camera]
            position_mm = [0, 0, {}]
            look_at_mm = [0, 0, 0]
            fov_deg = 10
            [environment]
            spectrum = "constant"
            intensity = 1
            [materials.skin]
            type = "skin"
            preset = "light"
            hemoglobin = 0.0
            melanin = 0.0
            [[meshes]]
            shape = "sphere"
            material = "skin"
            scale = {radius}
            "#,
            radius * 8.0
        ));
        let film = run(&s, 24, 24, 32, SEED);
        let y = xyz_of(|_| 1.0)[1];
        let env = xyz_of(|_| 1.0 / y);
        let got = mean_xyz(&film);
        for c in 0..3 {
            assert!(
                got[c] <= env[c] * 1.01,
                "radius {radius}: channel {c}: {got:?} vs environment {env:?}"
            );
        }
        let (w, h) = film.size();
        for py in 0..h {
            for px in 0..w {
                let v = film.xyz(px, py);
                assert!(
                    v.iter().all(|x| x.is_finite() && *x >= 0.0),
                    "pixel {px},{py}: {v:?}"
                );
            }
        }
    }
}

/// Skin parameters at the edges of their ranges render finite, non-negative images.
#[test]
fn edge_parameters_render_finite_non_negative_images() {
    for (melanin, hemoglobin) in [(0.5, 0.05), (0.1, 0.1), (0.0, 0.05), (0.0, 0.0), (0.5, 0.1)] {
        let s = scene(&format!(
            r#"
            [camera]
            position_mm = [0, 0, 300]
            look_at_mm = [0, 0, 0]
            fov_deg = 30
            [environment]
            spectrum = "d65"
            intensity = 0.3
            [materials.skin]
            type = "skin"
            melanin = {melanin}
            hemoglobin = {hemoglobin}
            [[meshes]]
            shape = "sphere"
            material = "skin"
            scale = 50
            [[lights]]
            type = "sphere"
            center_mm = [150, 150, 150]
            radius_mm = 20
            intensity = 30
            "#
        ));
        let film = run(&s, 16, 16, 4, SEED);
        let (w, h) = film.size();
        let mut total = 0.0;
        for py in 0..h {
            for px in 0..w {
                let v = film.xyz(px, py);
                assert!(
                    v.iter().all(|x| x.is_finite() && *x >= 0.0),
                    "C_m {melanin} C_h {hemoglobin}: {v:?}"
                );
                total += v[1];
            }
        }
        assert!(total > 0.0, "C_m {melanin} C_h {hemoglobin}: black image");
    }
}
