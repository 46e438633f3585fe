//! Monte Carlo photon transport in plane-parallel layers, the reference the diffusion model is judged
//! against: MCML ([WJZ95] Wang, Jacques & Zheng 1995) with a modern generator (docs/physics.md §11).
//! The medium is a [`LayeredMedium`].
//!
//! - Layers: σa, σs (mm⁻¹), Henyey–Greenstein g, index n, thickness (the last may be semi-infinite);
//!   ambient indices above and below; exact unpolarised Fresnel at every index mismatch
//!   (`brdf::fresnel`), all-or-none reflection as MCML does by default.
//! - Source: a collimated pencil beam at normal incidence on the origin; the entry specular
//!   reflection is deterministic and reported apart.
//! - Weights: implicit capture (each interaction deposits σa/σt of the weight), Russian roulette
//!   below weight 1e-4 with survival 1/10 ([`ROULETTE_THRESHOLD`], [`ROULETTE_SURVIVAL`]).
//! - Energy is accounted exactly: roulette adds weight to survivors and removes it from the dead;
//!   that balance (zero in expectation) is tallied and folded into `absorbed`, so
//!   R_d + R_spec + T + A = 1 to rounding in every run ([`McResult::energy_total`]).
//! - Statistics: the photons are split into equal batches, each with its own xoshiro256** stream
//!   (one seed, streams 2¹²⁸ apart by `jump`); batches run in parallel on rayon and are combined in
//!   batch order, so the same seed gives the same bits on any number of threads. Standard errors
//!   come from the spread of the batch means.
//! - Speed: a batch traces 8 photons at once in SIMD lanes, each lane with its own stream seeded
//!   from the batch's, compiled for AVX-512, AVX2 and plain code and picked at run time (the same
//!   bits on each); faces and roulette run lane by lane in scalar code. The scalar path, one
//!   photon at a time, stays as the reference the lanes are tested against.
//!
//! The module depends only on `skin-optics`, `brdf::fresnel`, `rand`/`rand_xoshiro`/`rand_distr`
//! (the ziggurat exponential of the scalar and the white paths), `pulp` (the run-time choice of
//! instruction set) and `rayon`: it lives in `multipole` because `Method::Exact` profiles use it;
//! `validation` compares with it.

mod oblique;
mod tally;
mod transport;

pub use crate::layered::{DEFAULT_G, Layer, LayeredMedium};
pub use oblique::{Harmonics, ObliqueOptions, azimuthal_harmonics};
pub use tally::{Estimate, McResult, RadialGrid, RadialProfile};
pub(crate) use transport::white::{WhiteMedium, trace_white};
pub use transport::{HgSampler, ROULETTE_SURVIVAL, ROULETTE_THRESHOLD, scatter_direction};

use crate::error::MultipoleError;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256StarStar;
use rayon::prelude::*;
use tally::{BatchTally, Combiner};
use transport::{Medium, trace_batch};

/// Run settings: photon count (the accuracy knob), batches for the standard errors, seed, grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct McOptions {
    photons: u64,
    batches: u32,
    seed: u64,
    grid: RadialGrid,
}

impl Default for McOptions {
    /// 10⁶ photons in 32 batches, seed 1, the default radial grid.
    fn default() -> Self {
        Self {
            photons: 1_000_000,
            batches: 32,
            seed: 1,
            grid: RadialGrid::default(),
        }
    }
}

impl McOptions {
    /// `photons` in [1, 1e12] histories split into `batches` in [2, 1e6] equal batches (rounded up
    /// to a multiple of `batches`), with `seed` for the generator and the default grid.
    pub fn new(photons: u64, batches: u32, seed: u64) -> Result<Self, MultipoleError> {
        if !(1..=1_000_000_000_000).contains(&photons) {
            return Err(MultipoleError::OutOfRange {
                name: "photons",
                value: photons as f64,
                range: "[1, 1e12]",
            });
        }
        if !(2..=1_000_000).contains(&batches) {
            return Err(MultipoleError::OutOfRange {
                name: "batches",
                value: f64::from(batches),
                range: "[2, 1e6]",
            });
        }
        Ok(Self {
            photons,
            batches,
            seed,
            grid: RadialGrid::default(),
        })
    }

    /// Same options with another radial grid.
    #[must_use]
    pub fn with_grid(mut self, grid: RadialGrid) -> Self {
        self.grid = grid;
        self
    }

    /// Photons per batch (the requested count divided by the batches, rounded up).
    #[must_use]
    pub fn photons_per_batch(&self) -> u64 {
        self.photons.div_ceil(u64::from(self.batches))
    }
    /// Photons actually traced: batches × photons per batch.
    #[must_use]
    pub fn total_photons(&self) -> u64 {
        self.photons_per_batch() * u64::from(self.batches)
    }
    /// Number of independent batches.
    #[must_use]
    pub fn batches(&self) -> u32 {
        self.batches
    }
    /// Generator seed.
    #[must_use]
    pub fn seed(&self) -> u64 {
        self.seed
    }
    /// Radial grid of R_d(r).
    #[must_use]
    pub fn grid(&self) -> RadialGrid {
        self.grid
    }
}

/// Trace the stack with the options on the current rayon pool.
#[must_use]
pub fn run(stack: &LayeredMedium, opts: &McOptions) -> McResult {
    run_with_progress(stack, opts, |_| {})
}

/// Batches traced in parallel before they are folded into the result: bounds the tallies held at
/// once (each holds one weight per annulus), whatever the batch count.
const BATCHES_IN_FLIGHT: u32 = 256;

/// As [`run`], calling `on_batch(photons_in_batch)` after each finished batch (for progress bars).
pub fn run_with_progress(
    stack: &LayeredMedium,
    opts: &McOptions,
    on_batch: impl Fn(u64) + Sync,
) -> McResult {
    let medium = Medium::new(stack);
    let specular = medium.specular(stack.n_above());
    let w0 = 1.0 - specular;
    let per_batch = opts.photons_per_batch();
    let layers = stack.layers().len();
    let grid = opts.grid;
    let mut combined = Combiner::new(layers, grid);
    let mut base = Xoshiro256StarStar::seed_from_u64(opts.seed);
    let mut left = opts.batches;
    while left > 0 {
        let n = left.min(BATCHES_IN_FLIGHT);
        left -= n;
        let tallies: Vec<BatchTally> = next_streams(&mut base, n)
            .into_par_iter()
            .map(|mut rng| {
                let mut tally = BatchTally::new(layers, grid.bins());
                trace_batch(&medium, grid, w0, per_batch, &mut rng, &mut tally);
                on_batch(per_batch);
                tally
            })
            .collect();
        tallies.iter().for_each(|t| combined.add(t));
    }
    combined.finish(specular)
}

/// The next `n` batch generators after `base`, each 2¹²⁸ draws after the previous (`jump`).
fn next_streams(base: &mut Xoshiro256StarStar, n: u32) -> Vec<Xoshiro256StarStar> {
    (0..n)
        .map(|_| {
            let rng = base.clone();
            base.jump();
            rng
        })
        .collect()
}

/// One generator per batch: xoshiro256** seeded from `seed`, each stream 2¹²⁸ draws after the
/// previous (`jump`), so batches never overlap.
pub(crate) fn batch_streams(seed: u64, batches: u32) -> Vec<Xoshiro256StarStar> {
    next_streams(&mut Xoshiro256StarStar::seed_from_u64(seed), batches)
}
