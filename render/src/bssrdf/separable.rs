//! The separable BSSRDF ([JMLH01], pbrt-v3; docs/physics.md §8) and its energy split with the specular
//! surface layer:
//!
//! S(p_o, ω_o; p_i, ω_i) = T(cos θ_o) · R(‖p_o − p_i‖) · S_ω(ω_i),   S_ω(ω) = T(cos θ) / (c π),
//!
//! where T is the fraction of light the surface lets through and c = ∫ T(μ) 2μ dμ makes
//! ∫ S_ω cos θ dω = 1 (so a flat slab reflects exactly R_tot · T(θ_o) of what enters).
//!
//! # Energy split (the choice, and why)
//! docs/physics.md §8 writes T = 1 − F_r (smooth-surface Fresnel) and c = 1 − 2 F̄₁ (`brdf::fresnel`).
//! The renderer's surface layer is a *rough* oily Torrance–Sparrow lobe ([TS67], [DJ06]) that
//! reflects ρ_dr(θ) = `directional_albedo`, which is not F_r(θ): with the Fresnel split, surface +
//! subsurface could exceed 1 or leave a gap. The default is therefore [`EnergySplit::SpecularLobe`],
//! T(θ) = 1 − ρ_dr(θ) (`TorranceSparrow::transmitted_fraction`), the same split the tracer's diffuse
//! stand-in used: surface + subsurface reflect ρ_dr(θ) + T(θ) R_tot ≤ 1 for every angle, and the
//! product form T(θ_o) T(θ_i) keeps S reciprocal. [`EnergySplit::Fresnel`] is kept as the paper's
//! variant (both are normalised by their own c).

use super::incidence::IncidenceGain;
use crate::spectrum::{N_WAVELENGTHS, SampledSpectrum, SampledWavelengths};
use brdf::TorranceSparrow;
use brdf::fresnel::{dielectric_reflectance, fresnel_moment};
use std::f32::consts::FRAC_1_PI;
use std::sync::Arc;

/// Which transmittance couples the subsurface term to the surface layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EnergySplit {
    /// T(θ) = 1 − directional albedo of the specular lobe (default, energy conserving with it).
    #[default]
    SpecularLobe,
    /// T(θ) = 1 − F_r(cos θ, η) (smooth dielectric, docs/physics.md §8 as written).
    Fresnel,
}

/// Nodes of the μ-midpoint rule for c (T is smooth; 1024 nodes are far below f32 noise).
const NORMALISATION_NODES: usize = 1024;

/// The directional part of the separable BSSRDF for one material: T(cos θ), the incidence gain
/// a(cos θ, λ) (docs/physics.md §8.1) and S_ω.
#[derive(Debug, Clone)]
pub struct Directional {
    split: EnergySplit,
    surface: TorranceSparrow,
    /// c = ∫₀¹ T(μ) 2μ dμ, dimensionless.
    c: f32,
    /// a(μ, λ), and c(λ) = ∫₀¹ T(μ) a(μ, λ) 2μ dμ per row of it (None: a = 1).
    incidence: Option<(Arc<IncidenceGain>, Vec<f32>)>,
}

impl Directional {
    /// The directional term for the surface lobe `surface` (its η is used by the Fresnel split).
    #[must_use]
    pub fn new(surface: TorranceSparrow, split: EnergySplit) -> Self {
        let mut d = Self {
            split,
            surface,
            c: 1.0,
            incidence: None,
        };
        d.c = match split {
            // docs/physics.md §8: c = 1 − 2 F̄₁, F̄₁ from the brdf crate's Fresnel moments.
            EnergySplit::Fresnel => {
                (1.0 - 2.0 * fresnel_moment(1, f64::from(d.surface.eta()))) as f32
            }
            EnergySplit::SpecularLobe => {
                let n = NORMALISATION_NODES;
                (0..n)
                    .map(|i| {
                        let mu = (i as f32 + 0.5) / n as f32;
                        d.transmittance(mu) * 2.0 * mu / n as f32
                    })
                    .sum()
            }
        };
        d
    }

    /// The same term with the incidence gain `gain` (docs/physics.md §8.1): the angular factor
    /// becomes T(μ) a(μ, λ), normalised per wavelength.
    #[must_use]
    pub fn with_incidence(mut self, gain: Arc<IncidenceGain>) -> Self {
        let n = NORMALISATION_NODES;
        let c = (0..gain.wavelengths())
            .map(|i| {
                (0..n)
                    .map(|k| {
                        let mu = (k as f32 + 0.5) / n as f32;
                        self.transmittance(mu) * gain.row_gain(i, mu) * 2.0 * mu / n as f32
                    })
                    .sum()
            })
            .collect();
        self.incidence = Some((gain, c));
        self
    }

    /// [`Self::with_incidence`] with the normalisation rows `c` it computed before for `gain` on
    /// this surface and split (a cached grid's, [`Self::normalisation_rows`]).
    #[must_use]
    pub fn with_normalised_incidence(mut self, gain: Arc<IncidenceGain>, c: Vec<f32>) -> Self {
        self.incidence = Some((gain, c));
        self
    }

    /// The normalisation c(λ) per row of the incidence gain, if any.
    #[must_use]
    pub fn normalisation_rows(&self) -> Option<&[f32]> {
        self.incidence.as_ref().map(|(_, c)| c.as_slice())
    }

    /// The incidence gain, if any.
    #[must_use]
    pub fn incidence(&self) -> Option<&IncidenceGain> {
        self.incidence.as_ref().map(|(g, _)| g.as_ref())
    }

    /// The incidence gain, shared (to build another split with the same gain).
    #[must_use]
    pub fn incidence_arc(&self) -> Option<Arc<IncidenceGain>> {
        self.incidence.as_ref().map(|(g, _)| Arc::clone(g))
    }

    /// The energy split in use.
    #[must_use]
    pub fn split(&self) -> EnergySplit {
        self.split
    }

    /// The normalisation c = ∫ T(μ) 2μ dμ (≈ 0.92 for Fresnel at η = 1.4).
    #[must_use]
    pub fn normalisation(&self) -> f32 {
        self.c
    }

    /// Fraction of light crossing the surface at incidence cosine `cos_theta` (0 for cos ≤ 0).
    #[must_use]
    pub fn transmittance(&self, cos_theta: f32) -> f32 {
        if cos_theta.is_nan() || cos_theta <= 0.0 {
            return 0.0;
        }
        let mu = cos_theta.min(1.0);
        match self.split {
            EnergySplit::SpecularLobe => self.surface.transmitted_fraction(mu).clamp(0.0, 1.0),
            EnergySplit::Fresnel => {
                (1.0 - dielectric_reflectance(f64::from(mu), f64::from(self.surface.eta()))) as f32
            }
        }
    }

    /// The angular factor T(cos θ) a(cos θ, λ) at wavelength `nm` (T alone without a gain).
    #[must_use]
    pub fn factor(&self, cos_theta: f32, nm: f32) -> f32 {
        let t = self.transmittance(cos_theta);
        match &self.incidence {
            Some((gain, _)) if t > 0.0 => t * gain.gain(cos_theta.min(1.0), nm),
            _ => t,
        }
    }

    /// The normalisation c(λ) = ∫₀¹ T(μ) a(μ, λ) 2μ dμ at `nm` ([`Self::normalisation`] without
    /// a gain). Linear in λ between the gain's rows, as a is.
    #[must_use]
    pub fn normalisation_at(&self, nm: f32) -> f32 {
        match &self.incidence {
            Some((gain, c)) if c.len() > 1 => {
                let (i, t) = gain.rows_at(nm);
                c[i] + t * (c[i + 1] - c[i])
            }
            Some((_, c)) if c.len() == 1 => c[0],
            _ => self.c,
        }
    }

    /// [`Self::normalisation_at`] at the path's wavelength `k`.
    #[must_use]
    #[inline]
    pub fn normalisation_lane(&self, wl: &SampledWavelengths, k: usize) -> f32 {
        match &self.incidence {
            Some((gain, c)) if gain.on_10nm_grid() => wl.on_10nm(k).lerp(c),
            _ => self.normalisation_at(wl.nm(k)),
        }
    }

    /// S_ω(ω) = T(cos θ) a(cos θ, λ) / (c(λ) π), sr⁻¹, at `nm`: the directional factor at the
    /// point where light enters.
    #[must_use]
    pub fn s_omega(&self, cos_theta: f32, nm: f32) -> f32 {
        self.factor(cos_theta, nm) * FRAC_1_PI / self.normalisation_at(nm)
    }

    /// The cosine-weighted continuation weight S_ω cos θ / (cos θ / π) = T a / c at `nm`.
    #[must_use]
    pub fn cosine_sample_weight(&self, cos_theta: f32, nm: f32) -> f32 {
        self.factor(cos_theta, nm) / self.normalisation_at(nm)
    }

    /// [`Self::factor`] at each of the path's wavelengths: T and the gain's angle are found once.
    #[must_use]
    pub fn factors(&self, cos_theta: f32, wl: &SampledWavelengths) -> SampledSpectrum {
        let t = self.transmittance(cos_theta);
        match &self.incidence {
            Some((gain, _)) if t > 0.0 => {
                let column = gain.column(cos_theta.min(1.0));
                SampledSpectrum(std::array::from_fn(|k| t * gain.gain_lane(column, wl, k)))
            }
            _ => SampledSpectrum([t; N_WAVELENGTHS]),
        }
    }

    /// [`Self::s_omega`] at each of the path's wavelengths.
    #[must_use]
    pub fn s_omegas(&self, cos_theta: f32, wl: &SampledWavelengths) -> SampledSpectrum {
        let f = self.factors(cos_theta, wl);
        SampledSpectrum(std::array::from_fn(|k| {
            f.0[k] * FRAC_1_PI / self.normalisation_lane(wl, k)
        }))
    }

    /// [`Self::cosine_sample_weight`] at each of the path's wavelengths.
    #[must_use]
    pub fn cosine_sample_weights(
        &self,
        cos_theta: f32,
        wl: &SampledWavelengths,
    ) -> SampledSpectrum {
        let f = self.factors(cos_theta, wl);
        SampledSpectrum(std::array::from_fn(|k| {
            f.0[k] / self.normalisation_lane(wl, k)
        }))
    }
}

/// The albedo texture's modulation of the subsurface term, from the texture's relative luminance
/// m (texture luminance / its mean) at the point where light leaves toward the viewer (`m_out`) and
/// where it enters (`m_in`): √(m_out · m_in).
///
/// [DJ05] (§ on textured skin) applies the square root of the albedo map at both ends of the
/// subsurface path: the product stays reciprocal (swapping the points changes nothing), a
/// uniformly coloured map gives exactly its colour, and detail is blurred by the profile only once
/// overall, matching the look of light that passed the pigmented layer going in and coming out.
/// Modulating at the exit alone would keep the detail sharper but breaks reciprocity.
#[must_use]
pub fn texture_modulation(m_out: f32, m_in: f32) -> f32 {
    (m_out.max(0.0) * m_in.max(0.0)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lobe() -> TorranceSparrow {
        TorranceSparrow::new(0.3, 0.25, 1.4).unwrap()
    }

    /// ∫ S_ω cos θ dω = 1 for both splits, by a fine midpoint rule over the hemisphere (in μ; S_ω
    /// does not depend on φ, so the φ integral is 2π).
    #[test]
    fn s_omega_is_normalised() {
        for split in [EnergySplit::SpecularLobe, EnergySplit::Fresnel] {
            let d = Directional::new(lobe(), split);
            let n = 100_000;
            let s: f64 = (0..n)
                .map(|i| {
                    let mu = (i as f64 + 0.5) / f64::from(n);
                    f64::from(d.s_omega(mu as f32, 550.0)) * mu * 2.0 * std::f64::consts::PI
                        / f64::from(n)
                })
                .sum();
            assert!((s - 1.0).abs() < 1e-4, "{split:?}: ∫ S_ω cos dω = {s}");
        }
    }

    /// c for the Fresnel split at η = 1.4 is 1 − 2·m1 with the exact first moment m1 = 0.038 405 77
    /// (400-point Gauss–Legendre, see `brdf::fresnel`'s tests): c = 0.923 188 5. pbrt-v3's polynomial
    /// fit gives 0.923 206. The value is stored as f32 (ulp 6e-8), so 1e-6.
    #[test]
    fn fresnel_normalisation_is_one_minus_twice_the_first_moment() {
        let c = Directional::new(lobe(), EnergySplit::Fresnel).normalisation();
        assert!((f64::from(c) - 0.923_188_5).abs() < 1e-6, "c = {c}");
    }

    #[test]
    fn texture_modulation_is_symmetric_and_exact_for_uniform_maps() {
        assert_eq!(texture_modulation(0.7, 0.7), 0.7);
        assert_eq!(texture_modulation(0.3, 1.2), texture_modulation(1.2, 0.3));
        assert_eq!(texture_modulation(-1.0, 1.0), 0.0);
    }
}
