//! Gauss–Legendre and Gauss–Radau quadrature (f64): the one rule of the workspace, used by the
//! albedo integrals here, by `multipole`'s inverse Hankel transform and by its adding-doubling
//! angular grid.

use std::f64::consts::PI;

/// A one-dimensional quadrature rule: nodes and weights, nodes ascending.
#[derive(Debug, Clone, PartialEq)]
pub struct Rule {
    /// The nodes, ascending.
    pub nodes: Vec<f64>,
    /// The weight of each node.
    pub weights: Vec<f64>,
}

impl Rule {
    fn from_pairs(mut pairs: Vec<(f64, f64)>) -> Self {
        pairs.sort_by(|p, q| p.0.total_cmp(&q.0));
        Self {
            nodes: pairs.iter().map(|p| p.0).collect(),
            weights: pairs.iter().map(|p| p.1).collect(),
        }
    }
}

/// Legendre polynomial P_n(x) and its derivative P_n'(x), by the three-term recurrence.
///
/// Inline: adding-doubling's phase-function expansion calls it in its per-layer loop.
#[inline]
#[must_use]
pub fn legendre_with_derivative(n: usize, x: f64) -> (f64, f64) {
    if n == 0 {
        return (1.0, 0.0);
    }
    let (mut p_prev, mut p) = (1.0, x);
    for k in 2..=n {
        let kf = k as f64;
        let next = ((2.0 * kf - 1.0) * x * p - (kf - 1.0) * p_prev) / kf;
        p_prev = p;
        p = next;
    }
    let nf = n as f64;
    let dp = if (1.0 - x * x).abs() < 1e-300 {
        // P_n'(±1) = (±1)^(n+1) n(n+1)/2.
        x.powi(n as i32 + 1) * nf * (nf + 1.0) / 2.0
    } else {
        nf * (p_prev - x * p) / (1.0 - x * x)
    };
    (p, dp)
}

/// Newton iteration on f from x0, stopping at machine precision.
fn newton(mut x: f64, f: impl Fn(f64) -> (f64, f64)) -> f64 {
    for _ in 0..100 {
        let (v, dv) = f(x);
        let step = v / dv;
        x -= step;
        if step.abs() < 1e-15 {
            break;
        }
    }
    x
}

/// The n-point Gauss–Legendre rule on [−1, 1] as (node, weight) pairs, nodes descending: the roots
/// of Pₙ by Newton's method from Tricomi's guess cos(π (k − 1/4) / (n + 1/2)), weights
/// 2 / ((1 − x²) Pₙ'(x)²).
#[must_use]
pub fn unit_gauss(n: usize) -> Vec<(f64, f64)> {
    (1..=n)
        .map(|k| {
            let x0 = (PI * (k as f64 - 0.25) / (n as f64 + 0.5)).cos();
            let x = newton(x0, |x| legendre_with_derivative(n, x));
            let (_, dp) = legendre_with_derivative(n, x);
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Nodes and weights of the n-point Gauss–Legendre rule on [a, b] as (node, weight) pairs, nodes
/// descending; exact for polynomials of degree 2n − 1.
#[must_use]
pub fn gauss_legendre(n: usize, a: f64, b: f64) -> Vec<(f64, f64)> {
    unit_gauss(n)
        .into_iter()
        .map(|(x, w)| (a + (x + 1.0) * 0.5 * (b - a), w * 0.5 * (b - a)))
        .collect()
}

/// The n-point Gauss–Legendre rule on [a, b] as a [`Rule`] (nodes ascending; no end point).
#[must_use]
pub fn gauss(n: usize, a: f64, b: f64) -> Rule {
    Rule::from_pairs(gauss_legendre(n, a, b))
}

/// n-point Gauss–Radau rule on [a, b] with b a node (exact for degree ≤ 2n − 2).
///
/// On [−1, 1] with the fixed node at −1 the free nodes are the roots of (P_{n−1} + P_n)/(1 + x),
/// weights 2/n² at −1 and (1 − x)/(n² P_{n−1}(x)²) elsewhere; x = −1 is then mapped to b.
#[must_use]
pub fn radau(n: usize, a: f64, b: f64) -> Rule {
    let nf = n as f64;
    let mut pairs = vec![(b, 2.0 / (nf * nf) * 0.5 * (b - a))];
    for k in 1..n {
        // Chebyshev–Gauss–Radau nodes start Newton next to each Legendre–Radau node.
        let x0 = -(2.0 * PI * k as f64 / (2.0 * nf - 1.0)).cos();
        let x = newton(x0, |x| {
            let (p1, d1) = legendre_with_derivative(n - 1, x);
            let (p2, d2) = legendre_with_derivative(n, x);
            (p1 + p2, d1 + d2)
        });
        let (p_nm1, _) = legendre_with_derivative(n - 1, x);
        let w = (1.0 - x) / (nf * nf * p_nm1 * p_nm1);
        pairs.push((b - (x + 1.0) * 0.5 * (b - a), w * 0.5 * (b - a)));
    }
    Rule::from_pairs(pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_exactly() {
        for n in [1usize, 2, 5, 16, 64, 200] {
            let rule = gauss_legendre(n, 0.0, 2.0);
            let total: f64 = rule.iter().map(|&(_, w)| w).sum();
            assert!((total - 2.0).abs() < 1e-13, "n = {n}: Σw = {total}");
            // x^(2n−1) on [0, 2] integrates to 2^(2n) / (2n).
            let deg = (2 * n - 1).min(40) as i32;
            let exact = 2f64.powi(deg + 1) / f64::from(deg + 1);
            let got: f64 = rule.iter().map(|&(x, w)| w * x.powi(deg)).sum();
            assert!(
                (got - exact).abs() < 1e-11 * exact,
                "n = {n}: {got} vs {exact}"
            );
        }
    }

    #[test]
    fn smooth_function() {
        let got: f64 = gauss_legendre(20, 0.0, PI)
            .iter()
            .map(|&(x, w)| w * x.sin())
            .sum();
        assert!((got - 2.0).abs() < 1e-14);
    }
}
