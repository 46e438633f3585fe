//! Spectrum fit with the instrument modelled (SCE/SCI) and the model chosen by the data
//! (docs/physics.md §13).
//!
//! 1. **Start**: the seed model's residual on a coarse grid over C_m, β_m, C_h (the search
//!    coordinates of [`fit_spectrum`]), then step 2 for the seed's parameters from the best nodes
//!    in distinct basins. `--model seed` under SCE is [`fit_spectrum`] itself, today's fit.
//! 2. **Refine** the free parameters together by bounded Levenberg–Marquardt (module
//!    `least_squares`) on the model the instrument sees: diffuse reflectance plus, for SCI,
//!    ρ_s a(cos 8°). An exact fit refines on the cheap search quadrature shifted to the full model
//!    (output space mapping, module `forward`), re-shifted until the full residual stops falling.
//! 3. **Select** (`auto`): starting from the seed's parameters, each candidate of
//!    [`Parameter::CANDIDATES`] not yet in is tried; the best one is kept if it lowers the
//!    criterion, then the next round. The criterion is the extended BIC of Chen & Chen (2008)
//!    with a known noise level σ ([`MeasuredOptions::noise`]):
//!    IC = n · rms² / σ² + k ln n + 2 ln C(m, j),
//!    for n wavelengths, k free parameters, j of the m candidates chosen. The last term charges
//!    for having picked the best of several candidates; without it a spectrum of the seed model
//!    plus noise gains a spurious parameter about 40 % of the time (best of 7 χ²₁ draws above ln 31).
//!
//! A colour target (module `colour`) shares the refinement and selection (module `select`).

use super::forward::Forward;
use super::geometry::{Geometry, unit_surface_reflectance};
use super::least_squares::{LM, LmBudget};
use super::model::{ModelChoice, Parameter};
use super::{FitError, FitOptions, MeasuredSpectrum, fit_spectrum};
use select::ln_binomial;
use skin_optics::{SkinParams, Wavelength};

/// Knobs of [`fit_measured`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredOptions {
    /// What the instrument reports (default SCE: the model's diffuse reflectance as is).
    pub geometry: Geometry,
    /// Which parameters to free (default `seed`).
    pub model: ModelChoice,
    /// Noise σ of one measured reflectance for the criterion, in (0, 1) (default 0.005: an assumed
    /// repeatability of a d/8 measurement on skin, probe placement included; a knob, not a fact).
    pub noise: f64,
    /// Convergence tolerance of the refinement in χ² units at `noise`, in [0, 1] (default
    /// [`CHI2_TOLERANCE`]): a descent step or a space-mapping round that lowers
    /// χ² = n · rms² / σ² by less than this ends it (0: only the relative tests, the descent to
    /// the optimiser's precision). The default is 1000× below the χ² change that bounds a
    /// parameter's 1σ interval (Δχ² = 1) and 3000× below the criterion's charge per parameter
    /// (ln n); what a descent that crawls along a valley leaves behind at it is measured in
    /// BENCHMARKS.md `## Fit` (chosen on the explore subjects).
    pub chi2_tolerance: f64,
    /// Fit ρ_s under SCI (default true); false keeps the base skin's ρ_s.
    pub fit_oiliness: bool,
    /// Starts of the `full` refinement, in [1, [`FULL_STARTS_MAX`]] (default 4): the seed fit's
    /// point, then every candidate at mid-range, a quarter and three quarters of its range (module
    /// `select`). Each start costs about as much as the first; fewer starts may stop in a worse
    /// valley (measured in BENCHMARKS.md `## Fit`).
    pub full_starts: usize,
    /// Of the extra `full` starts, how many are refined after a short trial descent from each ranks
    /// them, in [0, [`FULL_STARTS_MAX`] − 1] (default [`FULL_REFINED_STARTS`]); a start is refined
    /// only if its trial already beats the first refinement (module `select`). The maximum, 3,
    /// refines every start without trials (the exhaustive multi-start).
    pub full_refined_starts: usize,
    /// Candidates per `auto` round that get a trial fit, the best by the score test's predicted
    /// drop of the residual (module `score`), in [0, 7] (default [`SCREENED_TRIALS`]); a round
    /// whose best predicted drop cannot lower the criterion ends the selection untried. 0 turns
    /// the screening off: every remaining candidate gets a trial fit, the exhaustive selection.
    pub screened_trials: usize,
    /// The seed fit's knobs (forward model, search, base skin).
    pub fit: FitOptions,
}

impl Default for MeasuredOptions {
    fn default() -> Self {
        Self {
            geometry: Geometry::Sce,
            model: ModelChoice::Seed,
            noise: 0.005,
            chi2_tolerance: CHI2_TOLERANCE,
            fit_oiliness: true,
            full_starts: FULL_STARTS_MAX,
            screened_trials: SCREENED_TRIALS,
            full_refined_starts: FULL_REFINED_STARTS,
            fit: FitOptions::default(),
        }
    }
}

impl MeasuredOptions {
    /// Check the criterion's noise and the `full` starts against their ranges (the seed fit's
    /// knobs are checked by [`FitOptions::validate`]).
    pub fn validate(&self) -> Result<(), FitError> {
        if !(self.noise > 0.0 && self.noise < 1.0) {
            return Err(FitError::Option {
                name: "noise",
                value: self.noise,
                range: "(0, 1)",
            });
        }
        if !(0.0..=1.0).contains(&self.chi2_tolerance) {
            return Err(FitError::Option {
                name: "chi2_tolerance",
                value: self.chi2_tolerance,
                range: "[0, 1]",
            });
        }
        if !(1..=FULL_STARTS_MAX).contains(&self.full_starts) {
            return Err(FitError::Option {
                name: "full_starts",
                value: self.full_starts as f64,
                range: "[1, 4]",
            });
        }
        if self.full_refined_starts >= FULL_STARTS_MAX {
            return Err(FitError::Option {
                name: "full_refined_starts",
                value: self.full_refined_starts as f64,
                range: "[0, 3]",
            });
        }
        if self.screened_trials > Parameter::CANDIDATES.len() {
            return Err(FitError::Option {
                name: "screened_trials",
                value: self.screened_trials as f64,
                range: "[0, 7]",
            });
        }
        Ok(())
    }
}

/// One round of the `auto` selection: the best candidate of the round and whether it was kept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelectionStep {
    /// The candidate with the lowest residual this round.
    pub parameter: Parameter,
    /// Weighted RMS residual before adding it.
    pub rms_before: f64,
    /// Weighted RMS residual with it.
    pub rms_after: f64,
    /// Change of the criterion (negative = kept).
    pub delta_criterion: f64,
    /// Whether it was kept.
    pub accepted: bool,
    /// Whether `rms_after` and `delta_criterion` are the score test's prediction (a round that
    /// ended before its trial fit) rather than a refined fit's.
    pub predicted: bool,
}

/// Result of [`fit_measured`].
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredFit {
    /// The fitted skin (free parameters fitted, the rest from the base skin).
    pub skin: SkinParams,
    /// The parameters that were free, seed ones first.
    pub parameters: Vec<Parameter>,
    /// What the instrument sees for the fitted skin at each measured wavelength.
    pub model: Vec<f64>,
    /// Weighted RMS residual of `model` against the measurement.
    pub rms: f64,
    /// The reflectance the geometry adds (ρ_s a(cos 8°) for SCI, else 0).
    pub surface_reflectance: f64,
    /// The seed model's fit under the same geometry, the reference of the selection.
    pub seed_rms: f64,
    /// The criterion of the final model (see the module doc).
    pub criterion: f64,
    /// The rounds of the `auto` selection (empty for `seed` and `full`).
    pub steps: Vec<SelectionStep>,
    /// Full-model spectrum evaluations spent.
    pub full_evaluations: usize,
    /// Search-model spectrum evaluations spent.
    pub search_evaluations: usize,
}

/// Fit a measured spectrum with the instrument's geometry and the chosen model (module doc).
pub fn fit_measured(
    measured: &MeasuredSpectrum,
    opts: &MeasuredOptions,
) -> Result<MeasuredFit, FitError> {
    opts.fit.validate()?;
    opts.validate()?;
    let unit_surface = match opts.geometry {
        Geometry::Sce => 0.0,
        Geometry::Sci => unit_surface_reflectance(opts.fit.base.eta())?,
    };
    let seed_params = seed_parameters(opts);
    let mut problem = Problem::new(measured, opts, unit_surface)?;
    let n = measured.len() as f64;
    let m = Parameter::CANDIDATES.len();
    let criterion = |rms: f64, k: usize, j: usize| {
        n * (rms / opts.noise).powi(2) + k as f64 * n.ln() + 2.0 * ln_binomial(m, j)
    };
    let seed = if opts.geometry == Geometry::Sce && opts.model == ModelChoice::Seed {
        // Today's fit, unchanged (on the data as it has always received them: no negative values).
        let data = MeasuredSpectrum::new(
            measured.lambda_nm().to_vec(),
            measured.reflectance().iter().map(|r| r.max(0.0)).collect(),
            Some(measured.weights().to_vec()),
        )?;
        let start = fit_spectrum(&data, &opts.fit)?;
        // `evaluations` counts each full evaluation with its search pair, and the final model.
        problem.search_evals += start
            .evaluations
            .saturating_sub(2 * start.full_evaluations + 1);
        problem.full_evals += start.full_evaluations + 1;
        (start.skin, start.rms)
    } else {
        select::grid_start(&mut problem, &seed_params, &opts.fit)?
    };
    let seed_rms = seed.1;
    let (params, skin, rms, steps) =
        select::fit_model(&mut problem, opts, seed, &seed_params, criterion)?;
    let model = problem.full_model(&skin)?;
    let chosen = params.len() - seed_params.len();
    Ok(MeasuredFit {
        surface_reflectance: skin.oiliness() * unit_surface,
        criterion: criterion(rms, params.len(), chosen),
        skin,
        parameters: params,
        model,
        rms,
        seed_rms,
        steps,
        full_evaluations: problem.full_evals,
        search_evaluations: problem.search_evals,
    })
}

/// Most starts of the `full` refinement ([`MeasuredOptions::full_starts`]).
pub const FULL_STARTS_MAX: usize = 4;

/// Default [`MeasuredOptions::chi2_tolerance`].
pub const CHI2_TOLERANCE: f64 = 1e-3;

/// Default [`MeasuredOptions::full_refined_starts`].
pub const FULL_REFINED_STARTS: usize = 1;

/// Default [`MeasuredOptions::screened_trials`].
pub const SCREENED_TRIALS: usize = 2;

/// A fitted value closer than this fraction of its range to a bound counts as on the bound.
pub const AT_BOUND_FRACTION: f64 = 1e-3;

impl MeasuredFit {
    /// The free parameters whose fitted value sits on a bound of its fit range (within
    /// [`AT_BOUND_FRACTION`] of the range), with the bound: the optimiser wanted to go further,
    /// so the model lacks something there or trades that parameter against another.
    #[must_use]
    pub fn at_bounds(&self) -> Vec<(Parameter, f64)> {
        self.parameters
            .iter()
            .filter_map(|&p| {
                let [lo, hi] = p.range();
                let v = p.get(&self.skin);
                let tol = AT_BOUND_FRACTION * (hi - lo);
                if v <= lo + tol {
                    Some((p, lo))
                } else if v >= hi - tol {
                    Some((p, hi))
                } else {
                    None
                }
            })
            .collect()
    }
}

/// The seed's free parameters for `opts`: C_m, β_m, C_h, and ρ_s when SCI data fit it.
pub(crate) fn seed_parameters(opts: &MeasuredOptions) -> Vec<Parameter> {
    let mut p = Parameter::SEED.to_vec();
    if opts.geometry == Geometry::Sci && opts.fit_oiliness {
        p.push(Parameter::Oiliness);
    }
    p
}

/// `seed` followed by every candidate (the `full` model).
pub(crate) fn with_candidates(seed: &[Parameter]) -> Vec<Parameter> {
    seed.iter().copied().chain(Parameter::CANDIDATES).collect()
}

/// The measurement, the two forward models and the current space-mapping shift.
struct Problem<'a> {
    measured: &'a MeasuredSpectrum,
    lambdas: Vec<Wavelength>,
    full: Forward,
    search: Option<Forward>,
    shift: Vec<f64>,
    unit_surface: f64,
    geometry: Geometry,
    weight_sum: f64,
    full_evals: usize,
    search_evals: usize,
    /// The refinement's Levenberg–Marquardt budget (the reference scheme in a test).
    budget: LmBudget,
}

impl<'a> Problem<'a> {
    fn new(
        measured: &'a MeasuredSpectrum,
        opts: &MeasuredOptions,
        unit_surface: f64,
    ) -> Result<Self, FitError> {
        let lambdas = measured
            .lambda_nm()
            .iter()
            .map(|&nm| Wavelength::new(nm))
            .collect::<Result<Vec<_>, _>>()?;
        let lambdas_len = lambdas.len();
        Ok(Self {
            measured,
            shift: vec![0.0; lambdas.len()],
            lambdas,
            full: Forward::Method(opts.fit.method),
            search: Forward::search(opts.fit.method, opts.fit.search_quadrature_points),
            unit_surface,
            geometry: opts.geometry,
            weight_sum: measured.weights().iter().sum(),
            full_evals: 0,
            search_evals: 0,
            // The cost is the weighted mean square, χ² σ² / n.
            budget: LmBudget {
                f_atol: opts.chi2_tolerance * opts.noise * opts.noise / lambdas_len as f64,
                ..LM
            },
        })
    }

    /// What the instrument sees with forward model `f` (no shift).
    fn seen(&self, f: &Forward, skin: &SkinParams) -> Result<Vec<f64>, FitError> {
        let surface = match self.geometry {
            Geometry::Sce => 0.0,
            Geometry::Sci => skin.oiliness() * self.unit_surface,
        };
        Ok(f.spectrum(skin, &self.lambdas)?
            .into_iter()
            .map(|r| r + surface)
            .collect())
    }

    fn full_model(&mut self, skin: &SkinParams) -> Result<Vec<f64>, FitError> {
        self.full_evals += 1;
        self.seen(&self.full, skin)
    }

    fn rms(&self, model: &[f64]) -> f64 {
        self.residuals(model)
            .iter()
            .map(|r| r * r)
            .sum::<f64>()
            .sqrt()
    }

    /// √(wᵢ / Σw) (model − measured): their squares sum to the weighted mean square.
    fn residuals(&self, model: &[f64]) -> Vec<f64> {
        model
            .iter()
            .zip(self.measured.reflectance())
            .zip(self.measured.weights())
            .map(|((m, r), w)| (w / self.weight_sum).sqrt() * (m - r))
            .collect()
    }
}

impl select::Target for Problem<'_> {
    fn shifted_residuals(&mut self, skin: &SkinParams) -> Result<Vec<f64>, FitError> {
        let forward = self.search.unwrap_or(self.full);
        if self.search.is_some() {
            self.search_evals += 1;
        } else {
            self.full_evals += 1;
        }
        let mut m = self.seen(&forward, skin)?;
        for (v, b) in m.iter_mut().zip(&self.shift) {
            *v += b;
        }
        Ok(self.residuals(&m))
    }

    fn reshift(&mut self, skin: &SkinParams) -> Result<f64, FitError> {
        let full = self.full_model(skin)?;
        if let Some(search) = self.search {
            self.search_evals += 1;
            let cheap = self.seen(&search, skin)?;
            self.shift = full.iter().zip(&cheap).map(|(f, c)| f - c).collect();
        }
        Ok(self.rms(&full))
    }

    fn has_search(&self) -> bool {
        self.search.is_some()
    }

    fn budget(&self) -> LmBudget {
        self.budget
    }
}

mod colour;
mod score;
mod select;

pub use colour::{MeasuredColourFit, fit_measured_colour};
#[cfg(test)]
mod tests;
