//! One photon history, MCML style ([WJZ95] Wang, Jacques & Zheng 1995, §3–4): hop, drop, spin,
//! with boundary crossings handled by splitting the dimensionless step (§3.4).
//!
//! The geometry is z downwards from the lit face (z = 0). A layer that neither absorbs nor scatters
//! (σt = 0) is crossed in one move to its boundary. Interfaces reflect all-or-none with the exact
//! unpolarised Fresnel probability (MCML's default, [`brdf::fresnel::dielectric_reflectance`]).

use super::stack::LayerStack;
use super::tally::{BatchTally, RadialGrid};
use brdf::fresnel::dielectric_reflectance;
use rand::RngCore;
use rand_distr::{Distribution, Exp1};

/// Russian roulette starts below this weight ([WJZ95] §3.7: 1e-4).
pub const ROULETTE_THRESHOLD: f64 = 1.0e-4;
/// Survival chance of roulette ([WJZ95] §3.7: 1/10); survivors carry their weight × 10.
pub const ROULETTE_SURVIVAL: f64 = 0.1;
/// |u_z| above which a direction is treated as along the normal when rotating ([WJZ95] eq 3.20).
const COS_ZERO: f64 = 1.0 - 1.0e-12;

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
    pub fn new(stack: &LayerStack) -> Self {
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

/// Uniform in [0, 1) with 53 random bits.
#[inline(always)]
fn uniform(rng: &mut impl RngCore) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Henyey–Greenstein cosine sampling ([WJZ95] eq 3.15) with the per-layer constants hoisted:
/// cos θ = (1 + g² − t²) / (2g), t = (1 − g²) / (1 − g + 2gξ); isotropic (2ξ − 1) when g ≈ 0.
#[derive(Debug, Clone, Copy)]
struct HgSampler {
    isotropic: bool,
    one_plus_g2: f64,
    one_minus_g2: f64,
    one_minus_g: f64,
    two_g: f64,
    inv_two_g: f64,
}

impl HgSampler {
    fn new(g: f64) -> Self {
        let isotropic = g.abs() < 1.0e-6;
        Self {
            isotropic,
            one_plus_g2: 1.0 + g * g,
            one_minus_g2: 1.0 - g * g,
            one_minus_g: 1.0 - g,
            two_g: 2.0 * g,
            inv_two_g: if isotropic { 0.0 } else { 0.5 / g },
        }
    }

    #[inline(always)]
    fn cos_theta(&self, xi: f64) -> f64 {
        if self.isotropic {
            return 2.0 * xi - 1.0;
        }
        let t = self.one_minus_g2 / (self.one_minus_g + self.two_g * xi);
        ((self.one_plus_g2 - t * t) * self.inv_two_g).clamp(-1.0, 1.0)
    }
}

/// The photon state: position (mm), direction cosines, weight, current layer.
struct Photon {
    x: f64,
    y: f64,
    z: f64,
    ux: f64,
    uy: f64,
    uz: f64,
    w: f64,
    layer: usize,
}

/// Trace `photons` histories into `tally` ([WJZ95] §3–4). `w0` = 1 − R_spec is the launch weight.
pub(crate) fn trace_batch(
    medium: &Medium,
    grid: RadialGrid,
    w0: f64,
    photons: u64,
    rng: &mut impl RngCore,
    tally: &mut BatchTally,
) {
    let slabs = &medium.slabs[..];
    let last = slabs.len() - 1;
    for _ in 0..photons {
        let mut p = Photon {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            ux: 0.0,
            uy: 0.0,
            uz: 1.0,
            w: w0,
            layer: 0,
        };
        // Remaining dimensionless step (optical depth) carried over a boundary ([WJZ95] §3.4).
        let mut s_left = 0.0;
        loop {
            let slab = &slabs[p.layer];
            let step = if slab.mu_t == 0.0 {
                f64::INFINITY
            } else {
                if s_left == 0.0 {
                    // Exponential optical depth, −ln ξ in distribution ([WJZ95] eq 3.8), drawn by
                    // the ziggurat method: exact, and about twice as fast as the logarithm.
                    s_left = Exp1.sample(rng);
                }
                s_left * slab.inv_mu_t
            };
            // Does the step reach the face the photon heads for? (No division unless it does.)
            let z_new = p.z + step * p.uz;
            let crosses = if p.uz > 0.0 {
                z_new >= slab.z_bottom
            } else {
                p.uz < 0.0 && z_new <= slab.z_top
            };
            if crosses {
                // Hit the face: move there, keep the unused optical depth, cross or reflect.
                let up = p.uz < 0.0;
                let d_face = (if up { slab.z_top } else { slab.z_bottom } - p.z) / p.uz;
                p.x += d_face * p.ux;
                p.y += d_face * p.uy;
                // Rounding may make d_face exceed the step by an ulp: never carry a negative depth.
                s_left = if slab.mu_t == 0.0 {
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
                    continue;
                }
                let ratio = slab.n / n_next;
                if up {
                    if p.layer == 0 {
                        tally.diffuse_reflectance += p.w;
                        let r = (p.x * p.x + p.y * p.y).sqrt();
                        match grid.bin(r) {
                            Some(bin) => tally.radial[bin] += p.w,
                            None => tally.beyond_grid += p.w,
                        }
                        break;
                    }
                    p.layer -= 1;
                    p.uz = -cos_t;
                } else {
                    if p.layer == last {
                        tally.transmittance += p.w;
                        break;
                    }
                    p.layer += 1;
                    p.uz = cos_t;
                }
                p.ux *= ratio;
                p.uy *= ratio;
                continue;
            }
            // Interaction inside the layer: move, deposit σa/σt of the weight, scatter.
            p.x += step * p.ux;
            p.y += step * p.uy;
            p.z += step * p.uz;
            s_left = 0.0;
            let dw = p.w * slab.absorb_fraction;
            tally.absorbed_by_layer[p.layer] += dw;
            p.w -= dw;
            tally.interactions += 1;
            scatter(&mut p, &slab.hg, rng);
            if p.w < ROULETTE_THRESHOLD {
                if uniform(rng) < ROULETTE_SURVIVAL {
                    let gained = p.w * (1.0 / ROULETTE_SURVIVAL - 1.0);
                    tally.roulette_balance -= gained;
                    p.w += gained;
                } else {
                    tally.roulette_balance += p.w;
                    break;
                }
            }
        }
    }
    tally.photons += photons;
}

/// Uniform azimuth as (cos φ, sin φ) without trigonometry: a point uniform in the unit disc, squared
/// as a complex number, has a uniform angle 2θ; its cosine and sine are (x² − y², 2xy) / r².
#[inline(always)]
fn sample_azimuth(rng: &mut impl RngCore) -> (f64, f64) {
    loop {
        let x = 2.0 * uniform(rng) - 1.0;
        let y = 2.0 * uniform(rng) - 1.0;
        let r2 = x * x + y * y;
        if r2 <= 1.0 && r2 > 1.0e-300 {
            let inv = 1.0 / r2;
            return ((x * x - y * y) * inv, 2.0 * x * y * inv);
        }
    }
}

/// New direction after a Henyey–Greenstein scattering ([WJZ95] eqs 3.15–3.20).
#[inline(always)]
fn scatter(p: &mut Photon, hg: &HgSampler, rng: &mut impl RngCore) {
    let cos_t = hg.cos_theta(uniform(rng));
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let (cos_p, sin_p) = sample_azimuth(rng);
    if p.uz.abs() > COS_ZERO {
        p.ux = sin_t * cos_p;
        p.uy = sin_t * sin_p;
        // Not copysign: the sampled cosine keeps its own sign, relative to the current direction.
        p.uz = if p.uz > 0.0 { cos_t } else { -cos_t };
    } else {
        let tmp = (1.0 - p.uz * p.uz).sqrt();
        let inv = 1.0 / tmp;
        let ux = sin_t * (p.ux * p.uz * cos_p - p.uy * sin_p) * inv + p.ux * cos_t;
        let uy = sin_t * (p.uy * p.uz * cos_p + p.ux * sin_p) * inv + p.uy * cos_t;
        p.uz = -sin_t * cos_p * tmp + p.uz * cos_t;
        p.ux = ux;
        p.uy = uy;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256StarStar;

    #[test]
    fn azimuth_is_uniform_on_the_circle() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(2);
        let n = 100_000;
        let mut hist = [0u32; 8];
        for _ in 0..n {
            let (c, s) = sample_azimuth(&mut rng);
            assert!((c * c + s * s - 1.0).abs() < 1e-12);
            let phi = s.atan2(c) + std::f64::consts::PI;
            hist[((phi / (2.0 * std::f64::consts::PI) * 8.0) as usize).min(7)] += 1;
        }
        // Each octant expects n/8 = 12500 ± 105 (binomial): 5σ ≈ 520.
        for h in hist {
            assert!((f64::from(h) - 12_500.0).abs() < 520.0, "{hist:?}");
        }
    }

    #[test]
    fn hg_sample_mean_cosine_is_g() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(1);
        for g in [0.0, 0.5, 0.9, -0.3] {
            let n = 200_000;
            let hg = HgSampler::new(g);
            let m: f64 = (0..n).map(|_| hg.cos_theta(uniform(&mut rng))).sum::<f64>() / n as f64;
            // sd of cos θ ≤ 1, so 5 standard errors ≤ 5/√n ≈ 0.011.
            assert!((m - g).abs() < 0.011, "g {g}: mean cosine {m}");
        }
    }
}
