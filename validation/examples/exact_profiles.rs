//! Radial profile error of `Method::Exact` against the layered Monte Carlo (target: energy-weighted
//! error within 10%), for each `multipole::skin::ExactShape` and the plain multipole.
//!
//! Error = Σ_bins |E_model − E_mc| / R_mc, E = ∫ 2πr R dr over each MC annulus (per incident photon:
//! the model's per-entering profile times 1 − F_r(0)), R_mc the MC's total diffuse reflectance. The MC's
//! own noise contributes: the "noise" column is Σ √(2/π) σ_bin / R_mc, the expected value of that sum
//! for a model equal to the truth.
//!
//! The Monte Carlo shapes (`ExactShape::MonteCarlo`) are timed (wall, ms, all cores).
//!
//! `cargo run --release -p validation --features studies --example exact_profiles [photons]` (default 1e6, seed 7).

use indicatif::{ProgressBar, ProgressStyle};
use multipole::skin::{ExactShape, Method, exact_profile, profile};
use multipole::{Profile, ProfileOptions};
use skin_optics::{Preset, SkinParams, Wavelength};
use validation::montecarlo::{DEFAULT_G, LayeredMedium, McOptions, McResult, run};

/// Knob values of the Monte Carlo shape (escaping photons per wavelength).
const ESCAPES: [u64; 3] = [1_000, 4_000, 16_000];

/// Annulus energy of `p` on [a, b] (mm), 8-point Gauss–Legendre on 2πr R(r).
fn annulus_energy(p: &Profile, a: f64, b: f64) -> f64 {
    const X: [f64; 4] = [
        0.183_434_642_5,
        0.525_532_409_9,
        0.796_666_477_4,
        0.960_289_856_5,
    ];
    const W: [f64; 4] = [
        0.362_683_783_4,
        0.313_706_645_9,
        0.222_381_034_5,
        0.101_228_536_3,
    ];
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let f = |r: f64| 2.0 * std::f64::consts::PI * r * p.eval(r);
    h * X
        .iter()
        .zip(W)
        .map(|(x, w)| w * (f(m - h * x) + f(m + h * x)))
        .sum::<f64>()
}

/// Energy-weighted error of `p` (per entering flux) against the MC run `mc`.
fn error(p: &Profile, mc: &McResult) -> f64 {
    let g = mc.radial.grid;
    let enter = 1.0 - mc.specular_reflectance;
    let tot = mc.diffuse_reflectance.mean;
    (0..g.bins())
        .map(|i| {
            let model = enter * annulus_energy(p, g.inner_mm(i), g.outer_mm(i));
            let measured = mc.radial.reflectance_per_mm2[i] * g.annulus_area_mm2(i);
            (model - measured).abs()
        })
        .sum::<f64>()
        / tot
}

fn main() -> anyhow::Result<()> {
    let photons: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(1_000_000);
    let mc_opts = McOptions::new(photons, 32, 7)?;
    let opts = ProfileOptions::default();
    let cases: Vec<(Preset, f64)> = [Preset::Light, Preset::Dark]
        .into_iter()
        .flat_map(|p| [450.0, 550.0, 650.0].map(|nm| (p, nm)))
        .collect();
    let bar = ProgressBar::new(cases.len() as u64).with_style(ProgressStyle::with_template(
        "{bar:30} {pos}/{len} MC runs {elapsed}",
    )?);
    println!(
        "| preset | λ (nm) | R_mc | R_exact/R_mc − 1 | multipole | exact, rescaled total | exact, per layer | {} | MC noise |",
        ESCAPES
            .map(|e| format!("MC shape {e} escapes (ms)"))
            .join(" | ")
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for (preset, nm) in cases {
        let skin = SkinParams::preset(preset);
        let lambda = Wavelength::new(nm)?;
        let mc = run(&LayeredMedium::skin(&skin, lambda, DEFAULT_G)?, &mc_opts);
        bar.inc(1);
        let multi = profile(&skin, lambda, Method::Multipole, &opts)?;
        let resc = exact_profile(&skin, lambda, ExactShape::RescaledTotal, &opts)?;
        let per = exact_profile(&skin, lambda, ExactShape::PerLayer, &opts)?;
        let mut shapes = Vec::new();
        for escapes in ESCAPES {
            let t0 = std::time::Instant::now();
            let p = exact_profile(&skin, lambda, ExactShape::MonteCarlo { escapes }, &opts)?;
            shapes.push((p, t0.elapsed().as_secs_f64() * 1e3));
        }
        let tot = mc.diffuse_reflectance.mean;
        let g = mc.radial.grid;
        let noise: f64 = (0..g.bins())
            .map(|i| {
                (2.0 / std::f64::consts::PI).sqrt() * mc.radial.stderr[i] * g.annulus_area_mm2(i)
            })
            .sum::<f64>()
            / tot;
        let exact_obs = (1.0 - mc.specular_reflectance) * per.total();
        if std::env::var_os("EXACT_PROFILES_DETAIL").is_some() {
            let (sc, lt) = multipole::skin::layer_scales(&skin, lambda)?;
            bar.suspend(|| {
                eprintln!("{preset:?} {nm}: scales {sc:?}\n  exact {lt:?}");
                let edges = [0.0, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0];
                for w in edges.windows(2) {
                    let (mut em, mut ep, mut er, mut e) = (0.0, 0.0, 0.0, 0.0);
                    for i in 0..g.bins() {
                        let a = g.inner_mm(i);
                        if a < w[0] - 1e-12 || a >= w[1] - 1e-12 {
                            continue;
                        }
                        let b = g.outer_mm(i);
                        let enter = 1.0 - mc.specular_reflectance;
                        e += mc.radial.reflectance_per_mm2[i] * g.annulus_area_mm2(i);
                        em += enter * annulus_energy(&multi, a, b);
                        er += enter * annulus_energy(&resc, a, b);
                        ep += enter * annulus_energy(&per, a, b);
                    }
                    eprintln!(
                        "  r {:>4}-{:<4} mm: MC {:.4} multipole {:.4} rescaled {:.4} per-layer {:.4} (fractions of R_mc)",
                        w[0], w[1], e / tot, em / tot, er / tot, ep / tot
                    );
                }
            });
        }
        bar.suspend(|| {
            println!(
                "| {preset:?} | {nm} | {tot:.5} | {:+.2}% | {:.1}% | {:.1}% | {:.1}% | {} | {:.1}% |",
                100.0 * (exact_obs / tot - 1.0),
                100.0 * error(&multi, &mc),
                100.0 * error(&resc, &mc),
                100.0 * error(&per, &mc),
                shapes
                    .iter()
                    .map(|(p, ms)| format!("{:.1}% ({ms:.0})", 100.0 * error(p, &mc)))
                    .collect::<Vec<_>>()
                    .join(" | "),
                100.0 * noise,
            );
        });
    }
    bar.finish_and_clear();
    Ok(())
}
