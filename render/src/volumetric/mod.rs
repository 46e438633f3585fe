//! The volumetric reference integrator (`skin render --integrator volumetric`; docs/physics.md §15):
//! instead of the BSSRDF, light that enters a skin mesh random-walks through its two layers
//! ([`walk`]) until it leaves through the surface.
//!
//! Each skin material's meshes together bound its volume (closed meshes). The epidermis is the set
//! of points within d_epi of that surface ([`distance::SurfaceDistance`]), the dermis the rest
//! (with a thin epidermis in the maps, d_epi is the nearest surface texel's, [`hetero`]).
//! Both layers' σa, σs and g are the material's own (`crate::media::SkinMedia`, built once when
//! the material is), tabulated every 5 nm and read at the path's hero wavelength.

pub mod distance;
pub mod guide;
pub mod hetero;
pub mod majorant;
pub mod nearest;
pub mod shapes;
pub mod slab_table;
pub mod thin;
pub mod walk;

use crate::error::SettingError;
use crate::material::Material;
use crate::scene::Scene;
use crate::spectrum::{N_WAVELENGTHS, SampledSpectrum, SpectrumTable};
use distance::SurfaceDistance;
use multipole::exact::montecarlo::HgSampler;

pub use crate::media::LayerTables;
pub use thin::{ThinPart, ThinParts};
pub use walk::{Exit, Walk, walk};

/// The two-layer medium inside one skin material's closed meshes.
#[derive(Debug, Clone)]
pub struct SkinVolume {
    /// The epidermis' coefficients.
    pub epidermis: LayerTables,
    /// The dermis' coefficients.
    pub dermis: LayerTables,
    /// Henyey–Greenstein sampler of both layers' g.
    pub hg: HgSampler,
    /// Both layers' Henyey–Greenstein g.
    pub g: f64,
    /// Share of the walk's segments sampled towards the surface ([`guide`]; 0: classic only).
    pub guided_fraction: f64,
    /// Weight below which the walk plays Russian roulette (`walk::ROULETTE_BELOW` by default).
    pub roulette_below: f64,
    /// Dwivedi's ν₀ of the epidermis and the dermis ([`guide::dwivedi_nu0`] of σs/σt; 0 where
    /// a layer does not absorb), tabulated with the layers: the guide's only input that costs a
    /// root-finding. Any value > 1 keeps the walk unbiased.
    pub dwivedi_nu0: [SpectrumTable; 2],
    /// Index of refraction of the skin (outside: air, n = 1).
    pub eta: f32,
    /// Which points lie in the epidermis (within d_epi of the surface).
    pub epidermis_region: SurfaceDistance,
    /// Per-texel absorption of a skin with chromophore maps (`None`: the layers are uniform).
    pub maps: Option<hetero::MapMedium>,
    /// The majorant of delta tracking with maps ([`majorant`]; the guided walk keeps the global
    /// one).
    pub majorant: majorant::Majorant,
    /// How a real collision with maps accounts for absorption ([`walk::Absorption`]).
    pub absorption: walk::Absorption,
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
        let dwivedi_nu0 = [&epidermis, &dermis].map(|layer| {
            SpectrumTable::from_fn(|nm| {
                let nm = nm as f32;
                let (sa, ss) = (layer.sigma_a.at_nm(nm), layer.sigma_s.at_nm(nm));
                guide::dwivedi_nu0(f64::from(ss) / (f64::from(sa) + f64::from(ss))).unwrap_or(0.0)
            })
        });
        Self {
            epidermis,
            dermis,
            hg: HgSampler::new(g),
            g,
            guided_fraction: guide::DEFAULT_GUIDED_FRACTION,
            roulette_below: walk::ROULETTE_BELOW,
            dwivedi_nu0,
            eta,
            epidermis_region: SurfaceDistance::new(triangles, d_epi_mm),
            maps: None,
            majorant: majorant::Majorant::default(),
            absorption: walk::Absorption::default(),
        }
    }

    /// The same medium with `fraction` of the walk's segments guided towards the surface, in
    /// [0, 1] (0: the classic walk; 1: guided only, its weights unbounded).
    ///
    /// # Errors
    /// [`SettingError`] naming `guided_fraction` outside [0, 1].
    pub fn with_guided_fraction(mut self, fraction: f64) -> Result<Self, SettingError> {
        if !(0.0..=1.0).contains(&fraction) {
            return Err(SettingError {
                name: "guided_fraction",
                value: fraction.to_string(),
                range: "[0, 1]",
            });
        }
        self.guided_fraction = fraction;
        Ok(self)
    }

    /// The same medium with delta tracking against `majorant`.
    #[must_use]
    pub fn with_majorant(mut self, majorant: majorant::Majorant) -> Self {
        self.majorant = majorant;
        self
    }

    /// The same medium with real collisions accounting for absorption by `absorption`.
    #[must_use]
    pub fn with_absorption(mut self, absorption: walk::Absorption) -> Self {
        self.absorption = absorption;
        self
    }

    /// The same medium with the walk's Russian roulette below weight `weight`, in (0, 1]: the walk
    /// goes on with probability w/weight at that weight.
    ///
    /// # Errors
    /// [`SettingError`] naming `roulette_below` outside (0, 1].
    pub fn with_roulette_below(mut self, weight: f64) -> Result<Self, SettingError> {
        if !(weight > 0.0 && weight <= 1.0) {
            return Err(SettingError {
                name: "roulette_below",
                value: weight.to_string(),
                range: "(0, 1]",
            });
        }
        self.roulette_below = weight;
        Ok(self)
    }
}

/// The media of a scene, one per material (`None` for materials that are not skin).
#[derive(Debug, Clone, Default)]
pub struct Volumetric {
    /// Indexed by material.
    pub media: Vec<Option<SkinVolume>>,
}

impl Volumetric {
    /// The media of every skin material of `scene`: its layers (`SkinMedia`) inside its meshes.
    #[must_use]
    pub fn build(scene: &Scene) -> Self {
        let mut media = Vec::with_capacity(scene.materials.len());
        for (index, m) in scene.materials.iter().enumerate() {
            let Material::Skin(skin) = m else {
                media.push(None);
                continue;
            };
            let triangles = scene.geometry.triangles_of(index as u32);
            let mut volume = SkinVolume::new(
                skin.media.epidermis.clone(),
                skin.media.dermis.clone(),
                skin.media.phase_g,
                skin.params.eta() as f32,
                skin.maps
                    .as_ref()
                    .map_or(skin.params.epidermis_thickness_mm() as f32, |m| {
                        m.deepest_epidermis_mm()
                    }),
                triangles,
            );
            volume.maps = skin.maps.as_ref().map(|maps| {
                hetero::MapMedium::new(
                    maps.clone(),
                    &scene.geometry.triangles_with_uvs_of(index as u32),
                    f64::from(maps.deepest_epidermis_mm()),
                    majorant::DEFAULT_CELL_MM,
                )
            });
            media.push(Some(volume));
        }
        Self { media }
    }

    /// The medium of material `material`, if it is skin.
    #[must_use]
    pub fn medium(&self, material: u32) -> Option<&SkinVolume> {
        self.media.get(material as usize).and_then(Option::as_ref)
    }
}

/// The throughput kept by a walk traced at the hero wavelength alone: the other lanes end (0) and
/// the hero carries all N shares, which keeps the spectral estimate unbiased (the same as
/// `SampledWavelengths::terminate_secondary` for the film's estimator). Once per path: a later
/// walk on the same path keeps the hero's throughput as it is (docs/physics.md §15.2).
#[must_use]
pub fn hero_only(beta: SampledSpectrum) -> SampledSpectrum {
    let mut out = SampledSpectrum::zero();
    out.0[0] = beta.0[0] * N_WAVELENGTHS as f32;
    out
}
