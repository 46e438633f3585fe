//! The volumetric reference integrator (`skin render --integrator volumetric`; docs/physics.md §15):
//! instead of the BSSRDF, light that enters a skin mesh random-walks through its two layers
//! ([`walk`]) until it leaves through the surface.
//!
//! Each skin material's meshes together bound its volume (closed meshes). The epidermis is the set
//! of points within d_epi of that surface ([`distance::SurfaceDistance`]), the dermis the rest.
//! Both layers' σa, σs and g come from `multipole::LayeredMedium::skin` (the one σs' → σs
//! conversion) at the skin's `phase_g`, tabulated per material every 5 nm and read at the path's
//! hero wavelength.

pub mod distance;
pub mod shapes;
pub mod thin;
pub mod walk;

use crate::material::Material;
use crate::scene::Scene;
use crate::spectrum::{
    LAMBDA_MAX_NM, LAMBDA_MIN_NM, N_WAVELENGTHS, SampledSpectrum, SpectrumTable,
};
use distance::SurfaceDistance;
use multipole::exact::montecarlo::HgSampler;
use multipole::{LayeredMedium, MultipoleError};
use skin_optics::Wavelength;

pub use crate::error::VolumetricError;
pub use thin::{ThinPart, ThinParts};
pub use walk::{Exit, Walk, walk};

/// One layer's coefficients over the visible range, mm⁻¹.
#[derive(Debug, Clone)]
pub struct LayerTables {
    /// Absorption σa(λ), mm⁻¹.
    pub sigma_a: SpectrumTable,
    /// Scattering σs(λ) = σs'(λ) / (1 − g), mm⁻¹.
    pub sigma_s: SpectrumTable,
}

impl LayerTables {
    /// The same σa and σs (mm⁻¹) at every wavelength.
    #[must_use]
    pub fn constant(sigma_a_per_mm: f32, sigma_s_per_mm: f32) -> Self {
        Self {
            sigma_a: SpectrumTable::constant(sigma_a_per_mm),
            sigma_s: SpectrumTable::constant(sigma_s_per_mm),
        }
    }
}

/// The two-layer medium inside one skin material's closed meshes.
#[derive(Debug, Clone)]
pub struct SkinVolume {
    /// The epidermis' coefficients.
    pub epidermis: LayerTables,
    /// The dermis' coefficients.
    pub dermis: LayerTables,
    /// Henyey–Greenstein sampler of both layers' g.
    pub hg: HgSampler,
    /// Index of refraction of the skin (outside: air, n = 1).
    pub eta: f32,
    /// Which points lie in the epidermis (within d_epi of the surface).
    pub epidermis_region: SurfaceDistance,
}

impl SkinVolume {
    /// A medium of the given layers, anisotropy `g`, index `eta`, epidermis `d_epi_mm` thick
    /// under the surface `triangles` (world mm).
    #[must_use]
    pub fn new(
        epidermis: LayerTables,
        dermis: LayerTables,
        g: f64,
        eta: f32,
        d_epi_mm: f32,
        triangles: Vec<[glam::Vec3; 3]>,
    ) -> Self {
        Self {
            epidermis,
            dermis,
            hg: HgSampler::new(g),
            eta,
            epidermis_region: SurfaceDistance::new(triangles, d_epi_mm),
        }
    }
}

/// The media of a scene, one per material (`None` for materials that are not skin).
#[derive(Debug, Clone, Default)]
pub struct Volumetric {
    /// Indexed by material.
    pub media: Vec<Option<SkinVolume>>,
}

impl Volumetric {
    /// The media of every skin material of `scene`, from its parameters and `phase_g`.
    pub fn build(scene: &Scene) -> Result<Self, VolumetricError> {
        let mut media = Vec::with_capacity(scene.materials.len());
        for (index, m) in scene.materials.iter().enumerate() {
            let Material::Skin(skin) = m else {
                media.push(None);
                continue;
            };
            let name = &scene.material_names[index];
            let triangles = scene.geometry.triangles_of(index as u32);
            let (epidermis, dermis) =
                layer_tables(&skin.params, skin.phase_g).map_err(|(nm, source)| {
                    VolumetricError::Layers {
                        material: name.clone(),
                        nm,
                        source,
                    }
                })?;
            media.push(Some(SkinVolume::new(
                epidermis,
                dermis,
                skin.phase_g,
                skin.params.eta() as f32,
                skin.params.epidermis_thickness_mm() as f32,
                triangles,
            )));
        }
        Ok(Self { media })
    }

    /// The medium of material `material`, if it is skin.
    #[must_use]
    pub fn medium(&self, material: u32) -> Option<&SkinVolume> {
        self.media.get(material as usize).and_then(Option::as_ref)
    }
}

/// The throughput kept by a walk traced at the hero wavelength alone: the other lanes end (0) and
/// the hero carries all N shares, which keeps the spectral estimate unbiased (the same as
/// `SampledWavelengths::terminate_secondary` for the film's estimator).
#[must_use]
pub fn hero_only(beta: SampledSpectrum) -> SampledSpectrum {
    let mut out = SampledSpectrum::zero();
    out.0[0] = beta.0[0] * N_WAVELENGTHS as f32;
    out
}

/// σa and σs of the skin's two layers on the 5-nm grid of [`SpectrumTable`], from
/// `LayeredMedium::skin` at anisotropy `g`; an error carries its wavelength.
pub(crate) fn layer_tables(
    params: &skin_optics::SkinParams,
    g: f64,
) -> Result<(LayerTables, LayerTables), (f64, MultipoleError)> {
    let step = f64::from(SpectrumTable::STEP_NM);
    let (from, to) = (f64::from(LAMBDA_MIN_NM), f64::from(LAMBDA_MAX_NM));
    let n = ((to - from) / step) as usize + 1;
    let mut rows = Vec::with_capacity(n);
    for i in 0..n {
        let nm = from + step * i as f64;
        let lambda = Wavelength::new(nm).map_err(|e| (nm, MultipoleError::from(e)))?;
        let medium = LayeredMedium::skin(params, lambda, g).map_err(|e| (nm, e))?;
        let layers = medium.layers();
        let (e, d) = (layers[0], layers[layers.len() - 1]);
        rows.push([e.sigma_a(), e.sigma_s(), d.sigma_a(), d.sigma_s()]);
    }
    let table = |k: usize| {
        SpectrumTable::from_fn(|nm| rows[(((nm - from) / step).round() as usize).min(n - 1)][k])
    };
    Ok((
        LayerTables {
            sigma_a: table(0),
            sigma_s: table(1),
        },
        LayerTables {
            sigma_a: table(2),
            sigma_s: table(3),
        },
    ))
}
