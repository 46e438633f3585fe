//! Angular quadrature in μ = cos θ for adding-doubling: Gauss and Radau rules, and Prahl's split at the
//! critical angle ([Prahl95] §3.3; Radau keeps μ = 1, the normally incident beam, as a node).

pub(crate) use brdf::quadrature::{Rule, gauss, legendre_with_derivative, radau};

use super::memo::{Memo, memoized};

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
    static MEMO: Memo<(usize, u64), Rule> = std::sync::OnceLock::new();
    memoized(&MEMO, (n, mu_critical.to_bits()), || {
        slab_rule(n, mu_critical)
    })
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
