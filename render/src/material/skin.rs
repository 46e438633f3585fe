//! The skin material and its one constructor, [`SkinMaterial::build`]: from validated parameters
//! and the scene's knobs to the surface lobe, the total diffuse reflectance R_tot(λ) and (unless
//! subsurface scattering is off) the BSSRDF.
//!
//! R_tot(λ) is computed once per material and every consumer reads that one set of numbers: with a
//! BSSRDF they are the profile table's totals (`ProfileTable::total`, which the integrator's energy
//! cap and the branch choice between surface and body both read); without one (`no_subsurface`)
//! the Lambertian stand-in tabulates the same model's totals (`multipole::skin::total_reflectance`)
//! on the same 10-nm grid.

use crate::bssrdf::{
    Azimuth, AzimuthOptions, AzimuthalLobe, Curvature, CurvatureGain, Directional, EnergySplit,
    Incidence, IncidenceGain, Subsurface,
};
use crate::fidelity::SKIN_TABLE_STEP_NM;
use crate::fidelity::wavelengths::FROM_NM;
use crate::material::{SurfaceKind, TextureRef};
use crate::media::{MediaError, SkinMedia};
use crate::spectrum::{LAMBDA_MIN_NM, SpectrumTable};
use crate::texture::Texture;
use brdf::TorranceSparrow;
use glam::Vec2;
use rayon::prelude::*;
use skin_optics::SkinParams;
use std::sync::Arc;
use thiserror::Error;

/// Knobs of every skin material of a scene, chosen once when it is loaded (default: exact
/// method, subsurface on, table shapes).
#[derive(Debug, Clone, Copy, Default)]
pub struct SkinKnobs {
    /// How skin reflectance is computed (default exact: adding-doubling totals, exact shapes from
    /// the universal table).
    pub method: multipole::Method,
    /// Shade skin's body with the Lambertian stand-in instead of the BSSRDF (for comparisons;
    /// default false: subsurface scattering on).
    pub no_subsurface: bool,
    /// Escaping photons per Monte Carlo profile shape (`Method::Exact`), or `None` (the default)
    /// for the shapes of the universal table (`multipole::skin::ExactShape::Table`: no run-time
    /// photons, built once per machine and cached).
    pub shape_escapes: Option<u64>,
    /// The fidelity of the tables and of the shading (default auto; `crate::fidelity`).
    pub fidelity: crate::fidelity::FidelityKnobs,
    /// Henyey–Greenstein g of the skin's layers (scene key `phase_g`; `None` = 0.9,
    /// `multipole::DEFAULT_G`): the totals and shapes come from exact transport at this g.
    pub phase_g: Option<f64>,
    /// The surface model (scene key `surface`; default oily).
    pub surface: SurfaceKind,
    /// How the BSSRDF's angular factor treats oblique incidence (default the adding-doubling
    /// gain, docs/physics.md §8.1).
    pub incidence: Incidence,
    /// Whether the BSSRDF's profile carries the first-order curvature term (default on,
    /// docs/physics.md §8.2).
    pub curvature: Curvature,
    /// Whether the BSSRDF carries the azimuthal lobe of oblique light (default off,
    /// docs/physics.md §8.3).
    pub azimuth: Azimuth,
}

/// Why a skin material could not be built.
#[derive(Debug, Error)]
pub enum SkinBuildError {
    /// The surface lobe's roughness (or the skin's oiliness or η) is outside its range.
    #[error("{0}")]
    Surface(#[from] brdf::BrdfError),
    /// The radial profiles of the BSSRDF could not be computed.
    #[error("skin profiles: {0}")]
    Profiles(multipole::MultipoleError),
    /// The total reflectance could not be computed at a wavelength.
    #[error("skin reflectance at {nm} nm: {source}")]
    Reflectance {
        /// The wavelength, nm.
        nm: f64,
        /// What the model reported.
        source: multipole::MultipoleError,
    },
    /// The skin's layers could not be built at a wavelength.
    #[error("{0}")]
    Media(#[from] MediaError),
    /// A total came out outside [0, 1] (a model failure, never silently clamped).
    #[error("skin reflectance {0} outside [0, 1]")]
    OutOfRange(f64),
}

/// Skin: validated parameters, the surface lobe and the body reflectance table.
#[derive(Debug, Clone)]
pub struct SkinMaterial {
    /// The skin's parameters.
    pub params: SkinParams,
    /// The oily surface layer.
    pub surface: TorranceSparrow,
    /// Total diffuse reflectance R_d(λ) per unit flux entering: with a BSSRDF, its profile table's
    /// totals; without, the same model's totals at [`SKIN_TABLE_STEP_NM`] steps.
    pub total_reflectance: SpectrumTable,
    /// Optional albedo texture (relative luminance modulation).
    pub albedo_texture: Option<TextureRef>,
    /// The angular factor of the body: T(θ) a(θ, λ) and its normalisation (the BSSRDF's own,
    /// `bssrdf::Directional`; the Lambertian stand-in and the level of detail shade with it).
    pub directional: Arc<Directional>,
    /// The BSSRDF; when present it replaces the Lambertian body term.
    pub subsurface: Option<Subsurface>,
    /// What the fidelity chose for this skin's tables (`None` without a BSSRDF).
    pub choices: Option<Box<crate::fidelity::SkinChoices>>,
    /// The surface model: the oily lobe `surface`, or a smooth dielectric of index `surface.eta()`.
    pub surface_kind: SurfaceKind,
    /// Both layers' coefficients at the skin's Henyey–Greenstein g, built once: what the totals,
    /// the shapes and the volumetric walks use.
    pub media: Arc<SkinMedia>,
    /// Per-texel chromophores and what is built from them (`None`: the skin is uniform).
    pub maps: Option<Arc<super::hetero::SkinMaps>>,
}

impl SkinMaterial {
    /// The skin of `params` with surface roughness `roughness_m` (Beckmann RMS slope, (0, 1]) and
    /// an optional albedo texture: its surface lobe, its totals and, unless `knobs.no_subsurface`,
    /// its BSSRDF, all built here once.
    pub fn build(
        params: SkinParams,
        roughness_m: f32,
        albedo_texture: Option<TextureRef>,
        knobs: &SkinKnobs,
    ) -> Result<Self, SkinBuildError> {
        let surface =
            TorranceSparrow::new(roughness_m, params.oiliness() as f32, params.eta() as f32)?;
        let g = knobs.phase_g.unwrap_or(multipole::DEFAULT_G);
        let media = Arc::new(
            SkinMedia::new(&params, g)?.with_surface(boundary_of(knobs.surface, &surface)),
        );
        let directional = Directional::new(surface.clone(), split_of(knobs.surface));
        let directional = match knobs.incidence {
            Incidence::Normal => directional,
            Incidence::AddingDoubling => directional.with_incidence(Arc::new(
                IncidenceGain::build(media.every_10nm(), g).map_err(SkinBuildError::Profiles)?,
            )),
        };
        if knobs.no_subsurface {
            let totals = total_table(&media, knobs.method)?;
            return Ok(Self::new(params, surface, totals, albedo_texture, media)
                .with_surface_kind(knobs.surface)
                .with_directional(directional));
        }
        let (table, choices) = crate::fidelity::tables::skin_table(
            &params,
            &media,
            knobs.method,
            knobs.shape_escapes,
            &knobs.fidelity,
        )
        .map_err(SkinBuildError::Profiles)?;
        let step_nm = choices.wavelengths.step_nm as f32;
        if let Some(bad) = (0..table.wavelengths())
            .map(|j| f64::from(table.total(LAMBDA_MIN_NM + j as f32 * step_nm)))
            .find(|r| !(r.is_finite() && (0.0..=1.0).contains(r)))
        {
            return Err(SkinBuildError::OutOfRange(bad));
        }
        let totals = SpectrumTable::from_fn(|nm| f64::from(table.total(nm as f32)));
        let subsurface = Subsurface::new(Arc::new(table), directional.clone());
        let subsurface = match knobs.curvature {
            Curvature::Planar => subsurface,
            Curvature::FirstOrder => subsurface.with_curvature(CurvatureGain::new(&media)),
        };
        let subsurface = match knobs.azimuth {
            Azimuth::Separable => subsurface,
            Azimuth::Harmonics => {
                let lobe = azimuthal_lobe(&media, &directional, surface.clone(), &subsurface)
                    .map_err(SkinBuildError::Profiles)?;
                subsurface.with_azimuth(Arc::new(lobe))
            }
        };
        let mut skin = Self::new(params, surface, totals, albedo_texture, media)
            .with_surface_kind(knobs.surface)
            .with_directional(directional)
            .with_subsurface(subsurface);
        skin.choices = Some(Box::new(choices));
        Ok(skin)
    }

    /// Skin from its parameters, surface lobe, R_d(λ) table and layers (no BSSRDF).
    #[must_use]
    pub fn new(
        params: SkinParams,
        surface: TorranceSparrow,
        total_reflectance: SpectrumTable,
        albedo_texture: Option<TextureRef>,
        media: Arc<SkinMedia>,
    ) -> Self {
        let directional = Arc::new(Directional::new(surface.clone(), EnergySplit::SpecularLobe));
        Self {
            params,
            surface,
            total_reflectance,
            albedo_texture,
            directional,
            subsurface: None,
            choices: None,
            surface_kind: SurfaceKind::Oily,
            media,
            maps: None,
        }
    }

    /// The same skin with surface model `kind` (the smooth surface's Fresnel split,
    /// T = 1 − F(θ), for the body).
    #[must_use]
    pub fn with_surface_kind(mut self, kind: SurfaceKind) -> Self {
        self.surface_kind = kind;
        self.directional = Arc::new(Directional::new(self.surface.clone(), split_of(kind)));
        self
    }

    /// The same skin with the body's angular factor `directional` (with its incidence gain).
    #[must_use]
    pub fn with_directional(mut self, directional: Directional) -> Self {
        self.directional = Arc::new(directional);
        self
    }

    /// The same skin shading its body with the BSSRDF `subsurface` instead of the Lambertian term.
    #[must_use]
    pub fn with_subsurface(mut self, subsurface: Subsurface) -> Self {
        self.subsurface = Some(subsurface);
        self
    }

    /// Level of detail by pixel footprint (`None`: the BSSRDF at every hit).
    #[must_use]
    pub fn lod(&self) -> Option<crate::fidelity::Lod> {
        self.choices.as_ref().and_then(|c| c.lod)
    }

    /// The albedo texture's relative luminance m(uv) (texture luminance / its mean; 1 without one,
    /// and 1 with chromophore maps, which give the skin's colour per texel instead).
    #[must_use]
    pub fn texture_factor(&self, uv: Vec2, textures: &[Texture]) -> f32 {
        if self.maps.is_some() {
            return 1.0;
        }
        self.albedo_texture.map_or(1.0, |t| {
            textures[t.index].lookup_luminance(uv) / t.mean_luminance
        })
    }

    /// The body's total diffuse reflectance per lane at `uv`: the texel's totals with maps, else
    /// R_tot(λ) times the texture's modulation, each at most 1.
    #[must_use]
    pub fn body_totals(
        &self,
        uv: Vec2,
        wl: &crate::spectrum::SampledWavelengths,
        textures: &[Texture],
    ) -> crate::spectrum::SampledSpectrum {
        if let Some(maps) = &self.maps {
            return maps.totals(wl, uv).map(|r| r.min(1.0));
        }
        let m = self.texture_factor(uv, textures);
        self.total_reflectance.eval(wl).map(|r| (r * m).min(1.0))
    }
}

/// What surface model `kind` (with the oily lobe `lobe`) reflects from either side, as the
/// boundary of the body's totals (docs/physics.md §10.1): the same surface the light crossed to
/// get in, so the BSSRDF's totals and the volumetric walk's boundary are one model.
fn boundary_of(kind: SurfaceKind, lobe: &TorranceSparrow) -> multipole::Surface {
    match kind {
        SurfaceKind::Oily => multipole::Surface::Lobe {
            roughness_m: f64::from(lobe.roughness()),
            oiliness_rho_s: f64::from(lobe.oiliness()),
        },
        SurfaceKind::Smooth => multipole::Surface::Fresnel,
    }
}

/// The azimuthal lobe of the skin layers `media` (docs/physics.md §8.3), fitted against the
/// separable form with the Fresnel split and the incidence gain of `directional`, and the
/// totals of `subsurface`'s table.
fn azimuthal_lobe(
    media: &SkinMedia,
    directional: &Directional,
    surface: TorranceSparrow,
    subsurface: &Subsurface,
) -> Result<AzimuthalLobe, multipole::MultipoleError> {
    let rows: Vec<(f64, &multipole::LayeredMedium)> = media.every_10nm().collect();
    let fresnel = Directional::new(surface, EnergySplit::Fresnel);
    let fresnel = match directional.incidence_arc() {
        Some(g) => fresnel.with_incidence(g),
        None => fresnel,
    };
    AzimuthalLobe::build(
        |nm| {
            rows.iter()
                .min_by(|a, b| (a.0 - nm).abs().total_cmp(&(b.0 - nm).abs()))
                .map(|r| r.1)
                .expect("the 10-nm rows are never empty")
        },
        &fresnel,
        |nm| subsurface.table.total(nm),
        AzimuthOptions::default(),
    )
}

/// The energy split of surface model `kind`: the oily lobe's own, or Fresnel's.
fn split_of(kind: SurfaceKind) -> EnergySplit {
    match kind {
        SurfaceKind::Oily => EnergySplit::SpecularLobe,
        SurfaceKind::Smooth => EnergySplit::Fresnel,
    }
}

/// R_tot(λ) of the skin layers `media` with `method` every 10 nm ([`SKIN_TABLE_STEP_NM`]) over
/// 380–780 nm, computed in parallel and interpolated linearly.
fn total_table(
    media: &SkinMedia,
    method: multipole::Method,
) -> Result<SpectrumTable, SkinBuildError> {
    let rows: Vec<(f64, &multipole::LayeredMedium)> = media.every_10nm().collect();
    let n = rows.len();
    let rd = rows
        .into_par_iter()
        .map(|(nm, medium)| {
            multipole::skin::medium_total_reflectance(medium, method)
                .map_err(|source| SkinBuildError::Reflectance { nm, source })
        })
        .collect::<Result<Vec<f64>, _>>()?;
    if let Some(&bad) = rd
        .iter()
        .find(|r| !(r.is_finite() && (0.0..=1.0).contains(*r)))
    {
        return Err(SkinBuildError::OutOfRange(bad));
    }
    Ok(SpectrumTable::from_fn(|nm| {
        let x = ((nm - FROM_NM) / SKIN_TABLE_STEP_NM).clamp(0.0, (n - 1) as f64);
        let i = (x as usize).min(n - 2);
        rd[i] + (x - i as f64) * (rd[i + 1] - rd[i])
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_optics::Preset;

    /// One set of totals per skin. With a BSSRDF the totals the BSDF reads are the profile table's
    /// (at full fidelity both interpolate linearly between the same 10-nm rows, so they agree at every 5-nm step to
    /// f32 rounding, 1e-6); without one they are the model's at the same 10-nm steps, and the two
    /// agree there to the 1e-5 to which the table's rows hold the model's totals.
    #[test]
    fn the_bsdf_and_the_bssrdf_read_the_same_totals() {
        let params = SkinParams::preset(Preset::Light);
        // Full fidelity: the table's rows on the stand-in's own 10-nm grid.
        let full = SkinKnobs {
            fidelity: crate::fidelity::FidelityKnobs {
                fidelity: Some(crate::fidelity::Fidelity::Full),
                ..Default::default()
            },
            ..SkinKnobs::default()
        };
        let with = SkinMaterial::build(params, 0.3, None, &full).unwrap();
        let table = &with
            .subsurface
            .as_ref()
            .expect("BSSRDF on by default")
            .table;
        let knobs = SkinKnobs {
            no_subsurface: true,
            ..SkinKnobs::default()
        };
        let without = SkinMaterial::build(params, 0.3, None, &knobs).unwrap();
        assert!(without.subsurface.is_none());
        for k in 0..=80 {
            let nm = 380.0 + 5.0 * k as f32;
            let a = with.total_reflectance.at_nm(nm);
            let t = table.total(nm);
            assert!((a - t).abs() <= 1e-6 * t, "{nm} nm: BSDF {a} vs table {t}");
            if k % 2 == 0 {
                let b = without.total_reflectance.at_nm(nm);
                assert!((a - b).abs() <= 1e-5 * b, "{nm} nm: {a} vs model {b}");
            }
        }
    }

    /// A bad roughness is the surface's typed error, before any profile is computed.
    #[test]
    fn bad_roughness_is_a_surface_error() {
        let params = SkinParams::preset(Preset::Dark);
        let e = SkinMaterial::build(params, 0.0, None, &SkinKnobs::default()).unwrap_err();
        assert!(matches!(e, SkinBuildError::Surface(_)), "{e}");
    }
}
