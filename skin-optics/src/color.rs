//! Colour: CIE 1931 2° matching functions, illuminant D65, spectrum → XYZ → linear sRGB → sRGB ([CIE]).
//!
//! The only home of colour science in the workspace.

use crate::spectrum::GridSpectrum;
use crate::table::UniformTable;
use std::sync::OnceLock;

fn cmf_table() -> &'static UniformTable {
    static T: OnceLock<UniformTable> = OnceLock::new();
    T.get_or_init(|| UniformTable::parse(include_str!("../data/cie1931_2deg_cmf.csv")))
}

fn d65_table() -> &'static UniformTable {
    static T: OnceLock<UniformTable> = OnceLock::new();
    T.get_or_init(|| UniformTable::parse(include_str!("../data/cie_d65.csv")))
}

/// First wavelength of the CIE 1931 table, nm.
pub const CMF_START_NM: f64 = 360.0;
/// Last wavelength of the CIE 1931 table, nm.
pub const CMF_END_NM: f64 = 830.0;

/// CIE 1931 2° colour matching functions (x̄, ȳ, z̄) at `nm`, linearly interpolated in the 1-nm table;
/// zero outside 360–830 nm ([CIE] 015).
#[must_use]
pub fn cie_xyz_bar(nm: f64) -> [f64; 3] {
    let t = cmf_table();
    [t.lerp(0, nm), t.lerp(1, nm), t.lerp(2, nm)]
}

/// CIE illuminant D65 relative spectral power at `nm` (100 at 560 nm); zero outside 300–830 nm ([CIE] 015).
#[must_use]
pub fn d65(nm: f64) -> f64 {
    d65_table().lerp(0, nm)
}

/// ∫ ȳ(λ) dλ over 360–830 nm at 1 nm (≈ 106.857 nm): the normaliser for emitted spectra,
/// so that a constant radiance of 1 has luminance Y = 1.
#[must_use]
pub fn cie_y_integral() -> f64 {
    static Y: OnceLock<f64> = OnceLock::new();
    *Y.get_or_init(|| cmf_table().columns[1].iter().sum::<f64>())
}

/// CIE XYZ tristimulus values (Y = 1 for a perfect white reflector under the illuminant).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Xyz(pub [f64; 3]);

/// Linear sRGB (IEC 61966-2-1 primaries, D65 white), unclamped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearSrgb(pub [f64; 3]);

/// Gamma-encoded sRGB in [0, 1] per channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Srgb(pub [f64; 3]);

/// Reflectance spectrum → CIE XYZ under D65: XYZ = k Σ R(λ) S(λ) {x̄,ȳ,z̄}(λ) Δλ with k = 1 / Σ S ȳ Δλ.
///
/// The sum runs over the CIE table's own 1-nm grid (360–830 nm); the reflectance is interpolated
/// linearly and held constant beyond its grid, so a spectrum sampled only over 400–700 nm still
/// maps a perfect white reflector to the D65 white point exactly.
#[must_use]
pub fn reflectance_to_xyz(reflectance: &GridSpectrum) -> Xyz {
    let t = cmf_table();
    let n = t.columns[0].len();
    let mut xyz = [0.0; 3];
    let mut norm = 0.0;
    for i in 0..n {
        let nm = t.start_nm + t.step_nm * i as f64;
        let s = d65(nm);
        let r = reflectance.at_nm(nm);
        for (c, acc) in xyz.iter_mut().enumerate() {
            *acc += r * s * t.columns[c][i];
        }
        norm += s * t.columns[1][i];
    }
    Xyz(xyz.map(|v| v / norm))
}

impl Xyz {
    /// CIE XYZ → linear sRGB by the IEC 61966-2-1 matrix.
    #[must_use]
    pub fn to_linear_srgb(self) -> LinearSrgb {
        let [x, y, z] = self.0;
        LinearSrgb([
            3.2406 * x - 1.5372 * y - 0.4986 * z,
            -0.9689 * x + 1.8758 * y + 0.0415 * z,
            0.0557 * x - 0.2040 * y + 1.0570 * z,
        ])
    }

    /// CIE chromaticity (x, y).
    #[must_use]
    pub fn chromaticity(self) -> [f64; 2] {
        let s = self.0[0] + self.0[1] + self.0[2];
        [self.0[0] / s, self.0[1] / s]
    }
}

impl LinearSrgb {
    /// Linear sRGB → CIE XYZ (inverse IEC 61966-2-1 matrix).
    #[must_use]
    pub fn to_xyz(self) -> Xyz {
        let [r, g, b] = self.0;
        Xyz([
            0.4124 * r + 0.3576 * g + 0.1805 * b,
            0.2126 * r + 0.7152 * g + 0.0722 * b,
            0.0193 * r + 0.1192 * g + 0.9505 * b,
        ])
    }

    /// Clamp to [0, 1] and apply the sRGB transfer curve.
    #[must_use]
    pub fn to_srgb(self) -> Srgb {
        Srgb(self.0.map(|c| srgb_encode(c.clamp(0.0, 1.0))))
    }
}

impl Srgb {
    /// Undo the sRGB transfer curve.
    #[must_use]
    pub fn to_linear(self) -> LinearSrgb {
        LinearSrgb(self.0.map(srgb_decode))
    }

    /// `#rrggbb`, each channel rounded to 8 bits.
    #[must_use]
    pub fn to_hex(self) -> String {
        let [r, g, b] = self.0.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        format!("#{r:02x}{g:02x}{b:02x}")
    }

    /// Parse `#rrggbb` or `rrggbb`.
    pub fn from_hex(s: &str) -> Option<Srgb> {
        let h = s.trim().trim_start_matches('#');
        if h.len() != 6 || !h.chars().all(|c| c.is_ascii_hexdigit()) {
            return None;
        }
        let ch = |i: usize| {
            u8::from_str_radix(&h[i..i + 2], 16)
                .ok()
                .map(|v| f64::from(v) / 255.0)
        };
        Some(Srgb([ch(0)?, ch(2)?, ch(4)?]))
    }
}

/// The sRGB transfer curve (IEC 61966-2-1): linear [0, 1] → encoded [0, 1].
#[must_use]
pub fn srgb_encode(c: f64) -> f64 {
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`srgb_encode`].
#[must_use]
pub fn srgb_decode(c: f64) -> f64 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::WavelengthGrid;

    fn white() -> GridSpectrum {
        GridSpectrum::new(WavelengthGrid::visible(), vec![1.0; 31]).unwrap()
    }

    #[test]
    fn white_reflector_has_unit_luminance() {
        // k = 1 / Σ S ȳ Δλ makes Y exactly 1 for R ≡ 1.
        let xyz = reflectance_to_xyz(&white());
        assert!((xyz.0[1] - 1.0).abs() < 1e-12);
        let half = GridSpectrum::new(WavelengthGrid::visible(), vec![0.5; 31]).unwrap();
        assert!((reflectance_to_xyz(&half).0[1] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn white_reflector_maps_to_srgb_white() {
        let rgb = reflectance_to_xyz(&white()).to_linear_srgb();
        for c in rgb.0 {
            assert!((c - 1.0).abs() < 1e-3, "{rgb:?}");
        }
        let srgb = rgb.to_srgb();
        for c in srgb.0 {
            assert!((c - 1.0).abs() < 1e-3, "{srgb:?}");
        }
        assert_eq!(srgb.to_hex(), "#ffffff");
    }

    #[test]
    fn d65_white_point_chromaticity() {
        // CIE 015: D65 with the 1931 2° observer, x = 0.3127, y = 0.3290.
        let [x, y] = reflectance_to_xyz(&white()).chromaticity();
        assert!((x - 0.3127).abs() < 1e-4, "x = {x}");
        assert!((y - 0.3290).abs() < 1e-4, "y = {y}");
    }

    #[test]
    fn tables_hold_their_anchor_values() {
        // ȳ peaks at 1 at 555 nm; D65 is normalised to 100 at 560 nm ([CIE] 015).
        assert!((cie_xyz_bar(555.0)[1] - 1.0).abs() < 1e-6);
        assert!((d65(560.0) - 100.0).abs() < 1e-9);
        assert_eq!(cie_xyz_bar(CMF_START_NM - 1.0), [0.0; 3]);
        assert_eq!(d65(900.0), 0.0);
        // ∫ ȳ dλ over the 1-nm table ≈ 106.857 nm.
        assert!(
            (cie_y_integral() - 106.857).abs() < 1e-3,
            "{}",
            cie_y_integral()
        );
    }

    #[test]
    fn srgb_transfer_curve_inverts_and_is_continuous() {
        for i in 0..=100 {
            let c = f64::from(i) / 100.0;
            assert!((srgb_decode(srgb_encode(c)) - c).abs() < 1e-12);
        }
        // The two pieces meet at the threshold to within the standard's 4-digit constants.
        let t: f64 = 0.003_130_8;
        assert!((12.92 * t - (1.055 * t.powf(1.0 / 2.4) - 0.055)).abs() < 1e-6);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-15);
        assert_eq!(srgb_encode(0.0), 0.0);
    }

    #[test]
    fn srgb_matrices_are_inverse() {
        for rgb in [[1.0, 0.0, 0.0], [0.2, 0.5, 0.9], [1.0, 1.0, 1.0]] {
            let back = LinearSrgb(rgb).to_xyz().to_linear_srgb();
            for (a, b) in back.0.iter().zip(rgb) {
                // The IEC matrices are printed to 4 decimals.
                assert!((a - b).abs() < 5e-4, "{back:?} vs {rgb:?}");
            }
        }
    }

    #[test]
    fn hex_round_trip() {
        let s = Srgb::from_hex("#c8967d").unwrap();
        assert_eq!(s.to_hex(), "#c8967d");
        assert_eq!(Srgb::from_hex("c8967D").unwrap().to_hex(), "#c8967d");
        assert!(Srgb::from_hex("#c8967").is_none());
        assert!(Srgb::from_hex("#g8967d").is_none());
        let back = s.to_linear().to_srgb();
        assert_eq!(back.to_hex(), "#c8967d");
    }

    #[test]
    fn grey_reflector_keeps_white_chromaticity() {
        let grey = GridSpectrum::new(WavelengthGrid::visible(), vec![0.18; 31]).unwrap();
        let [x, y] = reflectance_to_xyz(&grey).chromaticity();
        let [xw, yw] = reflectance_to_xyz(&white()).chromaticity();
        assert!((x - xw).abs() < 1e-12 && (y - yw).abs() < 1e-12);
    }
}
