//! The colour spaces an RGB export is declared in: linear Rec.709 (the primaries of sRGB, D65 white) and
//! ACEScg (AP1 primaries, ACES white), docs/physics.md §14.

use std::fmt;
use std::str::FromStr;

/// Linear Rec.709 → ACEScg: the AP1 primaries of [ACES] with the Bradford adaptation from D65
/// to the ACES white, as published with the ACES reference implementation (each row sums to 1 to 1e-6,
/// so white stays white).
pub const REC709_TO_ACESCG: [[f64; 3]; 3] = [
    [0.613_097, 0.339_523, 0.047_380],
    [0.070_194, 0.916_354, 0.013_452],
    [0.020_616, 0.109_570, 0.869_815],
];

/// A linear RGB colour space of the exported colours.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColourSpace {
    /// Linear Rec.709 / sRGB primaries, D65 white (MaterialX `lin_rec709`).
    #[default]
    LinRec709,
    /// ACEScg: AP1 primaries, ACES white (MaterialX `acescg`).
    AcesCg,
}

impl ColourSpace {
    /// The MaterialX colour-space name.
    #[must_use]
    pub fn materialx_name(self) -> &'static str {
        match self {
            ColourSpace::LinRec709 => "lin_rec709",
            ColourSpace::AcesCg => "acescg",
        }
    }

    /// A linear Rec.709 triple expressed in this space.
    #[must_use]
    pub fn from_rec709(self, rgb: [f64; 3]) -> [f64; 3] {
        match self {
            ColourSpace::LinRec709 => rgb,
            ColourSpace::AcesCg => {
                REC709_TO_ACESCG.map(|row| row[0] * rgb[0] + row[1] * rgb[1] + row[2] * rgb[2])
            }
        }
    }
}

impl fmt::Display for ColourSpace {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.materialx_name())
    }
}

impl FromStr for ColourSpace {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "lin_rec709" | "rec709" | "srgb-linear" => Ok(ColourSpace::LinRec709),
            "acescg" => Ok(ColourSpace::AcesCg),
            _ => Err(format!(
                "unknown colour space '{s}' (valid: lin_rec709, acescg)"
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_stays_white_and_primaries_mix() {
        // Both spaces share the white (through the chromatic adaptation): (1,1,1) maps to itself.
        let w = ColourSpace::AcesCg.from_rec709([1.0, 1.0, 1.0]);
        assert!(w.iter().all(|c| (c - 1.0).abs() < 2e-6), "{w:?}");
        // AP1 is wider than Rec.709: a Rec.709 primary has every AP1 component positive.
        let red = ColourSpace::AcesCg.from_rec709([1.0, 0.0, 0.0]);
        assert!(red.iter().all(|&c| c > 0.0) && red[0] < 1.0);
        assert_eq!(
            ColourSpace::LinRec709.from_rec709([0.2, 0.3, 0.4]),
            [0.2, 0.3, 0.4]
        );
        assert_eq!("ACEScg".parse::<ColourSpace>(), Ok(ColourSpace::AcesCg));
        assert!(
            "xyz"
                .parse::<ColourSpace>()
                .unwrap_err()
                .contains("lin_rec709")
        );
    }
}
