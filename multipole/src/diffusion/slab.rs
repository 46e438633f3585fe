//! The multipole: reflectance and transmittance of a slab of thickness d with independent boundary
//! conditions on its lit (top) and far (bottom) faces ([DJ05] §3; docs/physics.md §4), in space and in the
//! frequency domain (docs/physics.md §5), with the pole count as a knob.
//!
//! Poles: z_r,i = iL + z0 and z_v,i = iL − z0 − 2 z_b0 for i = −n…n, with period L = 2(d + z_b0 + z_bd).
//! In the frequency domain every pole is sgn(z) e^(−|z| s), s = √(σtr² + q²); the sums over i are
//! geometric series in e^(−Ls), so [`Poles::Exact`] costs about as much as one pole.
//!
//! # Thin slabs
//! The multipole puts its real source at z0 = ℓ = 1/σt'. When d < ℓ that source lies outside the slab
//! and R or T turn negative (docs/physics.md §4). This crate's documented behaviour:
//! * a fraction w = min(1, σs' d) (the reduced scattering optical depth, ≈ the probability to scatter
//!   at all) is diffused; the rest is transmitted as a delta at r = 0 attenuated by e^(−σa d), with no
//!   reflection;
//! * the diffused part keeps its real source strictly inside the slab: z0 = ℓ w² (≤ w d α' < d). The
//!   square makes z0 continuous with the plain multipole's ℓ at w = 1 while it shrinks with d.
//!   (A source *on* the far face, z0 = min(ℓ, d), was tried first: it transmits half its light as a
//!   delta but makes the diffuse T(r) negative when lit from the matched side.)
//!
//! Slabs with σs' d ≥ 1 (which implies d ≥ ℓ) are untouched, so the published check values hold and the
//! skin's epidermis (σs' d ≥ 1.1 over 400–700 nm) is modelled by the plain multipole. With the source
//! inside, R(r) and T(r) are non-negative (tested from 0.05 to 1 mean free paths), and
//! for σa = 0 the blend conserves energy exactly (R̂(0) + T̂(0) = 1); a zero-thickness slab is the
//! identity (R = 0, T = δ).
//!
//! A limit shared by every multipole, thin or not: when the top extrapolation distance exceeds
//! d + z_bd, the slab's own R(r) has a small negative lobe far from the source (the lowest diffusion
//! mode peaks above the lit face). The bare epidermis at 700 nm is such a slab. Stacked over a dermis
//! the sum stays positive; `Profile` never carries a negative value (clamped to 0 and counted).
//! Public code blends toward a transmitted delta below two mean free paths;
//! this crate blends only where the multipole itself is not valid.

use crate::diffusion::boundary::a_coefficient;
use crate::diffusion::medium::{Medium, pole_kernel, pole_transform};
use crate::error::{MultipoleError, check_range};
use std::f64::consts::PI;

/// Number of dipole pairs in a multipole sum: the accuracy knob of [DJ05].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Poles {
    /// Infinitely many: the closed-form geometric series in the frequency domain; in space the sum runs
    /// until a pair adds less than 1e-12 of the running sum.
    #[default]
    Exact,
    /// Pairs i = −n…n (2n + 1 pairs; public code uses n = 5).
    Count(usize),
}

/// Relative size below which the spatial `Exact` sum stops.
const SPATIAL_EXACT_TOLERANCE: f64 = 1e-12;
/// Safety cap on spatial pole pairs (reached only for σtr L ≈ 0, i.e. σa ≈ 0).
const MAX_SPATIAL_POLES: usize = 100_000;

/// A slab of thickness d over which the medium is homogeneous, lit from its top face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slab {
    medium: Medium,
    thickness_mm: f64,
    a_top: f64,
    a_bottom: f64,
    z_b0: f64,
    z_bd: f64,
    period: f64,
    z0: f64,
    weight: f64,
}

impl Slab {
    /// Slab of `medium`, thickness `thickness_mm` in [0, 1e4] mm, with relative indices
    /// `eta_top` (lit face) and `eta_bottom` (far face), each in [0.2, 5] (n_slab / n_outside).
    pub fn new(
        medium: Medium,
        thickness_mm: f64,
        eta_top: f64,
        eta_bottom: f64,
    ) -> Result<Self, MultipoleError> {
        check_range("η_top (relative index)", eta_top, 0.2, 5.0, "[0.2, 5]")?;
        check_range(
            "η_bottom (relative index)",
            eta_bottom,
            0.2,
            5.0,
            "[0.2, 5]",
        )?;
        Self::with_a(
            medium,
            thickness_mm,
            a_coefficient(eta_top),
            a_coefficient(eta_bottom),
        )
    }

    /// Slab with explicit boundary coefficients A_top, A_bottom (≥ 1 for physical faces).
    pub fn with_a(
        medium: Medium,
        thickness_mm: f64,
        a_top: f64,
        a_bottom: f64,
    ) -> Result<Self, MultipoleError> {
        check_range(
            "slab thickness d (mm)",
            thickness_mm,
            0.0,
            1.0e4,
            "[0, 1e4]",
        )?;
        check_range(
            "A_top (boundary coefficient)",
            a_top,
            0.5,
            1.0e3,
            "[0.5, 1e3]",
        )?;
        check_range(
            "A_bottom (boundary coefficient)",
            a_bottom,
            0.5,
            1.0e3,
            "[0.5, 1e3]",
        )?;
        let z_b0 = medium.extrapolation_mm(a_top);
        let z_bd = medium.extrapolation_mm(a_bottom);
        let d = thickness_mm;
        let weight = (medium.sigma_s_prime() * d).min(1.0);
        Ok(Self {
            medium,
            thickness_mm: d,
            a_top,
            a_bottom,
            z_b0,
            z_bd,
            period: 2.0 * (d + z_b0 + z_bd),
            z0: medium.mean_free_path_mm() * weight * weight,
            weight,
        })
    }

    /// The same slab lit from below (top and bottom faces swapped): the ↑ direction of `stack`.
    #[must_use]
    pub fn flipped(&self) -> Self {
        // The inputs were validated when `self` was built, so this cannot fail.
        Self {
            a_top: self.a_bottom,
            a_bottom: self.a_top,
            z_b0: self.z_bd,
            z_bd: self.z_b0,
            ..*self
        }
    }

    /// The medium's coefficients.
    #[must_use]
    pub fn medium(&self) -> &Medium {
        &self.medium
    }

    /// Thickness d, mm.
    #[must_use]
    pub fn thickness_mm(&self) -> f64 {
        self.thickness_mm
    }

    /// Boundary coefficients (A_top, A_bottom), dimensionless.
    #[must_use]
    pub fn a_boundaries(&self) -> (f64, f64) {
        (self.a_top, self.a_bottom)
    }

    /// Depth of the real source z0 = ℓ w², mm (= ℓ unless the slab is thin; see the module doc).
    #[must_use]
    pub fn source_depth_mm(&self) -> f64 {
        self.z0
    }

    /// Fraction w = min(1, σs' d) of the light that is diffused; the rest passes as an attenuated delta.
    #[must_use]
    pub fn scattered_weight(&self) -> f64 {
        self.weight
    }

    /// Whether the thin-slab treatment is active (σs' d < 1).
    #[must_use]
    pub fn is_thin(&self) -> bool {
        self.weight < 1.0
    }

    fn prefactor(&self) -> f64 {
        self.weight * self.medium.albedo_prime()
    }

    /// Weight of the delta at r = 0 in the transmittance, dimensionless: the unscattered pass-through
    /// (1 − w) e^(−σa d), plus w α'/2 in the edge case of a source on the far face (σa = 0, σs' d = 1).
    #[must_use]
    pub fn transmitted_delta(&self) -> f64 {
        let on_face = if self.z0 >= self.thickness_mm {
            0.5 * self.prefactor()
        } else {
            0.0
        };
        on_face + (1.0 - self.weight) * (-self.medium.sigma_a() * self.thickness_mm).exp()
    }

    /// Depths of pole pair i: (z_r,i, z_v,i), mm.
    #[inline]
    fn poles(&self, i: i64) -> (f64, f64) {
        let shift = i as f64 * self.period;
        (shift + self.z0, shift - self.z0 - 2.0 * self.z_b0)
    }

    /// Sum a spatial pole series: `term(i)` for i = 0, ±1, ±2, … up to `poles`.
    fn spatial_sum(&self, poles: Poles, term: impl Fn(i64) -> f64) -> f64 {
        let mut sum = term(0);
        let mut scale = sum.abs();
        let limit = match poles {
            Poles::Count(n) => n,
            Poles::Exact => MAX_SPATIAL_POLES,
        };
        for i in 1..=limit as i64 {
            let pair = term(i) + term(-i);
            sum += pair;
            scale = scale.max(sum.abs());
            if poles == Poles::Exact && pair.abs() <= SPATIAL_EXACT_TOLERANCE * scale {
                break;
            }
        }
        sum
    }

    /// Diffuse reflectance R(r) at `r_mm`, mm⁻² ([DJ05] eq. 8; docs/physics.md §4).
    #[must_use]
    pub fn reflectance_mm2(&self, r_mm: f64, poles: Poles) -> f64 {
        let s = self.medium.sigma_tr();
        let sum = self.spatial_sum(poles, |i| {
            let (zr, zv) = self.poles(i);
            pole_kernel(zr, r_mm, s) - pole_kernel(zv, r_mm, s)
        });
        self.prefactor() / (4.0 * PI) * sum
    }

    /// Diffuse transmittance T(r) at `r_mm` on the far face, mm⁻² ([DJ05] eq. 9; docs/physics.md §4),
    /// without the delta at r = 0 ([`Slab::transmitted_delta`]).
    #[must_use]
    pub fn transmittance_mm2(&self, r_mm: f64, poles: Poles) -> f64 {
        let s = self.medium.sigma_tr();
        let d = self.thickness_mm;
        let sum = self.spatial_sum(poles, |i| {
            let (zr, zv) = self.poles(i);
            pole_kernel(d - zr, r_mm, s) - pole_kernel(d - zv, r_mm, s)
        });
        self.prefactor() / (4.0 * PI) * sum
    }

    /// The i = 0 pair of R(r) (real source and its image in the top face), mm⁻²: the part of R that
    /// decays slowest in frequency, evaluated in closed form by `hankel`.
    #[must_use]
    pub fn head_reflectance_mm2(&self, r_mm: f64) -> f64 {
        let s = self.medium.sigma_tr();
        let (zr, zv) = self.poles(0);
        self.prefactor() / (4.0 * PI) * (pole_kernel(zr, r_mm, s) - pole_kernel(zv, r_mm, s))
    }

    /// Transform of [`Slab::head_reflectance_mm2`] at frequency `q` (rad/mm), dimensionless.
    #[must_use]
    pub fn head_transform(&self, q: f64) -> f64 {
        let st = self.medium.sigma_tr();
        let s = (st * st + q * q).sqrt();
        let (zr, zv) = self.poles(0);
        0.5 * self.prefactor() * (pole_transform(zr, s) - pole_transform(zv, s))
    }

    /// Order-0 Hankel transforms (R̂(q), T̂(q)) at spatial frequency `q` (rad/mm), dimensionless
    /// (docs/physics.md §5); T̂ includes the transmitted delta. At q = 0 these are the totals.
    #[must_use]
    pub fn transform(&self, q: f64, poles: Poles) -> (f64, f64) {
        let st = self.medium.sigma_tr();
        let s = (st * st + q * q).sqrt();
        let d = self.thickness_mm;
        let half = 0.5 * self.prefactor();
        let pass = (1.0 - self.weight) * (-self.medium.sigma_a() * d).exp();
        match poles {
            Poles::Count(n) => {
                let (mut r, mut t) = (0.0, 0.0);
                for i in -(n as i64)..=n as i64 {
                    let (zr, zv) = self.poles(i);
                    r += pole_transform(zr, s) - pole_transform(zv, s);
                    t += pole_transform(d - zr, s) - pole_transform(d - zv, s);
                }
                (half * r, half * t + pass)
            }
            Poles::Exact => {
                let (z0, l) = (self.z0, self.period);
                let x1 = z0;
                let x2 = z0 + 2.0 * self.z_b0;
                let y1 = d - z0;
                let y2 = d + z0 + 2.0 * self.z_b0;
                let r = (-x1 * s).exp() + (-x2 * s).exp()
                    - image_series(x1, l, s)
                    - image_series(x2, l, s);
                let t = pole_transform(y1, s) - (-y2 * s).exp() - image_series(y1, l, s)
                    + image_series(y2, l, s);
                (half * r, half * t + pass)
            }
        }
    }

    /// Both directions at once, (R̂↓, T̂↓, R̂↑, T̂↑) at `q` (rad/mm), plus the head transform
    /// ([`Slab::head_transform`]): the hot path of `stack`. With `Poles::Exact` every term is a product
    /// of five exponentials e^(−x s), x ∈ {z0, 2z_b0, 2z_bd, d, d − z0}, shared by both directions.
    #[must_use]
    pub fn transform_both(&self, q: f64, poles: Poles) -> ([f64; 4], f64) {
        let st = self.medium.sigma_tr();
        let s = (st * st + q * q).sqrt();
        if poles != Poles::Exact || self.period * s < 1.0 {
            // Few poles, or small L s where 1 − e^(−Ls) would cancel: the general path.
            let (rd, td) = self.transform(q, poles);
            let (ru, tu) = self.flipped().transform(q, poles);
            return ([rd, td, ru, tu], self.head_transform(q));
        }
        let d = self.thickness_mm;
        let a = (-self.z0 * s).exp();
        let b = (-2.0 * self.z_b0 * s).exp();
        let c = (-2.0 * self.z_bd * s).exp();
        let e = (-d * s).exp();
        let g = (-(d - self.z0) * s).exp();
        let el = e * e * b * c;
        let inv = 1.0 / (1.0 - el);
        let half = 0.5 * self.prefactor();
        let pass = (1.0 - self.weight) * (-self.medium.sigma_a() * d).exp();
        // One direction with extrapolation factors (b, c) = (top, bottom); see `transform` for the terms.
        let dir = |b: f64, c: f64| -> (f64, f64) {
            let series_x1 = (g * e * b * c - el * a) * inv;
            let series_x2 = (g * e * c - el * a * b) * inv;
            let r = a + a * b - series_x1 - series_x2;
            let series_y1 = (e * a * b * c - el * g) * inv;
            let series_y2 = (g * c - el * e * a * b) * inv;
            let t = g - e * a * b - series_y1 + series_y2;
            (half * r, half * t + pass)
        };
        let (rd, td) = dir(b, c);
        let (ru, tu) = dir(c, b);
        ([rd, td, ru, tu], half * (a + a * b))
    }

    /// Total reflectance R̂(0), dimensionless.
    #[must_use]
    pub fn total_reflectance(&self, poles: Poles) -> f64 {
        self.transform(0.0, poles).0
    }

    /// Total transmittance T̂(0) including the delta, dimensionless.
    #[must_use]
    pub fn total_transmittance(&self, poles: Poles) -> f64 {
        self.transform(0.0, poles).1
    }
}

/// Σ_{k≥1} [e^(−(kL − x)s) − e^(−(kL + x)s)] = 2 sinh(xs)/(e^(Ls) − 1) for |x| < L: the images of a
/// pole at depth x in both faces, summed to infinity. Written in two forms so that neither overflows
/// (large Ls) nor cancels (small Ls); at s = 0 it is the limit 2x/L.
#[inline]
fn image_series(x: f64, l: f64, s: f64) -> f64 {
    let ls = l * s;
    if ls < 1.0 {
        if s == 0.0 {
            2.0 * x / l
        } else {
            2.0 * (x * s).sinh() / ls.exp_m1()
        }
    } else {
        ((-(l - x) * s).exp() - (-(l + x) * s).exp()) / -(-ls).exp_m1()
    }
}

#[cfg(test)]
mod tests;
