//! The fit's forward model per wavelength, and the two-stage scheme that makes an exact fit fast:
//! search with a cheap exact model, then correct to the full one by output space mapping.
//!
//! **Search model.** `Method::Exact` at its default quadrature (24 points) costs about twelve times
//! as much per colour as at 8 points (BENCHMARKS.md `## Exact method`), and a fit evaluates the model
//! some 1500 times (grid, starts, β_m sweep). The search stage therefore uses adding-doubling with
//! [`super::FitOptions::search_quadrature_points`] (default 8; its colour error against 24 points is
//! measured in BENCHMARKS.md `## Fit`).
//!
//! **Correction (output space mapping**, Bandler et al. 2004). At the search optimum x₀ the full
//! model's output (XYZ for a colour, the reflectances for a spectrum) is evaluated once, and the cheap
//! model is shifted by the difference b₀ = full(x₀) − cheap(x₀). The shifted cheap model equals the full
//! one at x₀ and differs from it only by how the quadrature error *varies* with the parameters, so
//! re-minimising it (Nelder–Mead from x₀) lands next to the full model's optimum; repeating with
//! b_k = full(x_k) − cheap(x_k) converges in two or three full evaluations. At a fixed point x* the
//! shifted model reproduces the full one's output exactly, so a colour the full model can match is
//! matched by it (ΔE00 → 0), whatever the search quadrature. The β_m sweep runs on the shifted model
//! with the final shift (a residual tolerance test, needed to a fraction of its 1 ΔE00 tolerance).

use super::FitError;
use super::nelder_mead::{Budget, minimize};
use multipole::Method;
use multipole::exact::adding_doubling::{AddingDoublingOptions, skin_totals};
use multipole::skin::diffuse_reflectance;
use rayon::prelude::*;
use skin_optics::{SkinParams, Wavelength};

/// A forward model: diffuse reflectance (the observable) of a skin at one wavelength.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Forward {
    /// [`multipole::skin::diffuse_reflectance`] with this method.
    Method(Method),
    /// Adding-doubling totals with these options (the search stage of an exact fit).
    Exact(AddingDoublingOptions),
}

impl Forward {
    /// The search-stage model for a fit with `method`, or `None` when the search uses `method` itself
    /// (multipole, or an exact fit whose search quadrature is not below the default).
    pub(crate) fn search(method: Method, search_points: usize) -> Option<Forward> {
        let default = AddingDoublingOptions::default();
        if method != Method::Exact || search_points >= default.quadrature_points() {
            return None;
        }
        AddingDoublingOptions::new(search_points, default.g())
            .ok()
            .map(|o| Forward::Exact(o.with_layer_cache(true)))
    }

    /// Whether one wavelength costs enough (an adding-doubling solve) to spread a spectrum over threads.
    fn is_costly(&self) -> bool {
        matches!(self, Forward::Exact(_) | Forward::Method(Method::Exact))
    }

    /// Diffuse reflectance of `skin` at `lambda`, per incident photon, specular excluded.
    pub(crate) fn reflectance(
        &self,
        skin: &SkinParams,
        lambda: Wavelength,
    ) -> Result<f64, FitError> {
        match self {
            Forward::Method(m) => Ok(diffuse_reflectance(skin, lambda, *m)?),
            Forward::Exact(o) => skin_totals(skin, lambda, o)
                .map(|t| t.diffuse_reflectance)
                .map_err(FitError::Model),
        }
    }

    /// [`Forward::reflectance`] at every wavelength of `lambdas`, in order; an adding-doubling model
    /// spreads the wavelengths over rayon's threads (each costs enough to pay for it), a diffusion
    /// one does not (too cheap per wavelength).
    pub(crate) fn spectrum(
        &self,
        skin: &SkinParams,
        lambdas: &[Wavelength],
    ) -> Result<Vec<f64>, FitError> {
        if self.is_costly() {
            lambdas
                .par_iter()
                .with_min_len(4)
                .map(|&l| self.reflectance(skin, l))
                .collect()
        } else {
            lambdas.iter().map(|&l| self.reflectance(skin, l)).collect()
        }
    }
}

/// Full-model evaluations at most in the space-mapping correction (each followed by a re-minimisation
/// of the shifted search model, except the last).
pub(crate) const MAPPING_ITERATIONS: usize = 5;

/// The correction has converged when successive optima differ by less than this in the unit search
/// box (the main refinement's own tolerance).
const MAPPING_X_TOL: f64 = 1e-4;

/// … or when the full objective changed by less than this fraction between successive optima.
const MAPPING_F_RTOL: f64 = 1e-3;

/// Initial simplex size of each re-minimisation: the search optimum is already within the search
/// model's quadrature error of the answer.
const MAPPING_STEP: f64 = 0.01;

/// Output space mapping from the search optimum `x0` (module doc).
///
/// `shifted` is the search objective with the current shift; `set_shift` installs a shift;
/// `full_at(x)` returns the shift that makes the search model equal the full one at x, and the full
/// objective at x. Returns the point with the lowest full objective seen (its shift installed), the
/// search-model evaluations and the full-model evaluations spent.
pub(crate) fn space_mapping<S>(
    x0: [f64; 3],
    shifted: &mut impl FnMut(&[f64; 3]) -> f64,
    set_shift: impl Fn(S),
    mut full_at: impl FnMut(&[f64; 3]) -> Result<(S, f64), FitError>,
    budget: Budget,
) -> Result<([f64; 3], usize, usize), FitError>
where
    S: Clone,
{
    let mut x = x0;
    let mut previous: Option<([f64; 3], f64)> = None;
    let mut best: Option<([f64; 3], f64, S)> = None;
    let (mut search_evals, mut full_evals) = (0, 0);
    for iteration in 0..MAPPING_ITERATIONS {
        let (shift, f_full) = full_at(&x)?;
        full_evals += 1;
        if best.as_ref().is_none_or(|b| f_full < b.1) {
            best = Some((x, f_full, shift.clone()));
        }
        // Converged when the optimum stops moving, or when the full objective stops changing
        // (along a direction the data cannot see, e.g. C_h under much melanin, x may drift on a
        // plateau while the fit is already as good as it gets).
        let converged = previous.is_some_and(|(p, f_prev): ([f64; 3], f64)| {
            p.iter().zip(&x).all(|(a, b)| (a - b).abs() < MAPPING_X_TOL)
                || (f_prev - f_full).abs() <= MAPPING_F_RTOL * f_prev
        });
        if converged || iteration + 1 == MAPPING_ITERATIONS {
            break;
        }
        set_shift(shift);
        let m = minimize(shifted, x, MAPPING_STEP, budget);
        search_evals += m.evals;
        previous = Some((x, f_full));
        x = m.x;
    }
    // At least one iteration ran, so `best` is set; `x0` is only a defensive fallback.
    let Some((x, _, shift)) = best else {
        return Ok((x0, search_evals, full_evals));
    };
    set_shift(shift);
    Ok((x, search_evals, full_evals))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::REFINE;
    use std::cell::Cell;

    /// A search model off the full one by a smooth, parameter-dependent error: minimising it alone
    /// misses the full optimum by ~0.05; the mapping reaches it to the refinement tolerance.
    #[test]
    fn space_mapping_reaches_the_full_optimum() {
        let target = [0.3, 0.5, 0.7];
        let full = |x: &[f64; 3]| *x;
        let search = |x: &[f64; 3]| x.map(|v| v + 0.05 * (3.0 * v).sin() + 0.03);
        let dist2 =
            |y: [f64; 3]| -> f64 { y.iter().zip(&target).map(|(a, b)| (a - b).powi(2)).sum() };
        let shift = Cell::new([0.0; 3]);
        let mut shifted = |x: &[f64; 3]| {
            let (c, s) = (search(x), shift.get());
            dist2([c[0] + s[0], c[1] + s[1], c[2] + s[2]])
        };
        let x0 = minimize(&mut shifted, [0.5; 3], 0.1, REFINE).x;
        let miss = x0
            .iter()
            .zip(&target)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(miss > 0.03, "the search model alone misses: {miss}");
        let full_at = |x: &[f64; 3]| -> Result<([f64; 3], f64), FitError> {
            let (f, c) = (full(x), search(x));
            Ok(([f[0] - c[0], f[1] - c[1], f[2] - c[2]], dist2(f)))
        };
        let (x, _, full_evals) =
            space_mapping(x0, &mut shifted, |s| shift.set(s), full_at, REFINE).unwrap();
        let err = x
            .iter()
            .zip(&target)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            err < 1e-3,
            "mapped optimum off by {err} after {full_evals} full evaluations"
        );
        assert!(full_evals <= MAPPING_ITERATIONS);
    }
}
