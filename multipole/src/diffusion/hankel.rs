//! The inverse order-0 Hankel transform f(r) = (1/2π) ∫₀^∞ F(q) J0(qr) q dq (docs/physics.md §5).
//!
//! Method (chosen for speed with a measured error; see `DiffusionOptions` and `skin::profile_error`):
//! only the *remainder* of a stack's spectrum is inverted numerically; the slowest-decaying part (the
//! top layer's first source pair) is added back in closed form in r by `profile`. The remainder decays
//! like e^(−a q) with a ≳ the smallest inter-layer path (≈ 0.3–0.5 mm for skin), so it needs q only up
//! to a few hundred rad/mm. The integral runs over Gauss–Legendre panels of width 2π/ρ in q
//! (one oscillation of J0 at the window radius ρ), n nodes each, up to a cutoff Q where
//! |F(Q)| Q² falls below a tolerance times the peak of |F(q)| q². Radii are x_j ρ with
//! x_j = (j/(m−1))², denser near r = 0 where the remainder varies fastest.
//!
//! The key to speed: in u = qρ the nodes, weights and J0(u_k x_j) do not depend on ρ, so the kernel
//! table w_k u_k J0(u_k x_j) is built once per (n, m) and shared by every wavelength and skin
//! ([`HankelTable::shared`]); an inversion is then one F evaluation per node and a matrix–vector product.

use std::f64::consts::PI;
use std::sync::{Arc, Mutex, OnceLock};

/// Largest number of 2π panels in u = qρ held by a table (Qρ ≤ 2π·1024 ≈ 6400).
pub const MAX_PANELS: usize = 1024;

/// A precomputed inverse-Hankel quadrature on normalised grids (module doc).
#[derive(Debug)]
pub struct HankelTable {
    nodes_per_panel: usize,
    x: Vec<f64>,
    u: Vec<f64>,
    kernel: Vec<f64>,
}

/// Gauss–Legendre nodes and weights on [−1, 1] ([`brdf::quadrature::unit_gauss`], nodes descending).
#[must_use]
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    brdf::quadrature::unit_gauss(n).into_iter().unzip()
}

impl HankelTable {
    /// Build a table with `nodes_per_panel` Gauss nodes per 2π panel and `radii` output radii.
    #[must_use]
    pub fn new(nodes_per_panel: usize, radii: usize) -> Self {
        let n = nodes_per_panel.max(1);
        let m = radii.max(2);
        let (gx, gw) = gauss_legendre(n);
        let mut u = Vec::with_capacity(MAX_PANELS * n);
        let mut wu = Vec::with_capacity(MAX_PANELS * n);
        for p in 0..MAX_PANELS {
            let a = 2.0 * PI * p as f64;
            for (xi, wi) in gx.iter().zip(&gw) {
                let uk = a + PI * (xi + 1.0);
                u.push(uk);
                wu.push(PI * wi * uk);
            }
        }
        let x: Vec<f64> = (0..m)
            .map(|j| (j as f64 / (m - 1) as f64).powi(2))
            .collect();
        let mut kernel = Vec::with_capacity(m * u.len());
        for &xj in &x {
            kernel.extend(u.iter().zip(&wu).map(|(&uk, &wk)| wk * libm::j0(uk * xj)));
        }
        Self {
            nodes_per_panel: n,
            x,
            u,
            kernel,
        }
    }

    /// The table for (`nodes_per_panel`, `radii`), built on first use and shared afterwards.
    #[must_use]
    pub fn shared(nodes_per_panel: usize, radii: usize) -> Arc<HankelTable> {
        static CACHE: OnceLock<Mutex<Vec<Arc<HankelTable>>>> = OnceLock::new();
        let cache = CACHE.get_or_init(|| Mutex::new(Vec::new()));
        // A poisoned lock only means another thread panicked mid-insert; the Vec is still valid.
        let mut guard = cache.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(t) = guard
            .iter()
            .find(|t| t.nodes_per_panel == nodes_per_panel.max(1) && t.x.len() == radii.max(2))
        {
            return Arc::clone(t);
        }
        let t = Arc::new(Self::new(nodes_per_panel, radii));
        guard.push(Arc::clone(&t));
        t
    }

    /// Normalised output radii x_j in [0, 1] (radius = x_j × window).
    #[must_use]
    pub fn unit_radii(&self) -> &[f64] {
        &self.x
    }

    /// f(x_j ρ) for window `window_mm` = ρ, from F evaluated at the nodes q ≤ `q_max` (rad/mm); mm⁻²
    /// when F is dimensionless. Returns the values and the number of F evaluations.
    pub fn invert(
        &self,
        window_mm: f64,
        q_max: f64,
        mut f: impl FnMut(f64) -> f64,
    ) -> (Vec<f64>, usize) {
        let n = self.nodes_per_panel;
        let panels = ((q_max * window_mm / (2.0 * PI)).ceil() as usize).clamp(1, MAX_PANELS);
        let k = panels * n;
        let fq: Vec<f64> = self.u[..k].iter().map(|&uk| f(uk / window_mm)).collect();
        let total = self.u.len();
        let scale = 1.0 / (2.0 * PI * window_mm * window_mm);
        let out = (0..self.x.len())
            .map(|j| {
                let row = &self.kernel[j * total..j * total + k];
                scale * row.iter().zip(&fq).map(|(a, b)| a * b).sum::<f64>()
            })
            .collect();
        (out, k)
    }
}

/// The frequency Q (rad/mm) beyond which |F(q)| q² stays below `tolerance` times its peak, found by a
/// geometric scan from `q_start` (factor 1.25) up to `q_limit`. Assumes F decays monotonically in its
/// tail, as every diffusion spectrum does (sums of e^(−z s)).
pub fn frequency_cutoff(
    mut f: impl FnMut(f64) -> f64,
    q_start: f64,
    q_limit: f64,
    tolerance: f64,
) -> f64 {
    let mut q = q_start.max(1e-6);
    let mut peak: f64 = 0.0;
    while q < q_limit {
        let v = (f(q) * q * q).abs();
        peak = peak.max(v);
        if v <= tolerance * peak && q > 4.0 * q_start {
            return q;
        }
        q *= 1.25;
    }
    q_limit
}

/// Shape-preserving cubic interpolant (Fritsch–Carlson PCHIP) through (xs, ys), xs increasing;
/// slopes are computed once, so each evaluation is a binary search and one cubic.
#[derive(Debug, Clone, PartialEq)]
pub struct Pchip {
    xs: Vec<f64>,
    ys: Vec<f64>,
    slopes: Vec<f64>,
}

impl Pchip {
    /// Interpolant through the nodes (xs strictly increasing, same length as ys).
    #[must_use]
    pub fn new(xs: Vec<f64>, ys: Vec<f64>) -> Self {
        let n = xs.len().min(ys.len());
        let delta: Vec<f64> = (0..n.saturating_sub(1))
            .map(|k| (ys[k + 1] - ys[k]) / (xs[k + 1] - xs[k]))
            .collect();
        let slopes = (0..n)
            .map(|k| {
                if n < 2 {
                    0.0
                } else if k == 0 {
                    delta[0]
                } else if k == n - 1 {
                    delta[n - 2]
                } else {
                    let (d0, d1) = (delta[k - 1], delta[k]);
                    if d0 * d1 <= 0.0 {
                        0.0
                    } else {
                        let (h0, h1) = (xs[k] - xs[k - 1], xs[k + 1] - xs[k]);
                        let (w1, w2) = (2.0 * h1 + h0, h1 + 2.0 * h0);
                        (w1 + w2) / (w1 / d0 + w2 / d1)
                    }
                }
            })
            .collect();
        Self { xs, ys, slopes }
    }

    /// Value at `x`; constant extrapolation outside [xs₀, xs_last].
    #[must_use]
    pub fn eval(&self, x: f64) -> f64 {
        let (xs, ys) = (&self.xs, &self.ys);
        let n = xs.len();
        if n == 0 {
            return 0.0;
        }
        if x <= xs[0] || n == 1 {
            return ys[0];
        }
        if x >= xs[n - 1] {
            return ys[n - 1];
        }
        let i = xs.partition_point(|&v| v <= x) - 1;
        let h = xs[i + 1] - xs[i];
        let t = (x - xs[i]) / h;
        let (t2, t3) = (t * t, t * t * t);
        (2.0 * t3 - 3.0 * t2 + 1.0) * ys[i]
            + (t3 - 2.0 * t2 + t) * h * self.slopes[i]
            + (-2.0 * t3 + 3.0 * t2) * ys[i + 1]
            + (t3 - t2) * h * self.slopes[i + 1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diffusion::{dipole::Dipole, medium::Medium};
    use approx::assert_relative_eq;

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        let (x, w) = gauss_legendre(8);
        let s: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(14)).sum();
        assert_relative_eq!(s, 2.0 / 15.0, max_relative = 1e-13);
    }

    #[test]
    fn inverts_the_dipole_transform_to_its_closed_form() {
        // Invert the whole dipole R̂(q) (no closed-form subtraction): it must reproduce R(r).
        // Tolerance: 1e-6 of R(0) absolute at every radius (σa = 0.1, σs' = 1, η = 1.4).
        let d = Dipole::new(Medium::new(0.1, 1.0).unwrap(), 1.4).unwrap();
        let table = HankelTable::new(8, 48);
        let window = d.radius_for_energy(0.9999);
        let q_max = frequency_cutoff(|q| d.transform(q), 0.1 / window, 1e4, 1e-12);
        let (f, _) = table.invert(window, q_max, |q| d.transform(q));
        let r0 = d.reflectance_mm2(0.0);
        for (xj, fj) in table.unit_radii().iter().zip(&f) {
            let r = xj * window;
            assert!(
                (fj - d.reflectance_mm2(r)).abs() < 1e-6 * r0,
                "r = {r}: {fj} vs {}",
                d.reflectance_mm2(r)
            );
        }
    }

    #[test]
    fn pchip_reproduces_nodes_and_is_monotone() {
        let p = Pchip::new(vec![0.0, 1.0, 2.0, 4.0], vec![1.0, 0.5, 0.2, 0.0]);
        assert_eq!(p.eval(2.0), 0.2);
        let mut last = f64::INFINITY;
        for i in 0..=400 {
            let v = p.eval(i as f64 * 0.01);
            assert!(v <= last + 1e-15);
            last = v;
        }
    }
}
