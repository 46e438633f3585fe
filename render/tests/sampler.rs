//! The variance-reduction knobs change the noise, never the mean: with every knob at its old
//! setting (independent numbers, uniform wavelengths, the subsurface branch chosen as a whole,
//! normal probes ½) and at its new one (Owen-scrambled Sobol, visible-wavelength density, the exit
//! light gathered at every skin hit, normal probes 0.8), a skin slab under a sphere light and a
//! dim environment renders to the same mean within the noise, and the new settings are less
//! noisy at equal sample count.

use render::testing as common;

use common::scene;
use render::bssrdf::ProbeAxes;
use render::film::Film;
use render::integrator::PathSettings;
use render::noise::{luminance, relative_noise};
use render::renderer::{RenderOptions, render};
use render::sampler::SamplerKind;
use render::scene::Scene;
use render::spectrum::WavelengthSampling;

/// A skin slab (BSSRDF) and a white diffuse sphere on it, lit by a sphere light and a dim
/// environment: light sampling, the subsurface probes, the bounce and the wavelengths all add
/// noise, so every knob matters.
const SKIN_SLAB: &str = r#"
    [camera]
    position_mm = [0, -150, 400]
    look_at_mm = [0, 0, 0]
    fov_deg = 30
    [environment]
    spectrum = "d65"
    intensity = 0.05
    [materials.skin]
    type = "skin"
    preset = "medium"
    [materials.white]
    type = "diffuse"
    albedo = 0.9
    [[meshes]]
    shape = "quad"
    material = "skin"
    scale = 1000
    [[meshes]]
    shape = "sphere"
    material = "white"
    scale = 40
    translate_mm = [0, 0, 40]
    [[lights]]
    type = "sphere"
    center_mm = [150, 100, 200]
    radius_mm = 20
    intensity = 40
"#;

fn old_settings() -> PathSettings {
    PathSettings {
        sampler: SamplerKind::Independent,
        wavelengths: WavelengthSampling::Uniform,
        probe_axes: ProbeAxes::PBRT,
        split_subsurface: false,
        ..PathSettings::default()
    }
}

fn new_settings() -> PathSettings {
    PathSettings {
        sampler: SamplerKind::Sobol,
        wavelengths: WavelengthSampling::Visible,
        probe_axes: ProbeAxes::new(0.8).unwrap(),
        split_subsurface: true,
        ..PathSettings::default()
    }
}

fn run(s: &Scene, path: PathSettings, spp: u32, seed: u64) -> Film {
    let o = RenderOptions {
        width: 24,
        height: 24,
        spp,
        seed,
        threads: Some(2),
        path,
        ..Default::default()
    };
    render(s, &o.validate().unwrap()).unwrap().0
}

fn luminances(film: &Film) -> Vec<f64> {
    let (w, h) = film.size();
    (0..w * h)
        .map(|i| luminance(film.linear_srgb(i % w, i / w)))
        .collect()
}

/// Image mean luminance and its standard error from the film's per-pixel variances (for Sobol
/// points the sample variance overstates the error, so the test is conservative there).
fn mean_and_stderr(film: &Film) -> (f64, f64) {
    let (w, h) = film.size();
    let n = (w * h) as f64;
    let mean = luminances(film).iter().sum::<f64>() / n;
    let var: f64 = (0..w * h).map(|i| film.variance(i % w, i / w)).sum();
    (mean, var.sqrt() / n)
}

/// The new settings' mean luminance equals the old ones' within 4 combined standard errors (a
/// false failure has probability 6·10⁻⁵), so none of the knobs biases the image.
#[test]
fn new_sampling_has_the_old_mean() {
    let s = scene(SKIN_SLAB);
    let (mo, eo) = mean_and_stderr(&run(&s, old_settings(), 128, 1));
    let (mn, en) = mean_and_stderr(&run(&s, new_settings(), 128, 2));
    assert!(
        (mo - mn).abs() <= 4.0 * eo.hypot(en),
        "old {mo} ± {eo}, new {mn} ± {en}"
    );
    // A broken estimator that returned black would pass the comparison only if both were black.
    assert!(mo > 10.0 * eo, "old mean {mo} ± {eo}");
}

/// At 32 spp the two-seed noise of the new settings is below the old settings' (576 pixels: the
/// metric itself fluctuates by about 1/√(2·576) ≈ 3%, so a 15% margin cannot be luck).
#[test]
fn new_sampling_is_less_noisy() {
    let s = scene(SKIN_SLAB);
    let noise = |path| {
        let a = luminances(&run(&s, path, 32, 1));
        let b = luminances(&run(&s, path, 32, 2));
        relative_noise(&a, &b).unwrap().relative_noise
    };
    let (old, new) = (noise(old_settings()), noise(new_settings()));
    assert!(new < 0.85 * old, "noise old {old}, new {new}");
}

/// With the Sobol sampler, the same seed gives the same image on one and on two threads.
#[test]
fn sobol_render_is_thread_count_independent() {
    let s = scene(SKIN_SLAB);
    let o = |threads| RenderOptions {
        width: 16,
        height: 16,
        spp: 8,
        seed: 3,
        threads: Some(threads),
        path: new_settings(),
        ..Default::default()
    };
    let a = render(&s, &o(1).validate().unwrap()).unwrap().0;
    let b = render(&s, &o(2).validate().unwrap()).unwrap().0;
    assert_eq!(a, b);
}
