//! Our Monte Carlo against an MCML reference, quantity by quantity, as z-scores from both codes'
//! batch errors (the derivation of the tolerance applied to them is in the tests that use it).

use super::{Case, DR_MM, NR, ReferenceData, mcml_binned};
use crate::montecarlo::{Estimate, McOptions, McResult, RadialGrid, run};
use rayon::prelude::*;
use std::ops::Range;

/// Outer edges (annulus index, exclusive) of the radial groups before merging: radii 0.01, 0.02,
/// 0.03, 0.05, …, 7, 9.99 mm, and MCML's overflow annulus (9.99 mm on) alone.
pub const GROUP_EDGES: [usize; 19] = [
    1, 2, 3, 5, 7, 10, 15, 20, 30, 50, 70, 100, 150, 200, 300, 500, 700, 999, 1000,
];

/// One compared quantity.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// What it is (`R_d`, `A`, `A layer 0`, `E[a, b) mm`: R_d(r) integrated over annuli).
    pub quantity: String,
    /// Ours: mean and batch standard error.
    pub ours: Estimate,
    /// MCML's.
    pub mcml: Estimate,
    /// (ours − MCML) / √(σ_ours² + σ_MCML²), after forgiving MCML's print rounding.
    pub z: f64,
}

/// The comparison of one case.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Every compared quantity.
    pub rows: Vec<Row>,
    /// Total transmittance of ours (mean); compared as a bound, having no usable error.
    pub our_transmittance: f64,
    /// Annulus ranges of the radial groups.
    pub groups: Vec<Range<usize>>,
}

impl Comparison {
    /// Largest |z|.
    #[must_use]
    pub fn max_abs_z(&self) -> f64 {
        self.rows.iter().map(|r| r.z.abs()).fold(0.0, f64::max)
    }
    /// Mean of z² (≈ 1 for two unbiased codes with correct errors).
    #[must_use]
    pub fn mean_z2(&self) -> f64 {
        self.rows.iter().map(|r| r.z * r.z).sum::<f64>() / self.rows.len() as f64
    }
    /// The rows as an aligned text table.
    #[must_use]
    pub fn table(&self) -> String {
        self.rows
            .iter()
            .map(|r| {
                format!(
                    "  {:<22} ours {:.5e} ± {:.1e}  MCML {:.5e} ± {:.1e}  z {:+.2}\n",
                    r.quantity, r.ours.mean, r.ours.stderr, r.mcml.mean, r.mcml.stderr, r.z
                )
            })
            .collect()
    }
}

/// Groups of [`GROUP_EDGES`] merged outwards until each holds at least `min_escapes` photons of a
/// run of `photons` by `reference`'s profile; a short remainder joins the last group.
#[must_use]
pub fn groups(reference: &ReferenceData, photons: f64, min_escapes: f64) -> Vec<Range<usize>> {
    let energy = |a: usize, b: usize| -> f64 {
        (a..b)
            .map(|i| reference.rd_r_per_mm2[i].mean * reference.annulus_area_mm2(i))
            .sum()
    };
    let mut out: Vec<Range<usize>> = Vec::new();
    let mut start = 0;
    for &end in &GROUP_EDGES {
        if energy(start, end) * photons >= min_escapes {
            out.push(start..end);
            start = end;
        }
    }
    if let Some(last) = out.last_mut() {
        last.end = NR;
    }
    out
}

/// Trace `case` as `runs` independent runs (seeds `seed`, `seed + 1`, …) of `photons_per_run` on
/// MCML's grid and compare R_d, A, A per layer and R_d(r) in [`groups`] of at least `min_escapes`
/// with `reference`. Our errors are the spread of the runs (group sums taken per run); MCML's group
/// errors add its annuli's in quadrature (an overstatement: one photon escapes in one annulus only,
/// so the annuli of a run are negatively correlated). A_l has `layer_slack` (relative) of its value
/// forgiven before the z-score: at least 5·10⁻⁴, MCML's print rounding to 4 significant digits.
pub fn compare(
    case: &Case,
    reference: &ReferenceData,
    runs: u64,
    photons_per_run: u64,
    seed: u64,
    min_escapes: f64,
    layer_slack: f64,
) -> Result<Comparison, super::McmlError> {
    let grid = RadialGrid::new(DR_MM, NR)?;
    let results = (0..runs)
        .into_par_iter()
        .map(|k| {
            Ok(run(
                &case.stack,
                &McOptions::new(photons_per_run, 2, seed + k)?.with_grid(grid),
            ))
        })
        .collect::<Result<Vec<McResult>, super::McmlError>>()?;
    let mut rows = Vec::new();
    let mut push = |quantity: String, ours: Estimate, mcml: Estimate, slack: f64| {
        let d = ours.mean - mcml.mean;
        let z = (d.abs() - slack).max(0.0).copysign(d) / ours.stderr.hypot(mcml.stderr);
        rows.push(Row {
            quantity,
            ours,
            mcml,
            z,
        });
    };
    let ours = |f: &dyn Fn(&McResult) -> f64| Estimate::from_batches(results.iter().map(f));
    push(
        "R_d".into(),
        ours(&|r| r.diffuse_reflectance.mean),
        reference.diffuse_reflectance,
        0.0,
    );
    push(
        "A".into(),
        ours(&|r| r.absorbed.mean),
        reference.absorbed,
        0.0,
    );
    for (l, m) in reference.absorbed_by_layer.iter().enumerate() {
        push(
            format!("A layer {l}"),
            ours(&|r| r.absorbed_by_layer[l]),
            *m,
            layer_slack.max(5e-4) * m.mean,
        );
    }
    let binned: Vec<Vec<f64>> = results
        .iter()
        .map(|r| mcml_binned(r).expect("uniform grid"))
        .collect();
    let groups = groups(reference, (photons_per_run * runs) as f64, min_escapes);
    for g in &groups {
        let energy = |v: &dyn Fn(usize) -> f64| -> f64 {
            g.clone()
                .map(|i| v(i) * reference.annulus_area_mm2(i))
                .sum()
        };
        let var: f64 = g
            .clone()
            .map(|i| (reference.rd_r_per_mm2[i].stderr * reference.annulus_area_mm2(i)).powi(2))
            .sum();
        let mcml = Estimate {
            mean: energy(&|i| reference.rd_r_per_mm2[i].mean),
            stderr: var.sqrt(),
        };
        let (a, b) = (g.start as f64 * DR_MM, g.end as f64 * DR_MM);
        push(
            format!("E[{a:.2}, {b:.2}) mm"),
            Estimate::from_batches(binned.iter().map(|v| energy(&|i| v[i]))),
            mcml,
            0.0,
        );
    }
    Ok(Comparison {
        rows,
        our_transmittance: ours(&|r| r.transmittance.mean).mean,
        groups,
    })
}
