//! CIELAB (D65, 2° observer), the CIEDE2000 colour difference and the Individual Typology Angle:
//! the colour vocabulary of dermatology ([CIE] 015; [SWD05]; [CGD91]).
//!
//! XYZ always comes from [`crate::color`]; this module only maps XYZ to L*a*b* and compares colours.
//! The reference white is the perfect reflecting diffuser under D65 as [`crate::color`] integrates it
//! (so a perfect white spectrum is exactly L* = 100, a* = b* = 0); it agrees with CIE 015's tabulated
//! D65 white (0.95047, 1, 1.08883) to about 1e-4.

use crate::color::{Srgb, Xyz, reflectance_to_xyz};
use crate::spectrum::{GridSpectrum, WavelengthGrid};
use std::fmt;
use std::sync::OnceLock;

/// A CIELAB colour: lightness L* in [0, 100] and the opponent coordinates a* (green–red) and
/// b* (blue–yellow), dimensionless ([CIE] 015 §8.2.1, D65 white, 2° observer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lab {
    /// Lightness L*, 0 (black) to 100 (white).
    pub l: f64,
    /// a*: negative green, positive red.
    pub a: f64,
    /// b*: negative blue, positive yellow.
    pub b: f64,
}

/// XYZ of the perfect reflecting diffuser under D65 (Y = 1), integrated by [`reflectance_to_xyz`].
#[must_use]
pub fn d65_white() -> Xyz {
    static W: OnceLock<Xyz> = OnceLock::new();
    *W.get_or_init(|| {
        let grid = WavelengthGrid::visible();
        // A constant spectrum held beyond its ends is a perfect white over the whole CIE range;
        // the value count equals the grid length by construction.
        let white =
            GridSpectrum::new(grid, vec![1.0; grid.len()]).expect("one value per grid point");
        reflectance_to_xyz(&white)
    })
}

/// CIE 1976 f(t): cube root above (6/29)³, linear below ([CIE] 015 eq. 8.4).
fn lab_f(t: f64) -> f64 {
    const DELTA: f64 = 6.0 / 29.0;
    if t > DELTA * DELTA * DELTA {
        t.cbrt()
    } else {
        t / (3.0 * DELTA * DELTA) + 4.0 / 29.0
    }
}

/// Inverse of [`lab_f`].
fn lab_f_inv(f: f64) -> f64 {
    const DELTA: f64 = 6.0 / 29.0;
    if f > DELTA {
        f * f * f
    } else {
        3.0 * DELTA * DELTA * (f - 4.0 / 29.0)
    }
}

impl Lab {
    /// CIE XYZ (Y = 1 for white) → CIELAB relative to [`d65_white`] ([CIE] 015 eqs 8.1–8.3).
    #[must_use]
    pub fn from_xyz(xyz: Xyz) -> Lab {
        let w = d65_white().0;
        let [fx, fy, fz] = [0, 1, 2].map(|i| lab_f(xyz.0[i] / w[i]));
        Lab {
            l: 116.0 * fy - 16.0,
            a: 500.0 * (fx - fy),
            b: 200.0 * (fy - fz),
        }
    }

    /// CIELAB → CIE XYZ (inverse of [`Lab::from_xyz`]).
    #[must_use]
    pub fn to_xyz(self) -> Xyz {
        let w = d65_white().0;
        let fy = (self.l + 16.0) / 116.0;
        let f = [fy + self.a / 500.0, fy, fy - self.b / 200.0];
        Xyz([0, 1, 2].map(|i| w[i] * lab_f_inv(f[i])))
    }

    /// An sRGB colour (IEC 61966-2-1, D65) → CIELAB, through [`Srgb::to_linear`] and the
    /// IEC matrix of [`crate::color`].
    #[must_use]
    pub fn from_srgb(srgb: Srgb) -> Lab {
        Lab::from_xyz(srgb.to_linear().to_xyz())
    }

    /// The sRGB colour of this CIELAB colour, clamped to the sRGB gamut.
    #[must_use]
    pub fn to_srgb(self) -> Srgb {
        self.to_xyz().to_linear_srgb().to_srgb()
    }

    /// Chroma C*ab = √(a*² + b*²).
    #[must_use]
    pub fn chroma(self) -> f64 {
        self.a.hypot(self.b)
    }

    /// Individual Typology Angle ITA° = arctan((L* − 50) / b*), degrees in [−90°, 90°] ([CGD91]),
    /// with b* floored at [`ITA_MIN_B`]: the angle is undefined for achromatic colours (b* ≈ 0,
    /// where its sign would follow rounding noise), so greys get a value continuous in L* instead
    /// of jumping between ±90°. No colour with b* ≥ [`ITA_MIN_B`] is affected.
    #[must_use]
    pub fn ita_deg(self) -> f64 {
        ((self.l - 50.0) / self.b.max(ITA_MIN_B))
            .atan()
            .to_degrees()
    }

    /// The skin-colour category of [`Lab::ita_deg`].
    #[must_use]
    pub fn ita_category(self) -> ItaCategory {
        ItaCategory::from_ita_deg(self.ita_deg())
    }

    /// CIEDE2000 colour difference ΔE00 to `other` (see [`delta_e_2000`]).
    #[must_use]
    pub fn delta_e_2000(self, other: Lab) -> f64 {
        delta_e_2000(self, other)
    }
}

/// Why a text is not a CIELAB colour `L,a,b`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LabParseError {
    /// Not three comma-separated fields.
    #[error(
        "'{text}' has {found} comma-separated fields; a CIELAB colour is L,a,b (e.g. 55.2,12.1,17.5)"
    )]
    Fields {
        /// The text given.
        text: String,
        /// Fields found.
        found: usize,
    },
    /// A field that is not a number.
    #[error("{coordinate} '{text}' is not a number")]
    Number {
        /// `L*`, `a*` or `b*`.
        coordinate: &'static str,
        /// The field.
        text: String,
    },
    /// A coordinate outside its range.
    #[error(transparent)]
    Range(#[from] crate::OpticsError),
}

impl std::str::FromStr for Lab {
    type Err = LabParseError;

    /// `L,a,b` (spaces allowed): L* in [0, 100], a* and b* in [−200, 200] (beyond every
    /// surface colour under D65).
    fn from_str(s: &str) -> Result<Lab, LabParseError> {
        let fields: Vec<&str> = s.split(',').map(str::trim).collect();
        if fields.len() != 3 {
            return Err(LabParseError::Fields {
                text: s.to_string(),
                found: fields.len(),
            });
        }
        let mut v = [0.0; 3];
        for (i, (name, range, lo, hi)) in [
            ("L*", "[0, 100]", 0.0, 100.0),
            ("a*", "[-200, 200]", -200.0, 200.0),
            ("b*", "[-200, 200]", -200.0, 200.0),
        ]
        .into_iter()
        .enumerate()
        {
            let x = fields[i]
                .parse::<f64>()
                .map_err(|_| LabParseError::Number {
                    coordinate: name,
                    text: fields[i].to_string(),
                })?;
            v[i] = crate::error::check_range(name, x, lo, hi, range)?;
        }
        Ok(Lab {
            l: v[0],
            a: v[1],
            b: v[2],
        })
    }
}

impl From<Xyz> for Lab {
    fn from(xyz: Xyz) -> Lab {
        Lab::from_xyz(xyz)
    }
}

impl fmt::Display for Lab {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "L*={:.2} a*={:.2} b*={:.2}", self.l, self.a, self.b)
    }
}

/// Hue angle in degrees [0, 360) of (a, b); 0 for the achromatic point ([SWD05] eq. 4).
fn hue_deg(a: f64, b: f64) -> f64 {
    if a == 0.0 && b == 0.0 {
        return 0.0;
    }
    let h = b.atan2(a).to_degrees();
    if h < 0.0 { h + 360.0 } else { h }
}

/// 25⁷, the chroma constant of the CIEDE2000 a* rescaling and rotation terms ([SWD05] eqs 2, 19).
const C7_REF: f64 = 6_103_515_625.0;

/// CIEDE2000 colour difference ΔE00 between two CIELAB colours, with k_L = k_C = k_H = 1
/// (Sharma, Wu & Dalal 2005 [SWD05] eqs 1–22, including their hue-mean and hue-difference rules
/// for hues on opposite sides of 0°/360° and for achromatic colours). Symmetric; 0 for equal colours.
#[must_use]
pub fn delta_e_2000(c1: Lab, c2: Lab) -> f64 {
    let [tl, tc, th, r_t] = weighted_differences(c1, c2);
    // The rotation term can make the radicand a rounding error below zero for tiny differences.
    (tl * tl + tc * tc + th * th + r_t * tc * th)
        .max(0.0)
        .sqrt()
}

/// ΔE00 as three terms whose Euclidean norm is [`delta_e_2000`] (to rounding): ΔL'/S_L,
/// ΔC'/S_C + (R_T/2) ΔH'/S_H and √(1 − R_T²/4) ΔH'/S_H ([SWD05] eq. 22 with its cross term
/// completed to a square; |R_T| ≤ 2). A least-squares fit to a colour minimises their squares.
#[must_use]
pub fn delta_e_2000_terms(c1: Lab, c2: Lab) -> [f64; 3] {
    let [tl, tc, th, r_t] = weighted_differences(c1, c2);
    [
        tl,
        tc + 0.5 * r_t * th,
        (1.0 - 0.25 * r_t * r_t).max(0.0).sqrt() * th,
    ]
}

/// [SWD05] eqs 2–22 up to the final sum: ΔL'/S_L, ΔC'/S_C, ΔH'/S_H and the rotation R_T.
fn weighted_differences(c1: Lab, c2: Lab) -> [f64; 4] {
    // Eqs 2–6: rescale a* so near-neutral colours get a hue scale closer to perception.
    let c_bar = 0.5 * (c1.chroma() + c2.chroma());
    let c_bar7 = c_bar.powi(7);
    let g = 0.5 * (1.0 - (c_bar7 / (c_bar7 + C7_REF)).sqrt());
    let a1p = (1.0 + g) * c1.a;
    let a2p = (1.0 + g) * c2.a;
    let c1p = a1p.hypot(c1.b);
    let c2p = a2p.hypot(c2.b);
    let h1p = hue_deg(a1p, c1.b);
    let h2p = hue_deg(a2p, c2.b);

    // Eqs 8–11: differences; the hue difference takes the short way round the circle.
    let dl = c2.l - c1.l;
    let dc = c2p - c1p;
    let chroma_product = c1p * c2p;
    let dh_deg = if chroma_product == 0.0 {
        0.0
    } else {
        let d = h2p - h1p;
        if d > 180.0 {
            d - 360.0
        } else if d < -180.0 {
            d + 360.0
        } else {
            d
        }
    };
    let dh_big = 2.0 * chroma_product.sqrt() * (0.5 * dh_deg).to_radians().sin();

    // Eqs 12–14: means; the hue mean also goes the short way round.
    let l_bar = 0.5 * (c1.l + c2.l);
    let cp_bar = 0.5 * (c1p + c2p);
    let hp_bar = if chroma_product == 0.0 {
        h1p + h2p
    } else if (h1p - h2p).abs() <= 180.0 {
        0.5 * (h1p + h2p)
    } else if h1p + h2p < 360.0 {
        0.5 * (h1p + h2p + 360.0)
    } else {
        0.5 * (h1p + h2p - 360.0)
    };

    // Eqs 15–22: weighting functions and the blue-region rotation term.
    let cos_deg = |x: f64| x.to_radians().cos();
    let t = 1.0 - 0.17 * cos_deg(hp_bar - 30.0)
        + 0.24 * cos_deg(2.0 * hp_bar)
        + 0.32 * cos_deg(3.0 * hp_bar + 6.0)
        - 0.20 * cos_deg(4.0 * hp_bar - 63.0);
    let d_theta_deg = 30.0 * (-((hp_bar - 275.0) / 25.0).powi(2)).exp();
    let cp_bar7 = cp_bar.powi(7);
    let r_c = 2.0 * (cp_bar7 / (cp_bar7 + C7_REF)).sqrt();
    let l50 = (l_bar - 50.0).powi(2);
    let s_l = 1.0 + 0.015 * l50 / (20.0 + l50).sqrt();
    let s_c = 1.0 + 0.045 * cp_bar;
    let s_h = 1.0 + 0.015 * cp_bar * t;
    let r_t = -(2.0 * d_theta_deg).to_radians().sin() * r_c;

    [dl / s_l, dc / s_c, dh_big / s_h, r_t]
}

/// Smallest b* the ITA° formula divides by (see [`Lab::ita_deg`]); skin is yellowish, b* well
/// above it.
pub const ITA_MIN_B: f64 = 1.0;

/// Skin-colour category of the Individual Typology Angle ([CGD91]; the six classes of
/// [DB06]). Each class includes its upper bound: light is 41° < ITA° ≤ 55°,
/// very light is ITA° > 55°, dark is ITA° ≤ −30°.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ItaCategory {
    /// ITA° > 55°.
    VeryLight,
    /// 41° < ITA° ≤ 55°.
    Light,
    /// 28° < ITA° ≤ 41°.
    Intermediate,
    /// 10° < ITA° ≤ 28°.
    Tan,
    /// −30° < ITA° ≤ 10°.
    Brown,
    /// ITA° ≤ −30°.
    Dark,
}

impl ItaCategory {
    /// All categories, lightest first.
    pub const ALL: [ItaCategory; 6] = [
        ItaCategory::VeryLight,
        ItaCategory::Light,
        ItaCategory::Intermediate,
        ItaCategory::Tan,
        ItaCategory::Brown,
        ItaCategory::Dark,
    ];

    /// The category of an ITA° value in degrees (NaN falls into `Dark`; callers pass finite angles).
    #[must_use]
    pub fn from_ita_deg(ita_deg: f64) -> ItaCategory {
        if ita_deg > 55.0 {
            ItaCategory::VeryLight
        } else if ita_deg > 41.0 {
            ItaCategory::Light
        } else if ita_deg > 28.0 {
            ItaCategory::Intermediate
        } else if ita_deg > 10.0 {
            ItaCategory::Tan
        } else if ita_deg > -30.0 {
            ItaCategory::Brown
        } else {
            ItaCategory::Dark
        }
    }

    /// Lower-case name, e.g. `very light`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            ItaCategory::VeryLight => "very light",
            ItaCategory::Light => "light",
            ItaCategory::Intermediate => "intermediate",
            ItaCategory::Tan => "tan",
            ItaCategory::Brown => "brown",
            ItaCategory::Dark => "dark",
        }
    }
}

impl fmt::Display for ItaCategory {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lab(l: f64, a: f64, b: f64) -> Lab {
        Lab { l, a, b }
    }

    /// [SWD05] Table 1 test data: pairs chosen to exercise the hue-mean, hue-difference,
    /// achromatic and rotation-term branches. Published to 4 decimals.
    const SHARMA_PAIRS: [([f64; 3], [f64; 3], f64); 14] = [
        ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
        ([50.0, 3.1571, -77.2803], [50.0, 0.0, -82.7485], 2.8615),
        ([50.0, -1.3802, -84.2814], [50.0, 0.0, -82.7485], 1.0000),
        ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
        ([50.0, 2.4900, -0.0010], [50.0, -2.4900, 0.0009], 7.1792),
        ([50.0, 2.4900, -0.0010], [50.0, -2.4900, 0.0011], 7.2195),
        ([50.0, -0.0010, 2.4900], [50.0, 0.0009, -2.4900], 4.8045),
        ([50.0, -0.0010, 2.4900], [50.0, 0.0011, -2.4900], 4.7461),
        ([50.0, 2.5, 0.0], [50.0, 0.0, -2.5], 4.3065),
        ([50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492),
        ([50.0, 2.5, 0.0], [56.0, -27.0, -3.0], 31.9030),
        (
            [60.2574, -34.0099, 36.2677],
            [60.4626, -34.1751, 39.4387],
            1.2644,
        ),
        (
            [22.7233, 20.0904, -46.6940],
            [23.0331, 14.9730, -42.5619],
            2.0373,
        ),
        (
            [2.0776, 0.0795, -1.1350],
            [0.9033, -0.0636, -0.5514],
            0.9082,
        ),
    ];

    #[test]
    fn delta_e_2000_matches_sharma_wu_dalal_pairs() {
        for (p, q, want) in SHARMA_PAIRS {
            let (x, y) = (lab(p[0], p[1], p[2]), lab(q[0], q[1], q[2]));
            let got = delta_e_2000(x, y);
            // The published values are rounded to 4 decimals: half a unit in the last place.
            assert!(
                (got - want).abs() <= 5e-5,
                "ΔE00({p:?}, {q:?}) = {got}, want {want}"
            );
            assert!((delta_e_2000(y, x) - got).abs() < 1e-12, "symmetry");
        }
    }

    /// The three terms square-sum to ΔE00 on every published pair (the blue ones carry a large
    /// rotation term R_T, so the completed square is exercised); 1e-9 is rounding.
    #[test]
    fn delta_e_2000_terms_square_sum_to_the_difference() {
        for (p, q, _) in SHARMA_PAIRS {
            let (x, y) = (lab(p[0], p[1], p[2]), lab(q[0], q[1], q[2]));
            let t = delta_e_2000_terms(x, y);
            let norm = t.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!((norm - delta_e_2000(x, y)).abs() < 1e-9, "{p:?} {q:?}");
        }
    }

    #[test]
    fn lab_text_parses_and_bad_text_is_a_typed_error() {
        let c: Lab = " 55.2, 12.1 ,17.5".parse().unwrap();
        assert_eq!((c.l, c.a, c.b), (55.2, 12.1, 17.5));
        let e = "55,12".parse::<Lab>().unwrap_err();
        assert_eq!(
            e,
            LabParseError::Fields {
                text: "55,12".into(),
                found: 2
            }
        );
        let e = "55,x,1".parse::<Lab>().unwrap_err();
        assert!(
            matches!(
                e,
                LabParseError::Number {
                    coordinate: "a*",
                    ..
                }
            ),
            "{e}"
        );
        let e = "101,0,0".parse::<Lab>().unwrap_err();
        assert_eq!(e.to_string(), "L* = 101 outside [0, 100]");
        let e = "50,0,NaN".parse::<Lab>().unwrap_err();
        assert!(
            matches!(
                e,
                LabParseError::Range(crate::OpticsError::NonFinite { name: "b*", .. })
            ),
            "{e}"
        );
    }

    #[test]
    fn delta_e_2000_is_zero_for_equal_colours() {
        let c = lab(61.3, 12.4, 17.8);
        assert_eq!(delta_e_2000(c, c), 0.0);
    }

    #[test]
    fn white_point_is_cie_d65_and_maps_to_l100() {
        let w = d65_white().0;
        for (got, want) in w.iter().zip([0.95047, 1.0, 1.08883]) {
            assert!((got - want).abs() < 5e-4, "white {w:?}");
        }
        let white = Lab::from_xyz(d65_white());
        assert!((white.l - 100.0).abs() < 1e-12 && white.a.abs() < 1e-12 && white.b.abs() < 1e-12);
        let black = Lab::from_xyz(Xyz([0.0; 3]));
        assert!(black.l.abs() < 1e-12);
    }

    #[test]
    fn srgb_primaries_have_their_known_lab() {
        // Red #ff0000 is L* 53.24, a* 80.09, b* 67.20 (D65; widely tabulated); the small slack
        // covers the 4-digit IEC matrix and our integrated white point.
        let red = Lab::from_srgb(Srgb([1.0, 0.0, 0.0]));
        assert!((red.l - 53.24).abs() < 0.05, "{red}");
        assert!((red.a - 80.09).abs() < 0.2, "{red}");
        assert!((red.b - 67.20).abs() < 0.2, "{red}");
        // Mid grey #777777 is neutral: a* and b* vanish up to the white-point mismatch.
        let grey = Lab::from_srgb(Srgb([0.4667; 3]));
        assert!(grey.a.abs() < 0.05 && grey.b.abs() < 0.05, "{grey}");
    }

    #[test]
    fn xyz_round_trips_through_lab() {
        for xyz in [[0.2, 0.3, 0.1], [0.001, 0.002, 0.0005], [0.9, 1.0, 1.05]] {
            let back = Lab::from_xyz(Xyz(xyz)).to_xyz().0;
            for (b, x) in back.iter().zip(xyz) {
                assert!((b - x).abs() < 1e-12, "{back:?} vs {xyz:?}");
            }
        }
    }

    #[test]
    fn ita_is_the_angle_of_l_minus_50_over_b() {
        // tan(ITA) = (L* − 50)/b*: L* = 50 + b* gives 45°.
        assert!((lab(70.0, 10.0, 20.0).ita_deg() - 45.0).abs() < 1e-12);
        assert!((lab(50.0, 0.0, 15.0).ita_deg()).abs() < 1e-12);
        assert!((lab(30.0, 5.0, 20.0).ita_deg() + 45.0).abs() < 1e-12);
    }

    #[test]
    fn ita_of_any_colour_lies_within_plus_minus_90_degrees() {
        for l in [0.0, 10.0, 49.9, 50.0, 50.1, 90.0, 100.0] {
            for b in [-100.0, -1.0, -1e-15, 0.0, 1e-15, 0.5, 1.0, 20.0] {
                let ita = lab(l, 3.0, b).ita_deg();
                assert!((-90.0..=90.0).contains(&ita), "L* {l} b* {b}: {ita}");
            }
        }
    }

    #[test]
    fn nearly_equal_greys_share_an_ita_category() {
        // #777777 (L* ≈ 50.04) and #767676 (L* ≈ 49.63) differ by 0.4 in L* and have b* ≈ 0 up
        // to rounding; atan2 put them at +99.8° and −90.9°. With b* floored at 1 both are
        // within atan(0.4) ≈ 22° of 0°: brown.
        let a = Lab::from_srgb(Srgb::from_hex("#777777").unwrap());
        let b = Lab::from_srgb(Srgb::from_hex("#767676").unwrap());
        assert_eq!(a.ita_category(), b.ita_category(), "{a:?} {b:?}");
        assert!((a.ita_deg() - b.ita_deg()).abs() < 25.0);
        // A skin colour (b* ≫ 1) keeps the textbook value: L* = 50 + b* gives 45°.
        assert!((lab(70.0, 10.0, 20.0).ita_deg() - 45.0).abs() < 1e-12);
    }

    #[test]
    fn ita_categories_at_their_boundaries() {
        use ItaCategory::*;
        let cases = [
            (55.000_001, VeryLight),
            (55.0, Light),
            (41.000_001, Light),
            (41.0, Intermediate),
            (28.000_001, Intermediate),
            (28.0, Tan),
            (10.000_001, Tan),
            (10.0, Brown),
            (-29.999_999, Brown),
            (-30.0, Dark),
            (-90.0, Dark),
            (90.0, VeryLight),
        ];
        for (deg, want) in cases {
            assert_eq!(ItaCategory::from_ita_deg(deg), want, "ITA {deg}°");
        }
        // Through a colour: L* = 50 + b* tan(θ) with θ just either side of 41°.
        for (theta, want) in [(41.01_f64, Light), (40.99, Intermediate)] {
            let c = lab(50.0 + 20.0 * theta.to_radians().tan(), 8.0, 20.0);
            assert_eq!(c.ita_category(), want, "{theta}°");
        }
    }
}
