//! The committed MCML reference of one case: means and standard errors over independent MCML runs.
//!
//! MCML reports no uncertainties, so each case is traced as several runs in one MCML process (one
//! `ran3` stream continued from run to run, so the runs are independent batches) and the standard
//! error of every quantity is sd(run values) / √runs, as for our Monte Carlo's batches.
//!
//! [`ReferenceData`] holds [`McmlOutput`]'s quantities with an `Estimate` in place of each number:
//! one is what a single run prints, the other the statistic over runs the tests compare against;
//! the specular term stays a plain number because it is deterministic.

use super::{McmlError, McmlOutput};
use crate::montecarlo::Estimate;
use std::fmt::Write as _;

/// MCML's reference for one case (all per incident photon; R_d(r) in mm⁻²).
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceData {
    /// Independent MCML runs (batches).
    pub runs: u32,
    /// Photons per run.
    pub photons_per_run: u64,
    /// Width of the annuli, mm.
    pub dr_mm: f64,
    /// Specular reflectance at entry (deterministic).
    pub specular: f64,
    /// Diffuse reflectance.
    pub diffuse_reflectance: Estimate,
    /// Absorbed fraction.
    pub absorbed: Estimate,
    /// Total transmittance.
    pub transmittance: Estimate,
    /// Absorbed fraction per layer, top first.
    pub absorbed_by_layer: Vec<Estimate>,
    /// R_d(r) per annulus of width `dr_mm` from r = 0, mm⁻²; the last holds all weight beyond it,
    /// divided by its own area (MCML's convention).
    pub rd_r_per_mm2: Vec<Estimate>,
}

/// Mean and standard error of one quantity over the runs.
fn over(runs: &[McmlOutput], f: impl Fn(&McmlOutput) -> f64 + Clone) -> Estimate {
    Estimate::from_batches(runs.iter().map(f))
}

impl ReferenceData {
    /// Combine `runs` (≥ 2 outputs of equal photon count and grid) of annuli `dr_mm` wide.
    pub fn from_runs(
        runs: &[McmlOutput],
        photons_per_run: u64,
        dr_mm: f64,
    ) -> Result<Self, McmlError> {
        let first = runs
            .first()
            .filter(|_| runs.len() >= 2)
            .ok_or_else(|| McmlError::Output("need at least 2 runs".into()))?;
        let (nr, nl) = (first.rd_r_per_mm2.len(), first.absorbed_by_layer.len());
        if runs
            .iter()
            .any(|r| r.rd_r_per_mm2.len() != nr || r.absorbed_by_layer.len() != nl)
        {
            return Err(McmlError::Output("runs on different grids".into()));
        }
        Ok(Self {
            runs: runs.len() as u32,
            photons_per_run,
            dr_mm,
            specular: first.specular,
            diffuse_reflectance: over(runs, |r| r.diffuse_reflectance),
            absorbed: over(runs, |r| r.absorbed),
            transmittance: over(runs, |r| r.transmittance),
            absorbed_by_layer: (0..nl)
                .map(|l| over(runs, move |r| r.absorbed_by_layer[l]))
                .collect(),
            rd_r_per_mm2: (0..nr)
                .map(|i| over(runs, move |r| r.rd_r_per_mm2[i]))
                .collect(),
        })
    }

    /// Photons traced in all runs.
    #[must_use]
    pub fn photons(&self) -> u64 {
        u64::from(self.runs) * self.photons_per_run
    }

    /// Area of annulus `i`, π((i + 1)² − i²) dr², mm² (MCML's 2π(i + ½)dr²).
    #[must_use]
    pub fn annulus_area_mm2(&self, i: usize) -> f64 {
        std::f64::consts::PI * (2 * i + 1) as f64 * self.dr_mm * self.dr_mm
    }

    /// The data as CSV (`quantity,index,mean,stderr`) under `header` comment lines.
    #[must_use]
    pub fn to_csv(&self, header: &str) -> String {
        let mut s = String::new();
        for line in header.lines() {
            let _ = writeln!(s, "# {line}");
        }
        let _ = writeln!(s, "quantity,index,mean,stderr");
        let _ = writeln!(s, "runs,,{},", self.runs);
        let _ = writeln!(s, "photons_per_run,,{},", self.photons_per_run);
        let _ = writeln!(s, "dr_mm,,{},", self.dr_mm);
        let _ = writeln!(s, "specular,,{:e},0", self.specular);
        let mut est = |name: &str, index: Option<usize>, e: &Estimate, digits: usize| {
            let i = index.map(|i| i.to_string()).unwrap_or_default();
            let _ = writeln!(s, "{name},{i},{:.digits$e},{:.2e}", e.mean, e.stderr);
        };
        est("rd", None, &self.diffuse_reflectance, 7);
        est("absorbed", None, &self.absorbed, 7);
        est("transmittance", None, &self.transmittance, 7);
        for (l, e) in self.absorbed_by_layer.iter().enumerate() {
            est("absorbed_layer", Some(l), e, 5);
        }
        for (i, e) in self.rd_r_per_mm2.iter().enumerate() {
            est("rd_r", Some(i), e, 5);
        }
        s
    }

    /// Read [`ReferenceData::to_csv`]'s format (comment lines start with `#`).
    pub fn parse(text: &str) -> Result<Self, McmlError> {
        let err = |line: usize, what: &str| McmlError::Reference {
            line,
            what: what.to_string(),
        };
        let (mut runs, mut photons, mut dr, mut specular) = (None, None, None, None);
        let (mut rd, mut a, mut tt) = (None, None, None);
        let (mut layers, mut annuli) = (Vec::new(), Vec::new());
        for (k, line) in text.lines().enumerate() {
            let n = k + 1;
            if line.starts_with('#') || line.trim().is_empty() || line.starts_with("quantity,") {
                continue;
            }
            let f: Vec<&str> = line.split(',').collect();
            let [name, index, mean, stderr] = f[..] else {
                return Err(err(n, "expected 4 fields"));
            };
            let num = |s: &str| s.parse::<f64>().map_err(|_| err(n, "not a number"));
            let value = num(mean)?;
            let estimate = || -> Result<Estimate, McmlError> {
                Ok(Estimate {
                    mean: value,
                    stderr: num(stderr)?,
                })
            };
            let push = |v: &mut Vec<Estimate>, e: Estimate| {
                (index.parse::<usize>().ok() == Some(v.len()))
                    .then(|| v.push(e))
                    .ok_or_else(|| err(n, "index out of order"))
            };
            match name {
                "runs" => runs = Some(value as u32),
                "photons_per_run" => photons = Some(value as u64),
                "dr_mm" => dr = Some(value),
                "specular" => specular = Some(value),
                "rd" => rd = Some(estimate()?),
                "absorbed" => a = Some(estimate()?),
                "transmittance" => tt = Some(estimate()?),
                "absorbed_layer" => push(&mut layers, estimate()?)?,
                "rd_r" => push(&mut annuli, estimate()?)?,
                _ => return Err(err(n, "unknown quantity")),
            }
        }
        let missing = |what: &str| err(0, &format!("missing {what}"));
        if annuli.is_empty() {
            return Err(missing("rd_r"));
        }
        Ok(Self {
            runs: runs.ok_or_else(|| missing("runs"))?,
            photons_per_run: photons.ok_or_else(|| missing("photons_per_run"))?,
            dr_mm: dr.ok_or_else(|| missing("dr_mm"))?,
            specular: specular.ok_or_else(|| missing("specular"))?,
            diffuse_reflectance: rd.ok_or_else(|| missing("rd"))?,
            absorbed: a.ok_or_else(|| missing("absorbed"))?,
            transmittance: tt.ok_or_else(|| missing("transmittance"))?,
            absorbed_by_layer: layers,
            rd_r_per_mm2: annuli,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn output(rd: f64) -> McmlOutput {
        McmlOutput {
            specular: 0.0277778,
            diffuse_reflectance: rd,
            absorbed: 1.0 - 0.0277778 - rd,
            transmittance: 0.0,
            absorbed_by_layer: vec![0.1, 1.0 - 0.1 - 0.0277778 - rd],
            rd_r_per_mm2: vec![rd, rd / 2.0, rd / 4.0],
        }
    }

    #[test]
    fn run_statistics_survive_the_csv() {
        let d = ReferenceData::from_runs(&[output(0.4), output(0.5)], 1000, 0.01).unwrap();
        assert!((d.diffuse_reflectance.mean - 0.45).abs() < 1e-15);
        // sd of {0.4, 0.5} = 0.0707, over √2: 0.05.
        assert!((d.diffuse_reflectance.stderr - 0.05).abs() < 1e-15);
        let back = ReferenceData::parse(&d.to_csv("a header\nof two lines")).unwrap();
        assert_eq!(back.runs, 2);
        assert_eq!(back.photons(), 2000);
        assert_eq!(back.rd_r_per_mm2.len(), 3);
        assert!((back.rd_r_per_mm2[1].mean - 0.225).abs() < 1e-9);
        assert!((back.diffuse_reflectance.stderr - 0.05).abs() < 1e-9);
        assert!((back.annulus_area_mm2(1) - 3.0 * std::f64::consts::PI * 1e-4).abs() < 1e-15);
    }

    #[test]
    fn malformed_data_names_the_line() {
        let e = ReferenceData::parse("quantity,index,mean,stderr\nrd_r,1,0.1,0.01\n").unwrap_err();
        assert!(e.to_string().contains("line 2"), "{e}");
        assert!(ReferenceData::parse("runs,,x,\n").is_err());
        assert!(ReferenceData::from_runs(&[output(0.4)], 1000, 0.01).is_err());
    }
}
