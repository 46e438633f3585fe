//! Refinement and model selection shared by the spectrum and the colour target (docs/physics.md
//! §13.3): bounded Levenberg–Marquardt on the unit box of the free parameters' ranges, re-shifted
//! onto the full model (output space mapping, module `forward`), the multi-start `full` fit and the
//! greedy `auto` selection. A target supplies the residual vector and its shift through [`Target`];
//! the residual figure is the RMS reflectance for a spectrum and ΔE00 for a colour.

use super::{MeasuredOptions, SelectionStep, score, with_candidates};
use crate::least_squares::{LM, LmBudget, minimize};
use crate::model::{ModelChoice, Parameter};
use crate::nelder_mead::{distinct_starts, grid_search};
use crate::{FitError, FitOptions, infeasibility, search_to_params, with_chromophores};
use skin_optics::SkinParams;

/// Space-mapping rounds of a refinement at most (each one full-model evaluation and one LM run).
const MAPPING_ROUNDS: usize = 4;

/// Where the extra starts of a `full` fit put every candidate, as a fraction of its range (the
/// seed's C_m, β_m, C_h and ρ_s start from the best fit so far).
const FULL_STARTS: [f64; 3] = [0.5, 0.25, 0.75];

/// What a fit target provides: residuals of the cheap model with the current shift, and the
/// shift itself.
pub(super) trait Target {
    /// Residuals of the shifted cheap model (the full model when there is no cheaper one) for
    /// `skin`; their squares sum to the residual figure squared.
    fn shifted_residuals(&mut self, skin: &SkinParams) -> Result<Vec<f64>, FitError>;
    /// Install the shift that makes the cheap model equal the full one at `skin`; returns the full
    /// model's residual figure there.
    fn reshift(&mut self, skin: &SkinParams) -> Result<f64, FitError>;
    /// Whether a cheaper model stands in for the full one (space mapping needed).
    fn has_search(&self) -> bool;
    /// The Levenberg–Marquardt budget of a refinement (default [`LM`]).
    fn budget(&self) -> LmBudget {
        LM
    }
}

/// `skin` with `params` set from unit coordinates `u` (each mapped onto its range), or `None` when
/// the skin rejects a value.
fn skin_at(skin: SkinParams, params: &[Parameter], u: &[f64]) -> Option<SkinParams> {
    params.iter().zip(u).try_fold(skin, |s, (p, &v)| {
        let [lo, hi] = p.range();
        p.set(s, lo + (hi - lo) * v).ok()
    })
}

/// LM over `params` from `skin` on the shifted cheap model, warm-started from `warm` (a Jacobian
/// at `skin`, or empty); returns the refined skin and the last Jacobian.
fn run(
    target: &mut impl Target,
    skin: SkinParams,
    params: &[Parameter],
    budget: LmBudget,
    warm: Vec<Vec<f64>>,
) -> Result<(SkinParams, Vec<Vec<f64>>), FitError> {
    let u0: Vec<f64> = params
        .iter()
        .map(|p| {
            let [lo, hi] = p.range();
            ((p.get(&skin) - lo) / (hi - lo)).clamp(0.0, 1.0)
        })
        .collect();
    let mut residuals = |u: &[f64]| -> Option<Vec<f64>> {
        let s = skin_at(skin, params, u)?;
        target.shifted_residuals(&s).ok()
    };
    let result = minimize(&mut residuals, &u0, budget, warm);
    let refined = skin_at(skin, params, &result.u).ok_or_else(|| {
        FitError::NotEnoughData("refined parameters left their valid range".to_string())
    })?;
    Ok((refined, result.jac))
}

/// Refine with space mapping until the full residual stops falling; returns the best skin and its
/// full-model residual figure.
pub(super) fn refine(
    target: &mut impl Target,
    skin: SkinParams,
    params: &[Parameter],
) -> Result<(SkinParams, f64), FitError> {
    let mut best = (skin, target.reshift(&skin)?);
    // The re-shift adds a constant to the residuals, so a descent's last Jacobian serves the next
    // round's start (the Broyden scheme of module `least_squares` only).
    let mut warm = Vec::new();
    for _ in 0..MAPPING_ROUNDS {
        let budget = target.budget();
        let (next, jac) = run(target, best.0, params, budget, std::mem::take(&mut warm))?;
        let r = target.reshift(&next)?;
        let gain = best.1 - r;
        let cost_gain = best.1 * best.1 - r * r;
        if r < best.1 {
            best = (next, r);
            warm = jac;
        } else {
            target.reshift(&best.0)?;
        }
        // A round that lowers the figure by less than 0.1 %, or its square (the descent's cost)
        // by less than the descent's absolute floor, ends the mapping.
        if !target.has_search() || gain <= 1e-3 * best.1 || cost_gain <= budget.f_atol {
            break;
        }
    }
    Ok(best)
}

/// The seed model's fit from nothing but the target: the residual of the cheap model (on the
/// current shift, zero for a new target) at every node of the `opts.grid` grid over the search
/// coordinates of C_m, β_m and C_h (those of `fit_spectrum`, §12; the rest of the skin is
/// `opts.base`), then [`refine`] of `params` from each of the best `opts.starts` nodes in distinct
/// basins. Returns the skin with the lowest full-model residual figure and that figure, the shift
/// left there.
///
/// Levenberg–Marquardt from the grid, where `fit_spectrum` runs Nelder–Mead descents: a
/// least-squares descent follows the residual vector, not only its norm, and reaches the same
/// optimum in far fewer spectra (BENCHMARKS.md `## Fit`).
pub(super) fn grid_start(
    target: &mut impl Target,
    params: &[Parameter],
    opts: &FitOptions,
) -> Result<(SkinParams, f64), FitError> {
    let skin_of =
        |x: &[f64; 3]| with_chromophores(&opts.base, search_to_params(x, opts.beta_prior));
    let mut failure = None;
    let mut objective = |x: &[f64; 3]| -> f64 {
        let r = skin_of(x)
            .map_err(FitError::from)
            .and_then(|s| target.shifted_residuals(&s));
        match r {
            // The penalty keeps nodes outside C_em + C_pm ≤ 0.5 (all mapped onto its edge) last.
            Ok(r) => r.iter().map(|v| v * v).sum::<f64>() + (10.0 * infeasibility(x)).powi(2),
            Err(e) => {
                failure.get_or_insert(e);
                f64::INFINITY
            }
        }
    };
    let grid = grid_search(&mut objective, opts.grid);
    let mut best: Option<(SkinParams, f64)> = None;
    for x in distinct_starts(&grid, opts.starts) {
        let refined = refine(target, skin_of(&x)?, params)?;
        if best.as_ref().is_none_or(|b| refined.1 < b.1) {
            best = Some(refined);
        }
    }
    let best = best.ok_or_else(|| {
        failure.unwrap_or_else(|| {
            FitError::NotEnoughData("no grid node gave a finite residual".to_string())
        })
    })?;
    // The last refinement left the shift at its own optimum.
    target.reshift(&best.0)?;
    Ok(best)
}

/// A quick trial of `params` from `skin` on the current shift (no re-shift): the selection's
/// ranking of candidates. Returns the trial skin and its shifted-model residual figure.
fn trial(
    target: &mut impl Target,
    skin: SkinParams,
    params: &[Parameter],
) -> Result<(SkinParams, f64), FitError> {
    let budget = LmBudget {
        max_iterations: 15,
        ..target.budget()
    };
    let (s, _) = run(target, skin, params, budget, Vec::new())?;
    let r = target.shifted_residuals(&s)?;
    Ok((s, r.iter().map(|v| v * v).sum::<f64>().sqrt()))
}

/// Every candidate freed, refined from `skin` and from the first `starts − 1` of [`FULL_STARTS`];
/// the lowest residual.
///
/// Several starts: every candidate at the base skin's value (where the seed fit left the target),
/// at mid-range, and at a quarter and three quarters of its range. With seven parameters that
/// trade against each other (blood near the surface against C_h, ρ_s against the scattering
/// scales), one local descent can stop in a valley.
///
/// Screening (`refined` < `starts − 1`): each extra start gets a short trial descent on the
/// first refinement's shift instead of a refinement; only the `refined` best of them are refined,
/// and only those whose trial already ends below the first refinement's residual (a start that
/// does not reach the first valley's depth in the trial is taken to sit in a shallower one).
fn full(
    target: &mut impl Target,
    skin: SkinParams,
    params: &[Parameter],
    starts: usize,
    refined: usize,
) -> Result<(SkinParams, f64), FitError> {
    let mut best = refine(target, skin, params)?;
    let extra = starts.saturating_sub(1);
    let start_at = |s: SkinParams, t: f64| {
        Parameter::CANDIDATES.iter().try_fold(s, |s, p| {
            let [lo, hi] = p.range();
            p.set(s, lo + t * (hi - lo))
        })
    };
    if refined >= extra {
        for &t in FULL_STARTS.iter().take(extra) {
            let trial = refine(target, start_at(best.0, t)?, params)?;
            if trial.1 < best.1 {
                best = trial;
            }
        }
        return Ok(best);
    }
    let first = best;
    let mut trials = Vec::with_capacity(extra);
    for &t in FULL_STARTS.iter().take(extra) {
        // The refinement leaves the shift at its best point.
        trials.push(trial(target, start_at(first.0, t)?, params)?);
    }
    trials.sort_by(|a, b| a.1.total_cmp(&b.1));
    for (s, r) in trials.into_iter().take(refined) {
        if r >= first.1 {
            break;
        }
        let candidate = refine(target, s, params)?;
        if candidate.1 < best.1 {
            best = candidate;
        }
    }
    Ok(best)
}

/// The `auto` selection from the seed's fit (`skin`, residual `rms`, `params`): each round ranks
/// the candidates not yet in, trial-fits the best `screened` of them (all when `screened` is 0),
/// refines the best trial and keeps it while `criterion(residual, k, j)` falls (k free parameters,
/// j candidates chosen). With screening on, the ranking is the score test's predicted drop (module
/// `score`), and a round whose best predicted drop cannot lower the criterion ends the selection
/// without a trial. Returns the final parameters, skin, residual and the rounds.
fn auto(
    target: &mut impl Target,
    start: (SkinParams, f64),
    seed_params: &[Parameter],
    screened: usize,
    criterion: impl Fn(f64, usize, usize) -> f64,
) -> Result<(Vec<Parameter>, SkinParams, f64, Vec<SelectionStep>), FitError> {
    let (mut skin, mut rms) = start;
    let mut params = seed_params.to_vec();
    let mut steps = Vec::new();
    let mut chosen = 0;
    loop {
        let mut remaining: Vec<Parameter> = Parameter::CANDIDATES
            .into_iter()
            .filter(|p| !params.contains(p))
            .collect();
        if remaining.is_empty() {
            break;
        }
        if screened > 0 {
            // The shift at `skin` (the last refinement may have left it at its other start).
            rms = target.reshift(&skin)?;
            let drops = score::predicted_drops(target, skin, &params, &remaining)?;
            let mut ranked: Vec<(Parameter, f64)> = remaining.into_iter().zip(drops).collect();
            ranked.sort_by(|a, b| b.1.total_cmp(&a.1));
            let (p, drop) = ranked[0];
            let predicted = (rms * rms - drop).max(0.0).sqrt();
            let delta = criterion(predicted, params.len() + 1, chosen + 1)
                - criterion(rms, params.len(), chosen);
            if delta >= 0.0 {
                steps.push(SelectionStep {
                    parameter: p,
                    rms_before: rms,
                    rms_after: predicted,
                    delta_criterion: delta,
                    accepted: false,
                    predicted: true,
                });
                break;
            }
            remaining = ranked.into_iter().take(screened).map(|(p, _)| p).collect();
        }
        let mut best: Option<(Parameter, SkinParams, f64)> = None;
        for p in remaining {
            let mut trial_params = params.clone();
            trial_params.push(p);
            let (s, r) = trial(target, skin, &trial_params)?;
            if best.as_ref().is_none_or(|b| r < b.2) {
                best = Some((p, s, r));
            }
        }
        let Some((p, s, _)) = best else { break };
        let mut with = params.clone();
        with.push(p);
        // Two starts for the new parameter: where the trial left it, and mid-range (a parameter
        // that trades off against the seed's, like blood near the surface against C_h, can sit
        // in a long valley). With screening on, the mid-range start is refined only if a trial
        // from it already beats the first refinement (the `full` starts' rule).
        let [lo, hi] = p.range();
        let mid = p.set(s, 0.5 * (lo + hi))?;
        let (s, r) = {
            let a = refine(target, s, &with)?;
            let b = if screened == 0 {
                Some(refine(target, mid, &with)?)
            } else {
                // The refinement leaves the shift at its best point.
                let t = trial(target, mid, &with)?;
                if t.1 < a.1 {
                    Some(refine(target, t.0, &with)?)
                } else {
                    None
                }
            };
            match b {
                Some(b) if b.1 < a.1 => b,
                _ => a,
            }
        };
        let delta = criterion(r, with.len(), chosen + 1) - criterion(rms, params.len(), chosen);
        let accepted = delta < 0.0;
        steps.push(SelectionStep {
            parameter: p,
            rms_before: rms,
            rms_after: r,
            delta_criterion: delta,
            accepted,
            predicted: false,
        });
        if !accepted {
            break;
        }
        (params, skin, rms, chosen) = (with, s, r, chosen + 1);
    }
    Ok((params, skin, rms, steps))
}

/// The fit `opts.model` asks for, from the seed's fit `seed` over `seed_params`: the seed itself,
/// every candidate ([`full`], from `opts.full_starts` starts) or the selection ([`auto`] with `criterion`). Returns the free
/// parameters, skin, residual figure and the selection rounds.
pub(super) fn fit_model(
    target: &mut impl Target,
    opts: &MeasuredOptions,
    seed: (SkinParams, f64),
    seed_params: &[Parameter],
    criterion: impl Fn(f64, usize, usize) -> f64,
) -> Result<(Vec<Parameter>, SkinParams, f64, Vec<SelectionStep>), FitError> {
    match opts.model {
        ModelChoice::Seed => Ok((seed_params.to_vec(), seed.0, seed.1, Vec::new())),
        ModelChoice::Full => {
            let all = with_candidates(seed_params);
            let (skin, r) = full(
                target,
                seed.0,
                &all,
                opts.full_starts,
                opts.full_refined_starts,
            )?;
            Ok((all, skin, r, Vec::new()))
        }
        ModelChoice::Auto => auto(target, seed, seed_params, opts.screened_trials, criterion),
    }
}

/// ln C(m, j).
pub(super) fn ln_binomial(m: usize, j: usize) -> f64 {
    (0..j).map(|i| ((m - i) as f64 / (i + 1) as f64).ln()).sum()
}
