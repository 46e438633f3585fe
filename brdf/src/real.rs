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

/// The impl for one float type: every method forwards to the inherent one of the same name.
macro_rules! impl_real {
    ($t:ty) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const TWO: Self = 2.0;
            fn ln_1p(self) -> Self {
                <$t>::ln_1p(self)
            }
            fn min(self, other: Self) -> Self {
                <$t>::min(self, other)
            }
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
            fn clamp(self, lo: Self, hi: Self) -> Self {
                <$t>::clamp(self, lo, hi)
            }
        }
    };
}

impl_real!(f32);
impl_real!(f64);
