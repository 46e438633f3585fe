//! End-to-end checks of subsurface scattering in the tracer: the flat slab renders to the
//! model's total diffuse reflectance with the documented energy split plus the specular term, a
//! closed sphere of skin in a white furnace renders to the separable BSSRDF's closed form there,
//! and skin parameters at the edges of their ranges render finite, non-negative images.

use render::bssrdf::{Directional, EnergySplit, IncidenceGain};
use render::testing as common;
use std::sync::Arc;

use common::{SceneText, assert_finite_non_negative, mean_xyz, run, xyz_of};
use glam::{Vec2, Vec3};
use render::material::Material;
use render::scene::Hit;
use skin_optics::color::d65;
use skin_optics::{Preset, SkinParams, Wavelength};

/// Seed of every render in this file.
const SEED: u64 = 7;

/// The default oily surface of `skin` as the boundary of its totals (docs/physics.md §10.1).
fn oily(skin: &SkinParams) -> multipole::Surface {
    multipole::Surface::lobe(f64::from(brdf::DEFAULT_ROUGHNESS), skin.oiliness()).unwrap()
}

/// R_tot(λ) per unit flux entering `skin` under its default oily surface, by the default method
/// (adding-doubling, §10.1), as the scene's tables use.
fn oily_total(skin: &SkinParams, nm: f64) -> f64 {
    let medium =
        multipole::LayeredMedium::skin(skin, Wavelength::new(nm).unwrap(), multipole::DEFAULT_G)
            .unwrap()
            .with_surface(oily(skin));
    multipole::skin::medium_total_reflectance(&medium, multipole::Method::default()).unwrap()
}

/// A 2 m wide slab of skin of `preset` at z = 0 under a distant D65 light of irradiance 1 (luminance)
/// from the unit direction `to_light`, seen from `camera` (mm) with a 2° field of view. Full
/// fidelity (10-nm table rows): these tests check the tracer against the model, and the automatic
/// wavelength choice trades up to ΔE2000 0.5 of the flat colour (docs/physics.md §16.2; for the
/// dark preset's 100-nm rows up to 3% in X here).
fn slab(preset: &str, to_light: Vec3, camera: Vec3) -> render::scene::Scene {
    slab_text(preset, to_light, camera).load()
}

/// The scene text of [`slab`].
fn slab_text(preset: &str, to_light: Vec3, camera: Vec3) -> SceneText {
    SceneText::camera(camera.to_array(), 2.0)
        .skin("skin", &format!("preset = \"{preset}\""))
        .mesh("quad", "skin", 1000.0)
        .distant(to_light.to_array(), 1.0)
        .with("[fidelity]\nfidelity = \"full\"")
}

/// The closed-form XYZ of that slab seen from `wo` and lit from `wi` (unit vectors, z the normal):
/// E(λ) cos θ_i [f_s(ω_o, ω_i) + T(θ_i) a(θ_i, λ) T(θ_o) a(θ_o, λ) R_tot(λ) / (π c(λ))] (separable
/// BSSRDF with the specular-lobe split and the adding-doubling incidence gain a,
/// `render::bssrdf::separable`, docs/physics.md §8.1; R_tot and a under the oily boundary, §10.1,
/// as the scene's tables use).
fn slab_closed_form(preset: &str, wi: Vec3, wo: Vec3) -> [f64; 3] {
    slab_closed_form_with(preset, wi, wo, |_| 1.0)
}

/// [`slab_closed_form`] with the subsurface term multiplied by `lobe(λ)` (the azimuthal lobe M at
/// the slab's angles, docs/physics.md §8.3).
fn slab_closed_form_with(preset: &str, wi: Vec3, wo: Vec3, lobe: impl Fn(f32) -> f64) -> [f64; 3] {
    let skin = SkinParams::preset(preset.parse::<Preset>().unwrap());
    let ts = brdf::TorranceSparrow::new(
        brdf::DEFAULT_ROUGHNESS,
        skin.oiliness() as f32,
        skin.eta() as f32,
    )
    .unwrap();
    let media = render::media::SkinMedia::new(&skin, multipole::DEFAULT_G)
        .unwrap()
        .with_surface(oily(&skin));
    let gain = IncidenceGain::build(media.every_10nm(), multipole::DEFAULT_G).unwrap();
    let dir = Directional::new(ts.clone(), EnergySplit::default()).with_incidence(Arc::new(gain));
    let cos_i = f64::from(wi.z);
    let specular = f64::from(ts.eval(wo, wi));
    let d65_y = xyz_of(d65)[1];
    xyz_of(|nm| {
        let l = nm as f32;
        let split = f64::from(
            dir.factor(wi.z, l) * dir.factor(wo.z, l)
                / (std::f32::consts::PI * dir.normalisation_at(l)),
        );
        let rd = oily_total(&skin, nm);
        d65(nm) / d65_y * cos_i * (specular + split * rd * lobe(l))
    })
}

/// The azimuthal lobe M of `scene`'s first material (a skin) for light from `wi` leaving toward
/// `wo` (unit, z the normal), per wavelength (docs/physics.md §8.3; 1 without the lobe).
fn lobe_factor(scene: &render::scene::Scene, wi: Vec3, wo: Vec3) -> impl Fn(f32) -> f64 {
    let Material::Skin(skin) = &scene.materials[0] else {
        panic!("skin");
    };
    let lobe = skin.subsurface.as_ref().and_then(|s| s.azimuth.clone());
    let (hi, ho) = (-wi.truncate(), wo.truncate());
    let cos_phi = if hi.length() > 0.0 && ho.length() > 0.0 {
        hi.normalize().dot(ho.normalize())
    } else {
        0.0
    };
    move |nm| {
        lobe.as_ref()
            .map_or(1.0, |l| f64::from(l.modulation(wi.z, wo.z, cos_phi, nm)))
    }
}

/// Render the slab at 32×32 and compare its mean XYZ with the closed form (with the material's
/// azimuthal lobe) within `rel` per channel.
fn check_slab(preset: &str, wi: Vec3, wo: Vec3, spp: u32, rel: f64) {
    let scene = slab(preset, wi, wo * 500.0);
    let film = run(&scene, 32, 32, spp, SEED);
    let want = slab_closed_form_with(preset, wi, wo, lobe_factor(&scene, wi, wo));
    let got = mean_xyz(&film);
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() <= rel * want[c],
            "{preset}, ωi {wi}, ωo {wo}: channel {c}: {got:?} vs {want:?}"
        );
    }
}

/// At normal incidence, seen head-on, the slab renders to the closed form within 2% per XYZ channel,
/// for the light and the dark presets. Measured (1,024 pixels × 48 paths, seed 7): dark within 0.3%;
/// 2% is the Monte Carlo noise of this mean plus the f32 tables' 5-nm interpolation of R_tot, with
/// headroom over the worst deviation measured in the oblique case below (0.8%).
#[test]
fn flat_slab_renders_to_the_total_diffuse_reflectance_plus_specular() {
    for preset in ["light", "dark"] {
        check_slab(preset, Vec3::Z, Vec3::Z, 48, 0.02);
    }
}

/// Oblique incidence (45°) and oblique view (30°), the light and camera in perpendicular planes so the
/// sign convention of the light's direction cannot matter: the slab still renders to
/// E cos θ_i [f_s + T a(θ_i) T a(θ_o) R_tot M / (π c)] (M the azimuthal lobe at φ = 90°) within 2% per channel, two-sided, so a loss or a gain
/// of subsurface energy away from normal incidence fails. Measured: light within 0.5%, dark within
/// 0.8% (X); tolerance as above.
#[test]
fn flat_slab_at_oblique_incidence_and_view_matches_the_closed_form() {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let wi = Vec3::new(s, 0.0, s);
    let wo = Vec3::new(0.0, 0.5, 0.75f32.sqrt());
    for preset in ["light", "dark"] {
        check_slab(preset, wi, wo, 48, 0.02);
    }
}

/// Grazing incidence and view, where T(θ) falls and the surface lobe rises fastest (the white
/// furnace integrates these angles too): 75° in / 80° out and 85° in / 70° out, in perpendicular
/// planes, against the same closed form within the same 2% per channel. Measured (light, 1,024
/// pixels × 48 paths, seed 7): within 0.15% in both.
#[test]
fn flat_slab_at_grazing_incidence_and_view_matches_the_closed_form() {
    let dir = |theta_deg: f32, along_x: bool| {
        let (s, c) = theta_deg.to_radians().sin_cos();
        if along_x {
            Vec3::new(s, 0.0, c)
        } else {
            Vec3::new(0.0, s, c)
        }
    };
    for (theta_i, theta_o) in [(75.0, 80.0), (85.0, 70.0)] {
        check_slab("light", dir(theta_i, true), dir(theta_o, false), 48, 0.02);
    }
}

/// Splitting at a skin hit (two probes, each with two light samples whose light choice is
/// stratified) is unbiased: the slab under two distant lights of irradiance 1 each, 45° from the
/// normal in perpendicular planes and seen at 30°, renders to the sum of the two lights' closed forms
/// within 2% per channel (the tolerance of the one-light checks above, whose measured deviations
/// are ≤ 0.8%; the split only lowers the noise of the same mean).
#[test]
fn split_probes_and_stratified_light_choice_keep_the_slab_closed_form() {
    use render::integrator::{ExitLights, PathSettings};
    use render::renderer::{RenderOptions, render};
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let (wi_a, wi_b) = (Vec3::new(s, 0.0, s), Vec3::new(0.0, -s, s));
    let wo = Vec3::new(0.0, 0.5, 0.75f32.sqrt());
    for preset in ["light", "dark"] {
        let scene = SceneText::camera((wo * 500.0).to_array(), 2.0)
            .skin("skin", &format!("preset = \"{preset}\""))
            .mesh("quad", "skin", 1000.0)
            .distant(wi_a.to_array(), 1.0)
            .distant(wi_b.to_array(), 1.0)
            .with("[fidelity]\nfidelity = \"full\"")
            .load();
        let options = RenderOptions {
            width: 32,
            height: 32,
            spp: 24,
            seed: SEED,
            path: PathSettings {
                subsurface_probes: 2,
                exit_lights: ExitLights::Choose {
                    samples: 2,
                    stratified: true,
                },
                ..PathSettings::default()
            },
            ..Default::default()
        };
        let film = render(&scene, &options.validate().unwrap()).unwrap().0;
        let (a, b) = (
            slab_closed_form_with(preset, wi_a, wo, lobe_factor(&scene, wi_a, wo)),
            slab_closed_form_with(preset, wi_b, wo, lobe_factor(&scene, wi_b, wo)),
        );
        let got = mean_xyz(&film);
        for c in 0..3 {
            let want = a[c] + b[c];
            assert!(
                (got[c] - want).abs() <= 0.02 * want,
                "{preset}: channel {c}: {got:?} vs {want}"
            );
        }
    }
}

/// Splitting the lights at each exit point (`ExitLights::Split`) estimates the same mean as
/// choosing one light per sample, including where a weak light is sampled only with probability
/// budget · p and the continuation's MIS weight must use that rate. A light-skin slab under a
/// uniform sky of luminance 1 (found by light sampling and by the cosine continuation alike), a
/// sphere light and a distant light of irradiance 6, seen at 30°: the image mean of each budget
/// (1.5: every light below 2/3 of the selection weight sampled by a coin; 8, the default; 10⁶:
/// every light) against two chosen samples per exit, per XYZ channel within 4 standard errors of
/// the difference (`pixel_standard_error` of each image, conservative) plus 0.2%. Measured (24×24
/// pixels × 32 paths, seed 7): within 0.12% (1.1 standard errors). Keeping the selection
/// probability p in the continuation's MIS weight instead of the rate r counts the sky's light
/// found by both strategies r²/(1 + r²) + 1/(1 + p²) times: 4.9–5.5% above at budget 1.5 and
/// 12.8–14.3% above at the others, and fails.
#[test]
fn split_exit_lights_estimate_the_chosen_lights_mean() {
    use render::integrator::{ExitLights, PathSettings};
    use render::renderer::{RenderOptions, render};
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let wo = Vec3::new(0.0, 0.5, 0.75f32.sqrt());
    let scene = SceneText::camera((wo * 500.0).to_array(), 2.0)
        .skin("skin", "preset = \"light\"")
        .mesh("quad", "skin", 1000.0)
        .environment("constant", 1.0)
        .distant([s, 0.0, s], 6.0)
        .sphere_light([-300.0, 0.0, 300.0], 40.0, 30.0)
        .load();
    let image = |exit_lights| {
        let options = RenderOptions {
            width: 24,
            height: 24,
            spp: 32,
            seed: SEED,
            path: PathSettings {
                exit_lights,
                ..PathSettings::default()
            },
            ..Default::default()
        };
        let film = render(&scene, &options.validate().unwrap()).unwrap().0;
        let mean = mean_xyz(&film);
        (mean, pixel_standard_error(&film, mean))
    };
    let (want, want_se) = image(ExitLights::Choose {
        samples: 2,
        stratified: false,
    });
    for budget in [1.5, 8.0, 1e6] {
        let (got, se) = image(ExitLights::Split { budget });
        for c in 0..3 {
            let tol = 4.0 * (se[c].powi(2) + want_se[c].powi(2)).sqrt() + 2e-3 * want[c];
            assert!(
                (got[c] - want[c]).abs() <= tol,
                "budget {budget}: channel {c}: {:.5} vs {:.5} (tolerance {tol:.5})",
                got[c],
                want[c]
            );
        }
    }
}

/// Exit-light settings outside their ranges are typed errors naming the key: a split budget below
/// 1, above 10⁶, infinite or NaN, and zero or more than 64 chosen samples.
#[test]
fn bad_exit_light_settings_are_errors_naming_the_key() {
    use render::integrator::{ExitLights, PathSettings};
    use render::renderer::RenderOptions;
    let check = |exit_lights, key: &str| {
        let options = RenderOptions {
            path: PathSettings {
                exit_lights,
                ..PathSettings::default()
            },
            ..Default::default()
        };
        assert_eq!(options.validate().unwrap_err().name, key, "{exit_lights:?}");
    };
    for budget in [0.5, 2e6, f32::INFINITY, f32::NAN] {
        check(ExitLights::Split { budget }, "path.exit_lights.budget");
    }
    for samples in [0, 65] {
        check(
            ExitLights::Choose {
                samples,
                stratified: false,
            },
            "path.exit_lights.samples",
        );
    }
}

/// A bloodless, melanin-free light-skin sphere of `radius_mm` inside a uniform white environment
/// of luminance 1, seen from 8 radii with a 10° field of view (the image lies inside the sphere's
/// disc: exit angles from 0° at the centre to 79° at the corners), at full fidelity, with the
/// planar profile (`Curvature::Planar`: the separable form's closed form is what is checked).
fn furnace(radius_mm: f32) -> render::scene::Scene {
    let text = SceneText::camera([0.0, 0.0, radius_mm * 8.0], 10.0)
        .environment("constant", 1.0)
        .skin(
            "skin",
            "preset = \"light\"\nhemoglobin = 0.0\nmelanin = 0.0",
        )
        .mesh("sphere", "skin", radius_mm)
        .with("[fidelity]\nfidelity = \"full\"");
    let knobs = render::material::SkinKnobs {
        curvature: render::bssrdf::Curvature::Planar,
        ..Default::default()
    };
    render::scene::Scene::from_toml(text.text(), "furnace.toml", None, &knobs).unwrap()
}

/// The image mean of the surface lobe's albedo ρ_dr(θ_o) over the film, and the exit cosines it
/// was taken at: 4×4 points per pixel, each a camera ray against the scene's own mesh, θ_o from
/// its shading normal.
fn image_mean_albedo(scene: &render::scene::Scene, w: usize, h: usize) -> (f64, Vec<f32>) {
    let Material::Skin(skin) = &scene.materials[0] else {
        unreachable!("the furnace holds one skin")
    };
    let k = 4;
    let mut rho = 0.0;
    let mut mus = Vec::with_capacity(w * h * k * k);
    for (py, px, j, i) in film_points(w, h, k) {
        let ndc = Vec2::new(
            (px as f32 + (i as f32 + 0.5) / k as f32) / w as f32,
            (py as f32 + (j as f32 + 0.5) / k as f32) / h as f32,
        );
        let (o, d) = scene
            .camera
            .generate_ray(ndc, w as f32 / h as f32, Vec2::ZERO);
        let Some(Hit::Surface(si)) = scene.intersect(o, d, 0.0, f32::INFINITY) else {
            panic!("pixel {px},{py} misses the sphere")
        };
        let mu = (-d).dot(si.ns).clamp(0.0, 1.0);
        rho += f64::from(skin.surface.directional_albedo(mu));
        mus.push(mu);
    }
    (rho / mus.len() as f64, mus)
}

/// Every (row, column, sub-row, sub-column) of a `w`×`h` film with `k`×`k` points per pixel.
fn film_points(w: usize, h: usize, k: usize) -> impl Iterator<Item = (usize, usize, usize, usize)> {
    (0..h).flat_map(move |py| {
        (0..w).flat_map(move |px| (0..k).flat_map(move |j| (0..k).map(move |i| (py, px, j, i))))
    })
}

/// Standard error of the film's mean XYZ from the spread of its pixels, sd / √pixels. It
/// overstates the noise (the pixels also differ by their exit angle), so a bound built on it is
/// conservative.
fn pixel_standard_error(film: &render::film::Film, mean: [f64; 3]) -> [f64; 3] {
    let (w, h) = film.size();
    let n = (w * h) as f64;
    std::array::from_fn(|c| {
        let ss: f64 = (0..h)
            .flat_map(|py| (0..w).map(move |px| (px, py)))
            .map(|(px, py)| (f64::from(film.xyz(px, py)[c]) - mean[c]).powi(2))
            .sum();
        (ss / (n - 1.0) / n).sqrt()
    })
}

/// A closed sphere of skin in a white furnace renders to what the separable BSSRDF gives there,
/// two-sided, and never outshines the environment.
///
/// Each pixel sees ρ_dr(θ_o) of the environment off the surface lobe plus T(θ_o) a(θ_o) R_tot
/// through the skin (a the incidence gain, docs/physics.md §8.1): light leaving the sphere
/// anywhere sees the whole uniform environment (the sphere is convex) and S_ω integrates to 1. So
/// the image mean is ρ̄ E + mean(T a) R_tot (ρ̄ and the mean of T a over the film's own rays,
/// `image_mean_albedo`; E the environment):
/// - radius 100 mm, far larger than the profiles' 99% radius (5 mm), where the probes find the
///   sphere as they find a plane: R_tot of adding-doubling under the oily boundary (§10.1);
/// - radius 2 mm, smaller than the profiles: the probes find the sphere's points at chord
///   distance d ≤ 2R, and over a sphere dA = 2πd dd (Archimedes' hat-box theorem), so they return
///   R_tot F(2R), F the profile's energy fraction within a radius; a normal probe misses where the
///   planar radius exceeds R (the sphere's shadow on its tangent plane), and the local fallback
///   (`render::bssrdf`, "Where probes find no surface") returns the planar energy only where no
///   skin lies at that distance, r > 2R: R_tot (1 − F(2R)). Together R_tot, as for the large
///   sphere. (A fallback on every miss gave R_tot (1 + F(2R) − F(R)), the band R < r < 2R counted
///   twice: 5–6% above R_tot in X and Y here, far outside the tolerance.)
///
/// Tolerance per channel: 4 standard errors of the image mean (`pixel_standard_error`,
/// conservative; 0.15–0.3% at radius 100, 0.45–0.6% at radius 2) plus 0.2% for the model side:
/// the table holds the model's totals to 1e-4 (full fidelity, 10-nm rows), the f32 tables and
/// the 16-point pixel quadrature of ρ̄ (ρ̄ ≈ 0.009) add less. Measured (24×24 pixels × 32 paths,
/// seeds 7 and 8): radius 100 within 0.3%, radius 2 within 0.55%.
///
/// (An earlier reading of 1.1–1.9% below R_tot, apparently independent of the radius, was one
/// seed's noise: the scene is scale-free, so the same seed traces the same paths at every radius;
/// seeds 8 and 9 gave −0.1% to +1.1%; docs/tests.md.)
#[test]
fn skin_sphere_in_a_white_furnace_renders_the_separable_closed_form() {
    let light = SkinParams::preset(Preset::Light);
    let bloodless = SkinParams::new(0.0, light.eumelanin_blend(), 0.0, light.oiliness()).unwrap();
    let y = xyz_of(|_| 1.0)[1];
    let env = xyz_of(|_| 1.0 / y);
    for radius in [100.0f32, 2.0] {
        let s = furnace(radius);
        let (w, h) = (24, 24);
        let (rho, mus) = image_mean_albedo(&s, w, h);
        let Material::Skin(skin) = &s.materials[0] else {
            unreachable!("the furnace holds one skin")
        };
        let dir = &skin.subsurface.as_ref().unwrap().directional;
        let t = |nm: f64| {
            mus.iter()
                .map(|&mu| f64::from(dir.factor(mu, nm as f32)))
                .sum::<f64>()
                / mus.len() as f64
        };
        let found = |nm: f64| oily_total(&bloodless, nm);
        let body = xyz_of(|nm| t(nm) * found(nm) / y);
        let film = run(&s, w, h, 32, SEED);
        let got = mean_xyz(&film);
        let se = pixel_standard_error(&film, got);
        for c in 0..3 {
            let want = rho * env[c] + body[c];
            assert!(
                (got[c] - want).abs() <= 4.0 * se[c] + 2e-3 * want,
                "radius {radius}: channel {c}: {got:?} vs {want} (± {})",
                se[c]
            );
            assert!(
                got[c] <= env[c],
                "radius {radius}: channel {c}: {got:?} above the environment {env:?}"
            );
        }
        assert_finite_non_negative(&film, &format!("radius {radius}"));
    }
}

/// Skin parameters at the edges of their ranges render finite, non-negative images.
#[test]
fn edge_parameters_render_finite_non_negative_images() {
    for (melanin, hemoglobin) in [(0.5, 0.05), (0.1, 0.1), (0.0, 0.05), (0.0, 0.0), (0.5, 0.1)] {
        let s = SceneText::camera([0.0, 0.0, 300.0], 30.0)
            .environment("d65", 0.3)
            .skin(
                "skin",
                &format!("melanin = {melanin}\nhemoglobin = {hemoglobin}"),
            )
            .mesh("sphere", "skin", 50.0)
            .sphere_light([150.0; 3], 20.0, 30.0)
            .load();
        let film = run(&s, 16, 16, 4, SEED);
        let what = format!("C_m {melanin} C_h {hemoglobin}");
        assert_finite_non_negative(&film, &what);
        assert!(mean_xyz(&film)[1] > 0.0, "{what}: black image");
    }
}

/// The BSSRDF against the volumetric walk (docs/physics.md §15) at one wavelength under a sky of
/// spectral radiance 1, both with the smooth surface and g = 0 (the walk's exact boundary and the
/// tables' adding-doubling totals are then the same physics, §15): the region's mean radiance of
/// each integrator and the standard error of their ratio (both renders' variance passes).
mod against_the_walk {
    use render::film::Film;
    use render::integrator::{BodyIntegrator, IntegratorKind};
    use render::renderer::{RenderOptions, render_with};
    use render::scene::{Hit, Scene};

    /// The skin of the curved-skin measurements (C_m 0.05, β_m 0.7, C_h 0.02), smooth, g = 0.
    pub const SKIN: &str =
        "melanin = 0.05\neumelanin = 0.7\nhemoglobin = 0.02\nsurface = \"smooth\"\nphase_g = 0";

    fn render(scene: &Scene, kind: IntegratorKind, side: usize, spp: u32, nm: f32) -> Film {
        let body = BodyIntegrator::build(scene, kind);
        let opts = RenderOptions {
            width: side,
            height: side,
            spp,
            seed: super::SEED,
            wavelength_nm: Some(nm),
            ..Default::default()
        };
        render_with(scene, &body, &opts.validate().unwrap(), None)
            .unwrap()
            .0
    }

    /// Pixels whose centre ray hits the scene at a point `keep` accepts.
    fn region(scene: &Scene, side: usize, keep: impl Fn(glam::Vec3) -> bool) -> Vec<usize> {
        (0..side * side)
            .filter(|&i| {
                let (o, d) = render::testing::pixel_ray(scene, side, i % side, i / side);
                matches!(scene.intersect(o, d, 0.0, f32::INFINITY),
                    Some(Hit::Surface(si)) if keep(si.p))
            })
            .collect()
    }

    /// (BSSRDF / walk − 1, its standard error) over the pixels `keep` selects.
    pub fn gap(
        scene: &Scene,
        side: usize,
        spp: (u32, u32),
        nm: f32,
        keep: impl Fn(glam::Vec3) -> bool,
    ) -> (f64, f64) {
        gaps(&[scene], side, spp, nm, keep)[0]
    }

    /// [`gap`] of each scene's BSSRDF against one walk (of the first scene: the scenes differ
    /// only in the BSSRDF's knobs, which the walk does not read).
    pub fn gaps(
        scenes: &[&Scene],
        side: usize,
        (spp_bssrdf, spp_walk): (u32, u32),
        nm: f32,
        keep: impl Fn(glam::Vec3) -> bool,
    ) -> Vec<(f64, f64)> {
        let px = region(scenes[0], side, keep);
        assert!(px.len() > side * side / 4, "{} pixels", px.len());
        let mean = |f: &Film| {
            let (s, v) = px.iter().fold((0.0, 0.0), |(s, v), &i| {
                let (x, y) = (i % side, i / side);
                (s + f64::from(f.xyz(x, y)[1]), v + f.variance(x, y))
            });
            (s, v.sqrt() / s)
        };
        let (w, sw) = mean(&render(
            scenes[0],
            IntegratorKind::Volumetric,
            side,
            spp_walk,
            nm,
        ));
        scenes
            .iter()
            .map(|scene| {
                let (b, sb) = mean(&render(scene, IntegratorKind::Bssrdf, side, spp_bssrdf, nm));
                (b / w - 1.0, (b / w) * sb.hypot(sw))
            })
            .collect()
    }
}

/// A 200 × 200 × 40 mm box of the skin `skin` (scene keys) tilted by `tilt_deg` about x under a
/// uniform sky of spectral radiance 1, seen from 400 mm on +Z with a 1° field of view.
fn box_under_a_sky(skin: &str, tilt_deg: f32) -> render::scene::Scene {
    use render::volumetric::shapes::box_obj;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("box.obj"), box_obj([200.0, 200.0, 40.0])).unwrap();
    let text = SceneText::camera([0.0, 0.0, 400.0], 1.0)
        .with("[environment]\nspectral_radiance = 1")
        .skin("skin", skin)
        .with(&format!(
            "[[meshes]]\nfile = \"box.obj\"\nmaterial = \"skin\"\nrotate_deg = [{tilt_deg}, 0, 0]"
        ));
    render::scene::Scene::from_toml(
        text.text(),
        "box.toml",
        Some(dir.path()),
        &render::material::SkinKnobs::default(),
    )
    .unwrap()
}

/// A flat slab seen at 64° from its normal (tilted under a camera on +Z) under a uniform sky:
/// by reciprocity each pixel is the slab's albedo for light from the camera's direction,
/// F(θ) + (1 − F(θ)) R_d(θ), and the BSSRDF with the incidence gain (docs/physics.md §8.1) renders
/// what the volumetric walk does within 0.5% + 3σ (σ the ratio's standard error, 0.3–0.4%; 0.5%
/// for the gain's 24-point quadrature, the f32 tables and the 10-nm rows). Measured at 550 nm:
/// without the gain (`Incidence::Normal`) the BSSRDF was 4.8% ± 0.6% dark at 64°, 3.9% at 50°.
#[test]
fn tilted_slab_under_a_sky_matches_the_volumetric_walk() {
    let scene = box_under_a_sky(against_the_walk::SKIN, 64.0);
    let (g, se) = against_the_walk::gap(&scene, 8, (256, 3072), 550.0, |_| true);
    assert!(
        g.abs() <= 0.005 + 3.0 * se,
        "BSSRDF / walk − 1 = {g:+.4} ± {se:.4}"
    );
}

/// A flat slab seen at 60° from its normal under a uniform sky, whose viewed part (at least 5 mm
/// from the map's border and from the slab's edge) holds high blood (C_h 0.12, as the lips'
/// texels) while most of the map, and so the material's typical skin, holds 0.005. By reciprocity
/// each pixel is the albedo of its own skin for light from the camera's direction, whose oblique
/// gain a(θ) is that skin's: with a gain per texel (docs/physics.md §19.3) the BSSRDF, and the
/// diffuse body that stands in for it (the level of detail's, `no_subsurface`), render what the
/// volumetric walk does within 0.5% + 3σ, as on the uniform tilted slab (σ the ratio's standard
/// error, 0.17–0.22%). Measured at 550 nm: BSSRDF +0.18% ± 0.17% (a map of 0.12 everywhere:
/// +0.16% ± 0.23%), diffuse body −0.03% ± 0.21%; with the typical skin's gain at every texel, as
/// before the gain followed the texels, −1.92% ± 0.17% and −2.12% ± 0.22% (the test fails there).
#[test]
fn tilted_slab_with_maps_takes_each_texels_oblique_gain() {
    use render::testing::hetero::{exr_bytes, slab_obj};
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("slab.obj"), slab_obj()).unwrap();
    let side = render::testing::hetero::SLAB_SIDE_MM;
    let blood: Vec<f32> = (0..256)
        .map(|i| {
            let x = -0.5 * side + (i as f32 + 0.5) * side / 256.0;
            if x < -2.0 { 0.12 } else { 0.005 }
        })
        .collect();
    std::fs::write(
        dir.path().join("maps.exr"),
        exr_bytes(256, 1, vec![("hemoglobin", blood)]),
    )
    .unwrap();
    // Turned about x and moved so that the top face's point (−11, 0) mm lies at the origin.
    let tilt = 60.0f32;
    let (sin, cos) = tilt.to_radians().sin_cos();
    let top = 0.5 * render::testing::hetero::SLAB_DEPTH_MM;
    let text = SceneText::camera([0.0, 0.0, 400.0], 1.0)
        .with("[environment]\nspectral_radiance = 1")
        .skin(
            "skin",
            &format!("{}\nmaps = \"maps.exr\"", against_the_walk::SKIN),
        )
        .with(&format!(
            "[[meshes]]\nfile = \"slab.obj\"\nmaterial = \"skin\"\nrotate_deg = [{tilt}, 0, 0]\n\
             translate_mm = [11, {}, {}]",
            top * sin,
            -top * cos
        ));
    let load = |no_subsurface: bool| {
        render::scene::Scene::from_toml(
            text.text(),
            "slab.toml",
            Some(dir.path()),
            &render::material::SkinKnobs {
                no_subsurface,
                ..Default::default()
            },
        )
        .unwrap()
    };
    // The BSSRDF, and the diffuse body that stands in for it (the level of detail's).
    let (scene, diffuse) = (load(false), load(true));
    let gaps = against_the_walk::gaps(&[&scene, &diffuse], 8, (512, 6144), 550.0, |_| true);
    for ((g, se), body) in gaps.into_iter().zip(["BSSRDF", "diffuse body"]) {
        assert!(
            g.abs() <= 0.005 + 3.0 * se,
            "{body} / walk − 1 = {g:+.4} ± {se:.4}"
        );
    }
}

/// A flat slab with the default oily surface, seen head-on under a uniform sky: the walk leaves the
/// skin through the lobe's own boundary (reflectance ρ_dr, docs/physics.md §15.3), and the BSSRDF's
/// totals, gain and normalisation come from adding-doubling under that same boundary (§10.1), so the
/// two render the same within 0.5% + 3σ (σ the ratio's standard error, 0.2–0.4%). Measured: light
/// skin (C_m 0.02) at 650 nm +0.01% ± 0.24%, C_m 0.3 at 550 nm +0.55% ± 0.38%; with the Fresnel
/// boundary in the totals, the light skin was −3.66% ± 0.23% (the test fails there).
#[test]
fn oily_slab_under_a_sky_matches_the_volumetric_walk() {
    for (skin, nm) in [
        (
            "melanin = 0.02\neumelanin = 0.5\nhemoglobin = 0.01\nphase_g = 0",
            650.0,
        ),
        (
            "melanin = 0.3\neumelanin = 0.5\nhemoglobin = 0.01\nphase_g = 0",
            550.0,
        ),
    ] {
        let scene = box_under_a_sky(skin, 0.0);
        let (g, se) = against_the_walk::gap(&scene, 8, (256, 2048), nm, |_| true);
        assert!(
            g.abs() <= 0.005 + 3.0 * se,
            "{skin} at {nm} nm: BSSRDF / walk − 1 = {g:+.4} ± {se:.4}"
        );
    }
}

/// A 10-mm sphere of skin under a uniform sky, region within 0.9 radii of the view axis (exit
/// angles to 64°): the BSSRDF renders what the volumetric walk does within 1% + 3σ at 450 and
/// 550 nm (σ the ratio's standard error, 0.4–0.6%). The 1% bounds what the model leaves at 10 mm,
/// measured (512 / 1,024 spp) −0.0% ± 0.3% (450 nm) and −0.2% ± 0.3% (550 nm) with the curvature
/// term, −0.2% and −0.8% with the planar profile (docs/physics.md §8.2). Before the incidence
/// gain the BSSRDF was 3.7–3.9% dark here.
#[test]
fn sphere_under_a_sky_matches_the_volumetric_walk() {
    let scene = SceneText::camera([0.0, 0.0, 120.0], 11.0)
        .with("[environment]\nspectral_radiance = 1")
        .skin("skin", against_the_walk::SKIN)
        .with("[[meshes]]\nshape = \"sphere\"\nmaterial = \"skin\"\nunits_mm = 10")
        .load();
    for nm in [450.0, 550.0] {
        let (g, se) =
            against_the_walk::gap(&scene, 16, (128, 1024), nm, |p| p.truncate().length() < 9.0);
        assert!(
            g.abs() <= 0.01 + 3.0 * se,
            "{nm} nm: BSSRDF / walk − 1 = {g:+.4} ± {se:.4}"
        );
    }
}

/// A 5-mm sphere of light skin under a uniform sky (region within 0.9 radii), where the planar
/// profile fails most: the BSSRDF with the curvature term (docs/physics.md §8.2) renders what the
/// volumetric walk does within 2% + 3σ at 550 and 650 nm (σ the ratio's standard error, 0.3–0.5%
/// at these counts; the 2% is the target, the model's error measured at 512 / 512 spp: +1.6% ±
/// 0.2% and −1.3% ± 0.2%), while the planar profile (`Curvature::Planar`) stays 5% and 9% dark,
/// beyond 2% + 3σ: the case tells the two apart.
#[test]
fn small_light_skin_sphere_matches_the_volumetric_walk_with_the_curvature_term() {
    use render::bssrdf::Curvature;
    use render::material::SkinKnobs;
    let text = SceneText::camera([0.0, 0.0, 60.0], 11.0)
        .with("[environment]\nspectral_radiance = 1")
        .skin(
            "skin",
            "preset = \"light\"\nsurface = \"smooth\"\nphase_g = 0",
        )
        .with("[[meshes]]\nshape = \"sphere\"\nmaterial = \"skin\"\nunits_mm = 5");
    let load = |curvature| {
        let knobs = SkinKnobs {
            curvature,
            ..SkinKnobs::default()
        };
        render::scene::Scene::from_toml(text.text(), "sphere.toml", None, &knobs).unwrap()
    };
    let (curved, planar) = (load(Curvature::FirstOrder), load(Curvature::Planar));
    let region = |p: Vec3| p.truncate().length() < 4.5;
    for nm in [550.0, 650.0] {
        let gaps = against_the_walk::gaps(&[&curved, &planar], 12, (64, 512), nm, region);
        let ((g, se), (gp, sep)) = (gaps[0], gaps[1]);
        assert!(
            g.abs() <= 0.02 + 3.0 * se,
            "{nm} nm: BSSRDF / walk − 1 = {g:+.4} ± {se:.4}"
        );
        assert!(
            gp < -(0.02 + 3.0 * sep),
            "{nm} nm, planar: BSSRDF / walk − 1 = {gp:+.4} ± {sep:.4}"
        );
    }
}

/// The curvature term integrates to its closed form on a sphere: under a uniform sky of radiance 1
/// each pixel of a convex body is its albedo for light from the camera, so a 5-mm sphere of light
/// skin at 650 nm renders (1 − T(μ)) + T(μ) a(μ) R_tot (1 + G), G = κ ∫ d²/2R · R(d) 2πd dd / R_tot
/// over the chords d < √2 R (docs/physics.md §8.2: h = d²/2R on a sphere, dA = 2πd dd by
/// Archimedes' hat-box theorem), the integral by a 20,000-point midpoint rule on the table, T and
/// a from 4×4 camera rays per pixel. G is 9.6% here; the BSSRDF must render it within 4 standard
/// errors of the region's mean (0.1%) plus 0.3% for the tessellated sphere (its points lie
/// inside the true sphere and the shading normals are interpolated, so h is d²/2R only to the
/// mesh's accuracy) and the f32 tables. This checks the probes, their MIS density and the
/// per-exit factor together, against quadrature rather than against another render.
#[test]
fn curvature_term_on_a_sphere_renders_its_closed_form() {
    let (radius, nm, side) = (5.0f32, 650.0f32, 16usize);
    let scene = SceneText::camera([0.0, 0.0, 12.0 * radius], 11.0)
        .with("[environment]\nspectral_radiance = 1")
        .skin(
            "skin",
            "preset = \"light\"\nsurface = \"smooth\"\nphase_g = 0",
        )
        .mesh("sphere", "skin", radius)
        .load();
    let Material::Skin(skin) = &scene.materials[0] else {
        unreachable!("the scene holds one skin")
    };
    let ss = skin.subsurface.as_ref().unwrap();
    let (table, dir) = (&ss.table, &ss.directional);
    let r_tot = f64::from(table.total(nm));
    let kappa = f64::from(ss.curvature.as_ref().unwrap().kappa_per_mm(nm));
    let r_max = f64::from(table.r_max_mm(nm)).min(2f64.sqrt() * f64::from(radius));
    let m2 = render::testing::radial_third_moment(|r| f64::from(table.eval(nm, r)), r_max) / r_tot;
    let gain = kappa * m2 / (2.0 * f64::from(radius));
    assert!(gain > 0.05, "G = {gain}: the case must test the term");
    let inside = |p: Vec3| p.truncate().length() < 0.9 * radius;
    let film = render::testing::render_bssrdf_at_nm(&scene, side, 128, SEED, nm);
    let (got, var, want, pixels) = render::testing::film_against_closed_form(
        &scene,
        &film,
        (side, 4),
        inside,
        render::testing::sky_sphere_closed_form(dir, nm, r_tot, gain),
    );
    assert!(pixels > side * side / 4, "{pixels} pixels");
    let se = var.sqrt() / want;
    let rel = got / want - 1.0;
    assert!(
        rel.abs() <= 4.0 * se + 3e-3,
        "rendered / closed form − 1 = {rel:+.4} ± {se:.4} (G = {gain:.4})"
    );
}

/// A light at 60° on the far side of the slab from a camera at 45° (the light travels toward the
/// camera, as the ear's back light does) and on the camera's side: the slab renders to
/// E cos θ_i [f_s + T a T a R_tot M / (π c)] with the material's own lobe M(μ_i, μ_o, φ)
/// (docs/physics.md §8.3; cos φ = +1 far, −1 near) within 2% per channel, two-sided (the tolerance
/// of the oblique case above), and M moves each case by more than that 2% (light skin: about
/// +5% far, −4% near), so a lobe applied at the wrong azimuth or not at all fails. The other slab
/// tests (perpendicular planes, two lights) carry M in their closed forms too.
#[test]
fn flat_slab_under_a_far_side_light_carries_the_azimuthal_lobe() {
    let (si, ci) = 60f32.to_radians().sin_cos();
    let (so, co) = 45f32.to_radians().sin_cos();
    let wo = Vec3::new(so, 0.0, co);
    for (wi, cos_phi) in [
        (Vec3::new(-si, 0.0, ci), 1.0),
        (Vec3::new(si, 0.0, ci), -1.0),
    ] {
        let knobs = render::material::SkinKnobs {
            azimuth: render::bssrdf::Azimuth::Harmonics,
            ..render::material::SkinKnobs::default()
        };
        let text = slab_text("light", wi, wo * 500.0);
        let scene =
            render::scene::Scene::from_toml(text.text(), "slab.toml", None, &knobs).unwrap();
        let Material::Skin(skin) = &scene.materials[0] else {
            panic!("skin");
        };
        let lobe = skin
            .subsurface
            .as_ref()
            .and_then(|s| s.azimuth.clone())
            .expect("the lobe is asked for");
        let m = |nm: f32| f64::from(lobe.modulation(wi.z, wo.z, cos_phi, nm));
        let want = slab_closed_form_with("light", wi, wo, m);
        let separable = slab_closed_form("light", wi, wo);
        let got = mean_xyz(&run(&scene, 32, 32, 48, SEED));
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= 0.02 * want[c],
                "cos φ {cos_phi}: channel {c}: {got:?} vs {want:?}"
            );
        }
        let moved = want[1] / separable[1] - 1.0;
        assert!(
            moved.abs() > 0.02 && moved.signum() == f64::from(cos_phi),
            "cos φ {cos_phi}: the lobe moves Y by {moved:+.4}"
        );
    }
}
