//! `skin-validate mean-colours`: the model fitted to the mean skin colours of the measured subset
//! (docs/physics.md §13.4). Per group and site, the mean CIELAB (D65, CIE 1931 2°) of its SCI
//! spectra — the figure a study of skin colour publishes — is fitted as a colour target with each
//! model under the SCI geometry (`skin_fit::fit_measured_colour`), which measures whether
//! the model's gamut reaches the measured colours.

use crate::measured::{EXPLORE_CSV, HELDOUT_CSV, Record, parse_records, progress, quantile};
use crate::measured_colour::{lab_of, mean_lab};
use crate::measured_report::Subset;
use anyhow::Context;
use rayon::prelude::*;
use skin_fit::{MeasuredColourFit, MeasuredOptions, ModelChoice, fit_measured_colour};
use skin_optics::lab::Lab;
use std::fmt::Write as _;
use std::path::Path;

/// One group/site: its label, record count and mean measured colour.
#[derive(Debug, Clone, PartialEq)]
pub struct MeanColour {
    /// "GROUP site".
    pub key: String,
    /// Records averaged.
    pub n: usize,
    /// Mean CIELAB of the records' spectra.
    pub lab: Lab,
}

/// Mean colour of each group/site in `records`, in the order first met.
pub fn mean_colours(records: &[Record]) -> anyhow::Result<Vec<MeanColour>> {
    let mut keys: Vec<String> = Vec::new();
    for r in records {
        let k = format!("{} {}", r.group, r.site);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|key| {
            let labs = records
                .iter()
                .filter(|r| format!("{} {}", r.group, r.site) == key)
                .map(|r| lab_of(r.spectrum.lambda_nm(), r.spectrum.reflectance()))
                .collect::<anyhow::Result<Vec<Lab>>>()?;
            Ok(MeanColour {
                key,
                n: labs.len(),
                lab: mean_lab(labs.into_iter()),
            })
        })
        .collect()
}

/// Fit every mean colour of `subset` with each of `models` (options `opts`, its model replaced);
/// print a summary and write `mean_colours_{set}_{geometry}.csv` and its summary into `out`.
pub fn run_mean_colours(
    subset: Subset,
    models: &[ModelChoice],
    opts: &MeasuredOptions,
    out: &Path,
) -> anyhow::Result<()> {
    let (text, name) = match subset {
        Subset::Explore => (EXPLORE_CSV, "explore"),
        Subset::Heldout => (HELDOUT_CSV, "heldout"),
    };
    let targets = mean_colours(&parse_records(text)?)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut fits: Vec<Vec<(MeasuredColourFit, f64)>> = Vec::new();
    let mut summary = String::new();
    for &model in models {
        let o = MeasuredOptions { model, ..*opts };
        let bar = progress(targets.len(), format!("colour fit {} {model}", o.geometry));
        let f = targets
            .par_iter()
            .map(|t| {
                let cpu = cpu_time::ThreadTime::now();
                let fit = fit_measured_colour(t.lab, &o);
                bar.inc(1);
                fit.map(|fit| (fit, cpu.elapsed().as_secs_f64()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        bar.finish_and_clear();
        let de: Vec<f64> = f.iter().map(|(x, _)| x.delta_e).collect();
        let cpu: Vec<f64> = f.iter().map(|(_, c)| *c).collect();
        let sigma: Vec<f64> = f.iter().map(|(x, _)| x.noise_delta_e).collect();
        writeln!(
            summary,
            "{name} {} geometry {} colour model {model}: {} group/site mean colours, ΔE2000 median {:.2}, max {:.2}, ≤ 1.0 in {}/{}; σ_c {:.2}–{:.2}; thread CPU per fit median {:.2} s, max {:.2} s",
            o.fit.method,
            o.geometry,
            f.len(),
            quantile(&de, 0.5),
            quantile(&de, 1.0),
            de.iter().filter(|&&d| d <= 1.0).count(),
            de.len(),
            quantile(&sigma, 0.0),
            quantile(&sigma, 1.0),
            quantile(&cpu, 0.5),
            quantile(&cpu, 1.0),
        )?;
        fits.push(f);
    }
    print!("{summary}");
    let mut csv = String::from("group_site,n,measured_l,measured_a,measured_b");
    for m in models {
        let _ = write!(csv, ",{m}_de2000,{m}_l,{m}_a,{m}_b,{m}_free,{m}_cpu_s");
    }
    csv.push('\n');
    for (i, t) in targets.iter().enumerate() {
        let _ = write!(
            csv,
            "{},{},{:.3},{:.3},{:.3}",
            t.key, t.n, t.lab.l, t.lab.a, t.lab.b
        );
        for f in &fits {
            let (x, cpu) = &f[i];
            let free: Vec<&str> = x.parameters.iter().map(|p| p.name()).collect();
            let _ = write!(
                csv,
                ",{:.3},{:.3},{:.3},{:.3},{},{:.3}",
                x.delta_e,
                x.lab.l,
                x.lab.a,
                x.lab.b,
                free.join(" "),
                cpu
            );
        }
        csv.push('\n');
    }
    let tag = format!("{name}_{}", opts.geometry);
    for (file, body) in [
        (format!("mean_colours_{tag}.csv"), &csv),
        (format!("summary_mean_colours_{tag}.txt"), &summary),
    ] {
        let path = out.join(file);
        skin_io::atomic::write_bytes(&path, body.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 24 group/site means on the held-out set, each over its 12 records, within the range of
    /// measured skin (L* 30–75, a* and b* positive).
    #[test]
    fn held_out_means_cover_every_group_and_site() {
        let m = mean_colours(&parse_records(HELDOUT_CSV).unwrap()).unwrap();
        assert_eq!(m.len(), 24);
        for c in &m {
            assert_eq!(c.n, 12, "{}", c.key);
            assert!(
                (30.0..75.0).contains(&c.lab.l) && c.lab.a > 0.0 && c.lab.b > 0.0,
                "{c:?}"
            );
        }
    }
}
