//! One photon history, MCML style ([WJZ95] Wang, Jacques & Zheng 1995, §3–4): hop, drop, spin,
//! with boundary crossings handled by splitting the dimensionless step (§3.4).
//!
//! The geometry is z downwards from the lit face (z = 0). A layer that neither absorbs nor scatters
//! (σt = 0) is crossed in one move to its boundary. Interfaces reflect all-or-none with the exact
//! unpolarised Fresnel probability (MCML's default, [`brdf::fresnel::dielectric_reflectance`]).

mod sampling;
#[cfg(test)]
mod tests;
pub(crate) mod white;

use super::tally::{BatchTally, RadialGrid};
use crate::layered::LayeredMedium;
use brdf::fresnel::dielectric_reflectance;
use rand_distr::{Distribution, Exp1};
use rand_xoshiro::Xoshiro256StarStar;
pub use sampling::{HgSampler, scatter_direction};
use sampling::{scatter, uniform};

/// Russian roulette starts below this weight ([WJZ95] §3.7: 1e-4).
pub const ROULETTE_THRESHOLD: f64 = 1.0e-4;
/// Survival chance of roulette ([WJZ95] §3.7: 1/10); survivors carry their weight × 10.
pub const ROULETTE_SURVIVAL: f64 = 0.1;

/// A layer prepared for the hot loop (all per-layer divisions done once).
#[derive(Debug, Clone, Copy)]
pub(crate) struct SlabOptics {
    z_top: f64,
    /// `f64::INFINITY` for a semi-infinite layer.
    z_bottom: f64,
    mu_t: f64,
    inv_mu_t: f64,
    /// σa / σt: the fraction of the weight deposited at each interaction (implicit capture).
    absorb_fraction: f64,
    /// Henyey–Greenstein sampling constants, precomputed (see [`HgSampler`]).
    hg: HgSampler,
    n: f64,
    /// Index beyond the top and the bottom face of this layer.
    n_up: f64,
    n_down: f64,
}

/// The medium as the photon loop sees it.
#[derive(Debug, Clone)]
pub(crate) struct Medium {
    slabs: Vec<SlabOptics>,
}

impl Medium {
    pub fn new(stack: &LayeredMedium) -> Self {
        let layers = stack.layers();
        let mut z = 0.0;
        let mut slabs = Vec::with_capacity(layers.len());
        for (i, l) in layers.iter().enumerate() {
            let mu_t = l.sigma_a() + l.sigma_s();
            let z_bottom = l.thickness_mm().map_or(f64::INFINITY, |d| z + d);
            slabs.push(SlabOptics {
                z_top: z,
                z_bottom,
                mu_t,
                inv_mu_t: if mu_t > 0.0 { 1.0 / mu_t } else { 0.0 },
                absorb_fraction: if mu_t > 0.0 { l.sigma_a() / mu_t } else { 0.0 },
                hg: HgSampler::new(l.g()),
                n: l.n(),
                n_up: if i == 0 {
                    stack.n_above()
                } else {
                    layers[i - 1].n()
                },
                n_down: layers.get(i + 1).map_or(stack.n_below(), |b| b.n()),
            });
            z = z_bottom;
        }
        Self { slabs }
    }

    /// Specular reflectance of the collimated normal beam at the top face ([WJZ95] eq 3.1).
    pub fn specular(&self, n_above: f64) -> f64 {
        dielectric_reflectance(1.0, self.slabs[0].n / n_above)
    }
}

/// Photons traced side by side in one batch. Each history is a long chain of dependent square
/// roots and divisions; interleaving independent histories lets the out-of-order core overlap
/// their chains. Measured on the half-space case (BENCHMARKS.md, "Monte Carlo (validation)"):
/// 19.9 ns per scattering with 1 lane, 16.8 with 2, 17.0 with 3, 16.9 with 4.
pub(crate) const LANES: usize = 2;

/// The photon state: position (mm), direction cosines, weight, current layer.
pub(super) struct Photon {
    pub(super) x: f64,
    pub(super) y: f64,
    pub(super) z: f64,
    pub(super) ux: f64,
    pub(super) uy: f64,
    pub(super) uz: f64,
    pub(super) w: f64,
    pub(super) layer: usize,
}

impl Photon {
    /// A collimated photon of weight `w` entering the top layer at the origin along +z.
    pub(super) fn launched(w: f64) -> Self {
        Self {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            ux: 0.0,
            uy: 0.0,
            uz: 1.0,
            w,
            layer: 0,
        }
    }
}

/// One history in flight.
struct Lane {
    p: Photon,
    /// Remaining dimensionless step (optical depth) carried over a boundary ([WJZ95] §3.4).
    s_left: f64,
    /// Weight on entering the current layer. Implicit capture only multiplies the weight inside a
    /// layer, so the photon deposits `w_entry − w` there: one tally store per layer visit, not one
    /// per interaction. A roulette win raises both (its gain is booked in `roulette_balance`).
    w_entry: f64,
}

impl Lane {
    /// A collimated photon of weight `w0` entering at the origin along +z.
    fn launch(&mut self, w0: f64) {
        self.p = Photon::launched(w0);
        self.s_left = 0.0;
        self.w_entry = w0;
    }

    /// One event: an interaction inside the layer or a meeting with a face. Returns true when the
    /// history has ended (escaped or lost to roulette), its weight tallied.
    #[inline(always)]
    fn step(
        &mut self,
        slabs: &[SlabOptics],
        grid: RadialGrid,
        rng: &mut Xoshiro256StarStar,
        tally: &mut BatchTally,
    ) -> bool {
        let p = &mut self.p;
        let slab = &slabs[p.layer];
        let step = if slab.mu_t == 0.0 {
            f64::INFINITY
        } else {
            if self.s_left == 0.0 {
                // Exponential optical depth, −ln ξ in distribution ([WJZ95] eq 3.8), drawn by
                // the ziggurat method: exact, and about twice as fast as the logarithm.
                self.s_left = Exp1.sample(rng);
            }
            self.s_left * slab.inv_mu_t
        };
        // Does the step reach the face the photon heads for? (No division unless it does.) The
        // sign of u_z is a coin toss after each scattering, so both tests are evaluated and
        // combined without short-circuit: a branch on it would be mispredicted half the time.
        let z_new = p.z + step * p.uz;
        let crosses =
            (p.uz > 0.0) & (z_new >= slab.z_bottom) | (p.uz < 0.0) & (z_new <= slab.z_top);
        if !crosses {
            // Interaction inside the layer: move, deposit σa/σt of the weight, scatter.
            p.x += step * p.ux;
            p.y += step * p.uy;
            p.z = z_new;
            self.s_left = 0.0;
            p.w -= p.w * slab.absorb_fraction;
            tally.interactions += 1;
            scatter(p, &slab.hg, rng);
            if p.w >= ROULETTE_THRESHOLD {
                return false;
            }
            if uniform(rng) < ROULETTE_SURVIVAL {
                let gained = p.w * (1.0 / ROULETTE_SURVIVAL - 1.0);
                tally.roulette_balance -= gained;
                p.w += gained;
                self.w_entry += gained;
                return false;
            }
            tally.absorbed_by_layer[p.layer] += self.w_entry - p.w;
            tally.roulette_balance += p.w;
            return true;
        }
        // Hit the face: move there, keep the unused optical depth, cross or reflect.
        let up = p.uz < 0.0;
        let d_face = (if up { slab.z_top } else { slab.z_bottom } - p.z) / p.uz;
        p.x += d_face * p.ux;
        p.y += d_face * p.uy;
        // Rounding may make d_face exceed the step by an ulp: never carry a negative depth.
        self.s_left = if slab.mu_t == 0.0 {
            0.0
        } else {
            ((step - d_face) * slab.mu_t).max(0.0)
        };
        p.z = if up { slab.z_top } else { slab.z_bottom };
        let n_next = if up { slab.n_up } else { slab.n_down };
        let cos_i = p.uz.abs();
        let (reflect, cos_t) = if n_next == slab.n {
            (false, cos_i)
        } else {
            let eta = n_next / slab.n;
            let r = dielectric_reflectance(cos_i, eta);
            // Fresnel gives 1 under total internal reflection, so no transmission then.
            let reflect = r >= 1.0 || uniform(rng) < r;
            let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
            (reflect, (1.0 - sin2_t).max(0.0).sqrt())
        };
        if reflect {
            p.uz = -p.uz;
            return false;
        }
        let ratio = slab.n / n_next;
        tally.absorbed_by_layer[p.layer] += self.w_entry - p.w;
        self.w_entry = p.w;
        if up {
            if p.layer == 0 {
                tally.diffuse_reflectance += p.w;
                let r = (p.x * p.x + p.y * p.y).sqrt();
                match grid.bin(r) {
                    Some(bin) => tally.radial[bin] += p.w,
                    None => tally.beyond_grid += p.w,
                }
                return true;
            }
            p.layer -= 1;
            p.uz = -cos_t;
        } else {
            if p.layer == slabs.len() - 1 {
                tally.transmittance += p.w;
                return true;
            }
            p.layer += 1;
            p.uz = cos_t;
        }
        p.ux *= ratio;
        p.uy *= ratio;
        false
    }
}

/// Trace `photons` histories into `tally` ([WJZ95] §3–4). `w0` = 1 − R_spec is the launch weight.
///
/// [`LANES`] histories are in flight at once; a lane whose photon ends starts the batch's next one
/// until `photons` have been launched. The lanes take turns, one event each, drawing from the
/// batch's one stream, so the result depends only on the batch's generator, never on the thread
/// count.
pub(crate) fn trace_batch(
    medium: &Medium,
    grid: RadialGrid,
    w0: f64,
    photons: u64,
    rng: &mut Xoshiro256StarStar,
    tally: &mut BatchTally,
) {
    trace_lanes::<LANES>(medium, grid, w0, photons, rng, tally);
}

/// [`trace_batch`] with `K` lanes. Its signature repeats `trace_batch`'s on purpose: the wrapper
/// fixes the lane count for callers, tests run this one at other counts.
fn trace_lanes<const K: usize>(
    medium: &Medium,
    grid: RadialGrid,
    w0: f64,
    photons: u64,
    rng: &mut Xoshiro256StarStar,
    tally: &mut BatchTally,
) {
    let slabs = &medium.slabs[..];
    // A local copy the optimiser can keep in registers; the batch's generator is not reused.
    let mut rng = rng.clone();
    let mut lanes: [Lane; K] = std::array::from_fn(|_| {
        let mut lane = Lane {
            p: Photon::launched(0.0),
            s_left: 0.0,
            w_entry: 0.0,
        };
        lane.launch(w0);
        lane
    });
    let mut live = [false; K];
    let mut launched = 0u64;
    for l in &mut live {
        if launched < photons {
            *l = true;
            launched += 1;
        }
    }
    let mut n_live = live.iter().filter(|&&l| l).count();
    while n_live > 0 {
        for (lane, l) in lanes.iter_mut().zip(live.iter_mut()) {
            if *l && lane.step(slabs, grid, &mut rng, tally) {
                if launched < photons {
                    lane.launch(w0);
                    launched += 1;
                } else {
                    *l = false;
                    n_live -= 1;
                }
            }
        }
    }
    tally.photons += photons;
}
