//! The random draws of one scattering ([WJZ95] §3.5): Henyey–Greenstein polar cosine, a uniform
//! azimuth, and the rotation of the direction.

use super::Photon;
use rand::RngCore;

/// |u_z| above which a direction is treated as along the normal when rotating ([WJZ95] eq 3.20).
const COS_ZERO: f64 = 1.0 - 1.0e-12;

/// Uniform in [0, 1) with 53 random bits.
#[inline(always)]
pub(super) fn uniform(rng: &mut impl RngCore) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Henyey–Greenstein cosine sampling ([WJZ95] eq 3.15) with the per-layer constants hoisted:
/// cos θ = (1 + g² − t²) / (2g), t = (1 − g²) / (1 − g + 2gξ); isotropic (2ξ − 1) when g ≈ 0.
#[derive(Debug, Clone, Copy)]
pub(super) struct HgSampler {
    isotropic: bool,
    one_plus_g2: f64,
    one_minus_g2: f64,
    one_minus_g: f64,
    two_g: f64,
    inv_two_g: f64,
}

impl HgSampler {
    pub(super) fn new(g: f64) -> Self {
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

/// Uniform azimuth as (cos φ, sin φ) from one 64-bit draw, with no branch and no division:
/// φ = d + kπ/2 with k uniform in {0, 1, 2, 3} (the top two bits) and d uniform in [−π/4, π/4)
/// (the low 53 bits) is uniform on the circle. cos d and sin d come from their Taylor series,
/// which on |d| ≤ π/4 are below one ulp after the d¹⁶ and d¹⁷ terms (next terms ≤ 2e-18);
/// the quarter turn k is applied exactly (multiplications by 0 and ±1).
#[inline(always)]
fn sample_azimuth(rng: &mut impl RngCore) -> (f64, f64) {
    const COS_K: [f64; 4] = [1.0, 0.0, -1.0, 0.0];
    const SIN_K: [f64; 4] = [0.0, 1.0, 0.0, -1.0];
    let bits = rng.next_u64();
    let k = (bits >> 62) as usize;
    let t = (bits & ((1u64 << 53) - 1)) as f64 * (1.0 / (1u64 << 52) as f64) - 1.0;
    let d = t * std::f64::consts::FRAC_PI_4;
    let (c, s) = cos_sin_small(d);
    (c * COS_K[k] - s * SIN_K[k], s * COS_K[k] + c * SIN_K[k])
}

/// cos d and sin d for |d| ≤ π/4 by Taylor series in d² (Horner), accurate to an ulp or two.
#[inline(always)]
fn cos_sin_small(d: f64) -> (f64, f64) {
    // 1/(2j)! and 1/(2j+1)! for j = 1..8.
    const C: [f64; 8] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
        -1.0 / 87_178_291_200.0,
        1.0 / 20_922_789_888_000.0,
    ];
    const S: [f64; 8] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5_040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 1_307_674_368_000.0,
        1.0 / 355_687_428_096_000.0,
    ];
    let d2 = d * d;
    let (mut c, mut s) = (C[7], S[7]);
    for j in (0..7).rev() {
        c = c * d2 + C[j];
        s = s * d2 + S[j];
    }
    (1.0 + d2 * c, d + d * d2 * s)
}

/// New direction after a Henyey–Greenstein scattering ([WJZ95] eqs 3.15–3.20).
#[inline(always)]
pub(super) fn scatter(p: &mut Photon, hg: &HgSampler, rng: &mut impl RngCore) {
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
