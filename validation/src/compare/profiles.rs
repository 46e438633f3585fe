//! Study 2: radial profiles R(r) of the light preset at 450, 550, 650 nm, multipole against MC.

use super::{Settings, Summary, progress, write_study};
use crate::montecarlo::{self, DEFAULT_G, LayeredMedium, McOptions, RadialGrid};
use multipole::diffusion::boundary::observable_reflectance;
use multipole::{Method, ProfileOptions};
use skin_optics::{Preset, SkinParams, Wavelength};
use skin_plot::{LineChart, Panel, Series};
use std::path::Path;

/// Wavelengths of the profile study, nm.
pub const PROFILE_WAVELENGTHS_NM: [f64; 3] = [450.0, 550.0, 650.0];

/// Mean of the multipole profile over annulus `i` (area weighted, 8 points), observable scale.
pub(crate) fn annulus_mean(p: &multipole::Profile, grid: &RadialGrid, i: usize, eta: f64) -> f64 {
    let (r0, dr) = (grid.inner_mm(i), grid.outer_mm(i) - grid.inner_mm(i));
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..8 {
        let r = r0 + (k as f64 + 0.5) / 8.0 * dr;
        num += r * p.eval(r);
        den += r;
    }
    observable_reflectance(num / den, eta)
}

/// Write `profiles.csv` and `profiles.png`; add each wavelength's energy-weighted error to `summary`.
pub fn run(settings: &Settings, out: &Path, summary: &mut Summary) -> anyhow::Result<()> {
    let skin = SkinParams::preset(Preset::Light);
    let grid = RadialGrid::new(0.02, 300)?;
    let bar = progress(PROFILE_WAVELENGTHS_NM.len() as u64, "profiles");
    let mut chart = LineChart::new(
        "Radial profile, light preset: multipole (lines) vs Monte Carlo (points)",
        "r (mm)",
        "R(r) (mm⁻², per incident flux)",
    )
    .log_y();
    let mut rows = Vec::new();
    let colors = [[40, 80, 220], [40, 160, 60], [210, 40, 40]];
    for (k, &nm) in PROFILE_WAVELENGTHS_NM.iter().enumerate() {
        let lambda = Wavelength::new(nm)?;
        let mp =
            multipole::skin::profile(&skin, lambda, Method::Multipole, &ProfileOptions::default())?;
        let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G)?;
        let opts = McOptions::new(settings.profile_photons, 16, settings.seed)?.with_grid(grid);
        let mc = montecarlo::run(&stack, &opts);
        let (mut line, mut pts) = (Vec::new(), Vec::new());
        let (mut abs_err, mut total) = (0.0, 0.0);
        for i in 0..grid.bins() {
            let r = grid.r_mid_mm(i);
            let m = annulus_mean(&mp, &grid, i, skin.eta());
            let (v, se) = (mc.radial.reflectance_per_mm2[i], mc.radial.stderr[i]);
            let area = grid.annulus_area_mm2(i);
            abs_err += (m - v).abs() * area;
            total += v * area;
            rows.push(format!("{nm},{r:.4},{m:.6e},{v:.6e},{se:.3e}"));
            // The multipole table stops at its 99.9%-energy radius; beyond it there is no curve.
            if r <= mp.r_max_mm() {
                line.push((r, m));
            }
            // Points whose noise is below half their value; the rest would clutter the log axis.
            if v > 0.0 && se < 0.5 * v {
                pts.push((r, v));
            }
        }
        let energy_error = abs_err / total;
        let c = colors[k];
        chart = chart
            .with_series(Series::line(format!("{nm} nm multipole"), line).with_color(c))
            .with_series(Series::scatter(format!("{nm} nm MC"), pts).with_color(c));
        summary.push(
            "2 profiles",
            &format!("light preset, {nm} nm"),
            format!("{:.1}% (energy-weighted)", 100.0 * energy_error),
            format!("r ≤ {} mm", grid.r_max_mm()),
        );
        bar.inc(1);
    }
    bar.finish_and_clear();
    write_study(
        out,
        "profiles",
        (
            "lambda_nm,r_mm,multipole_per_mm2,monte_carlo_per_mm2,monte_carlo_stderr",
            &rows,
        ),
        &[Panel::Line(chart)],
        (1000, 700),
    )
}
