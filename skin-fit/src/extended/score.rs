//! Score (Lagrange-multiplier) screening of the `auto` candidates (docs/physics.md §13.3): the drop
//! of Σr² that freeing one more parameter would bring, predicted by the Gauss–Newton model at the
//! current optimum instead of a trial fit.
//!
//! At the optimum of the free parameters (Jacobian columns J of the ones off their bounds) the
//! residual r has no component that J can still remove. Freeing candidate c with column j_c adds
//! the direction j_c⊥ = (I − P_J) j_c, and the Gauss–Newton model of Σr² along it,
//! Σr² + 2δ g + δ² H with g = j_c⊥ᵀ r⊥ and H = ‖j_c⊥‖², is lowest at δ* = −g / H: a predicted drop
//! of g² / H, the score statistic of Rao (1948) and Silvey (1959) for the restriction "c stays
//! where it is" ([Rao48], [Sil59]; the Gauss–Newton model: Nocedal & Wright 2006 §10.3). The step
//! is clipped to the candidate's box: a candidate on a bound counts only the feasible direction,
//! and one that the box stops short of δ* is credited with the drop of the clipped step.
//!
//! Cost: one residual evaluation per column (forward differences, backward at the upper bound),
//! against a 15-iteration trial fit per candidate.

use super::select::Target;
use crate::FitError;
use crate::model::Parameter;
use skin_optics::SkinParams;

/// A unit coordinate within this of 0 or 1 counts as on its bound (the LM clamps exactly there).
const ON_BOUND: f64 = 1e-9;

/// `p`'s value in `skin` as a fraction of its fit range, clamped to [0, 1].
fn unit(p: Parameter, skin: &SkinParams) -> f64 {
    let [lo, hi] = p.range();
    ((p.get(skin) - lo) / (hi - lo)).clamp(0.0, 1.0)
}

/// ∂r/∂u of `p` at `skin` (u its unit coordinate) by a difference of `h`, forward unless that
/// leaves the box; `r0` the residuals at `skin`.
fn column(
    target: &mut impl Target,
    skin: SkinParams,
    p: Parameter,
    r0: &[f64],
    h: f64,
) -> Result<Vec<f64>, FitError> {
    let u = unit(p, &skin);
    let step = if u + h <= 1.0 { h } else { -h };
    let [lo, hi] = p.range();
    let moved = p.set(skin, lo + (hi - lo) * (u + step))?;
    let r = target.shifted_residuals(&moved)?;
    Ok(r.iter().zip(r0).map(|(a, b)| (a - b) / step).collect())
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `v` with its components along the orthonormal `basis` removed.
fn project_out(basis: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
    let mut out = v.to_vec();
    for q in basis {
        let c = dot(q, &out);
        for (o, x) in out.iter_mut().zip(q) {
            *o -= c * x;
        }
    }
    out
}

/// The predicted drop of Σr² (the residual figure squared, on the target's current shift) for
/// freeing each of `candidates` at `skin`, where `params` are free and at their optimum (module
/// doc). Costs one residual evaluation for `skin` and one per interior parameter and candidate.
pub(super) fn predicted_drops(
    target: &mut impl Target,
    skin: SkinParams,
    params: &[Parameter],
    candidates: &[Parameter],
) -> Result<Vec<f64>, FitError> {
    let h = target.budget().h;
    let r0 = target.shifted_residuals(&skin)?;
    // An orthonormal basis of the interior parameters' columns (modified Gram–Schmidt; a column
    // that the others already span adds nothing).
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for &p in params {
        let u = unit(p, &skin);
        if u <= ON_BOUND || u >= 1.0 - ON_BOUND {
            continue;
        }
        let col = column(target, skin, p, &r0, h)?;
        let rest = project_out(&basis, &col);
        let norm = dot(&rest, &rest).sqrt();
        if norm > 1e-8 * dot(&col, &col).sqrt() {
            basis.push(rest.iter().map(|x| x / norm).collect());
        }
    }
    let r_perp = project_out(&basis, &r0);
    candidates
        .iter()
        .map(|&c| {
            let col = column(target, skin, c, &r0, h)?;
            let c_perp = project_out(&basis, &col);
            let curvature = dot(&c_perp, &c_perp);
            // Not above the floor, or not comparable (NaN): the column adds nothing.
            if curvature.partial_cmp(&(1e-16 * dot(&col, &col)))
                != Some(std::cmp::Ordering::Greater)
            {
                return Ok(0.0);
            }
            let g = dot(&c_perp, &r_perp);
            let u = unit(c, &skin);
            let delta = (-g / curvature).clamp(-u, 1.0 - u);
            Ok((-(2.0 * delta * g + delta * delta * curvature)).max(0.0))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::least_squares::{LM_REFERENCE, minimize};

    /// Residuals linear in the unit coordinates of `params`: r = Σ_p u_p a_p − b.
    struct Linear {
        params: Vec<Parameter>,
        columns: Vec<Vec<f64>>,
        b: Vec<f64>,
        evals: usize,
    }

    impl Linear {
        fn at(&self, u: &[f64]) -> Vec<f64> {
            (0..self.b.len())
                .map(|i| {
                    let s: f64 = self.columns.iter().zip(u).map(|(a, v)| a[i] * v).sum();
                    s - self.b[i]
                })
                .collect()
        }
    }

    impl Target for Linear {
        fn shifted_residuals(&mut self, skin: &SkinParams) -> Result<Vec<f64>, FitError> {
            self.evals += 1;
            let u: Vec<f64> = self.params.iter().map(|&p| unit(p, skin)).collect();
            Ok(self.at(&u))
        }
        fn reshift(&mut self, skin: &SkinParams) -> Result<f64, FitError> {
            let r = self.shifted_residuals(skin)?;
            Ok(dot(&r, &r).sqrt())
        }
        fn has_search(&self) -> bool {
            false
        }
    }

    fn skin_with(params: &[Parameter], u: &[f64]) -> SkinParams {
        params.iter().zip(u).fold(
            SkinParams::new(0.05, 0.7, 0.02, 0.5).unwrap(),
            |s, (p, &v)| {
                let [lo, hi] = p.range();
                p.set(s, lo + (hi - lo) * v).unwrap()
            },
        )
    }

    /// On residuals linear in the parameters the Gauss–Newton model is exact, so the predicted drop
    /// of freeing each candidate equals the drop a bounded least-squares fit of the free parameters
    /// plus that candidate reaches (to 1e-6 of Σr²): a candidate inside its box whose optimum lies
    /// past a bound (credited with the clipped step), one on its lower bound that wants to rise, and
    /// one on its upper bound that wants to rise further (no feasible direction: zero). One residual
    /// evaluation per column.
    #[test]
    fn predicted_drops_are_exact_on_a_linear_model_with_bounds() {
        let free = [
            Parameter::Melanin,
            Parameter::EumelaninBlend,
            Parameter::Hemoglobin,
        ];
        let candidates = [
            Parameter::EpidermisThickness,
            Parameter::Oxygenation,
            Parameter::DermisScattering,
        ];
        let params: Vec<Parameter> = free.iter().chain(&candidates).copied().collect();
        let n = 9;
        // Generic columns; the free ones three times larger, so that they move little when a
        // candidate is freed and stay inside their box.
        let columns: Vec<Vec<f64>> = (0..params.len())
            .map(|p| {
                let scale = if p < 3 { 3.0 } else { 1.0 };
                (0..n)
                    .map(|i| scale * (1.3 * (p + 1) as f64 * (i + 1) as f64 + 0.7 * p as f64).sin())
                    .collect()
            })
            .collect();
        // r(u) = Σ_p (u_p − u0_p) a_p + e with e orthogonal to the free columns: u0 is the optimum
        // of the free parameters with the candidates held, and e pulls every candidate upwards.
        let candidate_u = [0.5, 0.0, 1.0];
        let all = [
            0.5,
            0.5,
            0.5,
            candidate_u[0],
            candidate_u[1],
            candidate_u[2],
        ];
        let mut basis: Vec<Vec<f64>> = Vec::new();
        for col in &columns[..3] {
            let rest = project_out(&basis, col);
            let norm = dot(&rest, &rest).sqrt();
            basis.push(rest.iter().map(|x| x / norm).collect());
        }
        let pull: Vec<f64> = (0..n)
            .map(|i| -(1.0 * columns[3][i] + 0.3 * columns[4][i] + 0.3 * columns[5][i]))
            .collect();
        let e = project_out(&basis, &pull);
        let mut target = Linear {
            params: params.clone(),
            b: vec![0.0; n],
            columns,
            evals: 0,
        };
        let at_u0 = target.at(&all);
        target.b = at_u0.iter().zip(&e).map(|(r, e)| r - e).collect();
        let held_cost = dot(&e, &e);
        let skin = skin_with(&params, &all);
        target.evals = 0;
        let drops = predicted_drops(&mut target, skin, &free, &candidates).unwrap();
        assert_eq!(target.evals, 1 + free.len() + candidates.len());
        for (c, drop) in drops.iter().enumerate() {
            let mut freed = |u: &[f64]| {
                let mut v: Vec<f64> = u[..3].iter().chain(&candidate_u).copied().collect();
                v[3 + c] = u[3];
                Some(target.at(&v))
            };
            let start = [0.5, 0.5, 0.5, candidate_u[c]];
            let fit = minimize(&mut freed, &start, LM_REFERENCE, Vec::new());
            assert!(fit.u[..3].iter().all(|&v| v > 0.0 && v < 1.0), "{fit:?}");
            let exact = held_cost - fit.cost;
            eprintln!(
                "candidate {c}: predicted {drop:.6e}, fitted {exact:.6e}, at {:?}",
                fit.u
            );
            assert!(
                (drop - exact).abs() < 1e-6 * held_cost,
                "{c}: {drop} vs {exact}"
            );
        }
        assert!(drops[0] > 0.0 && drops[1] > 0.0, "{drops:?}");
        assert_eq!(drops[2], 0.0);
    }
}
