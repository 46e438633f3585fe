//! The random draws of one scattering ([WJZ95] §3.5): Henyey–Greenstein polar cosine, a uniform
//! azimuth, and the rotation of the direction.

use super::Photon;
use rand::RngCore;

/// |u_z| above which a direction is treated as along the normal when rotating ([WJZ95] eq 3.20).
const COS_ZERO: f64 = 1.0 - 1.0e-12;

/// Uniform in [0, 1) on the grid k·2⁻⁵²: the top 52 random bits as the mantissa of a number in
/// [1, 2), minus 1 (three integer and float operations, no integer-to-float conversion).
#[inline(always)]
pub(super) fn uniform(rng: &mut impl RngCore) -> f64 {
    f64::from_bits((rng.next_u64() >> 12) | ONE_BITS) - 1.0
}

/// Bit pattern of 1.0: sign 0, exponent 1023, mantissa 0.
const ONE_BITS: u64 = 0x3ff0_0000_0000_0000;

/// Henyey–Greenstein cosine sampling ([WJZ95] eq 3.15) with the per-layer constants hoisted:
/// cos θ = (1 + g² − t²) / (2g), t = (1 − g²) / (1 − g + 2gξ); isotropic (2ξ − 1) when g ≈ 0.
#[derive(Debug, Clone, Copy)]
pub struct HgSampler {
    isotropic: bool,
    one_plus_g2: f64,
    one_minus_g2: f64,
    one_minus_g: f64,
    two_g: f64,
    inv_two_g: f64,
}

impl HgSampler {
    /// The sampler of HG anisotropy `g` in (−1, 1) (|g| < 1e-6 samples the isotropic phase).
    #[must_use]
    pub fn new(g: f64) -> Self {
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

    /// The scattering cosine for a uniform `xi` in [0, 1) ([WJZ95] eq 3.15).
    #[inline(always)]
    #[must_use]
    pub fn cos_theta(&self, xi: f64) -> f64 {
        if self.isotropic {
            return 2.0 * xi - 1.0;
        }
        let t = self.one_minus_g2 / (self.one_minus_g + self.two_g * xi);
        ((self.one_plus_g2 - t * t) * self.inv_two_g).clamp(-1.0, 1.0)
    }
}

/// Uniform azimuth as (cos φ, sin φ) from one 64-bit draw, with no branch and no division:
/// φ = d + kπ/4 with k uniform in 0..8 (the top three bits) and d uniform in [−π/8, π/8)
/// (the low 52 bits) is uniform on the circle. cos d and sin d come from their Taylor series,
/// which on |d| ≤ π/8 are below an ulp after the d¹² and d¹³ terms (the next terms are
/// ≤ 3e-17 relative); the turn by kπ/4 is one complex multiplication.
#[inline(always)]
pub(super) fn sample_azimuth(rng: &mut impl RngCore) -> (f64, f64) {
    use std::f64::consts::{FRAC_1_SQRT_2 as H, FRAC_PI_8};
    const COS_K: [f64; 8] = [1.0, H, 0.0, -H, -1.0, -H, 0.0, H];
    const SIN_K: [f64; 8] = [0.0, H, 1.0, H, 0.0, -H, -1.0, -H];
    let bits = rng.next_u64();
    let k = (bits >> 61) as usize;
    // The low 52 bits as the mantissa of a number in [2, 4), minus 3: t uniform in [−1, 1).
    let t = f64::from_bits((bits & ((1u64 << 52) - 1)) | (ONE_BITS + (1u64 << 52))) - 3.0;
    let (c, s) = cos_sin_small(t * FRAC_PI_8);
    (c * COS_K[k] - s * SIN_K[k], s * COS_K[k] + c * SIN_K[k])
}

/// cos d and sin d for |d| ≤ π/8 by Taylor series in d² (Horner), accurate to an ulp or two.
#[inline(always)]
fn cos_sin_small(d: f64) -> (f64, f64) {
    // 1/(2j)! and (−1)ʲ/(2j+1)! for j = 1..6, alternating signs.
    const C: [f64; 6] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
    ];
    const S: [f64; 6] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5_040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
    ];
    let d2 = d * d;
    let (mut c, mut s) = (C[5], S[5]);
    for j in (0..5).rev() {
        c = c * d2 + C[j];
        s = s * d2 + S[j];
    }
    (1.0 + d2 * c, d + d * d2 * s)
}

/// The unit direction `u` = (u_x, u_y, u_z) after one Henyey–Greenstein scattering with `hg`
/// ([WJZ95] eqs 3.15–3.20): the photon physics of this Monte Carlo, for walks in other geometries
/// (the renderer's volumetric integrator).
#[inline]
pub fn scatter_direction(u: [f64; 3], hg: &HgSampler, rng: &mut impl RngCore) -> [f64; 3] {
    let mut p = Photon::launched(1.0);
    (p.ux, p.uy, p.uz) = (u[0], u[1], u[2]);
    scatter(&mut p, hg, rng);
    [p.ux, p.uy, p.uz]
}

/// New direction after a Henyey–Greenstein scattering ([WJZ95] eqs 3.15–3.20).
///
/// Eq 3.20 needs sin θ / √(1 − u_z²) and sin θ · √(1 − u_z²); both come from one square root,
/// q = √((1 − cos²θ)(1 − u_z²)), as q / (1 − u_z²) and q: one square root and one division
/// fewer than taking sin θ and √(1 − u_z²) apart.
#[inline(always)]
pub(super) fn scatter(p: &mut Photon, hg: &HgSampler, rng: &mut impl RngCore) {
    let cos_t = hg.cos_theta(uniform(rng));
    // |cos θ| ≤ 1 (clamped), so its rounded square is ≤ 1 and this is never negative.
    let sin2_t = 1.0 - cos_t * cos_t;
    let (cos_p, sin_p) = sample_azimuth(rng);
    if p.uz.abs() > COS_ZERO {
        let sin_t = sin2_t.sqrt();
        p.ux = sin_t * cos_p;
        p.uy = sin_t * sin_p;
        // Not copysign: the sampled cosine keeps its own sign, relative to the current direction.
        p.uz = if p.uz > 0.0 { cos_t } else { -cos_t };
    } else {
        let one_minus_uz2 = 1.0 - p.uz * p.uz;
        let q = (sin2_t * one_minus_uz2).sqrt();
        let q_over = q / one_minus_uz2;
        let ux = q_over * (p.ux * p.uz * cos_p - p.uy * sin_p) + p.ux * cos_t;
        let uy = q_over * (p.uy * p.uz * cos_p + p.ux * sin_p) + p.uy * cos_t;
        p.uz = p.uz * cos_t - q * cos_p;
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
        let n = 120_000;
        // 24 bins: none aligned with the 8 sectors the sampler builds φ from.
        let mut hist = [0u32; 24];
        for _ in 0..n {
            let (c, s) = sample_azimuth(&mut rng);
            assert!((c * c + s * s - 1.0).abs() < 1e-15);
            let phi = s.atan2(c) + std::f64::consts::PI;
            hist[((phi / (2.0 * std::f64::consts::PI) * 24.0) as usize).min(23)] += 1;
        }
        // Each bin expects n/24 = 5000 ± 70 (binomial): 5σ ≈ 350.
        for h in hist {
            assert!((f64::from(h) - 5_000.0).abs() < 350.0, "{hist:?}");
        }
    }

    #[test]
    fn short_series_match_libm_cos_and_sin() {
        let h = std::f64::consts::FRAC_PI_8;
        let mut worst = 0.0f64;
        for i in 0..=10_000 {
            let d = -h + 2.0 * h * f64::from(i) / 10_000.0;
            let (c, s) = cos_sin_small(d);
            worst = worst.max((c - d.cos()).abs()).max((s - d.sin()).abs());
        }
        // Two ulps of values below 1.
        assert!(worst <= 2.3e-16, "{worst:e}");
    }

    #[test]
    fn scattering_turns_by_hg_angles_and_keeps_unit_length() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(4);
        let hg = HgSampler::new(0.9);
        let mut p = Photon::launched(1.0);
        let n = 200_000;
        let (mut sum, mut sum_z) = (0.0, 0.0);
        for _ in 0..n {
            let u = (p.ux, p.uy, p.uz);
            scatter(&mut p, &hg, &mut rng);
            sum += u.0 * p.ux + u.1 * p.uy + u.2 * p.uz;
            sum_z += p.uz;
        }
        let norm = (p.ux * p.ux + p.uy * p.uy + p.uz * p.uz).sqrt();
        assert!(
            (norm - 1.0).abs() < 1e-9,
            "|u| = {norm} after {n} scatterings"
        );
        // Mean cosine between successive directions is g, with the HG variance
        // (1 + 2g²)/3 − g² (its second Legendre moment is g²): sd 0.2517 at g = 0.9, so five
        // standard errors over n turns are 5 · 0.2516/√n = 0.0028.
        let mean = sum / f64::from(n);
        assert!(
            (mean - 0.9).abs() < 5.0 * hg_sd(0.9) / f64::from(n).sqrt(),
            "mean turn cosine {mean}"
        );
        // No preferred direction: the mean u_z vanishes. Successive u_z are an AR(1) chain with
        // correlation g (E[u_z' | u_z] = g u_z), so the variance of the mean is
        // Var(u_z)/n · (1 + g)/(1 − g) = (1/3)(19)/n: sd 0.0056, five of them 0.028.
        assert!(
            (sum_z / f64::from(n)).abs() < 5.0 * (19.0 / 3.0 / f64::from(n)).sqrt(),
            "mean u_z {}",
            sum_z / f64::from(n)
        );
    }

    #[test]
    fn hg_sample_mean_cosine_is_g() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(1);
        for g in [0.0, 0.5, 0.9, -0.3] {
            let n = 200_000;
            let hg = HgSampler::new(g);
            let m: f64 = (0..n).map(|_| hg.cos_theta(uniform(&mut rng))).sum::<f64>() / n as f64;
            // Five standard errors of the mean, from the HG variance (0.0065 at g = 0, 0.0028
            // at g = 0.9).
            let bound = 5.0 * hg_sd(g) / f64::from(n).sqrt();
            assert!(
                (m - g).abs() < bound,
                "g {g}: mean cosine {m}, bound {bound}"
            );
        }
    }

    /// Standard deviation of cos θ under Henyey–Greenstein with anisotropy g:
    /// E[cos²θ] = (1 + 2g²)/3 (the second Legendre moment of HG is g²), so
    /// Var = (1 + 2g²)/3 − g² = (1 − g²)/3.
    fn hg_sd(g: f64) -> f64 {
        ((1.0 - g * g) / 3.0).sqrt()
    }
}
