//! The extended parameters of `skin fit --model` in the maps: one value per texture each, fitted
//! over a sample of the texels (docs/physics.md §18, "Extended parameters").
//!
//! Three colour numbers per texel already go to C_m and C_h, so a parameter beyond them can only
//! be read from the texture as a whole, as β_m is. Each free parameter in turn is set to
//! [`EXTENDED_STEPS`] values evenly over its fit range ([`Parameter::range`]); for each the exact
//! model's slice at the texture's β_m (the table's u, v nodes) is built and the sample inverted on
//! it, and the value whose RMS capped ΔE2000 is lowest is kept (a parabola through it and its
//! neighbours places it between values). `auto` keeps a parameter only when it lowers that RMS by
//! more than [`MapsOptions::beta_tolerance_de`] (the same tolerance that bounds the β_m spread);
//! otherwise it returns to its default. The forward table is then built on the fitted skin and
//! β_m and the exposure fitted again on it.

use super::table::ForwardTable;
use super::{FittedRange, Inverter, MapsError, MapsModel, MapsOptions, best_on_grid};
use crate::model::{ModelChoice, Parameter};
use rayon::prelude::*;
use skin_optics::SkinParams;

/// Values of a free parameter tried per texture, evenly over its range.
pub const EXTENDED_STEPS: usize = 5;

/// One extended parameter of a texture: its value and the range the texels allow.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExtendedValue {
    /// The parameter (its `skin fit --json` name is [`Parameter::name`]).
    pub parameter: Parameter,
    /// The value fitted.
    pub value: f64,
    /// The values whose RMS capped ΔE2000 is within the tolerance of the best.
    pub range: FittedRange,
    /// Whether it was kept (always for `full`; for `auto` when it lowered the RMS enough).
    pub kept: bool,
}

/// The extended parameters fitted to a texture and the skin they make.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtendedFit {
    /// The base skin with every kept parameter at its fitted value: the base of the table to fit
    /// the maps on.
    pub base: SkinParams,
    /// Every parameter tried, in [`Parameter::CANDIDATES`] order.
    pub values: Vec<ExtendedValue>,
    /// RMS capped ΔE2000 of the sample with the seed model.
    pub seed_rms_de: f64,
    /// ... and with the kept parameters.
    pub rms_de: f64,
}

impl ExtendedFit {
    /// The kept parameters with their values.
    pub fn kept(&self) -> impl Iterator<Item = &ExtendedValue> {
        self.values.iter().filter(|v| v.kept)
    }
}

impl MapsModel {
    /// The extended parameters of `model` (`seed`: none), tried in the order of `candidates`
    /// ([`Parameter::CANDIDATES`] for `skin fit`'s set), fitted per texture over the sample of
    /// `texels` (inside `mask`) that β_m is fitted on (module doc), from this model's β_m and
    /// exposure. `progress` gets the parameter's name before each is tried.
    pub fn fit_extended(
        &self,
        texels: &[[f32; 3]],
        mask: Option<&[bool]>,
        opts: &MapsOptions,
        model: ModelChoice,
        candidates: &[Parameter],
        progress: &(dyn Fn(&str) + Sync),
    ) -> Result<ExtendedFit, MapsError> {
        opts.validate()?;
        let fitted: Vec<bool> = mask.map_or_else(|| vec![true; texels.len()], <[bool]>::to_vec);
        if fitted.len() != texels.len() {
            return Err(MapsError::Length {
                what: "mask",
                found: fitted.len(),
                expected: texels.len(),
            });
        }
        let shared = self.fit_shared(texels, &fitted, opts);
        let sample = sample_texels(texels, &fitted, opts.beta_samples);
        let size = self.table().size();
        let rms_on = |base: SkinParams| -> Result<f64, MapsError> {
            let slice =
                ForwardTable::exact_slice(size.melanin, size.hemoglobin, base, shared.beta)?;
            Ok(super::sample_rms(
                &Inverter::new(slice),
                &sample,
                shared.gain,
            ))
        };
        let mut base = opts.base;
        let seed_rms = if sample.is_empty() {
            0.0
        } else {
            rms_on(base)?
        };
        let mut current = seed_rms;
        let mut values = Vec::new();
        for &p in candidates {
            if sample.is_empty() || model == ModelChoice::Seed {
                break;
            }
            progress(p.name());
            let [lo, hi] = p.range();
            let xs: Vec<f64> = (0..EXTENDED_STEPS)
                .map(|i| lo + (hi - lo) * i as f64 / (EXTENDED_STEPS - 1) as f64)
                .collect();
            let rms = xs
                .iter()
                .map(|&x| rms_on(p.set(base, x).map_err(crate::FitError::from)?))
                .collect::<Result<Vec<f64>, MapsError>>()?;
            let (x, range) = best_on_grid(&xs, &rms, opts.beta_tolerance_de);
            let x = x.clamp(lo, hi);
            let trial_rms = rms_on(p.set(base, x).map_err(crate::FitError::from)?)?;
            let grid_best = (0..xs.len())
                .min_by(|&a, &b| rms[a].total_cmp(&rms[b]))
                .unwrap_or(0);
            // The parabola's value unless a grid value beats it.
            let (value, value_rms) = if trial_rms <= rms[grid_best] {
                (x, trial_rms)
            } else {
                (xs[grid_best], rms[grid_best])
            };
            let kept = match model {
                ModelChoice::Auto => value_rms < current - opts.beta_tolerance_de,
                _ => true,
            };
            if kept {
                base = p.set(base, value).map_err(crate::FitError::from)?;
                current = value_rms;
            }
            values.push(ExtendedValue {
                parameter: p,
                value: p.get(&base),
                range,
                kept,
            });
        }
        Ok(ExtendedFit {
            base,
            values,
            seed_rms_de: seed_rms,
            rms_de: current,
        })
    }
}

/// The texels β_m is fitted on: `count` of the fitted ones at golden-ratio (Weyl) positions,
/// which spread over the texture without lining up with its rows.
pub(super) fn sample_texels(texels: &[[f32; 3]], fitted: &[bool], count: usize) -> Vec<[f32; 3]> {
    let chosen: Vec<usize> = (0..texels.len()).filter(|&k| fitted[k]).collect();
    if chosen.is_empty() {
        return Vec::new();
    }
    let count = count.min(chosen.len());
    let golden = 0.5 * (5f64.sqrt() - 1.0);
    (0..count)
        .into_par_iter()
        .map(|i| {
            let at = ((i as f64 * golden).fract() * chosen.len() as f64) as usize;
            texels[chosen[at.min(chosen.len() - 1)]]
        })
        .collect()
}
