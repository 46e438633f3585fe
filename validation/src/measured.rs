//! Fits to individual measured skin spectra (the ISSA subsets in `validation/data/`) and the
//! statistics of their residuals (docs/physics.md §13).
//!
//! The two subsets split the archive's subjects by a hash (`issa_explore.csv`, a quarter of the
//! subjects, to look at; `issa_heldout.csv`, the other three quarters, to report): the numbers a
//! reader should quote are the held-out ones.

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use skin_fit::{FitError, MeasuredFit, MeasuredOptions, MeasuredSpectrum, fit_measured};

/// The exploration subset (a quarter of the subjects), CSV text.
pub const EXPLORE_CSV: &str = include_str!("../data/issa_explore.csv");
/// The held-out subset (the other subjects), CSV text.
pub const HELDOUT_CSV: &str = include_str!("../data/issa_heldout.csv");

/// One measured spectrum with its labels.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// ISSA record number.
    pub id: u32,
    /// Group code (CA, CN, JP, TH, SA, IQ, AB, AF).
    pub group: String,
    /// Body site (forehead, cheek, inner_arm).
    pub site: String,
    /// The spectrum (SCI reflectance at 400–700 nm every 10 nm).
    pub spectrum: MeasuredSpectrum,
}

/// Errors reading a subset.
#[derive(Debug, thiserror::Error)]
pub enum MeasuredError {
    /// A malformed line (line number, 1-based).
    #[error("line {0}: {1}")]
    Line(usize, String),
    /// A spectrum the fit rejects.
    #[error(transparent)]
    Fit(#[from] FitError),
}

/// Parse a subset CSV: `#` comments, a header `record,origin,subject,group_code,site,r400,…`,
/// then one record per line.
pub fn parse_records(text: &str) -> Result<Vec<Record>, MeasuredError> {
    let mut lambdas: Option<Vec<f64>> = None;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        let Some(lambda) = &lambdas else {
            let nm = fields
                .iter()
                .skip(5)
                .map(|f| f.trim_start_matches('r').parse::<f64>())
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| MeasuredError::Line(i + 1, format!("header: {e}")))?;
            lambdas = Some(nm);
            continue;
        };
        if fields.len() != 5 + lambda.len() {
            return Err(MeasuredError::Line(i + 1, "wrong number of fields".into()));
        }
        let id = fields[0]
            .parse()
            .map_err(|e| MeasuredError::Line(i + 1, format!("record: {e}")))?;
        let r = fields[5..]
            .iter()
            .map(|f| f.parse::<f64>())
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| MeasuredError::Line(i + 1, format!("reflectance: {e}")))?;
        out.push(Record {
            id,
            group: fields[3].to_string(),
            site: fields[4].to_string(),
            spectrum: MeasuredSpectrum::new(lambda.clone(), r, None)?,
        });
    }
    Ok(out)
}

/// One record's fit.
#[derive(Debug, Clone)]
pub struct RecordFit {
    /// The record.
    pub record: Record,
    /// Its fit.
    pub fit: MeasuredFit,
    /// CPU time of the fit on the thread that ran it, s (one core's cost when rayon runs one
    /// thread, `RAYON_NUM_THREADS=1`; with more threads the nested per-wavelength work spreads).
    pub cpu_s: f64,
}

/// A progress bar on stderr for `len` fits, labelled `msg`.
#[must_use]
pub fn progress(len: usize, msg: String) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    if let Ok(style) = ProgressStyle::with_template("{msg} {bar:40} {pos}/{len} [{elapsed}<{eta}]")
    {
        bar.set_style(style);
    }
    bar.set_message(msg);
    bar
}

/// Fit every record (rayon across records, with a progress bar on stderr).
pub fn fit_records(records: &[Record], opts: &MeasuredOptions) -> Result<Vec<RecordFit>, FitError> {
    let bar = progress(
        records.len(),
        format!("fit {} {}", opts.geometry, opts.model),
    );
    let fits = records
        .par_iter()
        .map(|r| {
            let cpu = cpu_time::ThreadTime::now();
            let fit = fit_measured(&r.spectrum, opts);
            let cpu_s = cpu.elapsed().as_secs_f64();
            bar.inc(1);
            fit.map(|fit| RecordFit {
                record: r.clone(),
                fit,
                cpu_s,
            })
        })
        .collect::<Result<Vec<_>, _>>();
    bar.finish_and_clear();
    fits
}

/// The `q`-quantile (0–1) of `values` by linear interpolation between order statistics.
#[must_use]
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let x = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let i = x.floor() as usize;
    let j = (i + 1).min(v.len() - 1);
    v[i] + (x - i as f64) * (v[j] - v[i])
}

/// Residual statistics per wavelength (model − measurement): p10, median, p90 and mean.
#[must_use]
pub fn residual_bands(fits: &[RecordFit]) -> Vec<(f64, [f64; 4])> {
    let Some(first) = fits.first() else {
        return Vec::new();
    };
    let lambdas = first.record.spectrum.lambda_nm().to_vec();
    lambdas
        .iter()
        .enumerate()
        .map(|(i, &nm)| {
            let d: Vec<f64> = fits
                .iter()
                .map(|f| f.fit.model[i] - f.record.spectrum.reflectance()[i])
                .collect();
            let mean = d.iter().sum::<f64>() / d.len() as f64;
            (
                nm,
                [
                    quantile(&d, 0.1),
                    quantile(&d, 0.5),
                    quantile(&d, 0.9),
                    mean,
                ],
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subsets_parse_and_hold_disjoint_records() {
        let a = parse_records(EXPLORE_CSV).unwrap();
        let b = parse_records(HELDOUT_CSV).unwrap();
        assert_eq!((a.len(), b.len()), (141, 288));
        assert!(a.iter().all(|r| r.spectrum.len() == 31));
        assert!(a.iter().all(|r| b.iter().all(|s| s.id != r.id)));
    }

    #[test]
    fn quantiles_interpolate() {
        let v = [3.0, 1.0, 2.0, 4.0];
        assert_eq!(quantile(&v, 0.5), 2.5);
        assert_eq!(quantile(&v, 0.0), 1.0);
        assert_eq!(quantile(&v, 1.0), 4.0);
    }
}
