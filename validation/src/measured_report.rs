//! `skin-validate measured`: fit a subset of measured spectra with the seed model and with a
//! chosen one, and write the residual bands and fitted parameters as CSV and PNG charts.

use crate::measured::{
    EXPLORE_CSV, HELDOUT_CSV, RecordFit, fit_records, parse_records, quantile, residual_bands,
};
use crate::measured_colour::{bounds_summary, bounds_text, colour_summary, colours_csv};
use anyhow::Context;
use skin_fit::{MeasuredOptions, ModelChoice, Parameter};
use skin_plot::{LineChart, Panel, Series, palette_color, save_png};
use std::fmt::Write as _;
use std::path::Path;

/// Which subset to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Subset {
    /// A quarter of the subjects (to look at).
    Explore,
    /// The other three quarters (to report).
    Heldout,
}

/// Fit `subset` (at most `limit` records, evenly spread) with the seed model and with `opts.model`
/// under `opts.geometry`; print the RMS statistics and write CSV and PNG into `out`.
pub fn run_measured(
    subset: Subset,
    limit: Option<usize>,
    opts: &MeasuredOptions,
    out: &Path,
) -> anyhow::Result<()> {
    let text = match subset {
        Subset::Explore => EXPLORE_CSV,
        Subset::Heldout => HELDOUT_CSV,
    };
    let mut records = parse_records(text)?;
    if let Some(n) = limit.filter(|&n| n > 0 && n < records.len()) {
        let stride = records.len() as f64 / n as f64;
        records = (0..n)
            .map(|i| records[(i as f64 * stride) as usize].clone())
            .collect();
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let name = match subset {
        Subset::Explore => "explore",
        Subset::Heldout => "heldout",
    };
    let seed_opts = MeasuredOptions {
        model: ModelChoice::Seed,
        ..*opts
    };
    let start = std::time::Instant::now();
    let seed = fit_records(&records, &seed_opts)?;
    let t_seed = start.elapsed().as_secs_f64();
    let start = std::time::Instant::now();
    let chosen = if opts.model == ModelChoice::Seed {
        seed.clone()
    } else {
        fit_records(&records, opts)?
    };
    let t_chosen = start.elapsed().as_secs_f64();
    let mut summary = String::new();
    for (label, fits, t) in [
        ("seed", &seed, t_seed),
        (&*opts.model.to_string(), &chosen, t_chosen),
    ] {
        let rms: Vec<f64> = fits.iter().map(|f| f.fit.rms).collect();
        let pinned = fits
            .iter()
            .filter(|f| {
                let b = f.fit.skin.eumelanin_blend();
                b <= 1e-3 || b >= 1.0 - 1e-3
            })
            .count();
        let cpu: Vec<f64> = fits.iter().map(|f| f.cpu_s).collect();
        writeln!(
            summary,
            "{name} {} geometry {} model {label}: {} spectra, RMS median {:.4}, p90 {:.4}, β_m at a bound {:.0} %, wall {:.1} s, thread CPU per fit median {:.2} s, max {:.2} s",
            opts.fit.method,
            opts.geometry,
            fits.len(),
            quantile(&rms, 0.5),
            quantile(&rms, 0.9),
            100.0 * pinned as f64 / fits.len().max(1) as f64,
            t,
            quantile(&cpu, 0.5),
            quantile(&cpu, 1.0)
        )?;
    }
    for (label, fits) in [("seed", &seed), (&*opts.model.to_string(), &chosen)] {
        writeln!(summary, "{}", colour_summary(label, fits)?)?;
        writeln!(summary, "{}", bounds_summary(label, fits))?;
    }
    if opts.model == ModelChoice::Auto {
        let mut counts: Vec<(Parameter, usize)> = Parameter::CANDIDATES
            .iter()
            .map(|&p| {
                (
                    p,
                    chosen
                        .iter()
                        .filter(|f| f.fit.parameters.contains(&p))
                        .count(),
                )
            })
            .collect();
        counts.sort_by_key(|c| std::cmp::Reverse(c.1));
        let text: Vec<String> = counts.iter().map(|(p, c)| format!("{p} {c}")).collect();
        writeln!(summary, "auto chose: {}", text.join(", "))?;
    }
    print!("{summary}");
    let tag = format!("{name}_{}_{}", opts.geometry, opts.model);
    write(out, &format!("summary_{tag}.txt"), &summary)?;
    write(out, &format!("fits_{tag}.csv"), &fits_csv(&seed, &chosen))?;
    write(
        out,
        &format!("colours_{tag}.csv"),
        &colours_csv(&seed, &chosen)?,
    )?;
    residual_chart(out, &tag, &seed, &chosen, &opts.model.to_string())?;
    parameter_chart(out, &tag, &chosen)?;
    Ok(())
}

fn write(out: &Path, file: &str, text: &str) -> anyhow::Result<()> {
    let path = out.join(file);
    skin_io::atomic::write_bytes(&path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))
}

/// Columns of the per-record CSV, after the labels.
const PARAMS: [Parameter; 11] = [
    Parameter::Melanin,
    Parameter::EumelaninBlend,
    Parameter::Hemoglobin,
    Parameter::Oiliness,
    Parameter::CANDIDATES[0],
    Parameter::CANDIDATES[1],
    Parameter::CANDIDATES[2],
    Parameter::CANDIDATES[3],
    Parameter::CANDIDATES[4],
    Parameter::CANDIDATES[5],
    Parameter::CANDIDATES[6],
];

fn fits_csv(seed: &[RecordFit], chosen: &[RecordFit]) -> String {
    let mut csv = String::from("record,group,site,seed_rms,rms,seed_cpu_s,cpu_s,free,at_bounds");
    for p in PARAMS {
        let _ = write!(csv, ",{p}");
    }
    csv.push('\n');
    for (s, c) in seed.iter().zip(chosen) {
        let free: Vec<&str> = c.fit.parameters.iter().map(|p| p.name()).collect();
        let _ = write!(
            csv,
            "{},{},{},{:.5},{:.5},{:.3},{:.3},{},{}",
            c.record.id,
            c.record.group,
            c.record.site,
            s.fit.rms,
            c.fit.rms,
            s.cpu_s,
            c.cpu_s,
            free.join(" "),
            bounds_text(c)
        );
        for p in PARAMS {
            let _ = write!(csv, ",{:.5}", p.get(&c.fit.skin));
        }
        csv.push('\n');
    }
    csv
}

fn residual_chart(
    out: &Path,
    tag: &str,
    seed: &[RecordFit],
    chosen: &[RecordFit],
    label: &str,
) -> anyhow::Result<()> {
    let mut csv = String::from(
        "wavelength_nm,seed_p10,seed_median,seed_p90,seed_mean,model_p10,model_median,model_p90,model_mean\n",
    );
    let (a, b) = (residual_bands(seed), residual_bands(chosen));
    for ((nm, s), (_, m)) in a.iter().zip(&b) {
        let _ = writeln!(
            csv,
            "{nm},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5},{:.5}",
            s[0], s[1], s[2], s[3], m[0], m[1], m[2], m[3]
        );
    }
    write(out, &format!("residuals_{tag}.csv"), &csv)?;
    let mut panel = LineChart::new(
        format!("Residual, model − measured ({tag})"),
        "wavelength (nm)",
        "reflectance residual",
    );
    for (k, (name, bands)) in [("seed", &a), (label, &b)].into_iter().enumerate() {
        let colour = palette_color(k);
        let pick = |j: usize| bands.iter().map(|(nm, v)| (*nm, v[j])).collect::<Vec<_>>();
        panel = panel
            .with_series(Series::line(format!("{name} median"), pick(1)).with_color(colour))
            .with_series(Series::dashed(format!("{name} p10"), pick(0)).with_color(colour))
            .with_series(Series::dashed(format!("{name} p90"), pick(2)).with_color(colour));
    }
    let path = out.join(format!("residuals_{tag}.png"));
    save_png(&path, &[Panel::Line(panel)], 900, 560)
        .with_context(|| format!("writing {}", path.display()))
}

fn parameter_chart(out: &Path, tag: &str, fits: &[RecordFit]) -> anyhow::Result<()> {
    let groups = ["CA", "CN", "JP", "TH", "SA", "IQ", "AB", "AF"];
    let mut csv = String::from("group,parameter,p10,median,p90,n\n");
    let mut panels = Vec::new();
    for p in PARAMS {
        let mut points = Vec::new();
        for (gi, g) in groups.iter().enumerate() {
            let v: Vec<f64> = fits
                .iter()
                .filter(|f| f.record.group == *g)
                .map(|f| p.get(&f.fit.skin))
                .collect();
            let (lo, med, hi) = (quantile(&v, 0.1), quantile(&v, 0.5), quantile(&v, 0.9));
            let _ = writeln!(csv, "{g},{p},{lo:.5},{med:.5},{hi:.5},{}", v.len());
            for x in v {
                points.push((gi as f64, x));
            }
        }
        let varies = points.iter().any(|&(_, x)| x != points[0].1);
        if varies {
            panels.push(Panel::Line(
                LineChart::new(
                    format!("{p} per group (0..7 = {})", groups.join(" ")),
                    "group",
                    p.name(),
                )
                .with_x_range(-0.5, 7.5)
                .with_series(Series::scatter(p.name(), points)),
            ));
        }
    }
    write(out, &format!("parameters_{tag}.csv"), &csv)?;
    let path = out.join(format!("parameters_{tag}.png"));
    let height = (260 * panels.len().max(1)) as u32;
    save_png(&path, &panels, 900, height).with_context(|| format!("writing {}", path.display()))
}
