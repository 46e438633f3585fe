//! Bounds on the distance from a point to a closed triangle mesh's surface (docs/physics.md §15.1,
//! §15.5). The volumetric walk asks two things of them: is this point within d of the surface (the
//! epidermis), and can a flight of length s from here reach the surface at all (if not, it casts
//! no ray).
//!
//! Two grids answer, both in world mm with the queries in f64:
//!
//! - a sparse **fine grid** (cell h = max(d, extent / 256), larger when the mesh's area would
//!   need more than [`MAX_FINE_CELLS`]) lists per cell the triangles whose
//!   distance to the cell's centre c is at most R = d + h√3/2. For a point p of the cell every
//!   triangle not listed is farther than R − |p − c| ≥ d (triangle inequality), so with m the least
//!   distance over the list, lo = min(m, R − |p − c|) and hi = m bound the distance D:
//!   lo ≤ D ≤ hi, and lo = hi = D whenever D ≤ R − |p − c|, in particular whenever D ≤ d;
//! - a dense **coarse grid** (cell H ≥ h, at most 64 per side) marks the cells whose centre lies
//!   within H√3/2 of a triangle (every cell a triangle passes through is marked) and holds each
//!   cell's chessboard distance k, in cells, to the nearest marked one: every surface point lies in
//!   a marked cell, at least k − 1 cells away along some axis, so D ≥ (k − 1)·H.
//!
//! The point–triangle distance is Ericson's closest-point test ([Ericson05] §5.1.5), evaluated on
//! p − a taken in f64, so the answer keeps its precision far from the origin.

use glam::{DVec3, Vec3};
use rustc_hash::FxHashMap;
use std::collections::VecDeque;

/// Most fine cells one side of the grid spans over the mesh's extent.
const MAX_CELLS_PER_SIDE: f64 = 256.0;

/// About the most fine cells the grid holds (memory: a few tens of bytes each).
const MAX_FINE_CELLS: f64 = 1.0e6;

/// Most coarse cells per side.
const MAX_COARSE_PER_SIDE: f64 = 64.0;

/// One triangle: its first vertex and edges, f64.
#[derive(Debug, Clone, Copy)]
struct Tri {
    a: DVec3,
    ab: DVec3,
    ac: DVec3,
}

impl Tri {
    fn new(t: &[Vec3; 3]) -> Self {
        let [a, b, c] = t.map(Vec3::as_dvec3);
        Self {
            a,
            ab: b - a,
            ac: c - a,
        }
    }

    /// Distance along the line from `x` along `d` at which it crosses the triangle
    /// (Möller–Trumbore, f64; barycentrics within 1e-12 outside the edges count), if it does.
    #[inline]
    fn crossing(&self, x: DVec3, d: DVec3) -> Option<f64> {
        const EDGE: f64 = 1e-12;
        let p = d.cross(self.ac);
        let det = self.ab.dot(p);
        if det.abs() <= 1e-300 {
            return None;
        }
        let inv = 1.0 / det;
        let ax = x - self.a;
        let u = ax.dot(p) * inv;
        if !(-EDGE..=1.0 + EDGE).contains(&u) {
            return None;
        }
        let q = ax.cross(self.ab);
        let v = d.dot(q) * inv;
        if v < -EDGE || u + v > 1.0 + EDGE {
            return None;
        }
        Some(self.ac.dot(q) * inv)
    }

    /// Squared distance from `p`, mm² (in f64: in f32 the closest point of a face 10⁴ mm from the
    /// origin is off by its ulp, 0.001 mm, which a point just under the face would add).
    #[inline]
    fn distance_squared(&self, p: DVec3) -> f64 {
        let ap = p - self.a;
        (ap - closest_offset(ap, self.ab, self.ac)).length_squared()
    }
}

/// What the fine grid tells of a segment ([`SurfaceDistance::segment_hit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SegmentHit {
    /// The grid does not list every triangle the segment can reach.
    Unknown,
    /// The segment crosses no face.
    Clear,
    /// The first face crossed, at distance `t` mm.
    Face {
        /// Distance along the segment, mm.
        t: f64,
        /// The face's vertices, world mm.
        face: [Vec3; 3],
    },
}

/// The coarse grid: chessboard distances (in cells) to the nearest cell that holds surface.
#[derive(Debug, Clone)]
struct Coarse {
    lo: DVec3,
    cell_mm: f64,
    dims: [usize; 3],
    steps: Vec<u8>,
}

impl Coarse {
    fn new(triangles: &[[Vec3; 3]], lo: DVec3, extent: f64, fine_mm: f64) -> Self {
        let cell_mm = fine_mm.max(extent / MAX_COARSE_PER_SIDE);
        // One cell of margin on each side, so points just outside the mesh's box are on the grid.
        let lo = lo - DVec3::splat(cell_mm);
        let dims = [0, 1, 2].map(|_| (extent / cell_mm).ceil() as usize + 2);
        let n = dims[0] * dims[1] * dims[2];
        let index = |i: usize, j: usize, k: usize| (k * dims[1] + j) * dims[0] + i;
        let mut steps = vec![u8::MAX; n];
        let mut queue = VecDeque::new();
        let reach = cell_mm * 0.5 * 3f64.sqrt();
        let clamp = |x: f64, d: usize| (x.floor().max(0.0) as usize).min(d - 1);
        for t in triangles {
            let tri = Tri::new(t);
            let tlo = t[0].min(t[1]).min(t[2]).as_dvec3() - lo;
            let thi = t[0].max(t[1]).max(t[2]).as_dvec3() - lo;
            let a = [0, 1, 2].map(|c| clamp((tlo[c] - reach) / cell_mm, dims[c]));
            let b = [0, 1, 2].map(|c| clamp((thi[c] + reach) / cell_mm, dims[c]));
            for k in a[2]..=b[2] {
                for j in a[1]..=b[1] {
                    for i in a[0]..=b[0] {
                        let at = index(i, j, k);
                        if steps[at] == 0 {
                            continue;
                        }
                        let centre =
                            lo + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * cell_mm;
                        if tri.distance_squared(centre) <= reach * reach {
                            steps[at] = 0;
                            queue.push_back((i, j, k));
                        }
                    }
                }
            }
        }
        // Multi-source breadth-first search over the 26 neighbours: the chessboard distance.
        while let Some((i, j, k)) = queue.pop_front() {
            let next = steps[index(i, j, k)].saturating_add(1);
            for dk in -1i64..=1 {
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        let (x, y, z) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
                        if x < 0 || y < 0 || z < 0 {
                            continue;
                        }
                        let (x, y, z) = (x as usize, y as usize, z as usize);
                        if x >= dims[0] || y >= dims[1] || z >= dims[2] {
                            continue;
                        }
                        let at = index(x, y, z);
                        if steps[at] > next {
                            steps[at] = next;
                            queue.push_back((x, y, z));
                        }
                    }
                }
            }
        }
        Self {
            lo,
            cell_mm,
            dims,
            steps,
        }
    }

    /// Whether `p` lies on the grid (the mesh's bounding box and a cell around it).
    fn encloses(&self, p: DVec3) -> bool {
        let q = (p - self.lo) / self.cell_mm;
        q.min_element() >= 0.0
            && q.x < self.dims[0] as f64
            && q.y < self.dims[1] as f64
            && q.z < self.dims[2] as f64
    }

    /// A lower bound on the distance from `p` to the surface, mm (0 off the grid).
    #[inline]
    fn lower(&self, p: DVec3) -> f64 {
        let q = (p - self.lo) / self.cell_mm;
        if q.min_element() < 0.0 {
            return 0.0;
        }
        let (i, j, k) = (q.x as usize, q.y as usize, q.z as usize);
        if i >= self.dims[0] || j >= self.dims[1] || k >= self.dims[2] {
            return 0.0;
        }
        let s = self.steps[(k * self.dims[1] + j) * self.dims[0] + i];
        f64::from(s.saturating_sub(1)) * self.cell_mm
    }
}

/// Bounds on the distance to a closed mesh's surface, for "within d" queries and safe flights.
#[derive(Debug, Clone)]
pub struct SurfaceDistance {
    radius_mm: f64,
    cell_mm: f64,
    reach_mm: f64,
    triangles: Vec<Tri>,
    /// The triangles' f32 vertices, as given (the faces' identity).
    faces: Vec<[Vec3; 3]>,
    /// Per occupied fine cell, its range in `lists`.
    cells: FxHashMap<[i32; 3], (u32, u32)>,
    /// (distance of the triangle from the cell's centre in mm, triangle), nearest first.
    lists: Vec<(f32, u32)>,
    coarse: Coarse,
}

impl SurfaceDistance {
    /// The grids over `triangles` (world mm) for queries at distance `radius_mm` > 0.
    #[must_use]
    pub fn new(triangles: Vec<[Vec3; 3]>, radius_mm: f32) -> Self {
        let radius_mm = f64::from(radius_mm);
        let (lo, hi) = triangles.iter().flatten().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p.as_dvec3()), hi.max(p.as_dvec3())),
        );
        let (lo, hi) = if lo.is_finite() {
            (lo, hi)
        } else {
            (DVec3::ZERO, DVec3::ZERO)
        };
        let extent = (hi - lo).max_element().max(radius_mm);
        // Small cells list few triangles (a query tests each); the cells within R of an area A
        // number about 2A·R / h³, kept under a budget.
        let area: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(Vec3::as_dvec3);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum();
        let mut cell_mm = radius_mm.max(extent / MAX_CELLS_PER_SIDE);
        while 2.0 * area * (radius_mm + cell_mm) / cell_mm.powi(3) > MAX_FINE_CELLS {
            cell_mm *= 1.25;
        }
        let reach_mm = radius_mm + cell_mm * 0.5 * 3f64.sqrt();
        let reach2 = reach_mm * reach_mm;
        let tris: Vec<Tri> = triangles.iter().map(Tri::new).collect();
        // Per cell, (distance from its centre, triangle).
        let mut per_cell: FxHashMap<[i32; 3], Vec<(f32, u32)>> = FxHashMap::default();
        for (index, (t, tri)) in triangles.iter().zip(&tris).enumerate() {
            let tlo = t[0].min(t[1]).min(t[2]).as_dvec3() - DVec3::splat(reach_mm);
            let thi = t[0].max(t[1]).max(t[2]).as_dvec3() + DVec3::splat(reach_mm);
            let (a, b) = (cell_of(tlo, cell_mm), cell_of(thi, cell_mm));
            for i in a[0]..=b[0] {
                for j in a[1]..=b[1] {
                    for k in a[2]..=b[2] {
                        let centre = centre_of([i, j, k], cell_mm);
                        if tri.distance_squared(centre) <= reach2 {
                            per_cell
                                .entry([i, j, k])
                                .or_default()
                                .push((below(tri.distance_squared(centre).sqrt()), index as u32));
                        }
                    }
                }
            }
        }
        let mut cells = FxHashMap::default();
        let mut lists = Vec::with_capacity(per_cell.values().map(Vec::len).sum());
        for (cell, mut list) in per_cell {
            // Nearest the centre first: a query stops at the first triangle that cannot be nearer.
            list.sort_by(|a, b| a.0.total_cmp(&b.0));
            cells.insert(cell, (lists.len() as u32, list.len() as u32));
            lists.extend(list);
        }
        let coarse = Coarse::new(&triangles, lo, extent, cell_mm);
        Self {
            radius_mm,
            cell_mm,
            reach_mm,
            triangles: tris,
            faces: triangles,
            cells,
            lists,
            coarse,
        }
    }

    /// The query radius d, mm.
    #[must_use]
    pub fn radius_mm(&self) -> f64 {
        self.radius_mm
    }

    /// (lo, hi): lo ≤ the distance from `p` to the surface ≤ hi, mm, with lo = hi = the distance
    /// whenever it is at most the radius (hi is ∞ where no triangle is listed).
    #[must_use]
    #[inline]
    pub fn bounds(&self, p: DVec3) -> (f64, f64) {
        let cell = cell_of(p, self.cell_mm);
        let off_centre = (p - centre_of(cell, self.cell_mm)).length();
        let unlisted = self.reach_mm - off_centre;
        let Some(&(start, len)) = self.cells.get(&cell) else {
            return (unlisted.max(self.coarse.lower(p)), f64::INFINITY);
        };
        let mut m2 = f64::INFINITY;
        for &(from_centre, t) in &self.lists[start as usize..(start + len) as usize] {
            // |p − q| ≥ |c − q| − |p − c| for every point q of this and later triangles.
            let bound = f64::from(from_centre) - off_centre;
            if bound > 0.0 && bound * bound >= m2 {
                break;
            }
            m2 = m2.min(self.triangles[t as usize].distance_squared(p));
        }
        let m = m2.sqrt();
        let lo = if m <= unlisted {
            m
        } else {
            m.min(unlisted.max(self.coarse.lower(p)))
        };
        (lo, m)
    }

    /// The first face crossed by the segment from `x` along unit `d` within `reach_mm`, with its
    /// distance t in (`ahead_min`, `reach_mm`], passing over the face `skip`, found from the fine
    /// grid when the cell of `x` lists every triangle the segment can reach (|x − c| + reach ≤ R:
    /// a face within reach of x lies within R of c); [`SegmentHit::Unknown`] otherwise. The test is
    /// Möller–Trumbore in f64 with edges counted on both sides, so a segment through a shared edge
    /// meets a face.
    #[must_use]
    pub fn segment_hit(
        &self,
        x: DVec3,
        d: DVec3,
        reach_mm: f64,
        skip: Option<&[Vec3; 3]>,
        ahead_min: f64,
    ) -> SegmentHit {
        let cell = cell_of(x, self.cell_mm);
        let off_centre = (x - centre_of(cell, self.cell_mm)).length();
        let within = off_centre + reach_mm;
        if within > self.reach_mm {
            return SegmentHit::Unknown;
        }
        let Some(&(start, len)) = self.cells.get(&cell) else {
            return SegmentHit::Clear;
        };
        let mut best: Option<(f64, usize)> = None;
        for &(from_centre, t) in &self.lists[start as usize..(start + len) as usize] {
            if f64::from(from_centre) > within {
                break;
            }
            let index = t as usize;
            let Some(t) = self.triangles[index].crossing(x, d) else {
                continue;
            };
            if t > ahead_min
                && t <= reach_mm
                && best.is_none_or(|(b, _)| t < b)
                && skip != Some(&self.faces[index])
            {
                best = Some((t, index));
            }
        }
        match best {
            Some((t, index)) => SegmentHit::Face {
                t,
                face: self.faces[index],
            },
            None => SegmentHit::Clear,
        }
    }

    /// Whether `p` lies within the mesh's bounding box (and a margin): a point outside it is outside
    /// the closed mesh.
    #[must_use]
    pub fn encloses(&self, p: DVec3) -> bool {
        self.coarse.encloses(p)
    }

    /// True when some triangle lies within the radius of `p`.
    #[must_use]
    pub fn within(&self, p: DVec3) -> bool {
        self.bounds(p).1 <= self.radius_mm
    }

    /// Fine cells holding at least one triangle, and the triangle entries over all cells (memory).
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.cells.len(), self.lists.len())
    }
}

/// `x` ≥ 0 as an f32 no larger than it (a lower bound stays one).
fn below(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x && f > 0.0 {
        f32::from_bits(f.to_bits() - 1)
    } else {
        f
    }
}

fn cell_of(p: DVec3, h: f64) -> [i32; 3] {
    (p / h).to_array().map(floor_i32)
}

/// ⌊x⌋ for |x| < 2³¹ (cells of a mesh's grid) without a call to libm's `floor` (x86-64 before
/// SSE4.1 has no rounding instruction; the walk asks for cells at every distance query).
#[inline]
fn floor_i32(x: f64) -> i32 {
    let i = x as i32;
    i - i32::from(f64::from(i) > x)
}

fn centre_of(cell: [i32; 3], h: f64) -> DVec3 {
    (DVec3::new(f64::from(cell[0]), f64::from(cell[1]), f64::from(cell[2])) + 0.5) * h
}

/// Squared distance from `p` to the triangle `t`, mm² ([Ericson05] §5.1.5, closest point by
/// Voronoi regions).
#[must_use]
pub fn distance_squared(p: DVec3, t: &[Vec3; 3]) -> f64 {
    Tri::new(t).distance_squared(p)
}

/// The closest point of the triangle (a, a + `ab`, a + `ac`) to a + `ap`, relative to a
/// ([Ericson05] §5.1.5).
#[inline]
pub(crate) fn closest_offset(ap: DVec3, ab: DVec3, ac: DVec3) -> DVec3 {
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return DVec3::ZERO;
    }
    let bp = ap - ab;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return ab;
    }
    let cp = ap - ac;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return ac;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return ab * (d1 / (d1 - d3));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return ab + (ac - ab) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    ab * (vb * denom) + ac * (vc * denom)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// The triangles of a 1,280-triangle icosphere of radius 10 mm.
    fn sphere_10mm() -> Vec<[Vec3; 3]> {
        let mesh = crate::mesh::TriangleMesh::sphere(3);
        mesh.indices
            .iter()
            .map(|t| t.map(|i| mesh.positions[i as usize] * 10.0))
            .collect()
    }

    /// A direction from the normalised uniform point of the cube [−1, 1]³ (not uniform on the
    /// sphere; the tests only need directions of every kind).
    fn random_unit(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
        DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
        .normalize()
    }

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
            let brute = tris
                .iter()
                .any(|t| distance_squared(p.as_dvec3(), t) <= 0.04);
            assert_eq!(grid.within(p.as_dvec3()), brute, "{p}");
            inside += usize::from(brute);
        }
        assert!(inside > 1000, "the test must exercise both answers");
        // Closed form: a point above the square's interior is at its height.
        assert!((distance_squared(DVec3::new(2.0, 1.0, 0.3), &tris[0]) - 0.09).abs() < 1e-12);
        // Beyond a corner: the distance to the corner.
        let d2 = distance_squared(DVec3::new(6.0, -6.0, 0.0), &tris[0]);
        assert!((d2 - 2.0).abs() < 1e-12, "{d2}");
    }

    /// The bounds enclose the true distance (the least over all triangles) at random points in
    /// and around a closed box, and are exact within the radius; far inside, the coarse grid's
    /// bound is more than a third of the distance (it is not the trivial 0).
    #[test]
    fn bounds_enclose_the_distance_to_a_box() {
        let obj = super::super::shapes::box_obj([40.0, 30.0, 20.0]);
        let v: Vec<Vec3> = obj
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let c: Vec<f32> = l.split(' ').map(|x| x.parse().unwrap()).collect();
                Vec3::new(c[0], c[1], c[2])
            })
            .collect();
        let tris: Vec<[Vec3; 3]> = obj
            .lines()
            .filter_map(|l| l.strip_prefix("f "))
            .map(|l| {
                let i: Vec<usize> = l
                    .split(' ')
                    .map(|x| x.split("//").next().unwrap().parse().unwrap())
                    .collect();
                [v[i[0] - 1], v[i[1] - 1], v[i[2] - 1]]
            })
            .collect();
        let grid = SurfaceDistance::new(tris.clone(), 0.25);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(8);
        let mut deep = 0;
        for _ in 0..20_000 {
            let p = DVec3::new(
                rng.random_range(-22.0..22.0),
                rng.random_range(-17.0..17.0),
                rng.random_range(-12.0..12.0),
            );
            let exact = tris
                .iter()
                .map(|t| distance_squared(p, t))
                .fold(f64::INFINITY, f64::min)
                .sqrt();
            let (lo, hi) = grid.bounds(p);
            assert!(lo <= exact && exact <= hi, "{p}: {lo} {exact} {hi}");
            if exact <= 0.25 {
                assert!(hi == exact && lo == exact);
            }
            if exact > 6.0 {
                deep += 1;
                assert!(lo > exact / 3.0, "{p}: {lo} for {exact}");
            }
        }
        assert!(deep > 100);
    }

    /// The same on a curved mesh (a 1,280-triangle sphere of radius 10 mm, many triangles per
    /// cell), at points within 1 mm of its surface: the bounds enclose the brute-force distance
    /// and equal it within the radius.
    #[test]
    fn bounds_enclose_the_distance_to_a_sphere() {
        let tris = sphere_10mm();
        let grid = SurfaceDistance::new(tris.clone(), 0.25);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
        let mut within = 0;
        for _ in 0..5_000 {
            let p = random_unit(&mut rng) * rng.random_range(9.0..10.5);
            let exact = tris
                .iter()
                .map(|t| distance_squared(p, t))
                .fold(f64::INFINITY, f64::min)
                .sqrt();
            let (lo, hi) = grid.bounds(p);
            assert!(lo <= exact && exact <= hi, "{p}: {lo} {exact} {hi}");
            if exact <= 0.25 {
                within += 1;
                assert!(hi == exact && lo == exact, "{p}: {lo} {exact} {hi}");
            }
        }
        assert!(within > 500);
    }

    /// Where the grid answers a segment query, its first face is the brute-force first crossing
    /// over all triangles of a 1,280-triangle sphere (plane intersection and same-side edge tests,
    /// within 1e-9 mm), and `Clear` means no triangle is crossed within reach; segments from
    /// random points 0.05 to 0.5 mm under the surface, of random length up to 0.5 mm.
    #[test]
    fn segment_hits_match_brute_force() {
        let tris = sphere_10mm();
        let grid = SurfaceDistance::new(tris.clone(), 0.25);
        let crossing = |x: DVec3, d: DVec3, t: &[Vec3; 3]| -> Option<f64> {
            let [a, b, c] = t.map(Vec3::as_dvec3);
            let n = (b - a).cross(c - a);
            let t = n.dot(a - x) / n.dot(d);
            let p = x + d * t;
            let inside = [(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(u, v)| (v - u).cross(p - u).dot(n) >= 0.0);
            (inside && t.is_finite()).then_some(t)
        };
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(12);
        let (mut faces, mut clear) = (0, 0);
        for _ in 0..5_000 {
            let x = random_unit(&mut rng) * rng.random_range(9.5..9.95);
            let d = random_unit(&mut rng);
            let reach = rng.random_range(0.0..0.5);
            let brute = tris
                .iter()
                .filter_map(|t| crossing(x, d, t))
                .filter(|&t| t > 0.0 && t <= reach)
                .fold(f64::INFINITY, f64::min);
            match grid.segment_hit(x, d, reach, None, 1e-12) {
                SegmentHit::Unknown => {}
                SegmentHit::Clear => {
                    clear += 1;
                    assert!(brute.is_infinite(), "{x} {d} {reach}: brute {brute}");
                }
                SegmentHit::Face { t, face } => {
                    faces += 1;
                    assert!((t - brute).abs() < 1e-9, "{x} {d}: {t} vs {brute}");
                    let own = crossing(x, d, &face).unwrap();
                    assert!((own - t).abs() < 1e-9, "{own} vs {t}");
                }
            }
        }
        assert!(faces > 200 && clear > 200, "{faces} faces, {clear} clear");
    }
}
