//! CIEDE2000 ([SWD05] eqs 1–22) for the maps' per-texel residual, written without the two hue
//! angles: the same number as [`skin_optics::lab::delta_e_2000`] (to rounding, about 1e-13
//! ΔE00) at a fraction of its cost (docs/physics.md §18, "ΔE2000 per texel").
//!
//! The hue angles h'₁, h'₂ enter ΔE00 only through sin(Δh'/2) and the mean hue H̄'. With the
//! unit hue vectors e₁ = (a'₁, b₁)/C'₁ and e₂ = (a'₂, b₂)/C'₂:
//! - cos Δh' = e₁·e₂, sin Δh' = e₁×e₂ (Δh' taken the short way, eq. 10), so
//!   sin(Δh'/2) = sgn(e₁×e₂) √((1 − e₁·e₂)/2) (|Δh'/2| ≤ 90°);
//! - H̄' (eq. 14, also the short way) is the direction of e₁ + e₂, so cos H̄' and sin H̄' are its
//!   components and the four cosines of T (eq. 15) follow from the multiple-angle formulas;
//! - the rotation angle Δθ = 30° exp(−((H̄' − 275°)/25)²) (eq. 17) is below 6e-21° for
//!   H̄' < 100°, where R_T is taken as 0 (its share of ΔE00² is below 1e-21 relative); only
//!   for H̄' ≥ 100° is H̄' itself (one atan2) computed.
//!
//! Colours with a zero chroma or opposite hues (e₁ + e₂ = 0), where the angle conventions of
//! eqs 10 and 14 decide, go to [`skin_optics::lab::delta_e_2000`].

use skin_optics::lab::{Lab, delta_e_2000};

/// 25⁷, the chroma constant of eqs 4 and 18.
const C7_REF: f64 = 6_103_515_625.0;
/// cos 100°: below it (with sin H̄' ≥ 0), H̄' < 100° and the rotation term vanishes.
const COS_100: f64 = -0.173_648_177_666_930_4;

/// CIEDE2000 between CIELAB colours `x` and `y` (as [`delta_e_2000`], module doc).
#[inline]
#[must_use]
pub fn delta_e_2000_fast(x: &[f64; 3], y: &[f64; 3]) -> f64 {
    let ([l1, a1, b1], [l2, a2, b2]) = (*x, *y);
    // Eqs 2–7.
    let c_bar = 0.5 * ((a1 * a1 + b1 * b1).sqrt() + (a2 * a2 + b2 * b2).sqrt());
    let c_bar7 = c_bar.powi(7);
    let g1 = 1.0 + 0.5 * (1.0 - (c_bar7 / (c_bar7 + C7_REF)).sqrt());
    let (a1p, a2p) = (g1 * a1, g1 * a2);
    let c1p = (a1p * a1p + b1 * b1).sqrt();
    let c2p = (a2p * a2p + b2 * b2).sqrt();
    let product = c1p * c2p;
    if product == 0.0 || !product.is_finite() {
        return reference(x, y);
    }
    let (x1, y1) = (a1p / c1p, b1 / c1p);
    let (x2, y2) = (a2p / c2p, b2 / c2p);
    let (sx, sy) = (x1 + x2, y1 + y2);
    let bisector = (sx * sx + sy * sy).sqrt();
    // Hues within 1e-6 rad of opposite: the conventions of eqs 10 and 14 decide.
    if bisector < 2e-6 {
        return reference(x, y);
    }
    // Eqs 8–11.
    let cos_dh = (x1 * x2 + y1 * y2).min(1.0);
    let cross = x1 * y2 - y1 * x2;
    let half = (0.5 * (1.0 - cos_dh)).max(0.0).sqrt();
    let dh_big = 2.0 * product.sqrt() * if cross < 0.0 { -half } else { half };
    // Eqs 12–15, with cos kH̄' and sin kH̄' from the multiple-angle formulas.
    let (c, s) = (sx / bisector, sy / bisector);
    let (c2, s2) = (2.0 * c * c - 1.0, 2.0 * s * c);
    let (c3, s3) = (c * (4.0 * c * c - 3.0), s * (3.0 - 4.0 * s * s));
    let (c4, s4) = (2.0 * c2 * c2 - 1.0, 2.0 * s2 * c2);
    let (cos30, sin30) = (0.866_025_403_784_438_6, 0.5);
    let (cos6, sin6) = (0.994_521_895_368_273_3, 0.104_528_463_267_653_47);
    let (cos63, sin63) = (0.453_990_499_739_546_8, 0.891_006_524_188_367_8);
    let t = 1.0 - 0.17 * (c * cos30 + s * sin30) + 0.24 * c2 + 0.32 * (c3 * cos6 - s3 * sin6)
        - 0.20 * (c4 * cos63 + s4 * sin63);
    let l_bar = 0.5 * (l1 + l2);
    let cp_bar = 0.5 * (c1p + c2p);
    let l50 = (l_bar - 50.0) * (l_bar - 50.0);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * cp_bar;
    let s_h = 1.0 + 0.015 * cp_bar * t;
    let (tl, tc, th) = ((l2 - l1) / s_l, (c2p - c1p) / s_c, dh_big / s_h);
    // Eqs 16–19: the rotation term, zero to rounding for H̄' < 100° (module doc).
    let r_t = if s >= 0.0 && c > COS_100 {
        0.0
    } else {
        let h_deg = sy.atan2(sx).to_degrees().rem_euclid(360.0);
        let d_theta_deg = 30.0 * (-((h_deg - 275.0) / 25.0).powi(2)).exp();
        let cp_bar7 = cp_bar.powi(7);
        -(2.0 * d_theta_deg).to_radians().sin() * 2.0 * (cp_bar7 / (cp_bar7 + C7_REF)).sqrt()
    };
    (tl * tl + tc * tc + th * th + r_t * tc * th)
        .max(0.0)
        .sqrt()
}

#[cold]
fn reference(x: &[f64; 3], y: &[f64; 3]) -> f64 {
    let lab = |v: &[f64; 3]| Lab {
        l: v[0],
        a: v[1],
        b: v[2],
    };
    delta_e_2000(lab(x), lab(y))
}
