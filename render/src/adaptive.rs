//! Noise-targeted adaptive sampling: per-pixel sums of XYZ and of squared luminance, the noise of
//! each pixel's mean estimated from its own samples, and the set of pixels still sampled.
//!
//! The error of pixel p's mean after n samples is σ̂/√n, with σ̂² the unbiased sample variance of
//! the samples' luminance Y (n − 1 degrees of freedom; a half-buffer difference |A − B|/2 has one).
//! It is divided by max(Ȳ_p, T), T the lit threshold of [`crate::noise`], so the figure is the same
//! relative noise as the two-seed metric on lit pixels and an absolute one, relative to T, in the
//! dark. A pixel stops when the mean squared relative error over its 3×3 neighbourhood is below the
//! target²: pooling nine pixels keeps a pixel whose own few samples happened to agree (no firefly
//! seen yet) from stopping early, the source of adaptive sampling's downward bias.

use crate::film::Film;
use crate::noise::lit_threshold;

/// Fewest samples per pixel before a pixel may stop (a variance from fewer is unreliable).
pub const MIN_SPP: u32 = 16;

/// Per-pixel sample sums of an adaptive render.
#[derive(Debug, Clone, PartialEq)]
pub struct Accumulator {
    width: usize,
    height: usize,
    sum_xyz: Vec<[f64; 3]>,
    sum_y2: Vec<f64>,
    count: Vec<u32>,
    /// Non-finite samples dropped (not in `count` or the sums).
    dropped: u64,
}

impl Accumulator {
    /// Empty sums for `width × height` pixels.
    #[must_use]
    pub fn new(width: usize, height: usize) -> Self {
        let n = width * height;
        Self {
            width,
            height,
            sum_xyz: vec![[0.0; 3]; n],
            sum_y2: vec![0.0; n],
            count: vec![0; n],
            dropped: 0,
        }
    }

    /// Add one XYZ sample to pixel `i` (row-major).
    pub fn add(&mut self, i: usize, xyz: [f32; 3]) {
        // A non-finite sample is dropped and counted, as the film does, so no NaN or infinity
        // reaches the image or the stopping rule; the pixel averages the samples it kept.
        if !xyz.iter().all(|c| c.is_finite()) {
            self.dropped += 1;
            return;
        }
        for (sum, v) in self.sum_xyz[i].iter_mut().zip(xyz) {
            *sum += f64::from(v);
        }
        self.sum_y2[i] += f64::from(xyz[1]).powi(2);
        self.count[i] += 1;
    }

    /// Non-finite samples dropped so far, over all pixels.
    #[must_use]
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Samples kept at pixel `i`.
    #[must_use]
    pub fn count(&self, i: usize) -> u32 {
        self.count[i]
    }

    /// Mean samples per pixel.
    #[must_use]
    pub fn mean_spp(&self) -> f64 {
        self.count.iter().map(|&c| f64::from(c)).sum::<f64>() / self.count.len().max(1) as f64
    }

    /// Mean luminance Y of every pixel.
    #[must_use]
    pub fn mean_luminance(&self) -> Vec<f64> {
        self.sum_xyz
            .iter()
            .zip(&self.count)
            .map(|(s, &n)| s[1] / f64::from(n.max(1)))
            .collect()
    }

    /// Estimated variance of every pixel's mean luminance, σ̂²/n (∞ below two samples).
    #[must_use]
    pub fn variance_of_mean(&self) -> Vec<f64> {
        (0..self.count.len())
            .map(|i| {
                let n = f64::from(self.count[i]);
                if n < 2.0 {
                    return f64::INFINITY;
                }
                let mean = self.sum_xyz[i][1] / n;
                let var = ((self.sum_y2[i] / n - mean * mean) * n / (n - 1.0)).max(0.0);
                var / n
            })
            .collect()
    }

    /// Squared relative error of every pixel, σ̂²/(n · max(Ȳ, T)²), and the lit threshold T.
    fn relative_error2(&self) -> (Vec<f64>, f64) {
        let mean = self.mean_luminance();
        let t = lit_threshold(&mean);
        let var = self.variance_of_mean();
        let e2 = var
            .iter()
            .zip(&mean)
            .map(|(v, m)| {
                let d = m.max(t);
                if d > 0.0 { v / (d * d) } else { 0.0 }
            })
            .collect();
        (e2, t)
    }

    /// Estimated RMS relative noise of the image over its lit pixels: the two-seed metric of
    /// [`crate::noise`] predicted from one render.
    #[must_use]
    pub fn noise_estimate(&self) -> f64 {
        let (e2, t) = self.relative_error2();
        let mean = self.mean_luminance();
        let (mut s, mut n) = (0.0, 0usize);
        for (e, m) in e2.iter().zip(&mean) {
            if *m > 0.0 && *m >= t && e.is_finite() {
                s += e;
                n += 1;
            }
        }
        if n == 0 { 0.0 } else { (s / n as f64).sqrt() }
    }

    /// Stop pixels that have at least `min_spp` samples and whose 3×3 neighbourhood's mean squared
    /// relative error is at most `target²`; `active[i]` is cleared for them (never set again).
    /// Returns the number of stopped pixels.
    pub fn update_active(&self, active: &mut [bool], target: f64, min_spp: u32) -> usize {
        let (e2, _) = self.relative_error2();
        let (w, h) = (self.width, self.height);
        let target2 = target * target;
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if !active[i] || self.count[i] < min_spp {
                    continue;
                }
                let (mut s, mut n) = (0.0, 0.0);
                for yy in y.saturating_sub(1)..(y + 2).min(h) {
                    for xx in x.saturating_sub(1)..(x + 2).min(w) {
                        s += e2[yy * w + xx];
                        n += 1.0;
                    }
                }
                if s / n <= target2 {
                    active[i] = false;
                }
            }
        }
        active.iter().filter(|a| !**a).count()
    }

    /// The film of the pixels' means.
    #[must_use]
    pub fn to_film(&self) -> Film {
        let mean = self
            .sum_xyz
            .iter()
            .zip(&self.count)
            .map(|(s, &n)| s.map(|v| v / f64::from(n.max(1))))
            .collect();
        let var = self
            .variance_of_mean()
            .into_iter()
            .map(|v| if v.is_finite() { v } else { 0.0 })
            .collect();
        let spp = self.count.iter().copied().max().unwrap_or(0);
        Film::from_means(self.width, self.height, mean, var, spp).with_dropped(self.dropped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples alternating 1 and 3: variance 4/3 (n/(n−1) · 1 with n = 4), mean 2.
    #[test]
    fn variance_of_known_samples() {
        let mut acc = Accumulator::new(1, 1);
        for y in [1.0, 3.0, 1.0, 3.0] {
            acc.add(0, [0.0, y, 0.0]);
        }
        assert_eq!(acc.mean_luminance(), vec![2.0]);
        let v = acc.variance_of_mean()[0];
        assert!((v - 4.0 / 3.0 / 4.0).abs() < 1e-12, "{v}");
        // Relative error √(1/3)/2 ≈ 0.289.
        assert!((acc.noise_estimate() - (1.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-12);
    }

    /// A non-finite sample is left out of the pixel's mean and variance and counted, and the
    /// film reports it.
    #[test]
    fn non_finite_samples_are_dropped_and_counted() {
        let mut acc = Accumulator::new(1, 1);
        for y in [1.0, f32::NAN, 3.0, f32::INFINITY] {
            acc.add(0, [0.0, y, 0.0]);
        }
        acc.add(0, [f32::NEG_INFINITY, 1.0, 0.0]);
        assert_eq!((acc.count(0), acc.dropped()), (2, 3));
        assert_eq!(acc.mean_luminance(), vec![2.0]);
        let film = acc.to_film();
        assert_eq!(film.dropped_samples(), 3);
        assert_eq!(film.xyz(0, 0)[1], 2.0);
    }

    /// A constant pixel has zero error and stops at `min_spp`, not before.
    #[test]
    fn constant_pixels_stop_at_min_spp() {
        let mut acc = Accumulator::new(2, 2);
        let mut active = vec![true; 4];
        for k in 0..MIN_SPP {
            for i in 0..4 {
                acc.add(i, [0.5; 3]);
            }
            let stopped = acc.update_active(&mut active, 0.01, MIN_SPP);
            assert_eq!(stopped, if k + 1 < MIN_SPP { 0 } else { 4 });
        }
    }
}
