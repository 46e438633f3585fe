//! The widest profile within a probe's reach of each triangle of a skin with chromophore maps
//! (docs/physics.md §19.3): the BSSRDF draws radii from the low corner of the exit texel's cell
//! and, in a defensive mixture, from a wider profile, so that light entering in lighter skin
//! comes with bounded weights. That wider profile needs to bound only the skin a probe can reach,
//! not the whole map: a face's lightest texels (the eyes' and the teeth's) lie far from most of
//! its skin.
//!
//! The bound: the probes of an exit point p reach entry points within R of p, where R is the
//! widest profile's last tabulated radius. Cubic cells of edge R each keep the parameters' lower
//! bound over every triangle whose bounding box meets them (the maps' footprint of the
//! triangle's texture box, [`crate::material::maps::ChromophoreMaps::range_over`]) and whether
//! thin and thick epidermis is among them; a triangle takes the union over the cells its
//! bounding box, grown by R, meets, which holds every point within R of any of its points.

use crate::material::Material;
use crate::scene::Scene;
use glam::{IVec3, Vec3};

/// Per triangle of a scene, the node of its material's profile grid to mix into its BSSRDF's
/// radii ([`crate::material::hetero::SkinMaps::widest_node`]).
#[derive(Debug, Clone, Default)]
pub struct NearbyWidest {
    /// Node per triangle; [`NONE`] where the triangle's material has none.
    node: Vec<u32>,
}

/// A triangle without a node.
const NONE: u32 = u32::MAX;

/// Most cells one material's grid may hold: the cells grow until it fits.
const MAX_CELLS: usize = 1 << 20;

/// What the triangles meeting one cell hold: the parameters' lower bound, thin and thick
/// epidermis.
#[derive(Debug, Clone, Copy)]
struct Reach {
    lo: [f32; 3],
    thin: bool,
    thick: bool,
}

impl Reach {
    const EMPTY: Self = Self {
        lo: [f32::INFINITY; 3],
        thin: false,
        thick: false,
    };

    fn union(self, o: Self) -> Self {
        Self {
            lo: std::array::from_fn(|k| self.lo[k].min(o.lo[k])),
            thin: self.thin || o.thin,
            thick: self.thick || o.thick,
        }
    }
}

impl NearbyWidest {
    /// The nodes of every triangle of `scene` whose skin material has maps that sample per node.
    #[must_use]
    pub fn build(scene: &Scene) -> Self {
        let geometry = &scene.geometry;
        let mut node = vec![NONE; geometry.triangle_count()];
        for (m, material) in scene.materials.iter().enumerate() {
            let Material::Skin(skin) = material else {
                continue;
            };
            let (Some(maps), Some(ss)) = (&skin.maps, &skin.subsurface) else {
                continue;
            };
            if !maps.samples_per_node() {
                continue;
            }
            let triangles: Vec<u32> = (0..geometry.triangle_count() as u32)
                .filter(|&t| geometry.material_of(t) == m as u32)
                .collect();
            let reach_mm = ss.table.largest_radius_for_energy_mm(1.0);
            if triangles.is_empty() || reach_mm.is_nan() || reach_mm <= 0.0 {
                continue;
            }
            let own: Vec<([Vec3; 2], Reach)> = triangles
                .iter()
                .map(|&t| {
                    let p = geometry.triangle(t);
                    let uv = geometry.triangle_uvs(t);
                    let u = [
                        uv[0].x.min(uv[1].x).min(uv[2].x),
                        uv[0].x.max(uv[1].x).max(uv[2].x),
                    ];
                    let v = [
                        uv[0].y.min(uv[1].y).min(uv[2].y),
                        uv[0].y.max(uv[1].y).max(uv[2].y),
                    ];
                    let range = maps.maps.range_over(u, v);
                    let (thin, thick) = maps.maps.thin().map_or((false, true), |th| {
                        let [lo, hi] = th.flag_range_over(u, v);
                        (hi >= 0.5, lo < 0.5)
                    });
                    let reach = Reach {
                        lo: std::array::from_fn(|k| range[k][0]),
                        thin,
                        thick,
                    };
                    ([p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2])], reach)
                })
                .collect();
            let cells = Cells::new(&own, reach_mm);
            let mut grid = vec![Reach::EMPTY; cells.len()];
            for (bounds, reach) in &own {
                cells.for_each(bounds[0], bounds[1], |i| grid[i] = grid[i].union(*reach));
            }
            let grow = Vec3::splat(reach_mm);
            for (&t, (bounds, _)) in triangles.iter().zip(&own) {
                let mut near = Reach::EMPTY;
                cells.for_each(bounds[0] - grow, bounds[1] + grow, |i| {
                    near = near.union(grid[i]);
                });
                if let Some(n) = maps.widest_node(near.lo, near.thin, near.thick) {
                    node[t as usize] = n as u32;
                }
            }
        }
        Self { node }
    }

    /// The node of triangle `triangle`, if its material has one.
    #[must_use]
    #[inline]
    pub fn node(&self, triangle: u32) -> Option<usize> {
        self.node
            .get(triangle as usize)
            .filter(|&&n| n != NONE)
            .map(|&n| n as usize)
    }
}

/// A dense grid of cubic cells over a set of boxes.
struct Cells {
    origin: Vec3,
    edge_mm: f32,
    dims: IVec3,
}

impl Cells {
    /// Cells of edge `edge_mm` (grown until at most [`MAX_CELLS`]) over the boxes of `boxes`.
    fn new<T>(boxes: &[([Vec3; 2], T)], edge_mm: f32) -> Self {
        let lo = boxes.iter().fold(Vec3::INFINITY, |a, (b, _)| a.min(b[0]));
        let hi = boxes
            .iter()
            .fold(Vec3::NEG_INFINITY, |a, (b, _)| a.max(b[1]));
        let mut edge_mm = edge_mm;
        let dims = loop {
            let d = ((hi - lo) / edge_mm).floor().as_ivec3() + IVec3::ONE;
            if (d.x as usize) * (d.y as usize) * (d.z as usize) <= MAX_CELLS {
                break d;
            }
            edge_mm *= 1.25;
        };
        Self {
            origin: lo,
            edge_mm,
            dims,
        }
    }

    fn len(&self) -> usize {
        (self.dims.x * self.dims.y * self.dims.z) as usize
    }

    /// Calls `f` with the index of every cell that meets the box [`lo`, `hi`] (mm).
    fn for_each(&self, lo: Vec3, hi: Vec3, mut f: impl FnMut(usize)) {
        let cell = |p: Vec3| {
            ((p - self.origin) / self.edge_mm)
                .floor()
                .as_ivec3()
                .clamp(IVec3::ZERO, self.dims - IVec3::ONE)
        };
        let (a, b) = (cell(lo), cell(hi));
        for z in a.z..=b.z {
            for y in a.y..=b.y {
                for x in a.x..=b.x {
                    f((x + self.dims.x * (y + self.dims.y * z)) as usize);
                }
            }
        }
    }
}
