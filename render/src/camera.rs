//! A perspective camera with an optional thin lens (depth of field), in scene millimetres.

use crate::error::RenderError;
use crate::geometry::{MAX_COORD_MM, unit_vector, within_scene};
use glam::{Vec2, Vec3};

/// A validated perspective camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    position_mm: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    /// tan(vertical fov / 2).
    tan_half_fov: f32,
    /// Lens radius, mm (0 = pinhole).
    lens_radius_mm: f32,
    focus_distance_mm: f32,
}

impl Camera {
    /// A camera at `position_mm` looking at `look_at_mm`, `up` roughly upwards, vertical field of
    /// view `fov_deg` in (0, 180), lens aperture diameter `aperture_mm` ≥ 0 focused at
    /// `focus_distance_mm` (None = the look-at distance).
    pub fn new(
        position_mm: Vec3,
        look_at_mm: Vec3,
        up: Vec3,
        fov_deg: f32,
        aperture_mm: f32,
        focus_distance_mm: Option<f32>,
    ) -> Result<Self, RenderError> {
        let bad = |name: &'static str, value: String, range: &'static str| RenderError::Setting {
            name,
            value,
            range,
        };
        for (name, p) in [
            ("camera.position_mm", position_mm),
            ("camera.look_at_mm", look_at_mm),
        ] {
            if !within_scene(p) {
                return Err(bad(name, format!("{p}"), "points within ±1e9 mm"));
            }
        }
        let to = look_at_mm - position_mm;
        let Some(forward) = unit_vector(to) else {
            return Err(bad(
                "camera.look_at_mm",
                format!("{look_at_mm}"),
                "a finite point different from camera.position_mm",
            ));
        };
        let right = unit_vector(up)
            .map(|u| forward.cross(u))
            .filter(|r| r.length() >= 1e-6)
            .ok_or_else(|| {
                bad(
                    "camera.up",
                    format!("{up}"),
                    "a finite direction not parallel to the view",
                )
            })?
            .normalize();
        if !(fov_deg > 0.0 && fov_deg < 180.0) {
            return Err(bad(
                "camera.fov_deg",
                fov_deg.to_string(),
                "(0, 180) degrees",
            ));
        }
        if !(aperture_mm.is_finite() && aperture_mm >= 0.0) {
            return Err(bad(
                "camera.aperture_mm",
                aperture_mm.to_string(),
                "[0, ∞) mm",
            ));
        }
        let focus = focus_distance_mm.unwrap_or(to.length());
        if !(focus.is_finite() && focus > 0.0 && focus <= 2.0 * MAX_COORD_MM) {
            return Err(bad(
                "camera.focus_distance_mm",
                focus.to_string(),
                "(0, 2e9] mm",
            ));
        }
        Ok(Self {
            position_mm,
            forward,
            right,
            up: right.cross(forward),
            tan_half_fov: (fov_deg.to_radians() / 2.0).tan(),
            lens_radius_mm: aperture_mm / 2.0,
            focus_distance_mm: focus,
        })
    }

    /// Primary ray (origin mm, unit direction) through film position `ndc` ∈ [0, 1]² (x right,
    /// y down, as image rows) for an image of aspect `width / height`; `lens` ∈ [0, 1)² picks the
    /// point on the lens.
    #[must_use]
    pub fn generate_ray(&self, ndc: Vec2, aspect: f32, lens: Vec2) -> (Vec3, Vec3) {
        let sx = (2.0 * ndc.x - 1.0) * self.tan_half_fov * aspect;
        let sy = (1.0 - 2.0 * ndc.y) * self.tan_half_fov;
        let dir = (self.forward + self.right * sx + self.up * sy).normalize();
        if self.lens_radius_mm == 0.0 {
            return (self.position_mm, dir);
        }
        // Thin lens: all rays through the lens meet on the plane of focus.
        let focus_point = self.position_mm + dir * (self.focus_distance_mm / dir.dot(self.forward));
        let d = crate::sampling::concentric_disk(lens) * self.lens_radius_mm;
        let origin = self.position_mm + self.right * d.x + self.up * d.y;
        (origin, (focus_point - origin).normalize())
    }

    /// Whether rays start from a lens of finite aperture (the `lens` of [`Camera::generate_ray`]
    /// is read) rather than from a pinhole.
    #[must_use]
    pub fn has_lens(&self) -> bool {
        self.lens_radius_mm != 0.0
    }

    /// Angle one pixel subtends at the image centre for an image `height` pixels tall, radians:
    /// 2 tan(fov/2) / height (the pixel footprint is this times the distance).
    #[must_use]
    pub fn pixel_angle_rad(&self, height: usize) -> f32 {
        2.0 * self.tan_half_fov / height.max(1) as f32
    }

    /// Camera position, mm.
    #[must_use]
    pub fn position_mm(&self) -> Vec3 {
        self.position_mm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_target_and_corners_match_fov() {
        let eye = Vec3::new(0.0, 0.0, 100.0);
        let c = Camera::new(eye, Vec3::ZERO, Vec3::Y, 90.0, 0.0, None).unwrap();
        let (o, d) = c.generate_ray(Vec2::splat(0.5), 1.0, Vec2::ZERO);
        assert_eq!(o, eye);
        assert!((d - Vec3::NEG_Z).length() < 1e-6);
        // Top edge of a 90° vertical fov is 45° up.
        let (_, d) = c.generate_ray(Vec2::new(0.5, 0.0), 1.0, Vec2::ZERO);
        assert!((d.y - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-5, "{d}");
    }

    fn error_key(r: Result<Camera, RenderError>) -> &'static str {
        match r {
            Err(RenderError::Setting { name, .. }) => name,
            other => panic!("expected a setting error, got {other:?}"),
        }
    }

    #[test]
    fn camera_position_that_overflows_is_blamed_on_the_position_not_up() {
        let far = Vec3::new(3e38, 0.0, 0.0);
        let r = Camera::new(far, Vec3::ZERO, Vec3::Y, 40.0, 0.0, None);
        assert_eq!(error_key(r), "camera.position_mm");
        let r = Camera::new(Vec3::Z, Vec3::splat(-3e38), Vec3::Y, 40.0, 0.0, None);
        assert_eq!(error_key(r), "camera.look_at_mm");
    }

    #[test]
    fn focus_distance_3e38_is_refused() {
        let r = Camera::new(Vec3::Z * 100.0, Vec3::ZERO, Vec3::Y, 40.0, 5.0, Some(3e38));
        assert_eq!(error_key(r), "camera.focus_distance_mm");
    }

    #[test]
    fn an_up_vector_of_3e38_normalises() {
        // Its squared length overflows f32; as a direction it is plain +Y.
        let big = Camera::new(
            Vec3::Z,
            Vec3::ZERO,
            Vec3::new(0.0, 3e38, 0.0),
            40.0,
            0.0,
            None,
        );
        let unit = Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, 40.0, 0.0, None);
        assert_eq!(big.unwrap(), unit.unwrap());
    }

    #[test]
    fn bad_camera_is_rejected() {
        assert!(Camera::new(Vec3::ZERO, Vec3::ZERO, Vec3::Y, 40.0, 0.0, None).is_err());
        assert!(Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Z, 40.0, 0.0, None).is_err());
        assert!(Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, 180.0, 0.0, None).is_err());
    }
}
