//! Level of detail by pixel footprint (docs/physics.md §16.3). Where one pixel covers much more
//! than the profile's 99% radius r₉₉, the light a skin point reflects is the profile integrated
//! over the pixel: the subsurface term collapses to its total R_tot(λ), shaded as the skin's
//! Fresnel-weighted diffuse body (`material` docs: f = R_tot T(θi) T(θo) / (π T̄), the same split
//! as the BSSRDF's S_ω, so on a flat slab both reflect the same energy), with no probe rays. Where
//! it covers much less, the full BSSRDF. In between each hit picks the diffuse body with
//! probability w(x), x = footprint / r₉₉, a smoothstep in log x over the band: the image is an
//! unbiased mixture of the two, so nothing pops.
//!
//! The footprint is the camera's pixel angle times the distance the path has travelled
//! (`PathSettings::pixel_angle_rad`): exact for camera rays at the image centre, and a lower
//! bound after a bounce (a ray cone widens at every diffuse bounce), so indirect hits never
//! collapse more than their true footprint would allow.

use super::FidelityError;
use serde::{Deserialize, Serialize};

/// The band of x = footprint / r₉₉ over which the BSSRDF blends into the diffuse body.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LodBand {
    /// Full BSSRDF at or below this x.
    pub full_below: f32,
    /// Diffuse body at or above this x.
    pub diffuse_above: f32,
}

impl Default for LodBand {
    /// From one to four 99% radii per pixel: below, the profile spans a pixel or more and its blur
    /// is visible; above, 99% of the light leaves within a quarter pixel of where it entered.
    fn default() -> Self {
        Self {
            full_below: 1.0,
            diffuse_above: 4.0,
        }
    }
}

impl LodBand {
    /// The band if 0 < full_below < diffuse_above ≤ 1e6.
    pub fn checked(self) -> Result<Self, FidelityError> {
        let ok = self.full_below > 0.0
            && self.diffuse_above > self.full_below
            && self.diffuse_above <= 1e6;
        if ok {
            Ok(self)
        } else {
            Err(FidelityError {
                name: "fidelity.lod_band",
                value: f64::from(self.diffuse_above),
                range: "0 < full_below < diffuse_above ≤ 1e6 (pixel footprint / r99)",
            })
        }
    }

    /// w(x): probability of shading with the diffuse body at x = footprint / r₉₉ (0 below the
    /// band, 1 above, smoothstep in ln x between).
    #[must_use]
    pub fn diffuse_weight(&self, x: f32) -> f32 {
        if x.is_nan() || x <= self.full_below {
            return 0.0;
        }
        if x >= self.diffuse_above {
            return 1.0;
        }
        let t = (x / self.full_below).ln() / (self.diffuse_above / self.full_below).ln();
        t * t * (3.0 - 2.0 * t)
    }
}

/// The level of detail of one skin material: its r₉₉ and the band.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Lod {
    /// The 99% radius of the profile's luminance under D65 (ȳ·D65-weighted rows), mm
    /// ([`crate::bssrdf::ProfileTable::luminance_radius_for_energy_mm`]): the blur the image's
    /// luminance sees, not the widest (red) row's.
    pub r99_mm: f32,
    /// The band.
    pub band: LodBand,
}

impl Lod {
    /// Probability of the diffuse body at a pixel footprint of `footprint_mm`.
    #[must_use]
    pub fn diffuse_probability(&self, footprint_mm: f32) -> f32 {
        self.band.diffuse_weight(footprint_mm / self.r99_mm)
    }

    /// Footprints (mm) where the blend starts and ends.
    #[must_use]
    pub fn band_mm(&self) -> (f32, f32) {
        (
            self.band.full_below * self.r99_mm,
            self.band.diffuse_above * self.r99_mm,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// w is 0 below and 1 above the band, continuous and increasing across it, ½ at its
    /// geometric middle.
    #[test]
    fn the_blend_is_continuous_and_monotone() {
        let b = LodBand::default();
        assert_eq!(b.diffuse_weight(0.5), 0.0);
        assert_eq!(b.diffuse_weight(4.0), 1.0);
        assert!((b.diffuse_weight(2.0) - 0.5).abs() < 1e-6);
        let mut last = 0.0;
        for i in 0..=400 {
            let x = 0.5 * 1.01f32.powi(i);
            let w = b.diffuse_weight(x);
            assert!(w >= last && w - last < 0.02, "x {x}: {last} → {w}");
            last = w;
        }
        assert!(
            LodBand {
                full_below: 2.0,
                diffuse_above: 1.0
            }
            .checked()
            .is_err()
        );
    }
}
