//! Study 1: observable diffuse reflectance over 400–700 nm for each preset, multipole against MC.

use super::{Settings, Summary, progress, timed_mc, write_study};
use crate::montecarlo::{DEFAULT_G, LayeredMedium, McOptions};
use multipole::Method;
use skin_optics::{Preset, SkinParams, Wavelength, WavelengthGrid};
use skin_plot::{LineChart, Panel, Series};
use std::path::Path;

/// Write `spectra.csv` and `spectra.png` and add the worst error per preset to `summary`.
pub fn run(settings: &Settings, out: &Path, summary: &mut Summary) -> anyhow::Result<()> {
    let grid = WavelengthGrid::new(400.0, 700.0, settings.spectrum_step_nm)?;
    let bar = progress((grid.len() * Preset::ALL.len()) as u64, "spectra runs");
    let mut rows = Vec::new();
    let mut refl = LineChart::new(
        "Diffuse reflectance: multipole (lines) vs Monte Carlo (points)",
        "wavelength (nm)",
        "diffuse reflectance (specular excluded)",
    );
    let mut err = LineChart::new(
        "Relative error of the multipole against Monte Carlo",
        "wavelength (nm)",
        "(multipole − MC) / MC (%)",
    );
    let colors = [[200, 120, 60], [150, 80, 40], [70, 40, 20]];
    for (k, preset) in Preset::ALL.into_iter().enumerate() {
        let skin = SkinParams::preset(preset);
        let (mut mp, mut mc, mut re) = (Vec::new(), Vec::new(), Vec::new());
        let mut worst = (0.0f64, 0.0);
        for lambda in grid.iter() {
            let (m, r, s) = compare_one(&skin, lambda, settings)?;
            let rel = (m - r.0) / r.0;
            if rel.abs() > worst.0.abs() {
                worst = (rel, lambda.nm());
            }
            rows.push(format!(
                "{},{},{:.6},{:.6},{:.6},{:.5},{},{:.3}",
                preset,
                lambda.nm(),
                m,
                r.0,
                r.1,
                rel,
                settings.spectrum_photons,
                s
            ));
            mp.push((lambda.nm(), m));
            mc.push((lambda.nm(), r.0));
            re.push((lambda.nm(), 100.0 * rel));
            bar.inc(1);
        }
        let c = colors[k];
        refl = refl
            .with_series(Series::line(format!("{preset} multipole"), mp).with_color(c))
            .with_series(Series::scatter(format!("{preset} MC"), mc).with_color(c));
        err = err.with_series(
            Series::line(format!("{preset}"), re)
                .with_style(skin_plot::SeriesStyle::LinePoints)
                .with_color(c),
        );
        summary.push(
            "1 spectra",
            &format!("{preset} preset, 400–700 nm"),
            format!("{:+.1}%", 100.0 * worst.0),
            format!("{} nm", worst.1),
        );
    }
    bar.finish_and_clear();
    write_study(
        out,
        "spectra",
        (
            "preset,lambda_nm,multipole,monte_carlo,monte_carlo_stderr,relative_error,photons,mc_seconds",
            &rows,
        ),
        &[Panel::Line(refl), Panel::Line(err)],
        (1000, 1100),
    )
}

/// Multipole observable and MC (mean, stderr, seconds) for one skin and wavelength.
fn compare_one(
    skin: &SkinParams,
    lambda: Wavelength,
    settings: &Settings,
) -> anyhow::Result<(f64, (f64, f64), f64)> {
    let m = multipole::skin::diffuse_reflectance(skin, lambda, Method::Multipole)?;
    let stack = LayeredMedium::skin(skin, lambda, DEFAULT_G)?;
    let opts = McOptions::new(settings.spectrum_photons, 16, settings.seed)?;
    let (r, s) = timed_mc(&stack, &opts);
    Ok((
        m,
        (r.diffuse_reflectance.mean, r.diffuse_reflectance.stderr),
        s,
    ))
}
