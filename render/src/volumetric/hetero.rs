//! The absorption of a heterogeneous skin inside its volume (docs/physics.md §19.1): a point's
//! chromophores are those of the texel of its nearest surface point, in the epidermis and in the
//! dermis alike; σs does not depend on them ([DJ06] eq. 6), so only σa varies, and the walk's
//! majorant takes the largest σa over the maps' parameter box.

use super::nearest::NearestSurface;
use crate::material::hetero::{CornersAt, SkinMaps};
use glam::DVec3;
use std::cell::Cell;
use std::sync::Arc;

/// A skin material's maps and the nearest-point queries over its meshes.
#[derive(Debug, Clone)]
pub struct MapMedium {
    /// The material's maps, absorption corners and profiles.
    pub maps: Arc<SkinMaps>,
    /// The material's triangles with their texture coordinates.
    pub nearest: NearestSurface,
}

/// [`MapMedium`] at one wavelength, for one walk (it remembers the last nearest triangle, which
/// starts the next query).
#[derive(Debug, Clone)]
pub struct MapAbsorption<'a> {
    corners: CornersAt,
    /// The largest σa over the maps of the epidermis and of the dermis, mm⁻¹.
    pub largest: (f32, f32),
    medium: &'a MapMedium,
    hint: Cell<Option<u32>>,
}

impl MapMedium {
    /// The absorption at wavelength `nm`.
    #[must_use]
    pub fn at_nm(&self, nm: f32) -> MapAbsorption<'_> {
        let corners = self.maps.absorption.at_nm(nm);
        MapAbsorption {
            corners,
            largest: corners.largest(self.maps.maps.range()),
            medium: self,
            hint: Cell::new(None),
        }
    }
}

impl MapAbsorption<'_> {
    /// σa at `x` of the epidermis (`epidermis`) or the dermis, from the texel of the surface
    /// point nearest `x`, mm⁻¹.
    #[must_use]
    #[inline]
    pub fn sigma_a(&self, epidermis: bool, x: DVec3) -> f32 {
        let mut hint = self.hint.get();
        let uv = self
            .medium
            .nearest
            .uv_from(x, &mut hint)
            .unwrap_or_default();
        self.hint.set(hint);
        self.corners
            .sigma_a(epidermis, self.medium.maps.maps.at(uv))
    }
}
