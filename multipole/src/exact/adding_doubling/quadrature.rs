//! Angular quadrature in μ = cos θ for adding-doubling: Gauss and Radau rules, and Prahl's split at the
//! critical angle ([Prahl95] §3.3; Radau keeps μ = 1, the normally incident beam, as a node).

use std::f64::consts::PI;

/// Legendre polynomial P_n(x) and its derivative P_n'(x), by the three-term recurrence.
pub(crate) fn legendre_with_derivative(n: usize, x: f64) -> (f64, f64) {
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

/// A one-dimensional quadrature rule: nodes and weights, nodes ascending.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Rule {
    pub(crate) nodes: Vec<f64>,
    pub(crate) weights: Vec<f64>,
}

/// n-point Gauss–Legendre rule on [a, b] (exact for polynomials of degree ≤ 2n − 1; no end point).
pub(crate) fn gauss(n: usize, a: f64, b: f64) -> Rule {
    let mut pairs: Vec<(f64, f64)> = (1..=n)
        .map(|k| {
            let x0 = (PI * (k as f64 - 0.25) / (n as f64 + 0.5)).cos();
            let x = newton(x0, |x| legendre_with_derivative(n, x));
            let (_, dp) = legendre_with_derivative(n, x);
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            (a + (x + 1.0) * 0.5 * (b - a), w * 0.5 * (b - a))
        })
        .collect();
    pairs.sort_by(|p, q| p.0.total_cmp(&q.0));
    Rule {
        nodes: pairs.iter().map(|p| p.0).collect(),
        weights: pairs.iter().map(|p| p.1).collect(),
    }
}

/// n-point Gauss–Radau rule on [a, b] with b a node (exact for degree ≤ 2n − 2).
///
/// On [−1, 1] with the fixed node at −1 the free nodes are the roots of (P_{n−1} + P_n)/(1 + x),
/// weights 2/n² at −1 and (1 − x)/(n² P_{n−1}(x)²) elsewhere; x = −1 is then mapped to b.
pub(crate) fn radau(n: usize, a: f64, b: f64) -> Rule {
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
    pairs.sort_by(|p, q| p.0.total_cmp(&q.0));
    Rule {
        nodes: pairs.iter().map(|p| p.0).collect(),
        weights: pairs.iter().map(|p| p.1).collect(),
    }
}

/// The angular grid inside the slab: `n` nodes in (0, 1], the last one μ = 1.
///
/// With no critical angle (`mu_critical` = 0) it is one Radau rule on [0, 1]. Otherwise, as Prahl does,
/// n/2 Gauss nodes on [0, μc] (directions trapped by total internal reflection) and n/2 Radau nodes on
/// [μc, 1]: the Fresnel transmittance has a kink at μc, and splitting there keeps each piece smooth.
pub(crate) fn slab_rule(n: usize, mu_critical: f64) -> Rule {
    if mu_critical <= 0.0 {
        return radau(n, 0.0, 1.0);
    }
    let below = gauss(n / 2, 0.0, mu_critical);
    let above = radau(n - n / 2, mu_critical, 1.0);
    Rule {
        nodes: below.nodes.iter().chain(&above.nodes).copied().collect(),
        weights: below
            .weights
            .iter()
            .chain(&above.weights)
            .copied()
            .collect(),
    }
}

/// [`slab_rule`] built once per (n, μc) and shared: every wavelength of a spectrum uses the same
/// grid, and the Newton iterations for the nodes cost as much as a small layer solve.
pub(crate) fn slab_rule_cached(n: usize, mu_critical: f64) -> std::sync::Arc<Rule> {
    use std::collections::HashMap;
    use std::sync::{Arc, Mutex, OnceLock};
    type Cache = Mutex<HashMap<(usize, u64), Arc<Rule>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let key = (n, mu_critical.to_bits());
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    // A poisoned lock only means another thread panicked mid-insert of an independent entry.
    if let Some(hit) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Arc::clone(hit);
    }
    let built = Arc::new(slab_rule(n, mu_critical));
    let mut map = cache.lock().unwrap_or_else(|e| e.into_inner());
    Arc::clone(map.entry(key).or_insert(built))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn integrate(r: &Rule, f: impl Fn(f64) -> f64) -> f64 {
        r.nodes
            .iter()
            .zip(&r.weights)
            .map(|(&x, &w)| w * f(x))
            .sum()
    }

    #[test]
    fn gauss_is_exact_to_degree_2n_minus_1() {
        for n in [1, 2, 5, 8, 16, 32] {
            let r = gauss(n, 0.2, 0.9);
            let d = 2 * n - 1;
            let exact = (0.9f64.powi(d as i32 + 1) - 0.2f64.powi(d as i32 + 1)) / (d as f64 + 1.0);
            let got = integrate(&r, |x| x.powi(d as i32));
            assert!(
                (got - exact).abs() < 1e-13 * exact.abs().max(1.0),
                "n {n}: {got} vs {exact}"
            );
        }
    }

    #[test]
    fn radau_is_exact_to_degree_2n_minus_2_and_contains_b() {
        for n in [2, 3, 4, 8, 16, 32] {
            let r = radau(n, 0.3, 1.0);
            assert_eq!(*r.nodes.last().expect("n ≥ 1"), 1.0);
            assert!(
                r.nodes.windows(2).all(|w| w[0] < w[1]),
                "distinct nodes, n {n}"
            );
            assert!(r.nodes[0] > 0.3);
            for d in 0..=(2 * n - 2) {
                let exact = (1.0 - 0.3f64.powi(d as i32 + 1)) / (d as f64 + 1.0);
                let got = integrate(&r, |x| x.powi(d as i32));
                assert!(
                    (got - exact).abs() < 1e-13,
                    "n {n} degree {d}: {got} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn split_rule_integrates_each_side_of_the_critical_angle() {
        let mu_c = (1.0f64 - 1.0 / 1.96).sqrt();
        let r = slab_rule(16, mu_c);
        assert_eq!(r.nodes.len(), 16);
        assert!((r.nodes[7] - mu_c) < 0.0 && r.nodes[8] > mu_c);
        // A function with a kink at μc is integrated exactly when each piece is a polynomial.
        let f = |x: f64| if x < mu_c { x * x } else { 3.0 * x.powi(7) };
        let exact = mu_c.powi(3) / 3.0 + 3.0 * (1.0 - mu_c.powi(8)) / 8.0;
        assert!((integrate(&r, f) - exact).abs() < 1e-13);
    }
}
