//! Orthonormal shading frame built from a normal ([Duff17], "Building an Orthonormal Basis,
//! Revisited"): branchless, continuous except across the z = 0 plane, and exact for
//! normals pointing straight down, where Frisvad's 2012 version ([Fri12]) loses all precision.

use glam::Vec3;

/// A right-handed orthonormal frame: `x × y = z`, with `z` the surface normal. The BRDF works in the
/// local coordinates of this frame (+Z = normal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// First tangent (unit).
    pub x: Vec3,
    /// Second tangent (unit), `z × x`.
    pub y: Vec3,
    /// The normal (unit).
    pub z: Vec3,
}

impl Frame {
    /// Frame whose `z` is the unit normal `n` (the caller normalises; a non-unit `n` gives a
    /// non-orthonormal frame).
    #[must_use]
    pub fn from_normal(n: Vec3) -> Frame {
        // Duff et al. 2017, listing 3: the sign flip keeps 1/(sign + z) away from 1/0 for any unit n.
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let x = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let y = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { x, y, z: n }
    }

    /// World-space vector expressed in this frame's local coordinates (+Z = normal).
    #[must_use]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    /// Local vector (+Z = normal) expressed in world coordinates.
    #[must_use]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn assert_orthonormal(f: &Frame) {
        for (name, v) in [("x", f.x), ("y", f.y), ("z", f.z)] {
            assert!((v.length() - 1.0).abs() < 1e-5, "|{name}| = {}", v.length());
        }
        assert!(f.x.dot(f.y).abs() < 1e-5);
        assert!(f.x.dot(f.z).abs() < 1e-5);
        assert!(f.y.dot(f.z).abs() < 1e-5);
        // Right-handed: x × y = z.
        assert!((f.x.cross(f.y) - f.z).length() < 1e-5);
    }

    #[test]
    fn axis_normals_including_straight_down() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y] {
            assert_orthonormal(&Frame::from_normal(n));
        }
        // Signed zeros in the tangent components must not change the result's quality.
        assert_orthonormal(&Frame::from_normal(Vec3::new(-0.0, -0.0, -1.0)));
        assert_orthonormal(&Frame::from_normal(Vec3::new(-0.0, 0.0, 1.0)));
    }

    #[test]
    fn nearly_straight_down_keeps_precision() {
        // Frisvad's 2012 basis fails here (z ≈ -1 + 1e-8); Duff's sign trick does not.
        let n = Vec3::new(1e-4, -2e-4, -1.0).normalize();
        assert_orthonormal(&Frame::from_normal(n));
    }

    proptest! {
        #[test]
        fn random_normals_give_orthonormal_round_trip(
            x in -1.0f32..1.0, y in -1.0f32..1.0, z in -1.0f32..1.0,
            vx in -1.0f32..1.0, vy in -1.0f32..1.0, vz in -1.0f32..1.0,
        ) {
            let n = Vec3::new(x, y, z);
            prop_assume!(n.length() > 1e-3);
            let f = Frame::from_normal(n.normalize());
            assert_orthonormal(&f);
            let v = Vec3::new(vx, vy, vz);
            prop_assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
            prop_assert!((f.to_local(f.z) - Vec3::Z).length() < 1e-5);
        }
    }
}
