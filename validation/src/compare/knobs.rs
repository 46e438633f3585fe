//! Study 4: speed against accuracy for every approximation knob, light preset at 550 nm.
//!
//! Multipole profile knobs (poles, radial samples, transform nodes per panel): time of one
//! `multipole::skin::profile` call (best of 3) against `multipole::skin::profile_error`'s maximum
//! energy-density error relative to the converged reference. MC photon count: run time against the
//! relative error of the total against adding-doubling (`Method::Exact`, independent exact transport),
//! with the run's own relative standard error beside it (the error is noise of that size).
//! `Method::Exact`'s Monte Carlo shape (escaping photons): time of one profile against its
//! energy-weighted error Σ 2πr Δr |R − R_mc| / R_mc against an independent MC run of
//! `profile_photons` (whose own noise is a floor under the curve).

/// Escaping-photon settings of the exact profile's Monte Carlo shape.
const SHAPE_ESCAPES: [u64; 5] = [250, 1_000, 4_000, 16_000, 64_000];

use super::profiles::annulus_mean;
use super::{Settings, Summary, progress, timed_mc, write_study};
use crate::montecarlo::{self, DEFAULT_G, LayeredMedium, McOptions, RadialGrid};
use multipole::diffusion::slab::Poles;
use multipole::skin::ExactShape;
use multipole::{Method, ProfileOptions};
use skin_optics::{Preset, SkinParams, Wavelength};
use skin_plot::{LineChart, Panel, Series, SeriesStyle};
use std::path::Path;
use std::time::Instant;

/// (knob name, setting label, options) for every multipole setting measured.
fn multipole_settings() -> Vec<(&'static str, String, ProfileOptions)> {
    let base = ProfileOptions::default();
    type Set = fn(&mut ProfileOptions, usize);
    let knobs: [(&str, &[usize], Set); 3] = [
        ("poles", &[0, 1, 2, 3, 5, 10], |o, n| {
            o.diffusion.poles = Poles::Count(n)
        }),
        (
            "radial samples",
            &[16, 32, 64, 128, 256, 512, 1024],
            |o, n| o.diffusion.radial_samples = n,
        ),
        ("transform nodes", &[1, 2, 3, 5, 8, 16], |o, n| {
            o.diffusion.transform_nodes = n
        }),
    ];
    let mut v = Vec::new();
    for (knob, values, set) in knobs {
        for &n in values {
            let mut o = base;
            set(&mut o, n);
            v.push((knob, format!("{n}"), o));
        }
        if knob == "poles" {
            v.push(("poles", "exact".into(), base));
        }
    }
    v
}

/// Write `knobs.csv` and `knobs.png`; add the cheapest setting under 1% error per knob to `summary`.
pub fn run(settings: &Settings, out: &Path, summary: &mut Summary) -> anyhow::Result<()> {
    let skin = SkinParams::preset(Preset::Light);
    let lambda = Wavelength::new(550.0)?;
    let knobs = multipole_settings();
    let mut photon_counts = Vec::new();
    let mut n = 1000u64;
    while n <= settings.knob_max_photons {
        photon_counts.push(n);
        n *= 3;
    }
    let bar = progress(
        (knobs.len() + photon_counts.len() + SHAPE_ESCAPES.len()) as u64,
        "knob settings",
    );
    let mut rows = Vec::new();
    let mut series: Vec<(&str, Vec<(f64, f64)>)> = Vec::new();
    for (knob, label, opts) in &knobs {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let t = Instant::now();
            let p = multipole::skin::profile(&skin, lambda, Method::Multipole, opts)?;
            best = best.min(t.elapsed().as_secs_f64());
            std::hint::black_box(p);
        }
        let e = multipole::skin::profile_error(&skin, lambda, Method::Multipole, opts)?;
        let err = e.max_energy_density_error;
        rows.push(format!("multipole {knob},{label},{best:.6e},{err:.4e}"));
        match series.iter_mut().find(|(k, _)| k == knob) {
            Some((_, pts)) => pts.push((best, err)),
            None => series.push((knob, vec![(best, err)])),
        }
        bar.inc(1);
    }
    let exact = multipole::skin::diffuse_reflectance(&skin, lambda, Method::Exact)?;
    let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G)?;
    let (mut mc_pts, mut se_pts) = (Vec::new(), Vec::new());
    for &n in &photon_counts {
        let (r, s) = timed_mc(&stack, &McOptions::new(n, 16, settings.seed)?);
        let err = (r.diffuse_reflectance.mean - exact).abs() / exact;
        rows.push(format!("monte carlo photons,{n},{s:.6e},{err:.4e}"));
        let se = r.diffuse_reflectance.stderr / exact;
        rows.push(format!("monte carlo standard error,{n},{s:.6e},{se:.4e}"));
        mc_pts.push((s, err));
        se_pts.push((s, se));
        bar.inc(1);
    }
    let shape_pts = shape_knob(settings, &skin, lambda, &mut rows, &bar)?;
    bar.finish_and_clear();
    for (knob, pts) in &series {
        let cheapest = rows
            .iter()
            .filter(|r| r.starts_with(&format!("multipole {knob},")))
            .filter_map(|r| {
                let f: Vec<&str> = r.split(',').collect();
                let (t, e): (f64, f64) = (f[2].parse().ok()?, f[3].parse().ok()?);
                (e < 0.01).then_some((t, f[1].to_string(), e))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let worst = pts.iter().map(|p| p.1).fold(0.0, f64::max);
        summary.push(
            "4 knobs",
            &format!("multipole {knob}"),
            format!("{:.2}% (worst setting)", 100.0 * worst),
            cheapest.map_or("no setting under 1%".into(), |(t, l, e)| {
                format!(
                    "cheapest under 1%: {l} ({:.2} ms, {:.2}%)",
                    1e3 * t,
                    100.0 * e
                )
            }),
        );
    }
    if let Some((s, e)) = mc_pts.last() {
        summary.push(
            "4 knobs",
            "MC photons (total vs adding-doubling)",
            format!("{:.2}%", 100.0 * e),
            format!(
                "{} photons, {s:.2} s",
                photon_counts.last().copied().unwrap_or(0)
            ),
        );
    }
    if let Some(k) = shape_pts.iter().position(|p| p.1 < 0.10) {
        summary.push(
            "4 knobs",
            "exact profile: MC shape escapes (energy-weighted vs MC)",
            format!("{:.1}%", 100.0 * shape_pts[k].1),
            format!(
                "fewest under 10%: {} escapes ({:.2} s); {} escapes: {:.1}%",
                SHAPE_ESCAPES[k],
                shape_pts[k].0,
                SHAPE_ESCAPES[SHAPE_ESCAPES.len() - 1],
                100.0 * shape_pts[shape_pts.len() - 1].1
            ),
        );
    }
    let mut chart = LineChart::new(
        "Speed vs accuracy, light preset 550 nm",
        "time per evaluation (s)",
        "relative error (profile: max energy density; MC: total; shape: energy-weighted)",
    )
    .log_x()
    .log_y();
    for (knob, pts) in series {
        chart = chart.with_series(
            Series::line(format!("multipole {knob}"), pts).with_style(SeriesStyle::LinePoints),
        );
    }
    chart = chart
        .with_series(
            Series::line("Monte Carlo photons", mc_pts).with_style(SeriesStyle::LinePoints),
        )
        .with_series(Series::dashed("Monte Carlo standard error", se_pts))
        .with_series(
            Series::line(
                "exact profile: MC shape escapes (energy-weighted)",
                shape_pts,
            )
            .with_style(SeriesStyle::LinePoints),
        );
    write_study(
        out,
        "knobs",
        ("knob,setting,seconds,relative_error", &rows),
        &[Panel::Line(chart)],
        (1000, 700),
    )
}

/// Time and energy-weighted error of the exact profile's Monte Carlo shape per escapes setting.
fn shape_knob(
    settings: &Settings,
    skin: &SkinParams,
    lambda: Wavelength,
    rows: &mut Vec<String>,
    bar: &indicatif::ProgressBar,
) -> anyhow::Result<Vec<(f64, f64)>> {
    let grid = RadialGrid::new(0.02, 300)?;
    let stack = LayeredMedium::skin(skin, lambda, DEFAULT_G)?;
    // A seed of its own: the reference must be independent of the shape's fixed seed.
    let opts = McOptions::new(settings.profile_photons, 16, settings.seed + 7)?.with_grid(grid);
    let mc = montecarlo::run(&stack, &opts);
    let total: f64 = (0..grid.bins())
        .map(|i| mc.radial.reflectance_per_mm2[i] * grid.annulus_area_mm2(i))
        .sum();
    let mut pts = Vec::new();
    for escapes in SHAPE_ESCAPES {
        let t = Instant::now();
        let p = multipole::skin::exact_profile(
            skin,
            lambda,
            ExactShape::MonteCarlo { escapes },
            &ProfileOptions::default(),
        )?;
        let secs = t.elapsed().as_secs_f64();
        let err = (0..grid.bins())
            .map(|i| {
                let m = annulus_mean(&p, &grid, i, skin.eta());
                (m - mc.radial.reflectance_per_mm2[i]).abs() * grid.annulus_area_mm2(i)
            })
            .sum::<f64>()
            / total;
        rows.push(format!(
            "exact shape escapes,{escapes},{secs:.6e},{err:.4e}"
        ));
        pts.push((secs, err));
        bar.inc(1);
    }
    Ok(pts)
}
