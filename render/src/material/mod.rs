//! Materials and their BSDFs at a shading point: `Skin` (oily Torrance–Sparrow surface over a
//! diffusing body) and `Diffuse` (Lambert) for backdrops.
//!
//! # Skin with subsurface scattering (the default)
//!
//! When the material carries a [`Subsurface`] model, its BSDF is the surface lobe alone
//! (`Lobes::SkinSurface`) and the body is rendered by the separable BSSRDF in the integrator
//! (`crate::bssrdf`): at each skin hit the path follows the surface lobe with probability p
//! (∝ ρ_dr(θ_o) against T(θ_o) R̄_tot) or the subsurface branch with 1 − p. The energy split is
//! the same as below, so on a flat slab both forms render the same radiance.
//!
//! # Skin without subsurface scattering (`SkinKnobs::no_subsurface`)
//!
//! Skin shades as its surface lobe ([TS67], `brdf::TorranceSparrow`, m = 0.3, ρ_s from the
//! `SkinParams`, η = 1.4) plus a Lambertian body term built from the skin model's total
//! diffuse reflectance R_d(λ) (`multipole::skin::total_reflectance` with the scene's method, per
//! unit flux entering), tabulated per material at scene load by [`SkinMaterial::build`]. The energy split is the lobe's own: the light the lobe does
//! not reflect, T(θ) = 1 − ρ_dr(θ) (`ts.transmitted_fraction`), enters; R_d of it comes back out,
//! leaving with the same split. Reciprocal and energy conserving:
//!
//! f_body(ωi, ωo; λ) = R_d(λ) · m(uv) · T(θi) a(θi, λ) · T(θo) a(θo, λ) / (π c(λ)),
//! c(λ) = ∫ T(θ) a(θ, λ) 2 cosθ d cosθ,
//!
//! the BSSRDF's own angular factor (`bssrdf::Directional`, with the incidence gain a of
//! docs/physics.md §8.1; a = 1 with `Incidence::Normal`), so the body reflects R_d · T(θi) a(θi) of
//! the incident flux and surface + body ≤ ρ_dr + (1 − ρ_dr) R_d(θi) ≤ 1 (R_d a is the
//! adding-doubling reflectance at that incidence).
//! (The observable `multipole::skin::diffuse_reflectance` is the same R_d with the smooth-surface
//! split (1 − F(0)) instead of T(0°); the two differ by under 2% for ρ_s ≤ 0.25.)
//! `m(uv)` is the optional albedo texture's luminance relative to its mean, so the texture adds
//! spatial detail (brows, lips, pores) without replacing the model's spectral colour; the product
//! is clamped at 1.

use crate::bssrdf::AngularFactor;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, SpectrumTable, linear_srgb_at_nm};
use crate::texture::Texture;
use brdf::Frame;
#[cfg(test)]
use brdf::TorranceSparrow;
use glam::{Vec2, Vec3};
use std::cell::Cell;
use std::f32::consts::{FRAC_1_PI, PI};

pub mod hetero;
pub mod maps;
mod skin;
mod surface;

pub use skin::{SkinBuildError, SkinKnobs, SkinMaterial};
use surface::Surface;
pub use surface::SurfaceKind;

/// An albedo texture used by a material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TextureRef {
    /// Index into the scene's textures.
    pub index: usize,
    /// Mean luminance of the texture (for relative modulation).
    pub mean_luminance: f32,
}

/// Lambertian material with a spectral albedo, optionally times an sRGB texture.
#[derive(Debug, Clone)]
pub struct DiffuseMaterial {
    /// Albedo ρ(λ) in [0, 1].
    pub albedo: SpectrumTable,
    /// Optional albedo texture (its linear sRGB multiplies ρ, via the box-basis spectrum).
    pub albedo_texture: Option<TextureRef>,
}

/// A surface material.
// A scene holds a handful of materials, read at every hit: a box would add an indirection there
// to save a few hundred bytes per material.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum Material {
    /// Human skin ([DJ06]).
    Skin(SkinMaterial),
    /// Lambertian.
    Diffuse(DiffuseMaterial),
}

/// The BSDF at one shading point, for the path's wavelengths, in the shading frame.
#[derive(Debug, Clone)]
pub struct Bsdf<'a> {
    /// Shading frame (+Z = shading normal, facing the outgoing direction).
    pub frame: Frame,
    lobes: Lobes<'a>,
    /// The last (cos θ_o, surface lobe probability) of [`Bsdf::specular_probability`]: a path
    /// asks for it at one ω_o up to four times per hit (light sampling, the branch, the
    /// continuation and its density), and each costs a table lookup with a cube root.
    specular: Cell<Option<(f32, f32)>>,
}

#[derive(Debug, Clone)]
enum Lobes<'a> {
    Skin {
        surface: Surface<'a>,
        /// R_d(λ) m(uv).
        body: SampledSpectrum,
        /// T(θ) a(θ, λ) / c(λ) on both sides (the BSSRDF's angular factor, the texel's with
        /// maps).
        directional: AngularFactor<'a>,
        wl: &'a SampledWavelengths,
        /// π c(λ) per lane.
        pi_c: SampledSpectrum,
        /// The last (cos θ_o, T(θ_o) a(θ_o, λ)): ω_o is the same for every evaluation at a hit.
        outgoing: Cell<Option<(f32, SampledSpectrum)>>,
    },
    Lambert {
        /// ρ(λ) / π.
        body: SampledSpectrum,
    },
    /// Skin whose body is rendered by the BSSRDF: only the surface lobe is a BSDF here; the
    /// integrator takes the subsurface branch with probability 1 − p (`subsurface_probability`).
    SkinSurface {
        surface: Surface<'a>,
        /// Mean over the path's wavelengths of R_tot(λ) m(uv), for choosing the branch.
        subsurface_albedo: f32,
    },
}

/// A sampled incident direction with the BSDF value and density there.
#[derive(Debug, Clone, Copy)]
pub struct BsdfSample {
    /// Incident direction, world space.
    pub wi: Vec3,
    /// f(ωo, ωi) per wavelength, sr⁻¹.
    pub f: SampledSpectrum,
    /// Density of ωi, sr⁻¹; for a delta lobe (`delta`), the probability of choosing it, and `f`
    /// is then the lobe's weight divided by |cos θ_i|, so f |cos θ_i| / pdf is still the throughput.
    pub pdf: f32,
    /// True for the mirror reflection of a smooth surface (no density: no light sampling, no MIS).
    pub delta: bool,
}

impl Material {
    /// Whether a hit on this material shades skin with its diffuse body instead of the BSSRDF
    /// at a pixel footprint of `footprint_mm` (the level of detail, `crate::fidelity::lod`);
    /// `u` (uniform in [0, 1)) decides inside the blend band.
    #[must_use]
    pub fn collapses(&self, footprint_mm: f32, u: f32) -> bool {
        let Material::Skin(skin) = self else {
            return false;
        };
        let Some(lod) = skin.lod() else {
            return false;
        };
        if skin.subsurface.is_none() {
            return false;
        }
        let p = lod.diffuse_probability(footprint_mm);
        if p <= 0.0 {
            false
        } else if p >= 1.0 {
            true
        } else {
            u < p
        }
    }

    /// The BSDF at a point with shading normal `n` (facing the viewer) and texture coordinate `uv`.
    #[must_use]
    pub fn bsdf<'a>(
        &'a self,
        n: Vec3,
        uv: Vec2,
        wl: &'a SampledWavelengths,
        textures: &[Texture],
    ) -> Bsdf<'a> {
        self.bsdf_lod(n, uv, wl, textures, false, None)
    }

    /// [`Material::bsdf`], with skin's subsurface term collapsed to its diffuse body when
    /// `collapsed` (the level of detail of `crate::fidelity::lod`: same totals, no BSSRDF);
    /// `texel`: the maps' texel at `uv` where the caller has read it
    /// ([`hetero::SkinMaps::exit_texel`]).
    #[must_use]
    pub fn bsdf_lod<'a>(
        &'a self,
        n: Vec3,
        uv: Vec2,
        wl: &'a SampledWavelengths,
        textures: &[Texture],
        collapsed: bool,
        texel: Option<&hetero::ExitTexel<'_>>,
    ) -> Bsdf<'a> {
        let frame = Frame::from_normal(n);
        let lobes = match self {
            Material::Skin(s) if s.subsurface.is_some() && !collapsed => {
                let subsurface_albedo = match &s.maps {
                    Some(maps) => texel
                        .map_or_else(|| maps.totals(wl, uv), |t| t.corners.totals(wl))
                        .average()
                        .min(1.0),
                    None => {
                        let m = s.texture_factor(uv, textures);
                        (s.total_reflectance.eval(wl).average() * m).min(1.0)
                    }
                };
                Lobes::SkinSurface {
                    surface: Surface::of(s),
                    subsurface_albedo,
                }
            }
            Material::Skin(s) => {
                let rd = s.body_totals(uv, wl, textures);
                let directional = match s.maps.as_ref().and_then(|m| m.gain(uv)) {
                    Some(g) => AngularFactor::Texel(g),
                    None => AngularFactor::Material(&s.directional),
                };
                Lobes::Skin {
                    surface: Surface::of(s),
                    body: rd,
                    directional,
                    wl,
                    pi_c: directional.normalisations(wl) * PI,
                    outgoing: Cell::new(None),
                }
            }
            Material::Diffuse(d) => {
                let mut rho = d.albedo.eval(wl);
                if let Some(t) = d.albedo_texture {
                    let rgb = textures[t.index].lookup(uv);
                    rho = SampledSpectrum(std::array::from_fn(|i| {
                        rho.0[i] * linear_srgb_at_nm(rgb, wl.nm(i))
                    }));
                }
                Lobes::Lambert {
                    body: rho.map(|r| r.clamp(0.0, 1.0) * FRAC_1_PI),
                }
            }
        };
        Bsdf {
            frame,
            lobes,
            specular: Cell::new(None),
        }
    }
}

impl Bsdf<'_> {
    /// f(ωo, ωi), sr⁻¹, for world directions (reflection only: zero unless both are above the
    /// shading surface).
    #[must_use]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> SampledSpectrum {
        let (o, i) = (self.frame.to_local(wo), self.frame.to_local(wi));
        if o.z <= 0.0 || i.z <= 0.0 {
            return SampledSpectrum::zero();
        }
        match &self.lobes {
            Lobes::Skin {
                surface,
                body,
                directional,
                wl,
                pi_c,
                outgoing,
            } => {
                let fo = match outgoing.get() {
                    Some((z, fo)) if z.to_bits() == o.z.to_bits() => fo,
                    _ => {
                        let fo = directional.factors(o.z, wl);
                        outgoing.set(Some((o.z, fo)));
                        fo
                    }
                };
                let fi = directional.factors(i.z, wl);
                let split = SampledSpectrum(std::array::from_fn(|k| fi.0[k] * fo.0[k] / pi_c.0[k]));
                *body * split + SampledSpectrum::splat(surface.eval(o, i))
            }
            Lobes::Lambert { body } => *body,
            Lobes::SkinSurface { surface, .. } => SampledSpectrum::splat(surface.eval(o, i)),
        }
    }

    /// Probability that the integrator follows the subsurface branch at this point for `wo`
    /// (0 unless the skin's body is rendered by the BSSRDF).
    #[must_use]
    pub fn subsurface_probability(&self, wo: Vec3) -> f32 {
        let o = self.frame.to_local(wo);
        match &self.lobes {
            Lobes::SkinSurface { .. } if o.z > 0.0 => 1.0 - self.specular_probability(o.z),
            _ => 0.0,
        }
    }

    /// Probability of choosing the surface lobe when sampling from `o` (local): proportional to
    /// the lobe's albedo against the body's mean albedo.
    fn specular_probability(&self, o_z: f32) -> f32 {
        if let Some((z, p)) = self.specular.get()
            && z.to_bits() == o_z.to_bits()
        {
            return p;
        }
        let p = match &self.lobes {
            Lobes::Skin {
                surface,
                body,
                directional,
                ..
            } => {
                let s = surface.albedo(o_z);
                let d = body.average() * Surface::transmitted_of(s) / directional.normalisation();
                surface_share(s, d, 0.0)
            }
            Lobes::SkinSurface {
                surface,
                subsurface_albedo,
            } => {
                let s = surface.albedo(o_z);
                let d = subsurface_albedo * Surface::transmitted_of(s);
                // The subsurface branch keeps at least 5% for the surface even where it
                // reflects nothing, so the branch's weight 1/q stays bounded.
                surface_share(s, d, 0.05)
            }
            Lobes::Lambert { .. } => 0.0,
        };
        self.specular.set(Some((o_z, p)));
        p
    }

    /// Density with which [`Bsdf::sample`] picks `wi` for `wo`, sr⁻¹.
    #[must_use]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (o, i) = (self.frame.to_local(wo), self.frame.to_local(wi));
        if o.z <= 0.0 || i.z <= 0.0 {
            return 0.0;
        }
        let p = self.specular_probability(o.z);
        let diffuse = i.z * FRAC_1_PI;
        match &self.lobes {
            Lobes::Skin { surface, .. } => p * surface.pdf(o, i) + (1.0 - p) * diffuse,
            // The other branch (1 − p) leaves through the BSSRDF, not through a direction here.
            Lobes::SkinSurface { surface, .. } => p * surface.pdf(o, i),
            Lobes::Lambert { .. } => diffuse,
        }
    }

    /// Sample ωi for `wo`: `u_lobe` picks the lobe, `u` the direction.
    #[must_use]
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let o = self.frame.to_local(wo);
        if o.z <= 0.0 {
            return None;
        }
        let p = self.specular_probability(o.z);
        let surface = match &self.lobes {
            Lobes::Skin { surface, .. } if u_lobe < p => Some(surface),
            // The integrator already chose the surface branch (with probability p).
            Lobes::SkinSurface { surface, .. } => Some(surface),
            _ => None,
        };
        if let Some(Surface::Smooth { eta }) = surface {
            // Mirror reflection with the Fresnel weight, chosen with probability p (by `u_lobe`
            // for `Lobes::Skin`, by the integrator's branch for `SkinSurface`).
            let i = Vec3::new(-o.x, -o.y, o.z);
            let fresnel = brdf::fresnel::dielectric_reflectance_f32(o.z, *eta);
            return Some(BsdfSample {
                wi: self.frame.to_world(i),
                f: SampledSpectrum::splat(fresnel / o.z),
                pdf: p,
                delta: true,
            });
        }
        let i = match surface {
            Some(s) => s.sample(o, [u.x, u.y])?,
            None => crate::sampling::cosine_hemisphere(u),
        };
        if i.z <= 0.0 {
            return None;
        }
        let wi = self.frame.to_world(i);
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BsdfSample {
            wi,
            f: self.eval(wo, wi),
            pdf,
            delta: false,
        })
    }
}

/// Share of the surface lobe among the lobes: its albedo `s` against the body's `d` (both
/// dimensionless), clamped to [0.05, 0.95] so neither lobe's weight grows without bound;
/// `without_surface` where the surface reflects nothing.
fn surface_share(s: f32, d: f32, without_surface: f32) -> f32 {
    if s <= 0.0 {
        without_surface
    } else if d <= 0.0 {
        1.0
    } else {
        (s / (s + d)).clamp(0.05, 0.95)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn skin(rd: f32) -> Material {
        let params = skin_optics::SkinParams::preset(skin_optics::Preset::Light);
        let media = crate::media::SkinMedia::new(&params, multipole::DEFAULT_G).unwrap();
        Material::Skin(SkinMaterial::new(
            params,
            TorranceSparrow::new(0.3, 0.25, 1.4).unwrap(),
            SpectrumTable::constant(rd),
            None,
            std::sync::Arc::new(media),
        ))
    }

    /// Directional albedo by importance sampling: ∫ f cos dω = E[f cos / pdf].
    fn albedo(m: &Material, cos_o: f32) -> f32 {
        let wl = SampledWavelengths::sample_visible(0.1);
        let b = m.bsdf(Vec3::Z, Vec2::ZERO, &wl, &[]);
        let wo = Vec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            if let Some(s) = b.sample(wo, rng.random(), Vec2::new(rng.random(), rng.random())) {
                sum += f64::from(s.f.0[0] * s.wi.z / s.pdf);
            }
        }
        (sum / f64::from(n)) as f32
    }

    /// Body + surface reflect ρ_dr(θ) + R_d T(θ): the documented energy split, to 1% (MC).
    #[test]
    fn skin_albedo_is_surface_plus_split_body() {
        let ts = TorranceSparrow::new(0.3, 0.25, 1.4).unwrap();
        for cos_o in [1.0, 0.5, 0.2] {
            let expect = ts.directional_albedo(cos_o) + 0.6 * ts.transmitted_fraction(cos_o);
            let got = albedo(&skin(0.6), cos_o);
            assert!(
                (got - expect).abs() < 0.01 * expect,
                "cos {cos_o}: {got} vs {expect}"
            );
        }
        // Even a white body never reflects more than it receives.
        assert!(albedo(&skin(1.0), 0.3) <= 1.0 + 0.01);
    }

    #[test]
    fn skin_bsdf_is_reciprocal() {
        let wl = SampledWavelengths::sample_visible(0.1);
        let m = skin(0.5);
        let b = m.bsdf(Vec3::Z, Vec2::ZERO, &wl, &[]);
        let a = Vec3::new(0.3, 0.1, 0.9).normalize();
        let c = Vec3::new(-0.5, 0.2, 0.4).normalize();
        let (x, y) = (b.eval(a, c).0[0], b.eval(c, a).0[0]);
        assert!((x - y).abs() < 1e-5 * x.max(1e-3), "{x} vs {y}");
    }
}
