//! What one batch of photons scores, and how independent batches become means with standard errors.

use crate::error::{MultipoleError, check_range};

/// How the annuli of a [`RadialGrid`] are spaced.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Spacing {
    /// Annuli of equal width, mm.
    Uniform { dr_mm: f64 },
    /// A disc of radius `r0_mm`, then annuli whose outer radii grow by e^`ln_ratio` each.
    Geometric { r0_mm: f64, ln_ratio: f64 },
}

/// The radial grid of R_d(r): uniform annuli from r = 0, or a central disc and geometric annuli
/// (the shape tables of `skin::exact_profile`, which span 10⁻³ to 10 mm with few photons per bin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadialGrid {
    spacing: Spacing,
    bins: usize,
}

impl Default for RadialGrid {
    /// 0.01 mm × 1000 bins: resolves the epidermal peak and reaches 10 mm (the dermal tail of red light).
    fn default() -> Self {
        Self {
            spacing: Spacing::Uniform { dr_mm: 0.01 },
            bins: 1000,
        }
    }
}

impl RadialGrid {
    /// A grid of `bins` in [1, 1e6] annuli, each `dr_mm` in (0, 100] mm wide.
    pub fn new(dr_mm: f64, bins: usize) -> Result<Self, MultipoleError> {
        check_range(
            "radial bin width (mm)",
            dr_mm,
            f64::MIN_POSITIVE,
            100.0,
            "(0, 100] mm",
        )?;
        check_range("radial bins", bins as f64, 1.0, 1.0e6, "[1, 1e6]")?;
        Ok(Self {
            spacing: Spacing::Uniform { dr_mm },
            bins,
        })
    }

    /// A disc of radius `r0_mm` then `bins − 1` geometric annuli out to `r_max_mm`
    /// (1e-6 ≤ r0 < r_max ≤ 1000 mm, bins in [2, 1e6]).
    pub fn geometric(r0_mm: f64, r_max_mm: f64, bins: usize) -> Result<Self, MultipoleError> {
        check_range(
            "first radius (mm)",
            r0_mm,
            1.0e-6,
            1000.0,
            "[1e-6, 1000] mm",
        )?;
        check_range(
            "outer radius (mm)",
            r_max_mm,
            r0_mm * (1.0 + 1e-9),
            1000.0,
            "(r0, 1000] mm",
        )?;
        check_range("radial bins", bins as f64, 2.0, 1.0e6, "[2, 1e6]")?;
        Ok(Self {
            spacing: Spacing::Geometric {
                r0_mm,
                ln_ratio: (r_max_mm / r0_mm).ln() / (bins - 1) as f64,
            },
            bins,
        })
    }

    /// Number of annuli.
    #[must_use]
    pub fn bins(&self) -> usize {
        self.bins
    }
    /// Inner radius of annulus `i`, mm.
    #[must_use]
    pub fn inner_mm(&self, i: usize) -> f64 {
        match self.spacing {
            Spacing::Uniform { dr_mm } => i as f64 * dr_mm,
            Spacing::Geometric { .. } if i == 0 => 0.0,
            Spacing::Geometric { r0_mm, ln_ratio } => r0_mm * ((i - 1) as f64 * ln_ratio).exp(),
        }
    }
    /// Outer radius of annulus `i`, mm.
    #[must_use]
    pub fn outer_mm(&self, i: usize) -> f64 {
        match self.spacing {
            Spacing::Uniform { dr_mm } => (i + 1) as f64 * dr_mm,
            Spacing::Geometric { r0_mm, ln_ratio } => r0_mm * (i as f64 * ln_ratio).exp(),
        }
    }
    /// Outer radius of the grid, mm.
    #[must_use]
    pub fn r_max_mm(&self) -> f64 {
        self.outer_mm(self.bins - 1)
    }
    /// Representative radius of annulus `i`, mm: the middle of a uniform annulus, the geometric
    /// mean of a geometric one's radii, half the radius of the central disc.
    #[must_use]
    pub fn r_mid_mm(&self, i: usize) -> f64 {
        match self.spacing {
            Spacing::Uniform { .. } => 0.5 * (self.inner_mm(i) + self.outer_mm(i)),
            Spacing::Geometric { r0_mm, .. } if i == 0 => 0.5 * r0_mm,
            Spacing::Geometric { .. } => (self.inner_mm(i) * self.outer_mm(i)).sqrt(),
        }
    }
    /// Area of annulus `i`, π(r_out² − r_in²), mm².
    #[must_use]
    pub fn annulus_area_mm2(&self, i: usize) -> f64 {
        let (a, b) = (self.inner_mm(i), self.outer_mm(i));
        std::f64::consts::PI * (b - a) * (b + a)
    }
    /// The annulus holding radius `r_mm` ≥ 0, or `None` beyond the grid.
    #[inline(always)]
    #[must_use]
    pub fn bin(&self, r_mm: f64) -> Option<usize> {
        let i = match self.spacing {
            Spacing::Uniform { dr_mm } => (r_mm / dr_mm) as usize,
            Spacing::Geometric { r0_mm, .. } if r_mm < r0_mm => 0,
            Spacing::Geometric { r0_mm, ln_ratio } => 1 + ((r_mm / r0_mm).ln() / ln_ratio) as usize,
        };
        (i < self.bins).then_some(i)
    }
}

/// Raw weight sums of one batch (all per batch, not yet divided by its photon count).
#[derive(Debug, Clone)]
pub(crate) struct BatchTally {
    pub photons: u64,
    pub diffuse_reflectance: f64,
    pub transmittance: f64,
    /// Weight deposited by implicit capture, per layer.
    pub absorbed_by_layer: Vec<f64>,
    /// Weight removed by roulette deaths minus weight added to survivors (zero in expectation).
    pub roulette_balance: f64,
    /// Escaping weight per annulus.
    pub radial: Vec<f64>,
    /// Escaping weight beyond the grid's outer radius.
    pub beyond_grid: f64,
    /// Scattering events, for speed figures (events per second).
    pub interactions: u64,
}

impl BatchTally {
    pub fn new(layers: usize, bins: usize) -> Self {
        Self {
            photons: 0,
            diffuse_reflectance: 0.0,
            transmittance: 0.0,
            absorbed_by_layer: vec![0.0; layers],
            roulette_balance: 0.0,
            radial: vec![0.0; bins],
            beyond_grid: 0.0,
            interactions: 0,
        }
    }

    fn absorbed(&self) -> f64 {
        self.absorbed_by_layer.iter().sum::<f64>() + self.roulette_balance
    }
}

/// A Monte Carlo estimate: mean and its standard error from the spread of independent batches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Mean over all photons.
    pub mean: f64,
    /// Standard error of the mean, sd(batch means) / √batches.
    pub stderr: f64,
}

impl Estimate {
    /// Mean and standard error of equally sized batch values, combined in order (deterministic).
    pub fn from_batches(values: impl Iterator<Item = f64> + Clone) -> Self {
        let (mut n, mut sum) = (0usize, 0.0);
        for v in values.clone() {
            n += 1;
            sum += v;
        }
        let mean = sum / n as f64;
        let ss: f64 = values.map(|v| (v - mean) * (v - mean)).sum();
        let stderr = if n > 1 {
            (ss / ((n - 1) as f64 * n as f64)).sqrt()
        } else {
            f64::NAN
        };
        Self { mean, stderr }
    }

    /// Number of standard errors between this estimate and `reference` (an exact value).
    #[must_use]
    pub fn z_score(&self, reference: f64) -> f64 {
        (self.mean - reference) / self.stderr
    }
}

/// R_d(r) on a radial grid, mm⁻², per incident photon, with standard errors.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialProfile {
    /// The grid.
    pub grid: RadialGrid,
    /// Diffuse reflectance per unit area per incident photon in each annulus, mm⁻².
    pub reflectance_per_mm2: Vec<f64>,
    /// Standard error of each value, mm⁻².
    pub stderr: Vec<f64>,
    /// Fraction of incident photons that escaped beyond the grid (not in the annuli).
    pub beyond_grid: f64,
}

/// The result of one Monte Carlo run; every fraction is per incident photon.
#[derive(Debug, Clone, PartialEq)]
pub struct McResult {
    /// Photons launched.
    pub photons: u64,
    /// Independent batches the standard errors come from.
    pub batches: u32,
    /// Diffuse reflectance (everything leaving the top except the entry specular).
    pub diffuse_reflectance: Estimate,
    /// Specular reflectance at entry, F_r(0) of the top interface (exact, no variance).
    pub specular_reflectance: f64,
    /// Total transmittance out of the bottom (0 for a semi-infinite stack).
    pub transmittance: Estimate,
    /// Absorbed fraction including the Russian-roulette weight balance, so that
    /// R_d + R_spec + T + A = 1 to rounding for every run.
    pub absorbed: Estimate,
    /// Weight deposited by absorption in each layer (excludes the roulette balance).
    pub absorbed_by_layer: Vec<f64>,
    /// Weight removed by roulette deaths minus weight added to survivors; zero in expectation.
    pub roulette_balance: f64,
    /// Radial diffuse reflectance.
    pub radial: RadialProfile,
    /// Scattering events per photon (mean history length, for speed figures).
    pub interactions_per_photon: f64,
}

impl McResult {
    /// R_d + R_spec + T + A: 1 up to floating-point rounding.
    #[must_use]
    pub fn energy_total(&self) -> f64 {
        self.diffuse_reflectance.mean
            + self.specular_reflectance
            + self.transmittance.mean
            + self.absorbed.mean
    }
}

/// Batch tallies folded in batch order as they finish, so memory does not grow with the batch
/// count: per batch only its three scalar estimates are kept (24 bytes, for the two-pass standard
/// errors of [`Estimate::from_batches`]); each annulus keeps a running sum for its mean and
/// Welford's running sum of squared deviations for its standard error.
pub(crate) struct Combiner {
    grid: RadialGrid,
    photons: u64,
    batches: u32,
    /// Per batch: diffuse reflectance, transmittance, absorbed, each per photon.
    scalars: Vec<[f64; 3]>,
    absorbed_by_layer: Vec<f64>,
    roulette_balance: f64,
    beyond_grid: f64,
    interactions: f64,
    /// Per annulus: Σ values, Welford's running mean and M2.
    radial_sum: Vec<f64>,
    radial_mean: Vec<f64>,
    radial_m2: Vec<f64>,
}

impl Combiner {
    pub fn new(layers: usize, grid: RadialGrid) -> Self {
        let bins = grid.bins();
        Self {
            grid,
            photons: 0,
            batches: 0,
            scalars: Vec::new(),
            absorbed_by_layer: vec![0.0; layers],
            roulette_balance: 0.0,
            beyond_grid: 0.0,
            interactions: 0.0,
            radial_sum: vec![0.0; bins],
            radial_mean: vec![0.0; bins],
            radial_m2: vec![0.0; bins],
        }
    }

    /// Fold in the next batch (batches must come in batch order for reproducible bits).
    pub fn add(&mut self, t: &BatchTally) {
        let np = t.photons as f64;
        self.photons += t.photons;
        self.batches += 1;
        self.scalars.push([
            t.diffuse_reflectance / np,
            t.transmittance / np,
            t.absorbed() / np,
        ]);
        for (a, b) in self.absorbed_by_layer.iter_mut().zip(&t.absorbed_by_layer) {
            *a += b;
        }
        self.roulette_balance += t.roulette_balance;
        self.beyond_grid += t.beyond_grid;
        self.interactions += t.interactions as f64;
        let k = f64::from(self.batches);
        for i in 0..self.grid.bins() {
            let v = t.radial[i] / (np * self.grid.annulus_area_mm2(i));
            self.radial_sum[i] += v;
            let delta = v - self.radial_mean[i];
            self.radial_mean[i] += delta / k;
            self.radial_m2[i] += delta * (v - self.radial_mean[i]);
        }
    }

    pub fn finish(self, specular: f64) -> McResult {
        let np = self.photons as f64;
        let n = f64::from(self.batches);
        let per = |c: usize| Estimate::from_batches(self.scalars.iter().map(move |s| s[c]));
        let stderr = self
            .radial_m2
            .iter()
            .map(|m2| {
                if self.batches > 1 {
                    (m2 / ((n - 1.0) * n)).sqrt()
                } else {
                    f64::NAN
                }
            })
            .collect();
        McResult {
            photons: self.photons,
            batches: self.batches,
            diffuse_reflectance: per(0),
            specular_reflectance: specular,
            transmittance: per(1),
            absorbed: per(2),
            absorbed_by_layer: self.absorbed_by_layer.iter().map(|a| a / np).collect(),
            roulette_balance: self.roulette_balance / np,
            radial: RadialProfile {
                grid: self.grid,
                reflectance_per_mm2: self.radial_sum.iter().map(|s| s / n).collect(),
                stderr,
                beyond_grid: self.beyond_grid / np,
            },
            interactions_per_photon: self.interactions / np,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn running_radial_errors_match_the_two_pass_formula() {
        // Welford's update must give the same standard error as Σ(v − mean)² over stored values.
        let grid = RadialGrid::new(1.0, 1).unwrap();
        let area = grid.annulus_area_mm2(0);
        let values = [0.3, 0.1, 0.7, 0.2, 0.5];
        let mut c = Combiner::new(1, grid);
        for v in values {
            let mut t = BatchTally::new(1, 1);
            t.photons = 10;
            t.radial[0] = v * 10.0 * area;
            c.add(&t);
        }
        let r = c.finish(0.0);
        let want = Estimate::from_batches(values.into_iter());
        assert!((r.radial.reflectance_per_mm2[0] - want.mean).abs() < 1e-15);
        assert!((r.radial.stderr[0] - want.stderr).abs() < 1e-15);
    }

    #[test]
    fn estimate_of_known_values() {
        let e = Estimate::from_batches([1.0, 2.0, 3.0, 4.0].into_iter());
        assert!((e.mean - 2.5).abs() < 1e-15);
        // sd = sqrt(5/3), stderr = sd / 2
        assert!((e.stderr - (5.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-15);
    }

    #[test]
    fn geometric_annuli_tile_the_disc_and_bin_their_radii() {
        let g = RadialGrid::geometric(0.01, 10.0, 31).unwrap();
        let total: f64 = (0..31).map(|i| g.annulus_area_mm2(i)).sum();
        assert!(
            (total - std::f64::consts::PI * 100.0).abs() < 1e-9,
            "{total}"
        );
        assert!((g.r_max_mm() - 10.0).abs() < 1e-12);
        for i in 0..31 {
            assert_eq!(g.bin(g.r_mid_mm(i)), Some(i));
            assert!(g.inner_mm(i) < g.outer_mm(i));
        }
        assert_eq!(g.bin(10.5), None);
        assert!(RadialGrid::geometric(1.0, 0.5, 10).is_err());
        assert!(RadialGrid::geometric(0.01, 10.0, 1).is_err());
    }

    #[test]
    fn annuli_tile_the_disc() {
        let g = RadialGrid::new(0.1, 10).unwrap();
        let total: f64 = (0..10).map(|i| g.annulus_area_mm2(i)).sum();
        assert!((total - std::f64::consts::PI * 1.0).abs() < 1e-12);
    }
}
