//! A histogram axis from 0: a first bin [0, x₀), then bins growing geometrically.

/// Bin 0 is [0, x₀); bin i ≥ 1 is [x₀ qⁱ⁻¹, x₀ qⁱ) with q = 10^(1/per decade).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct LogAxis {
    x0: f64,
    ln_q: f64,
    bins: usize,
}

impl LogAxis {
    /// Bins from 0 to at least `x_max` > `x0` > 0, `per_decade` ≥ 1 geometric bins per decade.
    pub(super) fn new(x0: f64, x_max: f64, per_decade: u32) -> Self {
        let per_decade = f64::from(per_decade.max(1));
        let geometric = (per_decade * (x_max / x0).log10()).ceil().max(1.0) as usize;
        Self {
            x0,
            ln_q: std::f64::consts::LN_10 / per_decade,
            bins: 1 + geometric,
        }
    }

    /// Number of bins.
    pub(super) fn bins(&self) -> usize {
        self.bins
    }

    /// The bin holding `x` ≥ 0, or `None` beyond the last.
    #[inline]
    pub(super) fn bin(&self, x: f64) -> Option<usize> {
        let i = if x < self.x0 {
            0
        } else {
            1 + ((x / self.x0).ln() / self.ln_q) as usize
        };
        (i < self.bins).then_some(i)
    }

    /// Lower and upper edge of bin `i`.
    pub(super) fn edges(&self, i: usize) -> (f64, f64) {
        if i == 0 {
            (0.0, self.x0)
        } else {
            let lo = self.x0 * ((i - 1) as f64 * self.ln_q).exp();
            (lo, lo * self.ln_q.exp())
        }
    }

    /// π(hi² − lo²) of bin `i` read as an annulus.
    pub(super) fn annulus_area(&self, i: usize) -> f64 {
        let (lo, hi) = self.edges(i);
        std::f64::consts::PI * (hi - lo) * (hi + lo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_and_edges_agree() {
        let a = LogAxis::new(0.01, 1.0e4, 8);
        assert_eq!(a.bins(), 1 + 48);
        for x in [0.0, 0.005, 0.01, 0.0137, 1.0, 77.0, 9_999.0] {
            let i = a.bin(x).unwrap();
            let (lo, hi) = a.edges(i);
            assert!(
                lo <= x * (1.0 + 1e-12) && x < hi * (1.0 + 1e-12),
                "{x} in [{lo}, {hi})"
            );
        }
        assert_eq!(a.bin(2.0e4), None);
    }
}
