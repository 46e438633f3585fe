//! The local majorant of a skin with chromophore maps (docs/physics.md §19.1): a sparse grid of
//! cubic cells over the surface, each holding the box of parameters (C_m, β_m, C_h) that the
//! nearest surface point of any point of the cell can read, the layers the cell can hold, and
//! the triangles that can be nearest to its points. At one wavelength a cell's majorant is the
//! largest σt over that box and those layers; the walk tracks each cell with its own majorant
//! and draws the rest of a flight afresh in the next cell (delta tracking against a
//! piecewise-constant majorant, [NGHJ18]), so it stays unbiased while light skin's flights are no
//! longer bounded by the lips' absorption.
//!
//! The bound: for x in a cell of centre c and half-diagonal r, the distance D to the surface
//! obeys D(x) ≤ D(c) + r (D is 1-Lipschitz), so the nearest surface point q of x lies within
//! D(x) + r ≤ D(c) + 2r of c. Every triangle within that radius of c is listed, each adding the
//! texels of the part of it within the radius (its texture map's image of the disc where the ball
//! cuts its plane; bilinear footprint and a texel of margin). The grid keys the cells within
//! [`SHELL_MM`] of the surface and builds each on first use; deeper points lie in the dermis
//! alone and take its largest σa over the whole maps.

use super::nearest::{NearestAnchor, NearestSurface};
use crate::material::hetero::{CornersAt, SkinMaps};
use glam::{DVec3, Vec2};
use rustc_hash::FxHashMap;
use std::fmt;
use std::str::FromStr;
use std::sync::Arc;
use std::sync::OnceLock;

/// Which majorant the walk's delta tracking uses in a skin with chromophore maps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Majorant {
    /// The largest σt over the maps' whole parameter box, both layers.
    Global,
    /// Per cell of a [`MajorantGrid`], the largest σt its points can have.
    #[default]
    Local,
}

impl fmt::Display for Majorant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Global => "global",
            Self::Local => "local",
        })
    }
}

/// A majorant name that is neither `global` nor `local`.
#[derive(Debug, Clone, thiserror::Error)]
#[error("unknown majorant '{0}' (valid: global, local)")]
pub struct UnknownMajorant(pub String);

impl FromStr for Majorant {
    type Err = UnknownMajorant;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        [Self::Global, Self::Local]
            .into_iter()
            .find(|m| m.to_string().eq_ignore_ascii_case(s))
            .ok_or_else(|| UnknownMajorant(s.to_string()))
    }
}

/// Default edge of the grid's cells, mm: a few transport mean free paths of skin, so a cell
/// crossing is rare beside the collisions, and small beside the face's features.
pub const DEFAULT_CELL_MM: f64 = 2.0;

/// Depth under the surface the grid covers, mm: deeper cells take the dermis' largest σa over
/// the whole maps.
pub const SHELL_MM: f64 = 4.0;

/// Most cells the grid keys (about 30 bytes each, plus the lists of those built); the cells grow
/// until it fits.
const MAX_CELLS: f64 = 2.0e6;

/// A box of parameters (C_m, β_m, C_h), [lo, hi] each.
type ParamBox = [[f32; 2]; 3];

/// A triangle's parameter box and thin-epidermis flag range over its whole texture box, each
/// found on first use.
type WholeBox = (OnceLock<ParamBox>, OnceLock<[f32; 2]>);

const EMPTY: ParamBox = [[f32::INFINITY, f32::NEG_INFINITY]; 3];

fn union(a: ParamBox, b: ParamBox) -> ParamBox {
    std::array::from_fn(|k| [a[k][0].min(b[k][0]), a[k][1].max(b[k][1])])
}

/// What one cell's points can be: their parameters' box and their layers; and the triangles
/// that can be nearest to them.
#[derive(Debug, Clone, PartialEq)]
struct Cell {
    range: ParamBox,
    epidermis: bool,
    dermis: bool,
    /// The epidermis thickness under every texel the cell's points can read (the thin one or the
    /// material's), mm; `None` where it varies or the cell lies off the grid.
    epidermis_mm: Option<f32>,
    /// Every triangle not listed lies farther than this from the centre, mm.
    reach_mm: f64,
    /// (distance of the triangle from the centre in mm, rounded down; triangle), nearest first.
    list: Box<[(f32, u32)]>,
}

/// The grid of cells over a skin's surface, each built when a walk first enters it.
#[derive(Debug, Clone)]
pub struct MajorantGrid {
    cell_mm: f64,
    /// Half-diagonal of a cell with a margin for the rounding of positions, mm.
    half_diagonal_mm: f64,
    d_epi_mm: f64,
    /// The cells within the shell (by key), indices into `slots`.
    index: FxHashMap<[i32; 3], u32>,
    slots: Vec<OnceLock<Box<Cell>>>,
    /// The parameters over the surface.
    maps: Arc<SkinMaps>,
    /// Cells off the grid: deeper than the shell, the dermis over the maps' whole box.
    deep: Cell,
    /// Per triangle (numbered as the surface's nearest-point search numbers them), the
    /// parameters and the thin-epidermis flag over its whole texture box, each found once: a
    /// cell's ball holds most of its triangles whole.
    whole: Box<[WholeBox]>,
}

/// One cell of the grid at one wavelength, for the walk.
#[derive(Debug, Clone, Copy)]
pub struct CellMajorant {
    key: [i32; 3],
    lo: DVec3,
    hi: DVec3,
    /// The cell's majorant σ̄, mm⁻¹.
    pub sigma_t: f32,
    /// Each layer's largest σa in the cell (epidermis, dermis; 0 where the layer is absent), mm⁻¹.
    pub sigma_a: (f32, f32),
    /// Each layer's smallest σa in the cell (epidermis, dermis), lowered by the interpolation's
    /// rounding: no point of the cell absorbs less, mm⁻¹.
    pub least_sigma_a: (f32, f32),
    /// The epidermis thickness under every texel the cell's points can read, mm (`None`: it
    /// varies, the nearest texel tells).
    pub epidermis_mm: Option<f32>,
}

impl MajorantGrid {
    /// The grid over the surface `triangles` (world mm) with the parameters of `maps`, an epidermis `d_epi_mm` thick, cells of `cell_mm` (grown until at most
    /// `MAX_CELLS` cover the shell). Cells are keyed here and built when first asked for.
    #[must_use]
    pub fn new(
        triangles: &[[glam::Vec3; 3]],
        maps: Arc<SkinMaps>,
        d_epi_mm: f64,
        cell_mm: f64,
    ) -> Self {
        let deep = Cell {
            range: maps.maps.range(),
            epidermis: false,
            dermis: true,
            epidermis_mm: None,
            reach_mm: 0.0,
            list: Box::new([]),
        };
        let area: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(glam::Vec3::as_dvec3);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum();
        let mut cell_mm = cell_mm;
        // The shell's cells number about 2A·(shell + h)/h³ (both sides of the surface).
        while 2.0 * area * (SHELL_MM.max(d_epi_mm) + cell_mm) / cell_mm.powi(3) > MAX_CELLS {
            cell_mm *= 1.25;
        }
        let half_diagonal = 0.5 * 3f64.sqrt() * cell_mm;
        // Every cell whose centre can lie within the shell of a triangle (the shell at least
        // d_epi + r): a cell off this set has D(c) > shell, so its points have D > shell − r,
        // in the dermis.
        let reach = SHELL_MM.max(d_epi_mm + half_diagonal) + half_diagonal;
        let mut index = FxHashMap::default();
        for t in triangles {
            let lo = t[0].min(t[1]).min(t[2]).as_dvec3() - DVec3::splat(reach);
            let hi = t[0].max(t[1]).max(t[2]).as_dvec3() + DVec3::splat(reach);
            let (a, b) = (key_of(lo, cell_mm), key_of(hi, cell_mm));
            for i in a[0]..=b[0] {
                for j in a[1]..=b[1] {
                    for k in a[2]..=b[2] {
                        let next = index.len() as u32;
                        index.entry([i, j, k]).or_insert(next);
                    }
                }
            }
        }
        let slots = (0..index.len()).map(|_| OnceLock::new()).collect();
        // The rounding of a walk's position past its cell's faces, mm.
        let extent = triangles
            .iter()
            .flatten()
            .fold(0.0f64, |m, p| m.max(f64::from(p.abs().max_element())));
        Self {
            whole: (0..triangles.len()).map(|_| Default::default()).collect(),
            cell_mm,
            half_diagonal_mm: half_diagonal + 1e-9 * (1.0 + extent + reach),
            d_epi_mm,
            index,
            slots,
            maps,
            deep,
        }
    }

    /// The cell `key`, built on first use from the surface `nearest`.
    fn get(&self, nearest: &NearestSurface, key: [i32; 3]) -> &Cell {
        let Some(&slot) = self.index.get(&key) else {
            return &self.deep;
        };
        self.slots[slot as usize].get_or_init(|| Box::new(self.build(nearest, key)))
    }

    /// Cell `key`: the triangles within D(c) + 2r of its centre c, the parameters they can
    /// read, and its layers by D(c) ± r.
    fn build(&self, nearest: &NearestSurface, key: [i32; 3]) -> Cell {
        let c = centre_of(key, self.cell_mm);
        let r = self.half_diagonal_mm;
        let maps = &self.maps.maps;
        let Some(dist) = nearest.distance(c) else {
            return self.deep.clone();
        };
        let reach_mm = dist + 2.0 * r;
        let mut list = Vec::new();
        nearest.triangles_within(c, reach_mm, &mut list);
        list.sort_by(|a, b| a.0.total_cmp(&b.0));
        // (triangle, its box within reach, whether that is its whole box)
        let boxes: Vec<_> = list
            .iter()
            .map(|&(_, t)| {
                let b = nearest.uv_box_within(t, c, reach_mm);
                (t as usize, b, b == nearest.uv_box(t))
            })
            .collect();
        let range = boxes.iter().fold(EMPTY, |acc, &(t, (u, v), whole)| {
            let range = match self.whole.get(t) {
                Some(once) if whole => *once.0.get_or_init(|| maps.range_over(u, v)),
                _ => maps.range_over(u, v),
            };
            union(acc, range)
        });
        let epidermis = dist - r <= self.d_epi_mm;
        // The filtered flag over the same boxes: below ½ throughout, no point reads a thin
        // texel; at least ½ throughout, every point does. A cell without epidermis never asks.
        let epidermis_mm = match maps.thin() {
            _ if boxes.is_empty() || !epidermis => None,
            None => Some(self.maps.epidermis_mm),
            Some(thin) => {
                // A filtered value may pass its texels' range by the weights' rounding.
                let slack = 4.0 * f32::EPSILON;
                let (mut below, mut above) = (true, true);
                for &(t, (u, v), whole) in &boxes {
                    let [lo, hi] = match self.whole.get(t) {
                        Some(once) if whole => *once.1.get_or_init(|| thin.flag_range_over(u, v)),
                        _ => thin.flag_range_over(u, v),
                    };
                    below &= hi * (1.0 + slack) < 0.5;
                    above &= lo * (1.0 - slack) >= 0.5;
                    if !below && !above {
                        break;
                    }
                }
                if below {
                    Some(self.maps.epidermis_mm)
                } else if above {
                    Some(thin.thickness_mm)
                } else {
                    None
                }
            }
        };
        // With a thin epidermis in the maps, d_epi is the deepest boundary and the dermis may
        // begin at the thin one.
        let shallowest = maps.thin().map_or(self.d_epi_mm, |t| {
            self.d_epi_mm.min(f64::from(t.thickness_mm))
        });
        Cell {
            range,
            epidermis,
            dermis: dist + r > shallowest,
            epidermis_mm,
            reach_mm,
            list: list.into_boxed_slice(),
        }
    }

    /// The texture coordinates of the surface point of `nearest` (the grid's surface) nearest
    /// `x`: from the triangles listed in x's cell (every one that can be nearest), or from the
    /// whole surface off the grid; `anchor` as in [`NearestSurface::uv_anchored`].
    #[must_use]
    #[inline]
    pub fn uv(
        &self,
        nearest: &NearestSurface,
        x: DVec3,
        anchor: &mut Option<NearestAnchor>,
    ) -> Option<Vec2> {
        if let Some(uv) = nearest.uv_if_anchored(x, anchor.as_ref()) {
            return Some(uv);
        }
        let key = key_of(x, self.cell_mm);
        let cell = self.get(nearest, key);
        if cell.list.is_empty() {
            return nearest.uv_anchored(x, anchor);
        }
        let off_centre = x.distance(centre_of(key, self.cell_mm));
        nearest.uv_listed(
            x,
            &cell.list,
            off_centre,
            cell.reach_mm - off_centre,
            anchor,
        )
    }

    /// Edge of the cells, mm.
    #[must_use]
    pub fn cell_mm(&self) -> f64 {
        self.cell_mm
    }

    /// Cells keyed (the shell's; built or not).
    #[must_use]
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// Whether the grid keys no cell.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Cells built so far.
    #[must_use]
    pub fn built(&self) -> usize {
        self.slots.iter().filter(|s| s.get().is_some()).count()
    }

    /// The cell holding `x` at wavelength absorption `corners`, both layers' σs `sigma_s`
    /// (epidermis, dermis; mm⁻¹).
    #[must_use]
    pub fn cell_at(
        &self,
        nearest: &NearestSurface,
        x: DVec3,
        corners: &CornersAt,
        sigma_s: (f32, f32),
    ) -> CellMajorant {
        self.cell(nearest, key_of(x, self.cell_mm), corners, sigma_s)
    }

    /// The cell `key` at wavelength absorption `corners`, both layers' σs `sigma_s`.
    #[must_use]
    pub fn cell(
        &self,
        nearest: &NearestSurface,
        key: [i32; 3],
        corners: &CornersAt,
        sigma_s: (f32, f32),
    ) -> CellMajorant {
        let cell = self.get(nearest, key);
        // σa at a point is the corners' trilinear interpolation in f32, which may pass the
        // largest corner by its rounding.
        let least = smallest(corners, cell.range);
        let (e, d) = corners.largest(cell.range);
        let (e, d) = (
            e * (1.0 + 4.0 * f32::EPSILON),
            d * (1.0 + 4.0 * f32::EPSILON),
        );
        let sigma_a = (
            if cell.epidermis { e } else { 0.0 },
            if cell.dermis { d } else { 0.0 },
        );
        let mut sigma_t = 0.0f32;
        if cell.epidermis {
            sigma_t = sigma_t.max(e + sigma_s.0);
        }
        if cell.dermis {
            sigma_t = sigma_t.max(d + sigma_s.1);
        }
        let lo = DVec3::new(f64::from(key[0]), f64::from(key[1]), f64::from(key[2])) * self.cell_mm;
        CellMajorant {
            key,
            lo,
            hi: lo + DVec3::splat(self.cell_mm),
            // The sums' rounding likewise.
            sigma_t: sigma_t * (1.0 + 4.0 * f32::EPSILON),
            sigma_a,
            // The interpolation's rounding is a few ulps of the largest corner it mixes.
            least_sigma_a: (
                (least.0 - 8.0 * f32::EPSILON * e).max(0.0),
                (least.1 - 8.0 * f32::EPSILON * d).max(0.0),
            ),
            epidermis_mm: cell.epidermis_mm,
        }
    }

    /// The distance from `x` to the nearest face of `cell`, mm (negative outside): no flight
    /// shorter than it leaves the cell, whatever its direction.
    #[must_use]
    #[inline]
    pub fn inside_mm(cell: &CellMajorant, x: DVec3) -> f64 {
        (x - cell.lo).min(cell.hi - x).min_element()
    }

    /// The distance from `x` (in `cell`) along unit `d` to the next cell, mm, and its key.
    #[must_use]
    #[inline]
    pub fn exit(&self, cell: &CellMajorant, x: DVec3, d: DVec3) -> (f64, [i32; 3]) {
        let mut best = (f64::INFINITY, 0usize);
        for axis in 0..3 {
            let t = if d[axis] > 0.0 {
                (cell.hi[axis] - x[axis]) / d[axis]
            } else if d[axis] < 0.0 {
                (cell.lo[axis] - x[axis]) / d[axis]
            } else {
                continue;
            };
            if t < best.0 {
                best = (t, axis);
            }
        }
        let mut key = cell.key;
        key[best.1] += if d[best.1] > 0.0 { 1 } else { -1 };
        (best.0.max(0.0), key)
    }

    /// The parameter box and layers (epidermis, dermis) of the cell holding `x`.
    #[must_use]
    pub fn bound_at(&self, nearest: &NearestSurface, x: DVec3) -> ([[f32; 2]; 3], bool, bool) {
        let c = self.get(nearest, key_of(x, self.cell_mm));
        (c.range, c.epidermis, c.dermis)
    }
}

/// The smallest σa of each layer (epidermis, dermis) over the parameter box `range`: like the
/// largest, a multilinear function's smallest value over a box is at one of its corners.
fn smallest(corners: &CornersAt, range: ParamBox) -> (f32, f32) {
    let mut out = (f32::INFINITY, f32::INFINITY);
    for c in 0..8 {
        let p = std::array::from_fn(|k| range[k][(c >> k) & 1]);
        out.0 = out.0.min(corners.sigma_a(true, p));
        out.1 = out.1.min(corners.sigma_a(false, p));
    }
    (out.0.max(0.0), out.1.max(0.0))
}

fn key_of(p: DVec3, cell_mm: f64) -> [i32; 3] {
    let q = (p / cell_mm).floor();
    [q.x as i32, q.y as i32, q.z as i32]
}

fn centre_of(key: [i32; 3], cell_mm: f64) -> DVec3 {
    (DVec3::new(f64::from(key[0]), f64::from(key[1]), f64::from(key[2])) + 0.5) * cell_mm
}
