//! Scaffolding for end-to-end render tests, here and in the crates above: scene texts built from
//! their parts ([`SceneText`]), loading, rendering and the XYZ of a spectrum. Built with the
//! `test-support` feature only; the functions panic on failure, as tests want.

use crate::film::Film;
use crate::material::SkinKnobs;
use crate::renderer::{RenderOptions, render};
use crate::scene::Scene;
use skin_optics::color::{cie_xyz_bar, cie_y_integral};

/// A 2 m slab of light skin under a distant D65 light, seen head-on from 500 mm (2° field).
pub const LIGHT_SLAB: &str = r#"
[camera]
position_mm = [0, 0, 500]
look_at_mm = [0, 0, 0]
fov_deg = 2
[materials.skin]
type = "skin"
preset = "light"
[[meshes]]
shape = "quad"
material = "skin"
scale = 1000
[[lights]]
type = "distant"
direction = [0, 0, 1]
spectrum = "d65"
intensity = 1
"#;

/// The TOML of a test scene, assembled part by part so that no test spells out the same camera,
/// material, mesh or light again. The camera looks at the origin with +Y up.
#[derive(Debug, Clone)]
pub struct SceneText(String);

impl SceneText {
    /// A scene whose camera at `position_mm` looks at the origin with a `fov_deg` field of view.
    pub fn camera(position_mm: [f32; 3], fov_deg: f32) -> Self {
        let [x, y, z] = position_mm;
        Self(format!(
            "[camera]\nposition_mm = [{x}, {y}, {z}]\nlook_at_mm = [0, 0, 0]\nfov_deg = {fov_deg}\n"
        ))
    }

    /// Append raw TOML (a key, a section).
    #[must_use]
    pub fn with(mut self, toml: &str) -> Self {
        self.0.push_str(toml);
        self.0.push('\n');
        self
    }

    /// A uniform environment of `spectrum` ("constant", "d65") with luminance `intensity`.
    #[must_use]
    pub fn environment(self, spectrum: &str, intensity: f32) -> Self {
        self.with(&format!(
            "[environment]\nspectrum = \"{spectrum}\"\nintensity = {intensity}"
        ))
    }

    /// A Lambertian material `name` of constant `albedo`.
    #[must_use]
    pub fn diffuse(self, name: &str, albedo: f32) -> Self {
        self.with(&format!(
            "[materials.{name}]\ntype = \"diffuse\"\nalbedo = {albedo}"
        ))
    }

    /// A skin material `name` with the given extra keys (`preset = "light"`, `melanin = 0.1`, ...).
    #[must_use]
    pub fn skin(self, name: &str, keys: &str) -> Self {
        self.with(&format!("[materials.{name}]\ntype = \"skin\"\n{keys}"))
    }

    /// A built-in `shape` ("sphere", "quad") of `material`, scaled by `scale` at the origin.
    #[must_use]
    pub fn mesh(self, shape: &str, material: &str, scale: f32) -> Self {
        self.with(&format!(
            "[[meshes]]\nshape = \"{shape}\"\nmaterial = \"{material}\"\nscale = {scale}"
        ))
    }

    /// A distant D65 light from unit direction `to_light` with irradiance (luminance) `intensity`.
    #[must_use]
    pub fn distant(self, to_light: [f32; 3], intensity: f32) -> Self {
        let [x, y, z] = to_light;
        self.with(&format!(
            "[[lights]]\ntype = \"distant\"\ndirection = [{x}, {y}, {z}]\nspectrum = \"d65\"\nintensity = {intensity}"
        ))
    }

    /// A sphere light at `center_mm` of `radius_mm` and luminance `intensity`.
    #[must_use]
    pub fn sphere_light(self, center_mm: [f32; 3], radius_mm: f32, intensity: f32) -> Self {
        let [x, y, z] = center_mm;
        self.with(&format!(
            "[[lights]]\ntype = \"sphere\"\ncenter_mm = [{x}, {y}, {z}]\nradius_mm = {radius_mm}\nintensity = {intensity}"
        ))
    }

    /// The TOML text.
    #[must_use]
    pub fn text(&self) -> &str {
        &self.0
    }

    /// The scene, loaded with default options.
    #[must_use]
    pub fn load(&self) -> Scene {
        scene(&self.0)
    }
}

/// The camera ray of `scene` through the centre of pixel (`x`, `y`) of a `side` × `side` image:
/// origin (mm) and unit direction.
#[must_use]
pub fn pixel_ray(scene: &Scene, side: usize, x: usize, y: usize) -> (glam::Vec3, glam::Vec3) {
    let ndc = glam::Vec2::new(
        (x as f32 + 0.5) / side as f32,
        (y as f32 + 0.5) / side as f32,
    );
    scene.camera.generate_ray(ndc, 1.0, glam::Vec2::ZERO)
}

/// The white furnace: a diffuse albedo-1 sphere of radius 100 mm inside a constant environment
/// of luminance 1, seen from 300 mm.
#[must_use]
pub fn white_furnace() -> SceneText {
    SceneText::camera([0.0, 0.0, 300.0], 20.0)
        .environment("constant", 1.0)
        .diffuse("white", 1.0)
        .mesh("sphere", "white", 100.0)
}

/// A 2 m wide quad of `material` at z = 0 seen head-on from 500 mm with a 10° field of view.
#[must_use]
pub fn plane(material: &str) -> SceneText {
    SceneText::camera([0.0, 0.0, 500.0], 10.0).mesh("quad", material, 1000.0)
}

/// A scene from TOML text, with default options.
pub fn scene(text: &str) -> Scene {
    Scene::from_toml(text, "test.toml", None, &SkinKnobs::default()).unwrap()
}

/// Render `scene` at `w`×`h` with `spp` samples per pixel and a fixed `seed`.
pub fn run(scene: &Scene, w: usize, h: usize, spp: u32, seed: u64) -> Film {
    let settings = RenderOptions {
        width: w,
        height: h,
        spp,
        seed,
        ..Default::default()
    };
    render(scene, &settings.validate().unwrap()).unwrap().0
}

/// Mean XYZ over the whole film.
pub fn mean_xyz(film: &Film) -> [f64; 3] {
    film_mean(film, |x, y| film.xyz(x, y))
}

/// Mean over the whole film of a per-pixel triple `value(x, y)` (XYZ, linear sRGB, ...).
pub fn film_mean(film: &Film, value: impl Fn(usize, usize) -> [f32; 3]) -> [f64; 3] {
    let (w, h) = film.size();
    let mut s = [0.0f64; 3];
    for y in 0..h {
        for x in 0..w {
            let v = value(x, y);
            for c in 0..3 {
                s[c] += f64::from(v[c]);
            }
        }
    }
    s.map(|v| v / (w * h) as f64)
}

/// Fail, naming `what` and the pixel, unless every XYZ value of `film` is finite and ≥ 0.
pub fn assert_finite_non_negative(film: &Film, what: &str) {
    let (w, h) = film.size();
    for y in 0..h {
        for x in 0..w {
            let v = film.xyz(x, y);
            assert!(
                v.iter().all(|c| c.is_finite() && *c >= 0.0),
                "{what}: pixel {x},{y}: {v:?}"
            );
        }
    }
}

/// XYZ of a spectrum s(λ) over the rendered range 380–780 nm, normalised like the film
/// (a constant radiance of 1 has Y = 1).
pub fn xyz_of(s: impl Fn(f64) -> f64) -> [f64; 3] {
    let mut xyz = [0.0; 3];
    for nm in 380..=780 {
        let bar = cie_xyz_bar(f64::from(nm));
        for c in 0..3 {
            xyz[c] += s(f64::from(nm)) * bar[c];
        }
    }
    xyz.map(|v| v / cie_y_integral())
}

/// Assert every channel of `got` is within relative `rel` of `want`.
pub fn assert_close(got: [f64; 3], want: [f64; 3], rel: f64, what: &str) {
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() <= rel * want[c].abs(),
            "{what}: channel {c}: {got:?} vs {want:?}"
        );
    }
}

/// A valid 2×2 grey (0.5) RGB OpenEXR file written by the `exr` crate, for tests that corrupt it.
pub fn grey_exr_2x2() -> Vec<u8> {
    use exr::prelude::*;
    let mut bytes = Vec::new();
    Image::from_channels(
        (2, 2),
        SpecificChannels::rgb(|_: Vec2<usize>| (0.5f32, 0.5f32, 0.5f32)),
    )
    .write()
    .to_buffered(std::io::Cursor::new(&mut bytes))
    .unwrap();
    bytes
}

/// ∫₀^r_max 2π r³ R(r) dr of a radial profile `profile` (mm⁻² at r in mm), by the midpoint rule
/// over 20,000 steps: the second moment that sets the curvature term's gain (docs/physics.md §8.2)
/// once divided by R_tot.
pub fn radial_third_moment(profile: impl Fn(f32) -> f64, r_max_mm: f64) -> f64 {
    let n = 20_000;
    (0..n)
        .map(|i| {
            let d = (i as f64 + 0.5) / n as f64 * r_max_mm;
            profile(d as f32) * 2.0 * std::f64::consts::PI * d * d * d * r_max_mm / n as f64
        })
        .sum()
}

/// The radiance a skin sphere of directional term `dir` and total R_tot `r_tot` shows under a
/// sky of radiance 1 at wavelength `nm`, as a function of the view cosine μ, with the curvature
/// term's gain `gain` (docs/physics.md §8.2): (1 − T(μ)) + a(μ) R_tot (1 + G).
pub fn sky_sphere_closed_form(
    dir: &crate::bssrdf::Directional,
    nm: f32,
    r_tot: f64,
    gain: f64,
) -> impl Fn(f32) -> f64 + '_ {
    move |mu| {
        let t = f64::from(dir.transmittance(mu));
        (1.0 - t) + f64::from(dir.factor(mu, nm)) * r_tot * (1.0 + gain)
    }
}

/// A `side` × `side` render of `scene` by the BSSRDF at the single wavelength `nm`.
pub fn render_bssrdf_at_nm(scene: &Scene, side: usize, spp: u32, seed: u64, nm: f32) -> Film {
    use crate::integrator::{BodyIntegrator, IntegratorKind};
    let body = BodyIntegrator::build(scene, IntegratorKind::Bssrdf);
    let opts = RenderOptions {
        width: side,
        height: side,
        spp,
        seed,
        wavelength_nm: Some(nm),
        ..Default::default()
    };
    crate::renderer::render_with(scene, &body, &opts.validate().expect("valid options"), None)
        .expect("the render")
        .0
}

/// A film against a closed form per pixel, over the pixels of a `side` × `side` image of `scene`
/// whose centre ray meets a surface at a point where `inside` holds: (the film's summed
/// luminance, its summed variance, the closed form summed, pixels). Each pixel's closed form is
/// the mean of `closed(μ)` over `k` × `k` rays through the pixel, μ the cosine between the view
/// and the shading normal where each meets the surface.
pub fn film_against_closed_form(
    scene: &Scene,
    film: &Film,
    (side, k): (usize, usize),
    inside: impl Fn(glam::Vec3) -> bool,
    closed: impl Fn(f32) -> f64,
) -> (f64, f64, f64, usize) {
    use crate::scene::Hit;
    let (mut got, mut var, mut want, mut pixels) = (0.0, 0.0, 0.0, 0usize);
    for py in 0..side {
        for px in 0..side {
            let ray = |sx: f32, sy: f32| {
                let ndc = glam::Vec2::new(
                    (px as f32 + sx) / side as f32,
                    (py as f32 + sy) / side as f32,
                );
                let (o, d) = scene.camera.generate_ray(ndc, 1.0, glam::Vec2::ZERO);
                (d, scene.intersect(o, d, 0.0, f32::INFINITY))
            };
            if !matches!(ray(0.5, 0.5).1, Some(Hit::Surface(si)) if inside(si.p)) {
                continue;
            }
            let mut sum = 0.0;
            for j in 0..k * k {
                let (sx, sy) = (
                    ((j % k) as f32 + 0.5) / k as f32,
                    ((j / k) as f32 + 0.5) / k as f32,
                );
                let (d, Some(Hit::Surface(si))) = ray(sx, sy) else {
                    panic!("pixel {px},{py} leaves the surface")
                };
                sum += closed((-d).dot(si.ns).clamp(0.0, 1.0));
            }
            want += sum / (k * k) as f64;
            got += f64::from(film.xyz(px, py)[1]);
            var += film.variance(px, py);
            pixels += 1;
        }
    }
    (got, var, want, pixels)
}

/// Heterogeneous skin on a flat slab (docs/physics.md §19.4): a 40 × 40 × 20 mm box whose
/// texture coordinates map x ∈ [−20, 20] mm to u ∈ [0, 1] and y ∈ [20, −20] mm to v ∈ [0, 1]
/// (every vertex, so a point's nearest surface point reads the texel above or below it), under a
/// sky of spectral radiance 1, seen from +Z along a strip across x.
pub mod hetero {
    use crate::film::Film;
    use crate::integrator::{BodyIntegrator, IntegratorKind};
    use crate::material::SkinKnobs;
    use crate::renderer::{RenderOptions, render_with};
    use crate::scene::Scene;
    use std::fmt::Write as _;
    use std::path::Path;

    /// Side of the slab's square face, mm.
    pub const SLAB_SIDE_MM: f32 = 40.0;
    /// Depth of the slab, mm.
    pub const SLAB_DEPTH_MM: f32 = 20.0;

    /// The slab scene at `dir` (its OBJ written there) with skin keys `keys`, expected to fail to
    /// load: the error and its message.
    ///
    /// # Panics
    /// If the scene loads.
    pub fn load_error(dir: &Path, keys: &str) -> (crate::error::RenderError, String) {
        std::fs::write(dir.join("slab.obj"), slab_obj()).expect("a writable test folder");
        let text = format!(
            "[camera]\nposition_mm = [0, 0, 400]\nlook_at_mm = [0, 0, 0]\nfov_deg = 1\n\
             [materials.skin]\ntype = \"skin\"\n{keys}\n\
             [[meshes]]\nfile = \"slab.obj\"\nmaterial = \"skin\"\n"
        );
        let Err(e) = Scene::from_toml(&text, "bad.toml", Some(dir), &SkinKnobs::default()) else {
            panic!("{keys}: the scene loaded");
        };
        let m = e.to_string();
        (e, m)
    }

    /// The slab as OBJ with its planar texture coordinates (12 triangles, outward faces).
    #[must_use]
    pub fn slab_obj() -> String {
        let (h, d) = (0.5 * SLAB_SIDE_MM, 0.5 * SLAB_DEPTH_MM);
        let mut obj = String::from("# slab with planar uv\n");
        for i in 0..8 {
            let sign = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
            let (x, y, z) = (sign(1) * h, sign(2) * h, sign(4) * d);
            let _ = writeln!(
                obj,
                "v {x} {y} {z}\nvt {} {}",
                (x + h) / SLAB_SIDE_MM,
                (h - y) / SLAB_SIDE_MM
            );
        }
        let faces = [
            [1, 3, 7, 5],
            [2, 6, 8, 4],
            [1, 5, 6, 2],
            [3, 4, 8, 7],
            [1, 2, 4, 3],
            [5, 7, 8, 6],
        ];
        let normals = ["-1 0 0", "1 0 0", "0 -1 0", "0 1 0", "0 0 -1", "0 0 1"];
        for (k, ([a, b, c, e], n)) in faces.iter().zip(normals).enumerate() {
            let k = k + 1;
            let _ = writeln!(
                obj,
                "vn {n}\nf {a}/{a}/{k} {b}/{b}/{k} {c}/{c}/{k}\nf {a}/{a}/{k} {c}/{c}/{k} {e}/{e}/{k}"
            );
        }
        obj
    }

    /// A 32-bit float OpenEXR of `channels` (name, row-major values) at `width` × `height`.
    #[must_use]
    pub fn exr_bytes(width: usize, height: usize, channels: Vec<(&str, Vec<f32>)>) -> Vec<u8> {
        crate::texture::channels_exr_bytes(width, height, channels).expect("an EXR in memory")
    }

    /// A `melanin` channel of `side_x` × `side_y` texels over the slab's face, C_m = `f(x, y)` at
    /// each texel's centre (x, y in mm).
    #[must_use]
    pub fn melanin_exr(side_x: usize, side_y: usize, f: impl Fn(f32, f32) -> f32) -> Vec<u8> {
        let h = 0.5 * SLAB_SIDE_MM;
        let values = (0..side_y)
            .flat_map(|j| (0..side_x).map(move |i| (i, j)))
            .map(|(i, j)| {
                let x = -h + (i as f32 + 0.5) * SLAB_SIDE_MM / side_x as f32;
                let y = h - (j as f32 + 0.5) * SLAB_SIDE_MM / side_y as f32;
                f(x, y)
            })
            .collect();
        exr_bytes(side_x, side_y, vec![("melanin", values)])
    }

    /// The slab scene in `dir` (writes slab.obj there) with skin keys `skin_keys`, seen from
    /// 400 mm along a strip x ∈ [−`half_mm`, `half_mm`] of `columns` × 2 pixels.
    #[must_use]
    pub fn strip_scene(dir: &Path, half_mm: f32, columns: usize, skin_keys: &str) -> Scene {
        std::fs::write(dir.join("slab.obj"), slab_obj()).unwrap();
        let distance = 400.0f32;
        let top = 0.5 * SLAB_DEPTH_MM;
        let half_height = half_mm * 2.0 / columns as f32;
        let fov = 2.0 * (half_height / (distance - top)).atan().to_degrees();
        let text = format!(
            "[camera]\nposition_mm = [0, 0, {distance}]\nlook_at_mm = [0, 0, 0]\nfov_deg = {fov}\n\
             [environment]\nspectral_radiance = 1\n\
             [materials.skin]\ntype = \"skin\"\n{skin_keys}\n\
             [[meshes]]\nfile = \"slab.obj\"\nmaterial = \"skin\"\n"
        );
        Scene::from_toml(&text, "slab.toml", Some(dir), &SkinKnobs::default()).unwrap()
    }

    /// Render `scene` at one wavelength `nm`, `columns` × 2 pixels, with integrator `kind`.
    #[must_use]
    pub fn render_strip(
        scene: &Scene,
        kind: IntegratorKind,
        columns: usize,
        nm: f32,
        spp: u32,
        seed: u64,
    ) -> Film {
        let body = BodyIntegrator::build(scene, kind);
        let opts = RenderOptions {
            width: columns,
            height: 2,
            spp,
            seed,
            wavelength_nm: Some(nm),
            ..Default::default()
        };
        render_with(scene, &body, &opts.validate().unwrap(), None)
            .unwrap()
            .0
    }

    /// Per column: the mean radiance of its pixels and its standard error.
    #[must_use]
    pub fn columns(film: &Film) -> Vec<(f64, f64)> {
        let (w, h) = film.size();
        (0..w)
            .map(|x| {
                let (mut s, mut v) = (0.0, 0.0);
                for y in 0..h {
                    s += f64::from(film.linear_srgb(x, y)[1]);
                    v += film.variance(x, y);
                }
                (s / h as f64, v.sqrt() / h as f64)
            })
            .collect()
    }

    /// The mean and standard error over the columns whose centres lie in [`from_mm`, `to_mm`]
    /// of a strip x ∈ [−`half_mm`, `half_mm`].
    #[must_use]
    pub fn region(cols: &[(f64, f64)], half_mm: f32, from_mm: f32, to_mm: f32) -> (f64, f64) {
        let n = cols.len();
        let picked: Vec<(f64, f64)> = cols
            .iter()
            .enumerate()
            .filter(|(i, _)| {
                let x = -half_mm + (*i as f32 + 0.5) * 2.0 * half_mm / n as f32;
                (from_mm..=to_mm).contains(&x)
            })
            .map(|(_, c)| *c)
            .collect();
        let k = picked.len() as f64;
        let mean = picked.iter().map(|c| c.0).sum::<f64>() / k;
        let se = picked.iter().map(|c| c.1 * c.1).sum::<f64>().sqrt() / k;
        (mean, se)
    }

    /// The columns of [`render_strip`]'s film ([`columns`]).
    #[must_use]
    pub fn strip_columns(
        scene: &Scene,
        kind: IntegratorKind,
        columns_n: usize,
        nm: f32,
        spp: u32,
        seed: u64,
    ) -> Vec<(f64, f64)> {
        columns(&render_strip(scene, kind, columns_n, nm, spp, seed))
    }

    /// The mean over the whole strip of `scene` (half-width `half_mm`, `columns` columns) at `nm`,
    /// with its standard error, by the walk at `spp_walk` (seed 1) and the BSSRDF at `spp_bssrdf`
    /// (seed 2): a uniform slab's BSSRDF–walk gap.
    #[must_use]
    pub fn uniform_means(
        scene: &Scene,
        half_mm: f32,
        columns_n: usize,
        nm: f32,
        (spp_walk, spp_bssrdf): (u32, u32),
    ) -> [(f64, f64); 2] {
        let mean = |kind, spp, seed| {
            region(
                &strip_columns(scene, kind, columns_n, nm, spp, seed),
                half_mm,
                -half_mm,
                half_mm,
            )
        };
        [
            mean(IntegratorKind::Volumetric, spp_walk, 1),
            mean(IntegratorKind::Bssrdf, spp_bssrdf, 2),
        ]
    }
}
