//! The absorption of a heterogeneous skin inside its volume (docs/physics.md §19.1): a point's
//! chromophores are those of the texel of its nearest surface point, in the epidermis and in the
//! dermis alike; σs does not depend on them ([DJ06] eq. 6), so only σa varies, and the walk's
//! majorant takes the largest σa over the maps' parameter box, or over the box of the cell it
//! is in ([`super::majorant`]). Where texels have a thin epidermis, the epidermis/dermis boundary
//! lies at the nearest texel's thickness below the surface.

use super::majorant::{CellMajorant, MajorantGrid};
use super::nearest::{NearestAnchor, NearestSurface};
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
    /// The local majorant's cells.
    pub grid: MajorantGrid,
}

/// [`MapMedium`] at one wavelength, for one walk (it remembers the last nearest triangle and how
/// far the walk may go before another can be nearer, [`NearestSurface::uv_anchored`]).
#[derive(Debug, Clone)]
pub struct MapAbsorption<'a> {
    corners: CornersAt,
    /// The largest σa over the maps of the epidermis and of the dermis, mm⁻¹.
    pub largest: (f32, f32),
    medium: &'a MapMedium,
    anchor: Cell<Option<NearestAnchor>>,
}

impl MapMedium {
    /// The medium of `maps` over the `triangles` (world mm) with their texture coordinates, an
    /// epidermis `d_epi_mm` thick, the local majorant's cells of `cell_mm`
    /// ([`super::majorant::DEFAULT_CELL_MM`] by default).
    #[must_use]
    pub fn new(
        maps: Arc<SkinMaps>,
        triangles: &[([glam::Vec3; 3], [glam::Vec2; 3])],
        d_epi_mm: f64,
        cell_mm: f64,
    ) -> Self {
        let nearest = NearestSurface::new(triangles);
        let positions: Vec<[glam::Vec3; 3]> = triangles.iter().map(|t| t.0).collect();
        let grid = MajorantGrid::new(&positions, maps.clone(), d_epi_mm, cell_mm);
        Self {
            maps,
            nearest,
            grid,
        }
    }

    /// The absorption at wavelength `nm`.
    #[must_use]
    pub fn at_nm(&self, nm: f32) -> MapAbsorption<'_> {
        let corners = self.maps.absorption.at_nm(nm);
        MapAbsorption {
            corners,
            largest: corners.largest(self.maps.maps.range()),
            medium: self,
            anchor: Cell::new(None),
        }
    }
}

impl MapAbsorption<'_> {
    /// Whether some texel of the maps has a thin epidermis.
    #[must_use]
    pub fn has_thin(&self) -> bool {
        self.medium.maps.maps.thin().is_some()
    }

    /// The epidermis thickness under the texel of the surface point nearest `x`, mm: the thin one
    /// where that texel is thin, else the material's (docs/physics.md §19).
    #[must_use]
    #[inline]
    pub fn epidermis_mm(&self, x: DVec3) -> f32 {
        self.medium.maps.epidermis_at_mm(self.nearest_uv(x))
    }

    /// The texture coordinates of the surface point nearest `x`, the last answer kept as the
    /// next query's anchor.
    #[inline]
    fn nearest_uv(&self, x: DVec3) -> glam::Vec2 {
        let mut anchor = self.anchor.get();
        let uv = self
            .medium
            .grid
            .uv(&self.medium.nearest, x, &mut anchor)
            .unwrap_or_default();
        self.anchor.set(anchor);
        uv
    }

    /// σa at `x` of the epidermis (`epidermis`) or the dermis, from the texel of the surface
    /// point nearest `x`, mm⁻¹.
    #[must_use]
    #[inline]
    pub fn sigma_a(&self, epidermis: bool, x: DVec3) -> f32 {
        let uv = self.nearest_uv(x);
        self.corners
            .sigma_a(epidermis, self.medium.maps.maps.at(uv))
    }

    /// The local majorant's cell holding `x`, with both layers' σs `sigma_s` (mm⁻¹).
    #[must_use]
    pub fn cell_at(&self, x: DVec3, sigma_s: (f32, f32)) -> CellMajorant {
        self.medium
            .grid
            .cell_at(&self.medium.nearest, x, &self.corners, sigma_s)
    }

    /// The distance from `x` in `cell` along unit `d` to the next cell (mm), and that cell's key.
    #[must_use]
    #[inline]
    pub fn exit(&self, cell: &CellMajorant, x: DVec3, d: DVec3) -> (f64, [i32; 3]) {
        self.medium.grid.exit(cell, x, d)
    }

    /// The distance from `x` to the nearest face of `cell`, mm ([`MajorantGrid::inside_mm`]).
    #[must_use]
    #[inline]
    pub fn inside_mm(&self, cell: &CellMajorant, x: DVec3) -> f64 {
        MajorantGrid::inside_mm(cell, x)
    }

    /// The local majorant's cell `key` (from [`MapAbsorption::exit`]).
    #[must_use]
    pub fn cell(&self, key: [i32; 3], sigma_s: (f32, f32)) -> CellMajorant {
        self.medium
            .grid
            .cell(&self.medium.nearest, key, &self.corners, sigma_s)
    }
}
