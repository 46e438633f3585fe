//! The exponential free path −ln ξ ([WJZ95] eq 3.8) from one 64-bit draw, with no branch and no
//! table, so a loop over photon lanes vectorises (the scalar path draws it by the ziggurat).
//!
//! The logarithm is fdlibm's `__ieee754_log` (Sun Microsystems 1993, the algorithm of most libms):
//! ln x = k ln 2 + ln(1 + f) with 1 + f in [√2/2, √2), ln(1 + f) = f − s(f − R(s²)) with
//! s = f / (2 + f) and R a degree-7 minimax polynomial in s² (error < 2⁻⁵⁸·⁴⁵); error below one
//! ulp. Only its special cases are dropped: ξ is always a normal number in (0, 1).

/// 1.0's bits.
const ONE_BITS: u64 = 0x3ff0_0000_0000_0000;

/// ln 2 split into a head with trailing zero bits (k · head is exact) and the rest (fdlibm's
/// `ln2_hi`, `ln2_lo`, given by their bits as fdlibm does).
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
/// fdlibm's minimax coefficients Lg1…Lg7 of R(z) = Lg1 z + … + Lg7 z⁷, z = s² (0.6667, 0.4,
/// 0.2857, 0.2222, 0.1818, 0.1531, 0.1480).
const LG: [f64; 7] = [
    f64::from_bits(0x3fe5_5555_5555_5593),
    f64::from_bits(0x3fd9_9999_9997_fa04),
    f64::from_bits(0x3fd2_4924_9422_9359),
    f64::from_bits(0x3fcc_71c5_1d8e_78af),
    f64::from_bits(0x3fc7_4664_96cb_03de),
    f64::from_bits(0x3fc3_9a09_d078_c69f),
    f64::from_bits(0x3fc2_f112_df3e_5244),
];

/// ξ uniform on the midpoints (k + ½)·2⁻⁵², k in 0..2⁵², from the top 52 bits: never 0 or 1, so
/// −ln ξ is finite and positive. It is at most 36.7 optical depths: the exponential's tail
/// beyond, e⁻³⁶·⁷ ≈ 1e-16 of the draws, is cut off.
#[inline(always)]
fn open_unit(bits: u64) -> f64 {
    (f64::from_bits((bits >> 12) | ONE_BITS) - 1.0) + f64::from_bits(ONE_BITS - (53 << 52))
}

/// An exponential optical depth −ln ξ ([WJZ95] eq 3.8) from a 64-bit draw; below one ulp from
/// the correctly rounded value.
#[inline(always)]
pub(super) fn free_path_from_bits(bits: u64) -> f64 {
    -ln_normal(open_unit(bits))
}

/// ln x for a positive normal `x` (fdlibm `__ieee754_log` without its special cases).
#[inline(always)]
fn ln_normal(x: f64) -> f64 {
    let bits = x.to_bits();
    let hx = (bits >> 32) as i64;
    let mut k = (hx >> 20) - 1023;
    let hx = hx & 0x000f_ffff;
    // Scale x by 1/2 when its mantissa is above √2, so that 1 + f lies in [√2/2, √2).
    let i = (hx + 0x9_5f64) & 0x10_0000;
    let m = f64::from_bits((((hx | (i ^ 0x3ff0_0000)) as u64) << 32) | (bits & 0xffff_ffff));
    k += i >> 20;
    let f = m - 1.0;
    // k as f64 by the 2⁵² trick (integer add, float subtract): no i64 → f64 conversion, which
    // AVX2 lacks. |k| ≤ 1075, so k + 2048 is a small positive integer.
    let dk = f64::from_bits((0x4330_0000_0000_0000u64) + (k + 2048) as u64)
        - (4_503_599_627_370_496.0 + 2048.0);
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG[1] + w * (LG[3] + w * LG[5]));
    let t2 = z * (LG[0] + w * (LG[2] + w * (LG[4] + w * LG[6])));
    let r = t2 + t1;
    // fdlibm takes the half-square form at the far ends of the range (mantissa within about 0.02
    // of √2, |f| ≥ 0.29), where it is the more accurate one; both are evaluated, one selected.
    let far = ((hx - 0x6_147a) | (0x6_b851 - hx)) > 0;
    let hfsq = 0.5 * f * f;
    let with_hfsq = dk * LN2_HI - ((hfsq - (s * (hfsq + r) + dk * LN2_LO)) - f);
    let plain = dk * LN2_HI - ((s * (f - r) - dk * LN2_LO) - f);
    if far { with_hfsq } else { plain }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngCore, SeedableRng};
    use rand_xoshiro::Xoshiro256StarStar;

    #[test]
    fn ln_is_within_an_ulp_of_libm() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(9);
        let mut worst = 0.0f64;
        let mut check = |x: f64| {
            let (ours, libm) = (ln_normal(x), x.ln());
            // One ulp of the result, or of the absolute error near x = 1 where ln x → 0.
            let ulp = f64::EPSILON * libm.abs().max(f64::MIN_POSITIVE);
            worst = worst.max((ours - libm).abs() / ulp);
        };
        for _ in 0..200_000 {
            check(open_unit(rng.next_u64()));
        }
        // The ends and the neighbourhood of 1 and of the √2 switch.
        for x in [
            f64::from_bits(ONE_BITS - (53 << 52)),
            1.0 - f64::EPSILON / 2.0,
            0.5,
            std::f64::consts::FRAC_1_SQRT_2,
            0.75,
            0.999_999,
            1.0e-10,
        ] {
            check(x);
        }
        // fdlibm's bound is < 1 ulp; libm's own result may be 0.5 ulp off the other way.
        assert!(worst <= 1.5, "worst {worst} ulp");
    }

    #[test]
    fn free_paths_are_exponential() {
        let mut rng = Xoshiro256StarStar::seed_from_u64(10);
        let n = 200_000;
        let (mut sum, mut above_2) = (0.0, 0u32);
        for _ in 0..n {
            let s = free_path_from_bits(rng.next_u64());
            assert!(s > 0.0 && s.is_finite());
            sum += s;
            above_2 += u32::from(s > 2.0);
        }
        // Mean 1 with sd 1: five standard errors are 5/√n = 0.011.
        assert!((sum / f64::from(n) - 1.0).abs() < 5.0 / f64::from(n).sqrt());
        // P(s > 2) = e⁻² = 0.1353, binomial sd √(p(1 − p)/n) = 7.6e-4; five of them 3.8e-3.
        let p = f64::from(above_2) / f64::from(n);
        assert!((p - (-2.0f64).exp()).abs() < 3.8e-3, "{p}");
    }
}
