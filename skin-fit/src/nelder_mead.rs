//! Derivative-free minimisation in the unit box: a coarse grid search for the global basin, then
//! Nelder–Mead simplex refinement with bounds enforced by clamping (Nelder & Mead 1965; the standard
//! coefficients of Lagarias et al. 1998: reflection 1, expansion 2, contraction ½, shrink ½).
//!
//! Derivative-free because ΔE2000 has kinks (its hue terms switch branch) and the model is cheap.
//! Clamping can flatten the simplex against a face, so the refinement restarts once from its best
//! vertex with a fresh simplex: the restart costs a few dozen evaluations and rescues those cases.

/// Stopping rule and budget of one Nelder–Mead run.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Budget {
    /// Stop when every vertex lies within this distance (max norm, unit-box coordinates) of the best.
    pub x_tol: f64,
    /// ... and the objective spread over the simplex is below this.
    pub f_tol: f64,
    /// Hard cap on objective evaluations per run.
    pub max_evals: usize,
}

/// Outcome of a minimisation: the best point, its objective value, and the evaluations spent.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Minimum<const N: usize> {
    pub x: [f64; N],
    pub f: f64,
    pub evals: usize,
}

fn clamp_unit<const N: usize>(mut x: [f64; N]) -> [f64; N] {
    for v in &mut x {
        *v = v.clamp(0.0, 1.0);
    }
    x
}

fn lerp<const N: usize>(a: &[f64; N], b: &[f64; N], t: f64) -> [f64; N] {
    std::array::from_fn(|i| a[i] + t * (b[i] - a[i]))
}

/// One Nelder–Mead run in [0, 1]^N from `start`, initial edge `step`.
fn run<const N: usize>(
    f: &mut impl FnMut(&[f64; N]) -> f64,
    start: [f64; N],
    step: f64,
    budget: Budget,
) -> Minimum<N> {
    let mut evals = 0;
    let mut eval = |x: &[f64; N], evals: &mut usize| {
        *evals += 1;
        let v = f(x);
        // A failed evaluation (NaN) must never be chosen.
        if v.is_nan() { f64::INFINITY } else { v }
    };
    let start = clamp_unit(start);
    let mut simplex: Vec<([f64; N], f64)> = Vec::with_capacity(N + 1);
    simplex.push((start, eval(&start, &mut evals)));
    for i in 0..N {
        let mut x = start;
        // Step inward when the start sits on the upper face, so the simplex keeps full dimension.
        x[i] = if x[i] + step <= 1.0 {
            x[i] + step
        } else {
            x[i] - step
        };
        simplex.push((x, eval(&x, &mut evals)));
    }
    loop {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (best, f_best) = simplex[0];
        let f_worst = simplex[N].1;
        let size = simplex[1..]
            .iter()
            .flat_map(|(x, _)| x.iter().zip(&best).map(|(a, b)| (a - b).abs()))
            .fold(0.0, f64::max);
        if evals >= budget.max_evals || (size <= budget.x_tol && f_worst - f_best <= budget.f_tol) {
            return Minimum {
                x: best,
                f: f_best,
                evals,
            };
        }
        let centroid: [f64; N] =
            std::array::from_fn(|i| simplex[..N].iter().map(|(x, _)| x[i]).sum::<f64>() / N as f64);
        let worst = simplex[N].0;
        let xr = clamp_unit(lerp(&centroid, &worst, -1.0));
        let fr = eval(&xr, &mut evals);
        if fr < f_best {
            let xe = clamp_unit(lerp(&centroid, &worst, -2.0));
            let fe = eval(&xe, &mut evals);
            simplex[N] = if fe < fr { (xe, fe) } else { (xr, fr) };
            continue;
        }
        if fr < simplex[N - 1].1 {
            simplex[N] = (xr, fr);
            continue;
        }
        // Contract outside (towards the reflection) or inside (towards the worst vertex).
        let (xc, accept) = if fr < f_worst {
            let xc = clamp_unit(lerp(&centroid, &xr, 0.5));
            (xc, fr)
        } else {
            let xc = clamp_unit(lerp(&centroid, &worst, 0.5));
            (xc, f_worst)
        };
        let fc = eval(&xc, &mut evals);
        if fc < accept {
            simplex[N] = (xc, fc);
            continue;
        }
        // Shrink towards the best vertex.
        for v in simplex.iter_mut().skip(1) {
            let x = lerp(&best, &v.0, 0.5);
            *v = (x, eval(&x, &mut evals));
        }
    }
}

/// Nelder–Mead from `start` with initial edge `step`, then one restart from the best vertex
/// (edge `step / 4`) to recover from a simplex flattened on a face of the box.
pub(crate) fn minimize<const N: usize>(
    f: &mut impl FnMut(&[f64; N]) -> f64,
    start: [f64; N],
    step: f64,
    budget: Budget,
) -> Minimum<N> {
    let first = run(f, start, step, budget);
    let second = run(f, first.x, 0.25 * step, budget);
    let evals = first.evals + second.evals;
    if second.f <= first.f {
        Minimum { evals, ..second }
    } else {
        Minimum { evals, ..first }
    }
}

/// Evaluate `f` on the full tensor grid with `nodes[i]` ≥ 2 equally spaced nodes on [0, 1] per axis,
/// returning every node with its value, sorted best first.
pub(crate) fn grid_search<const N: usize>(
    f: &mut impl FnMut(&[f64; N]) -> f64,
    nodes: [usize; N],
) -> Vec<([usize; N], [f64; N], f64)> {
    let total: usize = nodes.iter().product();
    let mut out = Vec::with_capacity(total);
    for flat in 0..total {
        let mut rest = flat;
        let idx: [usize; N] = std::array::from_fn(|i| {
            let k = rest % nodes[i];
            rest /= nodes[i];
            k
        });
        let x: [f64; N] = std::array::from_fn(|i| idx[i] as f64 / (nodes[i] - 1) as f64);
        let v = f(&x);
        out.push((idx, x, if v.is_nan() { f64::INFINITY } else { v }));
    }
    out.sort_by(|a, b| a.2.total_cmp(&b.2));
    out
}

/// The best `count` grid nodes that are pairwise more than one node apart on some axis
/// (distinct basins rather than neighbours of one minimum), from a sorted [`grid_search`] result.
pub(crate) fn distinct_starts<const N: usize>(
    sorted: &[([usize; N], [f64; N], f64)],
    count: usize,
) -> Vec<[f64; N]> {
    let mut chosen: Vec<[usize; N]> = Vec::new();
    let mut starts = Vec::new();
    for (idx, x, v) in sorted {
        if starts.len() == count || !v.is_finite() {
            break;
        }
        let near = chosen
            .iter()
            .any(|c| c.iter().zip(idx).all(|(a, b)| a.abs_diff(*b) <= 1));
        if !near {
            chosen.push(*idx);
            starts.push(*x);
        }
    }
    starts
}

#[cfg(test)]
mod tests {
    use super::*;

    const TIGHT: Budget = Budget {
        x_tol: 1e-9,
        f_tol: 1e-14,
        max_evals: 2000,
    };

    #[test]
    fn finds_the_minimum_of_a_rotated_quadratic() {
        let target = [0.3, 0.7, 0.45];
        let mut f = |x: &[f64; 3]| {
            let d = [x[0] - target[0], x[1] - target[1], x[2] - target[2]];
            d[0] * d[0] + 10.0 * (d[1] + 0.5 * d[0]).powi(2) + 3.0 * d[2] * d[2]
        };
        let m = minimize(&mut f, [0.9, 0.1, 0.9], 0.2, TIGHT);
        for (a, b) in m.x.iter().zip(target) {
            assert!((a - b).abs() < 1e-6, "{:?}", m.x);
        }
    }

    #[test]
    fn stops_on_the_boundary_when_the_minimum_lies_outside() {
        // Unconstrained minimum at (−0.5, 0.4): the box minimum is (0, 0.4).
        let mut f = |x: &[f64; 2]| (x[0] + 0.5).powi(2) + (x[1] - 0.4).powi(2);
        let m = minimize(&mut f, [0.8, 0.8], 0.2, TIGHT);
        assert!(
            m.x[0].abs() < 1e-6 && (m.x[1] - 0.4).abs() < 1e-5,
            "{:?}",
            m.x
        );
    }

    #[test]
    fn rosenbrock_in_the_box() {
        // Rosenbrock scaled into the unit box: minimum at (0.75, 0.75) ↔ (1, 1) after x ↦ 4x − 2.
        let mut f = |x: &[f64; 2]| {
            let (a, b) = (4.0 * x[0] - 2.0, 4.0 * x[1] - 2.0);
            (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2)
        };
        let m = minimize(&mut f, [0.1, 0.9], 0.1, TIGHT);
        assert!(
            (m.x[0] - 0.75).abs() < 1e-5 && (m.x[1] - 0.75).abs() < 1e-5,
            "{:?}",
            m.x
        );
    }

    #[test]
    fn grid_search_orders_nodes_and_picks_distinct_basins() {
        // Two wells, at 0.0 and 1.0; the deeper one at 1.0.
        let mut f = |x: &[f64; 1]| (x[0] * (1.0 - x[0])) - 0.1 * x[0];
        let g = grid_search(&mut f, [11]);
        assert_eq!(g.len(), 11);
        assert_eq!(g[0].1, [1.0]);
        let starts = distinct_starts(&g, 2);
        assert_eq!(starts, vec![[1.0], [0.0]]);
    }
}
