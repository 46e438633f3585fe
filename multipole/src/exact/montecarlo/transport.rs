//! One photon history, MCML style ([WJZ95] Wang, Jacques & Zheng 1995, §3–4): hop, drop, spin,
//! with boundary crossings handled by splitting the dimensionless step (§3.4).
//!
//! The geometry is z downwards from the lit face (z = 0). A layer that neither absorbs nor scatters
//! (σt = 0) is crossed in one move to its boundary. Interfaces reflect all-or-none with the exact
//! unpolarised Fresnel probability (MCML's default, [`brdf::fresnel::dielectric_reflectance`]).
//!
//! The photons run in SIMD lanes ([`lanes`]); the scalar path, one photon at a time, is kept as
//! their reference in the tests. Both share one interaction ([`Photon::interact`]), one face test
//! ([`reaches_face`]), one face crossing ([`Lane::face`]) and one roulette ([`Lane::roulette`]);
//! `trace_batch` and the scalar `trace_scalar` take the same arguments, so a test can run either.

mod free_path;
mod lanes;
mod sampling;
#[cfg(test)]
mod tests;
pub(crate) mod white;

use super::tally::{BatchTally, RadialGrid};
use crate::layered::{FaceReflector, LayeredMedium, Surface};
use brdf::fresnel::dielectric_reflectance;
use rand::RngCore;
#[cfg(test)]
use rand_distr::{Distribution, Exp1};
use rand_xoshiro::Xoshiro256StarStar;
pub use sampling::{HgSampler, scatter_direction};
use sampling::{turn, uniform};

/// Russian roulette starts below this weight ([WJZ95] §3.7: 1e-4).
pub const ROULETTE_THRESHOLD: f64 = 1.0e-4;
/// Survival chance of roulette ([WJZ95] §3.7: 1/10); survivors carry their weight × 10.
pub const ROULETTE_SURVIVAL: f64 = 0.1;

/// A layer prepared for the hot loop (all per-layer divisions done once).
#[derive(Debug, Clone)]
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
    /// The stack's surface on this layer's top and bottom face where that face is an outer one and
    /// the surface is not Fresnel's (`None`: Fresnel, as between layers).
    face_up: Option<FaceReflector>,
    face_down: Option<FaceReflector>,
}

/// The medium as the photon loop sees it.
#[derive(Debug, Clone)]
pub(crate) struct Medium {
    slabs: Vec<SlabOptics>,
}

impl Medium {
    pub fn new(stack: &LayeredMedium) -> Self {
        let layers = stack.layers();
        let last = layers.len() - 1;
        let outer = |n_slab: f64, n_out: f64| {
            (stack.surface() != Surface::Fresnel).then(|| stack.surface().reflector(n_slab, n_out))
        };
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
                face_up: if i == 0 {
                    outer(l.n(), stack.n_above())
                } else {
                    None
                },
                face_down: if i == last {
                    outer(l.n(), stack.n_below())
                } else {
                    None
                },
            });
            z = z_bottom;
        }
        Self { slabs }
    }

    /// Specular reflectance of the collimated normal beam at the top face ([WJZ95] eq 3.1; the
    /// surface's own at normal incidence).
    pub fn specular(&self, n_above: f64) -> f64 {
        match &self.slabs[0].face_up {
            Some(face) => face.reflectance(1.0),
            None => dielectric_reflectance(1.0, self.slabs[0].n / n_above),
        }
    }
}

/// The photon state: position (mm), direction cosines, weight, current layer.
#[derive(Debug, Clone, Copy)]
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

    /// An interaction `step` mm ahead ([WJZ95] §3.3, §3.6, §3.5): move there, deposit the
    /// fraction `absorb` = σa/σt of the weight (implicit capture), turn by the drawn polar cosine
    /// and azimuth. The one home of the interaction: the scalar and the lane paths both call it.
    #[inline(always)]
    fn interact(&mut self, step: f64, absorb: f64, cos_t: f64, cos_p: f64, sin_p: f64) {
        self.x += step * self.ux;
        self.y += step * self.uy;
        self.z += step * self.uz;
        self.w -= self.w * absorb;
        [self.ux, self.uy, self.uz] = turn([self.ux, self.uy, self.uz], cos_t, cos_p, sin_p);
    }
}

/// Does a step from depth `z` along direction cosine `uz` to depth `z_new` reach the face of the
/// layer [`z_top`, `z_bottom`] the photon heads for? (No division unless it does.) The sign of u_z
/// is a coin toss after each scattering, so both tests are evaluated and combined without
/// short-circuit: a branch on it would be mispredicted half the time.
#[inline(always)]
fn reaches_face(uz: f64, z_new: f64, z_top: f64, z_bottom: f64) -> bool {
    (uz > 0.0) & (z_new >= z_bottom) | (uz < 0.0) & (z_new <= z_top)
}

/// One history in flight.
#[derive(Debug, Clone, Copy)]
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
    fn launched(w0: f64) -> Self {
        Self {
            p: Photon::launched(w0),
            s_left: 0.0,
            w_entry: w0,
        }
    }

    /// One event of the scalar path: an interaction inside the layer or a meeting with a face.
    /// Returns true when the history has ended (escaped or lost to roulette), its weight tallied.
    #[cfg(test)]
    #[inline(always)]
    fn step(
        &mut self,
        slabs: &[SlabOptics],
        grid: RadialGrid,
        rng: &mut Xoshiro256StarStar,
        tally: &mut BatchTally,
    ) -> bool {
        let slab = &slabs[self.p.layer];
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
        let z_new = self.p.z + step * self.p.uz;
        if reaches_face(self.p.uz, z_new, slab.z_top, slab.z_bottom) {
            return self.face(step, slabs, grid, rng, tally);
        }
        let cos_t = slab.hg.cos_theta(uniform(rng));
        let (cos_p, sin_p) = sampling::sample_azimuth(rng);
        self.p
            .interact(step, slab.absorb_fraction, cos_t, cos_p, sin_p);
        self.s_left = 0.0;
        tally.interactions += 1;
        self.roulette(rng, tally)
    }

    /// Russian roulette after an interaction ([WJZ95] §3.7): below [`ROULETTE_THRESHOLD`] the
    /// photon survives with chance [`ROULETTE_SURVIVAL`], its weight raised to keep the
    /// expectation. Returns true when it died, its deposit tallied.
    #[inline(always)]
    fn roulette(&mut self, rng: &mut impl RngCore, tally: &mut BatchTally) -> bool {
        let p = &mut self.p;
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
        true
    }

    /// The photon meets the face it heads for within `step` mm ([WJZ95] §3.4, §3.8–3.9): move
    /// there, keep the unused optical depth, reflect or cross (escaping from the stack when it is
    /// the outer face). Returns true when the history has ended, its weight tallied.
    fn face(
        &mut self,
        step: f64,
        slabs: &[SlabOptics],
        grid: RadialGrid,
        rng: &mut impl RngCore,
        tally: &mut BatchTally,
    ) -> bool {
        let p = &mut self.p;
        let slab = &slabs[p.layer];
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
            let r = match if up { &slab.face_up } else { &slab.face_down } {
                Some(face) => face.reflectance(cos_i),
                None => dielectric_reflectance(cos_i, eta),
            };
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
/// The photons run in SIMD lanes ([`lanes`]), each lane with its own generator stream seeded from
/// the batch's generator, so the result depends only on the batch's generator, never on the
/// thread count or the instruction set.
pub(crate) fn trace_batch(
    medium: &Medium,
    grid: RadialGrid,
    w0: f64,
    photons: u64,
    rng: &mut Xoshiro256StarStar,
    tally: &mut BatchTally,
) {
    lanes::trace(&medium.slabs, grid, w0, photons, rng, tally);
}

/// The scalar path, one photon at a time: the reference the lanes are tested against.
#[cfg(test)]
fn trace_scalar(
    medium: &Medium,
    grid: RadialGrid,
    w0: f64,
    photons: u64,
    rng: &mut Xoshiro256StarStar,
    tally: &mut BatchTally,
) {
    for _ in 0..photons {
        let mut lane = Lane::launched(w0);
        while !lane.step(&medium.slabs, grid, rng, tally) {}
    }
    tally.photons += photons;
}
