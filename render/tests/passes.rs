//! The render passes on scenes whose answers are known: the albedo of a diffuse plane, the
//! normals and depth of a sphere, the skin mask.

use render::testing as common;

use common::{SceneText, plane};
use glam::{Vec2, Vec3};
use render::passes::{NO_DEPTH, Passes};

/// A grey Lambertian plane of albedo 0.5 facing the camera: albedo (0.5, 0.5, 0.5) (the D65
/// weighting makes a flat reflectance neutral; 5 nm sums, so 1e-3), normal +Z, depth 500 mm at
/// the centre, mask 0.
#[test]
fn diffuse_plane_albedo_normal_depth() {
    let s = plane("grey").diffuse("grey", 0.5).load();
    let p = Passes::first_hit(&s, 9, 9);
    for i in 0..81 {
        for c in 0..3 {
            assert!((p.albedo[i][c] - 0.5).abs() < 1e-3, "{:?}", p.albedo[i]);
        }
        assert!((p.normal[i][2] - 1.0).abs() < 1e-5, "{:?}", p.normal[i]);
        assert_eq!(p.skin[i], 0.0);
    }
    // Centre pixel: straight down the axis.
    assert!((p.depth[40] - 500.0).abs() < 1e-2, "{}", p.depth[40]);
}

/// A skin sphere of radius 100 mm at the origin, camera at 500 mm: where the centre ray hits, the
/// normal equals (p − c)/r with p = o + t d, the depth is 400 mm, the mask is 1; off the sphere the
/// depth is NO_DEPTH and the mask 0.
#[test]
fn sphere_normals_and_mask() {
    let s = SceneText::camera([0.0, 0.0, 500.0], 40.0)
        .skin("skin", "preset = \"medium\"")
        .mesh("sphere", "skin", 100.0)
        .load();
    let (w, h) = (15, 15);
    let p = Passes::first_hit(&s, w, h);
    let c = (h / 2) * w + w / 2;
    // Tessellated sphere: the hit sits slightly inside the true surface (1 mm tolerance).
    assert!((p.depth[c] - 400.0).abs() < 1.0, "{}", p.depth[c]);
    assert!(p.normal[c][2] > 0.999, "{:?}", p.normal[c]);
    assert_eq!(p.skin[c], 1.0);
    assert!(
        p.albedo[c].iter().all(|&v| v > 0.0 && v < 1.0),
        "{:?}",
        p.albedo[c]
    );
    // Corner: misses the sphere (it spans ±11.4° of the 40° field).
    assert_eq!(p.depth[0], NO_DEPTH);
    assert_eq!(p.skin[0], 0.0);
    // Every hit's normal is (p − c)/r at p = o + t d: interpolated vertex normals of the
    // tessellated sphere deviate from the true normal by well under 0.02.
    let mut hits = 0;
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if p.skin[i] != 1.0 {
                continue;
            }
            let ndc = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let (o, d) = s.camera.generate_ray(ndc, 1.0, Vec2::splat(0.5));
            let want = (o + d * p.depth[i]).normalize();
            let got = Vec3::from_array(p.normal[i]);
            assert!(
                (got - want).length() < 0.02,
                "pixel ({x}, {y}): {got} vs {want}"
            );
            hits += 1;
        }
    }
    assert!(hits > 9, "{hits} pixels on the sphere");
}

/// An adaptive render of a grey plane under a small light, whose pixels stop at the target at
/// different counts: the EXR's `samples.count` layer holds
/// each pixel's sample count (the film's, i.e. the accumulator's), at least `min_spp` and at
/// most the cap, its mean is the mean spp the render reports, and some pixels stopped early.
#[test]
fn samples_pass_holds_each_pixels_sample_count() {
    use render::renderer::{RenderOptions, render};
    let s = SceneText::camera([0.0, 0.0, 500.0], 30.0)
        .environment("d65", 0.05)
        .diffuse("grey", 0.5)
        .mesh("quad", "grey", 1000.0)
        .sphere_light([150.0, 150.0, 200.0], 20.0, 40.0)
        .load();
    let (w, h, cap) = (16, 12, 96);
    let o = RenderOptions {
        width: w,
        height: h,
        spp: cap,
        noise: Some(0.03),
        threads: Some(1),
        ..Default::default()
    };
    let settings = o.validate().unwrap();
    let (film, stats) = render(&s, &settings).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("render.exr");
    Passes::first_hit(&s, w, h).write_exr(&film, &path).unwrap();
    let img = exr::prelude::read_first_flat_layer_from_file(&path).unwrap();
    let layer: Vec<f32> = img
        .layer_data
        .channel_data
        .list
        .iter()
        .find(|c| c.name.eq("samples.count"))
        .expect("samples.count channel")
        .sample_data
        .values_as_f32()
        .collect();
    assert_eq!(layer.len(), w * h);
    for y in 0..h {
        for x in 0..w {
            let n = layer[y * w + x];
            assert_eq!(n, film.samples(x, y) as f32, "pixel ({x}, {y})");
            assert!(n >= settings.min_spp as f32 && n <= cap as f32, "{n}");
        }
    }
    let mean = layer.iter().map(|&n| f64::from(n)).sum::<f64>() / (w * h) as f64;
    assert!(
        (mean - stats.mean_spp).abs() < 1e-9,
        "{mean} vs {}",
        stats.mean_spp
    );
    assert_eq!(layer.iter().copied().fold(0.0, f32::max), stats.spp as f32);
    // Pixels stopped at different counts.
    let least = layer.iter().copied().fold(f32::INFINITY, f32::min);
    assert!(least < stats.spp as f32, "{least}..{}", stats.spp);
}
