//! Sampling warps from the unit square [0, 1)² to disks, hemispheres and cones, shared by the
//! camera's lens, the BSDFs, the lights and the environment ([pbrt] §A.5).

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, TAU};

/// Map [0, 1)² to the unit disk, area preserving (Shirley–Chiu concentric map).
#[must_use]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    Vec2::new(theta.cos(), theta.sin()) * r
}

/// Cosine-weighted direction on the +Z hemisphere (Malley's method), density cos θ / π.
#[must_use]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    Vec3::new(d.x, d.y, (1.0 - d.length_squared()).max(0.0).sqrt())
}

/// Uniform direction in the cone of half-angle θ_max around +Z, given by `one_minus_cos_max` =
/// 1 − cos θ_max (so that a cap of 10⁻⁶ sr keeps its digits in f32), density 1 / (2π (1 − cos θ_max)).
#[must_use]
pub fn uniform_cone(u: Vec2, one_minus_cos_max: f32) -> Vec3 {
    // 1 − cos θ, and sin θ = √((1 − cos θ)(1 + cos θ)), both without the cancellation of 1 − cos².
    let one_minus_cos = u.x * one_minus_cos_max;
    let sin_t = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let phi = TAU * u.y;
    Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), 1.0 - one_minus_cos)
}

/// Density of [`uniform_cone`], sr⁻¹.
#[must_use]
pub fn uniform_cone_pdf(one_minus_cos_max: f32) -> f32 {
    1.0 / (TAU * one_minus_cos_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The disk map is area preserving: the fraction of a regular grid of u that lands inside
    /// radius ½ is ¼ (to the grid's resolution, 1/n per edge: tolerance 2% at n = 200).
    #[test]
    fn concentric_disk_preserves_area() {
        let n = 200;
        let inside = (0..n * n)
            .filter(|i| {
                let u = Vec2::new(
                    ((i % n) as f32 + 0.5) / n as f32,
                    ((i / n) as f32 + 0.5) / n as f32,
                );
                concentric_disk(u).length() < 0.5
            })
            .count();
        let frac = inside as f32 / (n * n) as f32;
        assert!((frac - 0.25).abs() < 0.02 * 0.25, "{frac}");
    }

    /// Directions of the cone stay inside it and reach its edge at u.x → 1.
    #[test]
    fn uniform_cone_stays_in_the_cone() {
        let cos_max = 0.8;
        for i in 0..100 {
            let u = Vec2::new(i as f32 / 100.0, (i * 37 % 100) as f32 / 100.0);
            let w = uniform_cone(u, 1.0 - cos_max);
            assert!((w.length() - 1.0).abs() < 1e-5 && w.z >= cos_max - 1e-6);
        }
        assert!((uniform_cone(Vec2::new(1.0, 0.0), 1.0 - cos_max).z - cos_max).abs() < 1e-6);
    }
}
