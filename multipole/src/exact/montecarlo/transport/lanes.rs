//! Photon lanes: [`W`] histories advanced together, one event each per round, so that the common
//! event (free path, Henyey–Greenstein cosine, azimuth, turn, implicit capture) runs as SIMD over
//! the lanes; the rare ones (a face, roulette) go to the scalar [`Lane`] code one lane at a time.
//! A lane whose photon ends takes the batch's next photon at once, so the lanes stay busy.
//!
//! - Every lane has its own xoshiro256** stream ([`Streams`]), seeded from the batch's generator,
//!   so a lane's history never depends on the others' and the batch result depends only on the
//!   batch's generator. Each round draws three numbers per lane (free path, cosine, azimuth);
//!   those of a lane that meets a face instead are discarded, which keeps them independent of
//!   the history (the decision does not look at them).
//! - The free path is −ln ξ by a branch-free fdlibm logarithm ([`free_path_from_bits`], below one
//!   ulp); the azimuth is branch-free ([`azimuth_from_bits`]); every lane evaluates the
//!   interaction and keeps it unless it met a face.
//! - The loop is compiled for AVX-512, AVX2 and plain x86-64 (or any target) and picked at run
//!   time (`pulp`'s dispatch). Rust never fuses a multiply and an add on its own, so the three
//!   give the same bits.
//!
//! The lane state is held field by field (one array per quantity, as `HgLanes` holds the phase
//! constants), so moving a photon in or out of a lane lists its fields one by one; `trace` and
//! `Trace` list the same arguments because `pulp` hands them over as one value.

use super::free_path::free_path_from_bits;
use super::sampling::{HgLanes, azimuth_from_bits, uniform_from_bits};
use super::{BatchTally, Lane, Photon, ROULETTE_THRESHOLD, RadialGrid, SlabOptics, reaches_face};
use rand::RngCore;
use rand_xoshiro::Xoshiro256StarStar;

/// Photons in flight per batch: one AVX-512 register of f64, two AVX2 ones (whose chains then
/// overlap).
pub(super) const W: usize = 8;

/// The xoshiro256** step (Blackman & Vigna 2018, as `rand_xoshiro`): returns the output and
/// advances the state.
#[inline(always)]
fn xoshiro_next(s: &mut [u64; 4]) -> u64 {
    let out = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
    let t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = s[3].rotate_left(45);
    out
}

/// One xoshiro256** stream per lane, the state held word by word so a draw for all lanes is a
/// handful of vector instructions.
struct Streams {
    s: [[u64; W]; 4],
}

impl Streams {
    /// Lane states from 256 bits of the batch's generator each. Two streams started at random
    /// points of the generator's cycle (length 2²⁵⁶ − 1) overlap within L draws each with
    /// probability about 2L/2²⁵⁶: 2⁻¹⁹¹ for L = 2⁶⁴. The all-zero state (the generator's fixed
    /// point) has probability 2⁻²⁵⁶.
    fn seeded(rng: &mut Xoshiro256StarStar) -> Self {
        let mut s = [[0; W]; 4];
        for lane in 0..W {
            for word in &mut s {
                word[lane] = rng.next_u64();
            }
        }
        Self { s }
    }

    /// The state of lane `i`.
    #[inline(always)]
    fn state(&self, i: usize) -> [u64; 4] {
        [self.s[0][i], self.s[1][i], self.s[2][i], self.s[3][i]]
    }

    /// Next output of lane `i`.
    #[inline(always)]
    fn next_of(&mut self, i: usize) -> u64 {
        let mut st = self.state(i);
        let out = xoshiro_next(&mut st);
        for (word, v) in self.s.iter_mut().zip(st) {
            word[i] = v;
        }
        out
    }

    /// Next output of every lane.
    #[inline(always)]
    fn next(&mut self) -> [u64; W] {
        std::array::from_fn(|i| self.next_of(i))
    }
}

/// Lane `lane`'s stream as a generator, for the scalar code of faces and roulette.
struct LaneRng<'a> {
    streams: &'a mut Streams,
    lane: usize,
}

impl RngCore for LaneRng<'_> {
    fn next_u32(&mut self) -> u32 {
        (self.next_u64() >> 32) as u32
    }
    fn next_u64(&mut self) -> u64 {
        self.streams.next_of(self.lane)
    }
    fn fill_bytes(&mut self, dst: &mut [u8]) {
        rand::rand_core::impls::fill_bytes_via_next(self, dst);
    }
}

/// The lanes' photons, field by field, with the optics of each lane's layer.
struct Pack {
    x: [f64; W],
    y: [f64; W],
    z: [f64; W],
    ux: [f64; W],
    uy: [f64; W],
    uz: [f64; W],
    w: [f64; W],
    s_left: [f64; W],
    w_entry: [f64; W],
    layer: [usize; W],
    live: [bool; W],
    /// 1/σt of the lane's layer, mm; ∞ in a layer that neither absorbs nor scatters (its step is
    /// infinite, as in the scalar path).
    inv_mu_t: [f64; W],
    absorb: [f64; W],
    z_top: [f64; W],
    z_bottom: [f64; W],
    hg: HgLanes<W>,
}

impl Pack {
    /// Every lane parked (see [`Pack::park`]).
    fn parked(hg: &super::HgSampler) -> Self {
        let mut pack = Self {
            x: [0.0; W],
            y: [0.0; W],
            z: [0.0; W],
            ux: [0.0; W],
            uy: [0.0; W],
            uz: [0.0; W],
            w: [0.0; W],
            s_left: [0.0; W],
            w_entry: [0.0; W],
            layer: [0; W],
            live: [false; W],
            inv_mu_t: [0.0; W],
            absorb: [0.0; W],
            z_top: [0.0; W],
            z_bottom: [0.0; W],
            hg: HgLanes::splat(hg),
        };
        (0..W).for_each(|k| pack.park(k));
        pack
    }

    /// Lane `k` holds no photon: it stands still inside (−1, 1) with weight 1 and takes zero
    /// steps, so it never meets a face nor roulette and never reaches a subnormal weight.
    fn park(&mut self, k: usize) {
        self.live[k] = false;
        (self.x[k], self.y[k], self.z[k]) = (0.0, 0.0, 0.0);
        (self.ux[k], self.uy[k], self.uz[k]) = (0.0, 0.0, 1.0);
        (self.w[k], self.s_left[k], self.w_entry[k]) = (1.0, 0.0, 1.0);
        (self.inv_mu_t[k], self.absorb[k]) = (0.0, 0.0);
        (self.z_top[k], self.z_bottom[k]) = (-1.0, 1.0);
    }

    /// Lane `k`'s photon.
    #[inline(always)]
    fn photon(&self, k: usize) -> Photon {
        Photon {
            x: self.x[k],
            y: self.y[k],
            z: self.z[k],
            ux: self.ux[k],
            uy: self.uy[k],
            uz: self.uz[k],
            w: self.w[k],
            layer: self.layer[k],
        }
    }

    /// Lane `k`'s history, for the scalar code.
    fn get(&self, k: usize) -> Lane {
        Lane {
            p: self.photon(k),
            s_left: self.s_left[k],
            w_entry: self.w_entry[k],
        }
    }

    /// Lane `k` takes the photon `lane` and the optics of its layer.
    fn put(&mut self, k: usize, lane: &Lane, slabs: &[SlabOptics]) {
        let p = &lane.p;
        (self.x[k], self.y[k], self.z[k]) = (p.x, p.y, p.z);
        (self.ux[k], self.uy[k], self.uz[k]) = (p.ux, p.uy, p.uz);
        (self.w[k], self.s_left[k], self.w_entry[k]) = (p.w, lane.s_left, lane.w_entry);
        self.layer[k] = p.layer;
        self.live[k] = true;
        let slab = &slabs[p.layer];
        self.inv_mu_t[k] = if slab.mu_t == 0.0 {
            f64::INFINITY
        } else {
            slab.inv_mu_t
        };
        self.absorb[k] = slab.absorb_fraction;
        (self.z_top[k], self.z_bottom[k]) = (slab.z_top, slab.z_bottom);
        self.hg.set(k, &slab.hg);
    }

    /// One event in every lane: each draws its free path (unless it carries one over a face)
    /// and, if the step stays inside its layer, interacts there. Returns the lanes that need the
    /// scalar code (a face met: `s_left` > 0; a weight below roulette's threshold: `s_left` = 0)
    /// as a bit mask, and the number of interactions.
    #[inline(always)]
    fn event(&mut self, streams: &mut Streams) -> (u32, u64) {
        let r_free = streams.next();
        let r_cos = streams.next();
        let r_az = streams.next();
        let mut rare = [false; W];
        let mut interactions = [0u64; W];
        for i in 0..W {
            let s = if self.s_left[i] == 0.0 {
                free_path_from_bits(r_free[i])
            } else {
                self.s_left[i]
            };
            let step = s * self.inv_mu_t[i];
            let z_new = self.z[i] + step * self.uz[i];
            let face = reaches_face(self.uz[i], z_new, self.z_top[i], self.z_bottom[i]);
            let cos_t = self.hg.cos_theta(i, uniform_from_bits(r_cos[i]));
            let (cos_p, sin_p) = azimuth_from_bits(r_az[i]);
            let mut p = self.photon(i);
            p.interact(step, self.absorb[i], cos_t, cos_p, sin_p);
            let pick = |old: f64, new: f64| if face { old } else { new };
            self.x[i] = pick(self.x[i], p.x);
            self.y[i] = pick(self.y[i], p.y);
            self.z[i] = pick(self.z[i], p.z);
            self.ux[i] = pick(self.ux[i], p.ux);
            self.uy[i] = pick(self.uy[i], p.uy);
            self.uz[i] = pick(self.uz[i], p.uz);
            self.w[i] = pick(self.w[i], p.w);
            self.s_left[i] = pick(s, 0.0);
            rare[i] = face | (p.w < ROULETTE_THRESHOLD);
            interactions[i] = u64::from(!face & self.live[i]);
        }
        let mask = (0..W).fold(0u32, |m, i| m | u32::from(rare[i]) << i);
        (mask, interactions.iter().sum())
    }
}

/// Trace `photons` histories into `tally` in [`W`] lanes, on the widest instruction set the CPU
/// has.
pub(super) fn trace(
    slabs: &[SlabOptics],
    grid: RadialGrid,
    w0: f64,
    photons: u64,
    rng: &mut Xoshiro256StarStar,
    tally: &mut BatchTally,
) {
    pulp::Arch::new().dispatch(Trace {
        slabs,
        grid,
        w0,
        photons,
        rng,
        tally,
    });
}

/// The arguments of [`trace`], for `pulp`'s dispatch.
struct Trace<'a> {
    slabs: &'a [SlabOptics],
    grid: RadialGrid,
    w0: f64,
    photons: u64,
    rng: &'a mut Xoshiro256StarStar,
    tally: &'a mut BatchTally,
}

impl pulp::WithSimd for Trace<'_> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        trace_lanes(self);
    }
}

/// The lane loop, inlined into each instruction set's copy.
#[inline(always)]
fn trace_lanes(t: Trace<'_>) {
    let Trace {
        slabs,
        grid,
        w0,
        photons,
        rng,
        tally,
    } = t;
    let mut streams = Streams::seeded(rng);
    let mut pack = Pack::parked(&slabs[0].hg);
    let mut launched = 0u64;
    for k in 0..W {
        if launched < photons {
            pack.put(k, &Lane::launched(w0), slabs);
            launched += 1;
        }
    }
    let mut live = launched;
    while live > 0 {
        let (mut rare, interactions) = pack.event(&mut streams);
        tally.interactions += interactions;
        while rare != 0 {
            let k = rare.trailing_zeros() as usize;
            rare &= rare - 1;
            if !pack.live[k] {
                continue;
            }
            let mut lane = pack.get(k);
            let mut rng = LaneRng {
                streams: &mut streams,
                lane: k,
            };
            let ended = if lane.s_left > 0.0 {
                let slab = &slabs[lane.p.layer];
                let step = lane.s_left * pack.inv_mu_t[k];
                debug_assert!(slab.mu_t > 0.0 || step.is_infinite());
                lane.face(step, slabs, grid, &mut rng, tally)
            } else {
                lane.roulette(&mut rng, tally)
            };
            if !ended {
                pack.put(k, &lane, slabs);
            } else if launched < photons {
                pack.put(k, &Lane::launched(w0), slabs);
                launched += 1;
            } else {
                pack.park(k);
                live -= 1;
            }
        }
    }
    tally.photons += photons;
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn lane_streams_are_xoshiro256starstar() {
        let mut batch = Xoshiro256StarStar::seed_from_u64(7);
        let mut streams = Streams::seeded(&mut batch.clone());
        let mut seed = [0u8; 32];
        for k in 0..W {
            for (j, chunk) in seed.chunks_mut(8).enumerate() {
                chunk.copy_from_slice(&streams.state(k)[j].to_le_bytes());
            }
            let mut reference = Xoshiro256StarStar::from_seed(seed);
            for _ in 0..5 {
                assert_eq!(
                    LaneRng {
                        streams: &mut streams,
                        lane: k
                    }
                    .next_u64(),
                    reference.next_u64()
                );
            }
        }
        // Lane states are the batch generator's next 4 W draws.
        let first = batch.next_u64();
        assert_eq!(
            Streams::seeded(&mut Xoshiro256StarStar::seed_from_u64(7)).s[0][0],
            first
        );
    }

    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        // Two slabs with index steps (faces, Fresnel, roulette all exercised).
        let stack = crate::layered::LayeredMedium::new(
            vec![
                crate::layered::Layer::slab(1.0, 20.0, 0.8, 1.4, 0.2).unwrap(),
                crate::layered::Layer::slab(0.05, 10.0, 0.9, 1.3, 1.0).unwrap(),
            ],
            1.0,
            1.2,
        )
        .unwrap();
        let medium = super::super::Medium::new(&stack);
        let grid = RadialGrid::default();
        let traced = |dispatch: bool| {
            let mut tally = BatchTally::new(2, grid.bins());
            let mut rng = Xoshiro256StarStar::seed_from_u64(8);
            let t = Trace {
                slabs: &medium.slabs,
                grid,
                w0: 0.97,
                photons: 3000,
                rng: &mut rng,
                tally: &mut tally,
            };
            if dispatch {
                pulp::Arch::new().dispatch(t);
            } else {
                // Compiled for the build's baseline target only.
                trace_lanes(t);
            }
            format!("{tally:?}")
        };
        assert_eq!(traced(true), traced(false));
    }
}
