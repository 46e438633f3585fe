//! The nearest surface point of a closed mesh to any point inside it, with its texture
//! coordinates (docs/physics.md §19.1): where the volumetric walk reads a heterogeneous skin's
//! chromophores. A bounding-volume hierarchy over the triangles answers by branch and bound
//! (children visited nearest box first, a box skipped once it is farther than the best triangle);
//! the triangle distance is the walk's own ([Ericson05] §5.1.5, `super::distance`).

use super::distance::closest_offset;
use glam::{DVec3, Vec2, Vec3};

/// Most triangles in a leaf.
const LEAF: usize = 4;

#[derive(Debug, Clone, Copy)]
struct Tri {
    a: DVec3,
    ab: DVec3,
    ac: DVec3,
    uv: [Vec2; 3],
}

impl Tri {
    /// The texture coordinates at the point `off` from the first vertex (on the triangle).
    #[inline]
    fn uv_at(&self, off: DVec3) -> Vec2 {
        let (v, w) = barycentric(off, self.ab, self.ac);
        self.uv[0] * (1.0 - v - w) as f32 + self.uv[1] * v as f32 + self.uv[2] * w as f32
    }
}

/// A point x₀, its nearest triangle and the distance d₂ from x₀ to every other triangle, mm
/// ([`NearestSurface::uv_anchored`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearestAnchor {
    x0: DVec3,
    tri: u32,
    other_mm: f64,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: first triangle and count; inner: index of the first child (the second follows it).
    start: u32,
    count: u32,
}

/// Triangles (world mm) with their vertices' texture coordinates, for nearest-point queries.
#[derive(Debug, Clone)]
pub struct NearestSurface {
    tris: Vec<Tri>,
    nodes: Vec<Node>,
}

impl NearestSurface {
    /// The hierarchy over `triangles`, each with its vertices' texture coordinates.
    #[must_use]
    pub fn new(triangles: &[([Vec3; 3], [Vec2; 3])]) -> Self {
        let mut tris: Vec<Tri> = triangles
            .iter()
            .map(|(t, uv)| {
                let [a, b, c] = t.map(Vec3::as_dvec3);
                Tri {
                    a,
                    ab: b - a,
                    ac: c - a,
                    uv: *uv,
                }
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * tris.len() / LEAF + 1);
        nodes.push(Node {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            start: 0,
            count: tris.len() as u32,
        });
        let mut todo = vec![0usize];
        while let Some(n) = todo.pop() {
            let (start, count) = (nodes[n].start as usize, nodes[n].count as usize);
            let part = &mut tris[start..start + count];
            let (lo, hi) = bounds(part);
            nodes[n].lo = lo;
            nodes[n].hi = hi;
            if count <= LEAF {
                continue;
            }
            let centre = |t: &Tri| t.a + (t.ab + t.ac) / 3.0;
            let axis = (hi - lo).max_position();
            part.sort_by(|x, y| centre(x)[axis].total_cmp(&centre(y)[axis]));
            let half = count / 2;
            let first = nodes.len();
            nodes[n] = Node {
                lo,
                hi,
                start: first as u32,
                count: 0,
            };
            for (s, c) in [(start, half), (start + half, count - half)] {
                nodes.push(Node {
                    lo: DVec3::ZERO,
                    hi: DVec3::ZERO,
                    start: s as u32,
                    count: c as u32,
                });
                todo.push(nodes.len() - 1);
            }
        }
        Self { tris, nodes }
    }

    /// The texture coordinates of the surface point nearest `p` (barycentric on its triangle);
    /// `None` without triangles.
    #[must_use]
    pub fn uv(&self, p: DVec3) -> Option<Vec2> {
        self.uv_from(p, &mut None)
    }

    /// [`NearestSurface::uv`], starting from triangle `hint` (the nearest one of a point close
    /// by, updated to this point's): its distance bounds the search from the start, so most of
    /// the hierarchy is skipped. The answer does not depend on the hint.
    #[must_use]
    pub fn uv_from(&self, p: DVec3, hint: &mut Option<u32>) -> Option<Vec2> {
        let (_, i, off) = self.nearest(p, hint)?;
        Some(self.tris[i].uv_at(off))
    }

    /// [`NearestSurface::uv`], reusing `anchor` (from an earlier query near `p`) when it proves
    /// its triangle is still the nearest: at x₀ every other triangle lay at least d₂ away, so
    /// at p each lies at least d₂ − |p − x₀| away (the distance to a set is 1-Lipschitz), and
    /// the anchor's triangle, at distance d from p, is the nearest when d < d₂ − |p − x₀|.
    /// Otherwise a full search at p renews the anchor. The answer is that of
    /// [`NearestSurface::uv`]; a walk's next collision a few hundredths of a mm away mostly
    /// costs one point–triangle distance.
    #[must_use]
    #[inline]
    pub fn uv_anchored(&self, p: DVec3, anchor: &mut Option<NearestAnchor>) -> Option<Vec2> {
        if let Some(uv) = self.uv_if_anchored(p, anchor.as_ref()) {
            return Some(uv);
        }
        let (i, off, other2) = self.nearest_two(p, anchor.map(|a| a.tri))?;
        *anchor = Some(NearestAnchor {
            x0: p,
            tri: i as u32,
            other_mm: other2.sqrt(),
        });
        Some(self.tris[i].uv_at(off))
    }

    /// The texture coordinates of the surface point nearest `p` when `anchor` proves its
    /// triangle is the nearest ([`NearestSurface::uv_anchored`]).
    #[must_use]
    #[inline]
    pub fn uv_if_anchored(&self, p: DVec3, anchor: Option<&NearestAnchor>) -> Option<Vec2> {
        let a = anchor?;
        let t = &self.tris[a.tri as usize];
        let off = closest_offset(p - t.a, t.ab, t.ac);
        ((p - t.a - off).length() + p.distance(a.x0) < a.other_mm).then(|| t.uv_at(off))
    }

    /// The nearest triangle to `p`, the offset of its nearest point from its first vertex, and
    /// the squared distance to the nearest of the other triangles (∞ with one triangle),
    /// starting from triangle `hint`.
    fn nearest_two(&self, p: DVec3, hint: Option<u32>) -> Option<(usize, DVec3, f64)> {
        // (squared distance, triangle, offset) of the nearest; squared distance of the next.
        let mut best = (f64::INFINITY, usize::MAX, DVec3::ZERO);
        let mut second = f64::INFINITY;
        let hint = hint.map(|i| i as usize).filter(|&i| i < self.tris.len());
        if let Some(i) = hint {
            let t = &self.tris[i];
            let off = closest_offset(p - t.a, t.ab, t.ac);
            best = ((p - t.a - off).length_squared(), i, off);
        }
        // A node farther than the second nearest changes neither.
        self.descend(p, second, |i, off, d2| {
            if Some(i) != hint {
                if d2 < best.0 {
                    second = best.0;
                    best = (d2, i, off);
                } else if d2 < second {
                    second = d2;
                }
            }
            second
        });
        (best.1 != usize::MAX).then_some((best.1, best.2, second))
    }

    /// Visit the triangles depth first, the nearer child first, skipping every node whose box is
    /// no nearer than the cutoff: `cutoff` to start with, then what `visit(triangle, offset of its
    /// nearest point, squared distance)` returns after each triangle.
    fn descend(&self, p: DVec3, mut cutoff: f64, mut visit: impl FnMut(usize, DVec3, f64) -> f64) {
        // The hierarchy halves each node, so a traversal holds at most one node per level and
        // one more: 64 cover any mesh (no allocation per query).
        let mut stack = [0usize; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let n = stack[top];
            let node = self.nodes[n];
            if box_distance_squared(p, node.lo, node.hi) >= cutoff {
                continue;
            }
            if self.is_leaf(n) {
                let (s, c) = (node.start as usize, node.count as usize);
                for (i, t) in self.tris[s..s + c].iter().enumerate() {
                    let off = closest_offset(p - t.a, t.ab, t.ac);
                    cutoff = visit(s + i, off, (p - t.a - off).length_squared());
                }
                continue;
            }
            let (a, b) = (node.start as usize, node.start as usize + 1);
            let da = box_distance_squared(p, self.nodes[a].lo, self.nodes[a].hi);
            let db = box_distance_squared(p, self.nodes[b].lo, self.nodes[b].hi);
            // The nearer child is popped first.
            let (far, near) = if da <= db { (b, a) } else { (a, b) };
            stack[top] = far;
            stack[top + 1] = near;
            top += 2;
        }
    }

    /// The distance from `p` to the surface, mm; `None` without triangles.
    #[must_use]
    pub fn distance(&self, p: DVec3) -> Option<f64> {
        self.nearest(p, &mut None).map(|(d2, _, _)| d2.sqrt())
    }

    /// The squared distance to the nearest triangle, its index and the offset of its nearest
    /// point from its first vertex; `hint` as in [`NearestSurface::uv_from`].
    fn nearest(&self, p: DVec3, hint: &mut Option<u32>) -> Option<(f64, usize, DVec3)> {
        let mut best = (f64::INFINITY, None::<(usize, DVec3)>);
        if let Some(i) = hint.map(|i| i as usize).filter(|&i| i < self.tris.len()) {
            let t = &self.tris[i];
            let off = closest_offset(p - t.a, t.ab, t.ac);
            best = ((p - t.a - off).length_squared(), Some((i, off)));
        }
        self.descend(p, best.0, |i, off, d2| {
            if d2 < best.0 {
                best = (d2, Some((i, off)));
            }
            best.0
        });
        let (i, off) = best.1?;
        *hint = Some(i as u32);
        Some((best.0, i, off))
    }

    fn is_leaf(&self, n: usize) -> bool {
        let node = &self.nodes[n];
        node.count > 0 || node.start == 0 && self.nodes.len() == 1
    }

    /// Every triangle within `radius_mm` of `p`: (its distance from `p` in mm, rounded down to
    /// f32, and its index), appended to `out`.
    pub fn triangles_within(&self, p: DVec3, radius_mm: f64, out: &mut Vec<(f32, u32)>) {
        if self.tris.is_empty() {
            return;
        }
        let r2 = radius_mm * radius_mm;
        // The traversal skips boxes no nearer than its cutoff; the next double above r² keeps
        // those at exactly the radius, as the triangles at it are kept.
        let cutoff = r2.next_up();
        self.descend(p, cutoff, |i, _, d2| {
            if d2 <= r2 {
                out.push((round_down(d2.sqrt()), i as u32));
            }
            cutoff
        });
    }

    /// The box [u₀, u₁] × [v₀, v₁] of triangle `index`'s texture coordinates (numbered as
    /// [`NearestSurface::triangles_within`] numbers them).
    #[must_use]
    pub fn uv_box(&self, index: u32) -> ([f32; 2], [f32; 2]) {
        let t = &self.tris[index as usize];
        let lo = t.uv[0].min(t.uv[1]).min(t.uv[2]);
        let hi = t.uv[0].max(t.uv[1]).max(t.uv[2]);
        ([lo.x, hi.x], [lo.y, hi.y])
    }

    /// A box [u₀, u₁] × [v₀, v₁] holding the texture coordinates of every point of triangle
    /// `index` (as [`NearestSurface::triangles_within`] numbers them) within `radius_mm` of `p`:
    /// that part lies in the disc where the ball cuts the triangle's plane, whose image under the
    /// triangle's affine texture map is an ellipse, boxed by its centre ± the disc's radius times
    /// the length of each coordinate's gradient; the box is clipped to the triangle's own.
    #[must_use]
    pub fn uv_box_within(&self, index: u32, p: DVec3, radius_mm: f64) -> ([f32; 2], [f32; 2]) {
        let t = &self.tris[index as usize];
        let whole = self.uv_box(index);
        let n = t.ab.cross(t.ac);
        let (d00, d01, d11) = (t.ab.dot(t.ab), t.ab.dot(t.ac), t.ac.dot(t.ac));
        let det = d00 * d11 - d01 * d01;
        if !(n.length_squared() > 0.0 && det > 1e-12 * d00 * d11) {
            return whole;
        }
        let n = n.normalize();
        let height = n.dot(p - t.a);
        let disc = radius_mm * radius_mm - height * height;
        if disc < 0.0 {
            return whole;
        }
        let rho = disc.sqrt();
        // Gradients of the barycentrics v, w (p − a = v·ab + w·ac) within the plane.
        let grad_v = (t.ab * d11 - t.ac * d01) / det;
        let grad_w = (t.ac * d00 - t.ab * d01) / det;
        let foot = p - n * height - t.a;
        let (v, w) = (grad_v.dot(foot), grad_w.dot(foot));
        let (du1, du2) = (
            (t.uv[1] - t.uv[0]).as_dvec2(),
            (t.uv[2] - t.uv[0]).as_dvec2(),
        );
        let centre = t.uv[0].as_dvec2() + du1 * v + du2 * w;
        let half = |k: usize| (grad_v * du1[k] + grad_w * du2[k]).length() * rho;
        let clip = |k: usize, whole: [f32; 2]| {
            // f32 rounding of the box kept outward; the texel margin covers the lookups'.
            let (a, b) = (centre[k] - half(k), centre[k] + half(k));
            [
                (a as f32).max(whole[0]).min(whole[1]),
                (b as f32).min(whole[1]).max(whole[0]),
            ]
        };
        (clip(0, whole.0), clip(1, whole.1))
    }

    /// [`NearestSurface::uv`] for a point `p` whose nearest triangle is among `list` ((distance
    /// from a centre c, triangle), nearest c first; `p` lies `off_centre_mm` from c, and every
    /// triangle not listed lies farther than `unlisted_mm` from `p`), searched nearest first
    /// (|p − q| ≥ |c − q| − |p − c| stops it); the search renews `anchor`.
    #[must_use]
    #[inline]
    pub fn uv_listed(
        &self,
        p: DVec3,
        list: &[(f32, u32)],
        off_centre_mm: f64,
        unlisted_mm: f64,
        anchor: &mut Option<NearestAnchor>,
    ) -> Option<Vec2> {
        let mut best = (f64::INFINITY, usize::MAX, DVec3::ZERO);
        let mut second = unlisted_mm.max(0.0).powi(2);
        for &(from_centre, i) in list {
            let bound = f64::from(from_centre) - off_centre_mm;
            if bound > 0.0 && bound * bound >= second {
                break;
            }
            let t = &self.tris[i as usize];
            let off = closest_offset(p - t.a, t.ab, t.ac);
            let d2 = (p - t.a - off).length_squared();
            if d2 < best.0 {
                second = second.min(best.0);
                best = (d2, i as usize, off);
            } else if d2 < second {
                second = d2;
            }
        }
        if best.1 == usize::MAX {
            return self.uv_anchored(p, anchor);
        }
        *anchor = Some(NearestAnchor {
            x0: p,
            tri: best.1 as u32,
            other_mm: second.sqrt(),
        });
        Some(self.tris[best.1].uv_at(best.2))
    }
}

/// The largest f32 at most `x`.
fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x {
        f32::from_bits(y.to_bits() - 1).max(0.0)
    } else {
        y
    }
}

/// (v, w) with `off` = v·ab + w·ac (off lies in the triangle's plane); (0, 0) for a degenerate
/// triangle.
fn barycentric(off: DVec3, ab: DVec3, ac: DVec3) -> (f64, f64) {
    let (d00, d01, d11) = (ab.dot(ab), ab.dot(ac), ac.dot(ac));
    let (d20, d21) = (off.dot(ab), off.dot(ac));
    let det = d00 * d11 - d01 * d01;
    if det.abs() <= f64::EPSILON * d00 * d11 {
        return (0.0, 0.0);
    }
    let v = (d11 * d20 - d01 * d21) / det;
    let w = (d00 * d21 - d01 * d20) / det;
    (v.clamp(0.0, 1.0), w.clamp(0.0, 1.0 - v.clamp(0.0, 1.0)))
}

fn bounds(tris: &[Tri]) -> (DVec3, DVec3) {
    tris.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), t| {
            let (b, c) = (t.a + t.ab, t.a + t.ac);
            (lo.min(t.a).min(b).min(c), hi.max(t.a).max(b).max(c))
        },
    )
}

fn box_distance_squared(p: DVec3, lo: DVec3, hi: DVec3) -> f64 {
    let d = (lo - p).max(p - hi).max(DVec3::ZERO);
    d.length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// On a 1,280-triangle sphere of radius 10 mm with uv = (x, y) / 10 of each vertex, the
    /// nearest point's uv equals that of the brute-force nearest triangle at random points inside
    /// (exact up to f32 rounding, 1e-5: the same distance function, and ties have one point), and
    /// a point just under a vertex reads that vertex's uv.
    #[test]
    fn nearest_uv_agrees_with_brute_force() {
        let mesh = crate::mesh::TriangleMesh::sphere(3);
        let tris: Vec<([Vec3; 3], [Vec2; 3])> = mesh
            .indices
            .iter()
            .map(|t| {
                let v = t.map(|i| mesh.positions[i as usize] * 10.0);
                (v, v.map(|p| Vec2::new(p.x, p.y) / 10.0))
            })
            .collect();
        let near = NearestSurface::new(&tris);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(4);
        for _ in 0..2000 {
            let p = DVec3::new(
                rng.random_range(-9.5..9.5),
                rng.random_range(-9.5..9.5),
                rng.random_range(-9.5..9.5),
            );
            let (i, _) = tris
                .iter()
                .map(|(t, _)| super::super::distance::distance_squared(p, t))
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |b, (i, d)| if d < b.1 { (i, d) } else { b },
                );
            let one = NearestSurface::new(&tris[i..=i]);
            let (got, want) = (near.uv(p).unwrap(), one.uv(p).unwrap());
            assert!((got - want).length() < 1e-5, "{p}: {got} vs {want}");
            // From any hint, the same point.
            let mut hint = Some(rng.random_range(0..tris.len() as u32));
            assert_eq!(near.uv_from(p, &mut hint), Some(got), "{p}");
        }
        let v0 = tris[0].0[0];
        // 1 µm under the vertex: the nearest point lies within about 1 µm of it, so its uv within
        // the uv slope (0.1 per mm) times that, 1e-4.
        let uv = near.uv(v0.as_dvec3() * 0.9999).unwrap();
        assert!(
            (uv - tris[0].1[0]).length() < 2e-4,
            "{uv} vs {}",
            tris[0].1[0]
        );
        assert!(NearestSurface::new(&[]).uv(DVec3::ZERO).is_none());
    }
}
