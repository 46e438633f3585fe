//! The universal table of exact two-layer profile shapes: one white Monte Carlo run
//! (`montecarlo::trace_white`, docs/physics.md §11) per (g, n), tallied over the exit radius for
//! each of a ladder of epidermal depths, all in scattering lengths. Any skin whose two layers share
//! σs, g and n — every [DJ06] skin with the dermis scattering scale 1, whatever its chromophores,
//! wavelength or epidermal thickness — has its exact profile shape as the sum over escapes of
//! exp(−α₁ l₁ − α₂ l₂) (α = σa/σs, l₁ and l₂ the paths above and below the depth). The table holds
//! that sum itself on a geometric grid of (α₁, α₂), each escape weighted exactly when it is traced,
//! and interpolates ln of the sum between grid nodes (cubic in ln α) and the sums between the two
//! nearest depths (linear in ln σs·d).
//!
//! Weighting at build time rather than histogramming path lengths: a path bin's weight varies
//! across the bin by e^(α l Δ), which for a strongly absorbing epidermis (dark skin in the blue,
//! α₁ ≈ 0.3–0.6, the reflected light's paths a few to tens of scattering lengths) reaches a
//! factor of several within one bin of 8 per decade and moved up to 3.6% of the energy between
//! radii. ln S(α) = ln Σ e^(−α l) is smooth and convex in α, so a cubic through 8 nodes per decade
//! follows it closely; the profile errors at the default knobs are in docs/accuracy_evidence.md.
//!
//! Knobs ([`ShapeTableOptions`]): photons (noise), depths per octave (interpolation), radial bins
//! and absorption nodes per decade; errors against the run-time Monte Carlo in BENCHMARKS.md
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
/// Largest σa/σs the table covers in either layer (the [DJ06] parameter box reaches about 0.6 in
/// the epidermis at 400 nm; beyond this the run-time Monte Carlo, cheap there, takes over).
pub const TABLE_MAX_ALPHA: f64 = 4.0;
/// Radius of the central disc of the table's radial axis, scattering lengths.
const R0: f64 = 0.05;
/// Fixed-point scale of the build's per-thread sums: integer adds make the table the same on any
/// thread count; a weight below 2⁻³³ rounds to 0, and 10⁹ photons of weight 1 stay below 2⁶⁴.
const FIXED_ONE: f64 = 4_294_967_296.0;

/// The knobs of a [`ShapeTable`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShapeTableOptions {
    /// White histories traced (noise falls as 1/√photons), in [10⁴, 10⁹].
    pub photons: u64,
    /// Depths of the epidermal ladder per octave of σs·d, in [1, 16].
    pub depths_per_octave: u32,
    /// Annuli per decade of radius, in [4, 64].
    pub radial_per_decade: u32,
    /// Absorption nodes (σa/σs of either layer) per decade, in [4, 16].
    pub alpha_per_decade: u32,
    /// Generator seed.
    pub seed: u64,
}

impl Default for ShapeTableOptions {
    fn default() -> Self {
        Self {
            photons: 500_000,
            depths_per_octave: 4,
            radial_per_decade: 16,
            alpha_per_decade: 8,
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
                "table absorption nodes per decade",
                f64::from(self.alpha_per_decade),
                4.0,
                16.0,
                "[4, 16]",
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

/// Absorption-weighted tallies of white histories: ln Σ exp(−α₁ l₁ − α₂ l₂) per (depth, annulus,
/// α₁ node, α₂ node), −∞ where no weight arrived.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeTable {
    g: f64,
    n: f64,
    opts: ShapeTableOptions,
    depths: Vec<f64>,
    r_axis: LogAxis,
    alphas: Vec<f64>,
    log_sums: Vec<f32>,
}

impl ShapeTable {
    /// Trace the white run for HG anisotropy `g` in [0, 0.99] and index `n` in [1, 3] on
    /// `threads` ≥ 1 plain threads (no rayon: the table may be built from inside a rayon task).
    /// `on_batch(photons)` is called after each of the 64 batches. Each batch's sums are added to
    /// the thread's as fixed-point integers, so the result is the same on any thread count.
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
        let cells = table.log_sums.len();
        let partials: Vec<Vec<u64>> = std::thread::scope(|s| {
            let workers: Vec<_> = (0..threads.max(1))
                .map(|_| {
                    s.spawn(|| {
                        let mut fixed = vec![0u64; cells];
                        let mut batch = vec![0.0f32; cells];
                        let mut scratch = Scratch::new(table.alphas.len());
                        loop {
                            let b = next.fetch_add(1, Ordering::Relaxed) as usize;
                            let Some(stream) = streams.get(b) else { break };
                            let mut rng = stream.clone();
                            trace_white(&medium, &table.depths, per_batch, &mut rng, |r, l, a| {
                                table.record(&mut batch, &mut scratch, r, l, a);
                            });
                            for (f, v) in fixed.iter_mut().zip(batch.iter_mut()) {
                                *f += (f64::from(*v) * FIXED_ONE).round() as u64;
                                *v = 0.0;
                            }
                            on_batch(per_batch);
                        }
                        fixed
                    })
                })
                .collect();
            workers
                .into_iter()
                .map(|w| w.join())
                .collect::<Result<_, _>>()
        })
        .map_err(|_| MultipoleError::Layers("shape table worker panicked".into()))?;
        let mut sums = vec![0u64; cells];
        for part in partials {
            for (c, p) in sums.iter_mut().zip(part) {
                *c += p;
            }
        }
        let mut table = table;
        for (l, &c) in table.log_sums.iter_mut().zip(&sums) {
            *l = if c == 0 {
                f32::NEG_INFINITY
            } else {
                (c as f64 / FIXED_ONE).ln() as f32
            };
        }
        Ok(table)
    }

    /// A table of empty sums (ln 0 = −∞) with the axes of `opts`.
    fn empty(g: f64, n: f64, opts: ShapeTableOptions) -> Self {
        let octaves = (TABLE_TAU_MAX / TABLE_TAU_MIN).log2();
        let steps = (octaves * f64::from(opts.depths_per_octave)).round() as usize;
        let depths = (0..=steps)
            .map(|i| TABLE_TAU_MIN * 2f64.powf(i as f64 / f64::from(opts.depths_per_octave)))
            .collect();
        let r_axis = LogAxis::new(R0, TABLE_MAX_PATH, opts.radial_per_decade);
        let per_decade = f64::from(opts.alpha_per_decade);
        let intervals = (per_decade * (TABLE_MAX_ALPHA / TABLE_MIN_ALPHA).log10()).ceil() as usize;
        // At least 4 nodes: the cubic interpolation's stencil.
        let alphas: Vec<f64> = (0..=intervals.max(3))
            .map(|k| TABLE_MIN_ALPHA * 10f64.powf(k as f64 / per_decade))
            .collect();
        let cells = (steps + 1) * r_axis.bins() * alphas.len() * alphas.len();
        Self {
            g,
            n,
            opts,
            depths,
            r_axis,
            alphas,
            log_sums: vec![f32::NEG_INFINITY; cells],
        }
    }

    /// Add one escape (radius, path, path above each depth), weighted at every node pair, to
    /// `sums`. Deeper depths the history never reached share one weight row (l₂ = 0), so the
    /// exponentials are taken once per distinct path above.
    fn record(&self, sums: &mut [f32], scratch: &mut Scratch, r: f64, path: f64, above: &[f64]) {
        let Some(ir) = self.r_axis.bin(r) else { return };
        let k = self.alphas.len();
        scratch.last_l1 = f64::NAN;
        scratch.last_l2 = f64::NAN;
        for (t, &l1) in above.iter().enumerate() {
            let l2 = (path - l1).max(0.0);
            if l1 != scratch.last_l1 {
                for (e, &a) in scratch.e1.iter_mut().zip(&self.alphas) {
                    *e = (-a * l1).exp() as f32;
                }
                scratch.last_l1 = l1;
            }
            if l2 != scratch.last_l2 {
                for (e, &a) in scratch.e2.iter_mut().zip(&self.alphas) {
                    *e = (-a * l2).exp() as f32;
                }
                scratch.last_l2 = l2;
            }
            let start = (t * self.r_axis.bins() + ir) * k * k;
            let cell = &mut sums[start..start + k * k];
            for (row, &a) in cell.chunks_exact_mut(k).zip(&scratch.e1) {
                if a == 0.0 {
                    continue;
                }
                for (c, &b) in row.iter_mut().zip(&scratch.e2) {
                    *c += a * b;
                }
            }
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
    /// `None` outside the table ([`TABLE_TAU_MIN`]..[`TABLE_TAU_MAX`], σa/σs in
    /// [[`TABLE_MIN_ALPHA`], [`TABLE_MAX_ALPHA`]]).
    #[must_use]
    pub fn shape(&self, alpha_top: f64, alpha_bottom: f64, tau: f64) -> Option<Vec<f64>> {
        let covered = |a: f64| (TABLE_MIN_ALPHA..=TABLE_MAX_ALPHA).contains(&a);
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
        let (s1, s2) = (self.stencil(alpha_top), self.stencil(alpha_bottom));
        let (nr, k) = (self.r_axis.bins(), self.alphas.len());
        let mut out = vec![0.0; nr];
        for (t, wt) in [(t0, 1.0 - w), (t0 + 1, w)] {
            if wt == 0.0 {
                continue;
            }
            for (i, o) in out.iter_mut().enumerate() {
                let cell = &self.log_sums[(t * nr + i) * k * k..(t * nr + i + 1) * k * k];
                *o += wt * interpolate(cell, k, &s1, &s2);
            }
        }
        let photons = self.opts.photons.div_ceil(64) * 64;
        for (i, o) in out.iter_mut().enumerate() {
            *o /= photons as f64 * self.r_axis.annulus_area(i);
        }
        Some(out)
    }

    /// The 4-node stencil around `alpha` (uniform nodes in ln α; it shifts inwards at the ends of
    /// the axis).
    fn stencil(&self, alpha: f64) -> Stencil {
        let per_decade = f64::from(self.opts.alpha_per_decade);
        let x = (alpha / TABLE_MIN_ALPHA).log10() * per_decade;
        let j = (x.floor() as isize - 1).clamp(0, self.alphas.len() as isize - 4) as usize;
        let u = x - j as f64;
        let mut weights = [1.0; 4];
        for (i, wi) in weights.iter_mut().enumerate() {
            for m in (0..4).filter(|&m| m != i) {
                *wi *= (u - m as f64) / (i as f64 - m as f64);
            }
        }
        Stencil {
            first: j,
            u,
            weights,
        }
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

/// Per-thread buffers of the build: e^(−α l) at every node for the current paths above and below.
struct Scratch {
    e1: Vec<f32>,
    e2: Vec<f32>,
    last_l1: f64,
    last_l2: f64,
}

impl Scratch {
    fn new(nodes: usize) -> Self {
        Self {
            e1: vec![0.0; nodes],
            e2: vec![0.0; nodes],
            last_l1: f64::NAN,
            last_l2: f64::NAN,
        }
    }
}

/// Where one α falls on the node axis: the first node of its 4-node stencil, its position from
/// that node (node spacings) and the cubic Lagrange weights there.
struct Stencil {
    first: usize,
    u: f64,
    weights: [f64; 4],
}

/// The sum of one (depth, annulus) cell (`k` × `k` values of ln S) at `s1` (α above, rows) and
/// `s2` (α below, columns): cubic in ln S where the 16 nodes all hold weight; bilinear in S
/// between the two nearest nodes where some do not (annuli with a handful of escapes).
fn interpolate(cell: &[f32], k: usize, s1: &Stencil, s2: &Stencil) -> f64 {
    let at = |a: usize, b: usize| f64::from(cell[(s1.first + a) * k + s2.first + b]);
    let mut log_sum = 0.0;
    let mut finite = true;
    for (a, wa) in s1.weights.iter().enumerate() {
        for (b, wb) in s2.weights.iter().enumerate() {
            let v = at(a, b);
            finite &= v.is_finite();
            log_sum += wa * wb * v;
        }
    }
    if finite {
        return log_sum.exp();
    }
    let split = |u: f64| {
        let i = (u.floor() as usize).min(2);
        (i, (u - i as f64).clamp(0.0, 1.0))
    };
    let ((a0, fa), (b0, fb)) = (split(s1.u), split(s2.u));
    (1.0 - fa) * ((1.0 - fb) * at(a0, b0).exp() + fb * at(a0, b0 + 1).exp())
        + fa * ((1.0 - fb) * at(a0 + 1, b0).exp() + fb * at(a0 + 1, b0 + 1).exp())
}

#[cfg(test)]
mod tests;
