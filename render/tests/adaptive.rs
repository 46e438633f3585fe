//! Noise-targeted adaptive sampling: unbiased against fixed sampling, a noise estimate that
//! agrees with the two-seed measurement, and thread-count independence.

use render::testing as common;

use common::SceneText;
use render::film::Film;
use render::integrator::PathSettings;
use render::noise::{luminance, relative_noise};
use render::renderer::{RenderOptions, RenderStats, render};
use render::sampler::SamplerKind;
use render::scene::Scene;

/// A grey plane lit by a small sphere light and a dim environment: every pixel is noisy (light
/// sampling and the bounce), none has a known closed form, so fixed sampling is the reference.
fn lit_plane() -> Scene {
    SceneText::camera([0.0, 0.0, 500.0], 30.0)
        .environment("d65", 0.05)
        .diffuse("grey", 0.5)
        .diffuse("white", 0.9)
        .mesh("quad", "grey", 1000.0)
        .mesh("sphere", "white", 60.0)
        .with("translate_mm = [0, 0, 60]")
        .sphere_light([150.0, 150.0, 200.0], 20.0, 40.0)
        .load()
}

fn run(s: &Scene, spp: u32, noise: Option<f64>, seed: u64, threads: usize) -> (Film, RenderStats) {
    let o = RenderOptions {
        width: 24,
        height: 24,
        spp,
        noise,
        seed,
        threads: Some(threads),
        ..Default::default()
    };
    render(s, &o.validate().unwrap()).unwrap()
}

fn luminances(film: &Film) -> Vec<f64> {
    let (w, h) = film.size();
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| luminance(film.linear_srgb(x, y)))
        .collect()
}

/// Image mean luminance and its standard error from the films' own per-pixel variances.
fn mean_and_stderr(film: &Film) -> (f64, f64) {
    let (w, h) = film.size();
    let n = (w * h) as f64;
    let mean = luminances(film).iter().sum::<f64>() / n;
    let var: f64 = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| film.variance(x, y))
        .sum();
    (mean, var.sqrt() / n)
}

/// The adaptive image's mean luminance equals the fixed-spp image's within 4 combined standard
/// errors (a false failure has probability 6·10⁻⁵), while the adaptive render took fewer samples.
#[test]
fn adaptive_mean_equals_fixed_mean() {
    let s = lit_plane();
    let (fixed, _) = run(&s, 256, None, 1, 2);
    let (adaptive, stats) = run(&s, 256, Some(0.05), 2, 2);
    let (mf, ef) = mean_and_stderr(&fixed);
    let (ma, ea) = mean_and_stderr(&adaptive);
    let tol = 4.0 * ef.hypot(ea);
    assert!(
        (mf - ma).abs() <= tol,
        "fixed {mf} ± {ef}, adaptive {ma} ± {ea}"
    );
    assert!(stats.mean_spp < 256.0 && stats.converged > 0, "{stats:?}");
}

/// The two-seed noise at 32 spp with `path`, and the noise the two renders estimated (mean).
fn measured_and_estimated(s: &Scene, path: PathSettings) -> (f64, f64) {
    let o = |seed| RenderOptions {
        width: 24,
        height: 24,
        spp: 32,
        seed,
        threads: Some(2),
        path,
        ..Default::default()
    };
    let (a, sa) = render(s, &o(1).validate().unwrap()).unwrap();
    let (b, sb) = render(s, &o(2).validate().unwrap()).unwrap();
    let measured = relative_noise(&luminances(&a), &luminances(&b))
        .unwrap()
        .relative_noise;
    (measured, 0.5 * (sa.noise + sb.noise))
}

/// The noise a render estimates from its own samples is within 20% of the two-seed metric, with
/// independent samples (sample variance) and with the default two scrambled Sobol half-sequences
/// per pixel (half difference). 576 lit pixels: the metric fluctuates by about 1/√(2·576) ≈ 3%,
/// the half-difference estimate (one degree of freedom per pixel) by 1/√(2·576) as well. With
/// one Sobol sequence per pixel the sample variance overstates the error of the mean (measured
/// here 7.2% estimated against 2.7%): that estimate may only be an upper bound (10% margin).
#[test]
fn noise_estimate_matches_two_seed_measurement() {
    let s = lit_plane();
    for sampler in [SamplerKind::Independent, SamplerKind::SobolPair] {
        let path = PathSettings {
            sampler,
            ..PathSettings::default()
        };
        let (measured, estimated) = measured_and_estimated(&s, path);
        assert!(
            (estimated / measured - 1.0).abs() < 0.2,
            "{sampler:?}: estimated {estimated}, measured {measured}"
        );
    }
    let one_sequence = PathSettings {
        sampler: SamplerKind::Sobol,
        ..PathSettings::default()
    };
    let (measured, estimated) = measured_and_estimated(&s, one_sequence);
    assert!(
        estimated >= 0.9 * measured,
        "Sobol: estimated {estimated}, measured {measured}"
    );
}

/// Pixels that stop at the noise target report the noise two seeds measure: a 48 × 48 lit plane
/// with a 3% target and a 1024-sample cap, where nearly every pixel stops at the target after
/// about 50 samples, i.e. on the first of many tests its estimate passes. The calibrated estimate
/// (the default) has ≈ n − 1 degrees of freedom per pixel, so stopping cannot select it low;
/// the half difference, one degree of freedom per pixel and nine pooled, reported 2.52% against
/// 3.47% measured here (−27%). Tolerance 10%: the two-seed metric over ≈ 1800 lit pixels
/// fluctuates by 1/√(2·1800) ≈ 1.7%, the estimate by less (ρ over 9 blocks of 256 pixels), so
/// 10% is > 4 combined standard deviations and the half difference fails by far.
#[test]
fn noise_estimate_of_stopped_pixels_matches_two_seed_measurement() {
    let s = lit_plane();
    let o = |seed| RenderOptions {
        width: 48,
        height: 48,
        spp: 1024,
        noise: Some(0.03),
        seed,
        threads: Some(2),
        ..Default::default()
    };
    let (a, sa) = render(&s, &o(1).validate().unwrap()).unwrap();
    let (b, sb) = render(&s, &o(2).validate().unwrap()).unwrap();
    let measured = relative_noise(&luminances(&a), &luminances(&b))
        .unwrap()
        .relative_noise;
    let estimated = 0.5 * (sa.noise + sb.noise);
    // Most pixels stopped at the target, well before the cap.
    for st in [sa, sb] {
        assert!(st.converged > 2000 && st.mean_spp < 200.0, "{st:?}");
    }
    assert!(
        (estimated / measured - 1.0).abs() < 0.1,
        "estimated {estimated}, measured {measured}"
    );
}

/// With a noise target, the same seed gives the same image on one and on two threads.
#[test]
fn adaptive_render_is_thread_count_independent() {
    let s = lit_plane();
    let (a, _) = run(&s, 64, Some(0.05), 3, 1);
    let (b, _) = run(&s, 64, Some(0.05), 3, 2);
    assert_eq!(a, b);
}

/// A noise target outside (0, 1) is a typed error naming `noise`.
#[test]
fn bad_noise_target_is_rejected() {
    for bad in [0.0, -0.1, 1.0, f64::NAN] {
        let o = RenderOptions {
            noise: Some(bad),
            ..Default::default()
        };
        assert_eq!(o.validate().unwrap_err().name, "noise");
    }
}
