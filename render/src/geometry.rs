//! All scene triangles in world millimetres, with their shading attributes and materials, behind
//! one [`Accel`]; turns a BVH hit into a shading point.

use crate::accel::{Accel, TriHit, ray};
use crate::mesh::TriangleMesh;
use glam::{Vec2, Vec3};

/// Largest coordinate magnitude anything in a scene may have, mm (1000 km): far beyond any
/// scene, far below where f32 squares overflow (1.8e19) and the BVH build breaks down.
pub const MAX_COORD_MM: f32 = 1e9;

/// `v` scaled to unit length, or `None` when it is zero or not finite. Divides by the largest
/// component first, so vectors whose squared length overflows f32 (components above 1.8e19)
/// still normalise.
#[must_use]
pub fn unit_vector(v: Vec3) -> Option<Vec3> {
    let m = v.abs().max_element();
    if !(m.is_finite() && m > 0.0) {
        return None;
    }
    (v / m).try_normalize()
}

/// Whether every component of `v` lies within ±[`MAX_COORD_MM`].
#[must_use]
pub fn within_scene(v: Vec3) -> bool {
    v.is_finite() && v.abs().max_element() <= MAX_COORD_MM
}

/// A surface point hit by a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceHit {
    /// Distance along the ray, mm.
    pub t: f32,
    /// Position, mm (interpolated from the vertices, not o + t·d, for precision).
    pub p: Vec3,
    /// Unit geometric normal, on the side of the shading normal.
    pub ng: Vec3,
    /// Unit shading normal (interpolated vertex normals).
    pub ns: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Material index.
    pub material: u32,
    /// Triangle index.
    pub triangle: u32,
}

/// Scene triangles (world mm) and the accelerator over them.
pub struct Geometry {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    triangles: Vec<[u32; 3]>,
    materials: Vec<u32>,
    accel: Accel,
}

impl Geometry {
    /// Merge placed meshes (already in mm) with one material index each and build the BVH.
    #[must_use]
    pub fn new(meshes: Vec<(TriangleMesh, u32)>) -> Self {
        let mut g = Geometry {
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            triangles: Vec::new(),
            materials: Vec::new(),
            accel: Accel::build(&[]),
        };
        for (m, material) in meshes {
            let base = g.positions.len() as u32;
            let n = m.positions.len();
            g.uvs.extend(m.uvs.unwrap_or_else(|| vec![Vec2::ZERO; n]));
            g.positions.extend(m.positions);
            g.normals.extend(m.normals);
            g.materials
                .extend(std::iter::repeat_n(material, m.indices.len()));
            g.triangles
                .extend(m.indices.iter().map(|t| t.map(|i| i + base)));
        }
        let verts: Vec<[Vec3; 3]> = g
            .triangles
            .iter()
            .map(|t| t.map(|i| g.positions[i as usize]))
            .collect();
        g.accel = Accel::build(&verts);
        g
    }

    /// The accelerator (for custom queries such as BSSRDF probe rays).
    #[must_use]
    pub fn accel(&self) -> &Accel {
        &self.accel
    }

    /// Number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The vertices (world mm) of every triangle of material `material`.
    #[must_use]
    pub fn triangles_of(&self, material: u32) -> Vec<[Vec3; 3]> {
        self.triangles
            .iter()
            .zip(&self.materials)
            .filter(|&(_, &m)| m == material)
            .map(|(t, _)| t.map(|i| self.positions[i as usize]))
            .collect()
    }

    /// The vertices (world mm) and texture coordinates of every triangle of material `material`.
    #[must_use]
    pub fn triangles_with_uvs_of(&self, material: u32) -> Vec<([Vec3; 3], [Vec2; 3])> {
        self.triangles
            .iter()
            .zip(&self.materials)
            .filter(|&(_, &m)| m == material)
            .map(|(t, _)| {
                (
                    t.map(|i| self.positions[i as usize]),
                    t.map(|i| self.uvs[i as usize]),
                )
            })
            .collect()
    }

    /// Material index of a triangle.
    #[must_use]
    pub fn material_of(&self, triangle: u32) -> u32 {
        self.materials[triangle as usize]
    }

    /// Nearest surface along (`o`, unit `d`) within (`tmin`, `tmax`), mm.
    #[must_use]
    pub fn intersect(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<SurfaceHit> {
        self.accel
            .closest(&ray(o, d, tmin, tmax))
            .map(|h| self.surface(&h))
    }

    /// Nearest surface of material `material` along (`o`, unit `d`) within (`tmin`, `tmax`), mm
    /// (other materials' triangles are passed through).
    #[must_use]
    pub fn intersect_material(
        &self,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
        material: u32,
    ) -> Option<SurfaceHit> {
        let materials = &self.materials;
        self.accel
            .closest_where(&ray(o, d, tmin, tmax), |t| {
                materials[t as usize] == material
            })
            .map(|h| self.surface(&h))
    }

    /// The vertices of triangle `triangle`, world mm.
    #[must_use]
    pub fn triangle(&self, triangle: u32) -> [Vec3; 3] {
        self.triangles[triangle as usize].map(|i| self.positions[i as usize])
    }

    /// The texture coordinates of triangle `triangle`'s vertices.
    #[must_use]
    pub fn triangle_uvs(&self, triangle: u32) -> [Vec2; 3] {
        self.triangles[triangle as usize].map(|i| self.uvs[i as usize])
    }

    /// True when something blocks the segment from `o` along unit `d` up to `tmax`.
    #[must_use]
    pub fn occluded(&self, o: Vec3, d: Vec3, tmax: f32) -> bool {
        self.accel.occluded(&ray(o, d, 0.0, tmax))
    }

    /// The shading point of a BVH hit.
    #[must_use]
    pub fn surface(&self, h: &TriHit) -> SurfaceHit {
        let t = self.triangles[h.triangle as usize];
        let (b1, b2) = (h.bary.x, h.bary.y);
        let b0 = 1.0 - b1 - b2;
        let [p0, p1, p2] = t.map(|i| self.positions[i as usize]);
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        let mut ng = (p1 - p0).cross(p2 - p0).normalize_or(Vec3::Z);
        let [n0, n1, n2] = t.map(|i| self.normals[i as usize]);
        let ns = (n0 * b0 + n1 * b1 + n2 * b2).normalize_or(ng);
        // Vertex normals are more reliable than the winding: the geometric normal follows them.
        if ns.dot(ng) < 0.0 {
            ng = -ng;
        }
        let [u0, u1, u2] = t.map(|i| self.uvs[i as usize]);
        SurfaceHit {
            t: h.t,
            p,
            ng,
            ns,
            uv: u0 * b0 + u1 * b1 + u2 * b2,
            material: self.materials[h.triangle as usize],
            triangle: h.triangle,
        }
    }
}

/// Offset a ray origin off the surface at `p` (normal `ng`) towards direction `d`, so a secondary
/// ray does not re-hit its own triangle: a few hundred f32 ulps of the coordinates.
#[must_use]
pub fn offset_origin(p: Vec3, ng: Vec3, d: Vec3) -> Vec3 {
    let eps = 2e-5 * (1.0 + p.abs().max_element());
    if d.dot(ng) >= 0.0 {
        p + ng * eps
    } else {
        p - ng * eps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_whose_squared_length_overflows_still_normalise() {
        let d = unit_vector(Vec3::splat(3e38)).unwrap();
        assert!((d - Vec3::splat(1.0 / 3f32.sqrt())).length() < 1e-6, "{d}");
        assert_eq!(
            unit_vector(Vec3::new(0.0, -f32::MAX, 0.0)),
            Some(Vec3::NEG_Y)
        );
        assert_eq!(unit_vector(Vec3::ZERO), None);
        assert_eq!(unit_vector(Vec3::new(f32::NAN, 1.0, 0.0)), None);
        assert_eq!(unit_vector(Vec3::new(f32::INFINITY, 1.0, 0.0)), None);
        assert!(within_scene(Vec3::splat(MAX_COORD_MM)));
        assert!(!within_scene(Vec3::new(0.0, 0.0, 2e19)));
    }
}
