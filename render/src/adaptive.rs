//! Noise-targeted adaptive sampling: per-pixel sums of XYZ and of squared luminance, the noise of
//! each pixel's mean estimated from its own samples, and the set of pixels still sampled.
//!
//! Three estimates of the error of pixel p's mean ([`ErrorEstimate`]; docs/physics.md §17). From
//! the sample variance: σ̂²/n, σ̂² the unbiased sample variance of the n samples' luminance Y
//! (n − 1 degrees of freedom); right for independent samples, an overstatement for the points of
//! one Sobol sequence, whose mean converges faster than 1/√n. From two independent halves (the
//! even and the odd samples of [`crate::sampler::SamplerKind::SobolPair`]): (Ȳ_A − Ȳ_B)²/4,
//! unbiased for any sampler whose halves are independent (E[(Ȳ_A − Ȳ_B)²]/4 = Var((Ȳ_A + Ȳ_B)/2)),
//! with one degree of freedom per pixel. Calibrated (the default with two halves): ρ·σ̂²/n, the
//! sample variance scaled by ρ = Σ d²/Σ σ̂²/n over a [`CALIBRATION_TILE`]² block, the ratio of the
//! half differences to the sample variance (the Sobol points' efficiency), so the figure is right
//! for Sobol points and has ≈ n − 1 degrees of freedom per pixel and ≈ 256 in ρ.
//!
//! The degrees of freedom matter because a pixel stops the first time its estimate is below the
//! target and keeps that value: with few of them the estimate a pixel stops on is selected low
//! (first passage), and the reported noise with it. Measured on the default scene: the half
//! difference pooled 3×3 (≈ 9 degrees of freedom) reported 22–25% less noise than two seeds gave.
//!
//! The error is divided by max(Ȳ_p, T), T the lit threshold of [`crate::noise`], so the figure
//! is the same relative noise as the two-seed metric on lit pixels and an absolute one, relative
//! to T, in the dark. A pixel stops when the mean squared relative error over its 3×3
//! neighbourhood is below the target²: pooling nine pixels keeps a pixel whose own few samples
//! happened to agree (no firefly seen yet) from stopping early, the source of adaptive sampling's
//! downward bias.
//!
//! The film's `variance` pass keeps σ̂²/n whatever the estimate (smooth, as denoisers expect it);
//! with Sobol points it is an upper bound on the error.

use crate::film::Film;
use crate::noise::lit_threshold;
use crate::sampler::SamplerKind;

/// Fewest samples per pixel before a pixel may stop (a variance from fewer is unreliable).
pub const MIN_SPP: u32 = 16;

/// Edge of the square pixel blocks over which [`ErrorEstimate::Calibrated`] forms its ratio,
/// pixels (a 16 × 16 block: ≈ 256 degrees of freedom in the ratio).
pub const CALIBRATION_TILE: usize = 16;

/// How the error of a pixel's mean is estimated from its samples (docs/physics.md §17).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ErrorEstimate {
    /// σ̂²/n from the sample variance (samples independent).
    SampleVariance,
    /// (Ȳ_A − Ȳ_B)²/4 from the means of the even (A) and the odd (B) samples (halves independent;
    /// one degree of freedom per pixel, so the value a pixel stops on is selected low).
    HalfDifference,
    /// ρ·σ̂²/n, ρ = Σ (Ȳ_A − Ȳ_B)²/4 / Σ σ̂²/n over the pixel's [`CALIBRATION_TILE`]² block, both
    /// sums relative (divided by max(Ȳ, T)²) (halves independent; ≈ n − 1 degrees of freedom per
    /// pixel, ≈ 256 in ρ).
    Calibrated,
}

impl ErrorEstimate {
    /// The default for `sampler`: calibrated where the halves are independent, else the sample
    /// variance.
    #[must_use]
    pub fn for_sampler(sampler: SamplerKind) -> Self {
        match sampler {
            SamplerKind::Sobol => Self::SampleVariance,
            SamplerKind::Independent | SamplerKind::SobolPair => Self::Calibrated,
        }
    }

    /// Whether the estimate needs the even and the odd samples to be independent halves.
    #[must_use]
    pub fn needs_independent_halves(self) -> bool {
        !matches!(self, Self::SampleVariance)
    }
}

/// Per-pixel sample sums of an adaptive render.
#[derive(Debug, Clone, PartialEq)]
pub struct Accumulator {
    width: usize,
    height: usize,
    estimate: ErrorEstimate,
    sum_xyz: Vec<[f64; 3]>,
    sum_y2: Vec<f64>,
    count: Vec<u32>,
    /// Luminance sums and sample counts of the even and the odd samples.
    sum_y_half: Vec<[f64; 2]>,
    count_half: Vec<[u32; 2]>,
    /// Non-finite samples dropped (not in `count` or the sums).
    dropped: u64,
}

impl Accumulator {
    /// Empty sums for `width × height` pixels whose error is estimated by `estimate`.
    #[must_use]
    pub fn new(width: usize, height: usize, estimate: ErrorEstimate) -> Self {
        let n = width * height;
        Self {
            width,
            height,
            estimate,
            sum_xyz: vec![[0.0; 3]; n],
            sum_y2: vec![0.0; n],
            count: vec![0; n],
            sum_y_half: vec![[0.0; 2]; n],
            count_half: vec![[0; 2]; n],
            dropped: 0,
        }
    }

    /// Add pixel `i`'s (row-major) sample number `sample` (its parity picks the half), in XYZ.
    pub fn add(&mut self, i: usize, sample: u32, xyz: [f32; 3]) {
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
        let half = (sample % 2) as usize;
        self.sum_y_half[i][half] += f64::from(xyz[1]);
        self.count_half[i][half] += 1;
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

    /// Samples kept at every pixel (row-major).
    #[must_use]
    pub fn counts(&self) -> &[u32] {
        &self.count
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

    /// (Ȳ_A − Ȳ_B)²/4 of every pixel, the half-difference estimate of its mean's variance (∞ while
    /// a half is empty).
    #[must_use]
    pub fn half_difference2(&self) -> Vec<f64> {
        self.sum_y_half
            .iter()
            .zip(&self.count_half)
            .map(|(s, n)| {
                if n[0] == 0 || n[1] == 0 {
                    return f64::INFINITY;
                }
                let d = s[0] / f64::from(n[0]) - s[1] / f64::from(n[1]);
                0.25 * d * d
            })
            .collect()
    }

    /// Estimated variance of every pixel's mean luminance by the accumulator's [`ErrorEstimate`]
    /// (∞ where it cannot be formed yet).
    #[must_use]
    pub fn error2(&self) -> Vec<f64> {
        let mean = self.mean_luminance();
        self.error2_with(&mean, lit_threshold(&mean))
    }

    /// [`Accumulator::error2`] given the pixels' mean luminance and its lit threshold T.
    fn error2_with(&self, mean: &[f64], t: f64) -> Vec<f64> {
        match self.estimate {
            ErrorEstimate::SampleVariance => self.variance_of_mean(),
            ErrorEstimate::HalfDifference => self.half_difference2(),
            ErrorEstimate::Calibrated => {
                let var = self.variance_of_mean();
                let rho = self.calibration(&self.half_difference2(), &var, mean, t);
                var.iter()
                    .zip(rho)
                    .map(|(&v, r)| if v.is_finite() { v * r } else { v })
                    .collect()
            }
        }
    }

    /// The ratio ρ of [`ErrorEstimate::Calibrated`] at every pixel: Σ h/D² / Σ v/D² over its
    /// [`CALIBRATION_TILE`]² block, h the half-difference and v the sample-variance estimate of
    /// each pixel's variance of the mean, D = max(Ȳ, T) (1 where the block has no variance, whose
    /// pixels then have none to scale).
    fn calibration(&self, half: &[f64], var: &[f64], mean: &[f64], t: f64) -> Vec<f64> {
        let (w, h) = (self.width, self.height);
        let mut rho = vec![1.0; w * h];
        for by in (0..h).step_by(CALIBRATION_TILE) {
            for bx in (0..w).step_by(CALIBRATION_TILE) {
                let block = || {
                    (by..(by + CALIBRATION_TILE).min(h)).flat_map(move |y| {
                        (bx..(bx + CALIBRATION_TILE).min(w)).map(move |x| y * w + x)
                    })
                };
                let (mut num, mut den) = (0.0, 0.0);
                for i in block() {
                    let d = mean[i].max(t);
                    if d > 0.0 && half[i].is_finite() && var[i].is_finite() {
                        num += half[i] / (d * d);
                        den += var[i] / (d * d);
                    }
                }
                if den > 0.0 {
                    for i in block() {
                        rho[i] = num / den;
                    }
                }
            }
        }
        rho
    }

    /// Squared relative error of every pixel, [`Accumulator::error2`]/max(Ȳ, T)², and the lit
    /// threshold T.
    fn relative_error2(&self) -> (Vec<f64>, f64) {
        let mean = self.mean_luminance();
        let t = lit_threshold(&mean);
        let var = self.error2_with(&mean, t);
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

    /// Degrees of freedom pixel `i` adds to a pooled error estimate: n − 1 for the sample
    /// variance and the calibrated estimate, one for the half difference.
    fn degrees_of_freedom(&self, i: usize) -> f64 {
        match self.estimate {
            ErrorEstimate::HalfDifference => 1.0,
            ErrorEstimate::SampleVariance | ErrorEstimate::Calibrated => {
                f64::from(self.count[i].saturating_sub(1))
            }
        }
    }

    /// Stop pixels that have at least `min_spp` samples and whose 3×3 neighbourhood's mean squared
    /// relative error, raised to its one-sided upper confidence bound, is at most `target²`:
    /// ê² (1 + z √(2/k)) ≤ ε², k the pooled degrees of freedom and z `confidence_z`
    /// (docs/physics.md §17). `active[i]` is cleared for them (never set again). Returns the
    /// number of stopped pixels.
    pub fn update_active(
        &self,
        active: &mut [bool],
        target: f64,
        min_spp: u32,
        confidence_z: f64,
    ) -> usize {
        let (e2, _) = self.relative_error2();
        let (w, h) = (self.width, self.height);
        let target2 = target * target;
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if !active[i] || self.count[i] < min_spp {
                    continue;
                }
                let (mut s, mut n, mut k) = (0.0, 0.0, 0.0);
                for yy in y.saturating_sub(1)..(y + 2).min(h) {
                    for xx in x.saturating_sub(1)..(x + 2).min(w) {
                        s += e2[yy * w + xx];
                        n += 1.0;
                        k += self.degrees_of_freedom(yy * w + xx);
                    }
                }
                let bound = 1.0 + confidence_z * (2.0 / k.max(1.0)).sqrt();
                if s / n * bound <= target2 {
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
        Film::from_means(self.width, self.height, mean, var, spp)
            .with_samples(self.count.clone())
            .with_dropped(self.dropped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples alternating 1 and 3: variance 4/3 (n/(n−1) · 1 with n = 4), mean 2.
    #[test]
    fn variance_of_known_samples() {
        let mut acc = Accumulator::new(1, 1, ErrorEstimate::SampleVariance);
        for (k, y) in [1.0, 3.0, 1.0, 3.0].into_iter().enumerate() {
            acc.add(0, k as u32, [0.0, y, 0.0]);
        }
        assert_eq!(acc.mean_luminance(), vec![2.0]);
        let v = acc.variance_of_mean()[0];
        assert!((v - 4.0 / 3.0 / 4.0).abs() < 1e-12, "{v}");
        // Relative error √(1/3)/2 ≈ 0.289.
        assert!((acc.noise_estimate() - (1.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-12);
    }

    /// Even samples 1, 1 and odd samples 3, 3: the half-means differ by 2, so the error of the
    /// mean 2 is estimated as 2²/4 = 1 (relative 1/2), while the sample variance says 4/3/4.
    #[test]
    fn half_difference_of_known_samples() {
        let mut acc = Accumulator::new(1, 1, ErrorEstimate::HalfDifference);
        assert_eq!(acc.error2(), vec![f64::INFINITY]);
        for (k, y) in [1.0, 3.0, 1.0, 3.0].into_iter().enumerate() {
            acc.add(0, k as u32, [0.0, y, 0.0]);
        }
        assert_eq!(acc.error2(), vec![1.0]);
        assert!((acc.noise_estimate() - 0.5).abs() < 1e-12);
        assert!((acc.variance_of_mean()[0] - 1.0 / 3.0).abs() < 1e-12);
    }

    /// A non-finite sample is left out of the pixel's mean and variance and counted, and the
    /// film reports it.
    #[test]
    fn non_finite_samples_are_dropped_and_counted() {
        let mut acc = Accumulator::new(1, 1, ErrorEstimate::SampleVariance);
        for (k, y) in [1.0, f32::NAN, 3.0, f32::INFINITY].into_iter().enumerate() {
            acc.add(0, k as u32, [0.0, y, 0.0]);
        }
        acc.add(0, 4, [f32::NEG_INFINITY, 1.0, 0.0]);
        assert_eq!((acc.count(0), acc.dropped()), (2, 3));
        assert_eq!(acc.mean_luminance(), vec![2.0]);
        let film = acc.to_film();
        assert_eq!(film.dropped_samples(), 3);
        assert_eq!(film.xyz(0, 0)[1], 2.0);
    }

    /// A constant pixel has zero error and stops at `min_spp`, not before.
    #[test]
    fn constant_pixels_stop_at_min_spp() {
        let mut acc = Accumulator::new(2, 2, ErrorEstimate::HalfDifference);
        let mut active = vec![true; 4];
        for k in 0..MIN_SPP {
            for i in 0..4 {
                acc.add(i, k, [0.5; 3]);
            }
            let stopped = acc.update_active(&mut active, 0.01, MIN_SPP, 1.645);
            assert_eq!(stopped, if k + 1 < MIN_SPP { 0 } else { 4 });
        }
    }

    /// The stop asks the estimate's one-sided upper bound to meet the target: a 3 × 3 image of
    /// pixels with samples 1 and 3 (n = 16, σ̂²/n = 1/15 each, relative error² 1/60 at mean 2)
    /// stops at ε² just above 1/60 with z = 0; with z = 1.645 the centre, pooling k = 9 · 15
    /// degrees of freedom, stops once ε² ≥ (1/60)(1 + z √(2/135)), and the corners, pooling
    /// 4 · 15, once ε² ≥ (1/60)(1 + z √(2/60)).
    #[test]
    fn the_stop_bounds_the_estimate_from_above() {
        let mut acc = Accumulator::new(3, 3, ErrorEstimate::SampleVariance);
        for k in 0..16 {
            for i in 0..9 {
                let y = if k % 2 == 0 { 1.0 } else { 3.0 };
                acc.add(i, k, [0.0, y, 0.0]);
            }
        }
        let e2 = 1.0 / 60.0;
        let bound = 1.0 + 1.645 * (2.0f64 / 135.0).sqrt();
        let stops = |eps2: f64, z: f64| {
            let mut active = vec![true; 9];
            acc.update_active(&mut active, eps2.sqrt(), 16, z)
        };
        assert_eq!(stops(e2 * 1.001, 0.0), 9);
        assert_eq!(stops(e2 * 1.001, 1.645), 0);
        assert_eq!(stops(e2 * bound * 0.999, 1.645), 0);
        assert_eq!(stops(e2 * bound * 1.001, 1.645), 1);
        let corners = 1.0 + 1.645 * (2.0f64 / 60.0).sqrt();
        assert_eq!(stops(e2 * corners * 0.999, 1.645), 5);
        assert_eq!(stops(e2 * corners * 1.001, 1.645), 9);
    }

    /// The calibrated estimate scales each pixel's σ̂²/n by its block's Σ h/Σ v: a block whose
    /// half-means agree exactly gets no error, one whose half-means differ by more than the sample
    /// variance says gets that ratio (3 here) times σ̂²/n.
    #[test]
    fn calibrated_estimate_scales_the_sample_variance_by_its_block() {
        let w = 2 * CALIBRATION_TILE;
        let mut acc = Accumulator::new(w, 1, ErrorEstimate::Calibrated);
        // Left block: samples 1, 3, 3, 1 (halves agree: h = 0 ⇒ ρ = 0); right block: 1, 3, 1, 3
        // (h = 1, v = 1/3 ⇒ ρ = 3).
        for x in 0..w {
            let ys = if x < CALIBRATION_TILE {
                [1.0, 3.0, 3.0, 1.0]
            } else {
                [1.0, 3.0, 1.0, 3.0]
            };
            for (k, y) in ys.into_iter().enumerate() {
                acc.add(x, k as u32, [0.0, y, 0.0]);
            }
        }
        let e2 = acc.error2();
        assert_eq!(e2[0], 0.0);
        assert!((e2[w - 1] - 1.0).abs() < 1e-12, "{}", e2[w - 1]);
        // Same per-pixel sums: the film's counts are the accumulator's.
        let film = acc.to_film();
        assert!((0..w).all(|x| film.samples(x, 0) == acc.counts()[x]));
    }

    /// Pixels with different sample counts: the film's `samples` pass holds each count.
    #[test]
    fn film_holds_each_pixels_sample_count() {
        let mut acc = Accumulator::new(3, 1, ErrorEstimate::Calibrated);
        for (i, n) in [2u32, 5, 9].into_iter().enumerate() {
            for k in 0..n {
                acc.add(i, k, [0.0, 1.0, 0.0]);
            }
        }
        acc.add(1, 5, [f32::NAN; 3]);
        let film = acc.to_film();
        assert_eq!(
            (film.samples(0, 0), film.samples(1, 0), film.samples(2, 0)),
            (2, 5, 9)
        );
        assert!((acc.mean_spp() - 16.0 / 3.0).abs() < 1e-12);
    }
}
