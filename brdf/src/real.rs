//! The few float operations the shared microfacet formulas need, for `f32` (per ray) and `f64`
//! (albedo quadrature), so each formula is written once (house rule: one home per formula).

use core::ops::{Add, Div, Mul, Neg, Sub};

/// A float type the microfacet formulas are generic over (`f32` or `f64`).
pub(crate) trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// 2.
    const TWO: Self;
    /// ln(1 + x), accurate for small x.
    fn ln_1p(self) -> Self;
    /// Smaller of two values.
    fn min(self, other: Self) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// Clamp to [lo, hi] (NaN passes through).
    fn clamp(self, lo: Self, hi: Self) -> Self;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const TWO: Self = 2.0;
    fn ln_1p(self) -> Self {
        f32::ln_1p(self)
    }
    fn min(self, other: Self) -> Self {
        f32::min(self, other)
    }
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    fn clamp(self, lo: Self, hi: Self) -> Self {
        f32::clamp(self, lo, hi)
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const TWO: Self = 2.0;
    fn ln_1p(self) -> Self {
        f64::ln_1p(self)
    }
    fn min(self, other: Self) -> Self {
        f64::min(self, other)
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn clamp(self, lo: Self, hi: Self) -> Self {
        f64::clamp(self, lo, hi)
    }
}
