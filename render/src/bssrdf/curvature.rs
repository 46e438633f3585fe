//! The first-order curvature term of the planar profile (docs/physics.md §8.2). The profile R(r)
//! is a half-space's; on a convex body the surface at chord distance d from the entry lies a
//! depth h below the entry's tangent plane, and light that in the half-space would have been
//! absorbed on its way back up that depth escapes there instead. In diffusion with an
//! extrapolated (Dirichlet) boundary, moving the boundary inward by h(x) raises the light escaping
//! at x by κ h(x) j(x) to first order (Hadamard's variation of the Green's function), κ = σ_tr
//! the dermis' effective attenuation and j the planar exit flux: each exit's weight is multiplied
//! by 1 + κ(λ) h. On a sphere of radius R, h = d² / 2R exactly and the total grows by
//! κ ⟨d²⟩ / 2R, ⟨d²⟩ the profile's energy-weighted mean square radius; on a plane h = 0.

use crate::media::SkinMedia;
use crate::spectrum::SpectrumTable;
use glam::Vec3;

/// How the BSSRDF treats the curvature of the skin between entry and exit (the knob of §8.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Curvature {
    /// The planar profile on every surface ([JMLH01], pbrt): a sphere of light skin 5 mm in
    /// radius renders 9% dark at 650 nm (docs/physics.md §8.2).
    Planar,
    /// The profile times 1 + κ(λ) h (default): the first-order term of a curved boundary.
    #[default]
    FirstOrder,
}

/// The effective attenuation σ_tr = √(3 σa (σa + σs (1 − g))) of a layer of absorption `sigma_a`
/// and scattering `sigma_s` (mm⁻¹) at Henyey–Greenstein `g`, mm⁻¹: the gain κ of the curvature term
/// when it is the dermis' (docs/physics.md §8.2).
#[must_use]
#[inline]
pub fn sigma_tr_per_mm(sigma_a: f32, sigma_s: f32, g: f32) -> f32 {
    (3.0 * sigma_a * (sigma_a + sigma_s * (1.0 - g)))
        .max(0.0)
        .sqrt()
}

/// κ(λ) of one skin, mm⁻¹: the dermis' σ_tr ([`sigma_tr_per_mm`]) on the 5-nm grid.
#[derive(Debug, Clone)]
pub struct CurvatureGain {
    kappa_per_mm: SpectrumTable,
}

impl CurvatureGain {
    /// The gain of a skin's layers (its dermis' coefficients at its g).
    #[must_use]
    pub fn new(media: &SkinMedia) -> Self {
        let d = &media.dermis;
        let g = media.phase_g as f32;
        Self {
            kappa_per_mm: SpectrumTable::from_fn(|nm| {
                let nm = nm as f32;
                f64::from(sigma_tr_per_mm(d.sigma_a.at_nm(nm), d.sigma_s.at_nm(nm), g))
            }),
        }
    }

    /// κ at `nm`, mm⁻¹.
    #[must_use]
    pub fn kappa_per_mm(&self, nm: f32) -> f32 {
        self.kappa_per_mm.at_nm(nm)
    }
}

/// The depth h (mm) of the exit below the entry's tangent plane, symmetrised so that the term
/// stays reciprocal: h = ½ (p_i − p_o) · (n_i − n_o), which is d² / 2R on a sphere of radius R
/// (d the chord), 0 on a plane and negative on a concave surface. `None` when the exit faces
/// away from the entry (n_i · n_o ≤ 0: the far face of a thin part, where the profile is not a
/// half-space's at all and the thin-part walk takes over, §16.6).
#[must_use]
pub fn depth_below_tangent_mm(p_o: Vec3, n_o: Vec3, p_i: Vec3, n_i: Vec3) -> Option<f32> {
    (n_i.dot(n_o) > 0.0).then(|| 0.5 * (p_i - p_o).dot(n_i - n_o))
}

/// The factor 1 + κ h (at least 0: a concave surface deeper than 1/κ returns nothing there).
#[must_use]
pub fn factor(kappa_per_mm: f32, depth_mm: f32) -> f32 {
    (1.0 + kappa_per_mm * depth_mm).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a sphere of radius R the depth is d²/2R for every pair of points on the same side,
    /// 0 on a plane, and the far face of a slab has none.
    #[test]
    fn depth_on_a_sphere_is_the_chord_squared_over_the_diameter() {
        let r = 5.0f32;
        let n_o = Vec3::Z;
        let p_o = n_o * r;
        for deg in [1.0f32, 10.0, 45.0, 80.0] {
            let t = deg.to_radians();
            let n_i = Vec3::new(t.sin(), 0.0, t.cos());
            let p_i = n_i * r;
            let d = (p_i - p_o).length();
            let h = depth_below_tangent_mm(p_o, n_o, p_i, n_i).unwrap();
            assert!(
                (h - d * d / (2.0 * r)).abs() < 1e-5 * r,
                "{deg}°: {h} vs {}",
                d * d / 2.0 / r
            );
            // The plain depth below the tangent plane, (p_o − p_i) · n_o.
            assert!((h - (p_o - p_i).dot(n_o)).abs() < 1e-5 * r);
        }
        let flat = depth_below_tangent_mm(Vec3::ZERO, Vec3::Z, Vec3::new(3.0, 1.0, 0.0), Vec3::Z);
        assert_eq!(flat, Some(0.0));
        let far = depth_below_tangent_mm(Vec3::ZERO, Vec3::Z, Vec3::new(0.5, 0.0, -2.0), -Vec3::Z);
        assert_eq!(far, None);
        assert_eq!(factor(0.7, -2.0), 0.0);
        assert!((factor(0.7, 1.0) - 1.7).abs() < 1e-6);
    }
}
