//! The random draws of one scattering ([WJZ95] §3.5): Henyey–Greenstein polar cosine, a uniform
//! azimuth, and the rotation of the direction.
//!
//! `HgLanes` holds `HgSampler`'s constants one array per field, and rebuilds the scalar sampler
//! for a lane from them field by field, so the scalar code stays the one owner of the formula.

use super::Photon;
use rand::RngCore;

/// |u_z| above which a direction is treated as along the normal when rotating ([WJZ95] eq 3.20).
const COS_ZERO: f64 = 1.0 - 1.0e-12;

/// Uniform in [0, 1) on the grid k·2⁻⁵²: the top 52 random bits as the mantissa of a number in
/// [1, 2), minus 1 (three integer and float operations, no integer-to-float conversion).
#[inline(always)]
pub(super) fn uniform(rng: &mut impl RngCore) -> f64 {
    uniform_from_bits(rng.next_u64())
}

/// [`uniform`] of a given 64-bit draw (the photon lanes draw for all lanes at once).
#[inline(always)]
pub(super) fn uniform_from_bits(bits: u64) -> f64 {
    f64::from_bits((bits >> 12) | ONE_BITS) - 1.0
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
    ///
    /// Both forms are evaluated and one is selected, so a loop over photon lanes in different
    /// layers vectorises (the isotropic constants keep the unused form finite: t = 1).
    #[inline(always)]
    #[must_use]
    pub fn cos_theta(&self, xi: f64) -> f64 {
        let t = self.one_minus_g2 / (self.one_minus_g + self.two_g * xi);
        let hg = ((self.one_plus_g2 - t * t) * self.inv_two_g).clamp(-1.0, 1.0);
        if self.isotropic { 2.0 * xi - 1.0 } else { hg }
    }
}

/// The [`HgSampler`]s of `W` photon lanes, held field by field so that a loop over the lanes
/// vectorises; [`HgLanes::cos_theta`] is [`HgSampler::cos_theta`] of lane `i`.
#[derive(Debug, Clone, Copy)]
pub(super) struct HgLanes<const W: usize> {
    isotropic: [bool; W],
    one_plus_g2: [f64; W],
    one_minus_g2: [f64; W],
    one_minus_g: [f64; W],
    two_g: [f64; W],
    inv_two_g: [f64; W],
}

impl<const W: usize> HgLanes<W> {
    /// Every lane with the sampler `hg`.
    pub(super) fn splat(hg: &HgSampler) -> Self {
        let mut lanes = Self {
            isotropic: [false; W],
            one_plus_g2: [0.0; W],
            one_minus_g2: [0.0; W],
            one_minus_g: [0.0; W],
            two_g: [0.0; W],
            inv_two_g: [0.0; W],
        };
        for i in 0..W {
            lanes.set(i, hg);
        }
        lanes
    }

    /// Lane `i` takes the sampler `hg`.
    #[inline(always)]
    pub(super) fn set(&mut self, i: usize, hg: &HgSampler) {
        self.isotropic[i] = hg.isotropic;
        self.one_plus_g2[i] = hg.one_plus_g2;
        self.one_minus_g2[i] = hg.one_minus_g2;
        self.one_minus_g[i] = hg.one_minus_g;
        self.two_g[i] = hg.two_g;
        self.inv_two_g[i] = hg.inv_two_g;
    }

    /// [`HgSampler::cos_theta`] of lane `i`.
    #[inline(always)]
    pub(super) fn cos_theta(&self, i: usize, xi: f64) -> f64 {
        HgSampler {
            isotropic: self.isotropic[i],
            one_plus_g2: self.one_plus_g2[i],
            one_minus_g2: self.one_minus_g2[i],
            one_minus_g: self.one_minus_g[i],
            two_g: self.two_g[i],
            inv_two_g: self.inv_two_g[i],
        }
        .cos_theta(xi)
    }
}

/// Uniform azimuth as (cos φ, sin φ) from one 64-bit draw ([`azimuth_from_bits`]).
#[inline(always)]
pub(super) fn sample_azimuth(rng: &mut impl RngCore) -> (f64, f64) {
    azimuth_from_bits(rng.next_u64())
}

/// Uniform azimuth (cos φ, sin φ) from a 64-bit draw, with no branch, no division and no table:
/// φ = d + qπ/2 with q uniform in 0..4 (the top two bits) and d uniform in [−π/4, π/4) (the low
/// 52 bits) is uniform on the circle. cos d and sin d come from their Taylor series, which on
/// |d| ≤ π/4 are below an ulp after the d¹⁶ and d¹⁷ terms (the next terms are ≤ 2e-18); the
/// quarter turns are a swap and two sign flips, so a loop over photon lanes vectorises.
#[inline(always)]
pub(super) fn azimuth_from_bits(bits: u64) -> (f64, f64) {
    use std::f64::consts::FRAC_PI_4;
    let q = bits >> 62;
    // The low 52 bits as the mantissa of a number in [2, 4), minus 3: t uniform in [−1, 1).
    let t = f64::from_bits((bits & ((1u64 << 52) - 1)) | (ONE_BITS + (1u64 << 52))) - 3.0;
    let (c, s) = cos_sin_small(t * FRAC_PI_4);
    // Turned by qπ/2: q = 1 gives (−s, c), q = 2 (−c, −s), q = 3 (s, −c).
    let (a, b) = if q & 1 == 1 { (s, c) } else { (c, s) };
    let flip_cos = ((q ^ (q >> 1)) & 1) << 63;
    let flip_sin = (q >> 1) << 63;
    (
        f64::from_bits(a.to_bits() ^ flip_cos),
        f64::from_bits(b.to_bits() ^ flip_sin),
    )
}

/// cos d and sin d for |d| ≤ π/4 by Taylor series in d² (Horner), accurate to an ulp or two.
#[inline(always)]
fn cos_sin_small(d: f64) -> (f64, f64) {
    // (−1)ʲ/(2j)! and (−1)ʲ/(2j+1)! for j = 1..8.
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

/// New direction after a Henyey–Greenstein scattering ([WJZ95] eqs 3.15–3.20): the draws, then
/// [`turn`].
#[inline(always)]
pub(super) fn scatter(p: &mut Photon, hg: &HgSampler, rng: &mut impl RngCore) {
    let cos_t = hg.cos_theta(uniform(rng));
    let (cos_p, sin_p) = sample_azimuth(rng);
    [p.ux, p.uy, p.uz] = turn([p.ux, p.uy, p.uz], cos_t, cos_p, sin_p);
}

/// The direction `u` turned by polar cosine `cos_t` and azimuth (`cos_p`, `sin_p`) ([WJZ95]
/// eq 3.20; along the normal, eqs 3.19).
///
/// Eq 3.20 needs sin θ / √(1 − u_z²) and sin θ · √(1 − u_z²); both come from one square root,
/// q = √((1 − cos²θ)(1 − u_z²)), as q / (1 − u_z²) and q: one square root and one division
/// fewer than taking sin θ and √(1 − u_z²) apart. Along the normal the same square root, of
/// 1 − cos²θ alone, gives sin θ. Both cases are evaluated and one selected, so a loop over photon
/// lanes vectorises.
#[inline(always)]
pub(super) fn turn(u: [f64; 3], cos_t: f64, cos_p: f64, sin_p: f64) -> [f64; 3] {
    let [ux, uy, uz] = u;
    let along_normal = uz.abs() > COS_ZERO;
    // |cos θ| ≤ 1 (clamped), so its rounded square is ≤ 1 and this is never negative.
    let sin2_t = 1.0 - cos_t * cos_t;
    let one_minus_uz2 = if along_normal { 1.0 } else { 1.0 - uz * uz };
    // q, or sin θ along the normal (where 1 − u_z² is replaced by 1).
    let q = (sin2_t * one_minus_uz2).sqrt();
    if along_normal {
        // Not copysign: the sampled cosine keeps its own sign, relative to the current direction.
        return [q * cos_p, q * sin_p, if uz > 0.0 { cos_t } else { -cos_t }];
    }
    let q_over = q / one_minus_uz2;
    [
        q_over * (ux * uz * cos_p - uy * sin_p) + ux * cos_t,
        q_over * (uy * uz * cos_p + ux * sin_p) + uy * cos_t,
        uz * cos_t - q * cos_p,
    ]
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
        // 25 bins: the quarter-turn seams fall inside bins, where a defect at a seam shows.
        let mut hist = [0u32; 25];
        for _ in 0..n {
            let (c, s) = sample_azimuth(&mut rng);
            assert!((c * c + s * s - 1.0).abs() < 1e-15);
            let phi = s.atan2(c) + std::f64::consts::PI;
            hist[((phi / (2.0 * std::f64::consts::PI) * 25.0) as usize).min(24)] += 1;
        }
        // Each bin expects n/25 = 4800 ± 68 (binomial, √(n p (1 − p))): 5σ ≈ 340.
        for h in hist {
            assert!((f64::from(h) - 4_800.0).abs() < 340.0, "{hist:?}");
        }
    }

    #[test]
    fn short_series_match_libm_cos_and_sin() {
        let h = std::f64::consts::FRAC_PI_4;
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
