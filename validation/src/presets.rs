//! Measured presets: the ISSA group/site median spectra (SCI) fitted with `--model auto`, written
//! as the table `skin_optics::measured` embeds (docs/physics.md §13).

use crate::measured_colour::lab_of;
use anyhow::Context;
use rayon::prelude::*;
use skin_fit::{
    ColourModel, Geometry, MeasuredOptions, MeasuredSpectrum, ModelChoice, fit_measured,
};
use std::fmt::Write as _;
use std::path::Path;

/// The ISSA summary (p10/median/p90 per group, site and wavelength), as embedded in skin-optics.
const SUMMARY_CSV: &str = include_str!("../../skin-optics/data/skin_reflectance_issa_summary.csv");

/// One group/site row of the summary: labels, record count, median spectrum.
struct Row {
    code: String,
    site: String,
    n: u32,
    lambda: Vec<f64>,
    median: Vec<f64>,
}

fn rows() -> anyhow::Result<Vec<Row>> {
    let mut out: Vec<Row> = Vec::new();
    for (i, line) in SUMMARY_CSV.lines().enumerate() {
        if line.starts_with('#') || line.starts_with("group_code") || line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split(',').collect();
        anyhow::ensure!(f.len() == 8, "summary line {}: {} fields", i + 1, f.len());
        let (nm, med): (f64, f64) = (f[4].parse()?, f[6].parse()?);
        match out.last_mut() {
            Some(r) if r.code == f[0] && r.site == f[2] => {
                r.lambda.push(nm);
                r.median.push(med);
            }
            _ => out.push(Row {
                code: f[0].to_string(),
                site: f[2].to_string(),
                n: f[3].parse()?,
                lambda: vec![nm],
                median: vec![med],
            }),
        }
    }
    Ok(out)
}

/// Fit every median and write the preset table to `path`; returns one line per preset.
pub fn run_presets(noise: f64, path: &Path) -> anyhow::Result<String> {
    let opts = MeasuredOptions {
        geometry: Geometry::Sci,
        model: ModelChoice::Auto,
        noise,
        ..MeasuredOptions::default()
    };
    let rows = rows()?;
    let fits = rows
        .par_iter()
        .map(|r| {
            let m = MeasuredSpectrum::new(r.lambda.clone(), r.median.clone(), None)?;
            fit_measured(&m, &opts)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut report = String::new();
    let mut csv = String::from(
        "# Measured skin presets: the ISSA group/site median SCI spectra (skin_reflectance_issa_summary.csv; ISSA, Lu et al., Scientific Data 2025, CC BY 4.0) fitted by `skin-validate presets` (geometry sci, model auto, exact forward model).\n",
    );
    let _ = writeln!(
        csv,
        "# Criterion noise sigma {noise}. Colour: the fitted skin's diffuse (SCE) reflectance under D65, 400-700 nm at 10 nm. Regenerate with `cargo run --release -p validation --bin skin-validate -- presets`."
    );
    csv.push_str("name,group_code,site,n_records,melanin,eumelanin_blend,hemoglobin,oiliness,oxygenation,epidermis_thickness_mm,dermis_scattering_scale,epidermis_blood,bilirubin_g_per_l,mie_scale,rayleigh_scale,rms,l,a,b,at_bounds\n");
    for (r, f) in rows.iter().zip(&fits) {
        let s = f.skin;
        let x = s.physiology();
        let lab = ColourModel::new(10.0, opts.fit.method, s)?.lab(&s)?;
        let bounds: Vec<String> = f
            .at_bounds()
            .iter()
            .map(|(p, b)| format!("{p}={b}"))
            .collect();
        let bounds = bounds.join(" ");
        // Both as the instrument sees them (SCI), the median spectrum's and the fit's.
        let de = lab_of(&r.lambda, &r.median)?.delta_e_2000(lab_of(&r.lambda, &f.model)?);
        let name = format!("{}-{}", r.code.to_lowercase(), r.site.replace('_', "-"));
        let _ = writeln!(
            csv,
            "{name},{},{},{},{:.5},{:.4},{:.5},{:.4},{:.4},{:.4},{:.4},{:.5},{:.5},{:.4},{:.4},{:.5},{:.2},{:.2},{:.2},{}",
            r.code,
            r.site,
            r.n,
            s.melanin(),
            s.eumelanin_blend(),
            s.hemoglobin(),
            s.oiliness(),
            s.oxygenation(),
            s.epidermis_thickness_mm(),
            s.dermis_scattering_scale(),
            x.get(skin_optics::Extension::EpidermisBlood),
            x.get(skin_optics::Extension::Bilirubin),
            x.get(skin_optics::Extension::MieScale),
            x.get(skin_optics::Extension::RayleighScale),
            f.rms,
            lab.l,
            lab.a,
            lab.b,
            bounds
        );
        let free: Vec<&str> = f.parameters.iter().skip(4).map(|p| p.name()).collect();
        let _ = writeln!(
            report,
            "{name:<18} RMS {:.4} (seed {:.4})  ΔE2000 to the median {de:.2}  L*a*b* ({:.1}, {:.1}, {:.1})  ITA° {:.1}  added: {}  on a bound: {}",
            f.rms,
            f.seed_rms,
            lab.l,
            lab.a,
            lab.b,
            lab.ita_deg(),
            free.join(", "),
            if bounds.is_empty() { "none" } else { &bounds }
        );
    }
    skin_io::atomic::write_bytes(path, csv.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(report)
}
