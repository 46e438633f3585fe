//! Bounded Levenberg–Marquardt on a unit box, for the extended spectrum fit (module `extended`).
//!
//! Minimises Σ rᵢ(u)² over u ∈ [0, 1]^k with a forward-difference Jacobian. Each step solves the
//! damped normal equations (JᵀJ + λ diag(JᵀJ)) δ = −Jᵀr (Marquardt 1963) and projects onto the box;
//! a coordinate at a bound whose step points outward is held there for that step (a simple active
//! set), so parameters whose best value is "off" (a blood fraction of 0) rest on their bound.
//!
//! Between finite-difference Jacobians (k residual evaluations each) the Jacobian is carried by
//! Broyden's rank-1 update J ← J + (Δr − J δ) δᵀ / δᵀδ after each step, accepted or rejected
//! (Madsen, Nielsen & Tingleff 2004, *Methods for non-linear least squares problems*, §3.4): an
//! iteration then costs one evaluation instead of k + 1. A fresh finite-difference Jacobian is
//! taken every [`LmBudget::broyden_refresh`] accepted steps, after two rejected steps in a row on
//! an updated Jacobian, and before stopping, so the stopping test is always made with a true Jacobian and the descent
//! ends where the reference scheme's does (test `broyden_lands_on_the_reference_optimum`).
//! An accepted step that keeps the direction of the previous iteration's move (cosine above
//! [`EXTEND_COSINE`]) is doubled while the cost keeps falling, one evaluation a try: a line search
//! along the step. Where parameters trade against each other the cost has long, nearly straight
//! valleys in which the damped step falls short of the valley's floor far along it, and the plain
//! descent crawls (BENCHMARKS.md `## Fit`: the eleven-parameter fit, measured).
//!
//! The descent stops when an accepted step lowers the cost by less than [`LmBudget::f_rtol`] of
//! it or by less than [`LmBudget::f_atol`] (a floor the caller derives from the data's noise).
//! k ≤ 12, so the k × k system is solved by Gaussian elimination with partial pivoting here rather
//! than through a linear-algebra crate.

/// Knobs of one minimisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LmBudget {
    /// Most iterations (each one Jacobian: k + 1 residual evaluations, plus rejected trials).
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this fraction.
    pub f_rtol: f64,
    /// Stop when an accepted step lowers the cost by less than this amount (cost units; 0 = only
    /// the relative test): a floor set by the data's noise, below which a lower cost means nothing.
    pub f_atol: f64,
    /// Forward-difference step in unit coordinates.
    pub h: f64,
    /// Accepted steps between finite-difference Jacobians; in between, Broyden rank-1 updates
    /// stand in for them (0 = a finite-difference Jacobian every iteration, the reference scheme).
    pub broyden_refresh: usize,
    /// Extend an accepted step that keeps the previous move's direction by doubling it while the
    /// cost falls (module doc; false = plain Levenberg–Marquardt).
    pub extend: bool,
}

/// The default budget: 1e-4 of each range per difference step is well above the forward model's
/// rounding (~1e-12 in reflectance) and well below any reported digit.
pub(crate) const LM: LmBudget = LmBudget {
    max_iterations: 60,
    f_rtol: 1e-7,
    f_atol: 0.0,
    h: 1e-4,
    broyden_refresh: 4,
    extend: true,
};

/// The reference scheme: a forward-difference Jacobian at every iteration.
#[cfg(test)]
pub(crate) const LM_REFERENCE: LmBudget = LmBudget {
    broyden_refresh: 0,
    ..LM
};

/// Result of [`minimize`]: the point, its cost Σ r², and the residual evaluations spent.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LmResult {
    pub u: Vec<f64>,
    pub cost: f64,
    pub evals: usize,
    /// The last Jacobian (columns), for a warm start of the next descent from `u` (empty when none
    /// was formed).
    pub jac: Vec<Vec<f64>>,
}

/// Minimise Σ r(u)² from `u0` in [0, 1]^k. `residuals` returns `None` where the model fails,
/// which counts as an infinitely bad point. `warm`, a Jacobian at `u0` from an earlier descent
/// (of residuals that differ by a constant, as a re-shifted model's do), stands in for the first
/// finite-difference one when Broyden updates are on; it counts as an updated one, so the stopping
/// test is still made on a true Jacobian.
pub(crate) fn minimize(
    residuals: &mut impl FnMut(&[f64]) -> Option<Vec<f64>>,
    u0: &[f64],
    budget: LmBudget,
    warm: Vec<Vec<f64>>,
) -> LmResult {
    let k = u0.len();
    let mut u: Vec<f64> = u0.iter().map(|v| v.clamp(0.0, 1.0)).collect();
    let mut evals = 1;
    let Some(mut r) = residuals(&u) else {
        return LmResult {
            u,
            cost: f64::INFINITY,
            evals,
            jac: Vec::new(),
        };
    };
    let mut cost = sum_sq(&r);
    let mut lambda = 1e-3;
    let use_warm =
        budget.broyden_refresh > 0 && warm.len() == k && warm.iter().all(|c| c.len() == r.len());
    let mut jac: Vec<Vec<f64>> = if use_warm { warm } else { Vec::new() };
    // Accepted steps since the last finite-difference Jacobian (None: take one now).
    let mut since_fd: Option<usize> = use_warm.then_some(0);
    // Rejected steps in a row on an updated Jacobian.
    let mut rejections = 0;
    // The last accepted iteration's move.
    let mut previous: Option<Vec<f64>> = None;
    for _ in 0..budget.max_iterations {
        let fresh = since_fd.is_none();
        if fresh {
            // Jacobian columns by forward differences (backward at the upper bound).
            jac.clear();
            for j in 0..k {
                let step = if u[j] + budget.h <= 1.0 {
                    budget.h
                } else {
                    -budget.h
                };
                let mut up = u.clone();
                up[j] += step;
                evals += 1;
                let Some(rj) = residuals(&up) else {
                    return LmResult {
                        u,
                        cost,
                        evals,
                        jac: Vec::new(),
                    };
                };
                jac.push(rj.iter().zip(&r).map(|(a, b)| (a - b) / step).collect());
            }
            since_fd = Some(0);
            rejections = 0;
        }
        let jtj =
            |a: usize, b: usize| -> f64 { jac[a].iter().zip(&jac[b]).map(|(x, y)| x * y).sum() };
        let grad: Vec<f64> = (0..k)
            .map(|j| jac[j].iter().zip(&r).map(|(x, y)| x * y).sum())
            .collect();
        let normal: Vec<Vec<f64>> = (0..k)
            .map(|a| (0..k).map(|b| jtj(a, b)).collect())
            .collect();
        let mut improved = false;
        while lambda < 1e10 {
            let Some(trial) = damped_step(&normal, &grad, &u, lambda) else {
                lambda *= 10.0;
                continue;
            };
            evals += 1;
            match residuals(&trial) {
                Some(rt) if sum_sq(&rt) < cost => {
                    let before = cost;
                    let from = u.clone();
                    if budget.broyden_refresh > 0 {
                        broyden_update(&mut jac, &u, &trial, &r, &rt);
                    }
                    let mut step: Vec<f64> = trial.iter().zip(&u).map(|(a, b)| a - b).collect();
                    cost = sum_sq(&rt);
                    (u, r) = (trial, rt);
                    let along = previous
                        .as_ref()
                        .is_some_and(|p: &Vec<f64>| cosine(p, &step) > EXTEND_COSINE);
                    if budget.extend && along {
                        // The descent keeps its direction: a straight valley the damped model
                        // under-steps. Double the step while the cost falls (a line search
                        // along it, one evaluation a try).
                        loop {
                            let ext: Vec<f64> = u
                                .iter()
                                .zip(&step)
                                .map(|(a, d)| (a + 2.0 * d).clamp(0.0, 1.0))
                                .collect();
                            if ext == u {
                                break;
                            }
                            evals += 1;
                            match residuals(&ext) {
                                Some(re) if sum_sq(&re) < cost => {
                                    if budget.broyden_refresh > 0 {
                                        broyden_update(&mut jac, &u, &ext, &r, &re);
                                    }
                                    step = ext.iter().zip(&u).map(|(a, b)| a - b).collect();
                                    cost = sum_sq(&re);
                                    (u, r) = (ext, re);
                                }
                                other => {
                                    if let (Some(re), true) = (other, budget.broyden_refresh > 0) {
                                        broyden_update(&mut jac, &u, &ext, &r, &re);
                                    }
                                    break;
                                }
                            }
                        }
                    }
                    previous = Some(u.iter().zip(&from).map(|(a, b)| a - b).collect());
                    let new_cost = cost;
                    let gain = (before - new_cost) / before.max(f64::MIN_POSITIVE);
                    let progress = gain > budget.f_rtol && before - new_cost > budget.f_atol;
                    lambda = (lambda / 3.0).max(1e-9);
                    rejections = 0;
                    improved = progress;
                    let n = since_fd.map_or(0, |n| n + 1);
                    since_fd =
                        (budget.broyden_refresh > 0 && n < budget.broyden_refresh).then_some(n);
                    break;
                }
                rejected if !fresh => {
                    // An updated Jacobian that fails to descend: learn from the failed step and
                    // damp more; a second failure in a row refreshes it by finite differences.
                    if let Some(rt) = rejected {
                        broyden_update(&mut jac, &u, &trial, &r, &rt);
                    }
                    lambda *= 4.0;
                    rejections += 1;
                    if rejections >= 2 {
                        since_fd = None;
                    }
                    improved = true;
                    break;
                }
                _ => lambda *= 4.0,
            }
        }
        if !improved {
            if fresh || budget.broyden_refresh == 0 {
                break;
            }
            // Too small a gain on an updated Jacobian: check it with a true one before stopping.
            since_fd = None;
        }
    }
    LmResult {
        u,
        cost,
        evals,
        jac,
    }
}

/// Broyden's rank-1 update of the Jacobian columns `jac` for the step `u → v` that moved the
/// residuals `r → rv`: J ← J + (Δr − J δ) δᵀ / δᵀδ, δ = v − u (held coordinates have δ = 0).
fn broyden_update(jac: &mut [Vec<f64>], u: &[f64], v: &[f64], r: &[f64], rv: &[f64]) {
    let delta: Vec<f64> = v.iter().zip(u).map(|(a, b)| a - b).collect();
    let dd = sum_sq(&delta);
    if dd <= 0.0 || !dd.is_finite() {
        return;
    }
    for (i, (a, b)) in rv.iter().zip(r).enumerate() {
        let predicted: f64 = jac.iter().zip(&delta).map(|(col, d)| col[i] * d).sum();
        let c = (a - b - predicted) / dd;
        for (col, d) in jac.iter_mut().zip(&delta) {
            col[i] += c * d;
        }
    }
}

/// Cosine of the angle between two steps above which an accepted step is extended.
const EXTEND_COSINE: f64 = 0.9;

/// Cosine of the angle between `a` and `b` (0 when either is zero).
fn cosine(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let n = (sum_sq(a) * sum_sq(b)).sqrt();
    if n > 0.0 { d / n } else { 0.0 }
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// The projected damped Gauss–Newton point from `u`, holding coordinates at a bound whose step
/// points outward; `None` if the system is singular.
fn damped_step(normal: &[Vec<f64>], grad: &[f64], u: &[f64], lambda: f64) -> Option<Vec<f64>> {
    let k = u.len();
    let mut free: Vec<usize> = (0..k).collect();
    for _ in 0..2 {
        let m = free.len();
        let a: Vec<Vec<f64>> = free
            .iter()
            .map(|&i| {
                free.iter()
                    .map(|&j| {
                        let d = if i == j {
                            lambda * normal[i][i].max(1e-12)
                        } else {
                            0.0
                        };
                        normal[i][j] + d
                    })
                    .collect()
            })
            .collect();
        let b: Vec<f64> = free.iter().map(|&i| -grad[i]).collect();
        let delta = solve(a, b)?;
        let blocked: Vec<usize> = (0..m)
            .filter(|&q| {
                let i = free[q];
                (u[i] <= 0.0 && delta[q] < 0.0) || (u[i] >= 1.0 && delta[q] > 0.0)
            })
            .collect();
        if blocked.is_empty() || m == blocked.len() {
            let mut out = u.to_vec();
            for (q, &i) in free.iter().enumerate() {
                out[i] = (u[i] + delta[q]).clamp(0.0, 1.0);
            }
            return Some(out);
        }
        free = (0..m)
            .filter(|q| !blocked.contains(q))
            .map(|q| free[q])
            .collect();
    }
    None
}

/// Solve the dense system `a x = b` by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-300 || !a[p][c].is_finite() {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        let (pivot_rows, rest) = a.split_at_mut(c + 1);
        let pivot = &pivot_rows[c];
        for (k, row) in rest.iter_mut().enumerate() {
            let f = row[c] / pivot[c];
            for (x, p) in row[c..].iter_mut().zip(&pivot[c..]) {
                *x -= f * p;
            }
            b[c + 1 + k] -= f * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|col| a[row][col] * x[col]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear least-squares problem is solved exactly (to the stopping tolerance), and an optimum
    /// outside the box lands on the bound with the free coordinate still optimal.
    #[test]
    fn solves_linear_problems_and_respects_the_box() {
        // r = (u0 − 0.3, 2(u1 − 0.6), u0 + u1 − 0.9): minimum at (0.3, 0.6), cost 0.
        let mut f = |u: &[f64]| Some(vec![u[0] - 0.3, 2.0 * (u[1] - 0.6), u[0] + u[1] - 0.9]);
        let m = minimize(&mut f, &[0.9, 0.1], LM, Vec::new());
        assert!(
            (m.u[0] - 0.3).abs() < 1e-6 && (m.u[1] - 0.6).abs() < 1e-6,
            "{m:?}"
        );
        // Unconstrained minimum at u0 = −0.5: held at 0, u1 free at 0.7.
        let mut g = |u: &[f64]| Some(vec![u[0] + 0.5, u[1] - 0.7]);
        let m = minimize(&mut g, &[0.5, 0.5], LM, Vec::new());
        assert_eq!(m.u[0], 0.0);
        assert!((m.u[1] - 0.7).abs() < 1e-6, "{m:?}");
    }

    #[test]
    fn rosenbrock_valley_is_followed() {
        // r = (10 (u1 − u0²), 1 − u0) on the box, minimum (1, 1) on the corner... shifted inside:
        // with v = 2u − 0.5 the minimum is at u = (0.75, 0.75).
        let mut f = |u: &[f64]| {
            let (x, y) = (2.0 * u[0] - 0.5, 2.0 * u[1] - 0.5);
            Some(vec![10.0 * (y - x * x), 1.0 - x])
        };
        let m = minimize(
            &mut f,
            &[0.1, 0.9],
            LmBudget {
                max_iterations: 500,
                ..LM
            },
            Vec::new(),
        );
        assert!(
            (m.u[0] - 0.75).abs() < 1e-4 && (m.u[1] - 0.75).abs() < 1e-4,
            "{m:?}"
        );
    }
}
