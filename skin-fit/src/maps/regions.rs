//! β_m per region of the texture, with a smoothness prior between neighbouring regions
//! (docs/physics.md §18, "β_m per region").
//!
//! The texture is cut into square regions of `block` texels a side. For each region and each
//! β_m candidate, up to [`REGION_SAMPLES`] of its fitted texels are inverted on the candidate's
//! slice and scored by the sum of their squared ΔE2000 (each capped at [`super::BETA_CAP_DE`]).
//! The labels minimise the sum of the scores plus `smoothness` (ΔE², per unit β_m squared) times
//! the squared β_m difference of every pair of edge neighbours, by iterated conditional modes from
//! each region's own best (at most [`MAX_SWEEPS`] sweeps). Every texel is then fitted on its
//! region's slice. Each region's own allowed range (where its RMS stays within the tolerance of
//! its best, as for one β_m) measures what the data pin; the summary reports their median width.

use super::{BETA_CAP_DE, FittedRange, Inverter, MapsError, best_on_grid, delta_e_2000_fast};
use super::{scaled, texel_lab, unscaled};
use rayon::prelude::*;

/// Texels of a region scored per candidate (evenly spread over its fitted texels).
pub const REGION_SAMPLES: usize = 64;
/// Most sweeps of iterated conditional modes.
const MAX_SWEEPS: usize = 50;

/// How β_m varies over the texture: one value per square region of `block` texels a side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Regions {
    /// Texels per row of the texture, ≥ 1 (the texel count must be a multiple).
    pub width: usize,
    /// Texels per side of a region, in [4, 4096].
    pub block: usize,
    /// Prior charge of a β_m step between neighbouring regions, ΔE² per unit β_m squared, ≥ 0
    /// (default [`DEFAULT_SMOOTHNESS`]: a step of 0.1 costs as much as one sampled texel 1 ΔE2000
    /// worse).
    pub smoothness: f64,
}

/// The default [`Regions::smoothness`], ΔE² per unit β_m squared.
pub const DEFAULT_SMOOTHNESS: f64 = 100.0;

/// What the regions found, for the summary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegionSummary {
    /// Regions with fitted texels.
    pub regions: usize,
    /// Lowest, median and highest β_m over those regions.
    pub min: f64,
    /// Median β_m over the regions.
    pub median: f64,
    /// Highest β_m over the regions.
    pub max: f64,
    /// Median over the regions of the width of the β_m range each region's texels allow.
    pub median_allowed_width: f64,
}

/// Per-region β_m labels of a texture.
pub(super) struct RegionFit {
    /// Candidate β_m of each texel's region (index into `betas`), per texel.
    pub label_of_texel: Vec<u8>,
    /// The candidates.
    pub betas: Vec<f64>,
    pub summary: RegionSummary,
}

/// Fit the regions' β_m (module doc) on the slices of `inverters` (one per candidate of `betas`).
pub(super) fn fit_regions(
    texels: &[[f32; 3]],
    fitted: &[bool],
    regions: Regions,
    betas: &[f64],
    inverters: &[Inverter],
    gain: [f64; 3],
    tolerance_de: f64,
) -> Result<RegionFit, MapsError> {
    let n = texels.len();
    let w = regions.width;
    if w == 0 || !n.is_multiple_of(w) {
        return Err(MapsError::Option {
            name: "eumelanin regions width",
            value: w as f64,
            range: "a divisor of the texel count",
        });
    }
    let h = n / w;
    let b = regions.block;
    let (nx, ny) = (w.div_ceil(b), h.div_ceil(b));
    let g = gain.map(|x| x as f32);
    // Squared capped ΔE2000 summed over each region's sample, per candidate.
    let scores: Vec<(Vec<f64>, bool)> = (0..nx * ny)
        .into_par_iter()
        .map(|r| {
            let (rx, ry) = (r % nx, r / nx);
            let members: Vec<usize> = (ry * b..((ry + 1) * b).min(h))
                .flat_map(|y| (rx * b..((rx + 1) * b).min(w)).map(move |x| y * w + x))
                .filter(|&k| fitted[k])
                .collect();
            if members.is_empty() {
                return (vec![0.0; betas.len()], false);
            }
            let count = members.len().min(REGION_SAMPLES);
            let sample: Vec<[f32; 3]> = (0..count)
                .map(|i| texels[members[i * members.len() / count]])
                .collect();
            let score = inverters
                .iter()
                .map(|inv| {
                    sample
                        .iter()
                        .map(|t| {
                            let r = inv.invert(&texel_lab(scaled(*t, g)).0);
                            let fit = if gain == [1.0; 3] {
                                r.lab
                            } else {
                                unscaled(&r.lab, gain)
                            };
                            delta_e_2000_fast(&texel_lab(*t).0, &fit)
                                .min(BETA_CAP_DE)
                                .powi(2)
                        })
                        .sum::<f64>()
                })
                .collect();
            (score, true)
        })
        .collect();
    let argmin = |v: &[f64]| {
        (0..v.len())
            .min_by(|&a, &c| v[a].total_cmp(&v[c]))
            .unwrap_or(0)
    };
    let mut labels: Vec<usize> = scores.iter().map(|(s, _)| argmin(s)).collect();
    // Regions without fitted texels start from the median label of the others.
    let mut own: Vec<usize> = (0..labels.len())
        .filter(|&r| scores[r].1)
        .map(|r| labels[r])
        .collect();
    own.sort_unstable();
    let middle = own.get(own.len() / 2).copied().unwrap_or(betas.len() / 2);
    for (r, l) in labels.iter_mut().enumerate() {
        if !scores[r].1 {
            *l = middle;
        }
    }
    let neighbours = |r: usize| {
        let (rx, ry) = (r % nx, r / nx);
        [
            (rx > 0).then(|| r - 1),
            (rx + 1 < nx).then(|| r + 1),
            (ry > 0).then(|| r - nx),
            (ry + 1 < ny).then(|| r + nx),
        ]
    };
    for _ in 0..MAX_SWEEPS {
        let mut changed = false;
        for r in 0..labels.len() {
            let cost = |l: usize| {
                scores[r].0[l]
                    + neighbours(r)
                        .iter()
                        .flatten()
                        .map(|&q| regions.smoothness * (betas[l] - betas[labels[q]]).powi(2))
                        .sum::<f64>()
            };
            let best = (0..betas.len())
                .min_by(|&a, &c| cost(a).total_cmp(&cost(c)))
                .unwrap_or(labels[r]);
            if cost(best) < cost(labels[r]) {
                labels[r] = best;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    let fitted_regions: Vec<usize> = (0..labels.len()).filter(|&r| scores[r].1).collect();
    let mut values: Vec<f64> = fitted_regions.iter().map(|&r| betas[labels[r]]).collect();
    values.sort_by(f64::total_cmp);
    let mut widths: Vec<f64> = fitted_regions
        .iter()
        .map(|&r| {
            let samples = sample_count(r, nx, b, w, h, fitted);
            let rms: Vec<f64> = scores[r]
                .0
                .iter()
                .map(|s| (s / samples.max(1) as f64).sqrt())
                .collect();
            let (_, range): (f64, FittedRange) = best_on_grid(betas, &rms, tolerance_de);
            range.max - range.min
        })
        .collect();
    widths.sort_by(f64::total_cmp);
    let mid = |v: &[f64]| v.get(v.len() / 2).copied().unwrap_or(0.0);
    let label_of_texel = (0..n)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            labels[(y / b) * nx + x / b] as u8
        })
        .collect();
    Ok(RegionFit {
        label_of_texel,
        betas: betas.to_vec(),
        summary: RegionSummary {
            regions: fitted_regions.len(),
            min: values.first().copied().unwrap_or(0.6),
            median: mid(&values),
            max: values.last().copied().unwrap_or(0.6),
            median_allowed_width: mid(&widths),
        },
    })
}

/// Texels scored in region `r` (its fitted texels, at most [`REGION_SAMPLES`]).
fn sample_count(r: usize, nx: usize, b: usize, w: usize, h: usize, fitted: &[bool]) -> usize {
    let (rx, ry) = (r % nx, r / nx);
    let members = (ry * b..((ry + 1) * b).min(h))
        .flat_map(|y| (rx * b..((rx + 1) * b).min(w)).map(move |x| y * w + x))
        .filter(|&k| fitted[k])
        .count();
    members.min(REGION_SAMPLES)
}
