//! The uniforms of one path: independent random numbers or an Owen-scrambled Sobol sequence
//! ([Burley 2020] hash-based Owen scrambling, the `sobol_burley` crate; [pbrt] 4th ed. §8.7).
//!
//! A path reads its uniforms in regions with a fixed dimension budget: the camera (wavelength,
//! film position, lens) and then one region per bounce. Each region starts at a fixed dimension,
//! so the k-th uniform of bounce d is the same Sobol dimension on every path, whatever earlier
//! bounces consumed; a region that needs more than its budget continues with independent numbers
//! (still unbiased, only not stratified).
//!
//! Dimensions come in sets of four that share one scramble (stratified in 4-D), each set padded
//! with its own seed, as the crate documents. A pixel's sequence is seeded from (seed, pixel), and
//! sample `i` of it is the i-th point, so an image depends on the seed and the sample count only,
//! never on the thread count. Past 2¹⁶ samples per pixel (the crate's sequence length) a new,
//! independently seeded sequence starts.

use glam::Vec2;
use rand::{Rng, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Which numbers a path's decisions are made from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SamplerKind {
    /// Independent uniforms (xoshiro256++ per pixel sample).
    Independent,
    /// Owen-scrambled Sobol points per pixel, padded in sets of four dimensions.
    Sobol,
    /// Two independently scrambled Sobol sequences per pixel, the even samples from one and the
    /// odd ones from the other, so the two half-means are independent estimates.
    #[default]
    SobolPair,
}

/// Dimensions reserved for the camera: wavelength, film x, y, lens u, v (and three spare).
pub const CAMERA_DIMENSIONS: u32 = 8;
/// Dimensions reserved for each bounce (light choice and position, subsurface probe, exit
/// light, continuation, roulette).
pub const BOUNCE_DIMENSIONS: u32 = 20;

/// Samples per Sobol sequence of `sobol_burley`.
const SEQUENCE_LENGTH: u32 = 1 << 16;

/// SplitMix64 finaliser: a well-mixed 64-bit hash of `z`.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Seed of pixel `pixel`'s sample `sample` for the independent stream.
fn sample_seed(seed: u64, pixel: u64, sample: u32) -> u64 {
    mix64(seed ^ pixel.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (u64::from(sample) << 40))
}

/// The uniforms of one pixel sample.
#[derive(Debug, Clone)]
pub struct PathSampler {
    kind: SamplerKind,
    /// Independent numbers: the whole stream of [`SamplerKind::Independent`], and the overflow of
    /// a Sobol region past its budget.
    rng: Xoshiro256PlusPlus,
    /// Point index within the pixel's current sequence.
    index: u32,
    /// Seed of the pixel's current sequence.
    sequence_seed: u64,
    /// Next dimension, the start and the end of the current region.
    dim: u32,
    start: u32,
    end: u32,
    /// The four values of dimension set `cached_set` (`u32::MAX`: none yet).
    cache: [f32; 4],
    cached_set: u32,
}

impl PathSampler {
    /// The sampler of pixel `pixel`'s sample `sample` for image seed `seed`.
    #[must_use]
    pub fn new(kind: SamplerKind, seed: u64, pixel: u64, sample: u32) -> Self {
        // SobolPair: point sample/2 of the sequence of half sample % 2 (the half enters the seed).
        let (point, half) = match kind {
            SamplerKind::SobolPair => (sample / 2, u64::from(sample % 2)),
            _ => (sample, 0),
        };
        Self {
            kind,
            rng: Xoshiro256PlusPlus::seed_from_u64(sample_seed(seed, pixel, sample)),
            index: point % SEQUENCE_LENGTH,
            sequence_seed: mix64(
                seed.wrapping_add(0x2545_F491_4F6C_DD1D)
                    ^ pixel.wrapping_mul(0xD1B5_4A32_D192_ED03)
                    ^ u64::from(point / SEQUENCE_LENGTH).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    ^ half.wrapping_mul(0x5851_F42D_4C95_7F2D),
            ),
            dim: 0,
            start: 0,
            end: CAMERA_DIMENSIONS,
            cache: [0.0; 4],
            cached_set: u32::MAX,
        }
    }

    /// Start the camera region (the first uniforms of a path).
    pub fn start_camera(&mut self) {
        self.dim = 0;
        self.start = 0;
        self.end = CAMERA_DIMENSIONS;
    }

    /// Start the region of bounce `depth` (0 = the camera ray's hit).
    pub fn start_bounce(&mut self, depth: u32) {
        self.start = CAMERA_DIMENSIONS.saturating_add(depth.saturating_mul(BOUNCE_DIMENSIONS));
        self.dim = self.start;
        self.end = self.start.saturating_add(BOUNCE_DIMENSIONS);
    }

    /// Continue the current region at its `offset`-th dimension (forward only), so a decision
    /// reads the same dimension whether or not the ones before it were consumed.
    pub fn seek(&mut self, offset: u32) {
        self.dim = self.dim.max(self.start.saturating_add(offset));
    }

    /// The next uniform in [0, 1).
    pub fn get_1d(&mut self) -> f32 {
        match self.kind {
            SamplerKind::Independent => self.rng.random(),
            SamplerKind::Sobol | SamplerKind::SobolPair if self.dim < self.end => {
                let d = self.dim;
                self.dim += 1;
                let set = d / 4;
                if set != self.cached_set {
                    // Each set of four dimensions reuses Sobol dimensions 0–3 under its own seed;
                    // the four are computed at once (SIMD in the crate).
                    let set_seed = mix64(self.sequence_seed ^ u64::from(set)) as u32;
                    self.cache = sobol_burley::sample_4d(self.index, 0, set_seed);
                    self.cached_set = set;
                }
                self.cache[(d % 4) as usize]
            }
            SamplerKind::Sobol | SamplerKind::SobolPair => self.rng.random(),
        }
    }

    /// One independent uniform in [0, 1), outside the stratified regions: for decisions whose
    /// stratification does not matter (a level-of-detail choice inside its blend band).
    pub fn independent_1d(&mut self) -> f32 {
        self.rng.random()
    }

    /// The independent stream itself, for walks of unbounded dimension (the volumetric walk).
    pub fn rng(&mut self) -> &mut Xoshiro256PlusPlus {
        &mut self.rng
    }

    /// Another sampler for the same pixel sample and region, whose Sobol dimensions are scrambled
    /// apart by `k` (and whose independent stream is its own): for a decision split into several
    /// estimates at one vertex, each stratified over the pixel's samples like the first.
    #[must_use]
    pub fn fork(&self, k: u32) -> Self {
        let salt = mix64(u64::from(k).wrapping_mul(0xA076_1D64_78BD_642F) ^ self.sequence_seed);
        Self {
            rng: Xoshiro256PlusPlus::seed_from_u64(salt ^ u64::from(self.index)),
            sequence_seed: salt,
            cached_set: u32::MAX,
            ..self.clone()
        }
    }

    /// The next two uniforms.
    pub fn get_2d(&mut self) -> Vec2 {
        let x = self.get_1d();
        Vec2::new(x, self.get_1d())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first 2^k points of one pixel's Sobol sequence put exactly one point in each of 2^k
    /// equal intervals of every dimension (a (0, m, 1)-net per dimension, kept by Owen
    /// scrambling), and 2D pairs of a set are stratified in 2^k elementary boxes of both shapes
    /// 2^a × 2^(k−a) for dimensions 0 and 1 of a set (the (0, 2)-sequence property). With
    /// [`SamplerKind::SobolPair`] the even samples and the odd samples each have the property.
    #[test]
    fn sobol_points_are_stratified() {
        let n = 64u32;
        let cases = [
            (SamplerKind::Sobol, 1, 0),
            (SamplerKind::SobolPair, 2, 0),
            (SamplerKind::SobolPair, 2, 1),
        ];
        for pixel in [0u64, 7, 12345] {
            for (kind, step, first) in cases {
                let pts: Vec<Vec<f32>> = (0..n)
                    .map(|j| {
                        let mut s = PathSampler::new(kind, 3, pixel, j * step + first);
                        s.start_bounce(2);
                        (0..BOUNCE_DIMENSIONS).map(|_| s.get_1d()).collect()
                    })
                    .collect();
                assert_stratified(&pts, n, &format!("{kind:?} {first} of pixel {pixel}"));
            }
        }
    }

    fn assert_stratified(pts: &[Vec<f32>], n: u32, what: &str) {
        for d in 0..BOUNCE_DIMENSIONS as usize {
            let mut seen = vec![false; n as usize];
            for p in pts {
                seen[(p[d] * n as f32) as usize] = true;
            }
            assert!(seen.iter().all(|&s| s), "dimension {d}, {what}");
        }
        for a in 0..=6u32 {
            let (bx, by) = (1u32 << a, n >> a);
            let mut seen = vec![false; n as usize];
            for p in pts {
                let cell = (p[0] * bx as f32) as u32 * by + (p[1] * by as f32) as u32;
                seen[cell as usize] = true;
            }
            assert!(seen.iter().all(|&s| s), "{bx}×{by} boxes, {what}");
        }
    }

    /// The two halves of a [`SamplerKind::SobolPair`] pixel are scrambled apart: point j of A
    /// and point j of B differ (one shared scramble would make them equal).
    #[test]
    fn pair_halves_are_scrambled_apart() {
        for j in 0..8 {
            let draw = |sample| {
                let mut s = PathSampler::new(SamplerKind::SobolPair, 4, 11, sample);
                s.start_camera();
                [s.get_1d(), s.get_1d()]
            };
            assert_ne!(draw(2 * j), draw(2 * j + 1), "point {j}");
        }
    }

    /// The same (seed, pixel, sample) gives the same numbers; another pixel other numbers.
    #[test]
    fn sampler_is_a_function_of_its_seed() {
        for kind in [
            SamplerKind::Independent,
            SamplerKind::Sobol,
            SamplerKind::SobolPair,
        ] {
            let draw = |pixel| {
                let mut s = PathSampler::new(kind, 9, pixel, 5);
                s.start_camera();
                [s.get_1d(), s.get_1d(), s.get_1d()]
            };
            assert_eq!(draw(4), draw(4));
            assert_ne!(draw(4), draw(5));
        }
    }

    /// Past its region's budget a bounce gets independent numbers, never the next bounce's.
    #[test]
    fn regions_do_not_overlap() {
        let mut a = PathSampler::new(SamplerKind::Sobol, 1, 0, 3);
        a.start_bounce(0);
        let over: Vec<f32> = (0..BOUNCE_DIMENSIONS + 4).map(|_| a.get_1d()).collect();
        let mut b = PathSampler::new(SamplerKind::Sobol, 1, 0, 3);
        b.start_bounce(1);
        let next: Vec<f32> = (0..4).map(|_| b.get_1d()).collect();
        assert_ne!(&over[BOUNCE_DIMENSIONS as usize..], &next[..]);
    }
}
