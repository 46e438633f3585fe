//! `skin-validate table-knobs`: error against cost for every knob of the exact profile's shape
//! table (`multipole::skin::ShapeTable`, docs/physics.md §11). Each knob is varied alone from the
//! defaults; the error is the energy-weighted profile error ([`crate::shape_error`]) against
//! independent layered Monte Carlo runs (seed 7, 0.02 mm annuli to 6 mm) of the light, medium and
//! dark presets at 450, 550 and 650 nm; the cost is the table's build time (CPU-s of the whole
//! process while it is traced) and one profile's evaluation (wall ms, one thread, median of the
//! nine cases). Writes `table_knobs.csv` and `table_knobs.png` (worst error against each cost).

use crate::montecarlo::{DEFAULT_G, LayeredMedium, McOptions, McResult, RadialGrid, run};
use crate::shape_error::energy_error;
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use multipole::skin::{Method, ShapeTable, ShapeTableOptions, total_reflectance};
use skin_optics::{Preset, SkinParams, Wavelength};
use skin_plot::{LineChart, Panel, Series, SeriesStyle, palette_color, save_png};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// This process's user + system CPU time, seconds (Linux `/proc/self/stat`, 100 ticks per second).
fn process_cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|v| v.parse().ok())
        .collect();
    f.iter().sum::<f64>() / 100.0
}

/// One reference case: a preset at a wavelength, its layers and its Monte Carlo run.
struct Case {
    name: String,
    sigma_s: f64,
    sigma_a: (f64, f64),
    d_mm: f64,
    total: f64,
    mc: McResult,
}

fn cases(mc_photons: u64) -> anyhow::Result<Vec<Case>> {
    let grid = RadialGrid::new(0.02, 300)?;
    let mut out = Vec::new();
    for preset in Preset::ALL {
        for nm in [450.0, 550.0, 650.0] {
            let skin = SkinParams::preset(preset);
            let lambda = Wavelength::new(nm)?;
            let c = skin.coefficients(lambda);
            let stack = LayeredMedium::skin(&skin, lambda, DEFAULT_G)?;
            out.push(Case {
                name: format!("{}_{nm}", preset.name()),
                sigma_s: c.epidermis.sigma_s_prime / (1.0 - DEFAULT_G),
                sigma_a: (c.epidermis.sigma_a, c.dermis.sigma_a),
                d_mm: skin.epidermis_thickness_mm(),
                total: total_reflectance(&skin, lambda, Method::Exact)?,
                mc: run(&stack, &McOptions::new(mc_photons, 32, 7)?.with_grid(grid)),
            });
        }
    }
    Ok(out)
}

/// Every setting of the study: the defaults, then each knob alone at other values.
fn settings() -> Vec<(&'static str, ShapeTableOptions)> {
    let d = ShapeTableOptions::default();
    let mut s = vec![("default", d)];
    for photons in [50_000, 200_000, 1_000_000] {
        s.push(("photons", ShapeTableOptions { photons, ..d }));
    }
    for depths_per_octave in [1, 2, 8] {
        let o = ShapeTableOptions {
            depths_per_octave,
            ..d
        };
        s.push(("depths_per_octave", o));
    }
    for radial_per_decade in [8, 32] {
        let o = ShapeTableOptions {
            radial_per_decade,
            ..d
        };
        s.push(("radial_per_decade", o));
    }
    for alpha_per_decade in [4, 16] {
        let o = ShapeTableOptions {
            alpha_per_decade,
            ..d
        };
        s.push(("alpha_per_decade", o));
    }
    s
}

/// The value of `knob` in `o`.
fn knob_value(knob: &str, o: &ShapeTableOptions) -> f64 {
    match knob {
        "photons" => o.photons as f64,
        "depths_per_octave" => f64::from(o.depths_per_octave),
        "radial_per_decade" => f64::from(o.radial_per_decade),
        _ => f64::from(o.alpha_per_decade),
    }
}

/// One measured setting: (knob, options, build CPU-s, eval ms, error per case).
type Row = (&'static str, ShapeTableOptions, f64, f64, Vec<f64>);

/// Run the study with `mc_photons` per reference and write CSV and PNG into `out`.
pub fn run_table_knobs(mc_photons: u64, out: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let cases = cases(mc_photons)?;
    let settings = settings();
    let bar = ProgressBar::new(settings.len() as u64);
    if let Ok(style) =
        ProgressStyle::with_template("table knobs {bar:30} {pos}/{len} [{elapsed}<{eta}]")
    {
        bar.set_style(style);
    }
    let mut rows: Vec<Row> = Vec::new();
    for (knob, o) in settings {
        let cpu0 = process_cpu_s();
        let table = ShapeTable::build(DEFAULT_G, 1.4, &o, rayon::current_num_threads(), |_| {})?;
        let build = process_cpu_s() - cpu0;
        let mut times = Vec::new();
        let mut errs = Vec::new();
        for c in &cases {
            let t = Instant::now();
            let p = table
                .profile(c.sigma_s, c.sigma_a.0, c.sigma_a.1, c.d_mm, c.total)?
                .ok_or_else(|| anyhow::anyhow!("{} outside the table", c.name))?;
            times.push(t.elapsed().as_secs_f64() * 1e3);
            errs.push(energy_error(&p, &c.mc).0);
        }
        times.sort_by(f64::total_cmp);
        rows.push((knob, o, build, times[times.len() / 2], errs));
        bar.inc(1);
    }
    bar.finish_and_clear();
    let noise: Vec<f64> = cases.iter().map(|c| energy_error_noise(&c.mc)).collect();
    let mut csv = String::from(
        "knob,photons,depths_per_octave,radial_per_decade,alpha_per_decade,build_cpu_s,eval_ms",
    );
    for c in &cases {
        let _ = write!(csv, ",{}", c.name);
    }
    csv.push_str(",worst\n");
    for (knob, o, build, eval, errs) in &rows {
        let _ = write!(
            csv,
            "{knob},{},{},{},{},{build:.2},{eval:.3}",
            o.photons, o.depths_per_octave, o.radial_per_decade, o.alpha_per_decade
        );
        for e in errs {
            let _ = write!(csv, ",{e:.5}");
        }
        let _ = writeln!(csv, ",{:.5}", errs.iter().copied().fold(0.0, f64::max));
    }
    let _ = write!(csv, "reference_noise,,,,,,");
    for n in &noise {
        let _ = write!(csv, ",{n:.5}");
    }
    let _ = writeln!(csv, ",{:.5}", noise.iter().copied().fold(0.0, f64::max));
    print!("{csv}");
    let path = out.join("table_knobs.csv");
    skin_io::atomic::write_bytes(&path, csv.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    chart(out, &rows, noise.iter().copied().fold(0.0, f64::max))
}

/// Worst error (%) against build CPU-s and against evaluation ms, one line per knob through the
/// default, plus the references' noise floor.
fn chart(out: &Path, rows: &[Row], noise: f64) -> anyhow::Result<()> {
    let knobs = [
        "photons",
        "depths_per_octave",
        "radial_per_decade",
        "alpha_per_decade",
    ];
    let default = rows.iter().find(|r| r.0 == "default");
    let mut panels = Vec::new();
    for (title, cost, x_name) in [
        ("build", 2usize, "table build, CPU-s"),
        ("eval", 3usize, "one profile, ms (wall, one thread)"),
    ] {
        let mut panel = LineChart::new(
            format!(
                "Shape table: worst energy-weighted error against {title} cost, each knob alone"
            ),
            x_name,
            "worst error over 9 cases (%)",
        )
        .log_x()
        .log_y();
        let mut x_span = (f64::INFINITY, 0.0_f64);
        for (k, knob) in knobs.iter().enumerate() {
            let mut pts: Vec<(f64, f64, f64)> = rows
                .iter()
                .filter(|r| r.0 == *knob)
                .chain(default)
                .map(|r| {
                    let x = if cost == 2 { r.2 } else { r.3 };
                    let worst = r.4.iter().copied().fold(0.0, f64::max);
                    (knob_value(knob, &r.1), x.max(1e-3), 100.0 * worst)
                })
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            for p in &pts {
                x_span = (x_span.0.min(p.1), x_span.1.max(p.1));
            }
            let line = pts.iter().map(|p| (p.1, p.2)).collect();
            panel = panel.with_series(
                Series::line(format!("{knob} (ascending)"), line)
                    .with_style(SeriesStyle::LinePoints)
                    .with_color(palette_color(k)),
            );
        }
        panel = panel.with_series(Series::dashed(
            "reference noise (a perfect model's error)",
            vec![(x_span.0, 100.0 * noise), (x_span.1, 100.0 * noise)],
        ));
        panels.push(Panel::Line(panel));
    }
    let path = out.join("table_knobs.png");
    save_png(&path, &panels, 900, 1000).with_context(|| format!("writing {}", path.display()))
}

/// Expected energy-weighted error of a model equal to the truth against `mc` (its noise alone).
fn energy_error_noise(mc: &McResult) -> f64 {
    let g = mc.radial.grid;
    (0..g.bins())
        .map(|i| (2.0 / std::f64::consts::PI).sqrt() * mc.radial.stderr[i] * g.annulus_area_mm2(i))
        .sum::<f64>()
        / mc.diffuse_reflectance.mean
}
