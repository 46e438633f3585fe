//! Scaffolding shared by the end-to-end render tests (tracer.rs, subsurface.rs).

// Each test binary compiles this module on its own and uses only part of it.
#![allow(dead_code)]

use render::film::Film;
use render::renderer::{RenderOptions, render};
use render::scene::{Scene, SceneOptions};
use skin_optics::color::{cie_xyz_bar, cie_y_integral};

/// A scene from TOML text, with default options.
pub fn scene(text: &str) -> Scene {
    Scene::from_toml(text, "test.toml", None, &SceneOptions::default()).unwrap()
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
    let (w, h) = film.size();
    let mut s = [0.0f64; 3];
    for y in 0..h {
        for x in 0..w {
            let v = film.xyz(x, y);
            for c in 0..3 {
                s[c] += f64::from(v[c]);
            }
        }
    }
    s.map(|v| v / (w * h) as f64)
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
