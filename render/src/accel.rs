//! One obvhs CWBVH over every triangle of the scene: closest hit, occlusion (shadow rays) and
//! all-hits queries (BSSRDF probe segments).
//!
//! The triangles are kept as `RtTriangle`s in the BVH's leaf order, so the traversal closure
//! indexes them directly; barycentrics come from `RtTriangle::compute_barycentric`
//! (obvhs 0.4's `Triangle::compute_barycentric` is scaled wrongly, see docs/crates.md §3).
//!
//! The tests spell out their triangles and queries in full (the random-ray tests share their setup
//! through `soup_and_rays` and differ in what they check) so that each states the whole case it
//! checks.

use glam::{Vec2, Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    cwbvh::{CwBvh, builder::build_cwbvh_from_tris},
    ray::{Ray, RayHit},
    rt_triangle::RtTriangle,
    triangle::Triangle,
};
use std::time::Duration;

/// The CWBVH build: obvhs's `very_slow_build` (reinsertion over every node) without its spatial
/// pre-splits, so each triangle is in exactly one leaf (the all-hits query reports it once). Its
/// traversal costs fewer instructions per path than `medium_build`'s for a slower build
/// (docs/benchmarks-archive.md, "Image noise: traversal, allocation and profile lookups").
pub const BVH_BUILD: BvhBuildParams = BvhBuildParams {
    pre_split: false,
    ..BvhBuildParams::very_slow_build()
};

/// Distance below which obvhs 0.4's CWBVH traversal passes over hits, mm: its node test clamps the
/// ray's entry distance to 10⁻⁴ scene units (`cwbvh::node::EPSILON`), so a node the ray leaves
/// sooner is skipped. A ray that must see a surface closer than this starts further back.
pub const BVH_MIN_T_MM: f32 = 1e-4;

/// A ray–triangle hit: distance, triangle id (index in the scene's triangle list) and barycentrics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriHit {
    /// Distance along the (unit) ray direction, mm.
    pub t: f32,
    /// Index of the triangle in the list the accelerator was built from.
    pub triangle: u32,
    /// Barycentric weights (w1, w2) of vertices 1 and 2; vertex 0 has 1 − w1 − w2.
    pub bary: Vec2,
}

/// The bounding volume hierarchy over all scene triangles.
pub struct Accel {
    bvh: CwBvh,
    /// Triangles in leaf order (`leaf_tris[i]` is triangle `bvh.primitive_indices[i]`).
    leaf_tris: Vec<RtTriangle>,
}

/// A ray from `origin` along unit `dir`, valid for t in [`tmin`, `tmax`] (mm).
#[must_use]
pub fn ray(origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Ray {
    // `+ 0.0` turns −0.0 direction components into +0.0: obvhs 0.4's CWBVH traversal misses
    // axis-aligned rays whose zero components are −0.0 (1/−0 = −∞ picks the wrong octant).
    Ray::new(
        Vec3A::from(origin),
        Vec3A::from(dir + Vec3::ZERO),
        tmin,
        tmax,
    )
}

impl Accel {
    /// Build a CWBVH ([`BVH_BUILD`]) over `triangles`, given as vertex triples.
    #[must_use]
    pub fn build(triangles: &[[Vec3; 3]]) -> Self {
        let tris: Vec<Triangle> = triangles
            .iter()
            .map(|t| Triangle {
                v0: t[0].into(),
                v1: t[1].into(),
                v2: t[2].into(),
            })
            .collect();
        let bvh = build_cwbvh_from_tris(&tris, BVH_BUILD, &mut Duration::default());
        let leaf_tris = bvh
            .primitive_indices
            .iter()
            .map(|&i| RtTriangle::from(&tris[i as usize]))
            .collect();
        Self { bvh, leaf_tris }
    }

    /// Number of triangles.
    #[must_use]
    pub fn len(&self) -> usize {
        self.leaf_tris.len()
    }

    /// True when built over no triangles.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.leaf_tris.is_empty()
    }

    /// Nearest hit in [tmin, tmax], if any.
    #[must_use]
    pub fn closest(&self, ray: &Ray) -> Option<TriHit> {
        self.closest_where(ray, |_| true)
    }

    /// Nearest hit in [tmin, tmax] among the triangles `keep` accepts (by their index in the list
    /// the accelerator was built from), if any.
    #[must_use]
    pub fn closest_where(&self, ray: &Ray, keep: impl Fn(u32) -> bool) -> Option<TriHit> {
        if self.leaf_tris.is_empty() {
            return None;
        }
        let mut hit = RayHit::none();
        let tris = &self.leaf_tris;
        let ids = &self.bvh.primitive_indices;
        if self.bvh.ray_traverse(*ray, &mut hit, |r, i| {
            if keep(ids[i]) {
                tris[i].intersect(r)
            } else {
                f32::INFINITY
            }
        }) {
            let leaf = hit.primitive_id as usize;
            Some(TriHit {
                t: hit.t,
                triangle: self.bvh.primitive_indices[leaf],
                bary: tris[leaf].compute_barycentric(ray),
            })
        } else {
            None
        }
    }

    /// True when anything lies on the ray within [tmin, tmax] (early exit).
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.leaf_tris.is_empty() {
            return false;
        }
        let tris = &self.leaf_tris;
        // `ray_traverse_miss` returns true when nothing was hit.
        !self
            .bvh
            .ray_traverse_miss(*ray, |r, i| tris[i].intersect(r))
    }

    /// Call `f` for every triangle the segment [tmin, tmax] crosses, in no particular order
    /// (BSSRDF probe rays). The intersection test is not watertight at shared edges: callers
    /// counting hits should merge hits at nearly equal t (docs/crates.md §3, gotcha 5).
    pub fn for_each_hit(&self, ray: &Ray, mut f: impl FnMut(TriHit)) {
        if self.leaf_tris.is_empty() {
            return;
        }
        let tris = &self.leaf_tris;
        let ids = &self.bvh.primitive_indices;
        self.bvh.ray_traverse_anyhit(*ray, |r, i| {
            let t = tris[i].intersect(r);
            if t.is_finite() {
                f(TriHit {
                    t,
                    triangle: ids[i],
                    bary: tris[i].compute_barycentric(r),
                });
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn random_soup(n: usize, rng: &mut Xoshiro256PlusPlus) -> Vec<[Vec3; 3]> {
        (0..n)
            .map(|_| {
                let c = Vec3::new(rng.random(), rng.random(), rng.random()) * 10.0;
                std::array::from_fn(|_| {
                    c + (Vec3::new(rng.random(), rng.random(), rng.random()) - Vec3::splat(0.5))
                        * 2.0
                })
            })
            .collect()
    }

    fn random_dir(rng: &mut Xoshiro256PlusPlus) -> Vec3 {
        loop {
            let v = Vec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - Vec3::ONE;
            if (0.01..1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }

    /// A 2000-triangle soup from `seed`, its BVH, and 10,000 random rays (origin, direction) from
    /// a box a little larger than the soup's.
    fn soup_and_rays(seed: u64) -> (Vec<[Vec3; 3]>, Accel, Vec<(Vec3, Vec3)>) {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let tris = random_soup(2000, &mut rng);
        let accel = Accel::build(&tris);
        let rays = (0..10_000)
            .map(|_| {
                let o =
                    Vec3::new(rng.random(), rng.random(), rng.random()) * 14.0 - Vec3::splat(2.0);
                (o, random_dir(&mut rng))
            })
            .collect();
        (tris, accel, rays)
    }

    fn brute_force(tris: &[[Vec3; 3]], r: &Ray) -> Option<(f32, usize)> {
        tris.iter()
            .enumerate()
            .map(|(i, t)| {
                (
                    RtTriangle::new(t[0].into(), t[1].into(), t[2].into()).intersect(r),
                    i,
                )
            })
            .filter(|(t, _)| t.is_finite())
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// Closest hits agree with testing every triangle, on 10,000 random rays.
    #[test]
    fn closest_hit_matches_brute_force() {
        let (tris, accel, rays) = soup_and_rays(6);
        let mut hits = 0;
        for (o, d) in rays {
            let r = ray(o, d, 0.0, f32::INFINITY);
            let bvh = accel.closest(&r);
            let brute = brute_force(&tris, &r);
            match (bvh, brute) {
                (None, None) => {}
                (Some(h), Some((t, i))) => {
                    hits += 1;
                    assert!((h.t - t).abs() <= 1e-4 * t.max(1.0), "t {} vs {t}", h.t);
                    // A different triangle is acceptable only at an exact tie in t.
                    if h.triangle as usize != i {
                        assert!((h.t - t).abs() < 1e-6);
                    }
                    // The barycentric point lies on the ray.
                    let [a, b, c] = tris[h.triangle as usize];
                    let p = a * (1.0 - h.bary.x - h.bary.y) + b * h.bary.x + c * h.bary.y;
                    let q = o + Vec3::from(r.direction) * h.t;
                    assert!((p - q).length() < 1e-3, "{p} vs {q}");
                }
                (a, b) => panic!("bvh {a:?} brute {b:?}"),
            }
        }
        assert!(
            hits > 4000,
            "only {hits} hits: the test would not test much"
        );
    }

    /// Axis-aligned rays with −0.0 components hit a flat quad (obvhs misses them unless the
    /// direction is canonicalised in `ray`).
    #[test]
    fn negative_zero_directions_hit() {
        let q = [
            [
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
            ],
            [
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
            ],
        ];
        let accel = Accel::build(&q);
        let dir = -Vec3::Z; // (−0, −0, −1)
        let h = accel.closest(&ray(Vec3::new(0.3, -0.2, 1.0), dir, 0.0, f32::INFINITY));
        assert!(h.is_some_and(|h| (h.t - 1.0).abs() < 1e-6), "{h:?}");
        let mut n = 0;
        accel.for_each_hit(&ray(Vec3::new(0.3, -0.2, 1.0), dir, 0.0, 2.0), |_| n += 1);
        assert_eq!(n, 1);
    }

    /// A shadow ray is blocked exactly when its length exceeds the closest-hit distance.
    #[test]
    fn shadow_rays_agree_with_closest_hit() {
        let (_, accel, rays) = soup_and_rays(7);
        let mut checked = 0;
        for (o, d) in rays {
            let inf = ray(o, d, 0.0, f32::INFINITY);
            let Some(h) = accel.closest(&inf) else {
                assert!(!accel.occluded(&inf));
                continue;
            };
            checked += 1;
            assert!(accel.occluded(&ray(o, d, 0.0, h.t * 1.001)));
            assert!(!accel.occluded(&ray(o, d, 0.0, h.t * 0.999)));
            // All-hits sees the closest hit too.
            let mut nearest = f32::INFINITY;
            accel.for_each_hit(&inf, |x| nearest = nearest.min(x.t));
            assert!((nearest - h.t).abs() <= 1e-5 * h.t.max(1.0));
        }
        assert!(checked > 4000);
    }
}
