//! The Torrance–Sparrow microfacet BRDF of the skin's oily surface layer ([TS67], [DJ06] §3;
//! docs/physics.md §7): evaluation, importance sampling and pdf in the local frame (+Z = normal).
//!
//! f_s(ωi, ωo) = ρ_s D(h) G(ωi, ωo) F(ωo·h) / (4 |n·ωi| |n·ωo|), h = normalize(ωi + ωo),
//! with the Beckmann D of [`crate::beckmann`], the V-cavity G of `v_cavity` and the exact unpolarised
//! dielectric Fresnel F of [`crate::fresnel`]. Both directions must be unit vectors in the upper
//! hemisphere; anything at or below the horizon gives 0.

use crate::albedo;
use crate::beckmann;
use crate::error::{Bounds, BrdfError, check_eta, check_oiliness, check_range, check_roughness};
use crate::fresnel::dielectric_reflectance_f32;
use crate::v_cavity;
use glam::Vec3;

/// Beckmann roughness of skin, m = 0.3 ([DJ06] §3: "a roughness value of ≈ 0.3 is sufficient").
pub const DEFAULT_ROUGHNESS: f32 = 0.3;
/// Oiliness ρ_s of the paper's Figure 1 renders, 0.25 ([DJ06] Fig. 1).
pub const DEFAULT_OILINESS: f32 = 0.25;
/// Relative refractive index of skin's surface, η = 1.4 ([DJ06]; docs/physics.md §7).
pub const DEFAULT_ETA: f32 = 1.4;

/// One importance sample of the lobe: the incident direction and the BRDF and pdf there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Sampled incident direction ωi (unit, local frame, upper hemisphere).
    pub wi: Vec3,
    /// f_s(ωo, ωi), sr⁻¹.
    pub value: f32,
    /// Density of ωi per steradian, sr⁻¹ (> 0).
    pub pdf: f32,
}

/// Torrance–Sparrow BRDF with Beckmann roughness m, oiliness scale ρ_s and relative index η,
/// valid by construction; holds its directional-albedo table (built at construction, ~0.2 s in
/// release, and shared through a small cache by lobes with the same m and η).
#[derive(Clone)]
pub struct TorranceSparrow {
    roughness_m: f32,
    oiliness_rho_s: f32,
    eta: f32,
    /// Directional albedo for ρ_s = 1 at cosθ = i / (len − 1) (see `albedo`).
    unit_albedo: std::sync::Arc<[f32]>,
}

impl std::fmt::Debug for TorranceSparrow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TorranceSparrow")
            .field("roughness_m", &self.roughness_m)
            .field("oiliness_rho_s", &self.oiliness_rho_s)
            .field("eta", &self.eta)
            .finish_non_exhaustive()
    }
}

impl TorranceSparrow {
    /// Lobe with Beckmann RMS slope `roughness_m` in (0, 1], oiliness `oiliness_rho_s` in [0, 1] and
    /// relative refractive index `eta` in [1, 3]; NaN and infinities are rejected.
    pub fn new(roughness_m: f32, oiliness_rho_s: f32, eta: f32) -> Result<Self, BrdfError> {
        let roughness_m = check_roughness(roughness_m)?;
        let oiliness_rho_s = check_oiliness(oiliness_rho_s)?;
        let eta = check_eta(eta)?;
        Ok(TorranceSparrow {
            roughness_m,
            oiliness_rho_s,
            eta,
            unit_albedo: albedo::cached_albedo_table(roughness_m, eta),
        })
    }

    /// Beckmann RMS slope m (dimensionless).
    #[must_use]
    pub fn roughness(&self) -> f32 {
        self.roughness_m
    }

    /// Oiliness ρ_s, the linear scale of the lobe (dimensionless).
    #[must_use]
    pub fn oiliness(&self) -> f32 {
        self.oiliness_rho_s
    }

    /// Relative refractive index η of the surface (dimensionless).
    #[must_use]
    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// f_s(ωo, ωi) in sr⁻¹ for unit local directions (+Z = normal); 0 if either is at or below the
    /// horizon. Wavelength independent. Symmetric in its arguments.
    ///
    /// The lobe is unbounded in the grazing mirror configuration (f ∝ 1/cos²θ); values beyond
    /// `f32::MAX` saturate there instead of becoming infinite, and when 4 cosθo cosθi underflows f32
    /// (both directions within ~1e-19 of the horizon) the result is 0. Never NaN or infinite.
    #[must_use]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        match half_vector(wo, wi) {
            Some((h, o_h)) => {
                let d = beckmann::distribution(h, self.roughness_m);
                self.value(h, o_h, wo.z, wi.z, d)
            }
            None => 0.0,
        }
    }

    /// f_s from the half-vector, ωo·h, the two cosines and D(h) (shared by `eval` and `sample`).
    fn value(&self, h: Vec3, o_h: f32, cos_o: f32, cos_i: f32, d: f32) -> f32 {
        let g = v_cavity::g(h.z, cos_o, cos_i, o_h);
        let f = dielectric_reflectance_f32(o_h, self.eta);
        let denominator = 4.0 * cos_o * cos_i;
        if denominator < f32::MIN_POSITIVE {
            // Both directions within ~1e-19 of the horizon: a measure-zero set where 0/0 could arise.
            return 0.0;
        }
        (self.oiliness_rho_s * d * g * f / denominator).min(f32::MAX)
    }

    /// Density in sr⁻¹ with which [`Self::sample`] returns ωi for outgoing ωo: D(h) cosθh / (4 ωo·h)
    /// (the Beckmann half-vector density times the reflection Jacobian dω_h/dωi = 1/(4 ωo·h));
    /// 0 at or below the horizon. Over the upper hemisphere it integrates to at most 1 (the rest is
    /// the probability of a sample below the horizon, returned as `None`).
    #[must_use]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match half_vector(wo, wi) {
            Some((h, o_h)) => {
                pdf_from_half_vector(h, o_h, beckmann::distribution(h, self.roughness_m))
            }
            None => 0.0,
        }
    }

    /// Importance sample ωi for outgoing ωo from two uniforms in [0, 1): draws h with density
    /// D(h) cosθh and reflects ωo about it. `None` when ωo is at or below the horizon, h faces away
    /// from ωo, or the reflected ωi falls below the horizon (absorbed by the estimator as zero).
    /// The estimator weight value·cosθi/pdf = ρ_s F G (ωo·h)/(cosθo cosθh) is bounded by 2 ρ_s F
    /// because G ≤ G₁(ωo).
    #[must_use]
    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<Sample> {
        if wo.z.is_nan() || wo.z <= 0.0 {
            return None;
        }
        let h = beckmann::sample_half_vector(u, self.roughness_m);
        let o_h = wo.dot(h);
        if o_h.is_nan() || o_h <= 0.0 {
            return None;
        }
        let wi = (2.0 * o_h * h - wo).normalize();
        // Recompute h and D from (ωo, ωi) exactly as `eval` and `pdf` do, so a sample's value and pdf
        // equal theirs bit for bit (multiple importance sampling compares them); D is evaluated once.
        let (h, o_h) = half_vector(wo, wi)?;
        let d = beckmann::distribution(h, self.roughness_m);
        let pdf = pdf_from_half_vector(h, o_h, d);
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some(Sample {
            wi,
            value: self.value(h, o_h, wo.z, wi.z, d),
            pdf,
        })
    }

    /// Directional albedo ∫ f_s cosθi dωi (dimensionless, in [0, 1]) for incidence cosine
    /// `cos_theta` (clamped to [0, 1]; NaN reads as grazing), by Catmull–Rom interpolation in the
    /// table of 129 cosines (cube-root spaced) built at construction with 64-node Gauss–Legendre
    /// quadrature per axis and piece (f64).
    /// Table error against [`Self::directional_albedo_quadrature`]: below 1e-4 (tested).
    #[must_use]
    pub fn directional_albedo(&self, cos_theta: f32) -> f32 {
        self.oiliness_rho_s * albedo::lookup(&self.unit_albedo, cos_theta)
    }

    /// Fraction of the light arriving with incidence cosine `cos_theta` that the surface lobe does
    /// not reflect: 1 − [`Self::directional_albedo`]. This is the energy split the renderer uses:
    /// the subsurface (BSSRDF) term of light entering at cosθ is scaled by this factor, so surface
    /// plus subsurface reflectance never exceeds 1 (docs/physics.md §7; the alternative, the
    /// smooth-surface Fresnel transmittance, ignores the lobe's roughness and ρ_s).
    #[must_use]
    pub fn transmitted_fraction(&self, cos_theta: f32) -> f32 {
        1.0 - self.directional_albedo(cos_theta)
    }

    /// Directional albedo at incidence cosine `cos_theta` in [0, 1] computed directly (no table) in
    /// f64 with an `nodes` × `nodes` Gauss–Legendre rule over the half-vector sampling variables,
    /// `nodes` in [1, 4096]; 96 nodes are accurate to 1e-5 (see the `albedo` module).
    pub fn directional_albedo_quadrature(
        &self,
        cos_theta: f64,
        nodes: usize,
    ) -> Result<f64, BrdfError> {
        let mu = check_range("cos θ", cos_theta, 0.0, 1.0, Bounds::Closed, "[0, 1]")?;
        check_range(
            "quadrature nodes",
            nodes as f64,
            1.0,
            4096.0,
            Bounds::Closed,
            "[1, 4096]",
        )?;
        let unit =
            albedo::albedo_quadrature(f64::from(self.roughness_m), f64::from(self.eta), mu, nodes);
        Ok(f64::from(self.oiliness_rho_s) * unit)
    }
}

/// Half-vector h and ωo·h for unit ωo, ωi both strictly above the horizon, else `None`.
fn half_vector(wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
    if !(wo.z > 0.0 && wi.z > 0.0) {
        return None;
    }
    let sum = wo + wi;
    let len = sum.length();
    // For unit ωo, ωi: ωo·h = ωi·h = |ωo + ωi| / 2, a form symmetric in the two directions. len > 0
    // because both z components are positive.
    Some((sum / len, 0.5 * len))
}

/// Sampling density of ωi, sr⁻¹: D(h) cosθh / (4 ωo·h), saturated at `f32::MAX`.
fn pdf_from_half_vector(h: Vec3, o_h: f32, d: f32) -> f32 {
    (d * h.z.max(0.0) / (4.0 * o_h)).min(f32::MAX)
}
