//! The universal table of exact two-layer profile shapes: one white Monte Carlo run
//! (`montecarlo::trace_white`, docs/physics.md §11) per (g, n), histogrammed over the exit radius
//! and the path lengths above and below each of a ladder of epidermal depths, all in scattering
//! lengths. Any skin whose two layers share σs, g and n — every [DJ06] skin with the dermis
//! scattering scale 1, whatever its chromophores, wavelength or epidermal thickness — then has its
//! exact profile shape as a weighted sum of the histogram with weights exp(−σa₁ l₁ − σa₂ l₂),
//! interpolated between the two nearest depths of the ladder.
//!
//! Knobs ([`ShapeTableOptions`]): photons (noise), depths per octave (interpolation), radial and
//! path bins per decade (binning); errors against the run-time Monte Carlo in BENCHMARKS.md
//! (`## Exact profile table`).

use super::shape::profile_from_shape;
use crate::diffusion::profile::Profile;
use crate::error::MultipoleError;
use crate::exact::montecarlo::{WhiteMedium, batch_streams, trace_white};
use std::sync::atomic::{AtomicU64, Ordering};

mod axis;
mod cache;
pub use cache::cached_table;

use axis::LogAxis;

/// Smallest epidermal scattering depth σs·d of the ladder (at g = 0.9, d = 0.008 mm at 400 nm and
/// 0.023 mm at 700 nm: thinner epidermises fall back to the run-time Monte Carlo).
pub const TABLE_TAU_MIN: f64 = 1.0;
/// Largest epidermal scattering depth σs·d of the ladder (at g = 0.9, d = 1.0 mm at 400 nm, 2.9 mm at 700 nm).
pub const TABLE_TAU_MAX: f64 = 128.0;
/// Histories longer than this many scattering lengths are dropped from the table.
pub const TABLE_MAX_PATH: f64 = 1.0e4;
/// Smallest σa/σs the table covers in either layer: a dropped history would carry at most
/// e^(−5) of its weight here, and histories this long are a fraction of a percent.
pub const TABLE_MIN_ALPHA: f64 = 5.0e-4;
/// Radius of the central disc of the table's radial axis, scattering lengths.
const R0: f64 = 0.05;
/// First path-length bin edge, scattering lengths.
const L0: f64 = 0.01;

/// The knobs of a [`ShapeTable`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShapeTableOptions {
    /// White histories traced (noise falls as 1/√photons), in [10⁴, 10⁹].
    pub photons: u64,
    /// Depths of the epidermal ladder per octave of σs·d, in [1, 16].
    pub depths_per_octave: u32,
    /// Annuli per decade of radius, in [4, 64].
    pub radial_per_decade: u32,
    /// Path-length bins per decade, in [2, 32].
    pub path_per_decade: u32,
    /// Generator seed.
    pub seed: u64,
}

impl Default for ShapeTableOptions {
    fn default() -> Self {
        Self {
            photons: 500_000,
            depths_per_octave: 4,
            radial_per_decade: 16,
            path_per_decade: 8,
            seed: 0x5EED_7AB1,
        }
    }
}

impl ShapeTableOptions {
    /// Check every knob against its documented range.
    pub fn validate(&self) -> Result<(), MultipoleError> {
        let checks = [
            ("table photons", self.photons as f64, 1e4, 1e9, "[1e4, 1e9]"),
            (
                "table depths per octave",
                f64::from(self.depths_per_octave),
                1.0,
                16.0,
                "[1, 16]",
            ),
            (
                "table radial bins per decade",
                f64::from(self.radial_per_decade),
                4.0,
                64.0,
                "[4, 64]",
            ),
            (
                "table path bins per decade",
                f64::from(self.path_per_decade),
                2.0,
                32.0,
                "[2, 32]",
            ),
        ];
        for (name, value, lo, hi, range) in checks {
            if !(lo..=hi).contains(&value) {
                return Err(MultipoleError::InvalidOption { name, value, range });
            }
        }
        Ok(())
    }
}

/// Histogram of white histories: counts per (depth, annulus, path above, path below).
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeTable {
    g: f64,
    n: f64,
    opts: ShapeTableOptions,
    depths: Vec<f64>,
    r_axis: LogAxis,
    l_axis: LogAxis,
    counts: Vec<f32>,
}

impl ShapeTable {
    /// Trace the white run for HG anisotropy `g` in [0, 0.99] and index `n` in [1, 3] on
    /// `threads` ≥ 1 plain threads (no rayon: the table may be built from inside a rayon task).
    /// `on_batch(photons)` is called after each of the 64 batches. The counts are integers, so the
    /// result is the same on any thread count.
    pub fn build(
        g: f64,
        n: f64,
        opts: &ShapeTableOptions,
        threads: usize,
        on_batch: impl Fn(u64) + Sync,
    ) -> Result<Self, MultipoleError> {
        opts.validate()?;
        crate::error::check_range("table anisotropy g", g, 0.0, 0.99, "[0, 0.99]")?;
        crate::error::check_range("table index n", n, 1.0, 3.0, "[1, 3]")?;
        let table = Self::empty(g, n, *opts);
        let batches = 64u32;
        let per_batch = opts.photons.div_ceil(u64::from(batches));
        let streams = batch_streams(opts.seed, batches);
        let next = AtomicU64::new(0);
        let medium = WhiteMedium {
            g,
            n,
            max_path: TABLE_MAX_PATH,
        };
        let cells = table.counts.len();
        let partials: Vec<Vec<u32>> = std::thread::scope(|s| {
            let workers: Vec<_> = (0..threads.max(1))
                .map(|_| {
                    s.spawn(|| {
                        let mut counts = vec![0u32; cells];
                        loop {
                            let b = next.fetch_add(1, Ordering::Relaxed) as usize;
                            let Some(stream) = streams.get(b) else { break };
                            let mut rng = stream.clone();
                            trace_white(&medium, &table.depths, per_batch, &mut rng, |r, l, a| {
                                table.record(&mut counts, r, l, a);
                            });
                            on_batch(per_batch);
                        }
                        counts
                    })
                })
                .collect();
            workers
                .into_iter()
                .map(|w| w.join())
                .collect::<Result<_, _>>()
        })
        .map_err(|_| MultipoleError::Layers("shape table worker panicked".into()))?;
        let mut table = table;
        for part in partials {
            for (c, p) in table.counts.iter_mut().zip(part) {
                *c += p as f32;
            }
        }
        Ok(table)
    }

    /// A table of zero counts with the axes of `opts`.
    fn empty(g: f64, n: f64, opts: ShapeTableOptions) -> Self {
        let octaves = (TABLE_TAU_MAX / TABLE_TAU_MIN).log2();
        let steps = (octaves * f64::from(opts.depths_per_octave)).round() as usize;
        let depths = (0..=steps)
            .map(|i| TABLE_TAU_MIN * 2f64.powf(i as f64 / f64::from(opts.depths_per_octave)))
            .collect();
        let r_axis = LogAxis::new(R0, TABLE_MAX_PATH, opts.radial_per_decade);
        let l_axis = LogAxis::new(L0, TABLE_MAX_PATH, opts.path_per_decade);
        let cells = (steps + 1) * r_axis.bins() * l_axis.bins() * l_axis.bins();
        Self {
            g,
            n,
            opts,
            depths,
            r_axis,
            l_axis,
            counts: vec![0.0; cells],
        }
    }

    /// Count one escape (radius, path, path above each depth) into `counts`.
    fn record(&self, counts: &mut [u32], r: f64, path: f64, above: &[f64]) {
        let Some(ir) = self.r_axis.bin(r) else { return };
        let nl = self.l_axis.bins();
        for (t, &l1) in above.iter().enumerate() {
            let (Some(j), Some(k)) = (self.l_axis.bin(l1), self.l_axis.bin((path - l1).max(0.0)))
            else {
                continue;
            };
            counts[((t * self.r_axis.bins() + ir) * nl + j) * nl + k] += 1;
        }
    }

    /// HG anisotropy of the run.
    #[must_use]
    pub fn g(&self) -> f64 {
        self.g
    }
    /// Index of refraction of the medium (air above).
    #[must_use]
    pub fn n(&self) -> f64 {
        self.n
    }
    /// The knobs it was built with.
    #[must_use]
    pub fn options(&self) -> &ShapeTableOptions {
        &self.opts
    }

    /// Mean reflectance per annulus, per unit area in scattering lengths² and per entering photon,
    /// for σa/σs = `alpha_top` above the depth `tau` (scattering lengths) and `alpha_bottom` below;
    /// `None` outside the table ([`TABLE_TAU_MIN`]..[`TABLE_TAU_MAX`], σa/σs ≥ [`TABLE_MIN_ALPHA`]).
    #[must_use]
    pub fn shape(&self, alpha_top: f64, alpha_bottom: f64, tau: f64) -> Option<Vec<f64>> {
        let covered = |a: f64| a.is_finite() && a >= TABLE_MIN_ALPHA;
        if !(covered(alpha_top)
            && covered(alpha_bottom)
            && (TABLE_TAU_MIN..=TABLE_TAU_MAX).contains(&tau))
        {
            return None;
        }
        let per_octave = f64::from(self.opts.depths_per_octave);
        let x = (tau / TABLE_TAU_MIN).log2() * per_octave;
        let t0 = (x.floor() as usize).min(self.depths.len() - 2);
        let w = (x - t0 as f64).clamp(0.0, 1.0);
        let f1 = self.l_axis.mean_exp(alpha_top);
        let f2 = self.l_axis.mean_exp(alpha_bottom);
        let (nr, nl) = (self.r_axis.bins(), self.l_axis.bins());
        let mut out = vec![0.0; nr];
        for (t, wt) in [(t0, 1.0 - w), (t0 + 1, w)] {
            if wt == 0.0 {
                continue;
            }
            let block = &self.counts[t * nr * nl * nl..(t + 1) * nr * nl * nl];
            for (i, o) in out.iter_mut().enumerate() {
                let rows = &block[i * nl * nl..(i + 1) * nl * nl];
                let mut sum = 0.0f32;
                for (row, &a) in rows.chunks_exact(nl).zip(&f1) {
                    let inner: f32 = row.iter().zip(&f2).map(|(&c, &b)| c * b).sum();
                    sum += a * inner;
                }
                *o += wt * f64::from(sum);
            }
        }
        let photons = self.opts.photons.div_ceil(64) * 64;
        for (i, o) in out.iter_mut().enumerate() {
            *o /= photons as f64 * self.r_axis.annulus_area(i);
        }
        Some(out)
    }

    /// Profile nodes of [`ShapeTable::shape`], scattering lengths: the disc's outer radius, then
    /// each annulus' geometric mean radius (the convention of `skin::shape_radii`).
    #[must_use]
    pub fn radii(&self) -> Vec<f64> {
        (0..self.r_axis.bins())
            .map(|i| {
                let (lo, hi) = self.r_axis.edges(i);
                if i == 0 { hi } else { (lo * hi).sqrt() }
            })
            .collect()
    }

    /// The profile of a two-layer medium of scattering coefficient `sigma_s` (mm⁻¹, both layers),
    /// absorption `sigma_a_top` over `thickness_mm` above a half-space of `sigma_a_bottom` (mm⁻¹),
    /// scaled to `total`; `None` where the table does not cover it.
    pub fn profile(
        &self,
        sigma_s: f64,
        sigma_a_top: f64,
        sigma_a_bottom: f64,
        thickness_mm: f64,
        total: f64,
    ) -> Result<Option<Profile>, MultipoleError> {
        let Some(shape) = self.shape(
            sigma_a_top / sigma_s,
            sigma_a_bottom / sigma_s,
            sigma_s * thickness_mm,
        ) else {
            return Ok(None);
        };
        let radii: Vec<f64> = self.radii().iter().map(|r| r / sigma_s).collect();
        let s2 = sigma_s * sigma_s;
        let values: Vec<f64> = shape.iter().map(|v| v * s2).collect();
        profile_from_shape(&radii, &values, total).map(Some)
    }
}

#[cfg(test)]
mod tests;
