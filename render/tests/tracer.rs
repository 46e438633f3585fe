//! End-to-end checks of the path tracer against closed forms: white furnace, Lambertian
//! plane under a distant light, D65 round trip to sRGB white, bad scenes, the default scene,
//! and thread-count independence.

mod common;

use common::{assert_close, mean_xyz, run, scene, xyz_of};
use render::renderer::{RenderOptions, TILE, render};
use render::scene::{Scene, SceneOptions};

/// Seed of every render in this file.
const SEED: u64 = 42;

/// A diffuse albedo-1 sphere inside a uniform environment of radiance 1 looks exactly like the
/// environment: every path's energy is conserved and the MIS weights sum to one.
#[test]
fn white_furnace_sphere_matches_environment() {
    let s = scene(
        r#"
        [camera]
        position_mm = [0, 0, 300]
        look_at_mm = [0, 0, 0]
        fov_deg = 20
        [environment]
        spectrum = "constant"
        intensity = 1
        [materials.white]
        type = "diffuse"
        albedo = 1
        [[meshes]]
        shape = "sphere"
        material = "white"
        scale = 100
        "#,
    );
    let film = run(&s, 32, 32, 16, SEED);
    // Equal-energy radiance with Y = 1.
    let y = xyz_of(|_| 1.0)[1];
    let want = xyz_of(|_| 1.0 / y);
    assert_close(mean_xyz(&film), want, 0.01, "furnace");
}

/// A Lambertian plane of albedo a under a distant light of irradiance E at θ = 60° has radiance
/// a E cosθ / π in every direction.
#[test]
fn lambertian_plane_under_distant_light() {
    let s = scene(
        r#"
        [camera]
        position_mm = [0, 0, 500]
        look_at_mm = [0, 0, 0]
        fov_deg = 10
        [materials.grey]
        type = "diffuse"
        albedo = 0.5
        [[meshes]]
        shape = "quad"
        material = "grey"
        scale = 1000
        [[lights]]
        type = "distant"
        direction = [0.8660254, 0, 0.5]
        spectrum = "d65"
        intensity = 2
        "#,
    );
    let film = run(&s, 32, 32, 8, SEED);
    let d65_y = xyz_of(skin_optics::color::d65)[1];
    let radiance = 0.5 * 2.0 * 0.5 / std::f64::consts::PI;
    let want = xyz_of(|nm| skin_optics::color::d65(nm) / d65_y * radiance);
    assert_close(mean_xyz(&film), want, 0.01, "lambert");
}

/// A white Lambertian plane under a D65 environment of luminance 1 renders to linear sRGB
/// (1, 1, 1), and the PNG maps it through exposure and the tone curve.
#[test]
fn d65_white_plane_is_srgb_white() {
    let s = scene(
        r#"
        [camera]
        position_mm = [0, 0, 500]
        look_at_mm = [0, 0, 0]
        fov_deg = 10
        [environment]
        spectrum = "d65"
        intensity = 1
        [materials.white]
        type = "diffuse"
        albedo = 1
        [[meshes]]
        shape = "quad"
        material = "white"
        scale = 1000
        "#,
    );
    let film = run(&s, 32, 32, 8, SEED);
    let (w, h) = film.size();
    let mut rgb = [0.0f64; 3];
    for y in 0..h {
        for x in 0..w {
            let v = film.linear_srgb(x, y);
            for c in 0..3 {
                rgb[c] += f64::from(v[c]) / (w * h) as f64;
            }
        }
    }
    assert_close(rgb, [1.0; 3], 0.01, "linear sRGB");
    // One stop down: 0.5 through the tone curve, equal in all channels.
    let png = film.to_srgb8(-1.0);
    let expect =
        (skin_optics::color::srgb_encode(f64::from(render::film::filmic(0.5))) * 255.0).round();
    let mean = png.iter().map(|&v| f64::from(v)).sum::<f64>() / png.len() as f64;
    assert!((mean - expect).abs() <= 2.0, "png {mean} vs {expect}");
}

/// The same seed gives the same image on 1, 2 and 4 threads, with 5 × 3 = 15 tiles of 16 px, more
/// tiles than threads, so the tile schedule differs between runs: bit for bit, since every pixel
/// sample has its own seeded stream and the film adds passes in pixel order.
#[test]
fn image_does_not_depend_on_thread_count() {
    let s = scene(
        r#"
        [camera]
        position_mm = [0, 0, 300]
        look_at_mm = [0, 0, 0]
        fov_deg = 40
        [environment]
        spectrum = "d65"
        intensity = 0.2
        [materials.skin]
        type = "skin"
        preset = "medium"
        [[meshes]]
        shape = "sphere"
        material = "skin"
        scale = 60
        [[lights]]
        type = "sphere"
        center_mm = [200, 200, 200]
        radius_mm = 30
        intensity = 20
        "#,
    );
    let mut settings = RenderOptions {
        width: 72,
        height: 40,
        spp: 3,
        threads: Some(1),
        ..Default::default()
    };
    let one = render(&s, &settings.clone().validate().unwrap()).unwrap().0;
    assert!(72usize.div_ceil(TILE) * 40usize.div_ceil(TILE) > 4);
    for threads in [2, 4] {
        settings.threads = Some(threads);
        let many = render(&s, &settings.clone().validate().unwrap()).unwrap().0;
        assert!(one == many, "{threads} threads differ from one");
    }
}

/// The time-limited path (the CLI's default) stops after whole passes: with a 0.3 s budget and a
/// million passes requested it stops early, reports the passes it made, and its image is bit for bit
/// the fixed-count render of that many passes with the same seed, i.e. the same unbiased estimator
/// the closed-form tests above check, never a partly added pass.
#[test]
fn time_limit_stops_after_whole_passes() {
    let s = scene(
        r#"
        [camera]
        position_mm = [0, 0, 300]
        look_at_mm = [0, 0, 0]
        fov_deg = 20
        [environment]
        spectrum = "constant"
        intensity = 1
        [materials.white]
        type = "diffuse"
        albedo = 1
        [[meshes]]
        shape = "sphere"
        material = "white"
        scale = 100
        "#,
    );
    let limited = RenderOptions {
        width: 16,
        height: 16,
        spp: 1_000_000,
        time_limit: Some(std::time::Duration::from_millis(300)),
        seed: SEED,
        ..Default::default()
    };
    let (film, stats) = render(&s, &limited.clone().validate().unwrap()).unwrap();
    assert!(stats.spp >= 1 && stats.spp < 1_000_000, "{} spp", stats.spp);
    assert_eq!(film.spp(), stats.spp);
    let fixed = RenderOptions {
        spp: stats.spp,
        time_limit: None,
        ..limited
    };
    let (reference, _) = render(&s, &fixed.validate().unwrap()).unwrap();
    assert!(
        film == reference,
        "{} spp: limited image differs",
        stats.spp
    );
}

/// The default scene renders at 64×48, 2 spp: finite, not all alike.
#[test]
fn default_scene_renders_small() {
    let s = Scene::load("builtin:three-heads", &SceneOptions::default()).unwrap();
    let film = run(&s, 64, 48, 2, SEED);
    let mut ys = Vec::new();
    for y in 0..48 {
        for x in 0..64 {
            let v = film.xyz(x, y);
            assert!(v.iter().all(|c| c.is_finite()), "pixel ({x}, {y}) = {v:?}");
            ys.push(v[1]);
        }
    }
    let max = ys.iter().copied().fold(0.0, f32::max);
    let min = ys.iter().copied().fold(f32::INFINITY, f32::min);
    assert!(
        max > 0.05 && max > 4.0 * min,
        "flat image: Y in [{min}, {max}]"
    );
}

/// The built-in ear scene loads.
#[test]
fn ear_scene_loads() {
    let s = Scene::load("builtin:ear", &SceneOptions::default()).unwrap();
    assert!(s.geometry.triangle_count() > 17_000);
}
