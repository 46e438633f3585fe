//! "Is this point within d of the surface?" for a closed triangle mesh: the epidermis of the
//! volumetric walk is the set of points within d_epi of the skin's surface (docs/physics.md §15).
//!
//! A sparse uniform grid (cell h = max(2d, extent / 256)) lists, per cell, the triangles whose
//! distance to the cell's centre is at most d + h√3/2: every triangle within d of any point of the
//! cell is listed there (triangle inequality), so one cell's list answers the query exactly. The
//! point–triangle distance is Ericson's closest-point test ([Ericson05] §5.1.5).

use glam::Vec3;
use std::collections::HashMap;

/// Most cells one side of the grid spans over the mesh's extent.
const MAX_CELLS_PER_SIDE: f32 = 256.0;

/// The triangles near each cell of a sparse grid, for within-distance queries.
#[derive(Debug, Clone)]
pub struct SurfaceDistance {
    radius_mm: f32,
    cell_mm: f32,
    triangles: Vec<[Vec3; 3]>,
    cells: HashMap<[i32; 3], Vec<u32>>,
}

impl SurfaceDistance {
    /// The grid over `triangles` (world mm) for queries at distance `radius_mm` > 0.
    #[must_use]
    pub fn new(triangles: Vec<[Vec3; 3]>, radius_mm: f32) -> Self {
        let (lo, hi) = triangles.iter().flatten().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let extent = (hi - lo).max_element().max(radius_mm);
        let cell_mm = (2.0 * radius_mm).max(extent / MAX_CELLS_PER_SIDE);
        let reach = radius_mm + cell_mm * 0.5 * 3f32.sqrt();
        let mut cells: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
        for (index, tri) in triangles.iter().enumerate() {
            let tlo = tri[0].min(tri[1]).min(tri[2]) - Vec3::splat(reach);
            let thi = tri[0].max(tri[1]).max(tri[2]) + Vec3::splat(reach);
            let (a, b) = (cell_of(tlo, cell_mm), cell_of(thi, cell_mm));
            for i in a[0]..=b[0] {
                for j in a[1]..=b[1] {
                    for k in a[2]..=b[2] {
                        let centre = (Vec3::new(i as f32, j as f32, k as f32) + 0.5) * cell_mm;
                        if distance_squared(centre, tri) <= reach * reach {
                            cells.entry([i, j, k]).or_default().push(index as u32);
                        }
                    }
                }
            }
        }
        Self {
            radius_mm,
            cell_mm,
            triangles,
            cells,
        }
    }

    /// True when some triangle lies within the radius of `p`.
    #[must_use]
    pub fn within(&self, p: Vec3) -> bool {
        let r2 = self.radius_mm * self.radius_mm;
        self.cells
            .get(&cell_of(p, self.cell_mm))
            .is_some_and(|list| {
                list.iter()
                    .any(|&t| distance_squared(p, &self.triangles[t as usize]) <= r2)
            })
    }

    /// Cells holding at least one triangle, and the triangle entries over all cells (memory).
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.cells.len(), self.cells.values().map(Vec::len).sum())
    }
}

fn cell_of(p: Vec3, h: f32) -> [i32; 3] {
    (p / h).floor().as_ivec3().to_array()
}

/// Squared distance from `p` to the triangle `t`, mm² ([Ericson05] §5.1.5, closest point by
/// Voronoi regions).
#[must_use]
pub fn distance_squared(p: Vec3, t: &[Vec3; 3]) -> f32 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    let closest = if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = p - b;
        let (d3, d4) = (ab.dot(bp), ac.dot(bp));
        let cp = p - c;
        let (d5, d6) = (ab.dot(cp), ac.dot(cp));
        let vc = d1 * d4 - d3 * d2;
        let vb = d5 * d2 - d1 * d6;
        let va = d3 * d6 - d5 * d4;
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else if d6 >= 0.0 && d5 <= d6 {
            c
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            a + ab * (d1 / (d1 - d3))
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            a + ac * (d2 / (d2 - d6))
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))
        } else {
            let denom = 1.0 / (va + vb + vc);
            a + ab * (vb * denom) + ac * (vc * denom)
        }
    };
    (p - closest).length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// The grid answers as the brute-force minimum over all triangles does, at random points
    /// near a two-triangle square (exact: the same distance function decides both).
    #[test]
    fn grid_agrees_with_brute_force() {
        let q = [
            Vec3::new(-5.0, -5.0, 0.0),
            Vec3::new(5.0, -5.0, 0.0),
            Vec3::new(5.0, 5.0, 0.0),
            Vec3::new(-5.0, 5.0, 0.0),
        ];
        let tris = vec![[q[0], q[1], q[2]], [q[0], q[2], q[3]]];
        let grid = SurfaceDistance::new(tris.clone(), 0.2);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let mut inside = 0;
        for _ in 0..20_000 {
            let p = Vec3::new(
                rng.random_range(-6.0..6.0),
                rng.random_range(-6.0..6.0),
                rng.random_range(-0.5..0.5),
            );
            let brute = tris.iter().any(|t| distance_squared(p, t) <= 0.04);
            assert_eq!(grid.within(p), brute, "{p}");
            inside += usize::from(brute);
        }
        assert!(inside > 1000, "the test must exercise both answers");
        // Closed form: a point above the square's interior is at its height.
        assert!((distance_squared(Vec3::new(2.0, 1.0, 0.3), &tris[0]) - 0.09).abs() < 1e-6);
        // Beyond a corner: the distance to the corner.
        let d2 = distance_squared(Vec3::new(6.0, -6.0, 0.0), &tris[0]);
        assert!((d2 - 2.0).abs() < 1e-5, "{d2}");
    }
}
