//! Gauss–Legendre quadrature nodes and weights (f64), for the deterministic albedo integrals.

use std::f64::consts::PI;

/// Nodes and weights of the n-point Gauss–Legendre rule on [a, b]; exact for polynomials of degree
/// 2n − 1. The nodes are the roots of the Legendre polynomial Pₙ, found by Newton's method from
/// Tricomi's initial guess cos(π (i + 3/4) / (n + 1/2)); 1e-15 accuracy needs a handful of steps.
#[must_use]
pub fn gauss_legendre(n: usize, a: f64, b: f64) -> Vec<(f64, f64)> {
    let half = 0.5 * (b - a);
    let mid = 0.5 * (a + b);
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (p, d) = legendre_and_derivative(n, x);
                dp = d;
                let dx = p / d;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            let (_, d) = legendre_and_derivative(n, x);
            if d.is_finite() {
                dp = d;
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            (mid + half * x, half * w)
        })
        .collect()
}

/// Pₙ(x) and Pₙ'(x) by the three-term recurrence.
fn legendre_and_derivative(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    if n == 0 {
        return (1.0, 0.0);
    }
    for k in 2..=n {
        let k = k as f64;
        let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
    }
    let n = n as f64;
    (p1, n * (x * p1 - p0) / (x * x - 1.0))
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
