//! Study 5: `Method::Exact` (adding-doubling totals) beside `Method::Multipole`, both against the
//! Monte Carlo: total diffuse reflectance over 400–700 nm for C_m ∈ {0, 0.01, 0.05, 0.1, 0.25, 0.5}
//! (β_m 0.7, C_h 0.02), and the energy-weighted radial profile error of the light and dark presets
//! at 450/550/650 nm (docs/physics.md §9).

use super::profiles::{PROFILE_WAVELENGTHS_NM, annulus_mean};
use super::{Settings, Summary, progress, write_csv, write_study};
use crate::montecarlo::{self, DEFAULT_G, LayeredMedium, McOptions, RadialGrid};
use multipole::{Method, ProfileOptions};
use skin_optics::{Preset, SkinParams, Wavelength, WavelengthGrid};
use skin_plot::{LineChart, Panel, Series, SeriesStyle};
use std::path::Path;

/// Melanin fractions C_m of the spectral study.
pub const MELANIN_FRACTIONS: [f64; 6] = [0.0, 0.01, 0.05, 0.1, 0.25, 0.5];
/// Eumelanin blend β_m of the spectral study.
pub const EUMELANIN_BLEND: f64 = 0.7;
/// Hemoglobin fraction C_h of the spectral study.
pub const HEMOGLOBIN: f64 = 0.02;
/// The two methods compared, in chart order.
const METHODS: [Method; 2] = [Method::Exact, Method::Multipole];

/// Write `exact_vs_multipole.{csv,png}` and `exact_profiles.{csv,png}`; add the worst errors to `summary`.
pub fn run(settings: &Settings, out: &Path, summary: &mut Summary) -> anyhow::Result<()> {
    spectra(settings, out, summary)?;
    profiles(settings, out, summary)
}

/// Relative error of both methods' total diffuse reflectance against the MC, per C_m and wavelength.
fn spectra(settings: &Settings, out: &Path, summary: &mut Summary) -> anyhow::Result<()> {
    let grid = WavelengthGrid::new(400.0, 700.0, settings.spectrum_step_nm)?;
    let bar = progress(
        (grid.len() * MELANIN_FRACTIONS.len()) as u64,
        "exact-vs-multipole runs",
    );
    let mut charts = METHODS.map(|m| {
        LineChart::new(
            format!(
                "{m}: relative error against Monte Carlo (β_m {EUMELANIN_BLEND}, C_h {HEMOGLOBIN})"
            ),
            "wavelength (nm)",
            "(method − MC) / MC (%)",
        )
    });
    let mut rows = Vec::new();
    for (k, &cm) in MELANIN_FRACTIONS.iter().enumerate() {
        let skin = SkinParams::new(cm, EUMELANIN_BLEND, HEMOGLOBIN, 0.0)?;
        let mut curves: [Vec<(f64, f64)>; 2] = [Vec::new(), Vec::new()];
        let mut worst = [(0.0f64, 0.0f64, 0.0f64); 2];
        // Largest |error| beyond two standard errors of the MC: what noise cannot explain.
        let mut excess = [0.0f64; 2];
        for lambda in grid.iter() {
            let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G)?;
            let expected = multipole::skin::diffuse_reflectance(&skin, lambda, Method::Exact)?;
            let photons = ((settings.exact_escapes as f64 / expected.max(1e-6)) as u64)
                .clamp(settings.exact_photons, 100 * settings.exact_photons);
            let opts = McOptions::new(photons, 16, settings.seed)?;
            let mc = montecarlo::run(&stack, &opts).diffuse_reflectance;
            let mut values = [0.0; 2];
            for (j, method) in METHODS.into_iter().enumerate() {
                let v = multipole::skin::diffuse_reflectance(&skin, lambda, method)?;
                let rel = (v - mc.mean) / mc.mean;
                if rel.abs() > worst[j].0.abs() {
                    worst[j] = (rel, lambda.nm(), mc.stderr / mc.mean);
                }
                excess[j] = excess[j].max(rel.abs() - 2.0 * mc.stderr / mc.mean);
                curves[j].push((lambda.nm(), 100.0 * rel));
                values[j] = v;
            }
            rows.push(format!(
                "{cm},{EUMELANIN_BLEND},{HEMOGLOBIN},{},{:.6},{:.6},{:.6},{:.6},{:.5},{:.5},{}",
                lambda.nm(),
                values[0],
                values[1],
                mc.mean,
                mc.stderr,
                (values[0] - mc.mean) / mc.mean,
                (values[1] - mc.mean) / mc.mean,
                photons
            ));
            bar.inc(1);
        }
        let color = skin_plot::palette_color(k);
        for (j, method) in METHODS.into_iter().enumerate() {
            let pts = std::mem::take(&mut curves[j]);
            charts[j] = std::mem::take(&mut charts[j]).with_series(
                Series::line(format!("C_m {cm}"), pts)
                    .with_style(SeriesStyle::LinePoints)
                    .with_color(color),
            );
            summary.push(
                "5 exact vs multipole",
                &format!("{method}, C_m {cm} (β_m {EUMELANIN_BLEND}, C_h {HEMOGLOBIN})"),
                format!("{:+.1}%", 100.0 * worst[j].0),
                format!(
                    "{} nm (MC ±{:.2}%); largest |error| beyond 2σ of the MC: {:.2}%",
                    worst[j].1,
                    100.0 * worst[j].2,
                    100.0 * excess[j].max(0.0)
                ),
            );
        }
    }
    bar.finish_and_clear();
    let [a, b] = charts;
    write_study(
        out,
        "exact_vs_multipole",
        (
            "melanin,eumelanin_blend,hemoglobin,lambda_nm,exact,multipole,monte_carlo,monte_carlo_stderr,exact_relative_error,multipole_relative_error,photons",
            &rows,
        ),
        &[Panel::Line(a), Panel::Line(b)],
        (1000, 1100),
    )
}

/// Energy-weighted profile error Σ 2πr Δr |R − R_mc| / R_mc,tot of both methods, light and dark presets.
fn profiles(settings: &Settings, out: &Path, summary: &mut Summary) -> anyhow::Result<()> {
    let grid = RadialGrid::new(0.02, 300)?;
    let presets = [Preset::Light, Preset::Dark];
    let bar = progress(
        (presets.len() * PROFILE_WAVELENGTHS_NM.len()) as u64,
        "exact profiles",
    );
    let mut rows = Vec::new();
    let mut detail = Vec::new();
    let mut charts = presets.map(|p| {
        LineChart::new(
            format!("Radial profile, {p} preset: exact (solid), multipole (dashed), MC (points)"),
            "r (mm)",
            "R(r) (mm⁻², per incident flux)",
        )
        .log_y()
    });
    for (pi, preset) in presets.into_iter().enumerate() {
        let skin = SkinParams::preset(preset);
        for (k, &nm) in PROFILE_WAVELENGTHS_NM.iter().enumerate() {
            let lambda = Wavelength::new(nm)?;
            let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G)?;
            let opts = McOptions::new(settings.profile_photons, 16, settings.seed)?.with_grid(grid);
            let mc = montecarlo::run(&stack, &opts);
            let color = [[40, 80, 220], [40, 160, 60], [210, 40, 40]][k];
            let mut errors = [0.0; 2];
            let mut curves: [Vec<(f64, f64)>; 2] = [Vec::new(), Vec::new()];
            let mut total = 0.0;
            let mut pts = Vec::new();
            let profiles = METHODS
                .map(|m| multipole::skin::profile(&skin, lambda, m, &ProfileOptions::default()));
            let [pe, pm] = profiles;
            let (pe, pm) = (pe?, pm?);
            for i in 0..grid.bins() {
                let r = grid.r_mid_mm(i);
                let area = grid.annulus_area_mm2(i);
                let (v, se) = (mc.radial.reflectance_per_mm2[i], mc.radial.stderr[i]);
                total += v * area;
                let mut values = [0.0; 2];
                for (j, p) in [&pe, &pm].into_iter().enumerate() {
                    let m = annulus_mean(p, &grid, i, skin.eta());
                    errors[j] += (m - v).abs() * area;
                    values[j] = m;
                    // Each table stops at its 99.9%-energy radius; beyond it there is no curve.
                    if r <= p.r_max_mm() && m > 0.0 {
                        curves[j].push((r, m));
                    }
                }
                detail.push(format!(
                    "{preset},{nm},{r:.4},{:.6e},{:.6e},{v:.6e},{se:.3e}",
                    values[0], values[1]
                ));
                // Points whose noise is below half their value; the rest would clutter the log axis.
                if v > 0.0 && se < 0.5 * v {
                    pts.push((r, v));
                }
            }
            let [ce, cm] = curves;
            charts[pi] = std::mem::take(&mut charts[pi])
                .with_series(Series::line(format!("{nm} nm exact"), ce).with_color(color))
                .with_series(Series::dashed(format!("{nm} nm multipole"), cm).with_color(color))
                .with_series(Series::scatter(format!("{nm} nm MC"), pts).with_color(color));
            let (ee, em) = (errors[0] / total, errors[1] / total);
            rows.push(format!(
                "{preset},{nm},{ee:.5},{em:.5},{},{total:.6}",
                settings.profile_photons
            ));
            summary.push(
                "5 exact profiles",
                &format!("{preset} preset, {nm} nm"),
                format!(
                    "exact {:.1}%, multipole {:.1}% (energy-weighted)",
                    100.0 * ee,
                    100.0 * em
                ),
                format!("r ≤ {} mm", grid.r_max_mm()),
            );
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    write_csv(
        &out.join("exact_profiles_radial.csv"),
        "preset,lambda_nm,r_mm,exact_per_mm2,multipole_per_mm2,monte_carlo_per_mm2,monte_carlo_stderr",
        &detail,
    )?;
    let [a, b] = charts;
    write_study(
        out,
        "exact_profiles",
        (
            "preset,lambda_nm,exact_energy_error,multipole_energy_error,photons,monte_carlo_total",
            &rows,
        ),
        &[Panel::Line(a), Panel::Line(b)],
        (1000, 1300),
    )
}
