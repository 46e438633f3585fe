//! Radius sampling of a tabulated radial density p(r) = 2πr R(r) (docs/physics.md §8), generic over
//! f32 (the renderer's tables) and f64 (`Profile`): the one implementation of the CDF and its
//! inversion.
//!
//! Between nodes p is linear in r, so the CDF is piecewise quadratic and inverted exactly; below
//! the first radius p rises linearly from p(0) = 0. [`invert`] and [`density`] are exactly
//! consistent with [`cumulative`].

use num_traits::Float;

/// Cumulative ∫₀^{r_i} p dr at each node (`radii` increasing, mm; `p` per mm, one value per radius
/// used: the result has `p.len()` entries): the trapezoid rule, exact for the linear model.
pub fn cumulative<T: Float>(radii: &[T], p: &[T]) -> Vec<T> {
    let half = T::from(0.5).unwrap_or_else(T::zero);
    let mut acc = half * radii[0] * p[0];
    let mut out = Vec::with_capacity(p.len());
    out.push(acc);
    for i in 1..p.len() {
        acc = acc + half * (radii[i] - radii[i - 1]) * (p[i] + p[i - 1]);
        out.push(acc);
    }
    out
}

/// The radius (mm) where the cumulative `cdf` of the density `p` on `radii` reaches `target`;
/// the last radius when `target` is at or beyond the table's integral. All three slices have the
/// same length (≥ 1).
pub fn invert<T: Float>(radii: &[T], p: &[T], cdf: &[T], target: T) -> T {
    let n = radii.len();
    if target >= cdf[n - 1] {
        return radii[n - 1];
    }
    let two = T::one() + T::one();
    let half = T::one() / two;
    let i = cdf.partition_point(|&c| c < target);
    let (r0, c0, p0) = if i == 0 {
        (T::zero(), T::zero(), T::zero())
    } else {
        (radii[i - 1], cdf[i - 1], p[i - 1])
    };
    let (r1, p1) = (radii[i], p[i]);
    let h = r1 - r0;
    // Within the segment p(t) = p0 + (p1 − p0) t/h; solve p0 t + (p1 − p0) t²/(2h) = target − c0.
    let need = (target - c0).max(T::zero());
    let a = half * (p1 - p0) / h;
    let linear_tol = T::from(1e-14).unwrap_or_else(T::epsilon);
    let tiny = T::from(1e-300).unwrap_or_else(T::zero);
    let t = if a.abs() < linear_tol * p0.max(p1).max(tiny) / h {
        if p0 > T::zero() { need / p0 } else { T::zero() }
    } else {
        let disc = (p0 * p0 + two * two * a * need).max(T::zero());
        // Stable root of a t² + p0 t − need = 0.
        let denom = p0 + disc.sqrt();
        if denom > T::zero() {
            two * need / denom
        } else {
            T::zero()
        }
    };
    r0 + t.max(T::zero()).min(h)
}

/// The density p at `r` (mm): linear between nodes, linear from 0 below the first radius, 0 for
/// NaN, negative `r` or beyond the last radius.
pub fn density<T: Float>(radii: &[T], p: &[T], r: T) -> T {
    let n = radii.len();
    if r.is_nan() || r < T::zero() || r > radii[n - 1] {
        return T::zero();
    }
    let i = radii.partition_point(|&x| x < r);
    if i == 0 {
        return p[0] * r / radii[0];
    }
    let t = (r - radii[i - 1]) / (radii[i] - radii[i - 1]);
    p[i - 1] + t * (p[i] - p[i - 1])
}
